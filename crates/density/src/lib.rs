//! `density`: photon density estimation. A k-nearest index over photon positions, the
//! kernels of algorithms.md §2.2, and the bias controls of worksheet 7 (same-side and
//! topological tests, Garcia et al.'s k-th photon exclusion). No file IO: photons come in
//! as values.
//!
//! Key decision: **every index returns exactly the same neighbours** — the k smallest
//! `(d2, index)` within `r_max`, ties broken by index — so the back-ends (our kd-tree,
//! kiddo, brute force) are interchangeable and tested for equality with brute force, and an
//! estimate never depends on which one ran. The default is our kd-tree: built in place
//! over f32 positions with u32 ids (anchors A3.4, A4.1, C), it was the fastest at 1M photons
//! for k = 50..1000 (`bench::bench_knn`).
//!
//! Second decision: kernels are normalised over the unit disc and the estimate is
//! E = (1/r²) Σ Φ_p K(d_p/r) in f64; r is the k-th distance over *all* candidates, and
//! photons failing the same-side or topological test just contribute nothing.

pub mod bench;
mod estimate;
mod index;
mod kernel;

pub use estimate::{EstimateParams, PhotonMap, radiance_lambertian};
pub use index::{Brute, Index, IndexKind, KdTree, Kiddo, Neighbor};
pub use kernel::{JENSEN_ALPHA, JENSEN_BETA, Kernel, jensen_gaussian_mass};

#[cfg(test)]
mod tests;
