//! Mitsuba 3 XML scenes at fault: each refused with one line naming the file, the line and
//! the element; what photonflow draws approximately or leaves out says so in a warning.

use super::*;

/// A good XML scene: a camera above a lit floor. `{extra}` goes inside `<scene>` after it.
fn xml(extra: &str) -> String {
    format!(
        r#"<scene version="3.0.0">
    <sensor type="perspective">
        <float name="fov" value="60"/>
        <transform name="to_world">
            <lookat origin="0, 1, 3" target="0, 0, 0" up="0, 1, 0"/>
        </transform>
        <film type="hdrfilm">
            <integer name="width" value="16"/>
            <integer name="height" value="16"/>
            <rfilter type="box"/>
        </film>
    </sensor>
    <shape type="rectangle">
        <transform name="to_world"><rotate x="1" angle="-90"/></transform>
    </shape>
    <shape type="rectangle">
        <transform name="to_world"><scale value="0.1"/><rotate x="1" angle="90"/><translate y="1"/></transform>
        <emitter type="area"><rgb name="radiance" value="4"/></emitter>
    </shape>
{extra}
</scene>
"#
    )
}

/// The scene `s.xml` (line 20 is the first line of `extra`) refused with `words`.
fn refused(name: &'static str, extra: &str, words: &'static [&'static str]) -> Case {
    Case {
        name,
        files: vec![("s.xml", text(xml(extra)))],
        setup: vec![],
        prepare: None,
        args: "render {d}/s.xml --method path --spp 1 --threads 1 --out {d}/out",
        code: 1,
        words,
        check: absent("out"),
    }
}

fn warned(name: &'static str, extra: &str, words: &'static [&'static str]) -> Case {
    Case {
        name,
        files: vec![("s.xml", text(xml(extra)))],
        setup: vec![],
        prepare: None,
        args: "info {d}/s.xml",
        code: 0,
        words: &[],
        check: warns_in("s.xml", words),
    }
}

fn cases() -> Vec<Case> {
    vec![
        refused(
            "malformed XML",
            "<shape type=\"cube\">",
            &["s.xml: malformed XML"],
        ),
        Case {
            name: "no version",
            files: vec![("s.xml", text("<scene>\n</scene>\n"))],
            setup: vec![],
            prepare: None,
            args: "info {d}/s.xml",
            code: 1,
            words: &["s.xml: line 1", "no `version`"],
            check: None,
        },
        Case {
            name: "not a scene",
            files: vec![("s.xml", text("<html version=\"3.0.0\"/>\n"))],
            setup: vec![],
            prepare: None,
            args: "info {d}/s.xml",
            code: 1,
            words: &["s.xml: line 1", "not <scene>"],
            check: None,
        },
        refused(
            "a shape photonflow lacks",
            "<shape type=\"cylinder\"/>",
            &[
                "s.xml: line 20",
                "<shape type=\"cylinder\">",
                "not a shape photonflow reads",
            ],
        ),
        refused(
            "a BSDF photonflow lacks",
            "<shape type=\"cube\"><bsdf type=\"hair\"/></shape>",
            &[
                "s.xml: line 20",
                "<bsdf type=\"hair\">",
                "not a BSDF photonflow reads",
            ],
        ),
        refused(
            "an emitter photonflow lacks",
            "<emitter type=\"sunsky\"/>",
            &[
                "s.xml: line 20",
                "<emitter type=\"sunsky\">",
                "not an emitter",
            ],
        ),
        refused(
            "a medium",
            "<medium type=\"homogeneous\" id=\"fog\"/>",
            &["s.xml: line 20", "<medium", "not read by photonflow"],
        ),
        refused(
            "an unknown parameter",
            "<emitter type=\"point\"><rgb name=\"intensity\" value=\"$power\"/></emitter>",
            &["s.xml: line 20", "`$power` has no value", "-D power="],
        ),
        refused(
            "a reference to nothing",
            "<shape type=\"cube\"><ref id=\"steel\"/></shape>",
            &["s.xml: line 20", "refers to `steel`"],
        ),
        refused(
            "two elements of one id",
            "<bsdf type=\"diffuse\" id=\"a\"/>\n<bsdf type=\"diffuse\" id=\"a\"/>",
            &["s.xml: line 21", "a second element with id `a`"],
        ),
        refused(
            "a number that is not one",
            "<shape type=\"sphere\"><float name=\"radius\" value=\"big\"/></shape>",
            &[
                "s.xml: line 20",
                "<float name=\"radius\">",
                "`big` is not a finite number",
            ],
        ),
        refused(
            "a NaN colour",
            "<emitter type=\"point\"><rgb name=\"intensity\" value=\"nan, 1, 1\"/></emitter>",
            &[
                "s.xml: line 20",
                "<rgb name=\"intensity\">",
                "not a finite number",
            ],
        ),
        refused(
            "an unknown transform",
            "<shape type=\"cube\"><transform name=\"to_world\"><shear value=\"1\"/></transform></shape>",
            &["s.xml: line 20", "unknown transform operation <shear>"],
        ),
        refused(
            "a sphere stretched",
            "<shape type=\"sphere\"><transform name=\"to_world\"><scale x=\"2\"/></transform></shape>",
            &[
                "s.xml: line 20",
                "<shape type=\"sphere\">",
                "stretches the sphere",
            ],
        ),
        refused(
            "an emitting sphere",
            "<shape type=\"sphere\"><emitter type=\"area\"/></shape>",
            &["s.xml: line 20", "area emitter on a sphere"],
        ),
        refused(
            "a missing mesh file",
            "<shape type=\"obj\"><string name=\"filename\" value=\"gone.obj\"/></shape>",
            &["gone.obj: cannot read OBJ file"],
        ),
        refused(
            "anisotropic roughness",
            "<shape type=\"cube\"><bsdf type=\"roughconductor\"><float name=\"alpha_u\" value=\"0.1\"/><float name=\"alpha_v\" value=\"0.3\"/></bsdf></shape>",
            &[
                "s.xml: line 20",
                "<bsdf type=\"roughconductor\">",
                "anisotropic",
            ],
        ),
        refused(
            "a hidden emitter",
            "<integrator type=\"path\"><boolean name=\"hide_emitters\" value=\"true\"/></integrator>",
            &["s.xml: line 20", "hide_emitters"],
        ),
        refused(
            "an integrator photonflow lacks",
            "<integrator type=\"aov\"/>",
            &["s.xml: line 20", "<integrator type=\"aov\">"],
        ),
        refused(
            "an include of itself",
            "<include filename=\"s.xml\"/>",
            &["s.xml", "included 16 files deep"],
        ),
        Case {
            name: "a mirrored camera",
            files: vec![(
                "s.xml",
                text(xml("").replace(
                    "<transform name=\"to_world\">\n            <lookat",
                    "<transform name=\"to_world\">\n            <scale x=\"-1\"/><lookat",
                )),
            )],
            setup: vec![],
            prepare: None,
            args: "info {d}/s.xml",
            code: 1,
            words: &[
                "s.xml: line 2",
                "<sensor type=\"perspective\">",
                "mirrors the view",
            ],
            check: None,
        },
        Case {
            name: "a parameter given to a TOML scene",
            files: good(),
            setup: vec![],
            prepare: None,
            args: "info {d}/s.toml -D spp=4",
            code: 1,
            words: &["s.toml", "-D spp=...", "Mitsuba 3 XML scenes"],
            check: None,
        },
        Case {
            name: "a parameter given to a command that reads no scene parameters",
            files: good(),
            setup: vec![],
            prepare: None,
            args: "compare {d}/a.exr {d}/b.exr -D spp=4",
            code: 1,
            words: &["-D spp=...", "only info, convert, render"],
            check: None,
        },
        Case {
            name: "convert of a TOML scene",
            files: good(),
            setup: vec![],
            prepare: None,
            args: "convert {d}/s.toml --out {d}/c.toml",
            code: 1,
            words: &["s.toml", "convert reads Mitsuba 3 XML scenes"],
            check: absent("c.toml"),
        },
        // Read approximately or not at all: warnings.
        warned(
            "a parameter photonflow does not read",
            "<shape type=\"cube\"><float name=\"wobble\" value=\"2\"/></shape>",
            &[
                "s.xml: line 20",
                "<float name=\"wobble\">",
                "not read by photonflow",
            ],
        ),
        Case {
            name: "a Gaussian pixel filter",
            files: vec![(
                "s.xml",
                text(xml("").replace("<rfilter type=\"box\"/>", "<rfilter type=\"gaussian\"/>")),
            )],
            setup: vec![],
            prepare: None,
            args: "info {d}/s.xml",
            code: 0,
            words: &[],
            check: warns_in(
                "s.xml",
                &[
                    "s.xml: line 10",
                    "<rfilter type=\"gaussian\">",
                    "drawn with a box",
                ],
            ),
        },
        warned(
            "a Beckmann surface",
            "<shape type=\"cube\"><bsdf type=\"roughconductor\"/></shape>",
            &["s.xml: line 20", "Beckmann", "drawn as GGX"],
        ),
        warned(
            "a one-sided diffuse surface",
            "<shape type=\"cube\"><bsdf type=\"diffuse\"/></shape>",
            &["one-sided in Mitsuba 3", "s.xml line 20"],
        ),
        warned(
            "a disk",
            "<shape type=\"disk\"/>",
            &["disk", "256-sided polygon"],
        ),
    ]
}

#[test]
fn bad_input_table() {
    run_table("xml", cases());
}
