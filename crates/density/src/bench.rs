//! k-NN throughput of each index (driven by `cargo xtask bench knn`; no timing in tests).
//!
//! Synthetic photons lie uniformly on the six faces of the unit cube [0,1]³, like a
//! global photon map in a closed room: 2-D manifolds in 3-D, with edges and corners.
//! Queries are fresh points on the same faces (with their own seed). Single-threaded; each
//! figure is the median of `RUNS` passes over the same queries.

use crate::index::{Index, IndexKind, Kiddo, Neighbor};
use glam::Vec3;
use math::Rng;
use std::hint::black_box;
use std::num::NonZero;
use std::time::Instant;

const RUNS: usize = 5;

#[derive(Clone, Copy, Debug)]
pub struct KnnBench {
    pub index: IndexKind,
    /// The index's name; "kd_map": our kd-tree relabelled by slot, as `PhotonMap` holds it;
    /// or "kiddo_raw": kiddo 5's own `nearest_n` (sorted by distance, no
    /// tie rule), the fairest figure for kiddo; "kiddo6_raw": the same query in kiddo 6,
    /// its newest release (the stable build: its SIMD paths need a nightly compiler).
    pub name: &'static str,
    pub photons: usize,
    pub k: usize,
    /// Queries actually timed (brute force gets fewer: it is O(n) per query).
    pub queries: usize,
    pub queries_per_s: f64,
    pub build_s: f64,
}

/// A point uniform on the surface of the unit cube.
pub fn point_on_unit_cube(rng: &mut Rng) -> [f32; 3] {
    let face = rng.below(6);
    let (u, v) = (rng.uniform(), rng.uniform());
    let c = (face / 2) as usize;
    let side = (face % 2) as f32;
    let mut p = [0.0; 3];
    p[c] = side;
    p[(c + 1) % 3] = u;
    p[(c + 2) % 3] = v;
    p
}

