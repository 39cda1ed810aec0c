//! Warps from the unit square to the shapes a renderer samples. Each comes as a trio
//! `sample_x` / `x_pdf` / `invert_x` (Mitsuba 3's `warp` module; pbrt-v4 Appendix A.5):
//! the inverse lets tests check a round trip, and lets samplers be composed with
//! stratified or low-discrepancy points later without redesign.
//!
//! Nothing here owns an RNG: uniform numbers come in as arguments, so the caller decides
//! which dimension of which stream feeds which decision (pbrt-v4 §8.3).

use glam::{Vec2, Vec3};
use std::f32::consts::{FRAC_1_PI, FRAC_PI_2, FRAC_PI_4, TAU};

/// The largest `f32` below 1: where a remapped uniform must stay inside `[0, 1)`.
pub const ONE_MINUS_EPSILON: f32 = 1.0 - f32::EPSILON / 2.0;

/// Azimuth `atan2(y, x)` mapped back to the `[0, 1)` uniform that produced it.
#[inline]
fn phi_to_unit(y: f32, x: f32) -> f32 {
    let mut t = y.atan2(x) / TAU;
    if t < 0.0 {
        t += 1.0;
    }
    t.min(ONE_MINUS_EPSILON)
}

// --- Disk -------------------------------------------------------------------------------

/// Uniform point on the unit disk by Shirley and Chiu's concentric map (1997): squares map to
/// rings, so strata keep their shape and area, unlike the polar `sqrt(u)` map
/// (pbrt-v4 §A.5.1).
#[inline]
pub fn sample_uniform_disk_concentric(u: [f32; 2]) -> Vec2 {
    let (ux, uy) = (2.0 * u[0] - 1.0, 2.0 * u[1] - 1.0);
    if ux == 0.0 && uy == 0.0 {
        return Vec2::ZERO;
    }
    let (r, theta) = if ux.abs() > uy.abs() {
        (ux, FRAC_PI_4 * (uy / ux))
    } else {
        (uy, FRAC_PI_2 - FRAC_PI_4 * (ux / uy))
    };
    Vec2::new(r * theta.cos(), r * theta.sin())
}

/// Density of [`sample_uniform_disk_concentric`] with respect to area: `1/π` on the disk.
#[inline]
pub fn uniform_disk_concentric_pdf(p: Vec2) -> f32 {
    if p.length_squared() <= 1.0 {
        FRAC_1_PI
    } else {
        0.0
    }
}

/// Inverse of [`sample_uniform_disk_concentric`] (Mitsuba 3,
/// `uniform_disk_to_square_concentric`): the signed radius picks the square's half, the
/// angle measured in that half's frame gives the other coordinate.
#[inline]
pub fn invert_uniform_disk_concentric(p: Vec2) -> [f32; 2] {
    let y_major = p.x.abs() < p.y.abs();
    let r_sign = if y_major { p.y } else { p.x };
    let r = p.length().copysign(r_sign);
    let phi = (p.y * r_sign.signum()).atan2(p.x * r_sign.signum());
    let mut t = phi / FRAC_PI_4;
    if y_major {
        t = 2.0 - t;
    }
    t *= r;
    let (ux, uy) = if y_major { (t, r) } else { (r, t) };
    [0.5 * ux + 0.5, 0.5 * uy + 0.5]
}

// --- Hemisphere and sphere --------------------------------------------------------------

/// Cosine-weighted direction about +z by Malley's method: lift a uniform disk point onto the
/// hemisphere (pbrt-v4 §A.5.3).
#[inline]
pub fn sample_cosine_hemisphere(u: [f32; 2]) -> Vec3 {
    let d = sample_uniform_disk_concentric(u);
    let z = (1.0 - d.length_squared()).max(0.0).sqrt();
    Vec3::new(d.x, d.y, z)
}

/// Solid-angle density of [`sample_cosine_hemisphere`]: `cos θ / π` above the plane, 0 below.
#[inline]
pub fn cosine_hemisphere_pdf(w: Vec3) -> f32 {
    w.z.max(0.0) * FRAC_1_PI
}

/// Inverse of [`sample_cosine_hemisphere`]: project to the disk, invert the disk map.
#[inline]
pub fn invert_cosine_hemisphere(w: Vec3) -> [f32; 2] {
    invert_uniform_disk_concentric(Vec2::new(w.x, w.y))
}

