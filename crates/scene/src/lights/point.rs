//! Point and spot lights (pbrt-v4 §12.1, §12.2; Mitsuba 3's `point` and `spot`): delta
//! lights at a position. No ray hits one, so next-event estimation alone reaches them (no
//! MIS weight) and paths from them through specular surfaces to a diffuse one are found only
//! by photons.

use geom::{Ray, SurfacePoint};
use glam::{DVec3, Vec3};
use math::Frame;
use math::warp::sample_uniform_sphere;

/// A point light: intensity `I` (W/sr per channel) in every direction.
#[derive(Clone, Copy, Debug)]
pub struct PointLight {
    pub position: Vec3,
    pub intensity: Vec3,
}

/// A spot light: intensity `I` on its axis, Mitsuba 3's falloff across its cone. Angles in
/// radians, `0 <= beam <= cutoff <= π/2`.
#[derive(Clone, Copy, Debug)]
pub struct SpotLight {
    pub position: Vec3,
    pub intensity: Vec3,
    /// `n` is the axis (towards `look_at`).
    pub frame: Frame,
    pub cutoff: f32,
    pub beam: f32,
}

impl PointLight {
    /// `4π I` (pbrt-v4 §12.1), f64.
    pub fn power(&self) -> DVec3 {
        delta_power(2.0, self.intensity)
    }

    /// A photon uniform over the sphere: it carries `I / (pdf_dir p_i N)`, whose mean is
    /// `Φ_i / (p_i N)` (pbrt-v4 §12.1 `SampleLe`).
    pub fn emit(&self, u_dir: [f32; 2], pmf: f64, photons: u64) -> (Ray, SurfacePoint, DVec3) {
        let d = sample_uniform_sphere(u_dir);
        let pdf_dir = 0.25 / std::f64::consts::PI;
        let flux = self.intensity.as_dvec3() / (pdf_dir * pmf * photons as f64);
        (Ray::new(self.position, d), at(self.position), flux)
    }
}

impl SpotLight {
    /// Mitsuba 3's falloff: 1 within `beam` of the axis, linear in angle down to 0 at
    /// `cutoff`, 0 beyond. `local_z` is cos θ of a unit direction.
    pub fn falloff(&self, local_z: f32) -> f32 {
        if local_z <= self.cutoff.cos() {
            0.0
        } else if local_z >= self.beam.cos() {
            1.0
        } else {
            ((self.cutoff - local_z.clamp(-1.0, 1.0).acos()) / (self.cutoff - self.beam))
                .clamp(0.0, 1.0)
        }
    }

    /// `∫ falloff dω / 2π = ∫₀^c falloff(θ) sin θ dθ`, in closed form: `1 - cos β` inside the
    /// beam plus `∫_β^c (c - θ)/(c - β) sin θ dθ = cos β - (sin c - sin β)/(c - β)` across
    /// the ramp, `1 - (sin c - sin β)/(c - β)` in all (`1 - cos c` when `β = c`).
    pub fn solid_angle_fraction(&self) -> f64 {
        let (c, b) = (self.cutoff as f64, self.beam as f64);
        if c - b < 1e-9 {
            1.0 - c.cos()
        } else {
            1.0 - (c.sin() - b.sin()) / (c - b)
        }
    }

    /// `2π I ∫ falloff sin θ dθ` (pbrt-v4 §12.2), f64.
    pub fn power(&self) -> DVec3 {
        delta_power(self.solid_angle_fraction(), self.intensity)
    }

    /// Intensity towards unit direction `w` (leaving the light).
    pub fn intensity_towards(&self, w: Vec3) -> Vec3 {
        self.intensity * self.falloff(self.frame.n.dot(w))
    }

    /// Solid angle of the cutoff cone, where photons leave.
    pub fn cone(&self) -> f64 {
        std::f64::consts::TAU * (1.0 - (self.cutoff as f64).cos())
    }

    /// A photon uniform in the cutoff cone, weighted by the falloff (Mitsuba 3's
    /// `sample_ray`): `I falloff / (pdf_dir p_i N)`, mean `Φ_i / (p_i N)`.
    pub fn emit(&self, u_dir: [f32; 2], pmf: f64, photons: u64) -> (Ray, SurfacePoint, DVec3) {
        let cos_c = self.cutoff.cos();
        let z = 1.0 - u_dir[0] * (1.0 - cos_c);
        let r = (1.0 - z * z).max(0.0).sqrt();
        let phi = std::f32::consts::TAU * u_dir[1];
        let local = Vec3::new(r * phi.cos(), r * phi.sin(), z);
        let pdf_dir = 1.0 / (std::f64::consts::TAU * (1.0 - cos_c as f64));
        let d = self.frame.to_world(local).normalize();
        let flux = self.intensity_towards(d).as_dvec3() / (pdf_dir * pmf * photons as f64);
        (Ray::new(self.position, d), at(self.position), flux)
    }
}

/// `2π frac I`: a point light's `frac` is 2 (the whole sphere).
fn delta_power(frac: f64, intensity: Vec3) -> DVec3 {
    2.0 * std::f64::consts::PI * frac * intensity.as_dvec3()
}

/// A delta light's position as a surface point: exact (no error bound); `n` is meaningless.
pub(super) fn at(p: Vec3) -> SurfacePoint {
    SurfacePoint {
        p,
        p_err: Vec3::ZERO,
        n: Vec3::Z,
    }
}

/// Next-event estimation towards a delta light at `position` whose intensity towards a unit
/// direction is `intensity`: irradiance-like `I falloff / r²` over the choice probability
/// (pbrt-v4 §12.1's `SampleLi`), since no density in solid angle exists.
pub(super) fn sample_li(
    position: Vec3,
    intensity: impl Fn(Vec3) -> Vec3,
    from: Vec3,
) -> Option<(SurfacePoint, Vec3, Vec3, f32)> {
    let to = position - from;
    let dist2 = to.length_squared();
    if dist2 <= 0.0 || !dist2.is_finite() {
        return None;
    }
    let dist = dist2.sqrt();
    let wi = to / dist;
    let le = intensity(-wi) / dist2;
    if le == Vec3::ZERO || !le.is_finite() {
        return None;
    }
    Some((at(position), le, wi, dist))
}
