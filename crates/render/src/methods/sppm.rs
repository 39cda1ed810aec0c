//! `sppm`: stochastic progressive photon mapping (Hachisuka and Jensen 2009; pbrt-v4 §16.2).
//! Every pass draws one camera sample per pixel to its first diffuse vertex (the visible
//! point, `eye::visible_points`; emission on the way and direct light by next-event
//! estimation there), traces `photons` new paths whose photons after at least one bounce
//! (with `direct` off: all of them) go into a kd-tree for that pass only, and updates each
//! pixel's statistics from the photons within its radius R:
//!
//! `N' = N + α M`, `R' = R sqrt(N' / (N + M))`, `τ' = (τ + β Φ) R'² / R²`,
//!
//! with M the photons found, Φ their kernel-weighted flux (`E π R²`, `E` from
//! `PhotonMap::irradiance_within` with `[estimate.global]`'s kernel and tests) and β the
//! visible point's weight. After J passes a pixel is `direct / J + τ / (J π R²)`: radii
//! shrink so that bias vanishes while the photon count in them still grows, so the error
//! goes to zero (consistent), unlike a fixed k or radius.

use super::{CountKind, Layer, Rendered, Run, Snapshot};
use crate::settings::SppmSettings;
use density::{IndexKind, PhotonMap};
use emit::{EmitParams, Plan};
use film::Class;
use flow::PipelineOptions;
use glam::{DVec3, Vec3};
use rayon::prelude::*;
use scene::Scene;
use store::MapKind;

/// Expected photons of the first pass inside a start radius on a surface lit as evenly as
/// the scene's total diffuse area would be: enough to keep the first passes from being
/// blotchy, few enough for their bias to fade within a few passes.
const START_PHOTONS: f64 = 32.0;

/// A pixel's running statistics.
#[derive(Clone, Copy, Debug)]
struct Stats {
    n: f64,
    tau: DVec3,
    r: f32,
    /// Sum over passes of emission and direct light.
    light: DVec3,
}

/// The automatic start radius: the radius holding [`START_PHOTONS`] photons of one pass if
/// they spread evenly over the scene's diffuse area, but at least two pixel footprints at
/// the distance from the camera to the scene's centre (smaller than a pixel, a radius only
/// adds noise).
pub fn start_radius(scene: &Scene, photons_per_pass: u64) -> f32 {
    let area = diffuse_area(scene);
    let even = (START_PHOTONS * area / (std::f64::consts::PI * photons_per_pass.max(1) as f64))
        .sqrt() as f32;
    let b = scene.geometry.bounds();
    let centre = 0.5 * (b.min + b.max);
    let distance = (centre - scene.camera.eye).length();
    let pixel_angle =
        2.0 * (scene.camera.vfov_deg.to_radians() * 0.5).tan() / scene.camera.height as f32;
    let r = even.max(2.0 * distance * pixel_angle);
    if r.is_finite() && r > 0.0 { r } else { 1.0 }
}

/// Total area of the surfaces with a diffuse material, in f64.
fn diffuse_area(scene: &Scene) -> f64 {
    let mesh = scene.geometry.mesh();
    let tris: f64 = (0..mesh.len())
        .filter(|&t| scene.is_diffuse(mesh.materials[t]))
        .map(|t| mesh.area(t) as f64)
        .sum();
    let spheres: f64 = scene
        .geometry
        .spheres()
        .iter()
        .filter(|s| scene.is_diffuse(s.material))
        .map(|s| 4.0 * std::f64::consts::PI * (s.radius as f64).powi(2))
        .sum();
    tris + spheres
}

/// The photons of pass `pass` that the visible points gather: every diffuse hit after at
/// least one bounce (and the first ones too unless direct light is estimated at the visible
/// points), through the channel pipeline in chunk order.
fn pass_photons(
    scene: &Scene,
    params: &EmitParams,
    plan: &Plan,
    pass: u64,
    threads: usize,
) -> Result<Vec<store::Photon>, String> {
    let mut photons = Vec::new();
    flow::run_chunks(
        params.photons,
        &PipelineOptions::new(threads),
        &|range| emit::trace_pass(scene, params, plan, pass, range),
        &mut |mut t: emit::Traced| {
            photons.append(&mut t.sets[MapKind::Global]);
            Ok(())
        },
    )?;
    Ok(photons)
}

