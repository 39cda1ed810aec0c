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

/// What a scene's MTL asks for and photonflow approximates is said on stderr, one `warning:`
/// line per material and key, naming the file and material; the run still succeeds.
#[test]
fn approximated_mtl_keys_are_warned_about() {
    let mtl = MTL.replace(
        "Kd 0.5 0.5 0.5",
        "Kd 0 0 0\nKs 0.9 0.9 0.9\nillum 5\nbump b.png",
    );
    let dir = Scratch::new(
        "warned",
        &[("s.toml", &toml()), ("a.obj", OBJ), ("m.mtl", &mtl)],
    );
    let out = Command::new(env!("CARGO_BIN_EXE_photonflow"))
        .arg("info")
        .arg(dir.0.join("s.toml"))
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    let warnings: Vec<&str> = stderr
        .lines()
        .filter(|l| l.starts_with("warning: "))
        .collect();
    assert_eq!(warnings.len(), 2, "{stderr}");
    for key in ["illum 5", "bump b.png"] {
        assert!(
            warnings
                .iter()
                .any(|w| w.contains("m.mtl: material `white`: ") && w.contains(key)),
            "no warning about {key}: {stderr}"
        );
    }
}

#[test]
fn a_closed_stdout_ends_quietly_with_the_sigpipe_status() {
    let dir = Scratch::new(
        "pipe",
        &[("s.toml", &toml()), ("a.obj", OBJ), ("m.mtl", MTL)],
    );
    // A pipe whose reader is gone before the child starts: its first write fails.
    let (reader, writer) = std::io::pipe().unwrap();
    drop(reader);
    let out = Command::new(env!("CARGO_BIN_EXE_photonflow"))
        .arg("info")
        .arg(dir.0.join("s.toml"))
        .stdout(writer)
        .stderr(std::process::Stdio::piped())
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(141), "{stderr}");
    assert!(stderr.is_empty(), "{stderr}");
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
        "m.mtl",
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

fn photonflow(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_photonflow"))
        .current_dir(concat!(env!("CARGO_MANIFEST_DIR"), "/../.."))
        .args(args)
        .output()
        .unwrap()
}