/// Benchmark every index over `photons` points for each k in `ks`, and kiddo's own
/// `nearest_n`. Per k, the runs are interleaved (one pass of each, `RUNS` times), so a
/// change of machine load hits all of them alike and their ratios hold.
pub fn bench_knn(photons: usize, ks: &[usize], queries: usize, seed: u64) -> Vec<KnnBench> {
    let mut rng = Rng::for_index(seed, 0);
    let points: Vec<[f32; 3]> = (0..photons).map(|_| point_on_unit_cube(&mut rng)).collect();
    let mut qrng = Rng::for_index(seed, 1);
    let qs: Vec<Vec3> = (0..queries)
        .map(|_| Vec3::from(point_on_unit_cube(&mut qrng)))
        .collect();
    let built: Vec<(Index, f64)> = IndexKind::ALL
        .iter()
        .map(|&kind| {
            let t0 = Instant::now();
            let index = Index::build(kind, &points);
            (index, t0.elapsed().as_secs_f64())
        })
        .collect();
    let t0 = Instant::now();
    let kiddo6 = kiddo6::ImmutableKdTree::<f32, 3>::new_from_slice(&points);
    let kiddo6 = kiddo6.map(|t| (t, t0.elapsed().as_secs_f64()));
    // The kd-tree as `PhotonMap` holds it: photons reordered to its slot order at build,
    // so results are slots and no id is looked up (kiddo keeps its items in its leaves).
    let map = built.iter().find_map(|(i, t)| match i {
        Index::KdTree(tree) => {
            let mut tree = tree.clone();
            tree.relabel_by_slot();
            Some((Index::KdTree(tree), *t))
        }
        _ => None,
    });
    let mut runs: Vec<Run> = built.iter().map(|(i, t)| Run::Index(i, *t)).collect();
    let kd_at = runs
        .iter()
        .position(|r| matches!(r, Run::Index(Index::KdTree(_), _)));
    if let (Some(at), Some((i, t))) = (kd_at, &map) {
        runs.insert(at + 1, Run::Map(i, *t));
    }
    let kiddo_at = runs.iter().position(|r| r.kind() == IndexKind::Kiddo);
    // kiddo's own queries right after ours through its index.
    let kiddo = built.iter().find_map(|(i, t)| match i {
        Index::Kiddo(kd) => Some((kd, *t)),
        _ => None,
    });
    if let (Some(at), Some((kd, t))) = (kiddo_at, kiddo) {
        runs.insert(at + 1, Run::KiddoRaw(kd, t));
        if let Ok((tree, t)) = &kiddo6 {
            runs.insert(at + 2, Run::Kiddo6Raw(tree, *t));
        }
    }
    let mut out = Vec::new();
    for &k in ks {
        let mut scratch: Vec<Neighbor> = Vec::with_capacity(k + 1);
        let mut times = vec![Vec::new(); runs.len()];
        let k1 = NonZero::new(k).unwrap_or(NonZero::<usize>::MIN);
        for _ in 0..RUNS {
            for (run, t) in runs.iter().zip(times.iter_mut()) {
                let nq = queries_for(run.kind(), photons, qs.len());
                let t0 = Instant::now();
                let mut acc = 0usize;
                for &q in &qs[..nq] {
                    acc += match run {
                        Run::KiddoRaw(kd, _) => kd.nearest_n_raw(q, k),
                        Run::Kiddo6Raw(tree, _) => tree
                            .query(&q.to_array())
                            .nearest_n::<kiddo6::SquaredEuclidean<f32>>(k1)
                            .execute()
                            .len(),
                        Run::Index(index, _) | Run::Map(index, _) => {
                            index.knn(q, k, f32::INFINITY, &mut scratch);
                            scratch.len()
                        }
                    };
                }
                black_box(acc);
                t.push(t0.elapsed().as_secs_f64());
            }
        }
        for (run, mut t) in runs.iter().zip(times) {
            t.sort_by(f64::total_cmp);
            let nq = queries_for(run.kind(), photons, qs.len());
            let (name, build_s) = match run {
                Run::Index(i, b) => (i.kind().name(), *b),
                Run::Map(_, b) => ("kd_map", *b),
                Run::KiddoRaw(_, b) => ("kiddo_raw", *b),
                Run::Kiddo6Raw(_, b) => ("kiddo6_raw", *b),
            };
            out.push(KnnBench {
                index: run.kind(),
                name,
                photons,
                k,
                queries: nq,
                queries_per_s: nq as f64 / t[RUNS / 2].max(1e-12),
                build_s,
            });
        }
    }
    out
}

