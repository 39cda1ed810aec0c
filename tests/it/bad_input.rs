//! Bad input, one table: each case writes its input files into a scratch directory, runs one
//! command line through `photonflow::run_args` (the binary's own entry, in process), and
//! checks the exit code and that the error is one line holding the given words (the file at
//! fault and the problem). Cases that must succeed (valid scenes once refused, `Kd 0.5`) check
//! what they wrote instead. A case that hangs fails after a timeout; one that panics fails
//! with the panic.
//!
//! Each kind of bad-input failure has cases here: panics, hangs, accepted bad values,
//! partial output, messages, valid scenes refused and temporary files (a stale file from a
//! dead process; Ctrl-C itself needs a process: the binary's own test `cli.rs` signals it).
//! Every loader (OBJ, MTL, scene file, photon file, EXR) and every command's flags have cases
//! too (the bench commands only with values refused before any timing starts).

use crate::kit::{TempDir, cli};
use film::Image;
use std::path::Path;
use std::sync::mpsc;
use std::time::Duration;

const CAMERA: &str =
    "[camera]\neye = [0, 1, 3]\nlook_at = [0, 0, 0]\nvfov = 60\nwidth = 16\nheight = 16\n";
const OBJ: &str = "mtllib m.mtl\no floor\nusemtl white\nv -1 0 -1\nv -1 0 1\nv 1 0 1\nv 1 0 -1\n\
f 1 2 3\nf 1 3 4\no light\nusemtl light\nv -0.1 1 -0.1\nv 0.1 1 -0.1\nv 0.1 1 0.1\n\
v -0.1 1 0.1\nf 5 6 7\nf 5 7 8\n";
const MTL: &str = "newmtl white\nKd 0.5 0.5 0.5\nnewmtl light\nKd 0 0 0\nKe 4 4 4\n";

/// One input file of a case.
enum Input {
    Text(String),
    Exr(Image),
    Fifo,
}

/// What a case must leave behind (paths relative to its directory).
type Check = Box<dyn Fn(&Path)>;

struct Case {
    name: &'static str,
    files: Vec<(&'static str, Input)>,
    /// Commands run first, each of which must succeed (`{d}` is the case's directory).
    setup: Vec<&'static str>,
    /// Run after the setup commands: damages what they wrote (a cached photon file, say).
    prepare: Option<fn(&Path)>,
    /// The command line (`{d}` is the case's directory), split on spaces.
    args: &'static str,
    code: u8,
    /// Words the one-line message must hold (empty for a success).
    words: &'static [&'static str],
    check: Option<Check>,
}

fn text(s: impl Into<String>) -> Input {
    Input::Text(s.into())
}

fn scene(extra: &str) -> String {
    format!("{CAMERA}[[mesh]]\nobj = \"a.obj\"\n{extra}")
}

/// The good scene's three files, with `obj` and `mtl` replacing the OBJ and MTL texts.
fn files(toml: String, obj: &str, mtl: &str) -> Vec<(&'static str, Input)> {
    vec![
        ("s.toml", text(toml)),
        ("a.obj", text(obj)),
        ("m.mtl", text(mtl)),
    ]
}

fn good() -> Vec<(&'static str, Input)> {
    files(scene(""), OBJ, MTL)
}

