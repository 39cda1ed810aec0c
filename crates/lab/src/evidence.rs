//! `photonflow evidence`: what accuracy costs in time, bias and variance apart. For each
//! method, a ladder of budgets, each rendered with K independent seeds (every random stream
//! changes with the seed), against one reference: per image and per region the errors
//! (relative MSE in two conventions, RMSE, mean ratio) and, from the K runs, bias² and
//! variance (`film::BiasVariance`), so `bias² + variance = MSE` shows where an estimator is
//! biased and where it is noisy. Regions come from the scene's geometry (camera rays through
//! pixel centres), not from hand-drawn boxes.

use density::Kernel;
use film::{BiasVariance, Image, Mask};
use render::{Overrides, Settings};
use render::{Photons, Rendered, Run};
use scene::{Method, Scene, SceneFile};
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::Mutex;
use std::time::Instant;

pub struct EvidenceArgs {
    pub scene: PathBuf,
    /// A linear RGB EXR of the same view (else a path-traced one, rendered once and cached).
    pub reference: Option<PathBuf>,
    /// The given reference's second independent half (other seed, same budget).
    pub reference_b: Option<PathBuf>,
    pub reference_spp: u32,
    /// Independent runs per method and budget.
    pub seeds: u32,
    /// The short ladders on an image at most [`QUICK_SIDE`] pixels on a side (unless
    /// `reference` fixes its size): minutes on 2 cores.
    pub quick: bool,
    /// Every budget (and the k sweep's photon count) times this, at least 1.
    pub budget_scale: f64,
    /// Only these techniques (their names' slugs, `k-sweep` for the sweep); empty: all.
    pub only: Vec<String>,
    pub out: PathBuf,
    pub threads: Option<usize>,
}

/// One technique of the evidence: a method with its knobs, and its ladder of budgets.
pub struct Technique {
    pub name: &'static str,
    pub overrides: Overrides,
    /// What each rung sets: `spp`, `photons` or `passes`.
    pub budget: Budget,
    pub ladder: Vec<u64>,
    /// Compare this layer alone (with the reference's layer of that name) instead of the
    /// whole image: the caustic map against splatting.
    pub layer: Option<&'static str>,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Budget {
    Spp,
    Photons,
    Passes,
    /// Caustic paths per splatting pass.
    SplatPhotons,
}

impl Budget {
    pub fn name(self) -> &'static str {
        match self {
            Budget::Spp => "spp",
            Budget::Photons => "photon paths",
            Budget::Passes => "passes",
            Budget::SplatPhotons => "caustic paths",
        }
    }

    pub fn apply(self, o: &Overrides, n: u64) -> Overrides {
        let mut o = o.clone();
        match self {
            Budget::Spp => o.spp = Some(n as u32),
            Budget::Photons => o.photons = Some(n),
            Budget::Passes => o.passes = Some(n as u32),
            Budget::SplatPhotons => o.splat_photons = Some(n),
        }
        o
    }
}

