//! `bsdf`: how surfaces scatter light, in the local shading frame (z = shading normal).
//!
//! Key decision: a *closed enum* ([`Bsdf`]) over a handful of models, not a trait object. The
//! material set is fixed by the scene format (MTL illum models), so a `match` gives static
//! dispatch, `Copy` values a photon tracer can stash per hit without allocating, and one
//! place to see every model (Mitsuba 3 and pbrt-v4 dispatch over a closed set too, via
//! `TaggedPointer`). Sampling never owns an RNG: callers pass the uniforms (pbrt-v4 §9.1.2).
//!
//! Conventions (pbrt-v4 §9.1): `wo` and `wi` point away from the surface, in the local frame
//! (callers convert with [`math::Frame`]); `f` is RGB; for a delta lobe `pdf` is the discrete
//! probability of having picked that lobe and `f` is set so `f · |cos θi| / pdf` is the
//! throughput factor, so one estimator serves smooth and delta lobes alike.

mod conductor;
mod dielectric;
mod glossy;
mod lambertian;
mod metal;
pub mod microfacet;
mod mirror;
pub mod optics;
mod plastic;
mod rough_conductor;
mod rough_dielectric;
mod rough_plastic;
mod thin_dielectric;

pub use conductor::Conductor;
pub use dielectric::Dielectric;
pub use glossy::Glossy;
pub use lambertian::Lambertian;
pub use metal::Metal;
pub use microfacet::TrowbridgeReitz;
pub use mirror::Mirror;
pub use optics::{
    fresnel_conductor, fresnel_dielectric, fresnel_diffuse_reflectance, reflect, refract,
};
pub use plastic::Plastic;
pub use rough_conductor::RoughConductor;
pub use rough_dielectric::RoughDielectric;
pub use rough_plastic::{COATING_RES, CoatingTable, RoughPlastic};
pub use thin_dielectric::ThinDielectric;

use glam::Vec3;
use std::ops::BitOr;

/// What a path carries. Cameras trace `Radiance`; photons from lights carry `Importance`-like
/// flux. Only refraction's `1/η²` radiance scaling differs: BSDFs with refraction are not
/// symmetric, so the adjoint differs (Veach 1997 §5.2; pbrt-v4 §9.5.2).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum TransportMode {
    Radiance,
    Importance,
}

/// Lobe kind of a sample: reflection or transmission, diffuse, glossy or specular (pbrt-v4
/// §9.1.2's `BxDFFlags`, reduced to what these models produce).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct Flags(u8);

impl Flags {
    pub const REFLECTION: Flags = Flags(1);
    pub const TRANSMISSION: Flags = Flags(2);
    pub const DIFFUSE: Flags = Flags(4);
    pub const SPECULAR: Flags = Flags(8);
    pub const GLOSSY: Flags = Flags(16);
    pub const DIFFUSE_REFLECTION: Flags = Flags(1 | 4);
    pub const SPECULAR_REFLECTION: Flags = Flags(1 | 8);
    pub const SPECULAR_TRANSMISSION: Flags = Flags(2 | 8);
    pub const GLOSSY_REFLECTION: Flags = Flags(1 | 16);
    pub const GLOSSY_TRANSMISSION: Flags = Flags(2 | 16);

    #[inline]
    pub const fn contains(self, other: Flags) -> bool {
        self.0 & other.0 == other.0
    }
    #[inline]
    pub const fn is_reflection(self) -> bool {
        self.contains(Flags::REFLECTION)
    }
    #[inline]
    pub const fn is_transmission(self) -> bool {
        self.contains(Flags::TRANSMISSION)
    }
    #[inline]
    pub const fn is_diffuse(self) -> bool {
        self.contains(Flags::DIFFUSE)
    }
    #[inline]
    pub const fn is_specular(self) -> bool {
        self.contains(Flags::SPECULAR)
    }
    #[inline]
    pub const fn is_glossy(self) -> bool {
        self.contains(Flags::GLOSSY)
    }
}

impl BitOr for Flags {
    type Output = Flags;
    fn bitor(self, rhs: Flags) -> Flags {
        Flags(self.0 | rhs.0)
    }
}

