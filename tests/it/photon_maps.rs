//! The photon-map methods end to end, in one process, through the functions the binary calls
//! (`render::trace`, `render::methods::render`, `render::maps::Maps::estimate`):
//!
//! - the furnace: photons traced into a cache directory, read back from the photon files,
//!   estimated and shown by the eye pass, against `Le / (1 - rho)` with the k-NN bias
//!   predicted per kernel;
//! - boundary correction through the estimate the eye pass calls: a uniformly lit square
//!   (edges and corners restored) and a diffuse sphere (left alone).
//!
//! Global-direct and final gathering on the worksheet scene are held against Mitsuba 3's
//! image in `references`.

use crate::kit::{Mean, TempDir, load, pixel, render_cached, scene_in, sum_layers};
use density::{EstimateParams, IndexKind, Kernel, KnnHint, PhotonMap};
use geom::Prim;
use glam::{DVec3, Vec3};
use render::Overrides;
use render::maps::Maps;
use scene::{Material, Method, Scene};
use std::path::Path;
use store::{MapKind, PerKind};

// ---------------------------------------------------------------------------------------------
// 1. The furnace.

/// Photon paths traced into the furnace (about two stored photons each at rho = 1/2).
const FURNACE_PATHS: u64 = 400_000;

/// The furnace as the scene file has it: its one material's albedo and emitted radiance.
fn furnace() -> (Scene, DVec3, DVec3) {
    let scene = load("furnace/furnace.toml");
    assert_eq!(scene.materials.len(), 1, "{:?}", scene.material_names);
    let Material::Lambertian { albedo } = scene.materials[0] else {
        panic!("the furnace is {:?}", scene.materials[0])
    };
    let (rho, le) = (albedo.as_dvec3(), scene.emission[0].as_dvec3());
    assert!(rho.max_element() < 1.0 && rho.min_element() > 0.0 && le.min_element() > 0.0);
    (scene, rho, le)
}

/// Traces the furnace's photons into `cache` and checks what reached the disk: one global
/// photon file recording every path emitted.
fn trace_furnace(scene: &Scene, cache: &Path) -> u64 {
    let o = Overrides {
        photons: Some(FURNACE_PATHS),
        ..Overrides::default()
    };
    let t = render::trace(scene, &o, cache, None, false).unwrap_or_else(|e| panic!("{e}"));
    assert!(!t.reused, "a fresh cache directory cannot hold the sets");
    assert_eq!(
        t.files.len(),
        1,
        "a box with no specular surface: global set only"
    );
    let (kind, file) = &t.files[0];
    assert_eq!(*kind, MapKind::Global);
    let stored = store::MappedStore::open(file).unwrap_or_else(|e| panic!("{e}"));
    let h = stored.header();
    assert_eq!(h.emitted, FURNACE_PATHS);
    // A closed box: every path is stored at least once.
    assert!(h.stored >= FURNACE_PATHS, "{} stored", h.stored);
    h.stored
}

/// Radius of a k-NN disc at a uniform density of `photons` over the box's walls.
fn knn_radius(scene: &Scene, photons: u64, k: usize) -> f64 {
    let mesh = scene.geometry.mesh();
    let area: f64 = (0..mesh.len()).map(|t| mesh.area(t) as f64).sum();
    (k as f64 / (std::f64::consts::PI * photons as f64 / area)).sqrt()
}

/// Pixels of the furnace image whose centre sees a wall more than `margin` from every edge of
/// the box (k-NN discs there lie on one face), with the spacing of neighbouring pixels' hits.
fn furnace_interior(scene: &Scene, margin: f32) -> (Vec<(usize, usize)>, f32) {
    let b = scene.geometry.bounds();
    let (w, h) = (scene.camera.width as usize, scene.camera.height as usize);
    let hit = |x: f32, y: f32| {
        let ray = scene.camera.ray(x, y);
        let hit = scene
            .geometry
            .intersect(&ray)
            .unwrap_or_else(|| panic!("the closed box leaks at pixel ({x}, {y})"));
        (hit.point.p, hit.point.n)
    };
    let mut inner = Vec::new();
    let mut spacing = f32::INFINITY;
    for y in 0..h {
        for x in 0..w {
            let (p, n) = hit(x as f32 + 0.5, y as f32 + 0.5);
            // Distance to the nearest edge: along the axes the face spans.
            let edge = (0..3)
                .filter(|&a| n[a].abs() < 0.5)
                .map(|a| (p[a] - b.min[a]).min(b.max[a] - p[a]))
                .fold(f32::INFINITY, f32::min);
            if edge > margin {
                inner.push((x, y));
                let (q, _) = hit(x as f32 + 1.5, y as f32 + 0.5);
                let (s, _) = hit(x as f32 + 0.5, y as f32 + 1.5);
                spacing = spacing.min(p.distance(q)).min(p.distance(s));
            }
        }
    }
    (inner, spacing)
}