/// The techniques the issue names: the path tracer, path + splatted caustics, the global
/// map shown directly (box and Silverman kernels, + the topological test, + boundary
/// correction), final gathering, SPPM, and the caustic map against splatting (the `caustic`
/// layer alone: `L S+ D E`, caustics seen directly).
pub fn techniques(quick: bool) -> Vec<Technique> {
    let ladder = |q: &[u64], full: &[u64]| if quick { q.to_vec() } else { full.to_vec() };
    let gd = |kernel: Kernel, topo: Option<f32>, boundary: bool| Overrides {
        method: Some(Method::GlobalDirect),
        kernel: Some(kernel),
        topo: Some(topo),
        boundary: Some(boundary),
        ..Overrides::default()
    };
    let m = |method| Overrides {
        method: Some(method),
        ..Overrides::default()
    };
    vec![
        Technique {
            name: "path",
            overrides: m(Method::Path),
            budget: Budget::Spp,
            layer: None,
            ladder: ladder(&[2, 8], &[16, 64, 128]),
        },
        Technique {
            name: "path+splat",
            overrides: m(Method::PathSplat),
            budget: Budget::Spp,
            layer: None,
            ladder: ladder(&[2, 8], &[4, 16, 64]),
        },
        Technique {
            name: "global map, box",
            overrides: gd(Kernel::Uniform, None, false),
            budget: Budget::Photons,
            layer: None,
            ladder: ladder(&[50_000, 200_000], &[100_000, 400_000, 1_600_000]),
        },
        Technique {
            name: "global map, Silverman",
            overrides: gd(Kernel::Silverman, None, false),
            budget: Budget::Photons,
            layer: None,
            ladder: ladder(&[50_000, 200_000], &[100_000, 400_000, 1_600_000]),
        },
        Technique {
            name: "global map, Silverman + topological test",
            overrides: gd(Kernel::Silverman, Some(0.1), false),
            budget: Budget::Photons,
            layer: None,
            ladder: ladder(&[50_000, 200_000], &[100_000, 400_000, 1_600_000]),
        },
        Technique {
            name: "global map, Silverman + topological test + boundary correction",
            overrides: gd(Kernel::Silverman, Some(0.1), true),
            budget: Budget::Photons,
            layer: None,
            ladder: ladder(&[50_000, 200_000], &[100_000, 400_000, 1_600_000]),
        },
        Technique {
            name: "final gathering",
            overrides: m(Method::FinalGather),
            budget: Budget::Spp,
            layer: None,
            ladder: ladder(&[1], &[1, 2]),
        },
        Technique {
            name: "sppm",
            overrides: m(Method::Sppm),
            budget: Budget::Passes,
            layer: None,
            ladder: ladder(&[2, 8], &[4, 16, 64]),
        },
        // The caustic map as the course's final gathering makes it (k = 250, every path of
        // the trace paid for, the global set's included, and direct light; one gather ray
        // straight into the global map, no irradiance cache: the least indirect light final
        // gathering computes), against photon-differential splatting onto eye vertices (no
        // map, no global set).
        Technique {
            name: "caustic map (k-NN)",
            overrides: Overrides {
                method: Some(Method::FinalGather),
                gather_rays: Some(1),
                gather_cache: Some(0),
                ..Overrides::default()
            },
            budget: Budget::Photons,
            layer: Some("caustic"),
            ladder: ladder(&[100_000, 400_000], &[200_000, 1_000_000, 4_000_000]),
        },
        Technique {
            name: "caustic splat (differentials)",
            overrides: Overrides {
                method: Some(Method::CausticSplat),
                splat_indirect: Some(false),
                ..Overrides::default()
            },
            budget: Budget::SplatPhotons,
            layer: Some("caustic"),
            ladder: ladder(&[100_000, 400_000], &[250_000, 1_000_000, 4_000_000]),
        },
    ]
}

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

/// The reference (`accuracy::reference`: given, or path-traced once and cached in `out`),
/// read and checked against the scene's size, with its caustic layer when it has one (a
/// path-traced reference does: `layers/caustic.exr` beside the image).
pub struct Reference {
    pub path: PathBuf,
    pub image: Image,
    pub caustic: Option<Image>,
    /// The two halves `image` is the mean of (`--reference-b`).
    pub halves: Option<film::Halves>,
}

fn reference(scene: &Scene, a: &EvidenceArgs) -> Result<Reference, String> {
    let path = crate::reference::reference(
        scene,
        a.reference.as_deref(),
        a.reference_spp,
        &a.out,
        a.threads,
    )?
    .exr;
    let read = |p: &Path| render::read_reference(scene, p);
    if let Some(b) = &a.reference_b {
        let Some(first) = &a.reference else {
            return Err(format!(
                "--reference-b {}: the second half needs the first (--reference)",
                b.display()
            ));
        };
        let mean = a.out.join("reference-halves-mean.exr");
        let halves = crate::reference::halves(scene, first, b, &mean)?;
        return Ok(Reference {
            path: mean,
            image: halves.mean.clone(),
            caustic: None,
            halves: Some(halves),
        });
    }
    let image = read(&path)?;
    let layer = path.with_file_name("layers").join("caustic.exr");
    let caustic = if layer.is_file() {
        Some(read(&layer)?)
    } else {
        None
    };
    Ok(Reference {
        path,
        image,
        caustic,
        halves: None,
    })
}

