use crate::float::gamma;
use glam::Vec3;

/// A ray `o + t d`, `0 < t < t_max`. `d` need not be unit length: rays spawned towards a
/// point use `t_max` just below 1.
#[derive(Clone, Copy, Debug)]
pub struct Ray {
    pub o: Vec3,
    pub d: Vec3,
    pub t_max: f32,
}

impl Ray {
    pub fn new(o: Vec3, d: Vec3) -> Ray {
        Ray {
            o,
            d,
            t_max: f32::INFINITY,
        }
    }

    pub fn at(&self, t: f32) -> Vec3 {
        self.o + t * self.d
    }
}

/// pbrt-v4's `ShadowEpsilon`: rays spawned *to* a point stop at `1 - SHADOW_EPSILON` of the
/// way, after both end points were offset past their error bounds (pbrt-v4 §6.8.6).
pub const SHADOW_EPSILON: f32 = 1e-4;

/// A point on a surface with a conservative bound on its floating-point error and the
/// geometric normal (unit) of the surface there.
#[derive(Clone, Copy, Debug)]
pub struct SurfacePoint {
    pub p: Vec3,
    /// Absolute error bound per component: the true point lies in `p ± p_err`.
    pub p_err: Vec3,
    pub n: Vec3,
}

impl SurfacePoint {
    /// Origin for a ray leaving towards `w`: `p` moved along the normal, to `w`'s side, by the
    /// projection of the error box on the normal, then rounded away from the surface
    /// (pbrt-v4 §6.8.6 `OffsetRayOrigin`).
    pub fn offset_origin(&self, w: Vec3) -> Vec3 {
        let d = self.n.abs().dot(self.p_err);
        let mut offset = d * self.n;
        if w.dot(self.n) < 0.0 {
            offset = -offset;
        }
        let po = self.p + offset;
        Vec3::new(
            ulp_step(po.x, offset.x),
            ulp_step(po.y, offset.y),
            ulp_step(po.z, offset.z),
        )
    }

    /// A ray leaving the surface in direction `d`.
    pub fn spawn_ray(&self, d: Vec3) -> Ray {
        Ray::new(self.offset_origin(d), d)
    }

    /// A ray towards the point `to` that stops just short of it (shadow rays to a sampled
    /// light point). `t` runs from 0 at the origin to 1 at `to`.
    pub fn spawn_ray_to(&self, to: Vec3) -> Ray {
        let o = self.offset_origin(to - self.p);
        Ray {
            o,
            d: to - o,
            t_max: 1.0 - SHADOW_EPSILON,
        }
    }

    /// A ray between two surface points with both ends offset past their error bounds, so
    /// neither surface occludes the segment (pbrt-v4 `SpawnRayTo(Interaction, Interaction)`).
    pub fn spawn_ray_to_point(&self, to: &SurfacePoint) -> Ray {
        let pf = self.offset_origin(to.p - self.p);
        let pt = to.offset_origin(pf - to.p);
        Ray {
            o: pf,
            d: pt - pf,
            t_max: 1.0 - SHADOW_EPSILON,
        }
    }

    /// Error bound of a barycentric interpolation `b0 p0 + b1 p1 + b2 p2` (pbrt-v4 §6.8.5).
    pub fn barycentric_error(b: [f32; 3], p: [Vec3; 3]) -> Vec3 {
        ((b[0] * p[0]).abs() + (b[1] * p[1]).abs() + (b[2] * p[2]).abs()) * gamma(7)
    }
}

/// `next_up(x)` where `s > 0`, `next_down(x)` where `s < 0`, else `x`, as one integer step
/// on the bits chosen without branches: the sign of an offset is a coin flip per spawned
/// ray, and the branches of the two calls it replaces cost a light-traced path more than the
/// step itself (`perf`, the spot box). Equal to `next_up`/`next_down` for every finite and
/// infinite `x` (`crates/geom/src/tests.rs`).
#[inline(always)]
pub(crate) fn ulp_step(x: f32, s: f32) -> f32 {
    let b = x.to_bits();
    let (up, down) = (s > 0.0, s < 0.0);
    let neg = b >> 31 == 1;
    // Away from zero the magnitude's bits grow by one, towards zero they shrink by one.
    let away = (up & !neg) | (down & neg);
    let delta = if away { 1 } else { u32::MAX };
    let stepped = b.wrapping_add(if up | down { delta } else { 0 });
    // A zero steps to the smallest subnormal of the step's sign; an infinity moving away
    // from zero stays.
    let zero = b << 1 == 0;
    let inf = b << 1 == 0xff00_0000;
    let to_zero_step = if down { 0x8000_0001 } else { 1 };
    let r = if zero & (up | down) {
        to_zero_step
    } else if inf & away {
        b
    } else {
        stepped
    };
    f32::from_bits(r)
}
