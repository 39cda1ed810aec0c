//! Smooth plastic: a diffuse base under a smooth dielectric coating, Mitsuba 3's `plastic`,
//! its internal scattering summed in closed form.

use crate::optics::{fresnel_dielectric, fresnel_diffuse_reflectance};
use crate::{BsdfSample, DiffuseLobe, Flags, same_hemisphere};
use glam::Vec3;
use math::warp::sample_cosine_hemisphere;
use std::f32::consts::FRAC_1_PI;

/// A Lambertian base of reflectance `diffuse` under a smooth coating of relative index `eta`
/// (n_coating / n_outside). Two lobes:
///
/// - specular: a delta reflection off the coating, `F(cos θo) · specular`;
/// - diffuse: light refracted in, scattered by the base, bounced between base and coating
///   (the coating reflects the fraction `F_dr(1/η)` of the diffuse light reaching it from
///   inside, [`fresnel_diffuse_reflectance`]), refracted out:
///   `f = (1 - F(cos θo)) (1 - F(cos θi)) ρ' / (π η²)`, where `ρ' = ρ / (1 - F_dr(1/η))`, or
///   `ρ / (1 - ρ F_dr(1/η))` when `nonlinear` (the geometric series of internal bounces with
///   the base's albedo in each term, which darkens and saturates colours as wet surfaces do).
///   `1/η²` is the radiance compression of entering the coating and leaving it.
///
/// Sampling picks the specular lobe with probability `F w / (F w + (1 - F)(1 - w))`, `F` the
/// Fresnel reflectance at `wo` and `w` = [`Plastic::specular_weight`], else the cosine-sampled
/// diffuse lobe, as Mitsuba does. Unlike Mitsuba's (one-sided) plugin both sides are coated,
/// as every reflector here is two-sided: directions below are mirrored to the upper side.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Plastic {
    pub diffuse: Vec3,
    pub specular: Vec3,
    pub eta: f32,
    pub nonlinear: bool,
    /// Mitsuba's `specular_sampling_weight`: mean specular / (mean diffuse + mean specular).
    pub specular_weight: f32,
    /// `F_dr(1/η)`, the diffuse reflectance of the coating from inside.
    pub fdr_int: f32,
}

/// `w` mirrored to the upper side.
#[inline]
pub(crate) fn upper(w: Vec3) -> Vec3 {
    Vec3::new(w.x, w.y, w.z.abs())
}

/// Mitsuba's `specular_sampling_weight` (1 when both are black, so sampling stays defined).
#[inline]
pub(crate) fn specular_weight(diffuse: Vec3, specular: Vec3) -> f32 {
    let (d, s) = (diffuse.element_sum() / 3.0, specular.element_sum() / 3.0);
    if d + s > 0.0 { s / (d + s) } else { 1.0 }
}

/// Probability of sampling the coating's lobe given its reflectance `r` at `wo` (Fresnel for
/// the smooth coating, `1 - t` for the rough one) and the sampling weight `w`.
#[inline]
pub(crate) fn coating_probability(r: f32, w: f32) -> f32 {
    let (ps, pd) = (r * w, (1.0 - r) * (1.0 - w));
    if ps + pd > 0.0 { ps / (ps + pd) } else { 1.0 }
}

/// The base's albedo with the internal bounces summed: `ρ / (1 - F_dr)` or, `nonlinear`,
/// `ρ / (1 - ρ F_dr)` (Mitsuba 3's `plastic`, `roughplastic`).
#[inline]
pub(crate) fn internal_albedo(rho: Vec3, fdr_int: f32, nonlinear: bool) -> Vec3 {
    if nonlinear {
        rho / (Vec3::ONE - rho * fdr_int)
    } else {
        rho / (1.0 - fdr_int)
    }
}

impl Plastic {
    /// A plastic of base `diffuse`, coating factor `specular` and relative index `eta`.
    pub fn new(diffuse: Vec3, specular: Vec3, eta: f32, nonlinear: bool) -> Plastic {
        Plastic {
            diffuse,
            specular,
            eta,
            nonlinear,
            specular_weight: specular_weight(diffuse, specular),
            fdr_int: fresnel_diffuse_reflectance(1.0 / eta),
        }
    }

