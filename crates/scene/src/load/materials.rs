//! Materials: the scene file's descriptions, their textures (read once per path), and the
//! checks every material passes whether it came from the scene file or an MTL file.

use super::Builder;
use crate::error::SceneError;
use crate::file::MaterialDesc;
use crate::file::SceneFile;
use crate::material::ALPHA_RANGE;
use crate::material::Material;
use crate::scene::AlbedoMap;
use crate::texture::Texture;
use glam::Vec3;
use std::path::Path;

/// A scene-file material and its emission.
pub(super) fn of_desc(desc: &MaterialDesc) -> (Material, Vec3) {
    match desc {
        MaterialDesc::Lambertian {
            albedo, emission, ..
        } => (
            Material::Lambertian {
                albedo: Vec3::from(*albedo),
            },
            Vec3::from(*emission),
        ),
        MaterialDesc::Mirror { reflectance } => (
            Material::Mirror {
                reflectance: Vec3::from(*reflectance),
            },
            Vec3::ZERO,
        ),
        MaterialDesc::Metal { reflectance } => (
            Material::Metal {
                reflectance: Vec3::from(*reflectance),
            },
            Vec3::ZERO,
        ),
        MaterialDesc::Dielectric {
            ior,
            transmittance,
            absorption,
        } => (
            Material::Dielectric {
                ior: *ior,
                transmittance: Vec3::from(*transmittance),
                absorption: Vec3::from(*absorption),
            },
            Vec3::ZERO,
        ),
        MaterialDesc::Glossy {
            albedo,
            specular,
            alpha,
            ..
        } => (
            Material::Glossy {
                albedo: Vec3::from(*albedo),
                specular: Vec3::from(*specular),
                alpha: *alpha,
            },
            Vec3::ZERO,
        ),
        MaterialDesc::RoughConductor {
            alpha,
            reflectance,
            eta,
            k,
        } => (
            Material::RoughConductor {
                reflectance: Vec3::from(*reflectance),
                alpha: *alpha,
                // Both or neither: `validate_materials` refuses one alone.
                eta: match (eta, k) {
                    (Some(e), Some(k)) => Some((Vec3::from(*e), Vec3::from(*k))),
                    (Some(e), None) => Some((Vec3::from(*e), Vec3::NAN)),
                    (None, Some(k)) => Some((Vec3::NAN, Vec3::from(*k))),
                    (None, None) => None,
                },
            },
            Vec3::ZERO,
        ),
        MaterialDesc::RoughDielectric {
            ior,
            alpha,
            transmittance,
            absorption,
        } => (
            Material::RoughDielectric {
                ior: *ior,
                alpha: *alpha,
                transmittance: Vec3::from(*transmittance),
                absorption: Vec3::from(*absorption),
            },
            Vec3::ZERO,
        ),
    }
}