fn with(
    mut f: Vec<(&'static str, Input)>,
    name: &'static str,
    i: Input,
) -> Vec<(&'static str, Input)> {
    f.retain(|(n, _)| *n != name);
    f.push((name, i));
    f
}

fn grey(w: usize, h: usize) -> Image {
    Image::from_fn(w, h, |_, _| [0.5; 3])
}

/// A polygon face of `n` vertices on a unit circle around the floor's centre (x, z), written
/// with 7 decimals; `notch` pulls one vertex to the centre (non-convex).
fn polygon_obj(n: usize, notch: bool) -> String {
    let mut o = String::from(OBJ);
    o += "o disc\nusemtl white\n";
    for i in 0..n {
        let t = std::f64::consts::TAU * i as f64 / n as f64;
        let (x, z) = if notch && i == n / 2 {
            (0.0, 0.0)
        } else {
            (t.cos(), -t.sin())
        };
        o += &format!("v {x:.7} 0.001 {z:.7}\n");
    }
    o += "f";
    for i in 0..n {
        o += &format!(" {}", i + 9);
    }
    o + "\n"
}

/// A polygon face of `n` vertices (a multiple of 4) along the edges of a square around the
/// floor's centre, `n / 4` per edge from its corner: between four corners, runs of collinear
/// vertices (the sides are x or z = +-0.5 exactly).
fn square_edges_obj(n: usize) -> String {
    let q = n / 4;
    let mut o = String::from(OBJ);
    o += "o square\nusemtl white\n";
    let t = |i: usize| -0.5 + i as f64 / q as f64;
    for side in 0..4 {
        for i in 0..q {
            let (x, z) = match side {
                0 => (t(i), 0.5),
                1 => (0.5, -t(i)),
                2 => (-t(i), -0.5),
                _ => (-0.5, t(i)),
            };
            o += &format!("v {x:.7} 0.001 {z:.7}\n");
        }
    }
    o += "f";
    for i in 0..4 * q {
        o += &format!(" {}", i + 9);
    }
    o + "\n"
}

/// The case's `s.toml` loads into `n` triangles: the work its loader did.
fn triangles(n: usize) -> Option<Check> {
    Some(Box::new(move |d: &Path| {
        let s = scene::Scene::load(d.join("s.toml")).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(s.geometry.mesh().len(), n, "triangles of s.toml");
    }))
}

/// `rel` (a text file) with `from` replaced by `to`, which must occur in it.
fn edit(d: &Path, rel: &str, from: &str, to: &str) {
    let p = d.join(rel);
    let t = std::fs::read_to_string(&p).unwrap();
    assert!(t.contains(from), "{rel} lacks `{from}`: {t}");
    std::fs::write(&p, t.replace(from, to)).unwrap();
}

fn absent(rel: &'static str) -> Option<Check> {
    Some(Box::new(move |d: &Path| {
        assert!(!d.join(rel).exists(), "{rel} was written");
    }))
}

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

fn present(rel: &'static str, holds: &'static str) -> Option<Check> {
    Some(Box::new(move |d: &Path| {
        let t = std::fs::read_to_string(d.join(rel)).unwrap_or_else(|e| panic!("{rel}: {e}"));
        assert!(t.contains(holds), "{rel} does not hold `{holds}`: {t}");
    }))
}

/// The one photon file of the case's cache, replaced by what `f` makes of its bytes (or a
/// FIFO for `None`).
fn damage_photons(d: &Path, f: impl Fn(Vec<u8>) -> Option<Vec<u8>>) {
    let file = std::fs::read_dir(d.join("cache"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .find(|p| p.extension().is_some_and(|x| x == "photons"))
        .expect("a traced photon file");
    let bytes = std::fs::read(&file).unwrap();
    std::fs::remove_file(&file).unwrap();
    match f(bytes) {
        Some(b) => std::fs::write(&file, b).unwrap(),
        None => {
            let made = std::process::Command::new("mkfifo").arg(&file).status();
            assert!(made.is_ok_and(|s| s.success()));
        }
    }
}

/// A case whose scene adds one `[[light]]` (`light`, TOML) beside `extra` files, refused at
/// loading with `words`; the render writes nothing.
fn light_case(
    name: &'static str,
    light: &str,
    extra: Vec<(&'static str, Input)>,
    words: &'static [&'static str],
) -> Case {
    let mut f = files(scene(&format!("[[light]]\n{light}\n")), OBJ, MTL);
    f.extend(extra);
    Case {
        name,
        files: f,
        setup: vec![],
        prepare: None,
        args: "render {d}/s.toml --method path --spp 1 --threads 1 --out {d}/out",
        code: 1,
        words,
        check: absent("out"),
    }
}

fn cases() -> Vec<Case> {
    let global = |extra: &str| scene(&format!("[estimate.global]\n{extra}\n"));
    let mut nan = grey(16, 16);
    nan.data[3] = [f32::NAN, 0.0, 0.0];
    nan.data[7] = [0.0, f32::INFINITY, 0.0];
    nan.data[9] = [0.0, 0.0, f32::NAN];
    let black = MTL.replace("Kd 0.5 0.5 0.5", "Kd 0 0 0");
    let mirror = MTL.replace("Kd 0.5 0.5 0.5", "illum 3\nKs 0.9 0.9 0.9");
    vec![
        // The photon file (a traced cache, then damaged): estimate names the file.
        Case {
            name: "a photon file with a flipped header byte",
            files: good(),
            setup: vec!["trace {d}/s.toml --photons 2000 --cache {d}/cache"],
            prepare: Some(|d| {
                damage_photons(d, |mut b| {
                    b[40] ^= 0xff;
                    Some(b)
                })
            }),
            args: "estimate {d}/s.toml --photons 2000 --cache {d}/cache --out {d}/out",
            code: 1,
            words: &["-global.photons", "checksum mismatch in the header"],
            check: absent("out"),
        },
        Case {
            name: "a truncated photon file",
            files: good(),
            setup: vec!["trace {d}/s.toml --photons 2000 --cache {d}/cache"],
            prepare: Some(|d| damage_photons(d, |b| Some(b[..100].to_vec()))),
            args: "estimate {d}/s.toml --photons 2000 --cache {d}/cache --out {d}/out",
            code: 1,
            words: &["-global.photons", "truncated"],
            check: absent("out"),
        },
        Case {
            name: "a photon file of foreign bytes",
            files: good(),
            setup: vec!["trace {d}/s.toml --photons 2000 --cache {d}/cache"],
            prepare: Some(|d| damage_photons(d, |_| Some(b"not photons at all".to_vec()))),
            args: "estimate {d}/s.toml --photons 2000 --cache {d}/cache --out {d}/out",
            code: 1,
            words: &["-global.photons", "not a photon file"],
            check: absent("out"),
        },
        Case {
            name: "a photon file that is a FIFO",
            files: good(),
            setup: vec!["trace {d}/s.toml --photons 2000 --cache {d}/cache"],
            prepare: Some(|d| damage_photons(d, |_| None)),
            args: "estimate {d}/s.toml --photons 2000 --cache {d}/cache --out {d}/out",
            code: 1,
            words: &["-global.photons", "not a regular file"],
            check: absent("out"),
        },
        Case {
            name: "estimate without a traced cache",
            files: good(),
            setup: vec![],
            prepare: None,
            args: "estimate {d}/s.toml --photons 2000 --cache {d}/cache --out {d}/out",
            code: 1,
            words: &["-global.photons", "run `trace` first"],
            check: absent("out"),
        },
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
        // Coloured and absorbing glass: the scene file's keys and MTL `Tf`.
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
        Case {
            name: "MTL Tf out of range on glass",
            files: files(
                scene(""),
                OBJ,
                &MTL.replace(
                    "Kd 0.5 0.5 0.5",
                    "Kd 0.5 0.5 0.5\nnewmtl glass\nillum 7\nNi 1.5\nTf 1.5 0.5 0.5",
                ),
            ),
            setup: vec![],
            prepare: None,
            args: "info {d}/s.toml",
            code: 1,
            words: &["m.mtl", "material `glass`", "`Tf 1.5 0.5 0.5`", "[0, 1]"],
            check: None,
        },
        Case {
            name: "MTL Tf on glass is coloured glass",
            files: files(
                scene(""),
                OBJ,
                &MTL.replace(
                    "Kd 0.5 0.5 0.5",
                    "Kd 0.5 0.5 0.5\nnewmtl glass\nillum 7\nNi 1.5\nTf 0.9 0.5 0.2",
                ),
            ),
            setup: vec![],
            prepare: None,
            args: "info {d}/s.toml",
            code: 0,
            words: &[],
            check: None,
        },
        // Every command's flags.
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
        Case {
            name: "trace --photons 0",
            files: good(),
            setup: vec![],
            prepare: None,
            args: "trace {d}/s.toml --photons 0 --cache {d}/cache",
            code: 1,
            words: &["error: --photons 0: must be in 1..=2^40"],
            check: absent("cache"),
        },
        Case {
            name: "render --k 0",
            files: good(),
            setup: vec![],
            prepare: None,
            args: "render {d}/s.toml --method global-direct --k 0 --cache {d}/cache --out {d}/out",
            code: 1,
            words: &["error: --k 0: must be in 1..=1048576"],
            check: absent("out"),
        },
        Case {
            name: "render --topo 2",
            files: good(),
            setup: vec![],
            prepare: None,
            args: "render {d}/s.toml --method global-direct --topo 2 --cache {d}/cache --out {d}/out",
            code: 1,
            words: &["error: --topo 2: must be in (0, 1]"],
            check: absent("out"),
        },
        Case {
            name: "render --kernel of no name",
            files: good(),
            setup: vec![],
            prepare: None,
            args: "render {d}/s.toml --kernel nope --out {d}/out",
            code: 2,
            words: &["--kernel", "unknown kernel `nope`"],
            check: absent("out"),
        },
        Case {
            name: "render --method of no name",
            files: good(),
            setup: vec![],
            prepare: None,
            args: "render {d}/s.toml --method nope --out {d}/out",
            code: 2,
            words: &["--method", "unknown method `nope`"],
            check: absent("out"),
        },
        Case {
            name: "render --time -1",
            files: good(),
            setup: vec![],
            prepare: None,
            args: "render {d}/s.toml --method sppm --time=-1 --out {d}/out",
            code: 1,
            words: &["--time -1 must be a positive number of seconds"],
            check: absent("out"),
        },
        Case {
            name: "render --passes 0",
            files: good(),
            setup: vec![],
            prepare: None,
            args: "render {d}/s.toml --method sppm --passes 0 --out {d}/out",
            code: 1,
            words: &["error: --passes 0: must be in 1..=1048576"],
            check: absent("out"),
        },
        Case {
            name: "render --gather-rays absurd",
            files: good(),
            setup: vec![],
            prepare: None,
            args: "render {d}/s.toml --method final-gather --gather-rays 100000000 --out {d}/out",
            code: 1,
            words: &["error: --gather-rays 100000000: is absurd (at most 65536)"],
            check: absent("out"),
        },
        Case {
            name: "render --spp 0",
            files: good(),
            setup: vec![],
            prepare: None,
            args: "render {d}/s.toml --method path --spp 0 --out {d}/out",
            code: 1,
            words: &["error: --spp 0: must be in 1..=16777216"],
            check: absent("out"),
        },
        Case {
            name: "estimate --method path",
            files: good(),
            setup: vec![],
            prepare: None,
            args: "estimate {d}/s.toml --method path --cache {d}/cache --out {d}/out",
            code: 1,
            words: &["estimate reads photon maps", "render --method path"],
            check: absent("out"),
        },
        Case {
            name: "composite of a directory that is no run",
            files: good(),
            setup: vec![],
            prepare: None,
            args: "composite {d} --out {d}/out",
            code: 1,
            words: &["image.json", "cannot read"],
            check: absent("out"),
        },
        Case {
            name: "worksheet --topo nan",
            files: good(),
            setup: vec![],
            prepare: None,
            args: "worksheet --scene {d}/s.toml --topo nan --reference-spp 1 --out {d}/out --cache {d}/cache",
            code: 1,
            words: &["error: --topo NaN: must be in (0, 1]"],
            check: absent("out"),
        },
        Case {
            name: "worksheet --k 0",
            files: good(),
            setup: vec![],
            prepare: None,
            args: "worksheet --scene {d}/s.toml --k 0 --reference-spp 1 --out {d}/out --cache {d}/cache",
            code: 1,
            words: &["error: --k 0: must be in 1..=1048576"],
            check: absent("out"),
        },
        Case {
            name: "evidence --seeds 1",
            files: good(),
            setup: vec![],
            prepare: None,
            args: "evidence {d}/s.toml --seeds 1 --out {d}/out",
            code: 1,
            words: &["--seeds 1 must be at least 2"],
            check: absent("out"),
        },
        Case {
            name: "evidence --only of no technique",
            files: good(),
            setup: vec![],
            prepare: None,
            args: "evidence {d}/s.toml --quick --only bogus --reference-spp 1 --out {d}/out",
            code: 1,
            words: &["--only bogus", "no such technique"],
            // Refused before the reference is rendered: nothing written.
            check: absent("out"),
        },
        Case {
            name: "evidence --reference-spp 0",
            files: good(),
            setup: vec![],
            prepare: None,
            args: "evidence {d}/s.toml --quick --reference-spp 0 --out {d}/out",
            code: 1,
            words: &["--reference-spp 0"],
            check: absent("out"),
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
        Case {
            name: "bench-accuracy --peer neither built in nor with a command",
            files: good(),
            setup: vec![],
            prepare: None,
            args: "bench-accuracy --case {d}/s.toml,{d}/a.exr,{d}/b.exr --peer bad --dir {d}/out",
            code: 2,
            words: &["--peer", "not a built-in peer", "NAME=COMMAND"],
            check: absent("out"),
        },
        // Panics.
        Case {
            name: "MTL colour of one number is grey",
            files: with(
                good(),
                "m.mtl",
                text(MTL.replace("Kd 0.5 0.5 0.5", "Kd 0.5")),
            ),
            setup: vec![],
            prepare: None,
            args: "info {d}/s.toml",
            code: 0,
            words: &[],
            check: None,
        },
        Case {
            name: "MTL colour of two numbers",
            files: with(
                good(),
                "m.mtl",
                text(MTL.replace("Kd 0.5 0.5 0.5", "Kd 0.5 0.5")),
            ),
            setup: vec![],
            prepare: None,
            args: "info {d}/s.toml",
            code: 1,
            words: &[
                "m.mtl",
                "line 2",
                "`Kd` needs one number (grey) or three",
                "s.toml",
            ],
            check: None,
        },
        Case {
            name: "a mesh scaled to 1e19",
            files: with(
                files(scene("[[mesh]]\nobj = \"b.obj\"\nscale = 1e19\n"), OBJ, MTL),
                "b.obj",
                text("mtllib m.mtl\no big\nusemtl white\nv -1 0 -1\nv -1 0 1\nv 1 0 1\nf 1 2 3\n"),
            ),
            setup: vec![],
            prepare: None,
            args: "info {d}/s.toml",
            code: 1,
            words: &[
                "b.obj",
                "beyond the 1e15 scene units",
                "mesh 1 of",
                "s.toml",
            ],
            check: None,
        },
        // Hangs.
        Case {
            name: "a convex face of 200k vertices",
            files: with(good(), "a.obj", text(polygon_obj(200_000, false))),
            setup: vec![],
            prepare: None,
            args: "info {d}/s.toml",
            code: 0,
            words: &[],
            check: None,
        },
        Case {
            name: "a non-convex face of 200k vertices",
            files: with(good(), "a.obj", text(polygon_obj(200_000, true))),
            setup: vec![],
            prepare: None,
            args: "info {d}/s.toml",
            code: 1,
            words: &[
                "a.obj",
                "object `disc`, face 1",
                "non-convex face of 200000",
                "s.toml",
            ],
            check: None,
        },
        Case {
            name: "a mesh that is a FIFO",
            files: with(good(), "a.obj", Input::Fifo),
            setup: vec![],
            prepare: None,
            args: "info {d}/s.toml",
            code: 1,
            words: &["a.obj", "not a regular file", "s.toml"],
            check: None,
        },
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
            name: "photon files that could never fit",
            files: good(),
            setup: vec![],
            prepare: None,
            args: "trace {d}/s.toml --photons 1000000000000 --cache {d}/cache",
            code: 1,
            words: &[
                "s.toml",
                "1000000000000 photon paths would write",
                "bytes free",
                "at most about",
            ],
            check: absent("cache/plan.txt"),
        },
        Case {
            name: "a face of 400k vertices along a square's edges",
            files: with(good(), "a.obj", text(square_edges_obj(400_000))),
            setup: vec![],
            prepare: None,
            args: "info {d}/s.toml",
            code: 0,
            words: &[],
            // The floor's and the light's 4, and the square's 2: its vertices inside straight
            // edges are no corners (400k - 2 triangles, most of no area, took minutes).
            check: triangles(6),
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
            name: "sppm --photons per pass beyond what one pass can map",
            files: good(),
            setup: vec![],
            prepare: None,
            args: "render {d}/s.toml --method sppm --photons 1000000000000 --passes 1 --threads 1 --out {d}/out",
            code: 1,
            words: &[
                "error: --photons 1000000000000: is sppm's pass size",
                "must be at most 4294967294",
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
            name: "NaN exposure",
            files: good(),
            setup: vec![],
            prepare: None,
            args: "render {d}/s.toml --method path --spp 1 --out {d}/out --exposure NaN",
            code: 2,
            words: &["--exposure", "NaN is not a finite number"],
            check: absent("out"),
        },
        Case {
            name: "infinite exposure of composite",
            files: good(),
            setup: vec!["render {d}/s.toml --method path --spp 1 --out {d}/run"],
            prepare: None,
            args: "composite {d}/run --out {d}/out --exposure inf",
            code: 2,
            words: &["--exposure", "inf is not a finite number"],
            check: absent("out"),
        },
        Case {
            name: "--threads 0 when the cache answers",
            files: good(),
            setup: vec!["trace {d}/s.toml --photons 2000 --cache {d}/cache"],
            prepare: None,
            args: "trace {d}/s.toml --photons 2000 --cache {d}/cache --threads 0",
            code: 2,
            words: &["--threads", "must be at least 1"],
            check: None,
        },
        Case {
            name: "--threads 0 of estimate",
            files: good(),
            setup: vec!["trace {d}/s.toml --photons 2000 --cache {d}/cache"],
            prepare: None,
            args: "estimate {d}/s.toml --photons 2000 --cache {d}/cache --out {d}/out --threads 0",
            code: 2,
            words: &["--threads", "must be at least 1"],
            check: absent("out"),
        },
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
        Case {
            name: "compare with a mask outside the image",
            files: vec![
                ("a.exr", Input::Exr(grey(16, 16))),
                ("b.exr", Input::Exr(grey(16, 16))),
            ],
            setup: vec![],
            prepare: None,
            args: "compare {d}/a.exr {d}/b.exr --mask 0,0,40,8",
            code: 1,
            words: &["a.exr", "--mask 0,0,40,8", "16x16"],
            check: None,
        },
        Case {
            name: "a mask of the wrong shape",
            files: vec![],
            setup: vec![],
            prepare: None,
            args: "compare {d}/a.exr {d}/b.exr --mask 1,2",
            code: 2,
            words: &["--mask", "expected x0,y0,x1,y1"],
            check: None,
        },
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
        Case {
            name: "render --gather-rays 0",
            files: good(),
            setup: vec![],
            prepare: None,
            args: "render {d}/s.toml --method final-gather --gather-rays 0 --photons 2000 --threads 1 --cache {d}/cache --out {d}/out",
            code: 1,
            words: &["error: --gather-rays 0: must be at least 1"],
            check: absent("out"),
        },
        Case {
            name: "composite of a run counting 1e300 samples",
            files: good(),
            setup: vec!["render {d}/s.toml --method path --spp 1 --threads 1 --out {d}/run"],
            prepare: Some(|d| edit(d, "run/image.json", "\"count\": 1,", "\"count\": 1e300,")),
            args: "composite {d}/run --out {d}/out",
            code: 1,
            words: &["image.json", "count 1e300 exceeds 2^53"],
            check: absent("out"),
        },
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
        // Messages.
        Case {
            name: "an empty OBJ",
            files: with(good(), "a.obj", text("")),
            setup: vec![],
            prepare: None,
            args: "info {d}/s.toml",
            code: 1,
            words: &["a.obj", "the OBJ file is empty", "s.toml"],
            check: None,
        },
        Case {
            name: "an OBJ without mtllib",
            files: with(good(), "a.obj", text(OBJ.replace("mtllib m.mtl\n", ""))),
            setup: vec![],
            prepare: None,
            args: "info {d}/s.toml",
            code: 1,
            words: &[
                "a.obj",
                "`usemtl white` (line 2)",
                "no `mtllib` line",
                "s.toml",
            ],
            check: None,
        },
        Case {
            name: "usemtl of an unknown material",
            files: with(
                good(),
                "a.obj",
                text(OBJ.replace("usemtl light", "usemtl lamp")),
            ),
            setup: vec![],
            prepare: None,
            args: "info {d}/s.toml",
            code: 1,
            words: &[
                "a.obj",
                "`usemtl lamp` (line 11): unknown material",
                "m.mtl defines `white`, `light`",
                "s.toml",
            ],
            check: None,
        },
        Case {
            name: "faces before any usemtl",
            files: with(good(), "a.obj", text(OBJ.replace("usemtl white\n", ""))),
            setup: vec![],
            prepare: None,
            args: "info {d}/s.toml",
            code: 1,
            words: &[
                "a.obj",
                "object `floor` has faces before any `usemtl` line",
                "s.toml",
            ],
            check: None,
        },
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
        Case {
            name: "an unknown flag spans one line",
            files: vec![],
            setup: vec![],
            prepare: None,
            args: "render {d}/s.toml --bogus",
            code: 2,
            words: &["--bogus", "(see --help)"],
            check: None,
        },
        // A flag's value is named as the flag; the file's keys one at a time.
        Case {
            name: "render --passes 0 of caustic-splat",
            files: good(),
            setup: vec![],
            prepare: None,
            args: "render {d}/s.toml --method caustic-splat --passes 0 --out {d}/out",
            code: 1,
            words: &["error: --passes 0: must be in 1..=1048576"],
            check: absent("out"),
        },
        Case {
            name: "render --passes 0 of path",
            files: good(),
            setup: vec![],
            prepare: None,
            args: "render {d}/s.toml --method path --passes 0 --out {d}/out",
            code: 1,
            words: &["error: --passes 0: must be in 1..=16777216"],
            check: absent("out"),
        },
        Case {
            name: "render --spp 0 of final-gather",
            files: good(),
            setup: vec![],
            prepare: None,
            args: "render {d}/s.toml --method final-gather --spp 0 --out {d}/out",
            code: 1,
            words: &["error: --spp 0: must be in 1..=1048576"],
            check: absent("out"),
        },
        Case {
            name: "render --photons 0",
            files: good(),
            setup: vec![],
            prepare: None,
            args: "render {d}/s.toml --method global-direct --photons 0 --cache {d}/cache --out {d}/out",
            code: 1,
            words: &["error: --photons 0: must be in 1..=2^40"],
            check: absent("out"),
        },
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
        // Valid scenes refused.
        Case {
            name: "all surfaces black, final gathering",
            files: files(scene(""), OBJ, &black),
            setup: vec![],
            prepare: None,
            args: "render {d}/s.toml --method final-gather --photons 2000 --cache {d}/cache --out {d}/out",
            code: 0,
            words: &[],
            check: present("out/plan.txt", "no surface is diffuse"),
        },
        Case {
            name: "only mirrors, final gathering",
            files: files(scene(""), OBJ, &mirror),
            setup: vec![],
            prepare: None,
            args: "render {d}/s.toml --method final-gather --photons 2000 --cache {d}/cache --out {d}/out",
            code: 0,
            words: &[],
            check: present(
                "out/plan.txt",
                "only emitters, seen directly or through specular",
            ),
        },
        Case {
            name: "only mirrors, sppm",
            files: files(scene(""), OBJ, &mirror),
            setup: vec![],
            prepare: None,
            args: "render {d}/s.toml --method sppm --photons 2000 --out {d}/out",
            code: 0,
            words: &[],
            check: present("out/plan.txt", "no surface is diffuse"),
        },
        // Shards and merge: a bad set is refused naming the file, nothing written.
        Case {
            name: "merge: a shard missing",
            files: good(),
            setup: vec![
                "trace {d}/s.toml --photons 2000 --shard 0/3 --out {d}/a0",
                "trace {d}/s.toml --photons 2000 --shard 2/3 --out {d}/a2",
            ],
            prepare: None,
            args: "merge {d}/a2 {d}/a0 --out {d}/m",
            code: 1,
            words: &["a2/shard.json", "missing", "1/3"],
            check: absent("m"),
        },
        Case {
            name: "merge: the last shard missing",
            files: good(),
            setup: vec!["render {d}/s.toml --method path --spp 8 --shard 0/2 --out {d}/a0"],
            prepare: None,
            args: "merge {d}/a0 --out {d}/m",
            code: 1,
            words: &["a0/shard.json", "missing", "1/2"],
            check: absent("m"),
        },
        Case {
            name: "merge: a shard given twice",
            files: good(),
            setup: vec![
                "trace {d}/s.toml --photons 2000 --shard 0/2 --out {d}/a0",
                "trace {d}/s.toml --photons 2000 --shard 0/2 --out {d}/b0",
                "trace {d}/s.toml --photons 2000 --shard 1/2 --out {d}/a1",
            ],
            prepare: None,
            args: "merge {d}/a0 {d}/a1 {d}/b0 --out {d}/m",
            code: 1,
            words: &["b0/shard.json", "duplicates", "a0/shard.json"],
            check: absent("m"),
        },
        Case {
            name: "merge: overlapping shards of two sets",
            files: good(),
            setup: vec![
                "trace {d}/s.toml --photons 2000 --shard 0/2 --out {d}/a0",
                "trace {d}/s.toml --photons 2000 --shard 1/3 --out {d}/b1",
                "trace {d}/s.toml --photons 2000 --shard 2/3 --out {d}/b2",
            ],
            prepare: None,
            args: "merge {d}/a0 {d}/b1 {d}/b2 --out {d}/m",
            code: 1,
            words: &["b1/shard.json", "overlaps", "a0/shard.json"],
            check: absent("m"),
        },
        Case {
            name: "merge: shards of another seed",
            files: good(),
            setup: vec![
                "trace {d}/s.toml --photons 2000 --shard 0/2 --out {d}/a0",
                "trace {d}/s.toml --photons 2000 --seed 7 --shard 1/2 --out {d}/a1",
            ],
            prepare: None,
            args: "merge {d}/a0 {d}/a1 --out {d}/m",
            code: 1,
            words: &["a1/shard.json", "seed 7"],
            check: absent("m"),
        },
        Case {
            name: "merge: shards of another scene",
            files: with(
                with(good(), "t.toml", text(scene("").replace("a.obj", "b.obj"))),
                "b.obj",
                text(OBJ.replace("v 1 0 1", "v 1 0 1.5")),
            ),
            setup: vec![
                "trace {d}/s.toml --photons 2000 --shard 0/2 --out {d}/a0",
                "trace {d}/t.toml --photons 2000 --shard 1/2 --out {d}/a1",
            ],
            prepare: None,
            args: "merge {d}/a0 {d}/a1 --out {d}/m",
            code: 1,
            words: &["a1/shard.json", "scene hash"],
            check: absent("m"),
        },
        Case {
            name: "merge: image shards of another parameter set",
            files: good(),
            setup: vec![
                "render {d}/s.toml --method path --spp 8 --shard 0/2 --out {d}/a0",
                "render {d}/s.toml --method path --spp 8 --no-caustics --shard 1/2 --out {d}/a1",
            ],
            prepare: None,
            args: "merge {d}/a0 {d}/a1 --out {d}/m",
            code: 1,
            words: &["a1/shard.json", "parameter hash"],
            check: absent("m"),
        },
        Case {
            name: "merge: photon shards with an image shard",
            files: good(),
            setup: vec![
                "trace {d}/s.toml --photons 2000 --shard 0/2 --out {d}/a0",
                "render {d}/s.toml --method path --spp 8 --shard 1/2 --out {d}/a1",
            ],
            prepare: None,
            args: "merge {d}/a0 {d}/a1 --out {d}/m",
            code: 1,
            words: &["a1/shard.json", "holds image"],
            check: absent("m"),
        },
        Case {
            name: "merge: an unfinished shard (no shard.json)",
            files: with(good(), "a1/global.photons", text("partial")),
            setup: vec!["trace {d}/s.toml --photons 2000 --shard 0/2 --out {d}/a0"],
            prepare: None,
            args: "merge {d}/a0 {d}/a1 --out {d}/m",
            code: 1,
            words: &["a1/shard.json", "not a complete shard"],
            check: absent("m"),
        },
        Case {
            name: "merge: a damaged photon shard",
            files: good(),
            setup: vec![
                "trace {d}/s.toml --photons 2000 --shard 0/2 --out {d}/a0",
                "trace {d}/s.toml --photons 2000 --shard 1/2 --out {d}/a1",
            ],
            prepare: Some(|d| {
                let p = d.join("a1/global.photons");
                let mut b = std::fs::read(&p).unwrap();
                let n = b.len();
                b[n - 5] ^= 0x10;
                std::fs::write(&p, b).unwrap();
            }),
            args: "merge {d}/a0 {d}/a1 --out {d}/m",
            code: 1,
            words: &["a1/global.photons", "checksum"],
            check: absent("m"),
        },
        Case {
            name: "merge: a damaged image shard",
            files: good(),
            setup: vec!["render {d}/s.toml --method path --spp 8 --shard 0/1 --out {d}/a0"],
            prepare: Some(|d| {
                let p = d.join("a0/sums.f64");
                let mut b = std::fs::read(&p).unwrap();
                b[100] ^= 0x01;
                std::fs::write(&p, b).unwrap();
            }),
            args: "merge {d}/a0 --out {d}/m",
            code: 1,
            words: &["a0/sums.f64", "checksum"],
            check: absent("m"),
        },
        Case {
            name: "merge: a shard file whose range is not its shard's",
            files: good(),
            setup: vec!["trace {d}/s.toml --photons 2000 --shard 0/1 --out {d}/a0"],
            prepare: Some(|d| {
                let p = d.join("a0/shard.json");
                let t = std::fs::read_to_string(&p).unwrap();
                std::fs::write(&p, t.replace("\"shard\": \"0/1\"", "\"shard\": \"0/2\"")).unwrap();
            }),
            args: "merge {d}/a0 --out {d}/m",
            code: 1,
            words: &["a0/shard.json", "should cover"],
            check: absent("m"),
        },
        Case {
            name: "--shard I/N with I = N",
            files: good(),
            setup: vec![],
            prepare: None,
            args: "trace {d}/s.toml --photons 2000 --shard 3/3",
            code: 2,
            words: &["--shard", "0 <= I < N"],
            check: None,
        },
        Case {
            name: "render --shard of sppm",
            files: good(),
            setup: vec![],
            prepare: None,
            args: "render {d}/s.toml --method sppm --photons 2000 --shard 0/2 --out {d}/a0",
            code: 1,
            words: &["sppm", "depend on each other"],
            check: absent("a0"),
        },
        Case {
            name: "render --shard with a time budget",
            files: good(),
            setup: vec![],
            prepare: None,
            args: "render {d}/s.toml --method path --time 1 --shard 0/2 --out {d}/a0",
            code: 1,
            words: &["--shard", "--time"],
            check: absent("a0"),
        },
        Case {
            name: "trace --shard N of more shards than photon paths",
            files: good(),
            setup: vec![],
            prepare: None,
            args: "trace {d}/s.toml --photons 2000 --threads 1 --shard 0/4294967295 --out {d}/sh",
            code: 1,
            words: &[
                "--shard 0/4294967295",
                "a run of 2000 photon paths",
                "N must be at most 2000",
            ],
            check: absent("sh"),
        },
        Case {
            name: "render --shard N of more shards than blocks",
            files: good(),
            setup: vec![],
            prepare: None,
            args: "render {d}/s.toml --method path --spp 2 --threads 1 --shard 0/1000 --out {d}/sh",
            code: 1,
            words: &[
                "--shard 0/1000",
                "the run has 2 blocks (2 samples per pixel)",
                "N must be at most 2",
            ],
            check: absent("sh"),
        },
        Case {
            name: "render --shard N that leaves a shard of uneven blocks empty",
            files: good(),
            setup: vec![],
            // 32 samples in passes of 1, 1, 2 and seven of 4: no pass starts in 9..12, the
            // samples of shard 3 of 10.
            prepare: None,
            args: "render {d}/s.toml --method path --spp 32 --threads 1 --shard 0/10 --out {d}/sh",
            code: 1,
            words: &[
                "--shard 0/10",
                "leave shard 3/10 without one",
                "N must be at most 8",
            ],
            check: absent("sh"),
        },
        Case {
            name: "merge: an image shard with a forged count",
            files: good(),
            setup: vec![
                "render {d}/s.toml --method path --spp 2 --threads 1 --shard 0/1 --out {d}/a0",
            ],
            prepare: Some(|d| edit(d, "a0/shard.json", "\"count\": 2,", "\"count\": 99,")),
            args: "merge {d}/a0 --out {d}/m",
            code: 1,
            words: &[
                "a0/shard.json",
                "count 99, but its blocks 0..2 hold 2 samples per pixel",
            ],
            check: absent("m"),
        },
        Case {
            name: "merge: a NaN in an image shard's sums, checksum resealed",
            files: good(),
            setup: vec![
                "render {d}/s.toml --method path --spp 2 --threads 1 --shard 0/1 --out {d}/a0",
            ],
            prepare: Some(|d| {
                let p = d.join("a0/sums.f64");
                let mut s = film::read_sums(&p).unwrap();
                s.planes[1][21][2] = f64::NAN;
                film::write_sums(&p, &s).unwrap();
            }),
            args: "merge {d}/a0 --out {d}/m",
            code: 1,
            words: &["a0/sums.f64", "plane 1", "pixel (5, 1) holds [", "NaN]"],
            check: absent("m"),
        },
        Case {
            name: "merge --out inside an input shard",
            files: good(),
            setup: vec![
                "trace {d}/s.toml --photons 2000 --threads 1 --shard 0/2 --out {d}/sh/0",
                "trace {d}/s.toml --photons 2000 --threads 1 --shard 1/2 --out {d}/sh/1",
            ],
            prepare: None,
            args: "merge {d}/sh/0 {d}/sh/1 --out {d}/sh/0/merged",
            code: 1,
            words: &[
                "sh/0/merged: the output directory lies inside the input shard",
                "sh/0",
            ],
            check: absent("sh/0/merged"),
        },
        Case {
            name: "merge --out holding the input shards",
            files: good(),
            setup: vec![
                "render {d}/s.toml --method path --spp 2 --threads 1 --shard 0/2 --out {d}/sh/0",
                "render {d}/s.toml --method path --spp 2 --threads 1 --shard 1/2 --out {d}/sh/1",
            ],
            prepare: None,
            args: "merge {d}/sh/0 {d}/sh/1 --out {d}/sh",
            code: 1,
            words: &["sh: the output directory contains the input shard", "sh/0"],
            check: absent("sh/image.json"),
        },
        Case {
            name: "merge: a photon shard with a forged count",
            files: good(),
            setup: vec![
                "trace {d}/s.toml --photons 2000 --threads 1 --shard 0/2 --out {d}/sh/0",
                "trace {d}/s.toml --photons 2000 --threads 1 --shard 1/2 --out {d}/sh/1",
            ],
            prepare: Some(|d| edit(d, "sh/1/shard.json", "\"count\": 1000,", "\"count\": 999,")),
            args: "merge {d}/sh/0 {d}/sh/1 --out {d}/m",
            code: 1,
            words: &[
                "sh/1/shard.json",
                "count 999, but its range 1000..2000 holds 1000 photon paths",
            ],
            check: absent("m"),
        },
        // Temporary files.
        Case {
            name: "a stale temp file of a dead process",
            files: with(good(), "cache/.x.photons.tmp-999999999-0", text("partial")),
            setup: vec![],
            prepare: None,
            args: "trace {d}/s.toml --photons 2000 --cache {d}/cache",
            code: 0,
            words: &[],
            check: absent("cache/.x.photons.tmp-999999999-0"),
        },
        Case {
            name: "merge: a stale temp file of a dead process in --out",
            files: with(good(), "m/.x.photons.tmp-999999999-0", text("partial")),
            setup: vec![
                "trace {d}/s.toml --photons 2000 --shard 0/2 --out {d}/a0",
                "trace {d}/s.toml --photons 2000 --shard 1/2 --out {d}/a1",
            ],
            prepare: None,
            args: "merge {d}/a0 {d}/a1 --out {d}/m",
            code: 0,
            words: &[],
            check: absent("m/.x.photons.tmp-999999999-0"),
        },
    ]
}

/// Runs `args` in process on a thread; `None` if it did not return within the timeout.
fn run(args: &str, dir: &Path) -> Option<std::thread::Result<(u8, Option<String>)>> {
    let argv: Vec<String> = args
        .split(' ')
        .map(|a| a.replace("{d}", &dir.display().to_string()))
        .collect();
    let (tx, rx) = mpsc::channel();
    std::thread::spawn(move || {
        let r = std::panic::catch_unwind(|| cli(argv));
        let _ = tx.send(r);
    });
    rx.recv_timeout(Duration::from_secs(120)).ok()
}

#[test]
fn bad_input_table() {
    let tmp = TempDir::new("bad-input");
    let mut failures = Vec::new();
    let cases = cases();
    let n = cases.len();
    for (i, case) in cases.into_iter().enumerate() {
        let dir = tmp.path().join(format!("case-{i:02}"));
        std::fs::create_dir_all(&dir).unwrap();
        for (name, input) in &case.files {
            let p = dir.join(name);
            if let Some(parent) = p.parent() {
                std::fs::create_dir_all(parent).unwrap();
            }
            match input {
                Input::Text(t) => std::fs::write(&p, t).unwrap(),
                Input::Exr(img) => film::write_exr(&p, img).unwrap(),
                Input::Fifo => {
                    let made = std::process::Command::new("mkfifo").arg(&p).status();
                    assert!(made.is_ok_and(|s| s.success()), "mkfifo {}", p.display());
                }
            }
        }
        for s in &case.setup {
            match run(s, &dir) {
                Some(Ok((0, _))) => {}
                other => panic!("{}: setup `{s}` failed: {other:?}", case.name),
            }
        }
        if let Some(prepare) = case.prepare {
            prepare(&dir);
        }
        let what = match run(case.args, &dir) {
            None => Err("hung (no answer in 120 s)".to_string()),
            Some(Err(_)) => Err("panicked".to_string()),
            Some(Ok((code, msg))) => {
                let msg = msg.unwrap_or_default();
                let missing: Vec<&&str> =
                    case.words.iter().filter(|w| !msg.contains(**w)).collect();
                if code != case.code {
                    Err(format!("exit {code}, expected {}: {msg}", case.code))
                } else if msg.contains('\n') {
                    Err(format!("message spans lines: {msg}"))
                } else if !missing.is_empty() {
                    Err(format!("message lacks {missing:?}: {msg}"))
                } else if case.code != 0 && !msg.starts_with("error: ") {
                    Err(format!("not an error line: {msg}"))
                } else {
                    Ok(())
                }
            }
        };
        let what = what.and_then(|()| match &case.check {
            Some(check) => std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| check(&dir)))
                .map_err(|e| {
                    e.downcast_ref::<String>()
                        .cloned()
                        .unwrap_or_else(|| "check failed".into())
                }),
            None => Ok(()),
        });
        if let Err(e) = what {
            failures.push(format!("{}: {e}", case.name));
        }
    }
    assert!(
        failures.is_empty(),
        "{} of {n} cases failed:\n{}",
        failures.len(),
        failures.join("\n")
    );
}
