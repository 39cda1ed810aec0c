//! An emissive triangle (pbrt-v4 §12.3's `DiffuseAreaLight` over one triangle): uniform
//! radiance `le` from its front side only, sampled uniformly over its area (Heitz's triangle
//! map, pbrt-v4 §6.5.4), photons cosine-weighted about its normal (Malley's method, Jensen
//! 2001 §5.1).

use geom::{Ray, SurfacePoint};
use glam::{DVec3, Vec3};
use math::Frame;
use math::warp::{sample_cosine_hemisphere, sample_uniform_triangle};

/// Photon differentials clamp the emission cosine here: a grazing photon's direction cell
/// `π / (N cos θ)` would otherwise grow without bound (its flux is `cos`-weighted anyway).
pub const MIN_EMIT_COS: f32 = 0.05;

/// One emissive triangle as loading finds it in the mesh. Emission is one-sided, towards
/// `normal`.
#[derive(Clone, Debug, PartialEq)]
pub struct AreaLight {
    pub triangle: u32,
    pub area: f32,
    /// Emitted radiance.
    pub le: Vec3,
    /// Unit normal of the emitting side.
    pub normal: Vec3,
    /// Emitted power `pi * area * le` of a Lambertian emitter.
    pub power: Vec3,
}

/// An emissive triangle ready for sampling.
#[derive(Clone, Copy, Debug)]
pub struct TriangleLight {
    pub vertices: [Vec3; 3],
    pub normal: Vec3,
    pub area: f32,
    pub le: Vec3,
    /// Frame about the emitting normal (photon directions).
    pub frame: Frame,
}

impl TriangleLight {
    pub fn new(vertices: [Vec3; 3], l: &AreaLight) -> TriangleLight {
        TriangleLight {
            vertices,
            normal: l.normal,
            area: l.area,
            le: l.le,
            frame: Frame::from_z(l.normal),
        }
    }

    /// `π A Le` in f64 from the scene's f32 area and radiance (no f32 rounding of the product).
    pub fn power(&self) -> DVec3 {
        std::f64::consts::PI * self.area as f64 * self.le.as_dvec3()
    }

    /// Radiance a ray travelling along `d` receives from the triangle: zero from its back.
    pub fn le(&self, d: Vec3) -> Vec3 {
        if d.dot(self.normal) < 0.0 {
            self.le
        } else {
            Vec3::ZERO
        }
    }

    /// The point `u` picks, uniform over the area, with its error bound.
    pub fn sample_point(&self, u: [f32; 2]) -> SurfacePoint {
        let v = self.vertices;
        let b = sample_uniform_triangle(u);
        SurfacePoint {
            p: b.x * v[0] + b.y * v[1] + b.z * v[2],
            p_err: SurfacePoint::barycentric_error(b.to_array(), v),
            n: self.normal,
        }
    }

    /// Solid-angle density of a point `to` on the triangle seen from `from` when the light is
    /// chosen with probability `pmf`: `pmf / A · r² / cos θ_light`, zero from behind.
    pub fn pdf(&self, pmf: f64, from: Vec3, to: Vec3) -> f32 {
        let d = to - from;
        let dist2 = d.length_squared();
        if dist2 <= 0.0 || !dist2.is_finite() {
            return 0.0;
        }
        let cos_light = -d.dot(self.normal) / dist2.sqrt();
        if cos_light <= 0.0 || cos_light.is_nan() {
            return 0.0;
        }
        pmf as f32 / self.area * dist2 / cos_light
    }

    /// Next-event estimation: `(point, le, wi, dist, pdf)`, `None` where the point cannot light
    /// `from` (its back, its plane).
    pub fn sample_li(
        &self,
        pmf: f64,
        from: Vec3,
        u: [f32; 2],
    ) -> Option<(SurfacePoint, Vec3, Vec3, f32, f32)> {
        let point = self.sample_point(u);
        let to = point.p - from;
        let dist2 = to.length_squared();
        if dist2 <= 0.0 || !dist2.is_finite() {
            return None;
        }
        let dist = dist2.sqrt();
        let wi = to / dist;
        let cos_light = -wi.dot(self.normal);
        if cos_light <= 0.0 || cos_light.is_nan() {
            return None;
        }
        let pdf = pmf as f32 / self.area * dist2 / cos_light;
        if !(pdf.is_finite() && pdf > 0.0) {
            return None;
        }
        Some((point, self.le, wi, dist, pdf))
    }

    /// A photon: the point `u_pos` picks, a direction cosine-weighted about the normal; it
    /// carries the light's share `flux` (`Φ_i / (p_i N)`).
    pub fn emit(&self, u_pos: [f32; 2], u_dir: [f32; 2]) -> (Ray, SurfacePoint) {
        let point = self.sample_point(u_pos);
        let d = self
            .frame
            .to_world(sample_cosine_hemisphere(u_dir))
            .normalize();
        (point.spawn_ray(d), point)
    }

    /// The cells a photon leaving along `d` owns (see [`crate::Spread`]): the point has area
    /// density `p_i / A_i`, so its cell is `A_i / (p_i N)` and `ρ_x = sqrt(A_i / (π p_i N))`
    /// along the light's tangents; the cosine-weighted direction (pdf `cos θ / π`) has the
    /// cell `π / (N cos θ)`, so `ρ_ω = sqrt(1 / (N cos θ))`, `cos θ` clamped to
    /// [`MIN_EMIT_COS`]. `n` is the photon count `N` and `pmf` the light's `p_i`.
    pub fn spread(&self, d: Vec3, pmf: f64, n: f64) -> (Frame, f64, f64) {
        let cell = self.area as f64 / (pmf * n);
        let rho_x = (cell / std::f64::consts::PI).sqrt();
        let cos = d.dot(self.frame.n).max(MIN_EMIT_COS) as f64;
        let rho_w = (1.0 / (n * cos)).sqrt();
        (self.frame, rho_x, rho_w)
    }
}
