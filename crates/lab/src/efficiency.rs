//! `bench-path`: the path tracer's efficiency against Mitsuba 3's path tracer at equal
//! samples per pixel, `1 / (relMSE x seconds)`, the figure of merit of Veach 1997 §2.4 (and
//! pbrt-v4 §2.1.4: variance times time).
//!
//! Each renderer runs `runs` times per scene and sample count (seeds 1, 2, ...; photonflow
//! and Mitsuba alternating, so a change in the machine's load falls on both), each run a
//! fresh process timed from start to finish, as a user would run it: photonflow's `render
//! --method path`, Mitsuba through `tests/references/peer.sh mitsuba` (JIT start-up included).
//! Both are unbiased, so a run's error is its noise: the per-pixel sample variance over the
//! runs, relative to the square of the mean of every run of both renderers plus 0.01 (the
//! relMSE of the other benchmarks, without a reference's own noise to remove). The ratio of
//! the two renderers' image means is printed beside, so a bias between them shows.

use std::path::{Path, PathBuf};
use std::time::Instant;

/// One renderer at one sample count: its runs' wall seconds and images.
struct Runs {
    seconds: Vec<f64>,
    images: Vec<film::Image>,
    /// What the renderer said it ran (Mitsuba's `settings:` line).
    note: Option<String>,
}

impl Runs {
    fn new() -> Runs {
        Runs {
            seconds: Vec::new(),
            images: Vec::new(),
            note: None,
        }
    }

    fn median_seconds(&self) -> f64 {
        crate::bench::median(&mut self.seconds.clone())
    }
}

/// `bench-path`: per scene and sample count, `runs` runs of photonflow's path tracer and
/// (with `PEERS` and `PEERS_VENV` set) of Mitsuba 3's, alternating; prints one table.
pub fn path(scenes: &[PathBuf], spp: &[u32], runs: usize, dir: &Path) -> Result<(), String> {
    if runs < 2 {
        return Err(format!(
            "--runs {runs}: the noise of a run is measured between runs, so at least 2"
        ));
    }
    if let Some(n) = spp.iter().find(|&&n| n == 0 || n > 1 << 20) {
        return Err(format!(
            "--spp {n}: samples per pixel must be in 1..=1048576"
        ));
    }
    for s in scenes {
        scene::Scene::load(s).map_err(|e| e.to_string())?;
    }
    std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    let exe = std::env::current_exe().map_err(|e| e.to_string())?;
    let peers = std::env::var_os("PEERS").is_some()
        && (std::env::var_os("PEERS_VENV").is_some() || std::env::var_os("PEERS_PYTHON").is_some());
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tests/references/peer.sh");
    let mut rows = Vec::new();
    let mut notes = Vec::new();
    for scene in scenes {
        let stem = scene
            .file_stem()
            .map_or("scene".into(), |s| s.to_string_lossy().into_owned());
        for &n in spp {
            let case = dir.join(format!("{stem}-{n}spp"));
            std::fs::create_dir_all(&case).map_err(|e| format!("{}: {e}", case.display()))?;
            let (mut ours, mut theirs) = (Runs::new(), Runs::new());
            for seed in 1..=runs {
                eprintln!(
                    "bench path: {} at {n} spp, run {seed} of {runs}",
                    scene.display()
                );
                let out = case.join(format!("photonflow-{seed}"));
                let mut cmd = std::process::Command::new(&exe);
                cmd.arg("render")
                    .arg(scene)
                    .args(["--method", "path", "--spp", &n.to_string()])
                    .args(["--seed", &seed.to_string(), "--out"])
                    .arg(&out);
                ours.seconds.push(timed(&mut cmd, "photonflow")?.0);
                ours.images.push(read(&out.join("image.exr"))?);
                if peers {
                    let exr = case.join(format!("mitsuba-{seed}.exr"));
                    let mut cmd = std::process::Command::new("bash");
                    cmd.arg(&script)
                        .args(["mitsuba"])
                        .arg(scene)
                        .arg("0")
                        .arg(&exr)
                        .env("PEER_SPP", n.to_string())
                        .env("PEER_SEED", seed.to_string());
                    let (s, stdout) = timed(&mut cmd, "Mitsuba 3")?;
                    theirs.seconds.push(s);
                    theirs.note = stdout
                        .lines()
                        .rev()
                        .find_map(|l| l.strip_prefix("settings: "))
                        .map(|l| l.trim().to_string());
                    theirs.images.push(read(&exr)?);
                }
            }
            let all: Vec<&film::Image> = ours.images.iter().chain(&theirs.images).collect();
            let norm = mean_image(&all)?;
            let e_ours = noise(&ours.images, &norm)?;
            let t_ours = ours.median_seconds();
            let eff_ours = 1.0 / (e_ours * t_ours);
            let name = scene.display();
            if theirs.images.is_empty() {
                rows.push(format!(
                    "| {name} | {n} | photonflow | {t_ours:.2} | {e_ours:.5} | {eff_ours:.1} | |"
                ));
                continue;
            }
            let e_theirs = noise(&theirs.images, &norm)?;
            let t_theirs = theirs.median_seconds();
            let eff_theirs = 1.0 / (e_theirs * t_theirs);
            let means = mean_of(&ours.images) / mean_of(&theirs.images);
            rows.push(format!(
                "| {name} | {n} | photonflow | {t_ours:.2} | {e_ours:.5} | {eff_ours:.1} | **{:.2}** (means {means:.3}) |",
                eff_ours / eff_theirs
            ));
            rows.push(format!(
                "| {name} | {n} | Mitsuba 3 | {t_theirs:.2} | {e_theirs:.5} | {eff_theirs:.1} | 1 |"
            ));
            if let Some(note) = theirs.note.take() {
                notes.push(format!("{name}, {n} spp: {note}"));
            }
        }
    }
    println!(
        "| scene | spp | renderer | wall s (median) | relMSE of a run | efficiency 1/(relMSE s) | efficiency / Mitsuba |"
    );
    println!("|---|---|---|---|---|---|---|");
    for r in rows {
        println!("{r}");
    }
    println!(
        "\n{runs} runs per renderer (seeds 1..={runs}), alternating, each a fresh process timed \
         from start to finish (photonflow: `render --method path --spp N`, scene load and \
         outputs included; Mitsuba 3: `tests/references/peer.sh mitsuba` with PEER_SPP, Python \
         and the JIT included). relMSE of a run: per-pixel variance over the runs / (mean of \
         every run of both renderers^2 + 0.01), averaged over pixels and channels. `means`: \
         photonflow's image mean over Mitsuba's."
    );
    for n in notes {
        println!("Mitsuba: {n}");
    }
    Ok(())
}