/// Everything an evidence run measured: the report and the plots are made from it.
pub struct Evidence {
    pub scene: PathBuf,
    pub seeds: u32,
    pub reference: String,
    pub reference_image: Image,
    pub rungs: Vec<RungResult>,
    /// The k sweep at a fixed photon count, then photons grown with k.
    pub sweep: Vec<SweepResult>,
    pub sweep_photons: u64,
    /// Why a technique was left out (no reference layer to compare with, say).
    pub skipped: Vec<String>,
    /// What `--quick` traded away, when it was given.
    pub quick: Option<String>,
}

/// One point of the k sweep.
pub struct SweepResult {
    /// The kernel and tests (`box`, `Silverman`, ...), or the grown-together series.
    pub variant: String,
    pub k: usize,
    pub photons: u64,
    pub rung: RungResult,
}

pub fn run(a: &EvidenceArgs) -> Result<Measured, String> {
    if a.seeds < 2 {
        return Err(format!(
            "--seeds {} must be at least 2 (bias and variance need two runs)",
            a.seeds
        ));
    }
    // Every flag is checked before anything is rendered or written (a bad name used to be
    // refused only after the reference was rendered and kept).
    if a.reference.is_none() && !(1..=1 << 24).contains(&a.reference_spp) {
        return Err(format!(
            "--reference-spp {} must be in 1..=16777216",
            a.reference_spp
        ));
    }
    let known: Vec<String> = techniques(a.quick)
        .iter()
        .map(|t| slug(t.name))
        .chain(["k-sweep".to_string()])
        .collect();
    if let Some(o) = a.only.iter().find(|o| !known.contains(&slug(o))) {
        return Err(format!(
            "--only {o}: no such technique (known: {})",
            known.join(", ")
        ));
    }
    if !(a.budget_scale > 0.0 && a.budget_scale <= 1e3) {
        return Err(format!(
            "--budget-scale {} must be in (0, 1000]",
            a.budget_scale
        ));
    }
    let scale = |n: u64| ((n as f64 * a.budget_scale).round() as u64).max(1);
    // `--quick` renders fewer pixels, unless a given reference fixes the image's size.
    let shrink = a.quick && a.reference.is_none();
    let edit = |f: &mut SceneFile| {
        if shrink {
            (f.camera.width, f.camera.height) = quick_size(f.camera.width, f.camera.height);
        }
    };
    let scene = Scene::load_with(&a.scene, edit).map_err(|e| e.to_string())?;
    // Nothing is written before the reference is known to be usable (a given one is read
    // and checked first; a cached one is rendered into `out`, which it creates).
    let reference = reference(&scene, a)?;
    let regions = crate::regions::regions(&scene);
    let caustic_regions: Vec<(&'static str, Mask)> = regions
        .iter()
        .filter(|(n, _)| matches!(*n, "image" | "caustic"))
        .cloned()
        .collect();
    let traces = Traces::new(a.out.join("cache"));
    let make = |seed: u64| {
        Scene::load_with(&a.scene, |f| {
            f.seed = seed;
            edit(f);
        })
        .map_err(|e| e.to_string())
    };
    let mut ev = Evidence {
        scene: a.scene.clone(),
        seeds: a.seeds,
        reference: a.reference.as_ref().map_or(
            format!("a {}-spp path-traced reference", a.reference_spp),
            |p| p.display().to_string(),
        ),
        reference_image: reference.image.clone(),
        rungs: Vec::new(),
        sweep: Vec::new(),
        sweep_photons: scale(200_000),
        skipped: Vec::new(),
        quick: a.quick.then(|| {
            format!(
                "`--quick`: {} x {} pixels{}, {} seeds, a {}, two budgets per technique (one \
                 for final gathering) and k in {{50, 250, 1000}}: a few minutes in place of \
                 about 45, at the price of noisier bias^2 and variance figures and errors \
                 nearer the reference's own noise.",
                scene.camera.width,
                scene.camera.height,
                if shrink {
                    " (the scene's view, fewer pixels)"
                } else {
                    ""
                },
                a.seeds,
                a.reference
                    .as_ref()
                    .map_or(format!("{}-spp reference", a.reference_spp), |_| {
                        "given reference".to_string()
                    }),
            )
        }),
    };
    let mut done = Done::default();
    let wanted = |name: &str| a.only.is_empty() || a.only.iter().any(|o| slug(o) == slug(name));
    for mut t in techniques(a.quick).into_iter().filter(|t| wanted(t.name)) {
        t.ladder = t.ladder.iter().map(|&n| scale(n)).collect();
        t.ladder.dedup();
        let (against, regions) = match t.layer {
            None => (
                Against {
                    image: &reference.image,
                    halves: reference.halves.as_ref(),
                },
                &regions,
            ),
            Some(_) => match &reference.caustic {
                Some(c) => (Against::from(c), &caustic_regions),
                None => {
                    ev.skipped.push(format!(
                        "{}: the reference {} has no layers/caustic.exr beside it",
                        t.name,
                        reference.path.display()
                    ));
                    continue;
                }
            },
        };
        for &amount in &t.ladder {
            let r = rung(
                &make, &t, amount, a.seeds, against, regions, &traces, a.threads,
            )?;
            let key = done.key(&make, &t, amount, a.seeds, against.halves.is_some())?;
            done.0.insert(key, Ran::Rung(ev.rungs.len()));
            let e = &r.regions[0].errors;
            println!(
                "{:<64} {:>22} {:8.2} s  relMSE {:.5}{}  FLIP {:.4}",
                r.technique,
                format!("{} {}", r.amount, r.budget.name()),
                r.seconds,
                e.relmse,
                e.relmse_corrected
                    .map_or(String::new(), |c| format!(" (reference noise out: {c:.5})")),
                e.flip,
            );
            ev.rungs.push(r);
        }
    }
    if wanted("k-sweep") {
        k_sweep(
            a,
            &make,
            &reference.image,
            &regions,
            &traces,
            &mut done,
            &mut ev,
        )?;
    }
    Ok(Measured {
        evidence: ev,
        scene,
        regions,
    })
}

/// The longer side of `--quick`'s image: a quarter of the worksheet's 512 x 512 pixels.
pub const QUICK_SIDE: u32 = 256;
/// Seeds and reference samples per pixel where the flags do not set them, without and with
/// `--quick`.
pub const SEEDS: u32 = 8;
pub const REFERENCE_SPP: u32 = 1024;
pub const QUICK_SEEDS: u32 = 4;
pub const QUICK_REFERENCE_SPP: u32 = 512;

/// `width` x `height` scaled so the longer side is at most [`QUICK_SIDE`] (the same view).
pub fn quick_size(width: u32, height: u32) -> (u32, u32) {
    let long = width.max(height) as u64;
    if long <= QUICK_SIDE as u64 {
        return (width, height);
    }
    let side = |n: u32| ((n as u64 * QUICK_SIDE as u64 + long / 2) / long).max(1) as u32;
    (side(width), side(height))
}

/// Where an earlier rung's result is.
#[derive(Clone, Copy)]
enum Ran {
    Rung(usize),
    Sweep(usize),
}

/// The rungs measured so far by what they render: a rung with equal settings (for seed 1),
/// seeds, layer and reference renders the same images bit for bit (every random stream
/// follows the seed), so it is taken, not rendered again (the k sweep's points at the
/// global map's own k and photon count).
#[derive(Default)]
struct Done(HashMap<String, Ran>);

impl Done {
    fn key(
        &self,
        make: &dyn Fn(u64) -> Result<Scene, String>,
        t: &Technique,
        amount: u64,
        seeds: u32,
        halves: bool,
    ) -> Result<String, String> {
        let scene = make(1)?;
        let hash = Settings::new(&scene, &t.budget.apply(&t.overrides, amount))?.hash(&scene);
        Ok(format!("{hash:016x} {:?} {seeds} {halves}", t.layer))
    }

    fn get<'e>(&self, key: &str, ev: &'e Evidence) -> Option<&'e RungResult> {
        match *self.0.get(key)? {
            Ran::Rung(i) => ev.rungs.get(i),
            Ran::Sweep(i) => ev.sweep.get(i).map(|s| &s.rung),
        }
    }
}

