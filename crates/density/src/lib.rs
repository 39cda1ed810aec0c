//! `density`: photon density estimation. A spatial index over photon positions (k-nearest
//! and fixed-radius queries), kernels normalised over the unit disc (Silverman 1986,
//! "Density Estimation"; Jensen 2001, "Realistic Image Synthesis Using Photon Mapping"
//! §7.2), and the bias controls of worksheet 7 (same-side and topological tests, Garcia et
//! al. 2012's k-th photon exclusion). No file IO: photons come in as values, their power
//! already divided by the number of light paths emitted. Also as pure functions: photon
//! splatting onto eye vertices (`splat`) and the per-pixel statistics of stochastic
//! progressive photon mapping (`sppm`).
//!
//! Key decision: **every index returns exactly the same neighbours** — the k smallest
//! `(d2, index)` within `r_max`, ties broken by index; for a fixed radius, every point
//! within it, in the same order — so the back-ends (our kd-tree, kiddo, brute force) are
//! interchangeable and tested for equality with brute force, and an estimate never depends
//! on which one ran. Use our kd-tree: built in place over f32 positions with u32 ids (no
//! node structs, positions hot and ids cold), searching radius-first (a range search at a
//! radius guessed from the density stored per leaf, then a bucket sort of the candidates;
//! depth-first search with buffered selection when the guess fails), it was the fastest at
//! 1M photons on a cube's faces for k from 50 to 1000 (`bench::bench_knn`), ahead of
//! kiddo's `ImmutableKdTree` (releases 5 and 6), with brute force far behind; ours also
//! builds faster.
//! Measurements: docs/benchmarks.md.
//!
//! Second decision: kernels are normalised over the unit disc and the estimate is
//! E = (1/r²) Σ Φ_p K(d_p/r) in f64; r is the k-th distance over *all* candidates, and
//! photons failing the same-side or topological test just contribute nothing.
//!
//! Third decision: for large k, search radius-first. [`KdTree::knn_hinted`] takes a
//! [`KnnHint`] (the previous query's point and k-th distance), gathers every point within a
//! slightly larger radius in slot order, and selects the k smallest in linear time (bucket
//! select), so no sort; the set is exactly `knn`'s, and [`PhotonMap::irradiance`] is
//! [`PhotonMap::irradiance_hinted`] without a hint, bit for bit. Queried in pixel order
//! (`bench::bench_coherent`), this made k-NN and irradiance several times faster, the more
//! so the larger k, and it still pays with the hint of an unrelated point of similar
//! density; compiling the estimate loop once per kernel and test combination (same sums,
//! same order, so bit-identical) sped it up further. Measurements: docs/benchmarks.md.
//!
//! Fourth decision: each photon is stored once, split by use: its position in the index
//! (all the search reads), direction and power in a compact array the estimate loop reads
//! per neighbour, its surface id apart.

pub mod bench;
mod estimate;
mod index;
mod kernel;
pub mod splat;
pub mod sppm;

pub use estimate::{EstimateParams, MapPhoton, PhotonMap, radiance_lambertian};
pub use index::{Brute, Index, IndexKind, KdTree, Kiddo, KnnHint, Neighbor};
pub use kernel::{JENSEN_ALPHA, JENSEN_BETA, Kernel, jensen_gaussian_mass};

#[cfg(test)]
mod tests;
