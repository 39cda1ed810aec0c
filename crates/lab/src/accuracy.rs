//! `bench-accuracy`: photonflow's progressive methods and the peer renderers at fixed time
//! budgets, all in one run (the machines are shared: only figures taken together mean
//! anything), each image scored against a reference given as two independent halves with the
//! reference's noise taken out. Each photonflow run is a whole `render --time S` command
//! (photons traced anew into an empty cache, outputs written), and each peer a whole shell
//! command, both timed from start to finish.

use render::{Overrides, Photons, RenderRequest};
use scene::{Method, Scene};
use std::path::{Path, PathBuf};
use std::time::Instant;

/// photonflow's methods in the table by default, in its column order.
pub const METHODS: [Method; 5] = [
    Method::Sppm,
    Method::Vcm,
    Method::PathSplat,
    Method::Path,
    Method::Light,
];

/// The default budgets, in seconds.
pub const BUDGETS: [f64; 4] = [2.0, 5.0, 15.0, 60.0];

/// The peers `--peer NAME` names: `tests/references/peer.sh NAME`.
pub const BUILTIN_PEERS: [&str; 7] = [
    "mitsuba",
    "mitsuba-ptracer",
    "luxcore",
    "cycles",
    "smallvcm-ppm",
    "smallvcm-bpt",
    "smallvcm-vcm",
];

/// One scene and the two independent halves of its reference.
#[derive(Clone, Debug, PartialEq)]
pub struct Case {
    pub scene: PathBuf,
    pub reference_a: PathBuf,
    pub reference_b: PathBuf,
    pub pixels: Pixels,
}

/// The pixels a case is scored over.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Pixels {
    /// Every pixel.
    #[default]
    All,
    /// Pixels whose camera rays all meet a non-delta surface first: the only ones a light
    /// tracer's reference defines (no light path joins the pinhole through glass or a
    /// mirror, nor draws the emitters it starts from), so every renderer is scored where
    /// both it and the reference see.
    DiffuseSeen,
}

/// Sub-pixel rays per axis that decide [`Pixels::DiffuseSeen`].
const MASK_RAYS: usize = 4;

/// The pixels of `scene` that `pixels` selects (`None`: all).
pub fn mask(scene: &Scene, pixels: Pixels) -> Option<film::Mask> {
    if pixels == Pixels::All {
        return None;
    }
    let (w, h) = (scene.camera.width as usize, scene.camera.height as usize);
    let diffuse = |x: f32, y: f32| {
        scene
            .geometry
            .intersect(&scene.camera.ray(x, y))
            .is_some_and(|hit| {
                scene.light_table.light_of(hit.prim).is_none()
                    && scene.bsdf_at(&hit).is_some_and(|b| !b.is_delta())
            })
    };
    let step = 1.0 / MASK_RAYS as f32;
    let pixels = (0..w * h)
        .map(|i| {
            let (x, y) = ((i % w) as f32, (i / w) as f32);
            (0..MASK_RAYS * MASK_RAYS).all(|k| {
                let (u, v) = ((k % MASK_RAYS) as f32, (k / MASK_RAYS) as f32);
                diffuse(x + (u + 0.5) * step, y + (v + 0.5) * step)
            })
        })
        .collect();
    Some(film::Mask {
        width: w,
        height: h,
        pixels,
    })
}

impl Case {
    /// `SCENE.toml,REF_A.exr,REF_B.exr` of `--case`.
    pub fn parse(s: &str) -> Result<Case, String> {
        match s.split(',').collect::<Vec<_>>().as_slice() {
            [scene, a, b] if !scene.is_empty() && !a.is_empty() && !b.is_empty() => Ok(Case {
                scene: scene.into(),
                reference_a: a.into(),
                reference_b: b.into(),
                pixels: Pixels::All,
            }),
            _ => Err(format!("`{s}`: expected SCENE.toml,REF_A.exr,REF_B.exr")),
        }
    }
}