/// A sampled incident direction with its BSDF value and probability.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BsdfSample {
    /// BSDF value (RGB). For delta lobes, chosen so `f · |cos θi| / pdf` is the throughput.
    pub f: Vec3,
    pub wi: Vec3,
    /// Solid-angle density, or for a delta lobe the probability of having chosen it.
    pub pdf: f32,
    pub flags: Flags,
    /// Relative index crossed (`η'`; 1 for reflection), for Russian roulette and `1/η²`
    /// bookkeeping (pbrt-v4 §14.1.4).
    pub eta: f32,
}

impl BsdfSample {
    #[inline]
    pub fn is_specular(&self) -> bool {
        self.flags.is_specular()
    }
    #[inline]
    pub fn is_reflection(&self) -> bool {
        self.flags.is_reflection()
    }
    #[inline]
    pub fn is_transmission(&self) -> bool {
        self.flags.is_transmission()
    }
    /// `f · |cos θi| / pdf`, the factor a path's throughput is multiplied by.
    #[inline]
    pub fn weight(&self) -> Vec3 {
        self.f * self.wi.z.abs() / self.pdf
    }
}

/// A model's Lambertian lobe ([`Bsdf::diffuse_lobe`]): its albedo, the probability with
/// which sampling chooses it, and the rest of the model (`None` when the lobe is all of it).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DiffuseLobe {
    pub albedo: Vec3,
    pub probability: f32,
    pub rest: Option<Bsdf>,
}

/// Every scattering model the renderer knows.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Bsdf {
    Lambertian(Lambertian),
    Mirror(Mirror),
    Metal(Metal),
    Conductor(Conductor),
    Dielectric(Dielectric),
    RoughConductor(RoughConductor),
    RoughDielectric(RoughDielectric),
    Glossy(Glossy),
    Plastic(Plastic),
    RoughPlastic(RoughPlastic),
    ThinDielectric(ThinDielectric),
}

impl Bsdf {
    /// BSDF value for a pair of directions; 0 for delta models, whose value is a Dirac
    /// distribution no pair of directions drawn independently can hit.
    pub fn f(&self, wo: Vec3, wi: Vec3, mode: TransportMode) -> Vec3 {
        // A grazing wo has no hemisphere (pbrt-v4 `BSDF::f`).
        if wo.z == 0.0 {
            return Vec3::ZERO;
        }
        match self {
            Bsdf::Lambertian(b) => b.f(wo, wi),
            Bsdf::RoughConductor(b) => b.f(wo, wi),
            Bsdf::RoughDielectric(b) => b.f(wo, wi, mode),
            Bsdf::Glossy(b) => b.f(wo, wi),
            Bsdf::Plastic(b) => b.f(wo, wi),
            Bsdf::RoughPlastic(b) => b.f(wo, wi),
            Bsdf::Mirror(_)
            | Bsdf::Metal(_)
            | Bsdf::Conductor(_)
            | Bsdf::Dielectric(_)
            | Bsdf::ThinDielectric(_) => Vec3::ZERO,
        }
    }

