//! Faults the binary must survive: kill -9 at any instant of `trace`, `render`, `merge` and
//! `evidence` (the output directory complete or absent, the photon cache only whole sets and
//! the reference cache only whole runs, the rerun's images the uninterrupted run's bit for
//! bit) and part way through `bench-accuracy` (its last whole directory kept); a disk that
//! fills during a run and an output place that cannot be written, wholly or in part (one
//! line naming the path and the OS error, nothing half written, the cache still good).

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::Instant;

/// A scratch directory, removed when dropped.
struct Work(PathBuf);

impl Work {
    fn new(name: &str) -> Work {
        let dir =
            std::env::temp_dir().join(format!("photonflow-faults-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        Work(dir)
    }
}

impl Drop for Work {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// The analytic Cornell box with its silver and glass spheres (caustics for every method) at
/// `size` x `size` pixels, written into `dir`.
fn scene(dir: &Path, size: u32) -> String {
    let root = concat!(env!("CARGO_MANIFEST_DIR"), "/../../scenes/cornell-spheres");
    let text = std::fs::read_to_string(format!("{root}/analytic.toml"))
        .unwrap()
        .replace("width = 512", &format!("width = {size}"))
        .replace("height = 512", &format!("height = {size}"))
        .replace(
            "obj = \"CornellBox.obj\"",
            &format!("obj = \"{root}/CornellBox.obj\""),
        );
    let path = dir.join("scene.toml");
    std::fs::write(&path, text).unwrap();
    path.to_str().unwrap().to_string()
}

fn photonflow(args: &[String]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_photonflow"))
        .args(args)
        .output()
        .unwrap()
}

fn path_str(p: &Path) -> String {
    p.to_str().unwrap().to_string()
}

/// `render SCENE --method METHOD EXTRA...` on one thread, its photon sets cached in `cache`,
/// into `out`.
fn render_args(scene: &str, method: &str, extra: &[&str], cache: &Path, out: &Path) -> Vec<String> {
    let mut args: Vec<String> = ["render", scene, "--method", method]
        .iter()
        .chain(extra)
        .map(|a| a.to_string())
        .collect();
    args.extend([
        "--threads".into(),
        "1".into(),
        "--cache".into(),
        path_str(cache),
    ]);
    args.extend(["--out".into(), path_str(out)]);
    args
}

/// Every file under `dir` (relative paths) with its bytes; an absent `dir` is empty.
fn tree(dir: &Path) -> BTreeMap<String, Vec<u8>> {
    let mut found = BTreeMap::new();
    let mut todo = vec![dir.to_path_buf()];
    while let Some(d) = todo.pop() {
        for e in std::fs::read_dir(&d).into_iter().flatten().flatten() {
            if e.file_type().unwrap().is_dir() {
                todo.push(e.path());
            } else {
                let rel = e.path().strip_prefix(dir).unwrap().display().to_string();
                found.insert(rel, std::fs::read(e.path()).unwrap_or_default());
            }
        }
    }
    found
}

fn is_temp(rel: &str) -> bool {
    rel.split('/').any(|n| temps::owner(n).is_some())
}

/// The temps directly in `dir` (staging directories of run directories, photon temp files).
fn temps_in(dir: &Path) -> Vec<String> {
    std::fs::read_dir(dir)
        .into_iter()
        .flatten()
        .flatten()
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| temps::owner(n).is_some())
        .collect()
}

/// What of an output file two runs of one command must agree on: every byte, except where
/// it records timings. A run directory's `image.json` and the evidence report's tables, pages
/// and plots against time hold seconds, so only their presence counts; `evidence.json` counts
/// with its `seconds` taken out (every error, bias and variance figure stays).
fn deterministic(name: &str, bytes: &[u8]) -> Option<Vec<u8>> {
    let file = name.rsplit('/').next().unwrap_or(name);
    if file == "evidence.json" {
        fn strip(v: &mut serde_json::Value) {
            match v {
                serde_json::Value::Object(m) => {
                    m.remove("seconds");
                    m.values_mut().for_each(strip);
                }
                serde_json::Value::Array(a) => a.iter_mut().for_each(strip),
                _ => {}
            }
        }
        let mut v: serde_json::Value = serde_json::from_slice(bytes).ok()?;
        strip(&mut v);
        return Some(v.to_string().into_bytes());
    }
    let timed = ["image.json", "evidence.md", "report.md", "report.html"].contains(&file)
        || file.ends_with("-vs-time.svg");
    (!timed).then(|| bytes.to_vec())
}

/// `out` is absent or holds what the uninterrupted run's directory `reference` holds: the
/// same files, each the same in what is [`deterministic`] (images bit for bit).
fn complete_or_absent(out: &Path, reference: &BTreeMap<String, Vec<u8>>, what: &str) {
    if !out.exists() {
        return;
    }
    let got = tree(out);
    let names = |t: &BTreeMap<String, Vec<u8>>| t.keys().cloned().collect::<Vec<_>>();
    assert_eq!(names(&got), names(reference), "{what}: a partial directory");
    for (name, bytes) in reference {
        assert!(
            deterministic(name, &got[name]) == deterministic(name, bytes),
            "{what}: {name} differs"
        );
    }
}

/// Every photon file in `cache` reads whole with its checksums and is the uninterrupted run's
/// file; other files there (a cached reference's run directory) are the uninterrupted run's
/// too in what is [`deterministic`], or (`temps_ok`) the temps of a killed process.
fn cache_valid(cache: &Path, reference: &BTreeMap<String, Vec<u8>>, temps_ok: bool, what: &str) {
    for (name, bytes) in tree(cache) {
        if is_temp(&name) {
            assert!(temps_ok, "{what}: the rerun kept {name} in the cache");
            continue;
        }
        if name.ends_with(".photons") {
            let r = store::StoreReader::open(&cache.join(&name))
                .unwrap_or_else(|e| panic!("{what}: {e}"));
            r.read_all().unwrap_or_else(|e| panic!("{what}: {e}"));
        }
        assert!(
            reference
                .get(&name)
                .is_some_and(|r| deterministic(&name, r) == deterministic(&name, &bytes)),
            "{what}: the cache's {name} is not the uninterrupted run's"
        );
    }
}

/// A fixed sequence of numbers in [0, 1) (xorshift64*): the kill instants of every run of the
/// test are the same.
struct Instants(u64);

impl Instants {
    fn next(&mut self) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        (self.0.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// One command of the harness: what it writes (an output directory `out`, which holds
/// `whole` once complete; its cache).
struct Case {
    name: &'static str,
    args: Vec<String>,
    out: Option<PathBuf>,
    whole: &'static str,
    cache: PathBuf,
}

/// What the kill -9 runs of a case came to.
#[derive(Default)]
struct Tally {
    instants: usize,
    killed: usize,
}

/// Runs `case` uninterrupted (from an empty cache, then with the cache warm), then `n` times:
/// starts it (every other time from no output and no cache, else over the last run's), kills
/// it with SIGKILL after a delay spread over the run's measured duration, checks what it left,
/// reruns it and checks the result against the uninterrupted run.
fn kill_at_instants(case: &Case, n: usize, instants: &mut Instants) -> Tally {
    let reset = || {
        let _ = std::fs::remove_dir_all(&case.cache);
        if let Some(out) = &case.out {
            let _ = std::fs::remove_dir_all(out);
        }
    };
    let timed = || {
        let t0 = Instant::now();
        let o = photonflow(&case.args);
        let e = String::from_utf8_lossy(&o.stderr);
        assert!(o.status.success(), "{}: {e}", case.name);
        t0.elapsed()
    };
    reset();
    let cold = timed();
    let out_ref = case.out.as_deref().map(tree).unwrap_or_default();
    let cache_ref = tree(&case.cache);
    let warm = timed();
    let check_rerun = |what: &str| {
        if let Some(out) = &case.out {
            assert!(
                out.join(case.whole).is_file(),
                "{what}: no output directory"
            );
            complete_or_absent(out, &out_ref, what);
            let beside = temps_in(out.parent().unwrap());
            assert!(beside.is_empty(), "{what}: kept {beside:?}");
        }
        cache_valid(&case.cache, &cache_ref, false, what);
    };
    check_rerun(&format!("{}: the warm run", case.name));

    let mut tally = Tally::default();
    for i in 0..n {
        let from_nothing = i % 2 == 0;
        if from_nothing {
            reset();
        }
        let span = if from_nothing { cold } else { warm };
        let delay = span.mul_f64(1.1 * instants.next());
        let what = format!("{}: kill -9 {} ms in ({i})", case.name, delay.as_millis());
        let mut child = Command::new(env!("CARGO_BIN_EXE_photonflow"))
            .args(&case.args)
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .unwrap();
        std::thread::sleep(delay);
        let pid = nix::unistd::Pid::from_raw(child.id() as i32);
        // Not yet reaped, so the pid is still the child's even if it has exited.
        nix::sys::signal::kill(pid, nix::sys::signal::Signal::SIGKILL).unwrap();
        let status = child.wait().unwrap();
        tally.instants += 1;
        if !status.success() {
            tally.killed += 1;
        }
        if let Some(out) = &case.out {
            complete_or_absent(out, &out_ref, &what);
        }
        cache_valid(&case.cache, &cache_ref, true, &what);

        let o = photonflow(&case.args);
        let e = String::from_utf8_lossy(&o.stderr);
        assert!(o.status.success(), "{what}, then the rerun: {e}");
        check_rerun(&format!("{what}, then the rerun"));
    }
    tally
}

/// kill -9 at 72 instants of `trace`, `render` (SPPM, path+splat, final gathering, each
/// tracing into its photon cache), `merge` and `evidence` (rendering its reference into its
/// cache), each followed by the same command again.
#[cfg(unix)]
#[test]
fn kill_9_at_any_instant_leaves_whole_outputs_and_a_good_cache() {
    let work = Work::new("kill");
    let scene = scene(&work.0, 24);
    let cache = work.0.join("cache");
    let runs = work.0.join("runs");
    let s = |v: &[&str]| v.iter().map(|a| a.to_string()).collect::<Vec<String>>();
    let render = |method: &str, budget: &[&str], name: &str| {
        let out = runs.join(name);
        let extra = [&["--photons", "5000"], budget].concat();
        (render_args(&scene, method, &extra, &cache, &out), out)
    };
    // The shard the merge reads, rendered once.
    let shard = work.0.join("shard");
    let o = photonflow(&s(&[
        "render",
        &scene,
        "--method",
        "path",
        "--spp",
        "4",
        "--shard",
        "0/1",
        "--threads",
        "1",
        "--out",
        &path_str(&shard),
    ]));
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));

    let mut cases = vec![Case {
        name: "trace",
        args: s(&[
            "trace",
            &scene,
            "--photons",
            "20000",
            "--threads",
            "1",
            "--force",
            "--cache",
            &path_str(&cache),
        ]),
        out: None,
        whole: "",
        cache: cache.clone(),
    }];
    for (name, method, budget) in [
        ("sppm", "sppm", &["--passes", "4"][..]),
        ("path+splat", "path+splat", &["--spp", "2"][..]),
        ("final-gather", "final-gather", &["--spp", "1"][..]),
    ] {
        let (args, out) = render(method, budget, name);
        cases.push(Case {
            name,
            args,
            out: Some(out),
            whole: "image.json",
            cache: cache.clone(),
        });
    }
    let merged = runs.join("merged");
    cases.push(Case {
        name: "merge",
        args: s(&["merge", &path_str(&shard), "--out", &path_str(&merged)]),
        out: Some(merged),
        whole: "image.json",
        // The merge of image shards reads no photons: an empty place.
        cache: work.0.join("no-cache"),
    });
    // Its quickest form: a 16-spp reference, two seeds, three techniques (the path tracer,
    // a global map and the caustic map, whose photon sets it traces into its directory) at
    // a fiftieth of `--quick`'s budgets; the report, maps and plots as a full run has them.
    let evidence = runs.join("evidence");
    let references = work.0.join("references");
    cases.push(Case {
        name: "evidence",
        args: s(&[
            "evidence",
            &scene,
            "--quick",
            "--seeds",
            "2",
            "--reference-spp",
            "16",
            "--budget-scale",
            "0.02",
            "--only",
            "path",
            "--only",
            "global-map-box",
            "--only",
            "caustic-map-k-nn",
            "--threads",
            "1",
            "--cache",
            &path_str(&references),
            "--out",
            &path_str(&evidence),
        ]),
        out: Some(evidence),
        whole: "report.html",
        cache: references,
    });

    let mut instants = Instants(0x9e37_79b9_7f4a_7c15);
    let (mut tried, mut killed) = (0, 0);
    for case in &cases {
        let t = kill_at_instants(case, 12, &mut instants);
        println!(
            "kill -9 harness: {}: {} instants, {} killed before the end",
            case.name, t.instants, t.killed
        );
        tried += t.instants;
        killed += t.killed;
    }
    println!("kill -9 harness: {tried} instants tried, {killed} killed before the end");
    assert!(tried >= 50);
}

/// A tmpfs mounted for a test, unmounted when dropped (a failed assertion included).
struct Mount(PathBuf);

impl Drop for Mount {
    fn drop(&mut self) {
        // A mount moved away with the directory that held it is unmounted where it went.
        let _ = Command::new("umount")
            .arg(&self.0)
            .stderr(Stdio::null())
            .status();
    }
}

/// Mounts a tmpfs with `options` at `dir` (made if missing); `None`, with the reason printed,
/// where this machine cannot, unless `PHOTONFLOW_REQUIRE_FAULTS` is set (CI), which fails.
fn tmpfs(dir: &Path, options: &str) -> Option<Mount> {
    std::fs::create_dir_all(dir).unwrap();
    let why = match Command::new("mount")
        .args(["-t", "tmpfs", "-o", options, "tmpfs"])
        .arg(dir)
        .output()
    {
        Ok(o) if o.status.success() => return Some(Mount(dir.to_path_buf())),
        Ok(o) => String::from_utf8_lossy(&o.stderr).trim().to_string(),
        Err(e) => format!("cannot run mount: {e}"),
    };
    let why = format!(
        "cannot mount a tmpfs ({options}) at {}: {why}",
        dir.display()
    );
    assert!(
        std::env::var_os("PHOTONFLOW_REQUIRE_FAULTS").is_none(),
        "PHOTONFLOW_REQUIRE_FAULTS is set: {why}"
    );
    println!("skipped: {why}");
    None
}

/// The one `error:` line of a failed run's stderr (progress lines aside).
fn error_line(o: &std::process::Output, what: &str) -> String {
    let e = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{what}: {e}");
    assert!(!e.contains("panicked"), "{what}: {e}");
    let errors: Vec<&str> = e.lines().filter(|l| l.starts_with("error:")).collect();
    assert_eq!(errors.len(), 1, "{what}: {e}");
    errors[0].to_string()
}

/// Output and cache on a 2 MB filesystem: the photon files fit, the run directory (SPPM's
/// snapshots at 200 x 200) fills it. One line names the file and the OS error, nothing of the
/// run directory is left, and the cache's whole sets serve the next run.
#[test]
fn a_full_disk_leaves_no_partial_output_and_a_good_cache() {
    let work = Work::new("full");
    let small = scene(&work.0, 200);
    let Some(m) = tmpfs(&work.0.join("disk"), "size=2m") else {
        return;
    };
    let cache = m.0.join("cache");
    let out = m.0.join("run");
    let args = |out: &Path| {
        let extra = ["--passes", "4", "--photons", "20000"];
        render_args(&small, "sppm", &extra, &cache, out)
    };
    // The photon sets first (about 1.5 MB), then the run that fills the disk.
    let trace = [
        "trace",
        &small,
        "--photons",
        "20000",
        "--threads",
        "1",
        "--cache",
        &path_str(&cache),
    ];
    let o = photonflow(&trace.map(String::from));
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let o = photonflow(&args(&out));
    let line = error_line(&o, "a full disk");
    assert!(
        line.contains(&path_str(&out)) && line.contains("No space left on device"),
        "{line}"
    );
    assert!(!line.contains(".tmp-"), "names a staging path: {line}");
    assert!(!out.exists(), "a partial run directory");
    let left: Vec<String> = tree(&m.0).into_keys().filter(|n| is_temp(n)).collect();
    assert!(left.is_empty(), "left {left:?}");
    let sets: Vec<String> = tree(&cache)
        .into_keys()
        .filter(|n| n.ends_with(".photons"))
        .collect();
    assert_eq!(sets.len(), 2, "{sets:?}");
    for name in &sets {
        let r = store::StoreReader::open(&cache.join(name)).unwrap();
        r.read_all().unwrap();
    }
    // The next run, with room for its output, estimates from the cache alone.
    let elsewhere = work.0.join("run");
    let mut a = args(&elsewhere);
    a[0] = "estimate".into();
    a[2..5].clone_from_slice(&["--method".into(), "final-gather".into(), "--spp".into()]);
    a[5] = "1".into();
    let o = photonflow(&a);
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{e}");
    assert!(elsewhere.join("image.json").is_file());
}

/// An output place that cannot be written (a read-only filesystem: root ignores modes): one
/// line naming the path and the OS error, nothing written; a run directory already there
/// stays whole, and the photon cache elsewhere serves the next run.
#[test]
fn a_read_only_output_place_is_one_line_and_keeps_what_is_there() {
    let work = Work::new("readonly");
    let small = scene(&work.0, 16);
    let cache = work.0.join("cache");
    let place = work.0.join("ro");
    let Some(m) = tmpfs(&place, "size=1m") else {
        return;
    };
    let out = m.0.join("run");
    let args = |method: &str| render_args(&small, method, &["--photons", "5000"], &cache, &out);
    let o = photonflow(&args("sppm"));
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let before = tree(&out);
    let o = Command::new("mount")
        .args(["-o", "remount,ro"])
        .arg(&m.0)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    for (what, method) in [("over a run", "final-gather"), ("beside it", "sppm")] {
        let target = if what == "beside it" {
            m.0.join("new")
        } else {
            out.clone()
        };
        let mut a = args(method);
        *a.last_mut().unwrap() = path_str(&target);
        let o = photonflow(&a);
        let line = error_line(&o, what);
        assert!(
            line.contains(&path_str(&target)) && line.contains("Read-only file system"),
            "{what}: {line}"
        );
    }
    assert!(tree(&out) == before, "the run directory there changed");
    assert!(!m.0.join("new").exists());
    let o = photonflow(&{
        let mut a = args("final-gather");
        *a.last_mut().unwrap() = path_str(&work.0.join("run"));
        a
    });
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{e}");
    assert!(!e.contains("photons: traced"), "traced again: {e}");
}

/// `bench-accuracy` killed (kill -9) part way, after it rendered a case's first runs: its
/// directory is the last whole run's, every file bit for bit (the runs' `image.json` record
/// their seconds, so a directory written in place would differ), the tables included; the
/// next run replaces it whole and leaves nothing beside it.
#[cfg(unix)]
#[test]
fn a_killed_bench_accuracy_leaves_its_last_whole_directory() {
    use std::os::unix::process::ExitStatusExt;
    let work = Work::new("bench");
    let scene = scene(&work.0, 16);
    let half = |name: &str, v: f32| {
        let p = work.0.join(name);
        film::write_exr(&p, &film::Image::from_fn(16, 16, |_, _| [v; 3])).unwrap();
        path_str(&p)
    };
    let (a, b) = (half("a.exr", 0.5), half("b.exr", 0.6));
    let dir = work.0.join("accuracy");
    // A peer that copies a half to $OUT; with `$KILL` set, its runs after the warm-up kill
    // the bench (the shell's parent) instead.
    let mark = work.0.join("warmed-up");
    let peer = format!(
        "copy=if [ -n \"$KILL\" ] && [ -e '{m}' ]; then kill -9 $PPID; exit 1; fi; touch '{m}'; \
         cp '{a}' \"$OUT\"",
        m = path_str(&mark)
    );
    let run = |kill: bool| {
        let _ = std::fs::remove_file(&mark);
        let mut c = Command::new(env!("CARGO_BIN_EXE_photonflow"));
        c.args(["bench-accuracy", "--case"])
            .arg(format!("{scene},{a},{b}"))
            .args([
                "--methods",
                "path",
                "--budgets",
                "0.05,0.1",
                "--threads",
                "1",
            ])
            .args(["--peer", &peer, "--dir", &path_str(&dir)]);
        if kill {
            c.env("KILL", "1");
        }
        c.output().unwrap()
    };
    let o = run(false);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let whole = tree(&dir);
    let complete = |t: &BTreeMap<String, Vec<u8>>| {
        for f in [
            "tables.md",
            "case-0/path-0.05s/image.json",
            "case-0/peer-copy-0.1s.exr",
        ] {
            assert!(t.contains_key(f), "no {f}: {:?}", t.keys());
        }
    };
    complete(&whole);
    let o = run(true);
    assert_eq!(
        o.status.signal(),
        Some(9),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    assert!(
        tree(&dir) == whole,
        "the killed run changed {}",
        dir.display()
    );
    let o = run(false);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let again = tree(&dir);
    complete(&again);
    assert_ne!(
        again["case-0/path-0.05s/image.json"],
        whole["case-0/path-0.05s/image.json"]
    );
    let beside = temps_in(&work.0);
    assert!(beside.is_empty(), "kept {beside:?}");
}

/// Makes `dir` a read-only bind mount of itself (the rest of its filesystem stays writable);
/// `None` as [`tmpfs`] says.
fn read_only(dir: &Path) -> Option<Mount> {
    let run = |args: &[&str]| {
        Command::new("mount")
            .args(args)
            .arg(dir)
            .output()
            .map_err(|e| format!("cannot run mount: {e}"))
            .and_then(|o| {
                o.status
                    .success()
                    .then_some(())
                    .ok_or_else(|| String::from_utf8_lossy(&o.stderr).trim().to_string())
            })
    };
    let why = match run(&["--bind", dir.to_str().unwrap()]) {
        Ok(()) => {
            let m = Mount(dir.to_path_buf());
            match run(&["-o", "remount,bind,ro"]) {
                Ok(()) => return Some(m),
                Err(e) => e,
            }
        }
        Err(e) => e,
    };
    let why = format!("cannot bind {} read-only: {why}", dir.display());
    assert!(
        std::env::var_os("PHOTONFLOW_REQUIRE_FAULTS").is_none(),
        "PHOTONFLOW_REQUIRE_FAULTS is set: {why}"
    );
    println!("skipped: {why}");
    None
}

/// Whether `dir` holds a whole run directory: `image.json` and every file it implies (the
/// images, the resolved scene, each layer it lists). Returns the run's method.
fn whole_run(dir: &Path) -> Option<String> {
    let json: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.join("image.json")).ok()?).ok()?;
    let files = ["image.exr", "image.png", "scene.toml"];
    let layers = json["layers"]
        .as_object()?
        .keys()
        .map(|name| dir.join("layers").join(format!("{name}.exr")));
    let all = files.iter().map(|f| dir.join(f)).chain(layers);
    all.into_iter()
        .all(|p| p.is_file())
        .then(|| json["method"].as_str().unwrap_or("?").to_string())
}

/// A run directory part of which cannot be written (its `layers/` a read-only mount, the rest
/// writable) is replaced whole, or kept whole: never the old run without its `image.json`
/// (runs used to remove the old `image.json` and `scene.toml` first, then fail on the
/// layers). The new run is published; the old one, set aside, cannot be removed, which one
/// warning line says, naming it and the OS error; once it can be, the next run removes it.
#[test]
fn a_run_directory_partly_read_only_is_replaced_whole() {
    let work = Work::new("partly");
    let small = scene(&work.0, 16);
    let cache = work.0.join("cache");
    let out = work.0.join("run");
    let render = |method: &str| {
        photonflow(&render_args(
            &small,
            method,
            &["--photons", "5000"],
            &cache,
            &out,
        ))
    };
    let o = render("sppm");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let Some(mount) = read_only(&out.join("layers")) else {
        return;
    };
    let o = render("final-gather");
    let e = String::from_utf8_lossy(&o.stderr);
    // The mount moved with the old run directory set aside: unmount it there.
    let aside = temps_in(&work.0);
    let moved: Vec<Mount> = aside
        .iter()
        .map(|a| Mount(work.0.join(a).join("layers")))
        .collect();
    drop(mount);
    assert!(!e.contains("panicked"), "{e}");
    assert_eq!(o.status.code(), Some(0), "{e}");
    assert_eq!(
        whole_run(&out).as_deref(),
        Some("final-gather"),
        "{} is not a whole run: {:?}",
        out.display(),
        tree(&out).keys()
    );
    assert_eq!(aside.len(), 1, "{aside:?}");
    let warning: Vec<&str> = e.lines().filter(|l| l.starts_with("warning:")).collect();
    assert_eq!(warning.len(), 1, "{e}");
    assert!(
        warning[0].contains(&path_str(&work.0.join(&aside[0])))
            && warning[0].contains("Read-only file system"),
        "{}",
        warning[0]
    );
    drop(moved);
    let o = render("final-gather");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(temps_in(&work.0), Vec::<String>::new());
}
