//! `bench-accuracy`: the time each method needs to reach the error of a 256-spp path-traced
//! image, against one long path-traced reference, all in one run (the machines are shared:
//! only ratios taken together mean anything). Each run is a whole `render` command (photons
//! traced anew into an empty cache, outputs written), timed from start to finish.

use render::Photons;
use render::{Overrides, RenderRequest};
use scene::{Method, Scene};
use std::path::Path;
use std::time::Instant;

/// One rung of a method's ladder: its budget, wall seconds and relative MSE.
struct Rung {
    budget: String,
    seconds: f64,
    relmse: f64,
}

/// Reads `image.json`'s snapshots of a progressive run: (passes, seconds, relmse).
fn snapshots(out: &Path) -> Result<Vec<(u32, f64, f64)>, String> {
    let path = out.join("image.json");
    let text = std::fs::read_to_string(&path).map_err(|e| format!("{}: {e}", path.display()))?;
    let j: serde_json::Value =
        serde_json::from_str(&text).map_err(|e| format!("{}: {e}", path.display()))?;
    Ok(j["snapshots"]
        .as_array()
        .map(|a| {
            a.iter()
                .filter_map(|s| {
                    Some((
                        s["passes"].as_u64()? as u32,
                        s["seconds"].as_f64()?,
                        s["relmse"].as_f64()?,
                    ))
                })
                .collect()
        })
        .unwrap_or_default())
}

