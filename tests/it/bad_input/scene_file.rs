//! The scene file at fault: missing, a FIFO or malformed, and its keys out of range
//! (`[estimate]`, `[photons]`, glass materials), each named alone.

use super::*;

/// A case whose scene file gives material `white` (the floor's) as `body`, run through
/// `info`: refused with `words`.
fn material(name: &'static str, body: &str, words: &'static [&'static str]) -> Case {
    Case {
        name,
        files: files(scene(&format!("[material.white]\n{body}\n")), OBJ, MTL),
        setup: vec![],
        prepare: None,
        args: "info {d}/s.toml",
        code: 1,
        words,
        check: None,
    }
}

fn cases() -> Vec<Case> {
    let global = |extra: &str| scene(&format!("[estimate.global]\n{extra}\n"));
    vec![
        // Coloured and absorbing glass: the scene file's keys.
        Case {
            name: "a negative absorption on glass",
            files: files(
                scene(
                    "[material.glass]\ntype = \"dielectric\"\nior = 1.5\nabsorption = [0.1, -1, 0]\n",
                ),
                OBJ,
                MTL,
            ),
            setup: vec![],
            prepare: None,
            args: "info {d}/s.toml",
            code: 1,
            words: &[
                "s.toml",
                "material `glass`",
                "absorption",
                "finite and >= 0",
            ],
            check: None,
        },
        Case {
            name: "a NaN absorption on rough glass",
            files: files(
                scene(
                    "[material.frost]\ntype = \"rough_dielectric\"\nior = 1.5\nalpha = 0.2\nabsorption = [nan, 0, 0]\n",
                ),
                OBJ,
                MTL,
            ),
            setup: vec![],
            prepare: None,
            args: "info {d}/s.toml",
            code: 1,
            words: &["s.toml", "material `frost`", "absorption"],
            check: None,
        },
        Case {
            name: "a glass transmittance above 1",
            files: files(
                scene(
                    "[material.glass]\ntype = \"dielectric\"\nior = 1.5\ntransmittance = [1.2, 0.5, 0.5]\n",
                ),
                OBJ,
                MTL,
            ),
            setup: vec![],
            prepare: None,
            args: "info {d}/s.toml",
            code: 1,
            words: &["s.toml", "material `glass`", "transmittance", "[0, 1]"],
            check: None,
        },
        // The scene file itself.
        Case {
            name: "info on a missing scene",
            files: vec![],
            setup: vec![],
            prepare: None,
            args: "info {d}/none.toml",
            code: 1,
            words: &["none.toml", "cannot read scene file"],
            check: None,
        },
        // Hangs.
        Case {
            name: "a scene file that is a FIFO",
            files: vec![("s.toml", Input::Fifo)],
            setup: vec![],
            prepare: None,
            args: "render {d}/s.toml",
            code: 1,
            words: &["s.toml", "not a regular file"],
            check: None,
        },
        Case {
            name: "sppm photons per pass beyond what one pass can map",
            files: files(
                scene("[estimate.sppm]\nphotons = 1000000000000\n"),
                OBJ,
                MTL,
            ),
            setup: vec![],
            prepare: None,
            args: "render {d}/s.toml --method sppm --passes 1 --threads 1 --out {d}/out",
            code: 1,
            words: &[
                "s.toml: estimate.sppm.photons = 1000000000000 must be at most 4294967294 \
                 photon paths per pass",
            ],
            check: absent("out"),
        },
        Case {
            name: "sppm photons per pass from [photons] beyond what one pass can map",
            files: files(scene("[photons]\nphotons = 5000000000\n"), OBJ, MTL),
            setup: vec![],
            prepare: None,
            args: "render {d}/s.toml --method sppm --passes 1 --threads 1 --out {d}/out",
            code: 1,
            words: &[
                "s.toml: photons = 5000000000: is sppm's pass size",
                "must be at most 4294967294",
            ],
            check: absent("out"),
        },
        // Accepted bad values.
        Case {
            name: "r_max negative",
            files: files(global("r_max = -1.0"), OBJ, MTL),
            setup: vec![],
            prepare: None,
            args: "render {d}/s.toml --method global-direct --photons 2000 --cache {d}/cache --out {d}/out",
            code: 1,
            words: &["s.toml", "estimate.global.r_max = -1 must be positive"],
            check: absent("out"),
        },
        Case {
            name: "r_max NaN",
            files: files(global("r_max = nan"), OBJ, MTL),
            setup: vec![],
            prepare: None,
            args: "estimate {d}/s.toml --photons 2000 --cache {d}/cache --out {d}/out",
            code: 1,
            words: &["s.toml", "r_max = NaN must be positive"],
            check: absent("out"),
        },
        Case {
            name: "sppm radius 1e30",
            files: files(scene("[estimate.sppm]\nradius = 1e30\n"), OBJ, MTL),
            setup: vec![],
            prepare: None,
            args: "render {d}/s.toml --method sppm --photons 2000 --passes 1 --threads 1 --out {d}/out",
            code: 1,
            words: &[
                "s.toml: estimate.sppm.radius = 1000000000000000000000000000000 exceeds the \
                 scene's bounding diagonal (3)",
            ],
            check: absent("out"),
        },
        Case {
            name: "splat indirect_radius -1",
            files: files(
                scene("[estimate.splat]\nindirect_radius = -1.0\n"),
                OBJ,
                MTL,
            ),
            setup: vec![],
            prepare: None,
            args: "render {d}/s.toml --method caustic-splat --photons 2000 --threads 1 --out {d}/out",
            code: 1,
            words: &["s.toml: estimate.splat.indirect_radius = -1 must be finite and >= 0"],
            check: absent("out"),
        },
        Case {
            name: "splat indirect_radius NaN",
            files: files(scene("[estimate.splat]\nindirect_radius = nan\n"), OBJ, MTL),
            setup: vec![],
            prepare: None,
            args: "render {d}/s.toml --method caustic-splat --photons 2000 --threads 1 --out {d}/out",
            code: 1,
            words: &["s.toml: estimate.splat.indirect_radius = NaN must be finite and >= 0"],
            check: absent("out"),
        },
        Case {
            name: "final_gather rays = 0",
            files: files(scene("[estimate.final_gather]\nrays = 0\n"), OBJ, MTL),
            setup: vec![],
            prepare: None,
            args: "render {d}/s.toml --method final-gather --photons 2000 --threads 1 --cache {d}/cache --out {d}/out",
            code: 1,
            words: &["s.toml: estimate.final_gather.rays = 0 must be at least 1"],
            check: absent("out"),
        },
        // Messages.
        Case {
            name: "a malformed scene file spans one line",
            files: vec![("s.toml", text("[camera\neye = 1\n"))],
            setup: vec![],
            prepare: None,
            args: "info {d}/s.toml",
            code: 1,
            words: &["s.toml", "malformed scene file", "line 1"],
            check: None,
        },
        // The file's keys are named one at a time.
        Case {
            name: "sppm passes = 0 in the file names that key alone",
            files: files(scene("[estimate.sppm]\npasses = 0\n"), OBJ, MTL),
            setup: vec![],
            prepare: None,
            args: "render {d}/s.toml --method sppm --out {d}/out",
            code: 1,
            words: &[
                "error: ",
                "s.toml: estimate.sppm.passes = 0 must be in 1..=1048576",
            ],
            check: absent("out"),
        },
        Case {
            name: "sppm alpha = 1 in the file names that key alone",
            files: files(scene("[estimate.sppm]\nalpha = 1.0\n"), OBJ, MTL),
            setup: vec![],
            prepare: None,
            args: "render {d}/s.toml --method sppm --out {d}/out",
            code: 1,
            words: &["s.toml: estimate.sppm.alpha = 1 must be in (0, 1)"],
            check: absent("out"),
        },
        Case {
            name: "splat splits = 99 in the file names that key alone",
            files: files(scene("[estimate.splat]\nsplits = 99\n"), OBJ, MTL),
            setup: vec![],
            prepare: None,
            args: "render {d}/s.toml --method caustic-splat --out {d}/out",
            code: 1,
            words: &["s.toml: estimate.splat.splits = 99 is absurd (at most 16)"],
            check: absent("out"),
        },
        // Material keys, each named with its value.
        material(
            "glossy alpha = 0",
            "type = \"glossy\"\nalbedo = [0.5, 0.5, 0.5]\nspecular = [0.2, 0.2, 0.2]\nalpha = 0",
            &["s.toml: material `white`: alpha = 0 must be in [1e-4, 1]"],
        ),
        material(
            "glossy alpha = 1e-5",
            "type = \"glossy\"\nalbedo = [0.5, 0.5, 0.5]\nspecular = [0.2, 0.2, 0.2]\nalpha = 1e-5",
            &["s.toml: material `white`: alpha = 0.00001 must be in [1e-4, 1]"],
        ),
        material(
            "rough_conductor alpha = 1.0001",
            "type = \"rough_conductor\"\nalpha = 1.0001",
            &["s.toml: material `white`: alpha = 1.0001 must be in [1e-4, 1]"],
        ),
        material(
            "rough_conductor alpha = -0.1",
            "type = \"rough_conductor\"\nalpha = -0.1",
            &["s.toml: material `white`: alpha = -0.1 must be in [1e-4, 1]"],
        ),
        material(
            "rough_dielectric alpha = NaN",
            "type = \"rough_dielectric\"\nior = 1.5\nalpha = nan",
            &["s.toml: material `white`: alpha = NaN must be in [1e-4, 1]"],
        ),
        material(
            "lambertian albedo above 1",
            "type = \"lambertian\"\nalbedo = [1.2, 0.5, 0.5]",
            &["s.toml: material `white`: albedo = [1.2, 0.5, 0.5] must lie in [0, 1]"],
        ),
        material(
            "glossy specular negative",
            "type = \"glossy\"\nalbedo = [0.5, 0.5, 0.5]\nspecular = [-0.1, 0.2, 0.2]\nalpha = 0.1",
            &["s.toml: material `white`: specular = [-0.1, 0.2, 0.2] must lie in [0, 1]"],
        ),
        material(
            "glossy albedo + specular above 1",
            "type = \"glossy\"\nalbedo = [0.5, 0.5, 0.5]\nspecular = [0.6, 0.2, 0.2]\nalpha = 0.1",
            &["s.toml: material `white`: albedo + specular = [1.1, 0.7, 0.7] exceeds 1"],
        ),
        material(
            "mirror reflectance above 1",
            "type = \"mirror\"\nreflectance = [1.5, 1, 1]",
            &["s.toml: material `white`: reflectance = [1.5, 1, 1] must lie in [0, 1]"],
        ),
        material(
            "dielectric ior = 0",
            "type = \"dielectric\"\nior = 0",
            &["s.toml: material `white`: ior = 0 must be in (0, 10)"],
        ),
        material(
            "rough_dielectric ior = 12",
            "type = \"rough_dielectric\"\nior = 12\nalpha = 0.1",
            &["s.toml: material `white`: ior = 12 must be in (0, 10)"],
        ),
        material(
            "rough_conductor eta = k = 0",
            "type = \"rough_conductor\"\nalpha = 0.1\neta = [0, 1, 1]\nk = [0, 1, 1]",
            &["s.toml: material `white`: eta = [0, 1, 1], k = [0, 1, 1]: eta or k must be > 0"],
        ),
        material(
            "rough_conductor eta negative",
            "type = \"rough_conductor\"\nalpha = 0.1\neta = [-1, 1, 1]\nk = [1, 1, 1]",
            &["s.toml: material `white`: eta = [-1, 1, 1] must be finite and >= 0"],
        ),
        material(
            "conductor unknown material",
            "type = \"conductor\"\nmaterial = \"gold\"",
            &["s.toml: material `white`: material = \"gold\" is not one of Mitsuba 3's"],
        ),
        material(
            "conductor material and eta",
            "type = \"conductor\"\nmaterial = \"Au\"\neta = [1, 1, 1]\nk = [1, 1, 1]",
            &["s.toml: material `white`: material = \"Au\" and eta, k both give the index"],
        ),
        material(
            "conductor reflectance above 1",
            "type = \"conductor\"\nreflectance = [1.1, 1, 1]",
            &["s.toml: material `white`: reflectance = [1.1, 1, 1] must lie in [0, 1]"],
        ),
        material(
            "plastic diffuse above 1",
            "type = \"plastic\"\ndiffuse = [1.5, 0.5, 0.5]",
            &["s.toml: material `white`: diffuse = [1.5, 0.5, 0.5] must lie in [0, 1]"],
        ),
        material(
            "plastic specular NaN",
            "type = \"plastic\"\ndiffuse = [0.5, 0.5, 0.5]\nspecular = [nan, 1, 1]",
            &["s.toml: material `white`: specular = [NaN, 1, 1] must lie in [0, 1]"],
        ),
        material(
            "plastic ior negative",
            "type = \"plastic\"\ndiffuse = [0.5, 0.5, 0.5]\nior = -1.5",
            &["s.toml: material `white`: ior = -1.5 must be in (0, 10)"],
        ),
        material(
            "rough_plastic ior = 1",
            "type = \"rough_plastic\"\ndiffuse = [0.5, 0.5, 0.5]\nior = 1",
            &["s.toml: material `white`: ior = 1 leaves no coating"],
        ),
        material(
            "rough_plastic alpha = 0",
            "type = \"rough_plastic\"\ndiffuse = [0.5, 0.5, 0.5]\nalpha = 0",
            &["s.toml: material `white`: alpha = 0 must be in [1e-4, 1]"],
        ),
        material(
            "thin_dielectric ior = 0",
            "type = \"thin_dielectric\"\nior = 0",
            &["s.toml: material `white`: ior = 0 must be in (0, 10)"],
        ),
        material(
            "thin_dielectric transmittance negative",
            "type = \"thin_dielectric\"\ntransmittance = [-0.5, 1, 1]",
            &["s.toml: material `white`: transmittance = [-0.5, 1, 1] must lie in [0, 1]"],
        ),
        material(
            "rough_conductor k negative",
            "type = \"rough_conductor\"\nalpha = 0.1\neta = [1, 1, 1]\nk = [-1, 1, 1]",
            &["s.toml: material `white`: k = [-1, 1, 1] must be finite and >= 0"],
        ),
        material(
            "rough_conductor eta without k",
            "type = \"rough_conductor\"\nalpha = 0.1\neta = [1, 1, 1]",
            &["s.toml: material `white`: eta and k", "k is missing"],
        ),
        // A texture brighter than 1 under a diffuse albedo.
        Case {
            name: "lambertian albedo x texture above 1",
            files: with(
                files(
                    scene(
                        "[material.white]\ntype = \"lambertian\"\nalbedo = [0.7, 0.7, 0.7]\ntexture = \"t.exr\"\n",
                    ),
                    OBJ,
                    MTL,
                ),
                "t.exr",
                Input::Exr(film::Image::from_fn(2, 2, |_, _| [4.0; 3])),
            ),
            setup: vec![],
            prepare: None,
            args: "info {d}/s.toml",
            code: 0,
            words: &[],
            check: texture_scaled(&["s.toml: material `white`", "brightest texel", "exceeds 1"]),
        },
    ]
}

#[test]
fn bad_input_table() {
    run_table("scene-file", cases());
}
