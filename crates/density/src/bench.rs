//! k-NN throughput of each index (driven by `cargo xtask bench knn`; no timing in tests).
//!
//! Synthetic photons lie uniformly on the six faces of the unit cube [0,1]³, like a
//! global photon map in a closed room: 2-D manifolds in 3-D, with edges and corners.
//! Queries are fresh points on the same faces (with their own seed). Single-threaded; each
//! figure is the median of `RUNS` passes over the same queries.

use crate::index::{Index, IndexKind, Neighbor};
use glam::Vec3;
use math::Rng;
use std::hint::black_box;
use std::time::Instant;

const RUNS: usize = 3;

#[derive(Clone, Copy, Debug)]
pub struct KnnBench {
    pub index: IndexKind,
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

/// Benchmark every index over `photons` points for each k in `ks`.
pub fn bench_knn(photons: usize, ks: &[usize], queries: usize, seed: u64) -> Vec<KnnBench> {
    let mut rng = Rng::for_index(seed, 0);
    let points: Vec<[f32; 3]> = (0..photons).map(|_| point_on_unit_cube(&mut rng)).collect();
    let mut qrng = Rng::for_index(seed, 1);
    let qs: Vec<Vec3> = (0..queries)
        .map(|_| Vec3::from(point_on_unit_cube(&mut qrng)))
        .collect();
    let mut out = Vec::new();
    for kind in IndexKind::ALL {
        let t0 = Instant::now();
        let index = Index::build(kind, &points);
        let build_s = t0.elapsed().as_secs_f64();
        // Brute force: cap the work at ~2e8 distance evaluations per pass.
        let nq = if kind == IndexKind::Brute {
            (200_000_000 / photons.max(1)).clamp(10, queries.max(10))
        } else {
            queries
        }
        .min(qs.len());
        for &k in ks {
            let mut scratch: Vec<Neighbor> = Vec::with_capacity(k + 1);
            let mut times: Vec<f64> = (0..RUNS)
                .map(|_| {
                    let t = Instant::now();
                    let mut acc = 0usize;
                    for &q in &qs[..nq] {
                        index.knn(q, k, f32::INFINITY, &mut scratch);
                        acc += scratch.len();
                    }
                    black_box(acc);
                    t.elapsed().as_secs_f64()
                })
                .collect();
            times.sort_by(f64::total_cmp);
            out.push(KnnBench {
                index: kind,
                photons,
                k,
                queries: nq,
                queries_per_s: nq as f64 / times[RUNS / 2].max(1e-12),
                build_s,
            });
        }
    }
    out
}