/// The furnace rendered with `o` from the `stored` photons traced into `cache`: the image's
/// mean over `pixels`, with its standard error from their spread.
fn furnace_mean(
    scene: &Scene,
    o: &Overrides,
    cache: &Path,
    stored: u64,
    pixels: &[(usize, usize)],
) -> (DVec3, DVec3) {
    let rendered = render_cached(scene, o, cache);
    assert_eq!(rendered.info["global_photons"].as_u64(), Some(stored));
    let img = sum_layers(&rendered, |_| true);
    let m = Mean::of(pixels.iter().map(|&p| pixel(&img, p)));
    (m.mean(), m.se())
}

/// The check resolves the bias: the box kernel's image, `m ± se`, is far from the unbiased
/// value.
fn assert_bias_resolved((m, se): (DVec3, DVec3), unbiased: DVec3) {
    let z = ((m - unbiased) / se).min_element();
    assert!(z > 6.0, "uniform kernel {m} ± {se} vs unbiased {unbiased}");
}

/// `got ± se` is within `z` standard errors of `predicted`, per channel.
fn assert_within(name: &str, got: DVec3, se: DVec3, predicted: DVec3, z: f64) {
    let dz = (got - predicted).abs() / se;
    assert!(
        dz.max_element() < z,
        "{name}: {got:.4} ± {se:.4}, predicted {predicted:.4} ({dz:.1} standard errors off)"
    );
}

#[test]
fn furnace_global_direct_shows_le_over_one_minus_rho_with_the_predicted_knn_bias() {
    // The furnace: a closed box whose walls all emit Le and reflect with albedo rho, so the
    // radiance everywhere is L = Le / (1 - rho) (2 for the file's Le = 1, rho = 1/2). The
    // global map (direct hits stored) holds the irradiance E = pi L on every wall, so
    // global-direct shows Le (emitted) + rho / pi E_est; only the photon-map part,
    // rho Le / (1 - rho), carries the estimate's bias.
    //
    // The bias, for a uniform Poisson photon density (the furnace's) away from edges: the
    // k-NN disc has area A with lambda A ~ Gamma(k), and
    // - the uniform (box) kernel sums all k photons over A: E[k / A] = lambda k / (k - 1),
    //   biased up by k / (k - 1) (Garcia et al. 2012);
    // - with the k-th photon dropped it sums k - 1: unbiased;
    // - Silverman's kernel vanishes at t = 1, so the k-th photon adds nothing and the k - 1
    //   inside are uniform on the disc, where the kernel averages 1 / A: unbiased.
    // At k = 10 the box kernel's bias is 11% of the photon part, which the test resolves.
    let (scene, rho, le) = furnace();
    let dir = TempDir::new("photon-maps-furnace-gd");
    let stored = trace_furnace(&scene, dir.path());
    let k = 10;
    let r = knn_radius(&scene, stored, k);
    // Pixels whose hit lies a quarter of the half-width from every edge, keeping every
    // other pixel in x and y: a pixel's k-NN discs (one per sample, anywhere in its
    // footprint) then never share photons with another kept pixel's, since the footprints
    // are a whole pixel apart and a pixel is wider than a disc (checked). The kept pixels'
    // values are independent, and their spread gives the standard error.
    let (interior, spacing) = furnace_interior(&scene, 0.25);
    assert!(
        spacing as f64 > 2.0 * r && r < 0.25,
        "pixels {spacing} apart, k-NN radius {r}"
    );
    let kept: Vec<(usize, usize)> = interior
        .into_iter()
        .filter(|&(x, y)| x % 2 == 0 && y % 2 == 0)
        .collect();
    assert!(kept.len() >= 100, "{} pixels", kept.len());
    let unbiased = le / (1.0 - rho);
    let photon_part = rho * le / (1.0 - rho);
    let box_bias = k as f64 / (k as f64 - 1.0);
    let mut uniform = (DVec3::ZERO, DVec3::ZERO);
    for (name, kernel, drop_kth, predicted) in [
        (
            "uniform",
            Kernel::Uniform,
            false,
            le + photon_part * box_bias,
        ),
        ("uniform, k-th dropped", Kernel::Uniform, true, unbiased),
        ("silverman", Kernel::Silverman, false, unbiased),
    ] {
        let o = Overrides {
            method: Some(Method::GlobalDirect),
            spp: Some(16),
            k: Some(k),
            kernel: Some(kernel),
            drop_kth: Some(drop_kth),
            photons: Some(FURNACE_PATHS),
            ..Overrides::default()
        };
        let (m, se) = furnace_mean(&scene, &o, dir.path(), stored, &kept);
        eprintln!(
            "furnace, global-direct, k = {k}, {name}: {m:.4} ± {se:.4}, predicted {predicted:.4}"
        );
        assert_within(name, m, se, predicted, 4.0);
        if kernel == Kernel::Uniform && !drop_kth {
            uniform = (m, se);
        }
    }
    assert_bias_resolved(uniform, unbiased);
}

