//! photonflow against an independent renderer: region means of its images of the worksheet
//! scene at 128 x 128 against Mitsuba 3's (`tests/references/`, two halves with independent
//! seeds, made by `tests/references/make.sh`). Regions come from the scene's geometry
//! (`lab::regions`): the whole image, the caustic under the glass sphere, the inner edges and
//! corners, the outer rim, the glass sphere, the open walls.
//!
//! Every method is compared: the path tracer, the global map shown directly with each
//! kernel, final gathering, the splatted caustic layers (alone, added to the path tracer
//! without its caustics, and as `path+splat`) and SPPM. A region's tolerance is `Z`
//! combined standard errors: the reference's, from its halves (`(A - B)/2` per pixel), and
//! photonflow's, measured over independent seeds (the figures are in each method's table),
//! around the method's known bias where it has one (fixed-k estimates, fixed splat discs).
//! Negative controls change the scene a little (a light's power or one albedo by 2%) or
//! leave a layer out, and must fail.
//!
//! A glass sphere's refraction barely moves a region mean of the worksheet's wide view: the
//! light's image in the sphere and the caustic's focus are a few pixels there. The close-up
//! (`scenes/cornell-spheres/closeup.toml`, its own Mitsuba halves) resolves them, and a glass
//! of index 1.45 instead of 1.5 must fail it.
//!
//! One file per reference scene; this module holds what they share: the reference halves
//! and their region means ([`RegionRef`]), the methods' measured tables ([`Measured`]), the
//! comparison ([`misfits`]), one image per method run, and the regions of the scenes lit by
//! a point light, a spot light or an environment map alone.

mod closeup;
mod coloured_glass;
mod environment;
mod gallery;
mod glossy;
mod mcguire;
mod point_caustic;
mod rough;
mod spot_box;
mod textured;
mod worksheet;

use crate::kit::*;
use film::Image;
use render::Overrides;
use scene::{Method, Scene};

const RES: u32 = 128;
/// Combined standard errors a region mean may lie from the reference's.
const Z: f64 = 4.0;