/// Seconds at which a ladder first reaches `target`: the first rung at or below it, or
/// between two rungs, log-log interpolation (error falls as a power of time).
fn time_to(target: f64, rungs: &[Rung]) -> Option<f64> {
    let mut prev: Option<&Rung> = None;
    for r in rungs {
        if r.relmse <= target {
            return Some(match prev {
                Some(p) if p.relmse > target && r.relmse < p.relmse => {
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

/// One `render` command, timed; returns (seconds, relmse against `reference`).
fn run_one(
    scene: &Scene,
    method: Method,
    spp: Option<u32>,
    passes: Option<u32>,
    out: &Path,
    reference: Option<&Path>,
    cache: &Path,
) -> Result<(f64, f64), String> {
    // A photon cache left from another run would make tracing free.
    let _ = std::fs::remove_dir_all(cache);
    let t0 = Instant::now();
    let summary = render::render(
        scene,
        &RenderRequest {
            overrides: Overrides {
                method: Some(method),
                spp,
                passes,
                ..Overrides::default()
            },
            cache,
            photons: Photons::TraceOrReuse,
            threads: None,
            out: out.to_path_buf(),
            exposure: 0.0,
            reference,
            label: None,
        },
    )?;
    let seconds = t0.elapsed().as_secs_f64();
    let _ = std::fs::remove_dir_all(cache);
    Ok((seconds, summary.metrics.map_or(f64::NAN, |m| m.relmse)))
}

/// A peer renderer: a shell command that writes a linear EXR to the path in `$OUT`.
pub struct Peer {
    pub name: String,
    pub command: String,
}

/// The relative MSE of the image at `exr` with the reference's noise taken out, when the
/// reference came as two halves (else nothing).
fn corrected(halves: Option<&film::Halves>, exr: &Path) -> Result<String, String> {
    let Some(h) = halves else {
        return Ok(String::new());
    };
    let img = render::output::read_finite(exr, "pixels")?;
    let m = film::metrics_halves(&img, h, None).map_err(|e| format!("{}: {e}", exr.display()))?;
    Ok(format!("  (reference noise out: {:.5})", m.relmse))
}

/// `bench accuracy`. `reference_b`: the second independent half of a given `reference`; the
/// plain errors are then against the halves' mean, each with the reference's noise taken out
/// beside it (time to the target stays on the plain figures, the path tracer's included).
pub fn accuracy(
    path: &Path,
    given_reference: Option<&Path>,
    reference_b: Option<&Path>,
    reference_spp: u32,
    peers: &[Peer],
    dir: &Path,
) -> Result<(), String> {
    let scene = Scene::load(path).map_err(|e| e.to_string())?;
    let (reference, halves) = match (given_reference, reference_b) {
        (Some(a), Some(b)) => {
            let mean = dir.join("reference-halves-mean.exr");
            let h = crate::reference::halves(&scene, a, b, &mean)?;
            (mean, Some(h))
        }
        (None, Some(b)) => {
            return Err(format!(
                "--reference-b {}: the second half needs the first (--reference)",
                b.display()
            ));
        }
        _ => (
            crate::reference::reference(&scene, given_reference, reference_spp, dir, None)?.exr,
            None,
        ),
    };
    let halves = halves.as_ref();
    std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    let cache = dir.join("cache");
    let mut table: Vec<(String, Vec<Rung>)> = Vec::new();
    let ladder = |name: &str, method: Method, budgets: &[u32], stop: Option<f64>| {
        let mut rungs = Vec::new();
        for &b in budgets {
            let out = dir.join(format!("{}-{b}", method.name().replace('+', "-")));
            let (seconds, relmse) = run_one(
                &scene,
                method,
                Some(b),
                None,
                &out,
                Some(&reference),
                &cache,
            )?;
            let c = corrected(halves, &out.join("image.exr"))?;
            println!("{name:<13} {b:>5} spp  {seconds:8.2} s  relMSE {relmse:.5}{c}");
            rungs.push(Rung {
                budget: format!("{b} spp"),
                seconds,
                relmse,
            });
            if stop.is_some_and(|t| relmse <= t) {
                break;
            }
        }
        Ok::<Vec<Rung>, String>(rungs)
    };
    // The path tracer sets the target: its 256-spp image's error.
    let path_rungs = ladder("path", Method::Path, &[64, 128, 256], None)?;
    let target = path_rungs.last().map_or(f64::NAN, |r| r.relmse);
    let path_time = path_rungs.last().map_or(f64::NAN, |r| r.seconds);
    println!("target: relMSE {target:.5} (path, 256 spp, {path_time:.2} s)");
    table.push(("path".into(), path_rungs));
    let stop = Some(target);
    table.push((
        "path+splat".into(),
        ladder(
            "path+splat",
            Method::PathSplat,
            &[4, 8, 16, 32, 64, 128],
            stop,
        )?,
    ));
    table.push((
        "final-gather".into(),
        ladder("final-gather", Method::FinalGather, &[1, 2, 4, 8, 16], stop)?,
    ));
    // The global map shown directly: its bias stays at any budget (which is why `estimate`
    // defaults to final gathering).
    table.push((
        "global-direct".into(),
        ladder("global-direct", Method::GlobalDirect, &[1, 4, 16], stop)?,
    ));
    // SPPM: one run, its snapshots are the ladder.
    let out = dir.join("sppm");
    let (seconds, relmse) = run_one(
        &scene,
        Method::Sppm,
        None,
        Some(64),
        &out,
        Some(&reference),
        &cache,
    )?;
    let c = corrected(halves, &out.join("image.exr"))?;
    println!("sppm             64 passes {seconds:8.2} s  relMSE {relmse:.5}{c} (whole run)");
    // Snapshot times count from the first pass; the run's loading and writing come on top.
    let snaps = snapshots(&out)?;
    let overhead = snaps
        .last()
        .map_or(0.0, |&(_, s, _)| (seconds - s).max(0.0));
    let mut rungs = Vec::new();
    for (p, s, e) in snaps {
        let s = s + overhead;
        let c = corrected(halves, &out.join(format!("snapshots/pass-{p:05}.exr")))?;
        println!("sppm          {p:>5} passes {s:8.2} s  relMSE {e:.5}{c} (snapshot)");
        rungs.push(Rung {
            budget: format!("{p} passes"),
            seconds: s,
            relmse: e,
        });
    }
    table.push(("sppm".into(), rungs));
    // Peers run from anywhere: give them an absolute path.
    let abs = std::fs::canonicalize(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    for peer in peers {
        let exr = abs.join(format!("peer-{}.exr", peer.name));
        let _ = std::fs::remove_file(&exr);
        let t0 = Instant::now();
        let status = std::process::Command::new("sh")
            .arg("-c")
            .arg(&peer.command)
            .env("OUT", &exr)
            .stdout(std::process::Stdio::null())
            .status()
            .map_err(|e| format!("peer {}: {e}", peer.name))?;
        let seconds = t0.elapsed().as_secs_f64();
        if !status.success() {
            return Err(format!(
                "peer {}: `{}` failed ({status})",
                peer.name, peer.command
            ));
        }
        let m = render::output::compare(&exr, &reference, None)?;
        let c = corrected(halves, &exr)?;
        println!(
            "{:<13} {seconds:8.2} s  relMSE {:.5}{c} (incl. start-up)",
            peer.name, m.relmse
        );
        // The comparison the path tracer is judged by: its time to the peer's error.
        let path = table.first().map_or(&[][..], |(_, r)| r.as_slice());
        match time_to(m.relmse, path) {
            Some(t) => println!(
                "{:<13} the path tracer reaches its relMSE {:.5} in {t:.2} s: {:.2}x {}'s time",
                "",
                m.relmse,
                t / seconds,
                peer.name
            ),
            None => println!(
                "{:<13} the path tracer's ladder does not reach its relMSE {:.5}",
                "", m.relmse
            ),
        }
        table.push((
            peer.name.clone(),
            vec![Rung {
                budget: "peer".into(),
                seconds,
                relmse: m.relmse,
            }],
        ));
    }
    println!(
        "\ntime to the 256-spp path tracer's relMSE {target:.5}, and the path tracer's time over it:"
    );
    println!("| method | time to target (s) | path tracer's time / method's | best rung |");
    println!("|---|---|---|---|");
    for (name, rungs) in &table {
        let best = rungs
            .iter()
            .min_by(|a, b| a.relmse.total_cmp(&b.relmse))
            .map_or(String::new(), |r| {
                format!("{}: {:.5} in {:.2} s", r.budget, r.relmse, r.seconds)
            });
        match time_to(target, rungs) {
            Some(t) => println!("| {name} | {t:.2} | {:.2}x | {best} |", path_time / t),
            None => println!("| {name} | not reached | - | {best} |"),
        }
    }
    Ok(())
}