/// One timed contender: an index through our `knn`, or kiddo 5's or 6's own `nearest_n`.
enum Run<'a> {
    Index(&'a Index, f64),
    /// Our kd-tree relabelled by slot, as the photon map uses it.
    Map(&'a Index, f64),
    KiddoRaw(&'a Kiddo, f64),
    Kiddo6Raw(&'a kiddo6::ImmutableKdTree<f32, 3>, f64),
}

impl Run<'_> {
    fn kind(&self) -> IndexKind {
        match self {
            Run::Index(i, _) | Run::Map(i, _) => i.kind(),
            Run::KiddoRaw(..) | Run::Kiddo6Raw(..) => IndexKind::Kiddo,
        }
    }
}

/// Queries timed per pass: all of them, but brute force is capped at ~2e8 distance
/// evaluations per pass.
fn queries_for(kind: IndexKind, photons: usize, queries: usize) -> usize {
    if kind == IndexKind::Brute {
        (200_000_000 / photons.max(1)).clamp(10, queries.max(10))
    } else {
        queries
    }
    .min(queries)
}

/// One row of [`bench_coherent`]: queries/s of the plain k-NN search and of the hinted
/// (radius-first) one, and of the irradiance estimate built on each.
#[derive(Clone, Copy, Debug)]
pub struct CoherentBench {
    pub k: usize,
    /// Pixel order (true) or the same points shuffled (false).
    pub coherent: bool,
    pub queries: usize,
    pub knn_per_s: f64,
    pub hinted_per_s: f64,
    pub irradiance_per_s: f64,
    pub irradiance_hinted_per_s: f64,
}

/// One timed query: point, normal, hint, neighbour buffer; returns something to keep.
type Probe<'a> = dyn FnMut(Vec3, Vec3, &mut crate::KnnHint, &mut Vec<Neighbor>) -> f32 + 'a;

/// The global map shown directly: `photons` on the unit cube's faces travelling inwards,
/// one estimate per pixel of a `res`² camera looking into the box through its z = 0 face
/// (back wall, floor, ceiling, side walls, their edges), visited row by row with one
/// [`crate::KnnHint`] carried from pixel to pixel; then the same points in random order.
/// Single-threaded; median of `RUNS` passes; the kd-tree.
pub fn bench_coherent(photons: usize, ks: &[usize], res: usize, seed: u64) -> Vec<CoherentBench> {
    use crate::{EstimateParams, KnnHint, PhotonMap};
    let mut rng = Rng::for_index(seed, 0);
    let photons: Vec<store::Photon> = (0..photons)
        .map(|i| {
            let p = Vec3::from(point_on_unit_cube(&mut rng));
            // Inwards: towards the face's side of the centre.
            let c = p - 0.5;
            let a = c.abs().max_position();
            let mut dir = Vec3::ZERO;
            dir[a] = c[a].signum();
            store::Photon::new(p, Vec3::ONE, dir, i as u32)
        })
        .collect();
    let map = PhotonMap::build(photons, IndexKind::KdTree);
    let eye = Vec3::new(0.5, 0.5, -1.2);
    let pixels: Vec<(Vec3, Vec3)> = (0..res * res)
        .map(|i| {
            let (px, py) = ((i % res) as f32 + 0.5, (i / res) as f32 + 0.5);
            let d = Vec3::new(px / res as f32, 1.0 - py / res as f32, 0.0) - eye;
            // Exit point of the ray from the box [0,1]³ and the inward normal there.
            let t_exit = |a: usize| {
                let side = if d[a] > 0.0 { 1.0 } else { 0.0 };
                (side - eye[a]) / d[a]
            };
            let a = (0..3)
                .min_by(|&a, &b| t_exit(a).total_cmp(&t_exit(b)))
                .unwrap_or(2);
            let mut n = Vec3::ZERO;
            n[a] = -d[a].signum();
            (eye + d * t_exit(a), n)
        })
        .collect();
    let mut shuffled = pixels.clone();
    for i in (1..shuffled.len()).rev() {
        shuffled.swap(i, rng.below(i as u32 + 1) as usize);
    }
    let median = |f: &mut dyn FnMut() -> f64| {
        let mut t: Vec<f64> = (0..RUNS).map(|_| f()).collect();
        t.sort_by(f64::total_cmp);
        t[RUNS / 2].max(1e-12)
    };
    let mut out = Vec::new();
    for &k in ks {
        let p = EstimateParams {
            k,
            ..Default::default()
        };
        for (coherent, qs) in [(true, &pixels), (false, &shuffled)] {
            let mut s: Vec<Neighbor> = Vec::with_capacity(4 * k);
            let mut time = |f: &mut Probe| {
                qs.len() as f64
                    / median(&mut || {
                        let mut hint = KnnHint::NONE;
                        let t = Instant::now();
                        let mut acc = 0.0;
                        for &(x, n) in qs.iter() {
                            acc += f(x, n, &mut hint, &mut s);
                        }
                        black_box(acc);
                        t.elapsed().as_secs_f64()
                    })
            };
            out.push(CoherentBench {
                k,
                coherent,
                queries: qs.len(),
                knn_per_s: time(&mut |x, _, _, s| {
                    map.knn(x, k, f32::INFINITY, s);
                    s.len() as f32
                }),
                hinted_per_s: time(&mut |x, _, h, s| {
                    map.knn_hinted(x, k, f32::INFINITY, h, s);
                    s.len() as f32
                }),
                irradiance_per_s: time(&mut |x, n, _, s| map.irradiance(x, n, &p, s).x),
                irradiance_hinted_per_s: time(&mut |x, n, h, s| {
                    map.irradiance_hinted(x, n, &p, h, s).x
                }),
            });
        }
    }
    out
}