#[test]
fn furnace_final_gathering_shows_le_over_one_minus_rho_with_the_predicted_knn_bias() {
    // Final gathering in the furnace: Le (emitted) + rho Le (next-event estimation of the
    // walls' emission) + rho * rho / pi E_est (gather rays reading the global map, which
    // holds all the light arriving where they land) = Le / (1 - rho); only the last term,
    // rho^2 Le / (1 - rho), carries the estimate's bias.
    // - Read from the map at every gather hit (irradiance cache off), the k-NN estimate is
    //   biased as in global-direct: by k / (k - 1) for the box kernel, not for Silverman's.
    // - Through the irradiance cache, each value is estimated at a photon: the k nearest
    //   include that photon itself at distance 0, and the k-th is the (k - 1)-th of the
    //   others, so the box kernel's bias becomes k / (k - 2) (at k = 100: 2%, below the
    //   resolution here).
    // Gather hits within a disc radius of the box's edges read up to 15% dark (the ball there
    // reaches onto the next wall, whose photons spread over a larger area) and 1/4 dark in a
    // corner; with radii of 0.01 (k = 10) and 0.03 (k = 100) that darkens the image by at most
    // 0.15%, below the standard error here (0.25%, measured).
    let (scene, rho, le) = furnace();
    let dir = TempDir::new("photon-maps-furnace-fg");
    let stored = trace_furnace(&scene, dir.path());
    // Every interior pixel counts: a pixel's gather rays land anywhere in the box, so two
    // pixels share photons only where their gather hits happen to fall within a disc of each
    // other, and next-event estimation is independent per pixel; the spread of the pixel
    // values gives the standard error.
    let (interior, _) = furnace_interior(&scene, 0.25);
    assert!(interior.len() >= 400, "{} pixels", interior.len());
    let unbiased = le / (1.0 - rho);
    let gathered = rho * rho * le / (1.0 - rho);
    let runs = [
        ("map, uniform", 10, Kernel::Uniform, Some(0), 10.0 / 9.0),
        ("map, silverman", 10, Kernel::Silverman, Some(0), 1.0),
        ("cache, uniform", 100, Kernel::Uniform, None, 100.0 / 98.0),
    ];
    let mut uniform = (DVec3::ZERO, DVec3::ZERO);
    for (name, k, kernel, gather_cache, bias) in runs {
        let o = Overrides {
            method: Some(Method::FinalGather),
            spp: Some(32),
            k: Some(k),
            kernel: Some(kernel),
            gather_cache,
            photons: Some(FURNACE_PATHS),
            ..Overrides::default()
        };
        let (m, se) = furnace_mean(&scene, &o, dir.path(), stored, &interior);
        let predicted = le + rho * le + gathered * bias;
        eprintln!(
            "furnace, final gathering, k = {k}, {name}: {m:.4} ± {se:.4}, predicted {predicted:.4}"
        );
        assert_within(name, m, se, predicted, 4.0);
        if name == "map, uniform" {
            uniform = (m, se);
        }
    }
    assert_bias_resolved(uniform, unbiased);
}

// ---------------------------------------------------------------------------------------------
// 2. Boundary correction through `Maps::estimate`, the estimate the eye pass calls.