    /// Solid-angle density of [`Bsdf::sample`] producing `wi`; 0 for delta models.
    pub fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        if wo.z == 0.0 {
            return 0.0;
        }
        match self {
            Bsdf::Lambertian(b) => b.pdf(wo, wi),
            Bsdf::RoughConductor(b) => b.pdf(wo, wi),
            Bsdf::RoughDielectric(b) => b.pdf(wo, wi),
            Bsdf::Glossy(b) => b.pdf(wo, wi),
            Bsdf::Plastic(b) => b.pdf(wo, wi),
            Bsdf::RoughPlastic(b) => b.pdf(wo, wi),
            Bsdf::Mirror(_)
            | Bsdf::Metal(_)
            | Bsdf::Conductor(_)
            | Bsdf::Dielectric(_)
            | Bsdf::ThinDielectric(_) => 0.0,
        }
    }

    /// Sample `wi` given `wo`: `uc` picks a lobe (dielectrics: reflect or refract; glossy and
    /// plastics: diffuse or the specular one), `u` the direction within it. `None` when no direction carries energy.
    pub fn sample(
        &self,
        wo: Vec3,
        uc: f32,
        u: [f32; 2],
        mode: TransportMode,
    ) -> Option<BsdfSample> {
        if wo.z == 0.0 {
            return None;
        }
        let s = match self {
            Bsdf::Lambertian(b) => b.sample(wo, u),
            Bsdf::Mirror(b) => b.sample(wo),
            Bsdf::Metal(b) => b.sample(wo),
            Bsdf::Conductor(b) => b.sample(wo),
            Bsdf::Dielectric(b) => b.sample(wo, uc, mode),
            Bsdf::RoughConductor(b) => b.sample(wo, u),
            Bsdf::RoughDielectric(b) => b.sample(wo, uc, u, mode),
            Bsdf::Glossy(b) => b.sample(wo, uc, u),
            Bsdf::Plastic(b) => b.sample(wo, uc, u),
            Bsdf::RoughPlastic(b) => b.sample(wo, uc, u),
            Bsdf::ThinDielectric(b) => b.sample(wo, uc),
        }?;
        debug_assert!(s.pdf > 0.0 && s.f.is_finite(), "bad sample {s:?}");
        Some(s)
    }

    /// True when every lobe is a delta: light sampling cannot help, skip next-event estimation.
    /// [`Plastic`] is not: its coating's reflection is a delta, its base is not, so it may
    /// return specular samples while `f` and `pdf` describe its diffuse lobe.
    pub fn is_delta(&self) -> bool {
        matches!(
            self,
            Bsdf::Mirror(_)
                | Bsdf::Metal(_)
                | Bsdf::Conductor(_)
                | Bsdf::Dielectric(_)
                | Bsdf::ThinDielectric(_)
        )
    }

    /// True when the only lobe is Lambertian: where photons are stored and density estimation
    /// is used. A [`Glossy`] surface has a diffuse part too: see [`Bsdf::diffuse_albedo`].
    pub fn is_diffuse(&self) -> bool {
        matches!(self, Bsdf::Lambertian(_))
    }

    /// [`Bsdf::sample`], but for the models that sum a diffuse and a glossy lobe one lobe
    /// alone ([`Glossy::sample_lobe`], [`RoughPlastic::sample_lobe`]); the flag is true when
    /// the lobe sampled is diffuse (a Lambertian model's always), and the last value is the
    /// whole BSDF's density of `wi` (what MIS weighs), which only those models have to
    /// evaluate apart ([`Plastic`]'s lobes never overlap: one is a delta).
    pub fn sample_lobe(
        &self,
        wo: Vec3,
        uc: f32,
        u: [f32; 2],
        mode: TransportMode,
    ) -> Option<(BsdfSample, bool, f32)> {
        match self {
            Bsdf::Glossy(g) if wo.z != 0.0 => g
                .sample_lobe(wo, uc, u)
                .map(|(s, diffuse)| (s, diffuse, g.pdf(wo, s.wi))),
            Bsdf::RoughPlastic(p) if wo.z != 0.0 => p
                .sample_lobe(wo, uc, u)
                .map(|(s, diffuse)| (s, diffuse, p.pdf(wo, s.wi))),
            _ => self
                .sample(wo, uc, u, mode)
                .map(|s| (s, s.flags.is_diffuse(), s.pdf)),
        }
    }

    /// Albedo of the Lambertian lobe, if the model has one (Lambertian, Glossy's base, the
    /// plastics' base under their coating).
    pub fn diffuse_albedo(&self) -> Option<Vec3> {
        match self {
            Bsdf::Lambertian(b) => Some(b.albedo),
            Bsdf::Glossy(b) => Some(b.albedo),
            Bsdf::Plastic(b) => Some(b.diffuse),
            Bsdf::RoughPlastic(b) => Some(b.diffuse),
            _ => None,
        }
    }

    /// The model's Lambertian lobe as photon estimates split it off, seen from `wo` (local
    /// frame): Lambertian: the whole model; Glossy: its base, chosen with its sampling
    /// probability beside the GGX lobe; the plastics: their base seen through the coating
    /// ([`Plastic::diffuse_lobe`], [`RoughPlastic::diffuse_lobe`]), the coating's reflection
    /// the rest. `None` for models without one. Eye and photon passes ask this rather than
    /// match on the model, so a new model with a diffuse part is one arm here.
    pub fn diffuse_lobe(&self, wo: Vec3) -> Option<DiffuseLobe> {
        match self {
            Bsdf::Lambertian(b) => Some(DiffuseLobe {
                albedo: b.albedo,
                probability: 1.0,
                rest: None,
            }),
            Bsdf::Glossy(g) => Some(DiffuseLobe {
                albedo: g.albedo,
                probability: g.diffuse_probability(),
                rest: Some(g.specular_lobe().into()),
            }),
            Bsdf::Plastic(p) => Some(p.diffuse_lobe(wo)),
            Bsdf::RoughPlastic(p) => Some(p.diffuse_lobe(wo)),
            _ => None,
        }
    }

    /// The relative index of refraction of smooth glass (a delta dielectric), `None` for every
    /// other model: SPPM splits its visible points there by Fresnel branch, and photon
    /// differentials refract through it. A thin slab is glass of index 1 here: it reflects
    /// and transmits by its own Fresnel sum but bends nothing.
    pub fn glass_eta(&self) -> Option<f32> {
        match self {
            Bsdf::Dielectric(d) => Some(d.eta),
            Bsdf::ThinDielectric(_) => Some(1.0),
            _ => None,
        }
    }

    /// The same model with its Lambertian lobe's albedo replaced (a texture's value at a
    /// surface point); models without one are returned as they are.
    pub fn with_diffuse_albedo(self, albedo: Vec3) -> Bsdf {
        match self {
            Bsdf::Lambertian(_) => Bsdf::Lambertian(Lambertian { albedo }),
            Bsdf::Glossy(g) => Bsdf::Glossy(Glossy { albedo, ..g }),
            Bsdf::Plastic(p) => Bsdf::Plastic(Plastic {
                diffuse: albedo,
                ..p
            }),
            Bsdf::RoughPlastic(p) => Bsdf::RoughPlastic(RoughPlastic {
                diffuse: albedo,
                ..p
            }),
            other => other,
        }
    }

    /// True for a model with a microfacet (glossy) lobe.
    pub fn is_glossy(&self) -> bool {
        self.roughness().is_some()
    }

    /// GGX `alpha` of the microfacet lobe as evaluated (clamped to [`microfacet::MIN_ALPHA`]),
    /// `None` for models without one.
    pub fn roughness(&self) -> Option<f32> {
        let alpha = match self {
            Bsdf::RoughConductor(b) => b.alpha,
            Bsdf::RoughDielectric(b) => b.alpha,
            Bsdf::Glossy(b) => b.alpha,
            Bsdf::RoughPlastic(b) => b.alpha,
            _ => return None,
        };
        Some(TrowbridgeReitz::new(alpha).alpha_x)
    }

    pub fn has_transmission(&self) -> bool {
        matches!(
            self,
            Bsdf::Dielectric(_) | Bsdf::RoughDielectric(_) | Bsdf::ThinDielectric(_)
        )
    }
}

