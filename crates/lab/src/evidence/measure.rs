//! One rung measured: its runs rendered with independent seeds, then their errors and bias²
//! and variance per region; and the photon sets the rungs of a run share.

use super::techniques::{Budget, Technique};
use film::{BiasVariance, Image, Mask};
use render::{Overrides, Settings};
use render::{Photons, Rendered, Run};
use scene::Scene;
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::Mutex;
use std::time::Instant;

/// Mean errors of a rung's runs over one region: relative MSE as `(v - r)² / (r² + 0.01)`
/// and as pbrt's `(v - r)² / (r + 0.01)²`, RMSE, the ratio of the means (`film::metrics` of
/// each run) and LDR-FLIP (`film::flip`), each averaged over the runs.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Errors {
    pub relmse: f64,
    /// With the reference given as two halves: the relative MSE with the reference's noise
    /// taken out (`film::metrics_halves`).
    pub relmse_corrected: Option<f64>,
    pub relmse_pbrt: f64,
    pub rmse: f64,
    pub mean_ratio: f64,
    pub flip: f64,
}

/// One region of a rung: its mean errors over the runs and its relative bias² and variance.
#[derive(Clone, Debug)]
pub struct RegionResult {
    pub region: &'static str,
    pub errors: Errors,
    pub sums: film::RegionSums,
}

/// One rung's result: its mean time, its regions, the maps and the first run's image.
#[derive(Clone)]
pub struct RungResult {
    pub technique: &'static str,
    pub budget: Budget,
    pub amount: u64,
    pub seconds: f64,
    pub regions: Vec<RegionResult>,
    pub maps: BiasVariance,
    pub first: Image,
}

impl RungResult {
    pub fn region(&self, name: &str) -> Option<&RegionResult> {
        self.regions.iter().find(|r| r.region == name)
    }
}

/// The image a method renders of `scene` with `o` (photons traced into `cache`).
pub fn render_image(
    scene: &Scene,
    o: &Overrides,
    cache: &Path,
    threads: Option<usize>,
) -> Result<(Image, Rendered), String> {
    let settings = Settings::new(scene, o)?;
    let run = Run {
        scene,
        settings: &settings,
        cache,
        photons: Photons::TraceOrReuse,
        threads,
    };
    let r = render::methods::render(&run, &|_| {})?;
    let parts: Vec<(&Image, f32)> = r.layers.iter().map(|l| (&l.image, 1.0)).collect();
    let img = film::composite(&parts).map_err(|e| e.to_string())?;
    Ok((img, r))
}

/// The photon sets of one evidence run, in one directory kept until the run ends: every rung
/// reading the sets of one seed and photon count (the global map's kernels and tests, the k
/// sweep, the caustic map) traces them once. Tracing is deterministic in the seed and the
/// parameters, so a reused set is the one a new trace would make; each run reusing it is
/// charged the seconds its tracing took, so times still count the tracing.
pub struct Traces {
    dir: PathBuf,
    /// Trace seconds per set (its cache file name).
    seconds: Mutex<HashMap<PathBuf, f64>>,
}

impl Traces {
    /// Empties `dir` first: a set left there by another run has no trace time to charge.
    pub fn new(dir: PathBuf) -> Traces {
        let _ = std::fs::remove_dir_all(&dir);
        Traces {
            dir,
            seconds: Mutex::new(HashMap::new()),
        }
    }

    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// The trace seconds to charge a run of `scene` with `o` that made `r`: none when it
    /// traced (its time holds them), the first trace's when it reused the sets.
    fn charge(&self, scene: &Scene, o: &Overrides, r: &Rendered) -> Result<f64, String> {
        let Some(trace) = r.info.get("trace") else {
            return Ok(0.0);
        };
        let key = photons::CacheKey::new(scene, &Settings::new(scene, o)?.emit)
            .file(&self.dir, store::MapKind::Global);
        let mut seconds = self.seconds.lock().unwrap_or_else(|e| e.into_inner());
        if trace == "traced" {
            let s = r.info.get("time_trace_s").and_then(|v| v.as_f64());
            seconds.insert(key, s.unwrap_or(0.0));
            Ok(0.0)
        } else {
            Ok(seconds.get(&key).copied().unwrap_or(0.0))
        }
    }
}