pub(super) fn render(run: &Run, progress: &(dyn Fn(u64) + Sync)) -> Result<Rendered, String> {
    let scene = run.scene;
    let s = run.settings;
    let sp: &SppmSettings = &s.estimate.sppm;
    let mut params = s.emit.clone();
    if sp.photons > 0 {
        params.photons = sp.photons;
    }
    // Photons at every diffuse hit, the first one only if no next-event estimation.
    params.global = true;
    params.caustic = false;
    params.store_direct = !sp.direct;
    let plan =
        Plan::for_scene(scene, &params).map_err(|e| format!("{}: {e}", scene.path.display()))?;
    // No diffuse surface (all black, or only mirrors and glass): a valid scene whose photon
    // layer is black; the passes still average what the eye sees of the emitters.
    if !plan.global {
        print!("{plan}");
    }
    let est = s.estimate.global;
    let r0 = if sp.radius > 0.0 {
        sp.radius
    } else {
        start_radius(scene, params.photons)
    };
    let (w, h) = (scene.camera.width as usize, scene.camera.height as usize);
    let mut stats = vec![
        Stats {
            n: 0.0,
            tau: DVec3::ZERO,
            r: r0,
            light: DVec3::ZERO,
        };
        w * h
    ];
    let alpha = sp.alpha as f64;
    let t0 = std::time::Instant::now();
    let mut passes = 0u32;
    let mut snapshots = Vec::new();
    let mut photons_stored = 0u64;
    while passes < sp.passes {
        let pass = passes as u64;
        let points = eye::visible_points(scene, pass, sp.direct, run.threads);
        let photons = if plan.global {
            pass_photons(scene, &params, &plan, pass, run.threads())?
        } else {
            Vec::new()
        };
        photons_stored += photons.len() as u64;
        let map = PhotonMap::build(photons, IndexKind::KdTree);
        // Each pixel's update reads only its own statistics: the same for any thread count.
        eye::on_threads(run.threads, || {
            stats
                .par_iter_mut()
                .zip(&points)
                .for_each_init(Vec::new, |scratch, (st, ps)| {
                    st.light += ps.light.as_dvec3();
                    let Some(vp) = ps.point else {
                        return;
                    };
                    let e = map.irradiance_within(vp.p, vp.n, st.r, &est, scratch);
                    let m = scratch.len() as f64;
                    if m == 0.0 {
                        return;
                    }
                    let n_new = st.n + alpha * m;
                    let r_new = st.r as f64 * (n_new / (st.n + m)).sqrt();
                    let r2 = (st.r as f64).powi(2);
                    let phi = (vp.weight * e).as_dvec3() * (std::f64::consts::PI * r2);
                    st.tau = (st.tau + phi) * (r_new * r_new / r2);
                    st.n = n_new;
                    st.r = r_new as f32;
                });
        });
        passes += 1;
        progress((w * h) as u64);
        let elapsed = t0.elapsed().as_secs_f64();
        // Passes left: to the count, or to the time budget if that comes first.
        let left = (sp.passes - passes) as f64 * elapsed / passes as f64;
        let left = s.time.map_or(left, |t| left.min((t - elapsed).max(0.0)));
        eprintln!(
            "sppm pass {passes}/{}: {elapsed:.2} s, {:.3} M photon paths/s, about {left:.1} s left",
            sp.passes,
            (passes as u64 * params.photons) as f64 / elapsed / 1e6
        );
        if passes.is_power_of_two() || passes == sp.passes {
            snapshots.push(Snapshot {
                passes,
                seconds: elapsed,
                layers: layers(&stats, passes, w, h, params.photons, sp.direct),
            });
        }
        if s.time.is_some_and(|t| elapsed >= t) {
            break;
        }
    }
    let seconds = t0.elapsed().as_secs_f64();
    let mut info = serde_json::Map::new();
    let r_mean = stats.iter().map(|st| st.r as f64).sum::<f64>() / stats.len().max(1) as f64;
    for (k, v) in [
        ("sppm", serde_json::json!(sp)),
        ("sppm_passes", passes.into()),
        ("sppm_start_radius", r0.into()),
        ("sppm_mean_final_radius", r_mean.into()),
        ("sppm_photons_per_pass", params.photons.into()),
        ("sppm_photons_stored", photons_stored.into()),
        ("global_estimate", serde_json::json!(est)),
        ("time_sppm_s", seconds.into()),
        (
            "photons_per_s",
            ((passes as u64 * params.photons) as f64 / seconds).into(),
        ),
    ] {
        info.insert(k.to_string(), v);
    }
    let layers = layers(&stats, passes, w, h, params.photons, sp.direct);
    Ok(Rendered {
        layers,
        plan: Some(plan),
        info,
        passes: Some(passes),
        samples: None,
        snapshots,
    })
}

/// The image after `passes` passes: `light` (emission, and direct light when estimated at
/// the visible points) and `photons` (everything else), each a mean over passes.
fn layers(
    stats: &[Stats],
    passes: u32,
    w: usize,
    h: usize,
    per_pass: u64,
    direct: bool,
) -> Vec<Layer> {
    let j = passes.max(1) as f64;
    let light = film::Image::from_fn(w, h, |x, y| {
        (stats[y * w + x].light / j).as_vec3().to_array()
    });
    let photons = film::Image::from_fn(w, h, |x, y| {
        let st = &stats[y * w + x];
        let area = std::f64::consts::PI * (st.r as f64).powi(2);
        let v: Vec3 = if area > 0.0 {
            (st.tau / (j * area)).as_vec3()
        } else {
            Vec3::ZERO
        };
        v.to_array()
    });
    vec![
        Layer {
            name: "light".into(),
            classes: if direct {
                vec![Class::Emitted, Class::Direct]
            } else {
                vec![Class::Emitted]
            },
            image: light,
            count: passes as u64,
            count_kind: CountKind::Spp,
        },
        Layer {
            name: "photons".into(),
            classes: if direct {
                vec![Class::Indirect, Class::Caustic, Class::CausticIndirect]
            } else {
                vec![
                    Class::Direct,
                    Class::Indirect,
                    Class::Caustic,
                    Class::CausticIndirect,
                ]
            },
            image: photons,
            count: passes as u64 * per_pass,
            count_kind: CountKind::PhotonPaths,
        },
    ]
}
