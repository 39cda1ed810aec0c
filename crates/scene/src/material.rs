use glam::Vec3;

/// What a surface does with light. Plain data: the eye and photon passes turn it into BSDFs.
///
/// MTL mapping (the course framework's conventions; `load.rs` applies it): `Kd` → [`Material::Lambertian`];
/// `illum 3` → [`Material::Mirror`] with `Ks`; `illum 4`, `6`, `7`, or `Ni > 1` on a
/// transparent (`d < 1`) material → [`Material::Dielectric`] with `Ni`; `illum 11` →
/// [`Material::Metal`] with reflectance `Ks` (the course's constant-reflectance model).
#[derive(Clone, Debug, PartialEq)]
pub enum Material {
    Lambertian { albedo: Vec3 },
    Mirror { reflectance: Vec3 },
    Metal { reflectance: Vec3 },
    Dielectric { ior: f32 },
}

impl Material {
    /// True for the delta (perfectly specular) materials: photons bounce off them and are
    /// never stored there; a path through them to a diffuse surface is a caustic path.
    pub fn is_specular(&self) -> bool {
        !matches!(self, Material::Lambertian { .. })
    }
}
