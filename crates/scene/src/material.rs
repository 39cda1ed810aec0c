use glam::Vec3;

/// What a surface does with light. Plain data: the eye and photon passes turn it into BSDFs.
///
/// MTL files map to materials by this table (`load.rs` applies it; the README repeats it).
/// What photonflow cannot draw is refused with an error naming the MTL file, the material
/// and the key; what it approximates is said in one warning line per material and key.
///
/// | MTL | material |
/// |---|---|
/// | `illum 0`, `1`, no `illum` | [`Material::Lambertian`] of `Kd` (a `Ks` is not drawn: warning) |
/// | `illum 2` | Lambertian `Kd`, plus with `Ks > 0` a GGX lobe of reflectance `Ks`, no Fresnel, α = √(2 / (`Ns` + 2)) ([`Material::Glossy`]; `Kd + Ks > 1` in a channel scales both there: warning) |
/// | `illum 3`, `5`, `8` | [`Material::Mirror`] of `Ks` (1 where `Ks` is absent or black); 5's Fresnel and 8's "no ray tracing" are not modelled (warning), nor a `Kd` (warning) |
/// | `illum 4`, `6`, `7`, `9` | [`Material::Dielectric`] of index `Ni` (1.5 where `Ni` <= 1 or absent: warning) and transmittance `Tf` (1 where absent); exact Fresnel (6 and 9 ask otherwise: warning) |
/// | `illum 10` | refused (shadow matte) |
/// | `illum 11` | [`Material::Metal`] of `Ks` (the course's constant-reflectance metal) |
/// | `d < 1` or `Tr > 0` | glass with illum 4, 6, 7, 9, or illum 0-2 with `Ni > 1` (the course's glass); refused on any other surface |
/// | `Ke` | emission (`emission = "ke"`, the default) |
/// | `Ka` | emission with `emission = "ka"` (the course's convention; a `Ke` too is refused), else the ambient colour, which a physically based renderer has no use for |
/// | `Tf` | on glass, the transmittance: a factor on the refracted light at every crossing, each in [0, 1] (out of range: refused); warning elsewhere. Absorption inside glass has no MTL key: the scene file's `absorption` |
/// | `map_Kd` | the diffuse albedo's texture times `Kd` (the texture alone without `Kd`), on illum 0-2 (warning elsewhere); read at the OBJ's `vt`, bilinear, repeated (`Scene::bsdf_at`); a missing or unreadable image, or texture options, refused |
/// | `map_Ks`, `map_d` | refused |
/// | `bump`, `map_Bump`, `map_Ns`, `refl`, `disp`, `decal` | warning: drawn without |
/// | `Pr`, `Pm`, `Ps`, `Pc`, `Pcr`, `aniso`, `anisor`, `map_Pr`, `map_Pm` (PBR extension) | refused |
#[derive(Clone, Debug, PartialEq)]
pub enum Material {
    Lambertian {
        albedo: Vec3,
    },
    Mirror {
        reflectance: Vec3,
    },
    Metal {
        reflectance: Vec3,
    },
    /// Smooth glass of index `ior` ([`bsdf::Dielectric`]): `transmittance` is a factor on
    /// the refracted lobe at every crossing (MTL `Tf`, Mitsuba 3's
    /// `specular_transmittance`), `absorption` the Beer-Lambert coefficient inside, per
    /// scene unit ([`Scene::transmittance_to`](crate::Scene::transmittance_to)).
    Dielectric {
        ior: f32,
        transmittance: Vec3,
        absorption: Vec3,
    },
    /// MTL `illum 2` with `Ks > 0`: Lambertian `albedo` plus a GGX lobe of constant
    /// reflectance `specular` and roughness `alpha` ([`bsdf::Glossy`]).
    Glossy {
        albedo: Vec3,
        specular: Vec3,
        alpha: f32,
    },
    /// A rough metal: GGX of roughness `alpha`, reflectance times the Fresnel term of the
    /// complex index `eta` (`(eta, k)`) where given ([`bsdf::RoughConductor`]).
    RoughConductor {
        reflectance: Vec3,
        alpha: f32,
        eta: Option<(Vec3, Vec3)>,
    },
    /// Rough glass: GGX of roughness `alpha` ([`bsdf::RoughDielectric`]), with the smooth
    /// glass's `transmittance` and `absorption`.
    RoughDielectric {
        ior: f32,
        alpha: f32,
        transmittance: Vec3,
        absorption: Vec3,
    },
}

/// Roughness a microfacet lobe may have: below it the lobe is a mirror in all but name
/// (Mitsuba 3 and pbrt-v4 switch to the smooth model near 1e-4), above it the single-scattering
/// GGX model loses most of its energy.
pub const ALPHA_RANGE: std::ops::RangeInclusive<f32> = 1e-4..=1.0;

impl Material {
    /// Clear smooth glass of index `ior`: no colour, no absorption.
    pub const fn glass(ior: f32) -> Material {
        Material::Dielectric {
            ior,
            transmittance: Vec3::ONE,
            absorption: Vec3::ZERO,
        }
    }

    /// The Beer-Lambert absorption coefficient inside the material (zero but for glass).
    pub fn absorption(&self) -> Vec3 {
        match *self {
            Material::Dielectric { absorption, .. }
            | Material::RoughDielectric { absorption, .. } => absorption,
            _ => Vec3::ZERO,
        }
    }

    /// True for the delta (perfectly specular) materials: photons bounce off them and are
    /// never stored there; a path through them to a diffuse surface is a caustic path.
    pub fn is_specular(&self) -> bool {
        matches!(
            self,
            Material::Mirror { .. } | Material::Metal { .. } | Material::Dielectric { .. }
        )
    }
}
