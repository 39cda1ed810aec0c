//! Orthonormal frames: the shading frame that BSDFs live in (z = normal).

use glam::Vec3;

/// A right-handed orthonormal basis `(s, t, n)`. Local coordinates put `n` on +z, so a BSDF
/// reads `cos θ` as `w.z` (pbrt-v4 §9.1.1, Mitsuba 3's `Frame3f`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Frame {
    pub s: Vec3,
    pub t: Vec3,
    pub n: Vec3,
}

impl Frame {
    /// The frame around a unit normal `n`. Branch-free and stable near `n = -z`, where the
    /// original Frisvad construction divides by zero (Duff et al. 2017, "Building an
    /// orthonormal basis, revisited", Listing 3).
    #[inline]
    pub fn from_z(n: Vec3) -> Frame {
        let sign = 1.0f32.copysign(n.z);
        let a = -1.0 / (sign + n.z);
        let b = n.x * n.y * a;
        let s = Vec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x);
        let t = Vec3::new(b, sign + n.y * n.y * a, -n.y);
        Frame { s, t, n }
    }

    /// World → local: projections on the axes (the basis is orthonormal, so the inverse is
    /// the transpose).
    #[inline]
    pub fn to_local(&self, v: Vec3) -> Vec3 {
        Vec3::new(v.dot(self.s), v.dot(self.t), v.dot(self.n))
    }

    /// Local → world.
    #[inline]
    pub fn to_world(&self, v: Vec3) -> Vec3 {
        self.s * v.x + self.t * v.y + self.n * v.z
    }
}
