//! The binary's contract on bad input: one line naming the file and the problem, a non-zero
//! exit, no panic. (The one integration test outside `tests/`: only this package's tests get
//! `CARGO_BIN_EXE_photonflow`.)

use std::path::PathBuf;
use std::process::Command;

struct Scratch(PathBuf);

impl Scratch {
    fn new(name: &str, files: &[(&str, &str)]) -> Scratch {
        let dir =
            std::env::temp_dir().join(format!("photonflow-cli-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        for (f, text) in files {
            std::fs::write(dir.join(f), text).unwrap();
        }
        Scratch(dir)
    }
}

impl Drop for Scratch {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

const CAMERA: &str =
    "[camera]\neye = [0, 1, 3]\nlook_at = [0, 0, 0]\nvfov = 60\nwidth = 8\nheight = 8\n";
const OBJ: &str = "mtllib m.mtl\no floor\nusemtl white\nv -1 0 -1\nv -1 0 1\nv 1 0 1\nv 1 0 -1\nf 1 2 3\nf 1 3 4\n\
o light\nusemtl light\nv -0.1 1 -0.1\nv 0.1 1 -0.1\nv 0.1 1 0.1\nv -0.1 1 0.1\nf 5 6 7\nf 5 7 8\n";
const MTL: &str = "newmtl white\nKd 0.5 0.5 0.5\nnewmtl light\nKd 0 0 0\nKe 4 4 4\n";

fn toml() -> String {
    format!("{CAMERA}[[mesh]]\nobj = \"a.obj\"\n")
}

/// Run `photonflow info` on a scene made of `files` and check the failure.
fn check(name: &str, files: &[(&str, &str)], file: &str, problem: &str) {
    let dir = Scratch::new(name, files);
    let out = Command::new(env!("CARGO_BIN_EXE_photonflow"))
        .arg("info")
        .arg(dir.0.join("s.toml"))
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{name}: {stderr}");
    assert!(!stderr.contains("panicked"), "{name}: {stderr}");
    assert!(
        stderr.contains(file),
        "{name}: `{stderr}` does not name {file}"
    );
    assert!(
        stderr.contains(problem),
        "{name}: `{stderr}` does not say {problem}"
    );
    assert_eq!(
        stderr.trim().lines().count(),
        1,
        "{name}: one line, got {stderr}"
    );
}

#[test]
fn a_good_scene_exits_zero() {
    let dir = Scratch::new(
        "good",
        &[("s.toml", &toml()), ("a.obj", OBJ), ("m.mtl", MTL)],
    );
    let out = Command::new(env!("CARGO_BIN_EXE_photonflow"))
        .arg("info")
        .arg(dir.0.join("s.toml"))
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(String::from_utf8_lossy(&out.stdout).contains("triangles  4"));
}

#[test]
fn bad_inputs_fail_cleanly() {
    let t = toml();
    check("missing-scene", &[], "s.toml", "cannot read scene file");
    check(
        "missing-obj",
        &[("s.toml", &t)],
        "a.obj",
        "cannot read OBJ file",
    );
    check(
        "missing-mtl",
        &[("s.toml", &t), ("a.obj", OBJ)],
        "m.mtl",
        "cannot read MTL file",
    );
    let nan = OBJ.replace("v 1 0 1", "v 1 nan 1");
    check(
        "nan",
        &[("s.toml", &t), ("a.obj", &nan), ("m.mtl", MTL)],
        "a.obj",
        "not finite",
    );
    let inf = OBJ.replace("v 1 0 1", "v 1 0 -inf");
    check(
        "inf",
        &[("s.toml", &t), ("a.obj", &inf), ("m.mtl", MTL)],
        "a.obj",
        "not finite",
    );
    let illum = MTL.replace("Kd 0.5 0.5 0.5", "Kd 0.5 0.5 0.5\nillum 99");
    check(
        "illum",
        &[("s.toml", &t), ("a.obj", OBJ), ("m.mtl", &illum)],
        "a.obj",
        "unknown illum code 99",
    );
    let dark = MTL.replace("Ke 4 4 4", "");
    check(
        "no-light",
        &[("s.toml", &t), ("a.obj", OBJ), ("m.mtl", &dark)],
        "s.toml",
        "no light",
    );
    let flat = OBJ.replace("v 0.1 1 0.1", "v 0.1 1 -0.1");
    check(
        "zero-area",
        &[("s.toml", &t), ("a.obj", &flat), ("m.mtl", MTL)],
        "s.toml",
        "zero-area light",
    );
    let bad = t.replace("width = 8", "width = -8");
    check(
        "toml",
        &[("s.toml", &bad), ("a.obj", OBJ), ("m.mtl", MTL)],
        "s.toml",
        "malformed scene file",
    );
    let absurd = t
        .replace("width = 8", "width = 100000")
        .replace("height = 8", "height = 100000");
    check(
        "absurd",
        &[("s.toml", &absurd), ("a.obj", OBJ), ("m.mtl", MTL)],
        "s.toml",
        "absurd",
    );
}
