//! The irradiance estimate E(x) = (1/r²) Σ_p Φ_p K(|x − x_p| / r), K normalised over the
//! unit disc (Jensen 2001 §7.1; Silverman 1986 §4.2): with k-NN, r is the distance to the
//! k-th nearest photon (a balloon estimator, bandwidth attached to the query point); with
//! a fixed radius, r is given (splatting and progressive photon mapping).

use crate::index::{Index, IndexKind, KnnHint, Neighbor};
use crate::kernel::Kernel;
use glam::{DVec3, Vec3};
use serde::{Deserialize, Serialize};
use store::Photon;

/// How to estimate. Round-trips through serde (parameter files; `r_max` infinite is spelled
/// `inf` in TOML). JSON cannot hold an infinite `r_max`: use a large finite one there.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct EstimateParams {
    /// Photons per estimate (k of k-NN). 0 gives zero.
    pub k: usize,
    /// Search radius limit; infinity = pure k-NN (the framework uses 1000 scene units).
    pub r_max: f32,
    pub kernel: Kernel,
    /// Keep only photons arriving from the normal's side: travel direction · n < 0.
    pub same_side: bool,
    /// Topological test against light leaking across corners (worksheet 7's check): keep
    /// photon p only if |n · (x_p − x)| < eps |x_p − x|, i.e. within asin(eps) of the
    /// tangent plane. `None` disables it. Rejected photons still count towards k and r
    /// (their area is elsewhere).
    pub topo: Option<f32>,
    /// Garcia et al. 2012 ("Description and solution of an unreported intrinsic bias in
    /// photon mapping density estimation with constant kernel", CGF 31(1)): when r is the
    /// distance to the k-th photon, sum only the k − 1 nearer ones.
    pub drop_kth: bool,
}

impl Default for EstimateParams {
    /// The framework's `irradiance_estimate`: k = 50, uniform kernel, same-side test.
    fn default() -> EstimateParams {
        EstimateParams {
            k: 50,
            r_max: f32::INFINITY,
            kernel: Kernel::Uniform,
            same_side: true,
            topo: None,
            drop_kth: false,
        }
    }
}

/// What the estimate loop reads per neighbour (see `PhotonMap::hot`).
#[derive(Clone, Copy, Debug)]
struct Hot {
    dir: Vec3,
    power: Vec3,
}

/// One photon as a [`PhotonMap`] holds it (its direction decoded), by map index.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MapPhoton {
    pub position: Vec3,
    /// Unit direction of travel (towards the surface).
    pub direction: Vec3,
    /// Flux, already divided by the number of paths emitted.
    pub power: Vec3,
    /// Primitive the photon landed on (`store::Photon::surface`).
    pub surface: u32,
}

/// Photons plus a spatial index over their positions. Each photon is stored once, split by
/// use: its position in the index (the search reads only positions), its direction and
/// power in `hot`, its surface id in `surface` (with the kd-tree, 45 bytes per photon in
/// all, its slot ids and split axes included, against 73 with a full copy). Map indices
/// (what [`Neighbor::index`] holds, what the accessors take) run in map order: the
/// kd-tree's slot order, so neighbours sit together in memory; the order given otherwise.
pub struct PhotonMap {
    index: Index,
    /// Direction, decoded once at build, and power: the estimate loop reads these two for
    /// every neighbour of every query (k = 1000 over 512² pixels is 2.6e8 reads); the
    /// octahedral decode (a divide and a normalise, in another crate so not inlined) cost a
    /// third of a k = 1000 estimate, and one 24-byte record with one bounds check beats a
    /// 32-byte photon plus a direction.
    hot: Vec<Hot>,
    surface: Vec<u32>,
}

impl PhotonMap {
    /// Photons' powers must already be divided by the number of light paths emitted to make
    /// them (not the number stored): estimates sum them as given. With the kd-tree the
    /// photons are reordered to its slot order, so map index i is no longer the i-th given.
    pub fn build(photons: Vec<Photon>, kind: IndexKind) -> PhotonMap {
        let pos: Vec<[f32; 3]> = photons.iter().map(|p| p.pos).collect();
        let mut index = Index::build(kind, &pos);
        drop(pos);
        let order = match &index {
            Index::KdTree(tree) => Some(tree.order()),
            _ => None,
        };
        let given = |i: usize| &photons[order.map_or(i, |o| o[i] as usize)];
        let hot = (0..photons.len())
            .map(|i| Hot {
                dir: given(i).direction(),
                power: given(i).power(),
            })
            .collect();
        let surface = (0..photons.len()).map(|i| given(i).surface).collect();
        if let Index::KdTree(tree) = &mut index {
            tree.relabel_by_slot();
        }
        PhotonMap {
            index,
            hot,
            surface,
        }
    }

