//! `photonflow evidence`: what accuracy costs in time, bias and variance apart. For each
//! method, a ladder of budgets, each rendered with K independent seeds (every random stream
//! changes with the seed), against one reference: per image and per region the errors
//! (relative MSE in two conventions, RMSE, mean ratio) and, from the K runs, bias² and
//! variance (`film::BiasVariance`), so `bias² + variance = MSE` shows where an estimator is
//! biased and where it is noisy. Regions come from the scene's geometry (camera rays through
//! pixel centres), not from hand-drawn boxes.

mod measure;
mod techniques;

pub use measure::{Against, Errors, RegionResult, RungResult, Traces, render_image, rung};
pub use techniques::{Budget, GROWN, SWEEP_VARIANTS, Technique, slug, techniques};

use density::Kernel;
use film::{Image, Mask};
use render::{Overrides, Settings};
use scene::{Method, Scene, SceneFile};
use std::collections::HashMap;
use std::path::{Path, PathBuf};

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
    /// The report's directory, written whole in a staging directory beside it and renamed
    /// into place.
    pub out: PathBuf,
    /// Where the path-traced reference is cached, apart from `out`: a run replaces `out`
    /// whole, and a reference rendered before a kill must serve the next run.
    pub cache: PathBuf,
    pub threads: Option<usize>,
}

/// What an evidence directory holds: the report and its files (the whole list, so that
/// a directory of the user's is refused, not replaced).
pub const EVIDENCE_FILES: [&str; 9] = [
    "report.md",
    "report.html",
    "evidence.md",
    "evidence.json",
    "maps",
    "images",
    "plots",
    "reference-halves-mean.exr",
    // The photon sets of a run that an earlier version kept here.
    "cache",
];

/// The mean of a reference given as two halves, in the evidence directory.
const HALVES_MEAN: &str = "reference-halves-mean.exr";

/// An evidence directory, replaced whole by the next run.
pub const LAYOUT: render::output::Layout = render::output::Layout {
    what: "an evidence directory",
    flag: "--out",
    // `reference-*`: the path-traced references an earlier version cached in it.
    holds: |name| EVIDENCE_FILES.contains(&name) || name.starts_with("reference-"),
};

/// The reference (`accuracy::reference`: given, or path-traced once and cached in `cache`),
/// read and checked against the scene's size, with its caustic layer when it has one (a
/// path-traced reference does: `layers/caustic.exr` beside the image). Writes nothing but
/// the cached reference.
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
        &a.cache,
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
        let halves = crate::reference::halves(scene, first, b)?;
        return Ok(Reference {
            // Written with the report.
            path: a.out.join(HALVES_MEAN),
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
/// Measures every rung; the report is then written into the returned [`Measured::staged`]
/// and published ([`crate::evidence`]).
pub fn run(a: &EvidenceArgs) -> Result<Measured, String> {
    check(a)?;
    // Before anything is rendered: a directory of the user's is never replaced.
    render::output::check_layout(&a.out, &LAYOUT)?;
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
    // and checked first; a path-traced one is rendered into the cache, or found there).
    let reference = reference(&scene, a)?;
    // The evidence directory is written whole beside `out` (its photon sets too, removed
    // before it is published), so a stopped run leaves the old one whole.
    let staged = render::output::stage_as(&a.out, &LAYOUT)?;
    if let Some(h) = &reference.halves {
        let mean = staged.path().join(HALVES_MEAN);
        film::write_exr(&mean, &h.mean).map_err(|e| staged.named(e.to_string()))?;
    }
    let regions = crate::regions::regions(&scene);
    let caustic_regions: Vec<(&'static str, Mask)> = regions
        .iter()
        .filter(|(n, _)| matches!(*n, "image" | "caustic"))
        .cloned()
        .collect();
    let traces = Traces::new(staged.path().join("cache"));
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
    drop(traces);
    Ok(Measured {
        evidence: ev,
        scene,
        regions,
        staged,
    })
}

/// Refuses the flags no run can use.
fn check(a: &EvidenceArgs) -> Result<(), String> {
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
    Ok(())
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
/// regions of its image; and the evidence directory being written.
pub struct Measured {
    pub evidence: Evidence,
    pub scene: Scene,
    pub regions: Vec<(&'static str, Mask)>,
    pub staged: render::output::Staged,
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