/// The global map alone, estimated with `params`, boundary correction off.
fn global_maps(photons: Vec<store::Photon>, params: EstimateParams) -> Maps<'static> {
    let mut maps: PerKind<Option<PhotonMap>> = PerKind::default();
    maps[MapKind::Global] = Some(PhotonMap::build(photons, IndexKind::KdTree));
    let mut per_kind: PerKind<EstimateParams> = PerKind::default();
    per_kind[MapKind::Global] = params;
    Maps {
        maps,
        params: per_kind,
        boundary: None,
        gather_cache: None,
    }
}

/// Global irradiance (red channel; photons are white) at each point with its normal, without
/// and with the boundary correction against `scene`.
fn plain_and_corrected<'a>(
    maps: &mut Maps<'a>,
    scene: &'a Scene,
    points: &[(Vec3, Vec3)],
) -> Vec<(f64, f64)> {
    let mut scratch = Vec::new();
    points
        .iter()
        .map(|&(x, n)| {
            maps.boundary = None;
            let mut hint = KnnHint::NONE;
            let (plain, _) = maps.estimate(MapKind::Global, x, n, &mut hint, &mut scratch);
            maps.boundary = Some(scene);
            let mut hint = KnnHint::NONE;
            let (corrected, _) = maps.estimate(MapKind::Global, x, n, &mut hint, &mut scratch);
            (plain.x as f64, corrected.x as f64)
        })
        .collect()
}

fn stats(values: impl IntoIterator<Item = f64>) -> (f64, f64, f64) {
    let mut m = Mean::default();
    for v in values {
        m.add(DVec3::splat(v));
    }
    let sd = m.se().x * m.n().sqrt();
    (m.mean().x, m.se().x, sd)
}

/// What a k-NN estimate of a uniform Poisson density E0 = 1 gives on average wherever the
/// disc holds only photons of one (possibly cut) region: k / (k - 1) for the box kernel,
/// unbiased for Silverman's (see the furnace tests).
fn knn_mean(p: &EstimateParams) -> f64 {
    match p.kernel {
        Kernel::Uniform if !p.drop_kth => p.k as f64 / (p.k as f64 - 1.0),
        Kernel::Uniform | Kernel::Silverman => 1.0,
        k => panic!("no prediction for {k:?}"),
    }
}