/// The cases of a suite file: `[[case]]` tables with `scene`, `reference_a`, `reference_b`
/// and optionally `pixels` ([`Pixels`], kebab-case: `"diffuse-seen"`). Scenes are relative to the suite file, references to `refs` if given (where
/// the big reference images are kept), else to the suite file too.
pub fn read_suite(path: &Path, refs: Option<&Path>) -> Result<Vec<Case>, String> {
    #[derive(serde::Deserialize)]
    #[serde(deny_unknown_fields)]
    struct Suite {
        case: Vec<Entry>,
    }
    #[derive(serde::Deserialize)]
    #[serde(deny_unknown_fields)]
    struct Entry {
        scene: PathBuf,
        reference_a: PathBuf,
        reference_b: PathBuf,
        #[serde(default)]
        pixels: Pixels,
    }
    let err = |e: String| format!("{}: {e}", path.display());
    let text = std::fs::read_to_string(path).map_err(|e| err(e.to_string()))?;
    let suite: Suite = toml::from_str(&text).map_err(|e| err(e.to_string()))?;
    let here = path.parent().unwrap_or(Path::new(""));
    let refs = refs.unwrap_or(here);
    Ok(suite
        .case
        .into_iter()
        .map(|e| Case {
            scene: here.join(e.scene),
            reference_a: refs.join(e.reference_a),
            reference_b: refs.join(e.reference_b),
            pixels: e.pixels,
        })
        .collect())
}

/// A peer renderer: a shell command that writes a linear EXR of `$SCENE`'s view to `$OUT` in
/// about `$BUDGET` seconds (`$THREADS`: `--threads`, 0 for all cores). It may print a line `settings: ...` (the table's note says what
/// ran); when it fails, its last line on stderr is the reason shown.
#[derive(Clone, Debug, PartialEq)]
pub struct Peer {
    pub name: String,
    pub command: String,
}

impl Peer {
    /// `NAME=CMD`, or `NAME` of [`BUILTIN_PEERS`]: the repository's peer runner.
    pub fn parse(s: &str) -> Result<Peer, String> {
        if let Some((name, command)) = s.split_once('=') {
            if name.is_empty() || command.is_empty() {
                return Err(format!("`{s}`: expected NAME=COMMAND or NAME"));
            }
            return Ok(Peer {
                name: name.into(),
                command: command.into(),
            });
        }
        if !BUILTIN_PEERS.contains(&s) {
            return Err(format!(
                "`{s}`: not a built-in peer ({}); give NAME=COMMAND for another",
                BUILTIN_PEERS.join(", ")
            ));
        }
        let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tests/references/peer.sh");
        Ok(Peer {
            name: s.into(),
            command: format!(
                "bash '{}' {s} \"$SCENE\" \"$BUDGET\" \"$OUT\"",
                script.display()
            ),
        })
    }
}

/// A run: its wall seconds and corrected relative MSE.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Rung {
    pub seconds: f64,
    pub relmse: f64,
}

/// A column of the table: a method or peer, one cell per budget (or why it did not run).
#[derive(Clone, Debug, PartialEq)]
pub struct Column {
    pub name: String,
    pub cells: Vec<Result<Rung, String>>,
}

/// Seconds at which runs of growing budget first reach `target`: the first at or below it,
/// or between two, log-log interpolation (error falls as a power of time).
pub fn time_to(target: f64, rungs: &[Rung]) -> Option<f64> {
    let mut prev: Option<&Rung> = None;
    for r in rungs {
        if r.relmse <= target {
            return Some(match prev {
                Some(p) if p.relmse > target && r.relmse < p.relmse && r.relmse > 0.0 => {
                    let t = (target.ln() - p.relmse.ln()) / (r.relmse.ln() - p.relmse.ln());
                    (p.seconds.ln() + t * (r.seconds.ln() - p.seconds.ln())).exp()
                }
                _ => r.seconds,
            });
        }
        prev = Some(r);
    }
    None
}

/// The column with the lowest error at budget `i`, and that cell.
fn best(columns: &[Column], i: usize) -> Option<(&Column, Rung)> {
    columns
        .iter()
        .filter_map(|c| Some((c, *c.cells.get(i)?.as_ref().ok()?)))
        .min_by(|a, b| a.1.relmse.total_cmp(&b.1.relmse))
}

