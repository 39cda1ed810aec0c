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
//!
//! The radii shrink slowly (R ∝ J^(-(1-α)/2), J^(-1/6) at α = 2/3), so a disc that runs off
//! a surface's open edge keeps the rim dark for hundreds of passes (-4% over the worksheet
//! scene's outer rim after 64 passes, -0.2% over the whole image). Each pass's estimate is
//! therefore divided by the share of its disc on the surface (`crate::boundary`, Jensen 2001
//! §7.2), as `[estimate.sppm] boundary` asks by default.

use crate::boundary::{MIN_MASS, kernel_mass_on_surface};
use crate::passes::Pass;
use crate::rendered::{CountKind, Layer, Rendered};
use crate::run::Run;
use crate::settings::{Knob, SPPM_BOUNDARY_TOPO, SppmSettings};
use density::sppm::PixelStats;
use density::{IndexKind, PhotonMap};
use emit::{EmitParams, Plan};
use film::Class;
use flow::PipelineOptions;
use rayon::prelude::*;
use scene::Scene;
use store::MapKind;

/// Expected photons of the first pass inside a start radius on a surface lit as evenly as
/// the scene's total diffuse area would be: enough to keep the first passes from being
/// blotchy, few enough for their bias to fade within a few passes.
const START_PHOTONS: f64 = 32.0;

/// Photons of its first pass in a visible point's own start radius. The global radius holds
/// [`START_PHOTONS`] on average, but every pixel of the worksheet scene finds at least that
/// many within it (the 3D ball also reaches photons of nearby surfaces): 128 widens the
/// radius where photons are sparse. Measured on the worksheet at 128 x 128 (noise-corrected
/// relative MSE against Mitsuba, seeds 2 and 3): 32 changes nothing, 64 with a floor of r0/4
/// loses 7%, 128 and 256 with a floor of r0/2 win 4% after 1 pass and 7-8% after 16. At 512
/// x 512 a pass's gathering then takes 6.5 s instead of 2.9 s (4 passes, profile of
/// `image.json`): more photons in every disc. So it is off unless asked for.
const ADAPTIVE_K: usize = 128;

/// A visible point's own start radius (`[estimate.sppm] adaptive`): the distance to its
/// [`ADAPTIVE_K`]-th nearest photon of the pass it first appears in, kept within
/// `[r0 / 2, 4 r0]` of the global start radius `r0` (and `4 r0` where fewer are that near).
/// The radius of a k-nearest-neighbour photon map estimate (Jensen 2001 §7.1), used once to
/// start the progressive radius where the density is.
pub(crate) fn adaptive_radius(
    map: &PhotonMap,
    p: glam::Vec3,
    r0: f32,
    scratch: &mut Vec<density::Neighbor>,
) -> f32 {
    map.knn(p, ADAPTIVE_K, 4.0 * r0, scratch);
    let r = if scratch.len() == ADAPTIVE_K {
        scratch[ADAPTIVE_K - 1].d2.sqrt()
    } else {
        4.0 * r0
    };
    r.clamp(0.5 * r0, 4.0 * r0)
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

/// A disc found wholly on one surface: its centre, normal and radius. A pixel's later
/// visible points, a jitter apart, with discs that shrink, mostly fall inside it.
#[derive(Clone, Copy)]
struct Inside {
    p: glam::Vec3,
    n: glam::Vec3,
    r: f32,
}

/// The share of the disc (radius `r` about `p`, normal `n`) on the surface, bounded below by
/// `MIN_MASS`, as [`kernel_mass_on_surface`] finds it, but asking no ray where the disc lies
/// within the pixel's last disc found wholly on the same plane (`inside`): SPPM asks every
/// pixel every pass, and most discs are far from any edge. A disc that must be probed is
/// probed a quarter larger first, so that the next passes' discs fit in it.
fn mass_on_surface(
    scene: &Scene,
    p: glam::Vec3,
    n: glam::Vec3,
    r: f32,
    est: &density::EstimateParams,
    inside: &mut Option<Inside>,
) -> f32 {
    if let Some(i) = inside
        && i.n.dot(n) > 0.9999
        && (p - i.p).dot(i.n).abs() < 1e-3 * i.r
        && (p - i.p).length() + r <= i.r
    {
        return 1.0;
    }
    let grown = 1.25 * r;
    if kernel_mass_on_surface(scene, p, n, grown, est) == 1.0 {
        *inside = Some(Inside { p, n, r: grown });
        return 1.0;
    }
    kernel_mass_on_surface(scene, p, n, r, est).max(MIN_MASS)
}

/// The statistics of one of a pixel's visible points past a glass split, by its branch
/// (`eye::VisiblePoint::branch`): each Fresnel branch sees its own surface, so each keeps its
/// own radius and flux (Hachisuka and Jensen 2009 keep one per visible point).
struct Split {
    branch: u32,
    stats: PixelStats,
    inside: Option<Inside>,
}

/// SPPM's image being made pass by pass: per pixel, its statistics (`density::sppm`).
struct Sppm<'a> {
    run: &'a Run<'a>,
    params: EmitParams,
    plan: Plan,
    r0: f32,
    /// `[estimate.global]`'s parameters, with the topological test the boundary
    /// correction needs.
    est: density::EstimateParams,
    boundary: bool,
    stats: Vec<PixelStats>,
    /// Per pixel, the last disc found wholly on its surface (see [`mass_on_surface`]).
    inside: Vec<Option<Inside>>,
    /// Per pixel, its main point's radius has been started (`[estimate.sppm] adaptive`).
    started: Vec<bool>,
    /// Per pixel, the statistics of its split visible points (empty for a pixel that never
    /// saw glass), in the order their branches first appeared.
    splits: Vec<Vec<Split>>,
    passes: u32,
    photons_stored: u64,
    t0: std::time::Instant,
    /// Seconds spent so far per part of a pass: [`PROFILE`]'s order.
    profile: [f64; 4],
}