fn reference_half(name: &str, half: &str) -> Image {
    let p = scenes_dir()
        .join("../tests/references")
        .join(format!("{name}-{RES}x{RES}-{half}.exr"));
    film::read_exr(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

/// The grey value of a pixel: its channels' mean.
fn grey(img: &Image, i: usize) -> f64 {
    img.data[i].iter().map(|&c| c as f64).sum::<f64>() / 3.0
}

/// Per region: the reference's mean (of the halves' mean) and its standard error.
struct RegionRef {
    name: &'static str,
    mask: film::Mask,
    mean: f64,
    se: f64,
}

/// The reference `name`'s mean and standard error over each of `masks`' non-empty regions.
fn region_refs(name: &str, masks: Vec<(&'static str, film::Mask)>) -> Vec<RegionRef> {
    let (a, b) = (reference_half(name, "a"), reference_half(name, "b"));
    region_refs_of(&a, &b, masks)
}

/// [`region_refs`] of the halves `a` and `b`.
fn region_refs_of(a: &Image, b: &Image, masks: Vec<(&'static str, film::Mask)>) -> Vec<RegionRef> {
    masks
        .into_iter()
        .filter(|(_, m)| m.count() > 0)
        .map(|(name, mask)| {
            let (mut sum, mut var, mut n) = (0.0, 0.0, 0.0);
            for i in (0..mask.pixels.len()).filter(|&i| mask.pixels[i]) {
                let (ga, gb) = (grey(a, i), grey(b, i));
                sum += 0.5 * (ga + gb);
                // The mean of two halves has variance (A - B)²/4 per pixel (unbiased).
                var += 0.25 * (ga - gb) * (ga - gb);
                n += 1.0;
            }
            RegionRef {
                name,
                mask,
                mean: sum / n,
                se: var.sqrt() / n,
            }
        })
        .collect()
}

/// The region means of `img` over `regions`.
fn means(img: &Image, regions: &[RegionRef]) -> Vec<f64> {
    regions
        .iter()
        .map(|r| {
            let idx: Vec<usize> = (0..r.mask.pixels.len())
                .filter(|&i| r.mask.pixels[i])
                .collect();
            idx.iter().map(|&i| grey(img, i)).sum::<f64>() / idx.len() as f64
        })
        .collect()
}

/// A method's region means against the reference's, `m / ref - 1`, measured over seeds 1-6,
/// per region in the order of `lab::regions::regions` (image, caustic, edges and corners,
/// outer rim, glass sphere, open walls) and the caustic's core: `bias` is the mean over the seeds where it lies
/// more than 3 of its standard errors from zero (the method's known bias), else 0; `sd` is
/// one run's standard deviation.
struct Measured<const N: usize = 7> {
    bias: [f64; N],
    sd: [f64; N],
}

/// Seeds behind every [`Measured`] table.
const SEEDS: f64 = 6.0;

/// Regions where `img` lies more than `Z` combined standard errors from the reference moved
/// by the method's known bias: the reference's standard error, one run's, and, where a bias
/// is allowed, the standard error of its measured value.
fn misfits<const N: usize>(img: &Image, regions: &[RegionRef], m: &Measured<N>) -> Vec<String> {
    assert_eq!(regions.len(), N, "the regions of the tables");
    let got = means(img, regions);
    let mut out = Vec::new();
    for (i, (r, g)) in regions.iter().zip(got).enumerate() {
        let (bias, sd) = (m.bias[i], m.sd[i]);
        let bias_se = if bias != 0.0 { sd / SEEDS.sqrt() } else { 0.0 };
        let rel_se = ((r.se / r.mean).powi(2) + sd * sd + bias_se * bias_se).sqrt();
        let rel = g / r.mean - 1.0;
        let z = (rel - bias) / rel_se;
        eprintln!(
            "  {:<18} photonflow {g:.6} reference {:.6} ({:+.3}%, known bias {:+.3}%, z {z:+.2}; \
             ref se {:.3}%)",
            r.name,
            r.mean,
            100.0 * rel,
            100.0 * bias,
            100.0 * r.se / r.mean
        );
        if z.abs() > Z {
            out.push(format!(
                "{}: {g:.6} against {:.6} ({:+.2}%, known bias {:+.2}%, z {z:+.1})",
                r.name,
                r.mean,
                100.0 * rel,
                100.0 * bias
            ));
        }
    }
    out
}

/// One image of `s` by `method` at `count` samples per pixel (path, path+splat) or passes
/// (SPPM, VCM).
fn image_by(s: &Scene, method: Method, count: u32) -> Image {
    let passes = matches!(method, Method::Sppm | Method::Vcm);
    let o = Overrides {
        method: Some(method),
        spp: (!passes).then_some(count),
        passes: passes.then_some(count),
        ..Overrides::default()
    };
    sum_layers(&render_uncached(s, &o, None), |_| true)
}

/// The seed of the runs whose tables are re-measured by running their tests with
/// `PHOTONFLOW_TABLE_SEED` set to 1, ..., 6 (the figures in the tables' comments); 1 else.
fn table_seed() -> u64 {
    std::env::var("PHOTONFLOW_TABLE_SEED")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(1)
}

/// The light tracer's run of `s`: `passes` passes of `photons` paths.
fn light_run(s: &Scene, passes: u32, photons: u64) -> render::Rendered {
    let o = Overrides {
        method: Some(Method::Light),
        passes: Some(passes),
        photons: Some(photons),
        ..Overrides::default()
    };
    render_uncached(s, &o, None)
}

/// The misfits of each run's image of `s` (method, count, its table) against `regs`.
fn misfits_of_runs<const N: usize>(
    s: &Scene,
    regs: &[RegionRef],
    runs: &[(Method, u32, &Measured<N>)],
) -> Vec<String> {
    let mut bad = Vec::new();
    for &(method, count, table) in runs {
        eprintln!("{method:?}, {count}:");
        bad.extend(misfits(&image_by(s, method, count), regs, table));
    }
    bad
}

// ---------------------------------------------------------------------------------------------
// Scenes lit by a point light, a spot light and an environment map alone.

/// Where the light of a light-scene region comes from: a point or spot light's position, or
/// the direction towards the environment map's sun.
#[derive(Clone, Copy)]
enum Toward {
    Point(glam::Vec3),
    Direction(glam::Vec3),
}

/// What the camera sees through `(x, y)` in a light scene: `background`; a sphere by its
/// material's name; or a mesh surface: `core` (in the glass sphere's shadow within 0.4 of its
/// radius of the axis from the light through the sphere's centre, where its caustic
/// focuses), `shadow` (elsewhere in that shadow, the rest of the caustic), `ceiling` (a
/// surface facing down at the camera) or `lit`.
fn light_scene_label(scene: &Scene, toward: Toward, x: f32, y: f32) -> &'static str {
    let glass = scene
        .geometry
        .spheres()
        .iter()
        .find(|s| scene.material_names[s.material as usize] == "glass")
        .expect("a glass sphere");
    let names = |m: u32| -> &'static str {
        match scene.material_names[m as usize].as_str() {
            "glass" => "glass",
            "silver" => "silver",
            "clay" => "clay",
            _ => "other sphere",
        }
    };
    let ray = scene.camera.ray(x, y);
    let Some(hit) = scene.geometry.intersect(&ray) else {
        return "background";
    };
    if matches!(hit.prim, geom::Prim::Sphere(_)) {
        return names(hit.material);
    }
    let p = hit.point.p;
    let (to_light, axis_from) = match toward {
        Toward::Point(l) => ((l - p).normalize(), l),
        Toward::Direction(d) => (d, glass.center + d * 100.0),
    };
    let shadowed = scene
        .geometry
        .intersect(&hit.point.spawn_ray(to_light))
        .is_some_and(|h| matches!(h.prim, geom::Prim::Sphere(_)) && names(h.material) == "glass");
    if shadowed {
        // The axis meets the receiver where a ray from just past the sphere, away from the
        // light, lands.
        let axis = (glass.center - axis_from).normalize();
        let from = glass.center + axis * (glass.radius * 1.001);
        let c = scene
            .geometry
            .intersect(&geom::Ray::new(from, axis))
            .map(|h| h.point.p);
        return match c {
            Some(c) if (p - c).length() < 0.4 * glass.radius => "core",
            _ => "shadow",
        };
    }
    let ng = hit.point.n;
    let facing = if ng.dot(-ray.d) >= 0.0 { ng } else { -ng };
    if facing.y < -0.9 { "ceiling" } else { "lit" }
}

/// Regions of a light scene: pixels whose every [`PIXEL_POINTS`] carries a label of `group`
/// (see [`light_scene_label`]), for each `(name, group)`.
fn light_scene_regions(
    scene: &Scene,
    reference: &str,
    toward: Toward,
    groups: &[(&'static str, &[&str])],
) -> Vec<RegionRef> {
    let (w, h) = (RES as usize, RES as usize);
    let labels: Vec<[&str; 5]> = (0..w * h)
        .map(|i| {
            let (x, y) = ((i % w) as f32, (i / w) as f32);
            PIXEL_POINTS.map(|(u, v)| light_scene_label(scene, toward, x + u, y + v))
        })
        .collect();
    let masks = groups
        .iter()
        .map(|(name, group)| {
            let pixels = labels
                .iter()
                .map(|l| group.is_empty() || l.iter().all(|s| group.contains(s)))
                .collect();
            (
                *name,
                film::Mask {
                    width: w,
                    height: h,
                    pixels,
                },
            )
        })
        .collect();
    region_refs(reference, masks)
}

/// Regions of the light-traced references (Mitsuba's `ptracer` draws no specular surface
/// the camera sees): the diffuse surfaces seen directly, those lit directly, the glass
/// sphere's shadow with its caustic, the caustic's core, and (in the box) the ceiling.
const DIRECT_GROUPS: [(&str, &[&str]); 5] = [
    ("diffuse seen", &["lit", "shadow", "core", "ceiling"]),
    ("lit", &["lit"]),
    ("glass shadow", &["shadow", "core"]),
    ("caustic core", &["core"]),
    ("ceiling", &["ceiling"]),
];