    pub fn len(&self) -> usize {
        self.hot.len()
    }

    pub fn is_empty(&self) -> bool {
        self.hot.is_empty()
    }

    pub fn position(&self, i: usize) -> Vec3 {
        Vec3::from(self.index.points().get(i))
    }

    /// Unit direction of travel (towards the surface), decoded.
    pub fn direction(&self, i: usize) -> Vec3 {
        self.hot[i].dir
    }

    pub fn power(&self, i: usize) -> Vec3 {
        self.hot[i].power
    }

    pub fn surface(&self, i: usize) -> u32 {
        self.surface[i]
    }

    pub fn photon(&self, i: usize) -> MapPhoton {
        MapPhoton {
            position: self.position(i),
            direction: self.direction(i),
            power: self.power(i),
            surface: self.surface(i),
        }
    }

    /// Every photon in map order (spatially coherent with the kd-tree).
    pub fn iter(&self) -> impl ExactSizeIterator<Item = MapPhoton> + '_ {
        (0..self.len()).map(|i| self.photon(i))
    }

    pub fn index(&self) -> &Index {
        &self.index
    }

    /// k nearest photons within `r_max`, by map index, sorted by `(d2, index)`.
    pub fn knn(&self, x: Vec3, k: usize, r_max: f32, out: &mut Vec<Neighbor>) {
        self.index.knn(x, k, r_max, out);
    }

    /// The same neighbours as [`PhotonMap::knn`], in index order, radius-first from `hint`
    /// ([`Index::knn_hinted`]).
    pub fn knn_hinted(
        &self,
        x: Vec3,
        k: usize,
        r_max: f32,
        hint: &mut KnnHint,
        out: &mut Vec<Neighbor>,
    ) {
        self.index.knn_hinted(x, k, r_max, hint, out);
    }

    /// Every photon within `r` of `x`, by map index, sorted by `(d2, index)`
    /// ([`Index::within`]).
    pub fn within(&self, x: Vec3, r: f32, out: &mut Vec<Neighbor>) {
        self.index.within(x, r, out);
    }

    /// Irradiance E (flux per area) at `x` on a surface with unit normal `n`; f64 sums.
    /// The same as [`PhotonMap::irradiance_hinted`] with no hint, bit for bit.
    ///
    /// r is the distance to the k-th nearest photon within `r_max`. With fewer than k found,
    /// r = `r_max` if finite, else the distance to the farthest found. No photon found, or
    /// r = 0 (every photon found sits exactly at `x`: the density is undefined), gives zero.
    /// The result is clamped to [0, f32::MAX] (a NaN sum becomes 0). `n` must be unit
    /// length. `scratch` holds the neighbours after the call, in index order.
    pub fn irradiance(
        &self,
        x: Vec3,
        n: Vec3,
        p: &EstimateParams,
        scratch: &mut Vec<Neighbor>,
    ) -> Vec3 {
        self.irradiance_hinted(x, n, p, &mut KnnHint::default(), scratch)
    }

    /// [`PhotonMap::irradiance`] with the neighbours found radius-first from `hint`, which
    /// then holds this query's k-th distance. Keep one hint per thread and map and query
    /// coherently (pixels along a row): at k = 1000 on 1M photons this is several times
    /// faster than a k-NN search (`bench::bench_coherent`). The neighbour set, and so the
    /// estimate, is bit for bit the one without a hint, whatever the hint.
    pub fn irradiance_hinted(
        &self,
        x: Vec3,
        n: Vec3,
        p: &EstimateParams,
        hint: &mut KnnHint,
        scratch: &mut Vec<Neighbor>,
    ) -> Vec3 {
        self.index.knn_hinted(x, p.k, p.r_max, hint, scratch);
        self.irradiance_from_neighbors(x, n, p, scratch)
    }

    /// [`PhotonMap::irradiance`] from neighbours already found with `p.k` and `p.r_max`
    /// (e.g. to compare kernels on one search), in any order: the k-th is the one with
    /// the largest `(d2, index)`, and the sum runs in the order given (f64 rounding makes
    /// the last bits depend on it; `irradiance` sums in index order, which walks the
    /// tree-ordered photons in memory order).
    pub fn irradiance_from_neighbors(
        &self,
        x: Vec3,
        n: Vec3,
        p: &EstimateParams,
        neighbors: &[Neighbor],
    ) -> Vec3 {
        let found = neighbors.len();
        if found == 0 {
            return Vec3::ZERO;
        }
        let r_max_finite = p.r_max.is_finite();
        let kth = neighbors.iter().map(|nb| nb.key()).max().unwrap_or(0);
        // Is the radius set by a photon (which then lies on the kernel's boundary)?
        let (r2, on_boundary) = if found == p.k || !r_max_finite {
            (f32::from_bits((kth >> 32) as u32) as f64, true)
        } else {
            ((p.r_max as f64).powi(2), false)
        };
        if !(r2 > 0.0 && r2.is_finite()) {
            return Vec3::ZERO;
        }
        // Dropping the k-th photon: sum around it (keys are unique, indices being unique).
        let skip = if p.drop_kth && on_boundary {
            neighbors.iter().position(|nb| nb.key() == kth)
        } else {
            None
        };
        self.estimate(x, n, p, r2, skip, neighbors)
    }

    /// Irradiance at `x` (surface normal `n`, unit length) from every photon within the
    /// fixed radius `r`: E = (1/r²) Σ Φ_p K(d_p/r), with `p`'s kernel, same-side and
    /// topological tests (`p.k`, `p.r_max` and `p.drop_kth` play no part: no photon sets
    /// r). For splatting and progressive estimators, whose radius comes from elsewhere.
    /// Unbiased on a uniform density away from edges (no k-NN boundary photon). Zero
    /// unless `r` is positive and finite; clamped like [`PhotonMap::irradiance`]. Bit for
    /// bit `irradiance` with `k = usize::MAX` and `r_max = r`. `scratch` holds the photons
    /// found, in index order.
    pub fn irradiance_within(
        &self,
        x: Vec3,
        n: Vec3,
        r: f32,
        p: &EstimateParams,
        scratch: &mut Vec<Neighbor>,
    ) -> Vec3 {
        if !(r > 0.0 && r.is_finite()) {
            scratch.clear();
            return Vec3::ZERO;
        }
        // Index order, as `irradiance` sums: the result does not depend on the back-end.
        self.index.within_in_index_order(x, r, scratch);
        if scratch.is_empty() {
            return Vec3::ZERO;
        }
        // As `irradiance_from_neighbors` squares a finite r_max.
        self.estimate(x, n, p, (r as f64).powi(2), None, scratch)
    }

    /// (norm / r²) Σ Φ_p shape(d2_p / r²) over `neighbors` (but `skip`) passing `p`'s
    /// tests, in the order given; `r2` positive and finite.
    fn estimate(
        &self,
        x: Vec3,
        n: Vec3,
        p: &EstimateParams,
        r2: f64,
        skip: Option<usize>,
        neighbors: &[Neighbor],
    ) -> Vec3 {
        let inv_r2 = 1.0 / r2;
        let f = Filter {
            x,
            n,
            skip,
            same_side: p.same_side,
            topo: p.topo,
            inv_r2,
        };
        // One loop per kernel (the `match` hoisted out; `shape` inlines to its own arm).
        // Each closure takes u = d2 / r² and returns exactly `shape(sqrt(u))`: the uniform
        // kernel needs no square root, since sqrt rounds correctly and monotonically, so
        // sqrt(u) > 1 exactly when u > 1 + ε (sqrt(1 + ε) rounds down to 1, sqrt(1 + 2ε)
        // up to 1 + ε). The others keep the root: t·t is not u to the last bit.
        let sum = match p.kernel {
            Kernel::Uniform => self.sum(&f, neighbors, |u| {
                if u > 1.0 + f64::EPSILON { 0.0 } else { 1.0 }
            }),
            Kernel::Cone { k } => self.sum(&f, neighbors, |u| Kernel::Cone { k }.shape(u.sqrt())),
            Kernel::Gaussian => self.sum(&f, neighbors, |u| Kernel::Gaussian.shape(u.sqrt())),
            Kernel::GaussianJensen => {
                self.sum(&f, neighbors, |u| Kernel::GaussianJensen.shape(u.sqrt()))
            }
            Kernel::Epanechnikov => {
                self.sum(&f, neighbors, |u| Kernel::Epanechnikov.shape(u.sqrt()))
            }
            Kernel::Silverman => self.sum(&f, neighbors, |u| Kernel::Silverman.shape(u.sqrt())),
            Kernel::Triweight => self.sum(&f, neighbors, |u| Kernel::Triweight.shape(u.sqrt())),
        };
        let e = sum * (p.kernel.norm() * inv_r2);
        e.as_vec3().clamp(Vec3::ZERO, Vec3::splat(f32::MAX))
    }

    /// Σ Φ_p shape(d2_p / r²) over the neighbours passing `f`'s tests, in the order given,
    /// in f64: one loop per combination of the tests (`sum_with`).
    #[inline(always)]
    fn sum(&self, f: &Filter, neighbors: &[Neighbor], shape: impl Fn(f64) -> f64) -> DVec3 {
        match (f.same_side, f.topo.is_some()) {
            (false, false) => self.sum_with::<false, false>(f, neighbors, shape),
            (true, false) => self.sum_with::<true, false>(f, neighbors, shape),
            (false, true) => self.sum_with::<false, true>(f, neighbors, shape),
            (true, true) => self.sum_with::<true, true>(f, neighbors, shape),
        }
    }

    /// [`PhotonMap::sum`] with the same-side and topological tests fixed at compile time.
    /// The neighbour at `f.skip` is left out by summing the slices either side of it.
    #[inline(always)]
    fn sum_with<const SAME_SIDE: bool, const TOPO: bool>(
        &self,
        f: &Filter,
        neighbors: &[Neighbor],
        shape: impl Fn(f64) -> f64,
    ) -> DVec3 {
        let (head, tail) = match f.skip {
            Some(i) => (&neighbors[..i], &neighbors[i + 1..]),
            None => (neighbors, &neighbors[..0]),
        };
        let sum = self.sum_slice::<SAME_SIDE, TOPO>(f, head, DVec3::ZERO, &shape);
        self.sum_slice::<SAME_SIDE, TOPO>(f, tail, sum, &shape)
    }

    /// `sum` plus the terms of `neighbors`, in order. Every neighbour's weight is computed
    /// (no branch on the tests before the arithmetic); a rejected one leaves the sum as is.
    #[inline(always)]
    fn sum_slice<const SAME_SIDE: bool, const TOPO: bool>(
        &self,
        f: &Filter,
        neighbors: &[Neighbor],
        mut sum: DVec3,
        shape: &impl Fn(f64) -> f64,
    ) -> DVec3 {
        let eps = f.topo.unwrap_or(0.0);
        let pts = self.index.points();
        for nb in neighbors {
            let i = nb.index as usize;
            let h = self.hot[i];
            let mut keep = true;
            // Not `dot < 0`: a NaN dot product keeps the photon, as it always has.
            if SAME_SIDE && h.dir.dot(f.n) >= 0.0 {
                keep = false;
            }
            if TOPO {
                let v = Vec3::from(pts.get(i)) - f.x;
                let len = v.length();
                // A photon at x itself lies in every tangent plane.
                keep &= !(len > 0.0 && f.n.dot(v).abs() >= eps * len);
            }
            let c = h.power.as_dvec3() * shape(nb.d2 as f64 * f.inv_r2);
            if keep {
                sum += c;
            }
        }
        sum
    }

    /// Radiance leaving a Lambertian surface of albedo `rho` at `x`: ρ/π · E.
    pub fn radiance_lambertian(
        &self,
        x: Vec3,
        n: Vec3,
        rho: Vec3,
        p: &EstimateParams,
        scratch: &mut Vec<Neighbor>,
    ) -> Vec3 {
        radiance_lambertian(self.irradiance(x, n, p, scratch), rho)
    }
}

/// The per-query constants of [`PhotonMap::irradiance_from_neighbors`]'s sum.
struct Filter {
    x: Vec3,
    n: Vec3,
    /// Position in `neighbors` of the one neighbour to leave out.
    skip: Option<usize>,
    same_side: bool,
    topo: Option<f32>,
    inv_r2: f64,
}

/// L = ρ/π · E for a Lambertian surface of albedo ρ.
pub fn radiance_lambertian(e: Vec3, rho: Vec3) -> Vec3 {
    rho * std::f32::consts::FRAC_1_PI * e
}