#[test]
fn render_writes_exr_png_layers_and_json_identically_for_any_thread_count() {
    let dir = Scratch::new("render", &[]);
    let out1 = dir.0.join("t1");
    let out2 = dir.0.join("t2");
    for (out, threads) in [(&out1, "1"), (&out2, "2")] {
        let o = photonflow(&[
            "render",
            "scenes/cornell-spheres/analytic.toml",
            "--method",
            "path",
            "--spp",
            "2",
            "--threads",
            threads,
            "--out",
            out.to_str().unwrap(),
        ]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    }
    for f in [
        "image.exr",
        "image.png",
        "image.json",
        "layers/direct.exr",
        "layers/caustic.exr",
    ] {
        let a = std::fs::read(out1.join(f)).unwrap();
        if f.ends_with(".exr") || f.ends_with(".png") {
            assert_eq!(
                a,
                std::fs::read(out2.join(f)).unwrap(),
                "{f} differs between 1 and 2 threads"
            );
        }
    }
    let json = std::fs::read_to_string(out1.join("image.json")).unwrap();
    for key in [
        "\"spp\": 2",
        "\"samples_per_s\"",
        "\"time_total_s\"",
        "\"view_hash\"",
        "\"count_kind\": \"spp\"",
        "\"scene_hash\"",
        "\"threads\": 1",
    ] {
        assert!(json.contains(key), "{key} missing from {json}");
    }
}

/// `compare TEST A B`: against the halves' mean, with the reference's noise taken out, on
/// images whose errors are known exactly: the halves are 1 ± 0.05 pixel by pixel (their mean
/// is exactly 1, its variance estimate (A - B)²/4 = 0.0025 everywhere) and the test image is
/// 1.1, so the plain MSE is 0.01 and the corrected one 0.0075.
#[test]
fn compare_takes_a_references_noise_out_given_its_two_halves() {
    let dir = Scratch::new("halves", &[]);
    let write = |name: &str, f: &dyn Fn(usize, usize) -> f32| {
        let p = dir.0.join(name);
        film::write_exr(&p, &film::Image::from_fn(8, 8, |x, y| [f(x, y); 3])).unwrap();
        p.to_str().unwrap().to_string()
    };
    let sign = |x: usize, y: usize| if (x + y).is_multiple_of(2) { 1.0 } else { -1.0 };
    let a = write("a.exr", &|x, y| 1.0 + 0.05 * sign(x, y));
    let b = write("b.exr", &|x, y| 1.0 - 0.05 * sign(x, y));
    let t = write("t.exr", &|_, _| 1.1);
    let o = photonflow(&["compare", &t, &a, &b]);
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "{text}");
    let value = |after: &str, key: &str| -> f64 {
        let start = text.find(after).unwrap_or_else(|| panic!("{text}")) + after.len();
        let part = &text[start..];
        let v = part.split(key).nth(1).unwrap_or_else(|| panic!("{text}"));
        v.split_whitespace().next().unwrap().parse().unwrap()
    };
    // Plain: rmse 0.1 (f32 images: 1.1 and 1 ± 0.05 are not exact, hence the tolerances).
    assert!((value("", "rmse=") - 0.1).abs() < 1e-6, "{text}");
    // relmse = (mse - var) / (1 + 0.01) per element.
    let corrected = value("taken out:", "relmse=");
    assert!((corrected - 0.0075 / 1.01).abs() < 1e-6, "{text}");
    assert!(
        (value("taken out:", " rmse=") - 0.0075f64.sqrt()).abs() < 1e-6,
        "{text}"
    );
    // Halves of different sizes are refused, naming them.
    let small = dir.0.join("s.exr");
    film::write_exr(&small, &film::Image::from_fn(4, 4, |_, _| [1.0; 3])).unwrap();
    let o = photonflow(&["compare", &t, &a, small.to_str().unwrap()]);
    let e = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{e}");
    assert!(e.contains("s.exr") && e.contains("size"), "{e}");
}

#[test]
fn compare_refuses_missing_files_and_bad_masks() {
    let o = photonflow(&["compare", "nope-a.exr", "nope-b.exr"]);
    let e = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1));
    assert!(e.contains("nope-a.exr") && !e.contains("panicked"), "{e}");
    let o = photonflow(&["compare", "a.exr", "b.exr", "--mask", "1,2,3"]);
    assert_eq!(o.status.code(), Some(2), "usage error");
}