#[test]
fn boundary_correction_restores_the_edges_and_corners_of_a_uniformly_lit_square() {
    // A 4 x 4 floor and a small light above it; photons of uniform density on the floor
    // (irradiance E0 = 1) and nothing beyond its edges. A plain k-NN estimate at an edge
    // finds its k photons in half a disc and so reads E0 / 2 (in a corner, a quarter disc:
    // E0 / 4), times the kernel's k-NN bias; the corrected one divides by the kernel mass the
    // probe rays find on the floor and reads E0 times that bias.
    let dir = TempDir::new("photon-maps-square");
    let scene = scene_in(
        dir.path(),
        &[
            (
                "f.obj",
                "mtllib f.mtl\no floor\nusemtl white\nv 0 0 0\nv 0 0 4\nv 4 0 4\nv 4 0 0\n\
                 f 1 2 3\nf 1 3 4\no light\nusemtl light\nv 1 3 1\nv 3 3 1\nv 3 3 3\nv 1 3 3\n\
                 f 5 6 7\nf 5 7 8\n",
            ),
            (
                "f.mtl",
                "newmtl white\nKd 0.5 0.5 0.5\nnewmtl light\nKe 1 1 1\n",
            ),
        ],
        "scene.toml",
        "[camera]\neye = [2, 5, 2.01]\nlook_at = [2, 0, 2]\nvfov = 60\nwidth = 8\nheight = 8\n\
         [[mesh]]\nobj = \"f.obj\"\n",
    );
    let n = 800_000;
    let power = 16.0 / n as f32; // flux 16 over area 16: E0 = 1
    let floor = scene::surface_id(Prim::Triangle(0));
    let mut rng = math::Rng::new(17);
    let photons: Vec<store::Photon> = (0..n)
        .map(|_| {
            let p = Vec3::new(4.0 * rng.uniform(), 0.0, 4.0 * rng.uniform());
            store::Photon::new(p, Vec3::splat(power), -Vec3::Y, floor)
        })
        .collect();
    // k = 1000 at this density: disc radius 0.08 inside, 0.11 at an edge, 0.16 in a corner.
    // Points within a kind are farther apart than two disc radii, so their estimates share no
    // photons and their spread gives the standard error: 64 inside (0.4 apart, 0.6 or more
    // from the edges), 40 on the edges (0.3 apart, 0.5 or more from the corners), the 4
    // corners. Four corners are too few to estimate a spread from: their standard error takes
    // the edges' relative spread per point, which is the same, since every k-NN disc holds k
    // photons wherever it is cut (lambda A ~ Gamma(k)).
    let inside: Vec<Vec3> = (0..64)
        .map(|i| Vec3::new(0.6 + 0.4 * (i % 8) as f32, 0.0, 0.6 + 0.4 * (i / 8) as f32))
        .collect();
    let edges: Vec<Vec3> = (0..40)
        .map(|i| {
            let t = 0.5 + 0.3 * (i % 10) as f32;
            [
                Vec3::new(t, 0.0, 0.0),
                Vec3::new(t, 0.0, 4.0),
                Vec3::new(0.0, 0.0, t),
                Vec3::new(4.0, 0.0, t),
            ][i / 10]
        })
        .collect();
    let corners = [
        Vec3::new(0.0, 0.0, 0.0),
        Vec3::new(4.0, 0.0, 0.0),
        Vec3::new(0.0, 0.0, 4.0),
        Vec3::new(4.0, 0.0, 4.0),
    ];
    let up = |v: &[Vec3]| v.iter().map(|&x| (x, Vec3::Y)).collect::<Vec<_>>();
    let mut maps = global_maps(photons, EstimateParams::default());
    for kernel in [Kernel::Uniform, Kernel::Silverman] {
        let params = EstimateParams {
            k: 1000,
            kernel,
            topo: Some(0.1),
            ..EstimateParams::default()
        };
        maps.params[MapKind::Global] = params;
        let b = knn_mean(&params);
        // Inside, the whole disc is floor: the correction changes nothing, to the bit.
        let inner = plain_and_corrected(&mut maps, &scene, &up(&inside));
        for (i, &(p, c)) in inner.iter().enumerate() {
            assert_eq!(p, c, "{kernel:?}: corrected inside at {}", inside[i]);
        }
        let (m, se, _) = stats(inner.iter().map(|v| v.0));
        eprintln!("square, {kernel:?}, inside: {m:.4} ± {se:.4}, predicted {b:.4}");
        assert!((m - b).abs() < 4.0 * se, "{kernel:?} inside: {m} ± {se}");
        let edge = plain_and_corrected(&mut maps, &scene, &up(&edges));
        let (_, _, sd) = stats(edge.iter().map(|v| v.0));
        let rel_sd = sd / stats(edge.iter().map(|v| v.0)).0;
        let corner = plain_and_corrected(&mut maps, &scene, &up(&corners));
        for (name, values, share) in [("edge", &edge, 0.5), ("corner", &corner, 0.25)] {
            for (what, pick, predicted) in [("plain", 0, share * b), ("corrected", 1, b)] {
                let v = values.iter().map(|v| if pick == 0 { v.0 } else { v.1 });
                let (m, se, _) = stats(v);
                let se = if name == "corner" {
                    rel_sd * m / (values.len() as f64).sqrt()
                } else {
                    se
                };
                eprintln!(
                    "square, {kernel:?}, {name}, {what}: {m:.4} ± {se:.4}, predicted {predicted:.4}"
                );
                assert!(
                    (m - predicted).abs() < 4.0 * se,
                    "{kernel:?} {name} {what}: {m} ± {se}, predicted {predicted}"
                );
            }
        }
    }
}

