use glam::Vec3;

/// What a surface does with light. Plain data: the eye and photon passes turn it into BSDFs.
///
/// MTL files map to materials by the table in `load/mtl.rs`, its one statement.
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
    /// A polished metal ([`bsdf::Conductor`]): `reflectance` times the Fresnel term of the
    /// complex index `(eta, k)` where given, else times 1 (Mitsuba 3's `material = "none"`).
    Conductor {
        reflectance: Vec3,
        eta: Option<(Vec3, Vec3)>,
    },
    /// A diffuse base under a smooth coating of relative index `ior` ([`bsdf::Plastic`]).
    Plastic {
        diffuse: Vec3,
        specular: Vec3,
        ior: f32,
        nonlinear: bool,
    },
    /// A diffuse base under a GGX coating ([`bsdf::RoughPlastic`]).
    RoughPlastic {
        diffuse: Vec3,
        specular: Vec3,
        ior: f32,
        alpha: f32,
        nonlinear: bool,
    },
    /// A thin slab of relative index `ior` ([`bsdf::ThinDielectric`]).
    ThinDielectric {
        ior: f32,
        reflectance: Vec3,
        transmittance: Vec3,
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

    /// True for glass that colours or absorbs the light crossing it (a transmittance other
    /// than 1 or an absorption other than 0).
    pub fn is_tinted(&self) -> bool {
        match *self {
            Material::Dielectric {
                transmittance,
                absorption,
                ..
            }
            | Material::RoughDielectric {
                transmittance,
                absorption,
                ..
            } => transmittance != Vec3::ONE || absorption != Vec3::ZERO,
            _ => false,
        }
    }

    /// True for the delta (perfectly specular) materials: photons bounce off them and are
    /// never stored there; a path through them to a diffuse surface is a caustic path. A
    /// plastic is not: its coating's reflection is a delta, but photons are stored on its
    /// base, and a path reflected by its coating is the path tracer's, as a glossy one is.
    pub fn is_specular(&self) -> bool {
        matches!(
            self,
            Material::Mirror { .. }
                | Material::Metal { .. }
                | Material::Dielectric { .. }
                | Material::Conductor { .. }
                | Material::ThinDielectric { .. }
        )
    }
}