impl Drop for Traces {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.dir);
    }
}

/// Renders one rung with seeds `1..=seeds` (`scene(seed)` makes the scene of each) and
/// decomposes its error against `reference` (the reference's layer `t.layer`, for a
/// technique that compares one layer).
#[allow(clippy::too_many_arguments)]
pub fn rung<'a>(
    scene: &dyn Fn(u64) -> Result<Scene, String>,
    t: &Technique,
    amount: u64,
    seeds: u32,
    reference: impl Into<Against<'a>>,
    regions: &[(&'static str, Mask)],
    traces: &Traces,
    threads: Option<usize>,
) -> Result<RungResult, String> {
    let Against {
        image: reference,
        halves,
    } = reference.into();
    let o = t.budget.apply(&t.overrides, amount);
    let mut images = Vec::new();
    let mut seconds = 0.0;
    for seed in 1..=seeds as u64 {
        let scene = scene(seed)?;
        let t0 = Instant::now();
        let (img, r) = render_image(&scene, &o, traces.dir(), threads)?;
        seconds += t0.elapsed().as_secs_f64() + traces.charge(&scene, &o, &r)?;
        let img = match t.layer {
            None => img,
            Some(name) => {
                r.layers
                    .into_iter()
                    .find(|l| l.name == name)
                    .ok_or_else(|| format!("{}: the run made no `{name}` layer", t.name))?
                    .image
            }
        };
        images.push(img);
    }
    let runs: Vec<&Image> = images.iter().collect();
    let maps = match halves {
        Some(h) => BiasVariance::against_halves(&runs, h, true),
        None => BiasVariance::new(&runs, reference, true),
    }
    .map_err(|e| e.to_string())?;
    let flips = images
        .iter()
        .map(|img| film::flip(img, reference, 1.0).map_err(|e| e.to_string()))
        .collect::<Result<Vec<_>, _>>()?;
    let mut out = Vec::new();
    let k = images.len() as f64;
    for (name, mask) in regions {
        // A region the scene does not have (no glass, say) has no errors.
        if mask.count() == 0 {
            continue;
        }
        let mut e = Errors::default();
        for (img, flip) in images.iter().zip(&flips) {
            let m = film::metrics(img, reference, Some(mask)).map_err(|e| e.to_string())?;
            e.relmse += m.relmse / k;
            if let Some(h) = halves {
                let c = film::metrics_halves(img, h, Some(mask)).map_err(|e| e.to_string())?;
                *e.relmse_corrected.get_or_insert(0.0) += c.relmse / k;
            }
            e.relmse_pbrt += m.relmse_pbrt / k;
            e.rmse += m.rmse / k;
            e.mean_ratio += m.mean_a / m.mean_b / k;
            e.flip += flip
                .mean(Some(mask))
                .map_err(|e| e.to_string())?
                .unwrap_or(0.0)
                / k;
        }
        let sums = maps.region(Some(mask)).map_err(|e| e.to_string())?;
        out.push(RegionResult {
            region: name,
            errors: e,
            sums,
        });
    }
    Ok(RungResult {
        technique: t.name,
        budget: t.budget,
        amount,
        seconds: seconds / seeds as f64,
        regions: out,
        maps,
        first: images.swap_remove(0),
    })
}

/// What a rung's runs are measured against: an image, and the halves it is the mean of when
/// the reference came as two.
#[derive(Clone, Copy)]
pub struct Against<'a> {
    pub image: &'a Image,
    pub halves: Option<&'a film::Halves>,
}

impl<'a> From<&'a Image> for Against<'a> {
    fn from(image: &'a Image) -> Against<'a> {
        Against {
            image,
            halves: None,
        }
    }
}
