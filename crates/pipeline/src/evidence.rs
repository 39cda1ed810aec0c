//! `photonflow evidence`: what accuracy costs in time, bias and variance apart. For each
//! method, a ladder of budgets, each rendered with K independent seeds (every random stream
//! changes with the seed), against one reference: per image and per region the errors
//! (relative MSE in two conventions, RMSE, mean ratio) and, from the K runs, bias² and
//! variance (`film::BiasVariance`), so `bias² + variance = MSE` shows where an estimator is
//! biased and where it is noisy. Regions come from the scene's geometry (camera rays through
//! pixel centres), not from hand-drawn boxes.

use crate::methods::{Photons, Rendered, Run};
use crate::{Overrides, Settings, worksheet};
use density::Kernel;
use film::{BiasVariance, Image, Mask};
use scene::{Material, Method, Scene};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::Instant;

pub struct EvidenceArgs {
    pub scene: PathBuf,
    /// A linear RGB EXR of the same view (else a path-traced one, rendered once and cached).
    pub reference: Option<PathBuf>,
    pub reference_spp: u32,
    /// Independent runs per method and budget.
    pub seeds: u32,
    /// The short ladder (minutes on 2 cores).
    pub quick: bool,
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
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Budget {
    Spp,
    Photons,
    Passes,
}

impl Budget {
    fn name(self) -> &'static str {
        match self {
            Budget::Spp => "spp",
            Budget::Photons => "photon paths",
            Budget::Passes => "passes",
        }
    }

    fn apply(self, o: &Overrides, n: u64) -> Overrides {
        let mut o = o.clone();
        match self {
            Budget::Spp => o.spp = Some(n as u32),
            Budget::Photons => o.photons = Some(n),
            Budget::Passes => o.passes = Some(n as u32),
        }
        o
    }
}

/// The techniques the issue names: the path tracer, path + splatted caustics, the global
/// map shown directly (box and Silverman kernels, + the topological test, + boundary
/// correction), final gathering and SPPM.
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
            ladder: ladder(&[4, 16], &[16, 64, 256]),
        },
        Technique {
            name: "path+splat",
            overrides: m(Method::PathSplat),
            budget: Budget::Spp,
            ladder: ladder(&[4, 16], &[4, 16, 64]),
        },
        Technique {
            name: "global map, box",
            overrides: gd(Kernel::Uniform, None, false),
            budget: Budget::Photons,
            ladder: ladder(&[50_000, 200_000], &[100_000, 400_000, 1_600_000]),
        },
        Technique {
            name: "global map, Silverman",
            overrides: gd(Kernel::Silverman, None, false),
            budget: Budget::Photons,
            ladder: ladder(&[50_000, 200_000], &[100_000, 400_000, 1_600_000]),
        },
        Technique {
            name: "global map, Silverman + topological test",
            overrides: gd(Kernel::Silverman, Some(0.1), false),
            budget: Budget::Photons,
            ladder: ladder(&[50_000, 200_000], &[100_000, 400_000, 1_600_000]),
        },
        Technique {
            name: "global map, Silverman + topological test + boundary correction",
            overrides: gd(Kernel::Silverman, Some(0.1), true),
            budget: Budget::Photons,
            ladder: ladder(&[50_000, 200_000], &[100_000, 400_000, 1_600_000]),
        },
        Technique {
            name: "final gathering",
            overrides: m(Method::FinalGather),
            budget: Budget::Spp,
            ladder: ladder(&[1], &[1, 4]),
        },
        Technique {
            name: "sppm",
            overrides: m(Method::Sppm),
            budget: Budget::Passes,
            ladder: ladder(&[4, 16], &[4, 16, 64]),
        },
    ]
}