/// The markdown tables of one scene: errors per budget and column, then per budget the best
/// of each side, the peer's error over photonflow's, and photonflow's time to the peer's
/// error (its best method at that budget, interpolated over its own budgets) over the peer's.
pub fn tables(budgets: &[f64], ours: &[Column], peers: &[Column]) -> String {
    let mut s = String::new();
    let all: Vec<&Column> = ours.iter().chain(peers).collect();
    s += "| budget |";
    for c in &all {
        s += &format!(" {} |", c.name);
    }
    s += "\n|---|";
    s += &"---|".repeat(all.len());
    for (i, b) in budgets.iter().enumerate() {
        s += &format!("\n| {b} s |");
        for c in &all {
            s += &match c.cells.get(i) {
                Some(Ok(r)) => format!(" {:.5} ({:.1} s) |", r.relmse, r.seconds),
                _ => " – |".into(),
            };
        }
    }
    s += "\n\n| budget | best photonflow | best peer | error ratio (peer / photonflow) \
          | photonflow's time to the peer's error / peer's time |\n|---|---|---|---|---|";
    for (i, b) in budgets.iter().enumerate() {
        let (o, p) = (best(ours, i), best(peers, i));
        let show = |x: Option<(&Column, Rung)>| {
            x.map_or("–".into(), |(c, r)| format!("{} {:.5}", c.name, r.relmse))
        };
        let (ratio, time) = match (o, p) {
            (Some((oc, or)), Some((_, pr))) => {
                let rungs: Vec<Rung> = oc.cells.iter().filter_map(|c| c.clone().ok()).collect();
                let time = match time_to(pr.relmse, &rungs) {
                    Some(t) => format!("{:.2} ({t:.1} s / {:.1} s)", t / pr.seconds, pr.seconds),
                    None => {
                        let last = rungs.last().map_or(f64::NAN, |r| r.seconds);
                        format!("> {:.2} (not reached in {last:.1} s)", last / pr.seconds)
                    }
                };
                (format!("{:.2}", pr.relmse / or.relmse), time)
            }
            _ => ("–".into(), "–".into()),
        };
        s += &format!("\n| {b} s | {} | {} | {ratio} | {time} |", show(o), show(p));
    }
    s + "\n"
}

/// What an image is scored against: the reference's halves and the pixels scored.
pub struct Scoring {
    pub halves: film::Halves,
    pub mask: Option<film::Mask>,
}

/// The corrected relative MSE of the image at `exr`.
fn corrected(scoring: &Scoring, exr: &Path) -> Result<f64, String> {
    let img = render::output::read_finite(exr, "pixels")?;
    let m = film::metrics_halves(&img, &scoring.halves, scoring.mask.as_ref())
        .map_err(|e| format!("{}: {e}", exr.display()))?;
    Ok(m.relmse)
}

/// One `render --time` command, timed from start to finish.
fn run_ours(
    scene: &Scene,
    method: Method,
    budget: f64,
    out: &Path,
    cache: &Path,
    scoring: &Scoring,
    threads: Option<usize>,
) -> Result<Rung, String> {
    // A photon cache left from another run would make tracing free.
    let _ = std::fs::remove_dir_all(cache);
    let t0 = Instant::now();
    render::render(
        scene,
        &RenderRequest {
            overrides: Overrides {
                method: Some(method),
                time: Some(budget),
                ..Overrides::default()
            },
            cache,
            photons: Photons::TraceOrReuse,
            threads,
            out: out.to_path_buf(),
            exposure: 0.0,
            reference: None,
            label: None,
        },
    )?;
    let seconds = t0.elapsed().as_secs_f64();
    let _ = std::fs::remove_dir_all(cache);
    Ok(Rung {
        seconds,
        relmse: corrected(scoring, &out.join("image.exr"))?,
    })
}

/// Where an SPPM run's passes spent their time (`image.json`'s `time_sppm_<part>_s`), as
/// `  [eye 0.9 s, trace 1.0 s, ...]`; nothing for other methods.
fn profile(out: &Path) -> String {
    let Ok(text) = std::fs::read_to_string(out.join("image.json")) else {
        return String::new();
    };
    let Ok(j) = serde_json::from_str::<serde_json::Value>(&text) else {
        return String::new();
    };
    let parts: Vec<String> = ["eye", "trace", "index", "gather"]
        .iter()
        .filter_map(|p| {
            let t = j[format!("time_sppm_{p}_s")].as_f64()?;
            Some(format!("{p} {t:.2} s"))
        })
        .collect();
    if parts.is_empty() {
        String::new()
    } else {
        format!("  [passes: {}]", parts.join(", "))
    }
}

