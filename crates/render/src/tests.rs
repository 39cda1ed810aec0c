//! Unit tests of the photon maps' helpers: the boundary correction's kernel mass, the
//! irradiance cache of final gathering. The pass loop and the path tracer's passes have
//! modules of their own.

/// The progressive pass loop on a simulated clock: time budgets used, capped and bounded.
mod passes;
/// The path tracer's passes: unchanged without a budget, every power of two of samples ends
/// one under a budget.
mod path;

use emit::{EmitParams, Plan};
use std::path::{Path, PathBuf};

fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("photonflow-render-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    d
}

fn cornell() -> scene::Scene {
    let p =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/cornell-spheres/analytic.toml");
    scene::Scene::load(p).unwrap()
}

#[test]
fn kernel_mass_on_surface_is_one_inside_and_drops_at_edges_and_corners() {
    use crate::boundary::kernel_mass_on_surface;
    use density::{EstimateParams, Kernel};
    use glam::Vec3;
    let s = cornell();
    let with = |kernel| EstimateParams {
        kernel,
        topo: Some(0.1),
        ..EstimateParams::default()
    };
    // Floor centre, away from the spheres' footprints: the whole disc is floor.
    let centre = Vec3::new(-7.0, 0.0, -2.0);
    let m = kernel_mass_on_surface(&s, centre, Vec3::Y, 0.5, &with(Kernel::Uniform));
    assert_eq!(m, 1.0);
    // At the back wall (z = -13.98), the floor disc is cut in half.
    let edge = Vec3::new(-7.0, 0.0, -13.98);
    let m = kernel_mass_on_surface(&s, edge, Vec3::Y, 0.5, &with(Kernel::Uniform));
    assert!((m - 0.5).abs() < 0.07, "{m}");
    // In the floor's corner with the right wall (x = 0): a quarter.
    let corner = Vec3::new(0.0, 0.0, -13.98);
    let m = kernel_mass_on_surface(&s, corner, Vec3::Y, 0.5, &with(Kernel::Uniform));
    assert!((m - 0.25).abs() < 0.07, "{m}");
    // Past the open front (z = 0) the floor ends too.
    let front = Vec3::new(-7.0, 0.0, 0.0);
    let m = kernel_mass_on_surface(&s, front, Vec3::Y, 0.5, &with(Kernel::Silverman));
    assert!((m - 0.5).abs() < 0.07, "{m}");
}

#[test]
fn the_gather_cache_answers_like_the_map_it_summarises() {
    use crate::gather_cache::IrradianceCache;
    use density::{EstimateParams, IndexKind, PhotonMap};
    use glam::Vec3;
    let p = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/corner/corner.toml");
    let scene = scene::Scene::load(p).unwrap();
    let params = EmitParams {
        photons: 40_000,
        ..EmitParams::default()
    };
    let plan = Plan::for_scene(&scene, &params).unwrap();
    let traced = emit::trace_range(&scene, &params, &plan, 0..params.photons);
    let map = PhotonMap::build(traced.sets.0[0].clone(), IndexKind::KdTree);
    let est = EstimateParams {
        k: 100,
        ..EstimateParams::default()
    };
    let estimate = |x: Vec3, n: Vec3, h: &mut density::KnnHint, s: &mut Vec<density::Neighbor>| {
        (map.irradiance_hinted(x, n, &est, h, s), h.r)
    };
    let cache = IrradianceCache::build(&scene, Some(&map), 4, &estimate);
    assert!(
        cache.len() > map.len() / 5,
        "{} of {}",
        cache.len(),
        map.len()
    );
    // Point by point on the floor (normal +y) away from the wall, the cached answer is a
    // neighbouring point's estimate: two k-NN estimates each with relative noise ~1/sqrt(k),
    // so they differ by less than 4 sqrt(2) / sqrt(k) (57% at k = 100) point by point, and
    // by less than 2% in the mean over 2000 points.
    let per_point = 4.0 * 2f64.sqrt() / (est.k as f64).sqrt();
    let mut rng = math::Rng::new(3);
    let (mut exact, mut cached) = (0.0f64, 0.0f64);
    let mut scratch = Vec::new();
    for _ in 0..2000 {
        let x = Vec3::new(0.5 + 3.0 * rng.uniform(), 0.0, -1.5 + 3.0 * rng.uniform());
        let e = map.irradiance(x, Vec3::Y, &est, &mut scratch).x as f64;
        let c = cache
            .lookup(x, Vec3::Y)
            .expect("a floor point near every floor query")
            .x as f64;
        assert!(
            (c / e - 1.0).abs() < per_point,
            "cached {c} vs {e} at {x:?}"
        );
        exact += e;
        cached += c;
    }
    assert!(
        (cached / exact - 1.0).abs() < 0.02,
        "cached {cached} vs exact {exact}"
    );
    // On the wall (normal +x) the cache answers from wall points: their value tracks the
    // wall's own estimate, not the floor's.
    for y in [0.5f32, 1.0, 2.0] {
        let x = Vec3::new(0.0, y, 0.3);
        let e = map.irradiance(x, Vec3::X, &est, &mut scratch).x;
        let c = cache
            .lookup(x, Vec3::X)
            .expect("wall points near the wall query")
            .x;
        assert!(
            (c / e - 1.0).abs() < per_point as f32,
            "wall: cached {c} vs {e}"
        );
    }
    // Far from every photon (outside the scene) nothing answers.
    assert!(cache.lookup(Vec3::new(50.0, 0.0, 0.0), Vec3::Y).is_none());
}

