//! Bad input, in tables: each case writes its input files into a scratch directory, runs one
//! command line through `photonflow::run_args` (the binary's own entry, in process), and
//! checks the exit code and that the error is one line holding the given words (the file at
//! fault and the problem). Cases that must succeed (valid scenes once refused, `Kd 0.5`) check
//! what they wrote instead. A case that hangs fails after a timeout; one that panics fails
//! with the panic.
//!
//! Each kind of bad-input failure has cases here: panics, hangs, accepted bad values,
//! partial output, messages, valid scenes refused and temporary files (a stale file from a
//! dead process; Ctrl-C itself needs a process: the binary's own test `cli.rs` signals it).
//! Every loader (OBJ, MTL, PLY, scene file, photon file, EXR) and every command's flags have cases
//! too (the bench commands only with values refused before any timing starts).
//!
//! The table is split by the kind of input at fault, one file each with its own
//! `bad_input_table` test: the scene file (`scene_file`), its lights (`lights`), OBJ, MTL and
//! PLY files (`obj_mtl`), images (`images`: EXR files, references, environment maps), flags
//! (`flags`), photon files (`photon_files`), shard sets and the runs `composite` reads back
//! (`shards`), and temporary files (`temp_files`). This module holds the good scene they
//! start from, the helpers several kinds share and the runner.

mod flags;
mod images;
mod lights;
mod obj_mtl;
mod photon_files;
mod scene_file;
mod shards;
mod temp_files;
mod xml;

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
    Bytes(Vec<u8>),
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

fn absent(rel: &'static str) -> Option<Check> {
    Some(Box::new(move |d: &Path| {
        assert!(!d.join(rel).exists(), "{rel} was written");
    }))
}

fn present(rel: &'static str, holds: &'static str) -> Option<Check> {
    Some(Box::new(move |d: &Path| {
        let t = std::fs::read_to_string(d.join(rel)).unwrap_or_else(|e| panic!("{rel}: {e}"));
        assert!(t.contains(holds), "{rel} does not hold `{holds}`: {t}");
    }))
}

/// The case's `s.toml` loads, with a warning that holds every one of `words`.
fn warns(words: &'static [&'static str]) -> Option<Check> {
    warns_in("s.toml", words)
}

/// The case's scene `file` loads, with a warning that holds every one of `words`.
fn warns_in(file: &'static str, words: &'static [&'static str]) -> Option<Check> {
    Some(Box::new(move |d: &Path| {
        let s = scene::Scene::load(d.join(file)).unwrap_or_else(|e| panic!("{e}"));
        assert!(
            s.warnings
                .iter()
                .any(|w| words.iter().all(|x| w.contains(x))),
            "no warning holds {words:?}: {:?}",
            s.warnings
        );
    }))
}

/// The case's `s.toml` loads; material `white`'s albedo texture, times its scale, peaks at 1
/// at most in every channel, with a warning that holds every one of `words`.
fn texture_scaled(words: &'static [&'static str]) -> Option<Check> {
    Some(Box::new(move |d: &Path| {
        warns(words).unwrap()(d);
        let s = scene::Scene::load(d.join("s.toml")).unwrap_or_else(|e| panic!("{e}"));
        let id = s.material_of("white").unwrap() as usize;
        let map = s.albedo_maps[id].as_ref().expect("white has no texture");
        let peak = map.scale * s.textures[map.texture as usize].max();
        assert!(peak.max_element() <= 1.0 + 1e-6, "albedo peaks at {peak}");
    }))
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

/// Runs one kind's table, each case in its own directory of a scratch directory named after
/// `kind`, and fails naming every case that failed.
fn run_table(kind: &str, cases: Vec<Case>) {
    let tmp = TempDir::new(&format!("bad-input-{kind}"));
    let mut failures = Vec::new();
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
                Input::Bytes(b) => std::fs::write(&p, b).unwrap(),
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
