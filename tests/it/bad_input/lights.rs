//! The scene file's `[[light]]` tables at fault (point, spot, directional, sun disc and
//! environment lights), and scenes lit by a point light alone or by no light.

use super::*;

fn cases() -> Vec<Case> {
    vec![
        // Accepted bad values.
        Case {
            name: "a point light of NaN intensity",
            files: files(
                scene(
                    "[[light]]\ntype = \"point\"\nposition = [0, 1, 0]\nintensity = [nan, 1, 1]\n",
                ),
                OBJ,
                MTL,
            ),
            setup: vec![],
            prepare: None,
            args: "render {d}/s.toml --method path --spp 1 --threads 1 --out {d}/out",
            code: 1,
            words: &["s.toml: light 0 (point): intensity must be finite and >= 0"],
            check: absent("out"),
        },
        Case {
            name: "a point light of negative intensity",
            files: files(
                scene(
                    "[[light]]\ntype = \"point\"\nposition = [0, 1, 0]\nintensity = [1, -1, 1]\n",
                ),
                OBJ,
                MTL,
            ),
            setup: vec![],
            prepare: None,
            args: "render {d}/s.toml --method path --spp 1 --threads 1 --out {d}/out",
            code: 1,
            words: &["s.toml: light 0 (point): intensity must be finite and >= 0"],
            check: absent("out"),
        },
        Case {
            name: "a point light of zero intensity",
            files: files(
                scene("[[light]]\ntype = \"point\"\nposition = [0, 1, 0]\nintensity = [0, 0, 0]\n"),
                OBJ,
                MTL,
            ),
            setup: vec![],
            prepare: None,
            args: "render {d}/s.toml --method path --spp 1 --threads 1 --out {d}/out",
            code: 1,
            words: &["s.toml: light 0 (point): intensity must not be zero"],
            check: absent("out"),
        },
        Case {
            name: "a point light at infinity",
            files: files(
                scene(
                    "[[light]]\ntype = \"point\"\nposition = [0, inf, 0]\nintensity = [1, 1, 1]\n",
                ),
                OBJ,
                MTL,
            ),
            setup: vec![],
            prepare: None,
            args: "render {d}/s.toml --method path --spp 1 --threads 1 --out {d}/out",
            code: 1,
            words: &["s.toml: light 0 (point): position must be finite"],
            check: absent("out"),
        },
        Case {
            name: "a spot with cutoff 0",
            files: files(
                scene(
                    "[[light]]\ntype = \"spot\"\nposition = [0, 1, 0]\nlook_at = [0, 0, 0]\nintensity = [1, 1, 1]\ncutoff_angle = 0\n",
                ),
                OBJ,
                MTL,
            ),
            setup: vec![],
            prepare: None,
            args: "render {d}/s.toml --method path --spp 1 --threads 1 --out {d}/out",
            code: 1,
            words: &["s.toml: light 0 (spot): cutoff_angle = 0 must be in (0, 90] degrees"],
            check: absent("out"),
        },
        Case {
            name: "a spot with cutoff 91",
            files: files(
                scene(
                    "[[light]]\ntype = \"spot\"\nposition = [0, 1, 0]\nlook_at = [0, 0, 0]\nintensity = [1, 1, 1]\ncutoff_angle = 91\n",
                ),
                OBJ,
                MTL,
            ),
            setup: vec![],
            prepare: None,
            args: "render {d}/s.toml --method path --spp 1 --threads 1 --out {d}/out",
            code: 1,
            words: &["s.toml: light 0 (spot): cutoff_angle = 91 must be in (0, 90] degrees"],
            check: absent("out"),
        },
        Case {
            name: "a spot whose beam is wider than its cutoff",
            files: files(
                scene(
                    "[[light]]\ntype = \"spot\"\nposition = [0, 1, 0]\nlook_at = [0, 0, 0]\nintensity = [1, 1, 1]\ncutoff_angle = 20\nbeam_width = 25\n",
                ),
                OBJ,
                MTL,
            ),
            setup: vec![],
            prepare: None,
            args: "render {d}/s.toml --method path --spp 1 --threads 1 --out {d}/out",
            code: 1,
            words: &[
                "s.toml: light 0 (spot): beam_width = 25 must be in [0, cutoff_angle = 20] degrees",
            ],
            check: absent("out"),
        },
        Case {
            name: "a spot looking at itself",
            files: files(
                scene(
                    "[[light]]\ntype = \"spot\"\nposition = [0, 1, 0]\nlook_at = [0, 1, 0]\nintensity = [1, 1, 1]\n",
                ),
                OBJ,
                MTL,
            ),
            setup: vec![],
            prepare: None,
            args: "render {d}/s.toml --method path --spp 1 --threads 1 --out {d}/out",
            code: 1,
            words: &["s.toml: light 0 (spot): look_at must be finite and differ from position"],
            check: absent("out"),
        },
        light_case(
            "a directional light of zero direction",
            "type = \"directional\"\ndirection = [0, 0, 0]\nirradiance = [1, 1, 1]",
            vec![],
            &["s.toml: light 0 (directional): direction must be finite and not zero"],
        ),
        light_case(
            "a directional light of NaN direction",
            "type = \"directional\"\ndirection = [0, nan, 0]\nirradiance = [1, 1, 1]",
            vec![],
            &["s.toml: light 0 (directional): direction must be finite and not zero"],
        ),
        light_case(
            "a directional light of negative irradiance",
            "type = \"directional\"\ndirection = [0, -1, 0]\nirradiance = [1, -1, 1]",
            vec![],
            &["s.toml: light 0 (directional): irradiance must be finite and >= 0"],
        ),
        light_case(
            "a directional light of NaN irradiance",
            "type = \"directional\"\ndirection = [0, -1, 0]\nirradiance = [nan, 1, 1]",
            vec![],
            &["s.toml: light 0 (directional): irradiance must be finite and >= 0"],
        ),
        light_case(
            "a directional light of zero irradiance",
            "type = \"directional\"\ndirection = [0, -1, 0]\nirradiance = [0, 0, 0]",
            vec![],
            &["s.toml: light 0 (directional): irradiance must not be zero"],
        ),
        light_case(
            "a sun disc of angular radius 0",
            "type = \"directional\"\ndirection = [0, -1, 0]\nirradiance = [1, 1, 1]\nangular_radius = 0",
            vec![],
            &["s.toml: light 0 (directional): angular_radius = 0 must be in (0, 90] degrees"],
        ),
        light_case(
            "a sun disc of angular radius 120",
            "type = \"directional\"\ndirection = [0, -1, 0]\nirradiance = [1, 1, 1]\nangular_radius = 120",
            vec![],
            &["s.toml: light 0 (directional): angular_radius = 120 must be in (0, 90] degrees"],
        ),
        light_case(
            "an environment with both a file and a radiance",
            "type = \"environment\"\nfilename = \"env.exr\"\nradiance = [1, 1, 1]",
            vec![("env.exr", Input::Exr(grey(8, 4)))],
            &["s.toml: light 0 (environment): give either filename (an image) or radiance"],
        ),
        light_case(
            "an environment with neither a file nor a radiance",
            "type = \"environment\"\nscale = 2",
            vec![],
            &["s.toml: light 0 (environment): give either filename (an image) or radiance"],
        ),
        light_case(
            "an environment of negative scale",
            "type = \"environment\"\nradiance = [1, 1, 1]\nscale = -1",
            vec![],
            &["s.toml: light 0 (environment): scale = -1 must be finite and > 0"],
        ),
        light_case(
            "an environment of NaN rotation",
            "type = \"environment\"\nradiance = [1, 1, 1]\nrotate = [0, nan, 0]",
            vec![],
            &["s.toml: light 0 (environment): rotate must be finite"],
        ),
        light_case(
            "an environment of negative radiance",
            "type = \"environment\"\nradiance = [1, -1, 1]",
            vec![],
            &[
                "s.toml: light 0 (environment): the environment radiance",
                "must be finite and non-negative",
            ],
        ),
        light_case(
            "the second light of two, an environment, is named by its index",
            "type = \"point\"\nposition = [0, 1, 0]\nintensity = [1, 1, 1]\n[[light]]\n\
             type = \"environment\"\nradiance = [1, 1, 1]\nscale = 0",
            vec![],
            &["s.toml: light 1 (environment): scale = 0 must be finite and > 0"],
        ),
        Case {
            name: "a light of unknown type",
            files: files(
                scene("[[light]]\ntype = \"area\"\nposition = [0, 1, 0]\nintensity = [1, 1, 1]\n"),
                OBJ,
                MTL,
            ),
            setup: vec![],
            prepare: None,
            args: "render {d}/s.toml --method path --spp 1 --threads 1 --out {d}/out",
            code: 1,
            words: &["s.toml", "unknown variant `area`"],
            check: absent("out"),
        },
        Case {
            name: "a point light with an unknown key",
            files: files(
                scene(
                    "[[light]]\ntype = \"point\"\nposition = [0, 1, 0]\nintensity = [1, 1, 1]\ncolour = 2\n",
                ),
                OBJ,
                MTL,
            ),
            setup: vec![],
            prepare: None,
            args: "render {d}/s.toml --method path --spp 1 --threads 1 --out {d}/out",
            code: 1,
            words: &["s.toml", "unknown field `colour`"],
            check: absent("out"),
        },
        Case {
            name: "a scene lit only by a point light (once refused: no light)",
            files: files(
                scene(
                    "[[light]]\ntype = \"point\"\nposition = [0, 0.5, 0]\nintensity = [1, 1, 1]\n",
                ),
                OBJ,
                &MTL.replace("Ke 4 4 4", "Ke 0 0 0"),
            ),
            setup: vec![],
            prepare: None,
            args: "render {d}/s.toml --method path --spp 1 --threads 1 --out {d}/out",
            code: 0,
            words: &[],
            check: present("out/image.json", "path"),
        },
        Case {
            name: "a scene without any light",
            files: files(scene(""), OBJ, &MTL.replace("Ke 4 4 4", "Ke 0 0 0")),
            setup: vec![],
            prepare: None,
            args: "render {d}/s.toml --method path --spp 1 --threads 1 --out {d}/out",
            code: 1,
            words: &["s.toml: the scene has no light"],
            check: absent("out"),
        },
        // Positions within the range vertices have.
        light_case(
            "a point light at 1e20",
            "type = \"point\"\nposition = [1e20, 1, 0]\nintensity = [1, 1, 1]",
            vec![],
            &[
                "s.toml: light 0 (point): position [1e20, 1.0, 0.0]",
                "1e15 scene units",
            ],
        ),
        light_case(
            "a spot aimed at 1e20",
            "type = \"spot\"\nposition = [0, 1, 0]\nlook_at = [0, -1e20, 0]\nintensity = [1, 1, 1]",
            vec![],
            &[
                "s.toml: light 0 (spot): look_at [0.0, -1e20, 0.0]",
                "1e15 scene units",
            ],
        ),
    ]
}

#[test]
fn bad_input_table() {
    run_table("lights", cases());
}