/// Runs `cmd` to the end; its wall seconds and standard output, or its error's last line.
fn timed(cmd: &mut std::process::Command, who: &str) -> Result<(f64, String), String> {
    let t0 = Instant::now();
    let out = cmd
        .output()
        .map_err(|e| format!("{who}: {:?}: {e}", cmd.get_program()))?;
    let seconds = t0.elapsed().as_secs_f64();
    if !out.status.success() {
        let stderr = String::from_utf8_lossy(&out.stderr);
        let last = stderr.lines().rev().find(|l| !l.trim().is_empty());
        return Err(format!(
            "{who} failed: {}",
            last.unwrap_or("no message").trim()
        ));
    }
    Ok((seconds, String::from_utf8_lossy(&out.stdout).into_owned()))
}

fn read(exr: &Path) -> Result<film::Image, String> {
    film::read_exr(exr).map_err(|e| e.to_string())
}

/// The per-pixel mean of `images`, which must share one size.
fn mean_image(images: &[&film::Image]) -> Result<Vec<[f64; 3]>, String> {
    let first = images.first().ok_or("no images")?;
    let mut sum = vec![[0.0f64; 3]; first.data.len()];
    for img in images {
        if (img.width, img.height) != (first.width, first.height) {
            return Err(format!(
                "images of {}x{} and {}x{}: the renderers disagree on the size",
                first.width, first.height, img.width, img.height
            ));
        }
        for (s, p) in sum.iter_mut().zip(&img.data) {
            for c in 0..3 {
                s[c] += p[c] as f64;
            }
        }
    }
    let k = images.len() as f64;
    Ok(sum.into_iter().map(|s| s.map(|v| v / k)).collect())
}

/// One run's relative variance: the per-pixel sample variance over `images` (unbiased,
/// `1 / (K - 1)`), over `norm^2 + 0.01`, averaged over pixels and channels.
fn noise(images: &[film::Image], norm: &[[f64; 3]]) -> Result<f64, String> {
    let refs: Vec<&film::Image> = images.iter().collect();
    let mean = mean_image(&refs)?;
    let k = images.len() as f64;
    let mut total = 0.0f64;
    for (i, (m, r)) in mean.iter().zip(norm).enumerate() {
        for c in 0..3 {
            let ss: f64 = images
                .iter()
                .map(|img| (img.data[i][c] as f64 - m[c]).powi(2))
                .sum();
            total += ss / (k - 1.0) / (r[c] * r[c] + film::RELMSE_EPSILON);
        }
    }
    Ok(total / (3 * mean.len()).max(1) as f64)
}

/// Mean of every pixel and channel over `images`.
fn mean_of(images: &[film::Image]) -> f64 {
    let (mut s, mut n) = (0.0f64, 0usize);
    for img in images {
        for p in &img.data {
            s += p.iter().map(|&v| v as f64).sum::<f64>();
            n += 3;
        }
    }
    s / n.max(1) as f64
}

#[cfg(test)]
mod tests {
    use super::*;

    fn image(values: &[f32]) -> film::Image {
        film::Image {
            width: values.len(),
            height: 1,
            data: values.iter().map(|&v| [v; 3]).collect(),
        }
    }

    /// The noise figure is the unbiased sample variance over `norm^2 + 0.01`: for runs of
    /// a pixel with variance 1 around mean 0 (`norm` 0) it is 100 in expectation, checked
    /// here by hand on two and three runs.
    #[test]
    fn noise_is_the_sample_variance_relative_to_the_norm() {
        let norm = vec![[0.0; 3]; 2];
        // Two runs: pixel 0 reads 1 and -1 (variance 2), pixel 1 reads 0 and 0.
        let e = noise(&[image(&[1.0, 0.0]), image(&[-1.0, 0.0])], &norm).unwrap();
        assert!((e - (2.0 / 0.01 + 0.0) / 2.0).abs() < 1e-9, "{e}");
        // Three runs of 1, 2, 3 (variance 1) against a norm of 2: 1 / 4.01.
        let norm = vec![[2.0; 3]];
        let e = noise(&[image(&[1.0]), image(&[2.0]), image(&[3.0])], &norm).unwrap();
        assert!((e - 1.0 / 4.01).abs() < 1e-12, "{e}");
    }

    #[test]
    fn images_of_different_sizes_are_refused() {
        let (a, b) = (image(&[1.0]), image(&[1.0, 2.0]));
        let e = mean_image(&[&a, &b]).unwrap_err();
        assert!(e.contains("1x1 and 2x1"), "{e}");
    }
}