/// What [`run`] measured, for the report: the evidence, the scene it was measured on and the
/// regions of its image.
pub struct Measured {
    pub evidence: Evidence,
    pub scene: Scene,
    pub regions: Vec<(&'static str, Mask)>,
}

/// The worksheet's trade-off itself: the global map shown directly, k swept for each kernel,
/// with and without the topological test and boundary correction, at a fixed photon count
/// (bias^2 rises and variance falls with k); then photons and k grown together (`photons /
/// k` fixed, so the disc keeps its size: the bias stays, the noise falls).
fn k_sweep(
    a: &EvidenceArgs,
    make: &dyn Fn(u64) -> Result<Scene, String>,
    reference: &Image,
    regions: &[(&'static str, Mask)],
    traces: &Traces,
    done: &mut Done,
    ev: &mut Evidence,
) -> Result<(), String> {
    let ks: &[usize] = if a.quick {
        &[50, 250, 1000]
    } else {
        &[50, 100, 250, 500, 1000, 2000]
    };
    let photons = ev.sweep_photons;
    let mut sweep = |variant: &str, o: Overrides, k: usize, amount: u64| {
        let t = Technique {
            name: "global map",
            overrides: o,
            budget: Budget::Photons,
            ladder: vec![amount],
            layer: None,
        };
        let key = done.key(make, &t, amount, a.seeds, false)?;
        let (r, again) = match done.get(&key, ev) {
            Some(r) => (
                RungResult {
                    technique: t.name,
                    ..r.clone()
                },
                " (the same runs as above)",
            ),
            None => (
                rung(
                    make, &t, amount, a.seeds, reference, regions, traces, a.threads,
                )?,
                "",
            ),
        };
        println!(
            "k sweep {variant:<44} k {k:>5} {amount:>9} paths  relMSE {:.5}{again}",
            r.regions[0].errors.relmse
        );
        done.0.insert(key, Ran::Sweep(ev.sweep.len()));
        ev.sweep.push(SweepResult {
            variant: variant.to_string(),
            k,
            photons: amount,
            rung: r,
        });
        Ok::<(), String>(())
    };
    for (name, kernel, topo, boundary) in SWEEP_VARIANTS {
        for &k in ks {
            let o = Overrides {
                method: Some(Method::GlobalDirect),
                k: Some(k),
                kernel: Some(kernel),
                topo: Some(topo),
                boundary: Some(boundary),
                ..Overrides::default()
            };
            sweep(name, o, k, photons)?;
        }
    }
    for &k in ks {
        let o = Overrides {
            method: Some(Method::GlobalDirect),
            k: Some(k),
            kernel: Some(Kernel::Silverman),
            ..Overrides::default()
        };
        sweep(GROWN, o, k, (photons / 1000).max(1) * k as u64)?;
    }
    Ok(())
}

/// The sweep's series: kernel, topological test, boundary correction.
pub const SWEEP_VARIANTS: [(&str, Kernel, Option<f32>, bool); 4] = [
    ("box", Kernel::Uniform, None, false),
    ("Silverman", Kernel::Silverman, None, false),
    (
        "Silverman + topological test",
        Kernel::Silverman,
        Some(0.1),
        false,
    ),
    (
        "Silverman + topological test + boundary",
        Kernel::Silverman,
        Some(0.1),
        true,
    ),
];

/// The series of the sweep whose photon count grows with k (Silverman, the fixed count's
/// paths at k = 1000).
pub const GROWN: &str = "Silverman, photons grown with k";

pub fn slug(s: &str) -> String {
    s.chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() {
                c.to_ascii_lowercase()
            } else {
                '-'
            }
        })
        .collect::<String>()
        .split('-')
        .filter(|p| !p.is_empty())
        .collect::<Vec<_>>()
        .join("-")
}