    /// Probability that [`Plastic::sample`] picks the coating's delta reflection at `wo`.
    #[inline]
    pub fn specular_probability(&self, wo: Vec3) -> f32 {
        coating_probability(
            fresnel_dielectric(wo.z.abs(), self.eta),
            self.specular_weight,
        )
    }

    /// The diffuse lobe's `f` (both directions on the upper side).
    #[inline]
    fn diffuse_f(&self, cos_o: f32, cos_i: f32) -> Vec3 {
        let (fo, fi) = (
            fresnel_dielectric(cos_o, self.eta),
            fresnel_dielectric(cos_i, self.eta),
        );
        internal_albedo(self.diffuse, self.fdr_int, self.nonlinear)
            * ((1.0 - fo) * (1.0 - fi) * FRAC_1_PI / (self.eta * self.eta))
    }

    /// The diffuse lobe; the delta reflection is 0 for any pair of directions.
    pub fn f(&self, wo: Vec3, wi: Vec3) -> Vec3 {
        if !same_hemisphere(wo, wi) {
            return Vec3::ZERO;
        }
        self.diffuse_f(wo.z.abs(), wi.z.abs())
    }

    /// The diffuse lobe's density times the probability of picking it.
    pub fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        if !same_hemisphere(wo, wi) {
            return 0.0;
        }
        (1.0 - self.specular_probability(wo)) * wi.z.abs() * FRAC_1_PI
    }

    pub fn sample(&self, wo: Vec3, uc: f32, u: [f32; 2]) -> Option<BsdfSample> {
        let below = wo.z < 0.0;
        let up = upper(wo);
        let fo = fresnel_dielectric(up.z, self.eta);
        let ps = coating_probability(fo, self.specular_weight);
        let (mut wi, f, pdf, flags) = if uc < ps {
            let wi = Vec3::new(-up.x, -up.y, up.z);
            (
                wi,
                self.specular * (fo / wi.z),
                ps,
                Flags::SPECULAR_REFLECTION,
            )
        } else {
            let wi = sample_cosine_hemisphere(u);
            let pdf = (1.0 - ps) * wi.z * FRAC_1_PI;
            (
                wi,
                self.diffuse_f(up.z, wi.z),
                pdf,
                Flags::DIFFUSE_REFLECTION,
            )
        };
        if !(pdf > 0.0 && f.is_finite()) {
            return None;
        }
        if below {
            wi.z = -wi.z;
        }
        Some(BsdfSample {
            f,
            wi,
            pdf,
            flags,
            eta: 1.0,
        })
    }

    /// The diffuse lobe as photon estimates read it: a Lambertian lobe of albedo
    /// `(1 - F(cos θo)) (1 - F_dr(η)) ρ' / η²`, chosen with the sampling's probability, the
    /// coating's reflection (this model with a black base) the rest. The one approximation:
    /// the incident light's Fresnel transmittance `1 - F(cos θi)` is replaced by its cosine-
    /// weighted mean `1 - F_dr(η)`, exact for uniform incident radiance (photon estimates
    /// sum flux regardless of its direction).
    pub fn diffuse_lobe(&self, wo: Vec3) -> DiffuseLobe {
        let fo = fresnel_dielectric(wo.z.abs(), self.eta);
        let fdr_ext = fresnel_diffuse_reflectance(self.eta);
        let albedo = internal_albedo(self.diffuse, self.fdr_int, self.nonlinear)
            * ((1.0 - fo) * (1.0 - fdr_ext) / (self.eta * self.eta));
        DiffuseLobe {
            albedo,
            probability: 1.0 - coating_probability(fo, self.specular_weight),
            rest: Some(self.coating().into()),
        }
    }

    /// The coating's reflection alone: this model with a black base, which always samples it.
    pub fn coating(&self) -> Plastic {
        Plastic {
            diffuse: Vec3::ZERO,
            specular_weight: 1.0,
            ..*self
        }
    }
}