/// The named regions of an image of `scene`, from its geometry: the caustic under the glass
/// sphere, the inner edges and corners of the box, the glass sphere, the open walls (diffuse
/// surfaces away from edges and caustics), and the whole image.
pub fn regions(scene: &Scene) -> Vec<(&'static str, Mask)> {
    let (w, h) = (scene.camera.width as usize, scene.camera.height as usize);
    let caustic = worksheet::caustic_region(scene, 1.6);
    // Edge band: two percent of the scene's diagonal (the k-NN discs' scale).
    let b = scene.geometry.bounds();
    let edges = worksheet::edge_mask(scene, 0.02 * (b.max - b.min).length());
    let seen = |x: usize, y: usize| {
        scene
            .geometry
            .intersect(&scene.camera.ray(x as f32 + 0.5, y as f32 + 0.5))
    };
    let glass = Mask::from_fn(w, h, |x, y| {
        seen(x, y).is_some_and(|hit| {
            matches!(
                scene.materials[hit.material as usize],
                Material::Dielectric { .. }
            )
        })
    });
    let walls = Mask::from_fn(w, h, |x, y| {
        let i = y * w + x;
        !caustic.pixels[i]
            && !edges.pixels[i]
            && seen(x, y).is_some_and(|hit| scene.is_diffuse(hit.material))
    });
    vec![
        ("image", Mask::all(w, h)),
        ("caustic", caustic),
        ("edges and corners", edges),
        ("glass sphere", glass),
        ("open walls", walls),
    ]
}

/// Mean errors of a rung's runs over one region: relative MSE as `(v - r)² / (r² + 0.01)`
/// and as pbrt's `(v - r)² / (r + 0.01)²`, RMSE, and the ratio of the means
/// (`film::metrics` of each run, averaged).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Errors {
    pub relmse: f64,
    pub relmse_pbrt: f64,
    pub rmse: f64,
    pub mean_ratio: f64,
}

