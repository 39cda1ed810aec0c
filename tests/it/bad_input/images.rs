//! Images at fault: EXR files that are not EXR, truncated or a FIFO, references of the wrong
//! size or holding NaN, environment maps missing, unreadable, too small or black.

use super::*;

/// Nothing but empty directories at `rel`.
fn no_files(rel: &'static str) -> Option<Check> {
    Some(Box::new(move |d: &Path| {
        fn files(p: &Path) -> usize {
            std::fs::read_dir(p).map_or(0, |r| {
                r.flatten()
                    .map(|e| match e.file_type() {
                        Ok(t) if t.is_dir() => files(&e.path()),
                        _ => 1,
                    })
                    .sum()
            })
        }
        assert_eq!(files(&d.join(rel)), 0, "{rel} holds files");
    }))
}

fn cases() -> Vec<Case> {
    let mut nan = grey(16, 16);
    nan.data[3] = [f32::NAN, 0.0, 0.0];
    nan.data[7] = [0.0, f32::INFINITY, 0.0];
    nan.data[9] = [0.0, 0.0, f32::NAN];
    vec![
        // EXR files.
        Case {
            name: "compare on bytes that are not EXR",
            files: vec![
                ("a.exr", text("garbage")),
                ("b.exr", Input::Exr(grey(16, 16))),
            ],
            setup: vec![],
            prepare: None,
            args: "compare {d}/a.exr {d}/b.exr",
            code: 1,
            words: &["a.exr", "EXR error"],
            check: None,
        },
        Case {
            name: "a truncated EXR reference",
            files: with(good(), "ref.exr", Input::Exr(grey(16, 16))),
            setup: vec![],
            prepare: Some(|d| {
                let p = d.join("ref.exr");
                let b = std::fs::read(&p).unwrap();
                std::fs::write(&p, &b[..b.len() / 2]).unwrap();
            }),
            args: "render {d}/s.toml --method path --spp 1 --out {d}/out --reference {d}/ref.exr",
            code: 1,
            words: &["ref.exr", "EXR error"],
            check: absent("out"),
        },
        Case {
            name: "an EXR that is a FIFO",
            files: vec![("a.exr", Input::Fifo), ("b.exr", Input::Exr(grey(16, 16)))],
            setup: vec![],
            prepare: None,
            args: "compare {d}/a.exr {d}/b.exr",
            code: 1,
            words: &["a.exr", "not a regular file"],
            check: None,
        },
        Case {
            name: "compare of two sizes",
            files: vec![
                ("a.exr", Input::Exr(grey(16, 16))),
                ("b.exr", Input::Exr(grey(8, 8))),
            ],
            setup: vec![],
            prepare: None,
            args: "compare {d}/a.exr {d}/b.exr",
            code: 1,
            words: &["16x16", "8x8"],
            check: None,
        },
        Case {
            name: "evidence with a reference of the wrong size",
            files: with(good(), "ref.exr", Input::Exr(grey(16, 8))),
            setup: vec![],
            prepare: None,
            args: "evidence {d}/s.toml --quick --reference {d}/ref.exr --out {d}/out",
            code: 1,
            words: &["ref.exr", "reference is 16x8"],
            // evidence makes its (empty) directory before it reads the reference.
            check: no_files("out"),
        },
        // Accepted bad values.
        Case {
            name: "--reference with --method path is used",
            files: with(good(), "ref.exr", Input::Exr(grey(16, 16))),
            setup: vec![],
            prepare: None,
            args: "render {d}/s.toml --method path --spp 1 --out {d}/out --reference {d}/ref.exr",
            code: 0,
            words: &[],
            check: present("out/image.json", "ref.exr"),
        },
        Case {
            name: "compare with NaN and infinity",
            files: vec![
                ("a.exr", Input::Exr(nan)),
                ("b.exr", Input::Exr(grey(16, 16))),
            ],
            setup: vec![],
            prepare: None,
            args: "compare {d}/a.exr {d}/b.exr",
            code: 1,
            words: &["a.exr", "3 of 256 pixels are not finite"],
            check: None,
        },
        light_case(
            "an environment map that is missing",
            "type = \"environment\"\nfilename = \"nope.exr\"",
            vec![],
            &[
                "s.toml: light 0 (environment): environment map `nope.exr`",
                "cannot read it",
            ],
        ),
        light_case(
            "an environment map that is not an image",
            "type = \"environment\"\nfilename = \"env.exr\"",
            vec![("env.exr", text("not an image\n"))],
            &[
                "s.toml: light 0 (environment): environment map `env.exr`",
                "not a PNG, JPEG, TGA, EXR or Radiance HDR image",
            ],
        ),
        light_case(
            "a 1x1 environment map",
            "type = \"environment\"\nfilename = \"env.exr\"",
            vec![("env.exr", Input::Exr(grey(1, 1)))],
            &[
                "s.toml: light 0 (environment): environment map `env.exr`: a 1x1 environment \
                 map is smaller than 2x3 texels",
            ],
        ),
        light_case(
            "a black environment map",
            "type = \"environment\"\nfilename = \"env.exr\"",
            vec![("env.exr", Input::Exr(Image::from_fn(8, 4, |_, _| [0.0; 3])))],
            &[
                "s.toml: light 0 (environment): environment map `env.exr`: the environment map \
                 is black everywhere",
            ],
        ),
        // Partial output.
        Case {
            name: "a missing reference",
            files: good(),
            setup: vec![],
            prepare: None,
            args: "render {d}/s.toml --method path --spp 1 --out {d}/out --reference {d}/none.exr",
            code: 1,
            words: &["none.exr"],
            check: absent("out"),
        },
        Case {
            name: "a reference of the wrong size",
            files: with(good(), "ref.exr", Input::Exr(grey(8, 16))),
            setup: vec![],
            prepare: None,
            args: "render {d}/s.toml --method sppm --photons 2000 --out {d}/out --reference {d}/ref.exr",
            code: 1,
            words: &["ref.exr", "reference is 8x16, the scene renders 16x16"],
            check: absent("out"),
        },
        Case {
            name: "a reference holding NaN",
            files: with(
                good(),
                "ref.exr",
                Input::Exr({
                    let mut i = grey(16, 16);
                    i.data[0] = [f32::NAN; 3];
                    i
                }),
            ),
            setup: vec![],
            prepare: None,
            args: "render {d}/s.toml --method path --spp 1 --out {d}/out --reference {d}/ref.exr",
            code: 1,
            words: &["ref.exr", "1 of 256 reference pixels are not finite"],
            check: absent("out"),
        },
        Case {
            name: "bench accuracy with a reference of the wrong size",
            files: with(
                with(good(), "ref.exr", Input::Exr(grey(16, 8))),
                "ref2.exr",
                Input::Exr(grey(16, 8)),
            ),
            setup: vec![],
            prepare: None,
            args: "bench-accuracy --case {d}/s.toml,{d}/ref.exr,{d}/ref2.exr --budgets 1 --dir {d}/out",
            code: 1,
            words: &["ref.exr", "reference is 16x8"],
            check: absent("out"),
        },
        // A reference's halves that are one image.
        Case {
            name: "compare A B B",
            files: vec![
                ("a.exr", Input::Exr(grey(16, 16))),
                ("b.exr", Input::Exr(grey(16, 16))),
            ],
            setup: vec![],
            prepare: None,
            args: "compare {d}/a.exr {d}/b.exr {d}/b.exr",
            code: 1,
            words: &["b.exr and", "identical", "no noise to take out"],
            check: None,
        },
        Case {
            name: "compare A B C with C a copy of B",
            files: vec![
                ("a.exr", Input::Exr(grey(16, 16))),
                ("b.exr", Input::Exr(grey(16, 16))),
                ("c.exr", Input::Exr(grey(16, 16))),
            ],
            setup: vec![],
            prepare: None,
            args: "compare {d}/a.exr {d}/b.exr {d}/c.exr",
            code: 1,
            words: &["b.exr and", "c.exr", "identical", "no noise to take out"],
            check: None,
        },
    ]
}

#[test]
fn bad_input_table() {
    run_table("images", cases());
}