/// One peer command, timed; `Err` holds the reason it did not run. `note` gets the peer's
/// `settings:` line.
fn run_peer(
    peer: &Peer,
    scene: &Path,
    budget: f64,
    exr: &Path,
    scoring: &Scoring,
    threads: Option<usize>,
    note: &mut Option<String>,
) -> Result<Rung, String> {
    let _ = std::fs::remove_file(exr);
    let t0 = Instant::now();
    let out = std::process::Command::new("sh")
        .arg("-c")
        .arg(&peer.command)
        .env("OUT", exr)
        .env("BUDGET", budget.to_string())
        .env("SCENE", scene)
        .env(
            "THREADS",
            threads.map_or_else(|| "0".to_string(), |t| t.to_string()),
        )
        .output()
        .map_err(|e| format!("cannot start: {e}"))?;
    let seconds = t0.elapsed().as_secs_f64();
    let stdout = String::from_utf8_lossy(&out.stdout);
    if let Some(l) = stdout
        .lines()
        .rev()
        .find_map(|l| l.strip_prefix("settings: "))
    {
        *note = Some(l.trim().to_string());
    }
    if !out.status.success() {
        let stderr = String::from_utf8_lossy(&out.stderr);
        let last = stderr.lines().rev().find(|l| !l.trim().is_empty());
        return Err(last.unwrap_or("no message").trim().to_string());
    }
    Ok(Rung {
        seconds,
        relmse: corrected(scoring, exr)?,
    })
}

/// `bench accuracy`: every case at every budget, photonflow's methods and the peers taking
/// turns (each peer warmed up first), then each case's tables and what each peer ran, printed
/// and in a file `tables.md` in `dir`, which is published whole when every case is done.
pub fn accuracy(
    cases: &[Case],
    budgets: &[f64],
    methods: &[Method],
    peers: &[Peer],
    threads: Option<usize>,
    dir: &Path,
) -> Result<(), String> {
    if cases.is_empty() {
        return Err("no case: give --case SCENE.toml,REF_A.exr,REF_B.exr or --suite FILE".into());
    }
    if let Some(m) = methods
        .iter()
        .find(|m| render::methods::row(**m).passes.is_none())
    {
        return Err(format!(
            "--methods {m}: it renders in one go and takes no time budget (progressive \
             methods only)"
        ));
    }
    if budgets.is_empty() {
        return Err("--budgets: give at least one budget in seconds".into());
    }
    for &b in budgets {
        render::check_time("--budgets", b)?;
    }
    if threads == Some(0) {
        return Err("--threads must be at least 1".into());
    }
    // Every case's scene and reference halves are checked before anything is written.
    for case in cases {
        let scene = Scene::load(&case.scene).map_err(|e| e.to_string())?;
        for half in [&case.reference_a, &case.reference_b] {
            render::read_reference(&scene, half)?;
        }
    }
    // The directory is written whole beside its place and renamed into it at the end: a
    // stopped run (an error, a signal, kill -9) leaves the last whole one, never a mix.
    let staged = render::output::stage_as(dir, &LAYOUT)?;
    let tables = measure(cases, budgets, methods, peers, threads, staged.path())
        .map_err(|e| staged.named(e))?;
    let file = staged.path().join(TABLES);
    film::write_atomic(&file, tables.as_bytes()).map_err(|e| staged.named(e.to_string()))?;
    staged.publish()?;
    println!("\nwrote {}", dir.join(TABLES).display());
    Ok(())
}

/// What a `bench accuracy` directory holds: a directory per case (photonflow's run
/// directories, the peers' images, the reference halves' mean) and every case's tables.
pub const LAYOUT: render::output::Layout = render::output::Layout {
    what: "a bench accuracy directory",
    flag: "--dir",
    holds: |name| name == TABLES || name == "cache" || name.starts_with("case-"),
};

/// The tables of every case, as printed.
const TABLES: &str = "tables.md";

