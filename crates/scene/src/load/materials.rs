//! Materials: the scene file's descriptions, their textures (read once per path), and the
//! checks every material passes whether it came from the scene file or an MTL file.

use super::Builder;
use crate::error::SceneError;
use crate::file::MaterialDesc;
use crate::file::SceneFile;
use crate::file::TextureDesc;
use crate::material::ALPHA_RANGE;
use crate::material::Material;
use crate::scene::AlbedoMap;
use crate::texture::{Checkerboard, Texture};
use glam::Vec3;
use std::path::Path;

/// How an MTL file names a material's albedo, its texture and its specular reflectance.
pub(super) const MTL_KEYS: [&str; 3] = ["`Kd`", "`map_Kd`", "`Ks`"];
/// How the scene file names them.
const FILE_KEYS: [&str; 3] = ["albedo", "texture", "specular"];

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
            material,
        } => (
            Material::RoughConductor {
                reflectance: Vec3::from(*reflectance),
                alpha: *alpha,
                eta: complex_index(*eta, *k, material.as_deref()),
            },
            Vec3::ZERO,
        ),
        MaterialDesc::Conductor {
            reflectance,
            eta,
            k,
            material,
        } => (
            Material::Conductor {
                reflectance: Vec3::from(*reflectance),
                eta: complex_index(*eta, *k, material.as_deref()),
            },
            Vec3::ZERO,
        ),
        MaterialDesc::Plastic {
            diffuse,
            specular,
            ior,
            nonlinear,
            ..
        } => (
            Material::Plastic {
                diffuse: Vec3::from(*diffuse),
                specular: Vec3::from(*specular),
                ior: *ior,
                nonlinear: *nonlinear,
            },
            Vec3::ZERO,
        ),
        MaterialDesc::RoughPlastic {
            diffuse,
            specular,
            ior,
            alpha,
            nonlinear,
            ..
        } => (
            Material::RoughPlastic {
                diffuse: Vec3::from(*diffuse),
                specular: Vec3::from(*specular),
                ior: *ior,
                alpha: *alpha,
                nonlinear: *nonlinear,
            },
            Vec3::ZERO,
        ),
        MaterialDesc::ThinDielectric {
            ior,
            reflectance,
            transmittance,
        } => (
            Material::ThinDielectric {
                ior: *ior,
                reflectance: Vec3::from(*reflectance),
                transmittance: Vec3::from(*transmittance),
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

/// A conductor's complex index from its `eta`, `k` and Mitsuba name. Both or neither of `eta`
/// and `k`, and no name beside them, or a known name: `check_descs` refuses the rest first
/// (they become NaN here, which `check` would refuse too). `"none"` is no index.
fn complex_index(
    eta: Option<[f32; 3]>,
    k: Option<[f32; 3]>,
    material: Option<&str>,
) -> Option<(Vec3, Vec3)> {
    let v = |x: Option<[f32; 3]>| x.map_or(Vec3::NAN, Vec3::from);
    match (eta, k, material) {
        (None, None, None | Some("none")) => None,
        (None, None, Some(name)) => Some(
            crate::mitsuba_conductor(name)
                .map_or((Vec3::NAN, Vec3::NAN), |(e, k)| (e.into(), k.into())),
        ),
        (eta, k, _) => Some((v(eta), v(k))),
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

    /// The material every face of mesh `index` takes, when the mesh names one: the named
    /// scene-file material, or with `radiance` a copy of it that emits (its own id, so other
    /// surfaces of that material stay dark).
    pub(super) fn mesh_material(
        &mut self,
        index: usize,
        desc: &crate::file::MeshDesc,
    ) -> Result<Option<u32>, SceneError> {
        let Some(name) = &desc.material else {
            return match desc.radiance {
                Some(_) => Err(self.err(format!(
                    "mesh {index} ({}): `radiance` needs `material`, the surface that emits",
                    desc.source()
                ))),
                None => Ok(None),
            };
        };
        let Some(&id) = self.by_name.get(name) else {
            return Err(self.err(format!(
                "mesh {index} ({}): unknown material `{name}` (the scene file's: {})",
                desc.source(),
                self.names.join(", ")
            )));
        };
        let Some(r) = desc.radiance else {
            return Ok(Some(id));
        };
        let le = Vec3::from(r);
        if !(le.is_finite() && le.min_element() >= 0.0) {
            return Err(self.err(format!(
                "mesh {index} ({}): `radiance` {r:?} must be finite and non-negative",
                desc.source()
            )));
        }
        let m = self.of_material(&self.materials, id)?.clone();
        let map = *self.of_material(&self.albedo_maps, id)?;
        let own = self.add_material(&format!("{name} (mesh {index})"), m, le);
        if let Some(slot) = self.albedo_maps.get_mut(own as usize) {
            *slot = map;
        }
        Ok(Some(own))
    }

    /// The texture of `source` (an image read once per path) as its index; `Err` is the
    /// problem, for the caller to name the file that asked for it.
    fn texture(&mut self, source: Source) -> Result<u32, String> {
        let path = match source {
            Source::File(p) => p,
            Source::Checker(c) => {
                let v = [c.color0, c.color1];
                if !v.iter().all(|c| c.is_finite() && c.min_element() >= 0.0)
                    || !c.to_uv.iter().flatten().all(|x| x.is_finite())
                {
                    return Err(format!(
                        "a checkerboard's colours must be finite and >= 0 and its to_uv finite \
                         (got {:?}, {:?}, {:?})",
                        c.color0, c.color1, c.to_uv
                    ));
                }
                self.textures.push(Texture::checkerboard(c));
                return Ok(self.textures.len() as u32 - 1);
            }
        };
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
    /// texture is not drawn. Where the albedo times the brightest texel (plus the specular
    /// reflectance) exceeds 1 in a channel, the material is scaled there to 1: no point
    /// reflects more than it gets. `keys` names the albedo, the texture and the specular
    /// reflectance in messages ([`MTL_KEYS`], [`FILE_KEYS`]). `Ok` holds a warning, if any;
    /// `Err` the problem with the image.
    pub(super) fn attach_albedo_map(
        &mut self,
        id: u32,
        source: Source,
        keys: [&str; 3],
    ) -> Result<Option<String>, String> {
        let [kd, map, ks] = keys;
        let Some(m) = self.materials.get(id as usize).cloned() else {
            return Err(format!("internal error: material id {id}"));
        };
        let what = match source {
            Source::File(p) => p.display().to_string(),
            Source::Checker(_) => "a checkerboard".to_string(),
        };
        let texture = self.texture(source)?;
        let t_max = self
            .textures
            .get(texture as usize)
            .map_or(Vec3::ONE, Texture::max);
        // The factor per channel that brings `peak` down to 1 where it exceeds it.
        let to_one = |peak: Vec3| Vec3::select(peak.cmpgt(Vec3::ONE), peak.recip(), Vec3::ONE);
        let mut warning = None;
        let scale = match m {
            Material::Lambertian { albedo } => {
                // An HDR texture may hold texels far above 1 (an EXR of 4 under `Kd 0.7`
                // reflected 2.8 times the light it got).
                let peak = albedo * t_max;
                let f = to_one(peak);
                if f != Vec3::ONE {
                    warning = Some(format!(
                        "{kd} x {map}'s brightest texel exceeds 1 in a channel ({} {} {}): {kd} \
                         scaled there so that texel reflects 1",
                        peak.x, peak.y, peak.z
                    ));
                    if let Some(mat) = self.materials.get_mut(id as usize) {
                        *mat = Material::Lambertian { albedo: albedo * f };
                    }
                }
                albedo * f
            }
            Material::Glossy {
                albedo,
                specular,
                alpha,
            } => {
                // The untextured rule (`Kd + Ks <= 1` per channel, both scaled there where
                // not) over the texture's brightest texel.
                let sum = albedo * t_max + specular;
                let f = to_one(sum);
                if f != Vec3::ONE {
                    warning = Some(format!(
                        "{kd} x {map}'s brightest texel + {ks} exceeds 1 in a channel ({} {} \
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
            Material::Plastic { diffuse, .. } | Material::RoughPlastic { diffuse, .. } => {
                // As a Lambertian's albedo: the base's reflectance at the brightest texel at
                // most 1 (the coating is not textured).
                let peak = diffuse * t_max;
                let f = to_one(peak);
                if f != Vec3::ONE {
                    warning = Some(format!(
                        "diffuse x texture's brightest texel exceeds 1 in a channel ({} {} {}): \
                         diffuse scaled there so that texel reflects 1",
                        peak.x, peak.y, peak.z
                    ));
                    if let Some(
                        Material::Plastic { diffuse, .. } | Material::RoughPlastic { diffuse, .. },
                    ) = self.materials.get_mut(id as usize)
                    {
                        *diffuse *= f;
                    }
                }
                diffuse * f
            }
            _ => {
                return Ok(Some(format!(
                    "{map} ({}): only diffuse and glossy (illum 0-2) materials are textured; \
                     this one is drawn without it",
                    what
                )));
            }
        };
        if let Some(slot) = self.albedo_maps.get_mut(id as usize) {
            *slot = Some(AlbedoMap { texture, scale });
        }
        Ok(warning)
    }

    /// Every material's values against their ranges ([`check`], with the scene file's key
    /// names), and its emission.
    pub(super) fn validate_materials(&self) -> Result<(), SceneError> {
        for (name, m) in self.names.iter().zip(&self.materials) {
            check(m, str::to_string).map_err(|p| self.err(format!("material `{name}`: {p}")))?;
        }
        for (name, e) in self.names.iter().zip(&self.emission) {
            if !(e.is_finite() && e.min_element() >= 0.0) {
                return Err(self.err(format!(
                    "material `{name}`: emission = {} must be finite and >= 0 in each channel",
                    list(*e)
                )));
            }
        }
        Ok(())
    }

    /// What the scene file's descriptions say that their [`Material`]s cannot: a conductor's
    /// `eta` or `k` given alone, or beside a named `material`, or a name Mitsuba 3 does not
    /// know.
    pub(super) fn check_descs(&self, file: &SceneFile) -> Result<(), SceneError> {
        for (name, desc) in &file.materials {
            let (MaterialDesc::RoughConductor {
                eta, k, material, ..
            }
            | MaterialDesc::Conductor {
                eta, k, material, ..
            }) = desc
            else {
                continue;
            };
            if eta.is_some() != k.is_some() {
                let missing = if eta.is_some() { "k" } else { "eta" };
                return Err(self.err(format!(
                    "material `{name}`: eta and k are given together or not at all \
                     ({missing} is missing)"
                )));
            }
            if let Some(m) = material {
                if eta.is_some() {
                    return Err(self.err(format!(
                        "material `{name}`: material = \"{m}\" and eta, k both give the index: \
                         give one"
                    )));
                }
                if m != "none" && crate::mitsuba_conductor(m).is_none() {
                    return Err(self.err(format!(
                        "material `{name}`: material = \"{m}\" is not one of Mitsuba 3's \
                         conductors (e.g. \"Au\", \"Ag\", \"Cu\", \"Al\", \"Cr\", \"none\"; \
                         names are case-sensitive)"
                    )));
                }
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
            }
            | MaterialDesc::Plastic {
                texture: Some(t), ..
            }
            | MaterialDesc::RoughPlastic {
                texture: Some(t), ..
            }) = desc
            else {
                continue;
            };
            let id = self.by_name.get(name).copied().unwrap_or(u32::MAX);
            let warned = match t {
                TextureDesc::File(t) => {
                    let image = self.dir.join(t);
                    self.attach_albedo_map(id, Source::File(&image), FILE_KEYS)
                        .map_err(|p| {
                            self.err(format!(
                                "material `{name}`: texture `{t}` ({}): {p}",
                                image.display()
                            ))
                        })?
                }
                TextureDesc::Checkerboard(c) => {
                    let c = Checkerboard {
                        color0: c.color0.into(),
                        color1: c.color1.into(),
                        to_uv: c.to_uv,
                    };
                    self.attach_albedo_map(id, Source::Checker(c), FILE_KEYS)
                        .map_err(|p| self.err(format!("material `{name}`: texture: {p}")))?
                }
            };
            let at = |w: String| format!("{}: material `{name}`: {w}", self.scene_path.display());
            self.warnings.extend(warned.map(at));
        }
        Ok(())
    }
}

/// Where a texture comes from.
#[derive(Clone, Copy)]
pub(super) enum Source<'p> {
    File(&'p Path),
    Checker(Checkerboard),
}

pub(super) fn in_unit(v: Vec3) -> bool {
    v.is_finite() && v.min_element() >= 0.0 && v.max_element() <= 1.0
}

pub(super) fn non_negative(v: Vec3) -> bool {
    v.is_finite() && v.min_element() >= 0.0
}

/// `[x, y, z]`, as the scene file writes a colour.
fn list(v: Vec3) -> String {
    format!("[{}, {}, {}]", v.x, v.y, v.z)
}

/// Material `m`'s values, each against its range. `Err` names the first key out of it, as
/// `key` spells the scene file's key (an MTL file has its own), and its value.
pub(super) fn check(m: &Material, key: impl Fn(&str) -> String) -> Result<(), String> {
    let unit = |k: &str, v: Vec3| {
        if in_unit(v) {
            Ok(())
        } else {
            Err(format!(
                "{} = {} must lie in [0, 1] in each channel",
                key(k),
                list(v)
            ))
        }
    };
    let alpha = |a: f32| {
        if ALPHA_RANGE.contains(&a) {
            Ok(())
        } else {
            Err(format!("{} = {a} must be in [1e-4, 1]", key("alpha")))
        }
    };
    let ior = |i: f32| {
        if i.is_finite() && i > 0.0 && i < 10.0 {
            Ok(())
        } else {
            Err(format!("{} = {i} must be in (0, 10)", key("ior")))
        }
    };
    let glass = |t: Vec3, a: Vec3| {
        unit("transmittance", t)?;
        if non_negative(a) {
            Ok(())
        } else {
            Err(format!(
                "{} = {} must be finite and >= 0 in each channel (per scene unit)",
                key("absorption"),
                list(a)
            ))
        }
    };
    let complex = |eta: Option<(Vec3, Vec3)>| {
        let Some((e, k)) = eta else {
            return Ok(());
        };
        if !non_negative(e) {
            return Err(format!(
                "{} = {} must be finite and >= 0 in each channel",
                key("eta"),
                list(e)
            ));
        }
        if !non_negative(k) {
            return Err(format!(
                "{} = {} must be finite and >= 0 in each channel",
                key("k"),
                list(k)
            ));
        }
        // `eta + i k = 0` has no Fresnel term (`eta = 0` with `k > 0` reflects everything,
        // Mitsuba 3's `none`).
        if (e + k).min_element() > 0.0 {
            Ok(())
        } else {
            Err(format!(
                "{} = {}, {} = {}: eta or k must be > 0 in each channel",
                key("eta"),
                list(e),
                key("k"),
                list(k)
            ))
        }
    };
    match *m {
        Material::Lambertian { albedo } => unit("albedo", albedo),
        Material::Mirror { reflectance } | Material::Metal { reflectance } => {
            unit("reflectance", reflectance)
        }
        Material::Dielectric {
            ior: i,
            transmittance,
            absorption,
        } => {
            glass(transmittance, absorption)?;
            ior(i)
        }
        Material::Glossy {
            albedo,
            specular,
            alpha: a,
        } => {
            unit("albedo", albedo)?;
            unit("specular", specular)?;
            let sum = albedo + specular;
            // MTL's scaling to a sum of 1 may round a hair above it.
            if !in_unit(sum / (1.0 + 1e-6)) {
                return Err(format!(
                    "{} + {} = {} exceeds 1 in a channel: no surface reflects more than it \
                     receives",
                    key("albedo"),
                    key("specular"),
                    list(sum)
                ));
            }
            alpha(a)
        }
        Material::RoughConductor {
            reflectance,
            alpha: a,
            eta,
        } => {
            unit("reflectance", reflectance)?;
            alpha(a)?;
            complex(eta)
        }
        Material::RoughDielectric {
            ior: i,
            alpha: a,
            transmittance,
            absorption,
        } => {
            glass(transmittance, absorption)?;
            ior(i)?;
            alpha(a)
        }
        Material::Conductor { reflectance, eta } => {
            unit("reflectance", reflectance)?;
            complex(eta)
        }
        Material::Plastic {
            diffuse,
            specular,
            ior: i,
            ..
        } => {
            unit("diffuse", diffuse)?;
            unit("specular", specular)?;
            ior(i)
        }
        Material::RoughPlastic {
            diffuse,
            specular,
            ior: i,
            alpha: a,
            ..
        } => {
            unit("diffuse", diffuse)?;
            unit("specular", specular)?;
            ior(i)?;
            // Mitsuba 3 refuses it too: the coating's tables need an interface.
            if i == 1.0 {
                return Err(format!(
                    "{} = 1 leaves no coating: use lambertian",
                    key("ior")
                ));
            }
            alpha(a)
        }
        Material::ThinDielectric {
            ior: i,
            reflectance,
            transmittance,
        } => {
            unit("reflectance", reflectance)?;
            unit("transmittance", transmittance)?;
            ior(i)
        }
    }
}
