//! Rough dielectric interface: reflection and refraction through GGX microfacets (Walter et al.
//! 2007; pbrt-v4 §9.7), Mitsuba 3's `roughdielectric` (GGX, visible normals).

use crate::microfacet::TrowbridgeReitz;
use crate::optics::{fresnel_dielectric, reflect, refract};
use crate::{BsdfSample, Flags, TransportMode};
use glam::Vec3;

/// A rough boundary with relative index `eta` = n_inside / n_outside, the inside being the side
/// opposite the shading normal, as for [`crate::Dielectric`]. `alpha` is clamped to
/// [`crate::microfacet::MIN_ALPHA`]. `transmittance` scales the transmitted lobe at every
/// crossing, as [`crate::Dielectric`]'s does (Mitsuba 3's `roughdielectric`
/// `specular_transmittance`); it changes neither the sampling nor the pdf.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RoughDielectric {
    pub eta: f32,
    pub alpha: f32,
    pub transmittance: Vec3,
}

/// The microfacet normal relating `wo` and `wi`, facing +z, and the relative index `η'` crossed
/// (1 for reflection).
struct Geometry {
    wm: Vec3,
    etap: f32,
    reflect: bool,
}

impl RoughDielectric {
    /// Clear rough glass of relative index `eta` and roughness `alpha`.
    pub const fn clear(eta: f32, alpha: f32) -> RoughDielectric {
        RoughDielectric {
            eta,
            alpha,
            transmittance: Vec3::ONE,
        }
    }

    /// The lobe's colour: 1 for reflection, the transmittance for refraction.
    #[inline]
    fn tint(&self, g: &Geometry) -> Vec3 {
        if g.reflect {
            Vec3::ONE
        } else {
            self.transmittance
        }
    }

    #[inline]
    pub(crate) fn distribution(&self) -> TrowbridgeReitz {
        TrowbridgeReitz::new(self.alpha)
    }

    /// Generalized half vector `wm ∝ wo + η' wi` (Walter et al. 2007, eq. 16; pbrt-v4 eq. 9.34),
    /// which for reflection (`η' = 1`) is the usual half vector; `None` for a degenerate or
    /// back-facing configuration.
    fn geometry(&self, wo: Vec3, wi: Vec3) -> Option<Geometry> {
        let (cos_o, cos_i) = (wo.z, wi.z);
        if cos_o == 0.0 || cos_i == 0.0 {
            return None;
        }
        let reflect = cos_o * cos_i > 0.0;
        let etap = match (reflect, cos_o > 0.0) {
            (true, _) => 1.0,
            (false, true) => self.eta,
            (false, false) => 1.0 / self.eta,
        };
        let wm = (wo + etap * wi).try_normalize()?;
        let wm = if wm.z < 0.0 { -wm } else { wm };
        // Both directions must see the microfacet's front from their own side: the χ⁺ terms
        // of G, repeated so the pdf vanishes where f does (pbrt-v4 §9.7.2).
        if wm.dot(wo) * cos_o <= 0.0 || wm.dot(wi) * cos_i <= 0.0 {
            return None;
        }
        Some(Geometry { wm, etap, reflect })
    }

    /// `f` for a known microfacet normal: reflection `F D G / (4 |cos θo cos θi|)`, transmission
    /// `(1 - F) D G |wi·wm wo·wm| / (|cos θo cos θi| (wi·wm + wo·wm / η')²)` (Walter et al.
    /// 2007, eqs. 20–21), divided by `η'²` for radiance (pbrt-v4 §9.5.2).
    fn f_at(&self, wo: Vec3, wi: Vec3, g: &Geometry, mode: TransportMode) -> f32 {
        let mf = self.distribution();
        let (wm, etap) = (g.wm, g.etap);
        let r = fresnel_dielectric(wo.dot(wm), self.eta);
        let dg = mf.d(wm) * mf.g(wo, wi, wm);
        let cos = (wo.z * wi.z).abs();
        if g.reflect {
            return r * dg / (4.0 * cos);
        }
        let denom = wi.dot(wm) + wo.dot(wm) / etap;
        let mut ft = (1.0 - r) * dg * (wi.dot(wm) * wo.dot(wm)).abs() / (cos * denom * denom);
        if mode == TransportMode::Radiance {
            ft /= etap * etap;
        }
        ft
    }

    /// Visible-normal density of `wm` seen from `wo`, times the lobe's Fresnel probability and
    /// the Jacobian `dwm/dwi`: `1 / (4 |wo·wm|)` for reflection, `|wi·wm| / (wi·wm +
    /// wo·wm/η')²` for refraction (Walter et al. 2007, eqs. 14, 17; pbrt-v4 eq. 9.37).
    fn pdf_at(&self, wo: Vec3, wi: Vec3, g: &Geometry) -> f32 {
        let mf = self.distribution();
        let wm = g.wm;
        let r = fresnel_dielectric(wo.dot(wm), self.eta);
        let vis = mf.visible_pdf(wo, wm);
        if g.reflect {
            r * vis / (4.0 * wo.dot(wm).abs())
        } else {
            let denom = wi.dot(wm) + wo.dot(wm) / g.etap;
            (1.0 - r) * vis * wi.dot(wm).abs() / (denom * denom)
        }
    }

    pub fn f(&self, wo: Vec3, wi: Vec3, mode: TransportMode) -> Vec3 {
        match self.geometry(wo, wi) {
            Some(g) => self.tint(&g) * self.f_at(wo, wi, &g, mode),
            None => Vec3::ZERO,
        }
    }

    pub fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        match self.geometry(wo, wi) {
            Some(g) => self.pdf_at(wo, wi, &g),
            None => 0.0,
        }
    }

    /// A visible microfacet normal is drawn for `wo` flipped to the upper side (the whole
    /// vector, so `|wo·wm|` is kept), then `uc` picks reflection with probability `R` of that
    /// microfacet and refraction with `T = 1 - R` (pbrt-v4 §9.7.5).
    pub fn sample(
        &self,
        wo: Vec3,
        uc: f32,
        u: [f32; 2],
        mode: TransportMode,
    ) -> Option<BsdfSample> {
        let mf = self.distribution();
        let up = if wo.z < 0.0 { -wo } else { wo };
        let wm = mf.sample_visible(up, u);
        let r = fresnel_dielectric(wo.dot(wm), self.eta);
        let (wi, flags) = if uc < r {
            (reflect(wo, wm), Flags::GLOSSY_REFLECTION)
        } else {
            // `refract` flips wm and eta itself when wo is on wm's back.
            let (wi, _) = refract(wo, wm, self.eta)?;
            (wi, Flags::GLOSSY_TRANSMISSION)
        };
        // The microfacet can send wi to the wrong macro side: no valid sample (pbrt-v4 §9.7.5).
        let g = self.geometry(wo, wi)?;
        if g.reflect != flags.is_reflection() {
            return None;
        }
        // f and pdf from the recomputed half vector, so a sample agrees with `f` and `pdf`
        // exactly rather than to rounding of wm.
        let f = self.f_at(wo, wi, &g, mode);
        let pdf = self.pdf_at(wo, wi, &g);
        if !(pdf > 0.0 && pdf.is_finite() && f.is_finite()) {
            return None;
        }
        Some(BsdfSample {
            f: self.tint(&g) * f,
            wi,
            pdf,
            flags,
            eta: g.etap,
        })
    }
}