#[test]
fn boundary_correction_removes_the_darkening_at_an_edge_and_a_corner() {
    // A 4 x 4 floor with photons of uniform density (irradiance E0 = 1) and nothing beyond
    // it: plain estimates near the edge see half a disc of photons (a quarter in the corner),
    // corrected ones divide by the kernel mass on the floor and recover E0.
    use crate::maps::Maps;
    use density::{EstimateParams, IndexKind, Kernel, KnnHint, PhotonMap};
    use glam::Vec3;
    use store::{MapKind, PerKind};
    let dir = scratch("edge");
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(
        dir.join("f.obj"),
        "mtllib f.mtl\no floor\nusemtl white\nv 0 0 0\nv 0 0 4\nv 4 0 4\nv 4 0 0\nf 1 2 3\nf 1 3 4\n\
         o light\nusemtl light\nv 1 3 1\nv 3 3 1\nv 3 3 3\nv 1 3 3\nf 5 6 7\nf 5 7 8\n",
    )
    .unwrap();
    std::fs::write(
        dir.join("f.mtl"),
        "newmtl white\nKd 0.5 0.5 0.5\nnewmtl light\nKe 1 1 1\n",
    )
    .unwrap();
    let text = "[camera]\neye = [2, 5, 2.01]\nlook_at = [2, 0, 2]\nvfov = 60\nwidth = 8\nheight = 8\n\
                [[mesh]]\nobj = \"f.obj\"\n";
    let scene = scene::Scene::from_toml(&dir.join("s.toml"), text).unwrap();
    let mut rng = math::Rng::new(17);
    let n = 800_000;
    let power = 16.0 / n as f32; // total flux 16 over area 16: E0 = 1
    let photons: Vec<store::Photon> = (0..n)
        .map(|_| {
            let p = Vec3::new(4.0 * rng.uniform(), 0.0, 4.0 * rng.uniform());
            store::Photon::new(p, Vec3::splat(power), -Vec3::Y, 0)
        })
        .collect();
    // Edge points: 20 along each of the 4 edges, a disc radius (~0.08) or more apart, so the
    // estimates are nearly independent; corner points: the 4 corners. One k = 1000 estimate
    // has relative noise ~1.5/sqrt(1000) = 5%: the means then carry ~0.8% (edges) and ~2.4%
    // (corners), and 0.08 is more than 3 standard errors of either.
    let edges: Vec<Vec3> = (0..80)
        .map(|i| {
            let t = 0.5 + 3.0 * (i % 20) as f32 / 19.0;
            [
                Vec3::new(t, 0.0, 0.0),
                Vec3::new(t, 0.0, 4.0),
                Vec3::new(0.0, 0.0, t),
                Vec3::new(4.0, 0.0, t),
            ][i / 20]
        })
        .collect();
    let corners = vec![
        Vec3::new(0.0, 0.0, 0.0),
        Vec3::new(4.0, 0.0, 0.0),
        Vec3::new(0.0, 0.0, 4.0),
        Vec3::new(4.0, 0.0, 4.0),
    ];
    for kernel in [Kernel::Uniform, Kernel::Silverman] {
        let est = EstimateParams {
            k: 1000,
            kernel,
            topo: Some(0.1),
            drop_kth: true,
            ..Default::default()
        };
        // The estimate the eye pass reads (`Maps::estimate`), with and without the scene
        // for the correction.
        let mut maps = Maps {
            maps: PerKind([
                Some(PhotonMap::build(photons.clone(), IndexKind::KdTree)),
                None,
            ]),
            params: PerKind([est, est]),
            boundary: None,
            gather_cache: None,
        };
        for (name, points, plain_expect) in [("edge", &edges, 0.5), ("corner", &corners, 0.25)] {
            let (mut plain, mut corrected) = (0.0f64, 0.0f64);
            let mut scratch = Vec::new();
            for &x in points.iter() {
                for (boundary, sum) in [(None, &mut plain), (Some(&scene), &mut corrected)] {
                    maps.boundary = boundary;
                    let mut hint = KnnHint::NONE;
                    let (e, _) =
                        maps.estimate(MapKind::Global, x, Vec3::Y, &mut hint, &mut scratch);
                    *sum += e.x as f64;
                }
            }
            let q = points.len() as f64;
            let (plain, corrected) = (plain / q, corrected / q);
            assert!(
                (plain - plain_expect).abs() < 0.08 * plain_expect * 2.0,
                "{kernel:?} {name}: plain {plain}"
            );
            assert!(
                (corrected - 1.0).abs() < 0.08,
                "{kernel:?} {name}: corrected {corrected}"
            );
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// `info` counts the point and spot lights beside the emissive triangles, and its power is
/// theirs too: 4π I for the point light added to the worksheet scene's triangles.
#[test]
fn describe_counts_point_and_spot_lights() {
    let plain = crate::describe(&cornell());
    assert!(
        plain.contains("lights     2 emissive triangles, area"),
        "{plain}"
    );
    assert!(!plain.contains("point"), "{plain}");
    let path =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/cornell-spheres/analytic.toml");
    let text = std::fs::read_to_string(&path).unwrap()
        + "\n[[light]]\ntype = \"point\"\nposition = [-7, 10, -7]\nintensity = [1, 1, 1]\n";
    let s = scene::Scene::from_toml(&path, &text).unwrap();
    let d = crate::describe(&s);
    assert!(
        d.contains("2 emissive triangles") && d.contains("1 point and 0 spot lights"),
        "{d}"
    );
    let extra = s.light_power().x - cornell().light_power().x;
    assert!((extra - 4.0 * std::f32::consts::PI).abs() < 1e-3, "{extra}");
}

/// Knaus and Zwicker's (2011) radius sequence in closed form: the product
/// `prod_{i=1..j} (i + alpha) / (i + 1)` is `Gamma(j + 1 + alpha) / (Gamma(1 + alpha)
/// Gamma(j + 2))`, which tends to `j^(alpha - 1) / Gamma(1 + alpha)`. The squared factor
/// times `j^(1 - alpha)` must reach `1 / Gamma(5/3) = 1.10773` at alpha = 2/3 (the O(1/j)
/// term leaves 1e-5 at j = 10^5), pass 0 is unscaled and alpha = 1 never shrinks.
#[test]
fn splat_footprints_shrink_as_knaus_and_zwicker_prescribe() {
    use crate::splat::shrink;
    assert_eq!(shrink(2.0 / 3.0, 0), 1.0);
    assert_eq!(shrink(1.0, 12345), 1.0);
    // One step by hand: (1 + 1/2) / 2.
    assert!((shrink(0.5, 1) - 0.75f32.sqrt()).abs() < 1e-7);
    let j = 100_000u64;
    let s = shrink(2.0 / 3.0, j) as f64;
    let limit = s * s * (j as f64).powf(1.0 / 3.0);
    assert!((limit - 1.107_73).abs() < 1e-4, "{limit}");
}

/// SPPM's adaptive start radius is the 128th nearest photon's distance: on a plane of photons
/// on a grid of spacing d, `d sqrt(128 / pi)` (a disc holds pi r^2 / d^2 photons), to within
/// the grid's granularity; clamped to `[r0 / 2, 4 r0]`.
#[test]
fn sppm_adaptive_radius_follows_the_photon_density() {
    use crate::methods::sppm::adaptive_radius;
    use density::{IndexKind, PhotonMap};
    let d = 0.01f32;
    let photons: Vec<store::Photon> = (0..200 * 200)
        .map(|i| {
            let p = glam::Vec3::new((i % 200) as f32 * d, (i / 200) as f32 * d, 0.0);
            store::Photon::new(p, glam::Vec3::ONE, -glam::Vec3::Z, 0)
        })
        .collect();
    let map = PhotonMap::build(photons, IndexKind::KdTree);
    let mut scratch = Vec::new();
    let at = glam::Vec3::new(1.0, 1.0, 0.0);
    let expect = d * (128.0 / std::f32::consts::PI).sqrt();
    let r = adaptive_radius(&map, at, expect, &mut scratch);
    assert!((r / expect - 1.0).abs() < 0.05, "{r} against {expect}");
    // Denser than the global radius expects: no smaller than half of it.
    assert_eq!(
        adaptive_radius(&map, at, 4.0 * expect, &mut scratch),
        2.0 * expect
    );
    // Sparser: no wider than four times it; off the plane, where none are near, the same.
    assert_eq!(
        adaptive_radius(&map, at, 0.1 * expect, &mut scratch),
        0.4 * expect
    );
    let away = glam::Vec3::new(1.0, 1.0, 5.0);
    assert_eq!(
        adaptive_radius(&map, away, expect, &mut scratch),
        4.0 * expect
    );
}
