//! Unit tests of the pipeline's machinery: the channel pipeline, the photon cache, the
//! irradiance cache, the edge mask.

use crate::flow::{self, ChannelSink, PipelineOptions, Sink, StoreSink};
use crate::photon_cache::{self as pipeline, CacheKey};
use crate::progress::Progress;
use emit::{EmitParams, Plan};
use std::path::{Path, PathBuf};
use store::{MapKind, MappedStore};

fn cornell() -> scene::Scene {
    let p =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/cornell-spheres/analytic.toml");
    scene::Scene::load(p).unwrap()
}

fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("photonflow-pipe-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    d
}

/// Runs the pipeline into `dir` and returns the photon files' bytes and the stats.
fn run(
    scene: &scene::Scene,
    params: &EmitParams,
    dir: &Path,
    threads: usize,
    chunk: u64,
    window: usize,
    consumer: Option<crossbeam_channel::Sender<std::sync::Arc<emit::Traced>>>,
) -> (Vec<Vec<u8>>, flow::TraceStats) {
    let plan = Plan::for_scene(scene, params).unwrap();
    let key = CacheKey::new(scene, params);
    let files: Vec<(MapKind, PathBuf)> = pipeline::planned_kinds(&plan)
        .into_iter()
        .map(|k| (k, key.file(dir, k)))
        .collect();
    let opts = PipelineOptions {
        threads,
        chunk,
        window,
    };
    let progress = Progress::new("test", params.photons, "photons");
    let mut store = StoreSink::create(&files, &|k| key.header(scene, k)).unwrap();
    let mut channel = consumer.map(ChannelSink);
    let mut sinks: Vec<&mut dyn Sink> = vec![&mut store];
    if let Some(c) = channel.as_mut() {
        sinks.push(c);
    }
    let stats = flow::run(scene, params, &plan, &mut sinks, &opts, &progress).unwrap();
    drop(sinks);
    store.finish(params.photons).unwrap();
    let bytes = files
        .iter()
        .map(|(_, f)| std::fs::read(f).unwrap())
        .collect();
    (bytes, stats)
}

