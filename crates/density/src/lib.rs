//! `density`: photon density estimation. A k-nearest index over photon positions, the
//! kernels of algorithms.md §2.2, and the bias controls of worksheet 7 (same-side and
//! topological tests, Garcia et al.'s k-th photon exclusion). No file IO: photons come in
//! as values.
//!
//! Key decision: **every index returns exactly the same neighbours** — the k smallest
//! `(d2, index)` within `r_max`, ties broken by index — so the back-ends (our kd-tree,
//! kiddo, brute force) are interchangeable and tested for equality with brute force, and an
//! estimate never depends on which one ran. Use our kd-tree: built in place over f32
//! positions with u32 ids (anchors A3.4, A4.1, C) and collecting neighbours by buffered
//! selection, it was the fastest at 1M photons on a cube's faces (`bench::bench_knn`,
//! release, one thread, a loaded 2-core machine): k = 50 / 250 / 1000 at about
//! 113–148k / 40–45k / 13–15k queries/s, against kiddo 5's `ImmutableKdTree` at
//! 89–117k / 30–36k / 8k and brute force at under 1k; both trees build in ~0.13 s.
//!
//! Third decision: for large k, search radius-first. [`KdTree::knn_hinted`] takes a
//! [`KnnHint`] (the previous query's point and k-th distance), gathers every point within a
//! slightly larger radius in slot order, and selects the k smallest in linear time (bucket
//! select), so no sort; the set is exactly `knn`'s, and [`PhotonMap::irradiance`] is
//! [`PhotonMap::irradiance_hinted`] without a hint, bit for bit. `bench::bench_coherent`
//! (1M photons on the cube's faces, 512² pixels into the box, one thread, loaded 2-core
//! machine), queries/s, plain k-NN → hinted k-NN, and irradiance before this change →
//! hinted irradiance: pixel order k = 50 / 250 / 1000: 296k → 578k, 92k → 243k,
//! 25k → 81k; irradiance 204k → 502k, 56k → 173k, 19k → 53k. Random order (hint from an
//! unrelated point of similar density): 186k → 228k, 57k → 112k, 20k → 42k. With the
//! estimate loop compiled once per kernel and test combination (same sums, same order, so
//! bit-identical), hinted irradiance in pixel order measured 431k / 212k / 82k queries/s on
//! a quieter machine (`cargo xtask bench knn`, 128² pixels).
//!
//! Second decision: kernels are normalised over the unit disc and the estimate is
//! E = (1/r²) Σ Φ_p K(d_p/r) in f64; r is the k-th distance over *all* candidates, and
//! photons failing the same-side or topological test just contribute nothing.

pub mod bench;
mod estimate;
mod index;
mod kernel;

pub use estimate::{EstimateParams, PhotonMap, radiance_lambertian};
pub use index::{Brute, Index, IndexKind, KdTree, Kiddo, KnnHint, Neighbor};
pub use kernel::{JENSEN_ALPHA, JENSEN_BETA, Kernel, jensen_gaussian_mass};

#[cfg(test)]
mod tests;
