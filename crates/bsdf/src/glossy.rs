//! The MTL `illum 2` model: a Lambertian base plus a GGX highlight.

use crate::lambertian::Lambertian;
use crate::rough_conductor::RoughConductor;
use crate::{BsdfSample, Flags};
use glam::Vec3;

/// `f = albedo / π + specular · D · G / (4 |cos θo cos θi|)`: the *sum* of a Lambertian lobe and a
/// GGX lobe of constant reflectance with no Fresnel term (a [`RoughConductor`] with `eta: None`),
/// reflecting on `wo`'s side. Not a convex blend, so `albedo + specular` may reach 1 per channel
/// (then it conserves energy up to GGX's own single-scattering loss).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Glossy {
    pub albedo: Vec3,
    pub specular: Vec3,
    pub alpha: f32,
}

impl Glossy {
    /// From MTL `Kd`, `Ks`, `Ns`: `alpha = sqrt(2 / (Ns + 2))`, Walter et al. 2007's Phong
    /// correspondence `Ns = 2 / α² - 2` solved for `α` (`Ns < 0` is read as 0).
    /// Where `Kd + Ks > 1` in a channel both are divided by their sum there, so the surface
    /// cannot reflect more than it receives; the flag says so, for the caller to warn.
    pub fn from_mtl(kd: Vec3, ks: Vec3, ns: f32) -> (Glossy, bool) {
        let sum = kd + ks;
        let scale = Vec3::select(sum.cmpgt(Vec3::ONE), sum.recip(), Vec3::ONE);
        let scaled = scale != Vec3::ONE;
        let alpha = (2.0 / (ns.max(0.0) + 2.0)).sqrt();
        (
            Glossy {
                albedo: kd * scale,
                specular: ks * scale,
                alpha,
            },
            scaled,
        )
    }

    #[inline]
    fn diffuse(&self) -> Lambertian {
        Lambertian {
            albedo: self.albedo,
        }
    }

    /// The GGX lobe alone: what photon estimates, which read diffuse lobes only, leave to
    /// be followed as a path.
    #[inline]
    pub fn specular_lobe(&self) -> RoughConductor {
        RoughConductor {
            alpha: self.alpha,
            reflectance: self.specular,
            eta: None,
        }
    }

    /// Probability of sampling the diffuse lobe: its share of the mean reflectances (one-sample
    /// MIS with the balance heuristic over lobes, Veach 1997 §9.2.4), 1/2 if both are black.
    pub fn diffuse_probability(&self) -> f32 {
        let (d, s) = (
            self.albedo.element_sum() / 3.0,
            self.specular.element_sum() / 3.0,
        );
        if d + s > 0.0 { d / (d + s) } else { 0.5 }
    }

    pub fn f(&self, wo: Vec3, wi: Vec3) -> Vec3 {
        self.diffuse().f(wo, wi) + self.specular_lobe().f(wo, wi)
    }

    pub fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        let pd = self.diffuse_probability();
        pd * self.diffuse().pdf(wo, wi) + (1.0 - pd) * self.specular_lobe().pdf(wo, wi)
    }

    /// One lobe, picked by `uc` with [`Glossy::diffuse_probability`], weighted by it alone:
    /// `f` is that lobe's and `pdf` its density times the probability of picking it, so the
    /// weight estimates that lobe's share and the two shares sum to the whole BSDF. The flag
    /// is true for the diffuse lobe. Callers that must tell a diffuse-lobe path from a
    /// glossy one use this (the path tracer's split with photon splatting).
    pub fn sample_lobe(&self, wo: Vec3, uc: f32, u: [f32; 2]) -> Option<(BsdfSample, bool)> {
        let pd = self.diffuse_probability();
        if uc < pd {
            let s = self.diffuse().sample(wo, u)?;
            (pd > 0.0).then_some((
                BsdfSample {
                    pdf: s.pdf * pd,
                    ..s
                },
                true,
            ))
        } else {
            let s = self.specular_lobe().sample(wo, u)?;
            let p = s.pdf * (1.0 - pd);
            (p > 0.0).then_some((
                BsdfSample {
                    pdf: p,
                    flags: Flags::GLOSSY_REFLECTION,
                    ..s
                },
                false,
            ))
        }
    }

    /// `uc` picks the lobe; the sample then carries the whole `f` and the mixture pdf, so its
    /// weight is the one-sample MIS estimate over both lobes.
    pub fn sample(&self, wo: Vec3, uc: f32, u: [f32; 2]) -> Option<BsdfSample> {
        let diffuse = uc < self.diffuse_probability();
        let s = if diffuse {
            self.diffuse().sample(wo, u)
        } else {
            self.specular_lobe().sample(wo, u)
        }?;
        let pdf = self.pdf(wo, s.wi);
        if pdf <= 0.0 {
            return None;
        }
        Some(BsdfSample {
            f: self.f(wo, s.wi),
            pdf,
            flags: if diffuse {
                Flags::DIFFUSE_REFLECTION
            } else {
                Flags::GLOSSY_REFLECTION
            },
            ..s
        })
    }
}