#[test]
fn photon_files_are_bit_identical_for_any_thread_count_and_chunking() {
    let scene = cornell();
    let params = EmitParams {
        photons: 20_000,
        ..EmitParams::default()
    };
    let d = scratch("threads");
    let (one, _) = run(&scene, &params, &d.join("a"), 1, 4096, 4, None);
    let (two, _) = run(&scene, &params, &d.join("b"), 2, 777, 6, None);
    assert_eq!(one.len(), 2, "global and caustic sets");
    assert_eq!(one, two);
    // And the payload equals one single-threaded trace of the whole range.
    let plan = Plan::for_scene(&scene, &params).unwrap();
    let whole = emit::trace_range(&scene, &params, &plan, 0..params.photons);
    let key = CacheKey::new(&scene, &params);
    let g = MappedStore::open(&key.file(&d.join("a"), MapKind::Global)).unwrap();
    assert_eq!(g.to_vec(), whole[MapKind::Global]);
    assert_eq!(g.header().emitted, params.photons);
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn backpressure_bounds_the_chunks_in_flight_and_the_consumer_sees_everything_in_order() {
    let scene = cornell();
    let params = EmitParams {
        photons: 30_000,
        ..EmitParams::default()
    };
    let d = scratch("window");
    let (tx, rx) = crossbeam_channel::unbounded();
    // 150 chunks of 200 paths, at most 3 alive at once.
    let (_, stats) = run(&scene, &params, &d, 2, 200, 3, Some(tx));
    assert!(
        stats.max_in_flight <= 3,
        "{} chunks in flight",
        stats.max_in_flight
    );
    let got: Vec<std::sync::Arc<emit::Traced>> = rx.iter().collect();
    assert_eq!(got.len(), 150);
    let caustic: Vec<store::Photon> = got
        .iter()
        .flat_map(|t| t[MapKind::Caustic].iter().copied())
        .collect();
    let key = CacheKey::new(&scene, &params);
    let file = MappedStore::open(&key.file(&d, MapKind::Caustic)).unwrap();
    assert_eq!(
        caustic,
        file.to_vec(),
        "consumer and file see the same photons, in order"
    );
    assert_eq!(got.iter().map(|t| t.emitted).sum::<u64>(), params.photons);
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn the_cache_reuses_only_identical_runs() {
    let scene = cornell();
    let params = EmitParams {
        photons: 3_000,
        ..EmitParams::default()
    };
    let d = scratch("cache");
    let key = CacheKey::new(&scene, &params);
    let plan = Plan::for_scene(&scene, &params).unwrap();
    let kinds = pipeline::planned_kinds(&plan);
    assert!(!pipeline::cached(&d, &key, &kinds));
    run(&scene, &params, &d, 2, 1000, 4, None);
    assert!(pipeline::cached(&d, &key, &kinds));
    // Other parameters, or another scene: another key, not cached.
    let other = EmitParams {
        photons: 3_001,
        ..params.clone()
    };
    assert!(!pipeline::cached(
        &d,
        &CacheKey::new(&scene, &other),
        &kinds
    ));
    let text = std::fs::read_to_string(&scene.path)
        .unwrap()
        .replace("ior = 1.5", "ior = 1.6");
    let edited = scene::Scene::from_toml(&scene.path, &text).unwrap();
    assert!(!pipeline::cached(
        &d,
        &CacheKey::new(&edited, &params),
        &kinds
    ));
    // A damaged file is not reused.
    let f = key.file(&d, MapKind::Global);
    let mut bytes = std::fs::read(&f).unwrap();
    let last = bytes.len() - 1;
    bytes[last] ^= 1;
    std::fs::write(&f, bytes).unwrap();
    assert!(
        !pipeline::cached(&d, &key, &kinds),
        "a damaged set must be traced anew"
    );
    let _ = std::fs::remove_dir_all(&d);
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
fn point_triangle_distance_matches_a_dense_search() {
    use crate::worksheet::distance_for_test;
    use glam::Vec3;
    let mut rng = math::Rng::new(5);
    let mut v = || Vec3::new(rng.uniform(), rng.uniform(), rng.uniform()) * 4.0 - 2.0;
    for _ in 0..200 {
        let t = [v(), v(), v()];
        let p = v();
        // Brute force over a 200 x 200 barycentric grid: an upper bound within the grid's
        // spacing of the true distance.
        let n = 200;
        let mut best = f32::INFINITY;
        for i in 0..=n {
            for j in 0..=n - i {
                let (b1, b2) = (i as f32 / n as f32, j as f32 / n as f32);
                let q = t[0] + (t[1] - t[0]) * b1 + (t[2] - t[0]) * b2;
                best = best.min((p - q).length());
            }
        }
        let d = distance_for_test(p, t);
        let spacing = ((t[1] - t[0]).length() + (t[2] - t[0]).length()) / n as f32;
        assert!(d <= best + 1e-5 && d >= best - spacing, "{d} vs {best}");
    }
}

#[test]
fn the_edge_mask_marks_the_inner_edges_only() {
    let s = cornell();
    let m = crate::worksheet::edge_mask(&s, 0.4);
    let share = m.count() as f64 / m.pixels.len() as f64;
    // A band of 0.4 along the box's inner edges covers a modest share of the image.
    assert!(share > 0.03 && share < 0.3, "{share}");
    // The centre of the back wall is far from every edge.
    let (w, h) = (m.width, m.height);
    assert!(!m.pixels[(h / 2 - 40) * w + w / 2]);
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
    use crate::boundary::kernel_mass_on_surface;
    use density::{EstimateParams, IndexKind, Kernel, KnnHint, PhotonMap};
    use glam::Vec3;
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
    let map = PhotonMap::build(photons, IndexKind::KdTree);
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
        for (name, points, plain_expect) in [("edge", &edges, 0.5), ("corner", &corners, 0.25)] {
            let (mut plain, mut corrected) = (0.0f64, 0.0f64);
            let mut scratch = Vec::new();
            for &x in points.iter() {
                let mut hint = KnnHint::NONE;
                let e = map
                    .irradiance_hinted(x, Vec3::Y, &est, &mut hint, &mut scratch)
                    .x;
                let m = kernel_mass_on_surface(&scene, x, Vec3::Y, hint.r, &est);
                plain += e as f64;
                corrected += (e / m) as f64;
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

#[test]
fn an_in_memory_stage_sees_the_same_photons_as_the_file_writer() {
    // Two consumers of one run: the photon file writer and an in-memory collector (what a
    // k-NN builder or a splatter does with the chunks). Both see every photon, in order.
    use crate::flow::CollectSink;
    let scene = cornell();
    let params = EmitParams {
        photons: 12_000,
        ..EmitParams::default()
    };
    let d = scratch("collect");
    let plan = Plan::for_scene(&scene, &params).unwrap();
    let key = CacheKey::new(&scene, &params);
    let files: Vec<(MapKind, PathBuf)> = pipeline::planned_kinds(&plan)
        .into_iter()
        .map(|k| (k, key.file(&d, k)))
        .collect();
    let mut store = StoreSink::create(&files, &|k| key.header(&scene, k)).unwrap();
    let mut collect = CollectSink::default();
    let opts = PipelineOptions {
        threads: 2,
        chunk: 1000,
        window: 4,
    };
    let stats = flow::run(
        &scene,
        &params,
        &plan,
        &mut [&mut store as &mut dyn Sink, &mut collect],
        &opts,
        &Progress::hidden(),
    )
    .unwrap();
    store.finish(params.photons).unwrap();
    assert!(stats.max_in_flight <= 4);
    assert_eq!(collect.0.emitted, params.photons);
    for (kind, path) in &files {
        let file = MappedStore::open(path).unwrap();
        assert!(!collect.0[*kind].is_empty(), "{kind:?}");
        assert_eq!(file.to_vec(), collect.0[*kind], "{kind:?}");
    }
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn the_rim_mask_marks_the_open_front_only() {
    let s = cornell();
    let b = s.geometry.bounds();
    let band = 0.02 * (b.max - b.min).length();
    let m = crate::worksheet::rim_mask(&s, band);
    let (w, h) = (m.width, m.height);
    assert!(m.count() > 500, "{} rim pixels", m.count());
    // The box's open side faces the camera (at +z): every rim pixel sees a point within the
    // band of that plane, and the inner edges at the back are not rim.
    for y in 0..h {
        for x in 0..w {
            if m.pixels[y * w + x] {
                let hit = s
                    .geometry
                    .intersect(&s.camera.ray(x as f32 + 0.5, y as f32 + 0.5))
                    .unwrap();
                assert!(
                    b.max.z - hit.point.p.z < band,
                    "({x}, {y}) at {}",
                    hit.point.p
                );
            }
        }
    }
}

/// `bench-rays --peer` reads the peer's rates from lines like the Embree script's.
#[test]
fn peer_ray_rates_are_read_from_their_lines() {
    let out = "embreex 4.4  triangles 16140  pinned to CPU 0\n\
        coherent primary (camera grid)     rays 1,048,576  hits 1,013,507 ( 96.7%)  wall 0.303 s  cpu 0.149 s    3.46 Mrays/s\n\
        incoherent (random o, random d)    rays 1,048,576  hits   882,790 ( 84.2%)  wall 0.495 s  cpu 0.245 s    2.12 Mrays/s\n";
    assert_eq!(crate::bench::peer_rate(out, "coherent"), Some(3.46));
    assert_eq!(crate::bench::peer_rate(out, "incoherent"), Some(2.12));
    assert_eq!(
        crate::bench::peer_rate("  coherent: 7.5 M rays/s\n", "coherent"),
        Some(7.5)
    );
    assert_eq!(
        crate::bench::peer_rate("coherent rays only\n", "coherent"),
        None
    );
}