#[test]
fn swapping_the_estimator_reads_the_cache_and_never_traces() {
    let dir = Scratch::new("swap", &[]);
    let cache = dir.0.join("cache");
    let cache_s = cache.to_str().unwrap();
    let scene = "scenes/corner/corner.toml";
    // Without a traced set, estimate refuses instead of tracing.
    let o = photonflow(&["estimate", scene, "--photons", "20000", "--cache", cache_s]);
    let e = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{e}");
    assert!(e.contains("run `trace` first"), "{e}");
    let photon_files = |dir: &std::path::Path| -> Vec<PathBuf> {
        std::fs::read_dir(dir)
            .map(|d| {
                d.map(|e| e.unwrap().path())
                    .filter(|p| p.extension().is_some_and(|x| x == "photons"))
                    .collect()
            })
            .unwrap_or_default()
    };
    assert!(photon_files(&cache).is_empty(), "estimate wrote photons");

    let o = photonflow(&["trace", scene, "--photons", "20000", "--cache", cache_s]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(
        text.contains("caustic photons: skipped"),
        "corner has no specular surface: {text}"
    );
    let files = photon_files(&cache);
    assert_eq!(files.len(), 1, "only the global set: {files:?}");
    let before = std::fs::metadata(&files[0]).unwrap().modified().unwrap();
    let bytes = std::fs::read(&files[0]).unwrap();

    let mut outs = Vec::new();
    for kernel in ["uniform", "silverman"] {
        let out = dir.0.join(kernel);
        let o = photonflow(&[
            "estimate",
            scene,
            "--photons",
            "20000",
            "--cache",
            cache_s,
            "--k",
            "50",
            "--kernel",
            kernel,
            "--out",
            out.to_str().unwrap(),
        ]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        outs.push(std::fs::read(out.join("image.exr")).unwrap());
        let json = std::fs::read_to_string(out.join("image.json")).unwrap();
        assert!(
            json.contains(&format!("\"kernel\": \"{kernel}\"")),
            "{json}"
        );
    }
    assert_ne!(outs[0], outs[1], "another kernel, another image");
    // The photon set was read, never rewritten.
    assert_eq!(
        std::fs::metadata(&files[0]).unwrap().modified().unwrap(),
        before
    );
    assert_eq!(std::fs::read(&files[0]).unwrap(), bytes);

    // render chains trace and estimate, and reuses the cached set.
    let o = photonflow(&[
        "render",
        scene,
        "--method",
        "global-direct",
        "--photons",
        "20000",
        "--cache",
        cache_s,
        "--k",
        "50",
        "--out",
        dir.0.join("r").to_str().unwrap(),
    ]);
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(
        o.status.success() && text.contains("reused cached photon sets"),
        "{text}"
    );
}

#[test]
fn a_truncated_cache_file_is_traced_anew() {
    let dir = Scratch::new("trunc", &[]);
    let cache = dir.0.join("cache");
    let cache_s = cache.to_str().unwrap();
    let scene = "scenes/corner/corner.toml";
    let o = photonflow(&["trace", scene, "--photons", "5000", "--cache", cache_s]);
    assert!(o.status.success());
    let f = std::fs::read_dir(&cache)
        .unwrap()
        .map(|e| e.unwrap().path())
        .find(|p| p.extension().is_some_and(|x| x == "photons"))
        .unwrap();
    let good = std::fs::read(&f).unwrap();
    std::fs::write(&f, &good[..good.len() - 7]).unwrap();
    let o = photonflow(&["trace", scene, "--photons", "5000", "--cache", cache_s]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{err}");
    assert!(
        err.contains("unusable") && err.contains("truncated"),
        "{err}"
    );
    assert_eq!(
        std::fs::read(&f).unwrap(),
        good,
        "traced again, bit for bit"
    );
}

#[test]
fn render_final_gather_runs_the_framework_standard_deterministically() {
    // Final gathering chains trace → estimate → composite.
    let dir = Scratch::new("fg", &[]);
    let cache = dir.0.join("cache");
    let mut images = Vec::new();
    for threads in ["1", "2"] {
        let out = dir.0.join(threads);
        let o = photonflow(&[
            "render",
            "scenes/corner/corner.toml",
            "--method",
            "final-gather",
            "--photons",
            "20000",
            "--k",
            "50",
            "--gather-rays",
            "4",
            "--threads",
            threads,
            "--cache",
            cache.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ]);
        let text = String::from_utf8_lossy(&o.stdout);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        assert!(
            text.contains("rendered final-gather") && text.contains("irradiance cache"),
            "{text}"
        );
        let json = std::fs::read_to_string(out.join("image.json")).unwrap();
        assert!(json.contains("\"gather_rays\": 4"), "{json}");
        for layer in ["emitted", "direct", "caustic", "indirect"] {
            assert!(
                out.join("layers").join(format!("{layer}.exr")).exists(),
                "{layer}"
            );
        }
        images.push(std::fs::read(out.join("image.exr")).unwrap());
    }
    assert_eq!(images[0], images[1], "1 and 2 threads give the same image");
    // The resolved scene file in the output reproduces the run bit for bit, flags included
    // (here --photons, --k and --gather-rays), from another working directory's view: its
    // mesh paths are absolute.
    let resolved = dir.0.join("1").join("scene.toml");
    let text = std::fs::read_to_string(&resolved).unwrap();
    assert!(
        text.contains("photons = 20000") && text.contains("rays = 4"),
        "{text}"
    );
    let again = dir.0.join("again");
    let o = photonflow(&[
        "render",
        resolved.to_str().unwrap(),
        "--cache",
        cache.to_str().unwrap(),
        "--out",
        again.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(
        std::fs::read(again.join("image.exr")).unwrap(),
        images[0],
        "the resolved scene file reproduces the image"
    );
}

#[test]
fn estimates_that_would_be_silently_wrong_are_refused() {
    let dir = Scratch::new("refuse", &[]);
    let cache = dir.0.join("cache");
    let cache_s = cache.to_str().unwrap();
    let scene = "scenes/corner/corner.toml";
    let o = photonflow(&["trace", scene, "--photons", "2000", "--cache", cache_s]);
    assert!(o.status.success());
    // The boundary correction without the topological test would amplify leaked photons.
    let o = photonflow(&[
        "estimate",
        scene,
        "--photons",
        "2000",
        "--cache",
        cache_s,
        "--boundary",
    ]);
    let e = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{e}");
    assert!(
        e.contains("boundary correction needs the topological test"),
        "{e}"
    );
    // The path tracer is not an estimate.
    let o = photonflow(&["estimate", scene, "--method", "path", "--cache", cache_s]);
    assert_eq!(o.status.code(), Some(1));
    // A global map without direct hits would lose direct light in both photon methods.
    let obj = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../scenes/corner/corner.obj"
    );
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../scenes/corner/corner.toml"
    ))
    .unwrap()
    .replace("obj = \"corner.obj\"", &format!("obj = {obj:?}"))
        + "\n[photons]\nstore_direct = false\n";
    let s = dir.0.join("nodirect.toml");
    std::fs::write(&s, text).unwrap();
    let o = photonflow(&[
        "render",
        s.to_str().unwrap(),
        "--method",
        "global-direct",
        "--cache",
        cache_s,
    ]);
    let e = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{e}");
    assert!(
        e.contains("store_direct = false") && e.contains("nodirect.toml"),
        "{e}"
    );
}

#[test]
fn composite_averages_runs_by_their_counts_and_refuses_other_views() {
    let dir = Scratch::new("composite", &[]);
    let scene = "scenes/corner/corner.toml";
    let mut outs = Vec::new();
    // Independent runs: another seed each (one seed would share random streams).
    for (spp, seed) in [("1", "11"), ("3", "12")] {
        let out = dir.0.join(spp);
        let o = photonflow(&[
            "render",
            scene,
            "--method",
            "path",
            "--spp",
            spp,
            "--seed",
            seed,
            "--out",
            out.to_str().unwrap(),
        ]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        outs.push(out);
    }
    let out = dir.0.join("sum");
    let o = photonflow(&[
        "composite",
        outs[1].to_str().unwrap(),
        outs[0].to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let read = |d: &PathBuf| film::read_exr(d.join("image.exr")).unwrap();
    let (a, b, c) = (read(&outs[0]), read(&outs[1]), read(&out));
    // 1 spp and 3 spp weighted by their counts: the 4-spp mean, to f32 rounding per layer.
    let mut worst = 0.0f64;
    for ((x, y), z) in a.data.iter().zip(&b.data).zip(&c.data) {
        for ch in 0..3 {
            let want = (x[ch] as f64 + 3.0 * y[ch] as f64) / 4.0;
            worst = worst.max((z[ch] as f64 - want).abs() / want.abs().max(1e-3));
        }
    }
    assert!(worst < 1e-5, "relative error {worst}");
    let json = std::fs::read_to_string(outs[1].join("image.json")).unwrap();
    assert!(json.contains("\"seed\": 12"), "{json}");
    // In the other order: the same bytes.
    let out2 = dir.0.join("sum2");
    let o = photonflow(&[
        "composite",
        outs[0].to_str().unwrap(),
        outs[1].to_str().unwrap(),
        "--out",
        out2.to_str().unwrap(),
    ]);
    assert!(o.status.success());
    assert_eq!(
        std::fs::read(out.join("image.exr")).unwrap(),
        std::fs::read(out2.join("image.exr")).unwrap()
    );
    // Another camera is another view: refused, naming the input.
    let obj = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../scenes/corner/corner.obj"
    );
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../scenes/corner/corner.toml"
    ))
    .unwrap()
    .replace("obj = \"corner.obj\"", &format!("obj = {obj:?}"))
    .replace("vfov = 60.0", "vfov = 50.0");
    let narrow = dir.0.join("narrow.toml");
    // (The same seed as the first run, so only the view can be what is refused.)
    std::fs::write(&narrow, text).unwrap();
    let other = dir.0.join("other");
    let o = photonflow(&[
        "render",
        narrow.to_str().unwrap(),
        "--method",
        "path",
        "--spp",
        "1",
        "--seed",
        "11",
        "--out",
        other.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let bad = dir.0.join("bad");
    let o = photonflow(&[
        "composite",
        outs[0].to_str().unwrap(),
        other.to_str().unwrap(),
        "--out",
        bad.to_str().unwrap(),
    ]);
    let e = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{e}");
    assert!(e.contains("view") && e.lines().count() == 1, "{e}");
    assert!(!bad.exists(), "nothing written");
}

/// Ctrl-C during `trace` removes the photon file being written and exits 130; after a
/// kill -9 the stale temp file stays until the next trace in that cache, which removes it.
#[cfg(unix)]
#[test]
fn interrupted_traces_leave_no_temp_files() {
    let dir = Scratch::new("interrupt", &[]);
    let cache = dir.0.join("cache");
    let names = || -> Vec<String> {
        std::fs::read_dir(&cache)
            .map(|d| {
                d.map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
                    .collect()
            })
            .unwrap_or_default()
    };
    let temps = || -> Vec<String> {
        names()
            .into_iter()
            .filter(|n| n.contains(".tmp-"))
            .collect()
    };
    // SIGINT and SIGKILL, each at several moments while the photon files are being written
    // (0 to 0.72 s after its first temporary file appears; the trace would take minutes),
    // ending with a kill -9 whose file the last run must remove.
    for (i, signal) in ["-INT", "-KILL", "-INT", "-KILL", "-KILL", "-INT", "-KILL"]
        .iter()
        .enumerate()
    {
        let mut child = Command::new(env!("CARGO_BIN_EXE_photonflow"))
            .current_dir(concat!(env!("CARGO_MANIFEST_DIR"), "/../.."))
            .args([
                "trace",
                "scenes/corner/corner.toml",
                "--photons",
                "100000000",
            ])
            .arg("--cache")
            .arg(&cache)
            .args(["--force", "--threads", "1"])
            .stdout(std::process::Stdio::null())
            .stderr(std::process::Stdio::null())
            .spawn()
            .unwrap();
        let t0 = std::time::Instant::now();
        let mine = format!(".tmp-{}-", child.id());
        while !temps().iter().any(|n| n.contains(&mine)) {
            assert!(t0.elapsed().as_secs() < 60, "no temp file appeared");
            std::thread::sleep(std::time::Duration::from_millis(5));
        }
        std::thread::sleep(std::time::Duration::from_millis(120 * i as u64));
        let sent = Command::new("kill")
            .arg(signal)
            .arg(child.id().to_string())
            .status()
            .unwrap();
        assert!(sent.success());
        let status = child.wait().unwrap();
        // No photon file was published: the run never finished, so nothing in the cache may
        // read as a photon set.
        let published: Vec<String> = names()
            .into_iter()
            .filter(|n| n.ends_with(".photons"))
            .collect();
        assert_eq!(published, Vec::<String>::new(), "{signal} at moment {i}");
        if *signal == "-INT" {
            // Its own temporary files removed on the signal, and a killed run's before it
            // began (their process is gone).
            assert_eq!(status.code(), Some(130), "{status:?}");
            assert!(temps().is_empty(), "left behind: {:?}", temps());
        } else {
            // kill -9 cannot clean up: its temporary files stay until the next run.
            assert!(temps().iter().any(|n| n.contains(&mine)), "{:?}", temps());
        }
    }
    let o = photonflow(&[
        "trace",
        "scenes/corner/corner.toml",
        "--photons",
        "2000",
        "--cache",
        cache.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(temps().is_empty(), "stale temp file kept: {:?}", temps());
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(e.contains("an unfinished file of process"), "{e}");
}

/// The temp files and staging directories (`temps`' names) under `dir`, as paths relative to
/// it; a staging directory is listed, not entered.
#[cfg(unix)]
fn temps_under(dir: &std::path::Path) -> Vec<String> {
    let mut found = Vec::new();
    let mut todo = vec![dir.to_path_buf()];
    while let Some(d) = todo.pop() {
        for e in std::fs::read_dir(&d).into_iter().flatten().flatten() {
            let name = e.file_name().to_string_lossy().into_owned();
            let rel = e.path().strip_prefix(dir).unwrap().display().to_string();
            if temps::owner(&name).is_some() {
                found.push(rel);
            } else if e.file_type().is_ok_and(|t| t.is_dir()) {
                todo.push(e.path());
            }
        }
    }
    found.sort();
    found
}

/// The furnace scene at `size` x `size` pixels, written into `dir`: big enough that encoding
/// each of its images takes a while, during which its temp file exists.
#[cfg(unix)]
fn big_furnace(dir: &Scratch, size: u32) -> String {
    let root = concat!(env!("CARGO_MANIFEST_DIR"), "/../../scenes/furnace");
    let text = std::fs::read_to_string(format!("{root}/furnace.toml"))
        .unwrap()
        .replace("width = 32", &format!("width = {size}"))
        .replace("height = 32", &format!("height = {size}"))
        .replace("obj = \"box.obj\"", &format!("obj = \"{root}/box.obj\""));
    let path = dir.0.join("furnace.toml");
    std::fs::write(&path, text).unwrap();
    path.to_str().unwrap().to_string()
}

/// How an interrupt test's run ended.
#[cfg(unix)]
struct Interrupted {
    status: std::process::ExitStatus,
    /// `.tmp-<pid>-`: what this run's temps hold in their names.
    mine: String,
}

/// Runs photonflow with `args` and sends it `signal` once `ready` holds for the temps under
/// `watch` (polled, so the moment does not depend on the machine's speed).
#[cfg(unix)]
fn interrupt(
    args: &[&str],
    watch: &std::path::Path,
    ready: &mut dyn FnMut(&[String], &str) -> bool,
    signal: nix::sys::signal::Signal,
) -> Interrupted {
    let mut child = Command::new(env!("CARGO_BIN_EXE_photonflow"))
        .current_dir(concat!(env!("CARGO_MANIFEST_DIR"), "/../.."))
        .args(args)
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .spawn()
        .unwrap();
    let mine = format!(".tmp-{}-", child.id());
    let t0 = std::time::Instant::now();
    while !ready(&temps_under(watch), &mine) {
        // Neither bound is a measurement: they only keep a broken run from hanging the test.
        assert!(
            t0.elapsed().as_secs() < 300,
            "{args:?}: the moment never came"
        );
        let done = child.try_wait().unwrap();
        assert!(done.is_none(), "{args:?} ended before the moment: {done:?}");
        std::thread::sleep(std::time::Duration::from_millis(2));
    }
    let pid = nix::unistd::Pid::from_raw(child.id() as i32);
    nix::sys::signal::kill(pid, signal).unwrap();
    Interrupted {
        status: child.wait().unwrap(),
        mine,
    }
}

/// The temps under `dir` as [`temps_under`] lists them, and those inside staging
/// directories too.
#[cfg(unix)]
fn temps_within(dir: &std::path::Path) -> Vec<String> {
    let mut found = Vec::new();
    let mut todo = vec![dir.to_path_buf()];
    while let Some(d) = todo.pop() {
        for e in std::fs::read_dir(&d).into_iter().flatten().flatten() {
            let name = e.file_name().to_string_lossy().into_owned();
            if temps::owner(&name).is_some() {
                found.push(e.path().strip_prefix(dir).unwrap().display().to_string());
            }
            if e.file_type().is_ok_and(|t| t.is_dir()) {
                todo.push(e.path());
            }
        }
    }
    found.sort();
    found
}

/// Signals `args`, a run writing a run directory at `out`, while it writes the k-th temp file
/// into its staging directory beside `out` (k from `plan`), and checks that SIGINT removes
/// what it was writing and that a kill -9's staging directory stays until the next run into
/// `out`, which removes it; `out` itself never appears before a run finishes.
#[cfg(unix)]
fn interrupt_while_writing(args: &[&str], out: &std::path::Path) {
    use nix::sys::signal::Signal::{SIGINT, SIGKILL};
    let beside = out.parent().unwrap();
    // Ending with a kill -9, whose files the rerun must remove.
    let plan = [
        (0, SIGINT),
        (1, SIGKILL),
        (2, SIGINT),
        (0, SIGKILL),
        (1, SIGINT),
        (2, SIGKILL),
    ];
    for (k, signal) in plan {
        // Every temp file of this run seen so far inside its staging directory: the k-th has
        // appeared once there are k + 1.
        let mut seen = std::collections::BTreeSet::new();
        let r = interrupt(
            args,
            beside,
            &mut |_, mine| {
                let files = temps_within(beside);
                seen.extend(
                    files
                        .iter()
                        .filter(|t| t.contains(mine) && t.contains('/'))
                        .cloned(),
                );
                seen.len() > k
            },
            signal,
        );
        // The run never finished, so nothing of it is published.
        assert!(!out.exists(), "{signal} at file {k}");
        let left = temps_under(beside);
        if signal == SIGINT {
            // Its own staging directory removed on the signal, and a killed run's before it
            // began writing (their process is gone).
            assert_eq!(r.status.code(), Some(130), "{signal} at file {k}");
            assert!(left.is_empty(), "{signal} at file {k} left {left:?}");
        } else {
            // kill -9 cannot clean up: its staging directory stays until the next run.
            assert!(left.iter().any(|t| t.contains(&r.mine)), "{left:?}");
        }
    }
    let o = photonflow(args);
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{e}");
    assert!(out.join("image.json").exists());
    assert!(
        temps_within(beside).is_empty(),
        "kept: {:?}",
        temps_within(beside)
    );
    assert!(
        e.contains("an unfinished staging directory of process"),
        "{e}"
    );
}

/// Ctrl-C while `render` writes its images removes the ones being written; a kill -9's stay
/// until the next render into that directory.
#[cfg(unix)]
#[test]
fn interrupted_renders_leave_no_temp_files() {
    let dir = Scratch::new("interrupt-render", &[]);
    let scene = big_furnace(&dir, 640);
    let out = dir.0.join("run");
    let args = [
        "render",
        &scene,
        "--method",
        "path",
        "--spp",
        "1",
        "--out",
        out.to_str().unwrap(),
    ];
    interrupt_while_writing(&args, &out);
}

/// Ctrl-C while `merge` writes the image of image shards removes the files being written; a
/// kill -9's stay until the next merge into that directory.
#[cfg(unix)]
#[test]
fn interrupted_merges_leave_no_temp_files() {
    let dir = Scratch::new("interrupt-merge", &[]);
    let scene = big_furnace(&dir, 640);
    let shard = dir.0.join("shard");
    let o = photonflow(&[
        "render",
        &scene,
        "--method",
        "path",
        "--spp",
        "1",
        "--shard",
        "0/1",
        "--out",
        shard.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let out = dir.0.join("merged");
    let args = [
        "merge",
        shard.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ];
    interrupt_while_writing(&args, &out);
}

/// Ctrl-C during `render --shard` removes its staging directory (nothing is published); a
/// kill -9's stays until the shard is written again.
#[cfg(unix)]
#[test]
fn interrupted_shards_leave_no_staging_directories() {
    use nix::sys::signal::Signal::{SIGINT, SIGKILL};
    let dir = Scratch::new("interrupt-shard", &[]);
    let shards = dir.0.join("shards");
    let out = shards.join("0");
    let args = |spp| {
        [
            "render",
            "scenes/furnace/furnace.toml",
            "--method",
            "path",
            "--spp",
            spp,
            "--shard",
            "0/2",
            "--out",
            out.to_str().unwrap(),
        ]
    };
    // At several moments of the rendering (the staging directory lives from its start, and
    // this one would take hours), ending with a kill -9 whose directory the last run removes.
    let plan = [SIGINT, SIGKILL, SIGINT, SIGKILL, SIGKILL, SIGINT, SIGKILL];
    for (i, signal) in plan.into_iter().enumerate() {
        let mut polls = 0;
        let r = interrupt(
            &args("16777216"),
            &shards,
            &mut |temps, mine| {
                // A few more polls each time: later moments.
                polls += temps.iter().any(|t| t.contains(mine)) as usize;
                polls > 20 * i
            },
            signal,
        );
        assert!(
            !out.exists(),
            "{signal} at moment {i}: a shard was published"
        );
        let left = temps_under(&shards);
        if signal == SIGINT {
            assert_eq!(r.status.code(), Some(130), "{signal} at moment {i}");
            assert!(left.is_empty(), "{signal} at moment {i} left {left:?}");
        } else {
            assert!(left.iter().any(|t| t.contains(&r.mine)), "{left:?}");
        }
    }
    // Another shard's, of a process this machine cannot see (shards of one run share their
    // directory across machines): not this shard's to remove.
    let other = ".1.tmp-999999999-0";
    std::fs::create_dir(shards.join(other)).unwrap();
    let o = photonflow(&args("2"));
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{e}");
    assert!(out.join("shard.json").is_file());
    assert_eq!(temps_under(&shards), [other]);
    assert!(
        e.contains("an unfinished staging directory of process"),
        "{e}"
    );
}

/// `--time` alone is a budget to use: the passes go on past the scene file's count (here 1)
/// until the time is used, and `image.json`, the snapshots and `scene.toml` record the passes
/// made; with `--passes` too the time only caps them. Nothing here asserts a duration.
#[test]
fn time_is_a_budget_to_use_and_with_passes_a_cap() {
    let scene = format!("{}[estimate.sppm]\npasses = 1\n", toml());
    let dir = Scratch::new(
        "time",
        &[("s.toml", &scene), ("a.obj", OBJ), ("m.mtl", MTL)],
    );
    let s = dir.0.join("s.toml");
    let render = |name: &str, extra: &[&str]| {
        let out = dir.0.join(name);
        let mut args = vec![
            "render",
            s.to_str().unwrap(),
            "--method",
            "sppm",
            "--photons",
            "200",
            "--out",
            out.to_str().unwrap(),
            "--cache",
            dir.0.to_str().unwrap(),
        ];
        args.extend(extra);
        let o = photonflow(&args);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let json = std::fs::read_to_string(out.join("image.json")).unwrap();
        let json: serde_json::Value = serde_json::from_str(&json).unwrap();
        let toml = std::fs::read_to_string(out.join("scene.toml")).unwrap();
        (json, toml)
    };
    // 0.5 s of passes of 200 photon paths on an 8x8 image: many more than the file's one.
    let (json, toml) = render("budget", &["--time", "0.5"]);
    assert_eq!(json["time_budget"]["stopped_by"], "time", "{json}");
    assert_eq!(json["time_budget"]["capped"], false);
    let made = json["sppm_passes"].as_u64().unwrap();
    assert!(made > 1, "{made} passes");
    assert_eq!(json["sppm"]["passes"], made);
    assert!(toml.contains(&format!("passes = {made}\n")), "{toml}");
    let snaps = json["snapshots"].as_array().unwrap();
    assert_eq!(snaps.last().unwrap()["passes"], made);
    // With --passes the time is a cap, and the count comes first.
    let (json, toml) = render("capped", &["--time", "1000", "--passes", "3"]);
    assert_eq!(json["time_budget"]["stopped_by"], "count", "{json}");
    assert_eq!(json["time_budget"]["capped"], true);
    assert_eq!(json["sppm_passes"], 3);
    assert!(toml.contains("passes = 3\n"), "{toml}");
}