impl Builder<'_> {
    pub(super) fn add_material(&mut self, name: &str, m: Material, e: Vec3) -> u32 {
        let id = self.materials.len() as u32;
        self.materials.push(m);
        self.names.push(name.to_string());
        self.emission.push(e);
        self.albedo_maps.push(None);
        self.by_name.insert(name.to_string(), id);
        id
    }

    /// Reads the texture at `path` (once per path) and returns its index; `Err` is the
    /// problem, for the caller to name the file that asked for it.
    fn texture(&mut self, path: &Path) -> Result<u32, String> {
        if let Some(&id) = self.texture_ids.get(path) {
            return Ok(id);
        }
        let bytes = super::read_regular(path).map_err(|e| format!("cannot read it: {e}"))?;
        self.hash.write(&bytes);
        let t = Texture::decode(&bytes, path)?;
        let id = self.textures.len() as u32;
        self.textures.push(t);
        self.texture_ids.insert(path.to_path_buf(), id);
        Ok(id)
    }

    /// Gives material `id` the albedo texture at `path`, the material's own albedo becoming
    /// the texture's scale. Only materials with a diffuse lobe take one; for the others the
    /// texture is not drawn. `Ok` holds a warning, if any; `Err` the problem with the image.
    pub(super) fn attach_albedo_map(
        &mut self,
        id: u32,
        path: &Path,
    ) -> Result<Option<String>, String> {
        let Some(m) = self.materials.get(id as usize).cloned() else {
            return Err(format!("internal error: material id {id}"));
        };
        let texture = self.texture(path)?;
        let mut warning = None;
        let scale = match m {
            Material::Lambertian { albedo } => albedo,
            Material::Glossy {
                albedo,
                specular,
                alpha,
            } => {
                // The untextured rule (`Kd + Ks <= 1` per channel, both scaled there where
                // not) over the texture's brightest texel: no point reflects more than it gets.
                let t_max = self
                    .textures
                    .get(texture as usize)
                    .map_or(Vec3::ONE, Texture::max);
                let sum = albedo * t_max + specular;
                let f = Vec3::select(sum.cmpgt(Vec3::ONE), sum.recip(), Vec3::ONE);
                if f != Vec3::ONE {
                    warning = Some(format!(
                        "`Kd` x `map_Kd`'s brightest texel + `Ks` exceeds 1 in a channel ({} {} \
                         {}): both scaled there to sum to 1",
                        sum.x, sum.y, sum.z
                    ));
                    if let Some(mat) = self.materials.get_mut(id as usize) {
                        *mat = Material::Glossy {
                            albedo: albedo * f,
                            specular: specular * f,
                            alpha,
                        };
                    }
                }
                albedo * f
            }
            _ => {
                return Ok(Some(format!(
                    "`map_Kd {}`: only diffuse and glossy (illum 0-2) materials are textured; \
                     this one is drawn without it",
                    path.display()
                )));
            }
        };
        if let Some(slot) = self.albedo_maps.get_mut(id as usize) {
            *slot = Some(AlbedoMap { texture, scale });
        }
        Ok(warning)
    }

    pub(super) fn validate_materials(&self) -> Result<(), SceneError> {
        let glass_ok = |ior: f32, transmittance: Vec3, absorption: Vec3| {
            ior.is_finite()
                && ior > 0.0
                && ior < 10.0
                && in_unit(transmittance)
                && non_negative(absorption)
        };
        for (name, m) in self.names.iter().zip(&self.materials) {
            // Glass's own keys first, each named alone.
            if let Material::Dielectric {
                transmittance,
                absorption,
                ..
            }
            | Material::RoughDielectric {
                transmittance,
                absorption,
                ..
            } = m
            {
                if !in_unit(*transmittance) {
                    return Err(self.err(format!(
                        "material `{name}`: transmittance {:?} must lie in [0, 1] in each channel",
                        transmittance.to_array()
                    )));
                }
                if !non_negative(*absorption) {
                    return Err(self.err(format!(
                        "material `{name}`: absorption {:?} must be finite and >= 0 in each \
                         channel (per scene unit)",
                        absorption.to_array()
                    )));
                }
            }
            let ok = match m {
                Material::Lambertian { albedo } => in_unit(*albedo),
                Material::Mirror { reflectance } | Material::Metal { reflectance } => {
                    in_unit(*reflectance)
                }
                Material::Dielectric {
                    ior,
                    transmittance,
                    absorption,
                } => glass_ok(*ior, *transmittance, *absorption),
                Material::Glossy {
                    albedo,
                    specular,
                    alpha,
                } => {
                    in_unit(*albedo)
                        && in_unit(*specular)
                        // MTL's scaling to a sum of 1 may round a hair above it.
                        && in_unit((*albedo + *specular) / (1.0 + 1e-6))
                        && ALPHA_RANGE.contains(alpha)
                }
                Material::RoughConductor {
                    reflectance,
                    alpha,
                    eta,
                } => {
                    in_unit(*reflectance)
                        && ALPHA_RANGE.contains(alpha)
                        && eta.is_none_or(|(e, k)| {
                            e.is_finite()
                                && k.is_finite()
                                && e.min_element() > 0.0
                                && k.min_element() >= 0.0
                        })
                }
                Material::RoughDielectric {
                    ior,
                    alpha,
                    transmittance,
                    absorption,
                } => glass_ok(*ior, *transmittance, *absorption) && ALPHA_RANGE.contains(alpha),
            };
            if !ok {
                return Err(self.err(format!(
                    "material `{name}`: albedo/reflectance/transmittance (and albedo + \
                     specular) must lie in [0, 1], ior in (0, 10), alpha in [1e-4, 1], \
                     absorption be finite and >= 0, eta > 0 and k >= 0 given together (got \
                     {m:?})"
                )));
            }
        }
        for (name, e) in self.names.iter().zip(&self.emission) {
            if !(e.is_finite() && e.min_element() >= 0.0) {
                return Err(self.err(format!(
                    "material `{name}`: emission must be finite and >= 0"
                )));
            }
        }
        Ok(())
    }

    /// The scene file's `texture` keys, attached to their materials.
    pub(super) fn scene_file_textures(&mut self, file: &SceneFile) -> Result<(), SceneError> {
        for (name, desc) in &file.materials {
            let (MaterialDesc::Lambertian {
                texture: Some(t), ..
            }
            | MaterialDesc::Glossy {
                texture: Some(t), ..
            }) = desc
            else {
                continue;
            };
            let image = self.dir.join(t);
            let id = self.by_name.get(name).copied().unwrap_or(u32::MAX);
            let warned = self.attach_albedo_map(id, &image).map_err(|p| {
                self.err(format!(
                    "material `{name}`: texture `{t}` ({}): {p}",
                    image.display()
                ))
            })?;
            let at = |w: String| format!("{}: material `{name}`: {w}", self.scene_path.display());
            self.warnings.extend(warned.map(at));
        }
        Ok(())
    }
}

pub(super) fn in_unit(v: Vec3) -> bool {
    v.is_finite() && v.min_element() >= 0.0 && v.max_element() <= 1.0
}

pub(super) fn non_negative(v: Vec3) -> bool {
    v.is_finite() && v.min_element() >= 0.0
}
