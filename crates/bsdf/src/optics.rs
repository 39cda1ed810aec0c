//! Geometric optics shared by the specular models: reflection, refraction, Fresnel.
//! Directions point *away* from the surface (pbrt-v4 §9.1 convention).

use glam::Vec3;

/// Mirror `wo` about `n`: `-wo + 2 (wo·n) n` (pbrt-v4 §9.2, eq. 9.1).
#[inline]
pub fn reflect(wo: Vec3, n: Vec3) -> Vec3 {
    -wo + 2.0 * wo.dot(n) * n
}

/// Refract `wi` through a surface with normal `n` and relative index `eta` = n_inside /
/// n_outside, where "outside" is the side `n` points to. If `wi` arrives from the inside the
/// normal and `eta` are flipped, so callers need not orient anything. Returns the transmitted
/// direction and the relative index `etap` actually crossed, or `None` on total internal
/// reflection (pbrt-v4 §9.3.2, eq. 9.4: `wt = -wi/η + (cos θi/η - cos θt) n`).
#[inline]
pub fn refract(wi: Vec3, n: Vec3, eta: f32) -> Option<(Vec3, f32)> {
    let (mut n, mut eta) = (n, eta);
    let mut cos_i = n.dot(wi);
    if cos_i < 0.0 {
        eta = 1.0 / eta;
        cos_i = -cos_i;
        n = -n;
    }
    let sin2_i = (1.0 - cos_i * cos_i).max(0.0);
    let sin2_t = sin2_i / (eta * eta);
    if sin2_t >= 1.0 {
        return None;
    }
    let cos_t = (1.0 - sin2_t).max(0.0).sqrt();
    Some((-wi / eta + (cos_i / eta - cos_t) * n, eta))
}

/// Fresnel reflectances `(R_s, R_p)` of a smooth dielectric interface for the two
/// polarisations, from the angle cosine on the incident side (negative: incident from inside,
/// so `eta` is inverted). Total internal reflection gives `(1, 1)` (pbrt-v4 §9.3.5, eq. 9.6).
#[inline]
pub fn fresnel_dielectric_polarized(cos_theta_i: f32, eta: f32) -> (f32, f32) {
    let (mut cos_i, mut eta) = (cos_theta_i.clamp(-1.0, 1.0), eta);
    if cos_i < 0.0 {
        eta = 1.0 / eta;
        cos_i = -cos_i;
    }
    let sin2_t = (1.0 - cos_i * cos_i) / (eta * eta);
    if sin2_t >= 1.0 {
        return (1.0, 1.0);
    }
    let cos_t = (1.0 - sin2_t).max(0.0).sqrt();
    let r_perp = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    let r_parl = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    (r_perp * r_perp, r_parl * r_parl)
}

/// Unpolarised Fresnel reflectance of a smooth dielectric: the mean of the two polarisations,
/// since light sources here are unpolarised (pbrt-v4 §9.3.5, `FrDielectric`).
#[inline]
pub fn fresnel_dielectric(cos_theta_i: f32, eta: f32) -> f32 {
    let (rs, rp) = fresnel_dielectric_polarized(cos_theta_i, eta);
    0.5 * (rs + rp)
}

/// Unpolarised Fresnel reflectance of a conductor with complex index `eta + i k`, per RGB
/// channel (pbrt-v4 §9.3.6, `FrComplex`: the dielectric formula in complex arithmetic).
/// Incidence is from outside; `|cos θ|` is used.
#[inline]
pub fn fresnel_conductor(cos_theta_i: f32, eta: Vec3, k: Vec3) -> Vec3 {
    let c = cos_theta_i.abs().min(1.0) as f64;
    let fr = |e: f32, k: f32| fresnel_complex(c, Complex::new(e as f64, k as f64)) as f32;
    Vec3::new(fr(eta.x, k.x), fr(eta.y, k.y), fr(eta.z, k.z))
}

fn fresnel_complex(cos_i: f64, eta: Complex) -> f64 {
    let sin2_i = 1.0 - cos_i * cos_i;
    let sin2_t = Complex::real(sin2_i).div(eta.mul(eta));
    let cos_t = Complex::real(1.0).sub(sin2_t).sqrt();
    let ci = Complex::real(cos_i);
    let r_parl = eta.mul(ci).sub(cos_t).div(eta.mul(ci).add(cos_t));
    let r_perp = ci.sub(eta.mul(cos_t)).div(ci.add(eta.mul(cos_t)));
    0.5 * (r_parl.norm() + r_perp.norm())
}

/// Just enough complex arithmetic for `FrComplex`, in f64 so grazing angles keep precision.
#[derive(Clone, Copy, Debug)]
struct Complex {
    re: f64,
    im: f64,
}

impl Complex {
    fn new(re: f64, im: f64) -> Complex {
        Complex { re, im }
    }
    fn real(re: f64) -> Complex {
        Complex { re, im: 0.0 }
    }
    fn add(self, o: Complex) -> Complex {
        Complex::new(self.re + o.re, self.im + o.im)
    }
    fn sub(self, o: Complex) -> Complex {
        Complex::new(self.re - o.re, self.im - o.im)
    }
    fn mul(self, o: Complex) -> Complex {
        Complex::new(
            self.re * o.re - self.im * o.im,
            self.re * o.im + self.im * o.re,
        )
    }
    fn div(self, o: Complex) -> Complex {
        let d = o.norm();
        Complex::new(
            (self.re * o.re + self.im * o.im) / d,
            (self.im * o.re - self.re * o.im) / d,
        )
    }
    /// Squared magnitude `|z|²` (pbrt's `pstd::norm`).
    fn norm(self) -> f64 {
        self.re * self.re + self.im * self.im
    }
    /// Principal square root, avoiding cancellation by taking the root of the larger part
    /// first (pbrt-v4 `pstd::sqrt(complex)`).
    fn sqrt(self) -> Complex {
        let n = self.norm().sqrt();
        if n == 0.0 {
            return Complex::real(0.0);
        }
        let t1 = (0.5 * (n + self.re.abs())).sqrt();
        let t2 = 0.5 * self.im / t1;
        if self.re >= 0.0 {
            Complex::new(t1, t2)
        } else {
            Complex::new(t2.abs(), t1.copysign(self.im))
        }
    }
}

/// Diffuse Fresnel reflectance `F_dr(η)`: the fraction of uniform (cosine-weighted) incident
/// light a smooth interface of relative index `eta` reflects, `2 ∫ F(μ) μ dμ`. By the two fits
/// Mitsuba 3's `fresnel_diffuse_reflectance` uses, so plastics agree with it: Egan &
/// Hilgeman's (1973) polynomial in `η` and `1/η` for `η < 1`, and d'Eon & Irving's quintic in
/// `1/η` (2011, "A Quantized-Diffusion Model for Rendering Translucent Materials") for
/// `η >= 1`; Mitsuba quotes relative errors below 0.6% for indices up to 2.
pub fn fresnel_diffuse_reflectance(eta: f32) -> f32 {
    let inv = 1.0 / eta;
    if eta < 1.0 {
        0.0636 * inv + eta * (eta * -1.4399 + 0.7099) + 0.6681
    } else {
        // Horner form of 0.919317 - 3.4793 x + 6.75335 x² - 7.80989 x³ + 4.98554 x⁴
        // - 1.36881 x⁵, x = 1/η.
        0.919317
            + inv
                * (-3.4793 + inv * (6.75335 + inv * (-7.80989 + inv * (4.98554 + inv * -1.36881))))
    }
}