/// Uniform direction on the hemisphere about +z: `z` is uniform because the area of a
/// spherical zone is proportional to its height (Archimedes; pbrt-v4 §A.5.2).
#[inline]
pub fn sample_uniform_hemisphere(u: [f32; 2]) -> Vec3 {
    let z = u[0];
    let r = (1.0 - z * z).max(0.0).sqrt();
    let phi = TAU * u[1];
    Vec3::new(r * phi.cos(), r * phi.sin(), z)
}

/// Solid-angle density of [`sample_uniform_hemisphere`]: `1/(2π)` for `z ≥ 0`.
#[inline]
pub fn uniform_hemisphere_pdf(w: Vec3) -> f32 {
    if w.z >= 0.0 { 0.5 * FRAC_1_PI } else { 0.0 }
}

/// Inverse of [`sample_uniform_hemisphere`].
#[inline]
pub fn invert_uniform_hemisphere(w: Vec3) -> [f32; 2] {
    [w.z, phi_to_unit(w.y, w.x)]
}

/// Uniform direction on the unit sphere (`z` uniform in `[-1, 1]`, as for the hemisphere).
#[inline]
pub fn sample_uniform_sphere(u: [f32; 2]) -> Vec3 {
    let z = 1.0 - 2.0 * u[0];
    let r = (1.0 - z * z).max(0.0).sqrt();
    let phi = TAU * u[1];
    Vec3::new(r * phi.cos(), r * phi.sin(), z)
}

/// Solid-angle density of [`sample_uniform_sphere`]: `1/(4π)`.
#[inline]
pub fn uniform_sphere_pdf(_w: Vec3) -> f32 {
    0.25 * FRAC_1_PI
}

/// Inverse of [`sample_uniform_sphere`].
#[inline]
pub fn invert_uniform_sphere(w: Vec3) -> [f32; 2] {
    [(0.5 - 0.5 * w.z).clamp(0.0, 1.0), phi_to_unit(w.y, w.x)]
}

// --- Triangle ---------------------------------------------------------------------------

/// Uniform barycentrics `(b0, b1, b2)` by Heitz's low-distortion map (2019, "A Low-Distortion
/// Map Between Triangle and Square"; pbrt-v4 §6.5.4): a shear of one half of the square
/// instead of the classic `sqrt(u0)` fold, so it is exactly invertible and cheap.
#[inline]
pub fn sample_uniform_triangle(u: [f32; 2]) -> Vec3 {
    let (b0, b1) = if u[0] < u[1] {
        let b0 = 0.5 * u[0];
        (b0, u[1] - b0)
    } else {
        let b1 = 0.5 * u[1];
        (u[0] - b1, b1)
    };
    Vec3::new(b0, b1, 1.0 - b0 - b1)
}

/// Density of [`sample_uniform_triangle`] over the `(b0, b1)` parameter triangle, whose area is
/// 1/2: the map's Jacobian is 1/2 everywhere, so the density is 2. On a real triangle of
/// area `A` the area density is `1/A`.
#[inline]
pub fn uniform_triangle_pdf(b: Vec3) -> f32 {
    if b.min_element() >= 0.0 && b.x + b.y <= 1.0 {
        2.0
    } else {
        0.0
    }
}

/// Inverse of [`sample_uniform_triangle`]: `b0 < b1` exactly when `u0 < u1`.
#[inline]
pub fn invert_uniform_triangle(b: Vec3) -> [f32; 2] {
    if b.x < b.y {
        [2.0 * b.x, b.y + b.x]
    } else {
        [b.x + b.y, 2.0 * b.y]
    }
}

// --- Discrete ---------------------------------------------------------------------------

/// A discrete distribution proportional to non-negative weights (lights by power, pbrt-v4
/// §12.6.2), sampled by inverting its CDF with a binary search. Sums run in `f64` so a
/// million small weights do not lose the tail to rounding.
#[derive(Clone, Debug)]
pub struct Distribution1D {
    func: Vec<f64>,
    cdf: Vec<f64>,
    total: f64,
}