/// The parts of a pass that `image.json` times (`time_sppm_<part>_s`).
const PROFILE: [&str; 4] = ["eye", "trace", "index", "gather"];

impl<'a> Sppm<'a> {
    fn new(run: &'a Run<'a>) -> Result<Sppm<'a>, String> {
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
        let plan = Plan::for_scene(scene, &params)
            .map_err(|e| format!("{}: {e}", scene.path.display()))?;
        // No diffuse surface (all black, or only mirrors and glass): a valid scene whose
        // photon layer is black; the passes still average what the eye sees of the emitters.
        if !plan.global {
            print!("{plan}");
        }
        let r0 = if sp.radius > 0.0 {
            sp.radius
        } else {
            start_radius(scene, params.photons)
        };
        let pixels = (scene.camera.width * scene.camera.height) as usize;
        let boundary = sp.boundary || s.estimate.boundary;
        let mut est = s.estimate.global;
        if boundary && est.topo.is_none() {
            est.topo = Some(SPPM_BOUNDARY_TOPO);
        }
        Ok(Sppm {
            run,
            params,
            plan,
            r0,
            est,
            boundary,
            stats: vec![PixelStats::new(r0); pixels],
            inside: vec![None; pixels],
            started: vec![false; pixels],
            splits: (0..pixels).map(|_| Vec::new()).collect(),
            passes: 0,
            photons_stored: 0,
            t0: std::time::Instant::now(),
            profile: [0.0; 4],
        })
    }
}

