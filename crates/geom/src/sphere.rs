use crate::float::gamma;
use crate::{Ray, SurfacePoint};
use glam::{DVec3, Vec3};

/// An analytic sphere. Its geometric normal points outwards.
#[derive(Clone, Copy, Debug)]
pub struct Sphere {
    pub center: Vec3,
    pub radius: f32,
    pub material: u32,
}

impl Sphere {
    /// Nearest root in `(0, t_max)`. Solved in f64 with the cancellation-free quadratic
    /// (Numerical Recipes §5.6; pbrt-v4 §6.8.4 discusses the f32 alternative): the
    /// origin offsets from `spawn_ray` are ~1e-7 relative, far above f64 rounding, so a ray
    /// leaving the sphere never finds a positive root at its own origin.
    #[inline]
    pub fn intersect(&self, ray: &Ray) -> Option<f32> {
        let oc = ray.o.as_dvec3() - self.center.as_dvec3();
        let d = ray.d.as_dvec3();
        let r = self.radius as f64;
        let a = d.length_squared();
        let b = oc.dot(d);
        // c = |oc|^2 - r^2 as a product of sums: exact sign near the surface.
        let loc = oc.length();
        let c = (loc - r) * (loc + r);
        // Discriminant via pbrt-v4's form |oc - (b/a) d|: avoids b^2 - ac cancellation for
        // small spheres far away.
        let perp = oc - (b / a) * d;
        let lp = perp.length();
        let disc = a * (r - lp) * (r + lp);
        if disc < 0.0 {
            return None;
        }
        let q = -(b + b.signum() * disc.sqrt());
        let (mut t0, mut t1) = if q == 0.0 { (0.0, 0.0) } else { (q / a, c / q) };
        if t0 > t1 {
            std::mem::swap(&mut t0, &mut t1);
        }
        let t_max = ray.t_max as f64;
        let t = if t0 > 0.0 { t0 } else { t1 };
        if t <= 0.0 || t >= t_max {
            return None;
        }
        Some(t as f32).filter(|t| *t > 0.0)
    }

    /// Surface point for a hit at `t`: re-projected onto the sphere (pbrt-v4 §6.8.5) and
    /// rounded to f32 once, so the error is a rounding of each component plus the
    /// re-projection's few operations. With `uv`, also the hit's parameterisation `(phi / 2pi,
    /// theta / pi)` (else zeros): an atan2 and an acos in f64, which only textured spheres
    /// need.
    #[inline]
    pub fn surface_point(&self, ray: &Ray, t: f32, uv: bool) -> (SurfacePoint, [f32; 2]) {
        let c = self.center.as_dvec3();
        let r = self.radius as f64;
        let ph = ray.o.as_dvec3() + t as f64 * ray.d.as_dvec3() - c;
        let n = ph.normalize_or(DVec3::Y);
        let p = (c + n * r).as_vec3();
        let p_err = gamma(5) * (n * r).abs().as_vec3() + gamma(2) * p.abs();
        let uv = if uv { Sphere::uv(n) } else { [0.0; 2] };
        (
            SurfacePoint {
                p,
                p_err,
                n: n.as_vec3(),
            },
            uv,
        )
    }

    /// `(phi / 2pi, theta / pi)` of the outward unit normal `n`.
    fn uv(n: DVec3) -> [f32; 2] {
        let phi = n.z.atan2(n.x);
        let phi = if phi < 0.0 {
            phi + std::f64::consts::TAU
        } else {
            phi
        };
        let theta = n.y.clamp(-1.0, 1.0).acos();
        [
            (phi / std::f64::consts::TAU) as f32,
            (theta / std::f64::consts::PI) as f32,
        ]
    }
}