impl Distribution1D {
    /// Panics on an empty slice or a negative or non-finite weight: those are caller bugs.
    /// All-zero weights fall back to uniform, as pbrt-v4's `PiecewiseConstant1D` does, so a
    /// scene of black lights still samples something.
    pub fn new(weights: &[f64]) -> Distribution1D {
        assert!(
            !weights.is_empty(),
            "Distribution1D needs at least one weight"
        );
        assert!(
            weights.iter().all(|w| w.is_finite() && *w >= 0.0),
            "Distribution1D weights must be finite and non-negative"
        );
        let total: f64 = weights.iter().sum();
        let func = if total > 0.0 {
            weights.to_vec()
        } else {
            vec![1.0; weights.len()]
        };
        let norm: f64 = func.iter().sum();
        let mut cdf = Vec::with_capacity(func.len() + 1);
        let mut run = 0.0;
        cdf.push(0.0);
        for w in &func {
            run += w;
            cdf.push(run / norm);
        }
        // Exactly 1, so every u < 1 finds a bucket.
        *cdf.last_mut().expect("non-empty") = 1.0;
        Distribution1D { func, cdf, total }
    }

    pub fn len(&self) -> usize {
        self.func.len()
    }

    /// Always false: construction rejects empty weights.
    pub fn is_empty(&self) -> bool {
        self.func.is_empty()
    }

    /// Sum of the weights given to [`Distribution1D::new`] (e.g. total emitted power).
    pub fn total(&self) -> f64 {
        self.total
    }

    /// `(index, pmf, u')` where `u'` is `u` rescaled within the chosen bucket, a fresh uniform
    /// that can drive the next decision (pbrt-v4 §A.1, "sample reuse").
    #[inline]
    pub fn sample(&self, u: f32) -> (usize, f32, f32) {
        let u = u as f64;
        // First i with cdf[i + 1] > u: never a zero-weight bucket, whose cdf step is empty.
        let i = self.cdf[1..]
            .partition_point(|&c| c <= u)
            .min(self.len() - 1);
        let width = self.cdf[i + 1] - self.cdf[i];
        let u_remapped = if width > 0.0 {
            ((u - self.cdf[i]) / width) as f32
        } else {
            0.0
        };
        (i, width as f32, u_remapped.clamp(0.0, ONE_MINUS_EPSILON))
    }

    /// Probability of index `i`.
    #[inline]
    pub fn pmf(&self, i: usize) -> f32 {
        (self.cdf[i + 1] - self.cdf[i]) as f32
    }

    /// Inverse of [`Distribution1D::sample`]: the `u` that picks `i` with remapped `u'`.
    #[inline]
    pub fn invert(&self, i: usize, u_remapped: f32) -> f32 {
        let u = self.cdf[i] + u_remapped as f64 * (self.cdf[i + 1] - self.cdf[i]);
        (u as f32).min(ONE_MINUS_EPSILON)
    }
}

/// A piecewise-constant density on `[0, 1]^2` from an `nu x nv` grid of non-negative weights:
/// a marginal [`Distribution1D`] over the rows picks `v`, then that row's conditional picks
/// `u` (pbrt-v4 §A.5.6, `PiecewiseConstant2D`). It drives importance sampling of
/// environment maps, where a cell is a texel (pbrt-v4 §12.5.2).
#[derive(Clone, Debug)]
pub struct Distribution2D {
    nu: usize,
    nv: usize,
    /// One distribution over the columns per row.
    conditional: Vec<Distribution1D>,
    /// Over the rows, by row sums.
    marginal: Distribution1D,
}

/// The cell of `x` in `[0, 1]` among `n` equal cells. Sampling, pdf and inversion all find
/// cells through this one function, so a sampled point's pdf is the pdf its sample reported.
#[inline]
fn cell_of(x: f32, n: usize) -> usize {
    ((x.max(0.0) as f64 * n as f64) as usize).min(n - 1)
}

/// `(cell + t) / n` in `f32`, stepped by an ulp if rounding moved it into a neighbour cell
/// (e.g. `1 + ONE_MINUS_EPSILON` rounds to 2): a zero-weight neighbour would report pdf 0.
#[inline]
fn point_in_cell(cell: usize, t: f32, n: usize) -> f32 {
    let mut x = ((cell as f64 + t as f64) / n as f64) as f32;
    while cell_of(x, n) > cell {
        x = f32::from_bits(x.to_bits() - 1);
    }
    while cell_of(x, n) < cell {
        x = f32::from_bits(x.to_bits() + 1);
    }
    x
}