/// Every case measured into `dir`; returns the tables, which it also prints.
fn measure(
    cases: &[Case],
    budgets: &[f64],
    methods: &[Method],
    peers: &[Peer],
    threads: Option<usize>,
    dir: &Path,
) -> Result<String, String> {
    // Peers run from anywhere: give them absolute paths.
    let abs = std::fs::canonicalize(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    let cache = dir.join("cache");
    let mut all = String::new();
    for (k, case) in cases.iter().enumerate() {
        let scene = Scene::load(&case.scene).map_err(|e| e.to_string())?;
        let scene_abs = std::fs::canonicalize(&case.scene)
            .map_err(|e| format!("{}: {e}", case.scene.display()))?;
        let case_dir = abs.join(format!("case-{k}"));
        let scoring = Scoring {
            halves: crate::reference::halves(&scene, &case.reference_a, &case.reference_b)?,
            mask: mask(&scene, case.pixels),
        };
        std::fs::create_dir(&case_dir).map_err(|e| format!("{}: {e}", case_dir.display()))?;
        film::write_exr(
            case_dir.join("reference-halves-mean.exr"),
            &scoring.halves.mean,
        )
        .map_err(|e| e.to_string())?;
        println!(
            "\n{} ({}, {}x{}), reference halves {} and {}",
            scene.file.name,
            case.scene.display(),
            scene.camera.width,
            scene.camera.height,
            case.reference_a.display(),
            case.reference_b.display()
        );
        if let Some(m) = &scoring.mask {
            println!(
                "scored over the {} of {} pixels whose camera rays all meet a non-delta surface \
                 first (a light tracer's reference defines no others)",
                m.pixels.iter().filter(|p| **p).count(),
                m.pixels.len()
            );
        }
        let column = |name: &str| Column {
            name: name.into(),
            cells: Vec::new(),
        };
        let mut ours: Vec<Column> = methods.iter().map(|m| column(&m.name())).collect();
        let mut theirs: Vec<Column> = peers.iter().map(|p| column(&p.name)).collect();
        let mut notes: Vec<Option<String>> = vec![None; peers.len()];
        // A warm-up run of each peer at the smallest budget, untimed: its calibrations and
        // caches are made and its files read once before the timed runs; a peer that cannot
        // render the scene is out of every budget.
        let smallest = budgets.iter().copied().fold(f64::INFINITY, f64::min);
        let mut out_of: Vec<Option<String>> = Vec::new();
        for (p, note) in peers.iter().zip(&mut notes) {
            let exr = case_dir.join(format!("peer-{}-warm-up.exr", p.name));
            let r = run_peer(p, &scene_abs, smallest, &exr, &scoring, threads, note);
            if let Err(e) = &r {
                println!("{:<14} warm-up: did not run: {e}", p.name);
            }
            out_of.push(r.err());
        }
        for &b in budgets {
            for (m, col) in methods.iter().zip(&mut ours) {
                let out = case_dir.join(format!("{}-{b}s", m.name().replace('+', "-")));
                let r = run_ours(&scene, *m, b, &out, &cache, &scoring, threads)?;
                println!(
                    "{:<14} {b:>5} s budget {:8.2} s  relMSE {:.5}{}",
                    col.name,
                    r.seconds,
                    r.relmse,
                    profile(&out)
                );
                col.cells.push(Ok(r));
            }
            for (((p, col), note), out) in
                peers.iter().zip(&mut theirs).zip(&mut notes).zip(&out_of)
            {
                if let Some(e) = out {
                    col.cells.push(Err(e.clone()));
                    continue;
                }
                let exr = case_dir.join(format!("peer-{}-{b}s.exr", p.name));
                let r = run_peer(p, &scene_abs, b, &exr, &scoring, threads, note);
                match &r {
                    Ok(r) => println!(
                        "{:<14} {b:>5} s budget {:8.2} s  relMSE {:.5}",
                        p.name, r.seconds, r.relmse
                    ),
                    Err(e) => println!("{:<14} {b:>5} s budget  did not run: {e}", p.name),
                }
                col.cells.push(r);
            }
        }
        use std::fmt::Write;
        let mut s = format!(
            "\n{}, {}x{}: corrected relative MSE (wall seconds)\n\n",
            scene.file.name, scene.camera.width, scene.camera.height
        );
        s += &tables(budgets, &ours, &theirs);
        s += "\nphotonflow: `render --method M --time S` on all cores, photons traced anew per \
              run; each peer ran once untimed at the smallest budget first (calibrations, \
              caches).\n";
        for ((p, col), note) in peers.iter().zip(&theirs).zip(&notes) {
            let failed: Vec<String> = col.cells.iter().filter_map(|c| c.clone().err()).collect();
            let how = note.clone().unwrap_or_else(|| format!("`{}`", p.command));
            let _ = match failed.first() {
                Some(e) => writeln!(s, "{}: {how}; – : {e}", p.name),
                None => writeln!(s, "{}: {how}", p.name),
            };
        }
        print!("{s}");
        all += &s;
    }
    Ok(all)
}