impl crate::passes::Progressive for Sppm<'_> {
    fn done(&self) -> u32 {
        self.passes
    }

    fn total(&self) -> u32 {
        self.run.settings.estimate.sppm.passes
    }

    fn limit(&self) -> (u32, String) {
        (Knob::SppmPasses.max(), Knob::SppmPasses.at_max())
    }

    /// One photon pass, whatever `_pass` allows: its size is the photons per pass, which the
    /// statistics' update assumes.
    fn step(&mut self, _pass: Pass, progress: &(dyn Fn(u64) + Sync)) -> Result<(), String> {
        let (run, scene, s) = (self.run, self.run.scene, self.run.settings);
        let sp = &s.estimate.sppm;
        let pass = self.passes as u64;
        let mut clock = std::time::Instant::now();
        let mut lap = |part: usize, profile: &mut [f64; 4]| {
            let now = std::time::Instant::now();
            profile[part] += (now - clock).as_secs_f64();
            clock = now;
        };
        let points = eye::visible_points(scene, pass, sp.direct, sp.splits, run.threads);
        lap(0, &mut self.profile);
        let photons = if self.plan.global {
            pass_photons(scene, &self.params, &self.plan, pass, run.threads())?
        } else {
            Vec::new()
        };
        self.photons_stored += photons.len() as u64;
        lap(1, &mut self.profile);
        let map = PhotonMap::build(photons, IndexKind::KdTree);
        lap(2, &mut self.profile);
        let (est, boundary) = (self.est, self.boundary);
        let alpha = sp.alpha as f64;
        // Each pixel's update reads only its own statistics: the same for any thread count.
        eye::on_threads(run.threads, || {
            let (r0, adaptive) = (self.r0, sp.adaptive);
            self.stats
                .par_iter_mut()
                .zip(&mut self.inside)
                .zip(&mut self.started)
                .zip(&mut self.splits)
                .zip(&points)
                .for_each_init(
                    Vec::new,
                    |scratch, ((((st, inside), started), splits), ps)| {
                        st.add_light(ps.light);
                        for vp in &ps.points {
                            let (st, inside, new) = if vp.branch == 1 {
                                (&mut *st, &mut *inside, !std::mem::replace(started, true))
                            } else {
                                let i = splits.iter().position(|s| s.branch == vp.branch);
                                let new = i.is_none();
                                let i = i.unwrap_or_else(|| {
                                    splits.push(Split {
                                        branch: vp.branch,
                                        stats: PixelStats::new(r0),
                                        inside: None,
                                    });
                                    splits.len() - 1
                                });
                                let s = &mut splits[i];
                                (&mut s.stats, &mut s.inside, new)
                            };
                            if new && adaptive {
                                st.r = adaptive_radius(&map, vp.p, r0, scratch);
                            }
                            let mut e = map.irradiance_within(vp.p, vp.n, st.r, &est, scratch);
                            if boundary && !scratch.is_empty() {
                                e /= mass_on_surface(scene, vp.p, vp.n, st.r, &est, inside);
                            }
                            st.update(scratch.len(), e, vp.weight, alpha);
                        }
                    },
                );
        });
        lap(3, &mut self.profile);
        self.passes += 1;
        let passes = self.passes;
        progress(self.stats.len() as u64);
        let elapsed = self.t0.elapsed().as_secs_f64();
        // Time left: to the count, or to the time budget if that comes first; a budget alone
        // has no count to show.
        let by_count = sp.passes.saturating_sub(passes) as f64 * elapsed / passes as f64;
        let (of, left) = match s.time {
            Some(b) if !b.capped => (String::new(), (b.seconds - elapsed).max(0.0)),
            b => (
                format!("/{}", sp.passes),
                b.map_or(by_count, |b| by_count.min((b.seconds - elapsed).max(0.0))),
            ),
        };
        eprintln!(
            "sppm pass {passes}{of}: {elapsed:.2} s, {:.3} M photon paths/s, about {left:.1} s left",
            (passes as u64 * self.params.photons) as f64 / elapsed / 1e6
        );
        Ok(())
    }

    fn layers(&self) -> Vec<Layer> {
        let scene = self.run.scene;
        layers(
            &self.stats,
            &self.splits,
            self.passes,
            scene.camera.width as usize,
            scene.camera.height as usize,
            self.params.photons,
            self.run.settings.estimate.sppm.direct,
        )
    }

    fn finish(&self, seconds: f64) -> Rendered {
        let sp = &self.run.settings.estimate.sppm;
        let passes = self.passes;
        let mut info = serde_json::Map::new();
        let stats = &self.stats;
        let r_mean = stats.iter().map(|st| st.r as f64).sum::<f64>() / stats.len().max(1) as f64;
        for (k, v) in [
            // The settings of the run made: a time budget sets the passes.
            ("sppm", serde_json::json!(SppmSettings { passes, ..*sp })),
            ("sppm_passes", passes.into()),
            ("sppm_start_radius", self.r0.into()),
            ("sppm_mean_final_radius", r_mean.into()),
            ("sppm_photons_per_pass", self.params.photons.into()),
            ("sppm_photons_stored", self.photons_stored.into()),
            ("global_estimate", serde_json::json!(self.est)),
            ("boundary_correction", self.boundary.into()),
            ("time_sppm_s", seconds.into()),
            (
                "photons_per_s",
                ((passes as u64 * self.params.photons) as f64 / seconds).into(),
            ),
        ] {
            info.insert(k.to_string(), v);
        }
        for (part, t) in PROFILE.iter().zip(self.profile) {
            info.insert(format!("time_sppm_{part}_s"), t.into());
        }
        Rendered {
            plan: Some(self.plan.clone()),
            passes: Some(passes),
            ..Rendered::new(self.layers(), info)
        }
    }
}

pub(super) fn render(run: &Run, progress: &(dyn Fn(u64) + Sync)) -> Result<Rendered, String> {
    let mut sppm = Sppm::new(run)?;
    crate::passes::run(&mut sppm, run.settings.time, progress)
}

/// The image after `passes` passes: `light` (emission, and direct light when estimated at
/// the visible points) and `photons` (everything else), each a mean over passes.
fn layers(
    stats: &[PixelStats],
    splits: &[Vec<Split>],
    passes: u32,
    w: usize,
    h: usize,
    per_pass: u64,
    direct: bool,
) -> Vec<Layer> {
    let light = film::Image::from_fn(w, h, |x, y| {
        stats[y * w + x].light_radiance(passes).to_array()
    });
    // Each point's statistics hold the sum over passes of its weighted estimate, zero in
    // the passes it was not seen: the pixel is their sum.
    let photons = film::Image::from_fn(w, h, |x, y| {
        let i = y * w + x;
        let split: glam::DVec3 = splits[i]
            .iter()
            .map(|s| s.stats.photon_radiance(passes).as_dvec3())
            .sum();
        if split == glam::DVec3::ZERO {
            return stats[i].photon_radiance(passes).to_array();
        }
        (stats[i].photon_radiance(passes).as_dvec3() + split)
            .as_vec3()
            .to_array()
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