/// One rung's result: its mean time and, per region, the mean errors over the runs and the
/// relative bias² and variance.
pub struct RungResult {
    pub technique: &'static str,
    pub budget: Budget,
    pub amount: u64,
    pub seconds: f64,
    pub regions: Vec<(&'static str, Errors, film::RegionSums)>,
    pub maps: BiasVariance,
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
    let r = crate::methods::render(&run, &|_| {})?;
    let parts: Vec<(&Image, f32)> = r.layers.iter().map(|l| (&l.image, 1.0)).collect();
    let img = film::composite(&parts).map_err(|e| e.to_string())?;
    Ok((img, r))
}

/// Renders one rung with seeds `1..=seeds` (`scene(seed)` makes the scene of each) and
/// decomposes its error.
#[allow(clippy::too_many_arguments)]
pub fn rung(
    scene: &dyn Fn(u64) -> Result<Scene, String>,
    t: &Technique,
    amount: u64,
    seeds: u32,
    reference: &Image,
    regions: &[(&'static str, Mask)],
    cache: &Path,
    threads: Option<usize>,
) -> Result<RungResult, String> {
    let o = t.budget.apply(&t.overrides, amount);
    let mut images = Vec::new();
    let mut seconds = 0.0;
    for seed in 1..=seeds as u64 {
        let scene = scene(seed)?;
        // Each run traces its own photons: the seed changes them, and the time counts them.
        let _ = std::fs::remove_dir_all(cache);
        let t0 = Instant::now();
        let (img, _) = render_image(&scene, &o, cache, threads)?;
        seconds += t0.elapsed().as_secs_f64();
        images.push(img);
    }
    let _ = std::fs::remove_dir_all(cache);
    let runs: Vec<&Image> = images.iter().collect();
    let maps = BiasVariance::new(&runs, reference, true).map_err(|e| e.to_string())?;
    let mut out = Vec::new();
    let k = images.len() as f64;
    for (name, mask) in regions {
        // A region the scene does not have (no glass, say) has no errors.
        if mask.count() == 0 {
            continue;
        }
        let mut e = Errors::default();
        for img in &images {
            let m = film::metrics(img, reference, Some(mask)).map_err(|e| e.to_string())?;
            e.relmse += m.relmse / k;
            e.relmse_pbrt += m.relmse_pbrt / k;
            e.rmse += m.rmse / k;
            e.mean_ratio += m.mean_a / m.mean_b / k;
        }
        let sums = maps.region(Some(mask)).map_err(|e| e.to_string())?;
        out.push((*name, e, sums));
    }
    Ok(RungResult {
        technique: t.name,
        budget: t.budget,
        amount,
        seconds: seconds / seeds as f64,
        regions: out,
        maps,
    })
}

/// The reference (`accuracy::reference`: given, or path-traced once and cached in `out`),
/// read and checked against the scene's size.
fn reference(scene: &Scene, a: &EvidenceArgs) -> Result<Image, String> {
    let path = crate::accuracy::reference(scene, a.reference.as_deref(), a.reference_spp, &a.out)?;
    let img = film::read_exr(&path).map_err(|e| e.to_string())?;
    let (w, h) = (scene.camera.width as usize, scene.camera.height as usize);
    if (img.width, img.height) != (w, h) {
        return Err(format!(
            "{}: reference is {}x{}, the scene renders {w}x{h}",
            path.display(),
            img.width,
            img.height
        ));
    }
    Ok(img)
}

pub fn run(a: &EvidenceArgs) -> Result<(), String> {
    if a.seeds < 2 {
        return Err(format!(
            "--seeds {} must be at least 2 (bias and variance need two runs)",
            a.seeds
        ));
    }
    let scene = Scene::load(&a.scene).map_err(|e| e.to_string())?;
    std::fs::create_dir_all(&a.out).map_err(|e| format!("{}: {e}", a.out.display()))?;
    let reference = reference(&scene, a)?;
    let regions = regions(&scene);
    let cache = a.out.join("cache");
    let mut md = String::new();
    let _ = writeln!(
        md,
        "# Evidence: {}\n\n{} independent runs per rung (seeds 1..={}); errors against {}; \
         relative MSE `(v - r)^2 / (r^2 + 0.01)` (relMSE) and pbrt's `(v - r)^2 / (r + 0.01)^2` \
         (relMSE pbrt), means over the runs; bias^2 and variance relative \
         (`/ (r^2 + 0.01)`), from the runs: bias^2 + variance = one run's relMSE.\n",
        a.scene.display(),
        a.seeds,
        a.seeds,
        a.reference.as_ref().map_or(
            format!("a {}-spp path-traced reference", a.reference_spp),
            |p| p.display().to_string()
        )
    );
    let _ = writeln!(
        md,
        "| technique | budget | time (s) | region | relMSE | relMSE pbrt | RMSE | mean / ref | bias^2 | variance |\n|---|---|---|---|---|---|---|---|---|---|"
    );
    let mut json = Vec::new();
    let make = |seed: u64| Scene::load_with(&a.scene, |f| f.seed = seed).map_err(|e| e.to_string());
    for t in techniques(a.quick) {
        for &amount in &t.ladder {
            let r = rung(
                &make, &t, amount, a.seeds, &reference, &regions, &cache, a.threads,
            )?;
            let label = format!("{} {}", r.amount, r.budget.name());
            println!(
                "{:<64} {label:>22} {:8.2} s  relMSE {:.5}",
                r.technique, r.seconds, r.regions[0].1.relmse
            );
            for (region, e, s) in &r.regions {
                let _ = writeln!(
                    md,
                    "| {} | {label} | {:.2} | {region} | {:.5} | {:.5} | {:.5} | {:.4} | {:.5} | {:.5} |",
                    r.technique,
                    r.seconds,
                    e.relmse,
                    e.relmse_pbrt,
                    e.rmse,
                    e.mean_ratio,
                    s.bias2,
                    s.variance
                );
                json.push(serde_json::json!({
                    "technique": r.technique, "budget": r.budget.name(), "amount": r.amount,
                    "seconds": r.seconds, "region": region, "pixels": s.pixels,
                    "relmse": e.relmse, "relmse_pbrt": e.relmse_pbrt, "rmse": e.rmse,
                    "mean_ratio": e.mean_ratio, "bias2": s.bias2, "variance": s.variance,
                    "mse": s.mse,
                }));
            }
            // Maps of each rung: EXR (linear) and false colour (square-root scale up to the
            // rung's 99th percentile of bias^2 + variance).
            let dir = a
                .out
                .join("maps")
                .join(slug(&format!("{}-{}", r.technique, r.amount)));
            std::fs::create_dir_all(&dir).map_err(|e| format!("{}: {e}", dir.display()))?;
            let mut both: Vec<f64> = r
                .maps
                .bias2
                .iter()
                .zip(&r.maps.variance)
                .map(|(b, v)| b + v)
                .collect();
            both.sort_by(f64::total_cmp);
            let top = both[(both.len() * 99 / 100).min(both.len() - 1)];
            for (name, map) in [("bias2", &r.maps.bias2), ("variance", &r.maps.variance)] {
                film::write_exr(dir.join(format!("{name}.exr")), &r.maps.image(map))
                    .map_err(|e| e.to_string())?;
                film::write_png(
                    dir.join(format!("{name}.png")),
                    &r.maps.false_colour(map, top),
                    &film::ToneMap {
                        gamma: 1.0,
                        exposure: 0.0,
                    },
                )
                .map_err(|e| e.to_string())?;
            }
            film::write_exr(dir.join("mean.exr"), &r.maps.mean).map_err(|e| e.to_string())?;
        }
    }
    k_sweep(a, &make, &reference, &regions, &cache, &mut md, &mut json)?;
    film::write_atomic(&a.out.join("evidence.md"), md.as_bytes()).map_err(|e| e.to_string())?;
    let text = serde_json::to_string_pretty(&json).map_err(|e| e.to_string())? + "\n";
    film::write_atomic(&a.out.join("evidence.json"), text.as_bytes()).map_err(|e| e.to_string())?;
    println!(
        "wrote {} (table), evidence.json and maps/",
        a.out.join("evidence.md").display()
    );
    Ok(())
}

/// The worksheet's trade-off itself: the global map shown directly, k swept for each kernel,
/// with and without the topological test and boundary correction, at a fixed photon count
/// (bias^2 rises and variance falls with k); then photons and k grown together (`photons /
/// k` fixed, so the disc keeps its size: the bias stays, the noise falls; each rung's time is
/// in evidence.json).
fn k_sweep(
    a: &EvidenceArgs,
    make: &dyn Fn(u64) -> Result<Scene, String>,
    reference: &Image,
    regions: &[(&'static str, Mask)],
    cache: &Path,
    md: &mut String,
    json: &mut Vec<serde_json::Value>,
) -> Result<(), String> {
    let ks: &[usize] = if a.quick {
        &[50, 250, 1000]
    } else {
        &[50, 100, 250, 500, 1000, 2000]
    };
    let photons = 200_000u64;
    let variants: [(&str, Kernel, Option<f32>, bool); 4] = [
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
    let _ = writeln!(
        md,
        "\n## The global map's k against bias and variance ({photons} photon paths)\n\n\
         | kernel | k | region | bias^2 | variance | relMSE |\n|---|---|---|---|---|---|"
    );
    let mut sweep = |md: &mut String, label: String, o: Overrides, amount: u64| {
        let t = Technique {
            name: "global map",
            overrides: o,
            budget: Budget::Photons,
            ladder: vec![amount],
        };
        let r = rung(
            make, &t, amount, a.seeds, reference, regions, cache, a.threads,
        )?;
        println!("k sweep {label:<58} relMSE {:.5}", r.regions[0].1.relmse);
        for (region, e, s) in &r.regions {
            let _ = writeln!(
                md,
                "| {label} | {region} | {:.5} | {:.5} | {:.5} |",
                s.bias2, s.variance, e.relmse
            );
            json.push(serde_json::json!({
                "sweep": label, "photons": amount, "region": region, "seconds": r.seconds,
                "mean_ratio": e.mean_ratio,
                "bias2": s.bias2, "variance": s.variance, "relmse": e.relmse,
            }));
        }
        Ok::<(), String>(())
    };
    for (name, kernel, topo, boundary) in variants {
        for &k in ks {
            let o = Overrides {
                method: Some(Method::GlobalDirect),
                k: Some(k),
                kernel: Some(kernel),
                topo: Some(topo),
                boundary: Some(boundary),
                ..Overrides::default()
            };
            sweep(md, format!("{name} | {k}"), o, photons)?;
        }
    }
    let _ = writeln!(
        md,
        "\n## Photons and k grown together (Silverman, photons / k = 200)\n\n\
         | kernel | k | region | bias^2 | variance | relMSE |\n|---|---|---|---|---|---|"
    );
    for &k in ks {
        let o = Overrides {
            method: Some(Method::GlobalDirect),
            k: Some(k),
            kernel: Some(Kernel::Silverman),
            ..Overrides::default()
        };
        let label = format!("Silverman, {} paths | {k}", 200 * k);
        sweep(md, label, o, 200 * k as u64)?;
    }
    Ok(())
}

fn slug(s: &str) -> String {
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