impl Distribution2D {
    /// `weights` is row-major, `weights[v * nu + u]`, row `v` covering
    /// `[v / nv, (v + 1) / nv]`. `None` when every weight is 0: there is nothing to sample,
    /// and unlike [`Distribution1D`] a uniform fallback would hide a black environment map.
    /// Panics, as [`Distribution1D::new`] does, on an empty grid, a length that is not
    /// `nu * nv`, or a negative or non-finite weight: those are caller bugs.
    pub fn new(weights: &[f64], nu: usize, nv: usize) -> Option<Distribution2D> {
        assert!(nu > 0 && nv > 0, "Distribution2D needs a non-empty grid");
        assert_eq!(
            weights.len(),
            nu * nv,
            "Distribution2D needs nu * nv weights"
        );
        let conditional: Vec<Distribution1D> =
            weights.chunks_exact(nu).map(Distribution1D::new).collect();
        let rows: Vec<f64> = conditional.iter().map(Distribution1D::total).collect();
        if rows.iter().sum::<f64>() <= 0.0 {
            return None;
        }
        Some(Distribution2D {
            nu,
            nv,
            conditional,
            marginal: Distribution1D::new(&rows),
        })
    }

    /// Grid size `(nu, nv)`.
    pub fn resolution(&self) -> (usize, usize) {
        (self.nu, self.nv)
    }

    /// Sum of all weights.
    pub fn total(&self) -> f64 {
        self.marginal.total()
    }

    /// A point of `[0, 1]^2` and its density with respect to area. `u[1]` picks the row and
    /// `u[0]` the column, so a stratified `u[0]` stays stratified within a row.
    #[inline]
    pub fn sample(&self, u: [f32; 2]) -> (Vec2, f32) {
        let (row, pmf_row, tv) = self.marginal.sample(u[1]);
        let (col, pmf_col, tu) = self.conditional[row].sample(u[0]);
        let p = Vec2::new(
            point_in_cell(col, tu, self.nu),
            point_in_cell(row, tv, self.nv),
        );
        (p, pmf_row * pmf_col * (self.nu * self.nv) as f32)
    }

    /// Density of [`Distribution2D::sample`] at `p`: the cell's probability over its area
    /// `1 / (nu nv)`; 0 outside the square.
    #[inline]
    pub fn pdf(&self, p: Vec2) -> f32 {
        if !(0.0..=1.0).contains(&p.x) || !(0.0..=1.0).contains(&p.y) {
            return 0.0;
        }
        let (col, row) = (cell_of(p.x, self.nu), cell_of(p.y, self.nv));
        self.marginal.pmf(row) * self.conditional[row].pmf(col) * (self.nu * self.nv) as f32
    }

    /// Inverse of [`Distribution2D::sample`]: the `u` that lands on `p`.
    #[inline]
    pub fn invert(&self, p: Vec2) -> [f32; 2] {
        let p = p.clamp(Vec2::ZERO, Vec2::ONE);
        let (col, row) = (cell_of(p.x, self.nu), cell_of(p.y, self.nv));
        let tu = (p.x as f64 * self.nu as f64 - col as f64).clamp(0.0, 1.0) as f32;
        let tv = (p.y as f64 * self.nv as f64 - row as f64).clamp(0.0, 1.0) as f32;
        [
            self.conditional[row].invert(col, tu),
            self.marginal.invert(row, tv),
        ]
    }
}

// --- Multiple importance sampling -------------------------------------------------------

/// Veach's power heuristic with β = 2 (Veach 1997 §9.2.4; pbrt-v4 §2.2.3): the MIS weight of a
/// sample from strategy f, drawn `nf` times, against strategy g drawn `ng` times.
#[inline]
pub fn power_heuristic(nf: u32, f_pdf: f32, ng: u32, g_pdf: f32) -> f32 {
    let f = nf as f32 * f_pdf;
    let g = ng as f32 * g_pdf;
    let (f2, g2) = (f * f, g * g);
    // A delta-like pdf (or one whose square overflows) takes the whole weight.
    if f2.is_infinite() {
        return 1.0;
    }
    if f2 + g2 == 0.0 { 0.0 } else { f2 / (f2 + g2) }
}
