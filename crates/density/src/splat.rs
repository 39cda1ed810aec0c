//! A photon's anisotropic footprint for splatting (Frisvad et al. 2014, "Photon differential
//! splatting for rendering caustics", CGF 33(6)): the ellipse `{x + α a + β b : α² + β² ≤ 1}`
//! spanned by the photon's positional differentials `a`, `b` in the tangent plane, and the
//! irradiance it deposits at a point y, `E_p(y) = Φ_p K(|M (y - x)|) |det M|` with `M` the
//! map from the plane to the unit disc and `K` Silverman's kernel, so that each photon's
//! splat integrates to its flux over the plane.
//!
//! The ellipse is kept in its principal form: the semi-axes are the singular values of
//! `[a b]` (eigenvalues of `[a b][a b]ᵀ`) along orthonormal directions. That is what makes
//! the clamps of the paper's stability discussion well defined: each principal semi-axis is
//! clamped to `[min_len, max_len]` (a focus makes one of them vanish; a long chain of
//! internal reflections makes them huge), and `|det M| = 1 / (σ₁ σ₂)` is recomputed from the
//! clamped axes, so every photon still deposits exactly its flux. A degenerate footprint
//! (parallel or zero axes, non-finite values) becomes a disc of radius `min_len`.

use crate::Kernel;
use glam::Vec3;

/// A photon's footprint on its surface, ready to weigh points.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Footprint {
    pub center: Vec3,
    /// Unit normal of the surface plane.
    pub normal: Vec3,
    /// Principal directions (unit, in the plane) divided by their clamped semi-axes: the rows
    /// of `M`.
    rows: [Vec3; 2],
    /// Clamped principal semi-axes, largest first.
    pub axes: [f32; 2],
}

impl Footprint {
    /// The footprint of semi-axes `a`, `b` (any two vectors; their components along `normal`
    /// are ignored) about `center`, principal semi-axes clamped to `[min_len, max_len]`.
    /// `None` only for a normal that is not a direction or bounds that are not
    /// `0 < min_len <= max_len`, all finite.
    pub fn new(
        center: Vec3,
        normal: Vec3,
        a: Vec3,
        b: Vec3,
        min_len: f32,
        max_len: f32,
    ) -> Option<Footprint> {
        let n = normal.normalize_or_zero();
        if n == Vec3::ZERO
            || !center.is_finite()
            || !(min_len > 0.0 && min_len <= max_len && max_len.is_finite())
        {
            return None;
        }
        let frame = math::Frame::from_z(n);
        let (t1, t2) = (frame.s, frame.t);
        let finite = |v: Vec3| if v.is_finite() { v } else { Vec3::ZERO };
        let (a, b) = (finite(a), finite(b));
        // [a b] in the tangent basis, and S = A Aᵀ (in f64: squares of tiny or huge axes).
        let (a1, a2, b1, b2) = (
            a.dot(t1) as f64,
            a.dot(t2) as f64,
            b.dot(t1) as f64,
            b.dot(t2) as f64,
        );
        let (p, q, r) = (a1 * a1 + b1 * b1, a1 * a2 + b1 * b2, a2 * a2 + b2 * b2);
        let mean = 0.5 * (p + r);
        let dev = (0.25 * (p - r) * (p - r) + q * q).sqrt();
        let (l1, l2) = (mean + dev, (mean - dev).max(0.0));
        // Eigenvector of the larger eigenvalue; any direction when S is a multiple of I.
        let (e1x, e1y) = if dev <= 1e-12 * mean.max(f64::MIN_POSITIVE) {
            (1.0, 0.0)
        } else if p >= r {
            (l1 - r, q)
        } else {
            (q, l1 - p)
        };
        let len = (e1x * e1x + e1y * e1y).sqrt();
        let (e1x, e1y) = if len > 0.0 && len.is_finite() {
            (e1x / len, e1y / len)
        } else {
            (1.0, 0.0)
        };
        let e1 = (e1x as f32) * t1 + (e1y as f32) * t2;
        let e2 = n.cross(e1);
        let clamp = |l: f64| {
            let s = l.sqrt() as f32;
            if s.is_finite() {
                s.clamp(min_len, max_len)
            } else {
                max_len
            }
        };
        let (s1, s2) = (clamp(l1), clamp(l2));
        Some(Footprint {
            center,
            normal: n,
            rows: [e1 / s1, e2 / s2],
            axes: [s1.max(s2), s1.min(s2)],
        })
    }

    /// Radius of the smallest disc about the centre holding the ellipse.
    pub fn radius(&self) -> f32 {
        self.axes[0]
    }

    /// `|det M|`: one over the clamped ellipse's parameter area `σ₁ σ₂`.
    pub fn det(&self) -> f32 {
        1.0 / (self.axes[0] * self.axes[1])
    }

    /// `t = |M (y - x)|` for a point `y` (its offset along the normal is ignored: callers
    /// decide which points lie on the surface).
    pub fn t(&self, y: Vec3) -> f32 {
        let d = y - self.center;
        let (u, v) = (self.rows[0].dot(d), self.rows[1].dot(d));
        (u * u + v * v).sqrt()
    }

    /// The irradiance per unit flux this footprint deposits at `y`:
    /// `K(|M (y - x)|) |det M|` with Silverman's kernel (zero outside the ellipse).
    pub fn weight(&self, y: Vec3) -> f64 {
        let t = self.t(y);
        if t >= 1.0 {
            return 0.0;
        }
        Kernel::Silverman.weight(t as f64) * self.det() as f64
    }
}