macro_rules! impl_from {
    ($($t:ident),*) => {$(
        impl From<$t> for Bsdf {
            fn from(b: $t) -> Bsdf {
                Bsdf::$t(b)
            }
        }
    )*};
}
impl_from!(
    Lambertian,
    Mirror,
    Metal,
    Conductor,
    Dielectric,
    RoughConductor,
    RoughDielectric,
    Glossy,
    Plastic,
    RoughPlastic,
    ThinDielectric
);

/// Both directions on the same side of the surface (local frame).
#[inline]
pub(crate) fn same_hemisphere(a: Vec3, b: Vec3) -> bool {
    a.z * b.z > 0.0
}

/// Delta reflection about +z scaled by `r`: `f = r / |cos θi|` with pdf 1, so the throughput
/// is exactly `r` (pbrt-v4 §9.3, `ConductorBxDF` smooth case).
#[inline]
pub(crate) fn specular_reflection(wo: Vec3, r: Vec3) -> BsdfSample {
    let wi = Vec3::new(-wo.x, -wo.y, wo.z);
    BsdfSample {
        f: r / wi.z.abs(),
        wi,
        pdf: 1.0,
        flags: Flags::SPECULAR_REFLECTION,
        eta: 1.0,
    }
}

#[cfg(test)]
mod tests;
