//! The Trowbridge–Reitz (GGX) microfacet distribution (Trowbridge & Reitz 1975; Walter et al.
//! 2007, "Microfacet Models for Refraction through Rough Surfaces"; pbrt-v4 §9.6).
//!
//! Shadowing–masking is Smith's *separable* form `G = G1(wo) G1(wi)` (Walter et al. 2007,
//! eq. 23), not pbrt-v4's height-correlated `1 / (1 + Λ(wo) + Λ(wi))`: Mitsuba 3's
//! `MicrofacetDistribution` uses the separable one, and images are compared against Mitsuba.
//! Sampling draws visible normals (Heitz 2018, "Sampling the GGX Distribution of Visible
//! Normals", JCGT 7(4)), whose density `D_w(wm) = G1(w) max(0, w·wm) D(wm) / cos θ`
//! (Heitz 2014, "Understanding the Masking-Shadowing Function", eq. 38) is what the models'
//! pdfs are built on.

use glam::Vec3;
use math::warp::sample_uniform_disk_concentric;
use std::f32::consts::PI;

/// Smallest roughness used: below it `D` peaks beyond what f32 half vectors resolve. Mitsuba 3
/// clamps to the same 1e-4 (its `MicrofacetDistribution::configure`); a smaller `alpha` is
/// clamped, not mapped to the smooth models, so a material keeps one lobe type.
pub const MIN_ALPHA: f32 = 1e-4;

/// GGX with roughness `alpha_x`, `alpha_y` along the shading frame's x and y axes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TrowbridgeReitz {
    pub alpha_x: f32,
    pub alpha_y: f32,
}

impl TrowbridgeReitz {
    /// Isotropic distribution; `alpha` is clamped to [`MIN_ALPHA`].
    pub fn new(alpha: f32) -> TrowbridgeReitz {
        TrowbridgeReitz::anisotropic(alpha, alpha)
    }

    /// Anisotropic distribution; both roughnesses are clamped to [`MIN_ALPHA`].
    pub fn anisotropic(alpha_x: f32, alpha_y: f32) -> TrowbridgeReitz {
        TrowbridgeReitz {
            alpha_x: alpha_x.max(MIN_ALPHA),
            alpha_y: alpha_y.max(MIN_ALPHA),
        }
    }

    /// Density of microfacet normals per unit projected area, `D(wm)`; 0 for `wm` below the
    /// surface. Written as `1 / (π αx αy (x²/αx² + y²/αy² + z²)²)`, which equals pbrt-v4's
    /// `1 / (π αx αy cos⁴θ (1 + tan²θ (cos²φ/αx² + sin²φ/αy²))²)` (eq. 9.16) without the
    /// tangent's blow-up near grazing.
    #[inline]
    pub fn d(&self, wm: Vec3) -> f32 {
        if wm.z <= 0.0 {
            return 0.0;
        }
        let (x, y) = (wm.x / self.alpha_x, wm.y / self.alpha_y);
        let s = x * x + y * y + wm.z * wm.z;
        let d = 1.0 / (PI * self.alpha_x * self.alpha_y * s * s);
        // Mitsuba zeroes D · cos θ below 1e-20: keeps far-tail values from underflowing in
        // products to denormals and NaN.
        if d * wm.z > 1e-20 { d } else { 0.0 }
    }

    /// `α² tan² θ` of `w` with the roughness projected onto `w`'s azimuth (pbrt-v4 eq. 9.19).
    #[inline]
    fn alpha2_tan2(&self, w: Vec3) -> f32 {
        let (x, y) = (self.alpha_x * w.x, self.alpha_y * w.y);
        (x * x + y * y) / (w.z * w.z)
    }

    /// Smith's auxiliary function `Λ(w) = (sqrt(1 + α² tan²θ) - 1) / 2` (pbrt-v4 eq. 9.19).
    #[inline]
    pub fn lambda(&self, w: Vec3) -> f32 {
        let a2t2 = self.alpha2_tan2(w);
        if !a2t2.is_finite() {
            return f32::INFINITY;
        }
        0.5 * ((1.0 + a2t2).sqrt() - 1.0)
    }

    /// Smith's masking `G1(w, wm) = 1 / (1 + Λ(w))`, written `2 / (1 + sqrt(1 + α² tan²θ))` to
    /// avoid cancellation; 0 when `wm` faces away from `w` relative to the macrosurface (the
    /// back of a microfacet cannot be seen from the front: Walter et al. 2007, eq. 7's χ⁺).
    #[inline]
    pub fn g1(&self, w: Vec3, wm: Vec3) -> f32 {
        if w.dot(wm) * w.z <= 0.0 {
            return 0.0;
        }
        let a2t2 = self.alpha2_tan2(w);
        if !a2t2.is_finite() {
            return 0.0;
        }
        2.0 / (1.0 + (1.0 + a2t2).sqrt())
    }

    /// Separable shadowing–masking `G1(wo, wm) G1(wi, wm)` (Mitsuba 3's `G`).
    #[inline]
    pub fn g(&self, wo: Vec3, wi: Vec3, wm: Vec3) -> f32 {
        self.g1(wo, wm) * self.g1(wi, wm)
    }

    /// Density of [`TrowbridgeReitz::sample_visible`]: `G1(w) |w·wm| D(wm) / |cos θ|`, for `w`
    /// on either side (the sampler is fed `w` flipped to the upper side, and `|w·wm|`,
    /// `|cos θ|` and `G1` are unchanged by that flip).
    #[inline]
    pub fn visible_pdf(&self, w: Vec3, wm: Vec3) -> f32 {
        let cos = w.z.abs();
        if cos == 0.0 {
            return 0.0;
        }
        self.g1(w, wm) * w.dot(wm).abs() * self.d(wm) / cos
    }

    /// A microfacet normal visible from `w` (`w.z > 0`), by Heitz 2018: stretch `w` to the
    /// `α = 1` configuration, where visible normals are the projection of a uniform disk onto
    /// the hemisphere about `w`, squeezed on the half the surface hides; then unstretch. The
    /// disk point comes from the concentric map (pbrt-v4 §9.6.4 does the same), so strata of
    /// `u` stay compact.
    pub fn sample_visible(&self, w: Vec3, u: [f32; 2]) -> Vec3 {
        debug_assert!(w.z > 0.0, "sample_visible needs w above the surface");
        let wh = Vec3::new(self.alpha_x * w.x, self.alpha_y * w.y, w.z).normalize();
        // Orthonormal basis about wh (Heitz 2018, listing 1: T1 in the xy plane).
        let len2 = wh.x * wh.x + wh.y * wh.y;
        let t1 = if len2 > 0.0 {
            Vec3::new(-wh.y, wh.x, 0.0) / len2.sqrt()
        } else {
            Vec3::X
        };
        let t2 = wh.cross(t1);
        let p = sample_uniform_disk_concentric(u);
        // Warp the disk's far half so it covers only the visible part (Heitz 2018, eq. 9).
        let h = (1.0 - p.x * p.x).max(0.0).sqrt();
        let s = 0.5 * (1.0 + wh.z);
        let py = (1.0 - s) * h + s * p.y;
        let pz = (1.0 - p.x * p.x - py * py).max(0.0).sqrt();
        let nh = p.x * t1 + py * t2 + pz * wh;
        Vec3::new(self.alpha_x * nh.x, self.alpha_y * nh.y, nh.z.max(0.0)).normalize()
    }
}
