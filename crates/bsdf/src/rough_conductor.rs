//! Rough metal: a GGX microfacet reflector (Cook & Torrance 1982; Walter et al. 2007; pbrt-v4
//! §9.6), Mitsuba 3's `roughconductor`.

use crate::microfacet::TrowbridgeReitz;
use crate::optics::fresnel_conductor;
use crate::{BsdfSample, Flags, reflect, same_hemisphere};
use glam::Vec3;

/// `f = reflectance · F · D · G / (4 |cos θo| |cos θi|)` on `wo`'s side. `F` is the exact
/// conductor Fresnel term at the microfacet when `eta = Some((η, k))` is given, else 1 (Mitsuba's
/// `material = "none"` with `specular_reflectance`). Both sides reflect, as a Lambertian does:
/// directions are mirrored to `wo`'s side first. `alpha` is clamped to
/// [`crate::microfacet::MIN_ALPHA`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RoughConductor {
    pub alpha: f32,
    pub reflectance: Vec3,
    pub eta: Option<(Vec3, Vec3)>,
}

/// `w` mirrored to the upper side (z only: reflection about the tangent plane, which keeps
/// every angle a microfacet model depends on).
#[inline]
fn upper(w: Vec3) -> Vec3 {
    Vec3::new(w.x, w.y, w.z.abs())
}

impl RoughConductor {
    #[inline]
    pub(crate) fn distribution(&self) -> TrowbridgeReitz {
        TrowbridgeReitz::new(self.alpha)
    }

    #[inline]
    fn fresnel(&self, cos: f32) -> Vec3 {
        match self.eta {
            Some((eta, k)) => fresnel_conductor(cos, eta, k),
            None => Vec3::ONE,
        }
    }

    /// Half vector of two directions above the surface, or `None` when they cancel.
    #[inline]
    fn half(wo: Vec3, wi: Vec3) -> Option<Vec3> {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return None;
        }
        (wo + wi).try_normalize()
    }

    pub fn f(&self, wo: Vec3, wi: Vec3) -> Vec3 {
        if !same_hemisphere(wo, wi) {
            return Vec3::ZERO;
        }
        let (wo, wi) = (upper(wo), upper(wi));
        let Some(wm) = Self::half(wo, wi) else {
            return Vec3::ZERO;
        };
        let mf = self.distribution();
        let dg = mf.d(wm) * mf.g(wo, wi, wm) / (4.0 * wo.z * wi.z);
        // F at the microfacet: wo·wm = wi·wm for a half vector, so f stays symmetric.
        self.reflectance * self.fresnel(wo.dot(wm)) * dg
    }

    /// Visible-normal density through the reflection Jacobian `1 / (4 |wo·wm|)` (Walter et al.
    /// 2007, eq. 14): `D_wo(wm) / (4 wo·wm) = G1(wo) D(wm) / (4 cos θo)`.
    pub fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        if !same_hemisphere(wo, wi) {
            return 0.0;
        }
        let (wo, wi) = (upper(wo), upper(wi));
        let Some(wm) = Self::half(wo, wi) else {
            return 0.0;
        };
        let mf = self.distribution();
        mf.visible_pdf(wo, wm) / (4.0 * wo.dot(wm))
    }

    pub fn sample(&self, wo: Vec3, u: [f32; 2]) -> Option<BsdfSample> {
        let below = wo.z < 0.0;
        let wo = upper(wo);
        let mf = self.distribution();
        let wm = mf.sample_visible(wo, u);
        let mut wi = reflect(wo, wm);
        if wi.z <= 0.0 {
            return None;
        }
        let pdf = mf.visible_pdf(wo, wm) / (4.0 * wo.dot(wm));
        let f = self.reflectance
            * self.fresnel(wo.dot(wm))
            * (mf.d(wm) * mf.g(wo, wi, wm) / (4.0 * wo.z * wi.z));
        if !(pdf > 0.0 && pdf.is_finite() && f.is_finite()) {
            return None;
        }
        if below {
            wi.z = -wi.z;
        }
        Some(BsdfSample {
            f,
            wi,
            pdf,
            flags: Flags::GLOSSY_REFLECTION,
            eta: 1.0,
        })
    }
}