#[test]
fn boundary_correction_leaves_a_diffuse_sphere_alone() {
    // A diffuse sphere (radius 1) with photons of uniform density over it (E0 = 1, arriving
    // from outside) and a light far above. The k-NN estimate on a sphere needs no correction:
    // the part of a sphere within chord distance d of a point on it has area pi d^2 exactly
    // (Archimedes), so the estimate behaves as on a plane, and with k = 1000 (disc radius
    // 0.1) the topological test (eps = 0.1 keeps chords up to 0.2) rejects none of it. The
    // correction's probes must find the sphere under every point of the tangent disc, which
    // falls below the tangent plane by up to r^2 / 2 = 0.005: a probe band of 0.01 r (0.001)
    // misses all but the innermost ring and multiplied the estimate by about 4 (box kernel)
    // or 1.7 (Silverman's).
    let dir = TempDir::new("photon-maps-sphere");
    let scene = scene_in(
        dir.path(),
        &[
            (
                "light.obj",
                "mtllib light.mtl\no light\nusemtl light\nv -0.5 6 -0.5\nv 0.5 6 -0.5\n\
                 v 0.5 6 0.5\nv -0.5 6 0.5\nf 1 2 3\nf 1 3 4\n",
            ),
            ("light.mtl", "newmtl light\nKe 1 1 1\n"),
        ],
        "scene.toml",
        "[camera]\neye = [0, 0, 5]\nlook_at = [0, 0, 0]\nvfov = 40\nwidth = 8\nheight = 8\n\
         [[mesh]]\nobj = \"light.obj\"\n\
         [[sphere]]\ncenter = [0, 0, 0]\nradius = 1\nmaterial = \"white\"\n\
         [material.white]\ntype = \"lambertian\"\nalbedo = [0.5, 0.5, 0.5]\n",
    );
    let sphere = scene.geometry.spheres()[0];
    let (c, radius) = (sphere.center, sphere.radius);
    let n = 400_000;
    let power = 4.0 * std::f32::consts::PI * radius * radius / n as f32; // E0 = 1
    let id = scene::surface_id(Prim::Sphere(0));
    let mut rng = math::Rng::new(29);
    let photons: Vec<store::Photon> = (0..n)
        .map(|_| {
            let z = 1.0 - 2.0 * rng.uniform();
            let phi = std::f32::consts::TAU * rng.uniform();
            let s = (1.0 - z * z).max(0.0).sqrt();
            let u = Vec3::new(s * phi.cos(), s * phi.sin(), z);
            store::Photon::new(c + radius * u, Vec3::splat(power), -u, id)
        })
        .collect();
    // 150 points spread evenly over the sphere (a Fibonacci lattice), each farther than two
    // disc radii (0.2) from the next, so their estimates share no photons, and all far from
    // the light (5 away).
    let m = 150;
    let points: Vec<(Vec3, Vec3)> = (0..m)
        .map(|i| {
            let z = 1.0 - (2 * i + 1) as f32 / m as f32;
            let phi = i as f32 * std::f32::consts::PI * (3.0 - 5f32.sqrt());
            let s = (1.0 - z * z).sqrt();
            let u = Vec3::new(s * phi.cos(), s * phi.sin(), z);
            (c + radius * u, u)
        })
        .collect();
    let closest = points
        .iter()
        .enumerate()
        .flat_map(|(i, a)| points[i + 1..].iter().map(move |b| a.0.distance(b.0)))
        .fold(f32::INFINITY, f32::min);
    assert!(closest > 0.2, "points {closest} apart");
    let mut maps = global_maps(photons, EstimateParams::default());
    for kernel in [Kernel::Silverman, Kernel::Uniform] {
        let params = EstimateParams {
            k: 1000,
            kernel,
            topo: Some(0.1),
            ..EstimateParams::default()
        };
        maps.params[MapKind::Global] = params;
        let v = plain_and_corrected(&mut maps, &scene, &points);
        let (ratio, ratio_se, _) = stats(v.iter().map(|(p, c)| c / p));
        let (plain, plain_se, _) = stats(v.iter().map(|v| v.0));
        let (corrected, corrected_se, _) = stats(v.iter().map(|v| v.1));
        let b = knn_mean(&params);
        eprintln!(
            "sphere, {kernel:?}: corrected / plain {ratio:.4} ± {ratio_se:.4}; plain {plain:.4} \
             ± {plain_se:.4}, corrected {corrected:.4} ± {corrected_se:.4}, predicted {b:.4}"
        );
        // Today every probe finds the sphere and the ratio is exactly 1 at every point (its
        // standard error then 0).
        assert!(
            (ratio - 1.0).abs() <= 4.0 * ratio_se,
            "{kernel:?}: the correction scales a sphere by {ratio} ± {ratio_se}"
        );
        for (what, m, se) in [
            ("plain", plain, plain_se),
            ("corrected", corrected, corrected_se),
        ] {
            assert!(
                (m - b).abs() < 4.0 * se,
                "{kernel:?} {what}: {m} ± {se}, predicted {b}"
            );
        }
    }
}
