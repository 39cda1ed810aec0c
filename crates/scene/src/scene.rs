//! [`Scene`]: a loaded scene, ready to trace, and what passes ask of it as a whole. Loading
//! (`load/`) builds it; `world.rs` answers per surface.

use crate::camera::Camera;
use crate::file::{RenderSettings, SceneFile};
use crate::lights::AreaLight;
use crate::lights::LightTable;
use crate::material::Material;
use crate::texture::Texture;
use bsdf::Bsdf;
use geom::Geometry;
use glam::{DVec3, Vec3};
use std::path::PathBuf;

/// A material's albedo texture: the diffuse albedo at a point is `scale` times the texture's
/// value there (MTL: `Kd` times `map_Kd`, as the MTL spec multiplies them).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AlbedoMap {
    /// Index into [`Scene::textures`].
    pub texture: u32,
    pub scale: Vec3,
}

/// A loaded scene, ready to trace.
pub struct Scene {
    pub path: PathBuf,
    pub file: SceneFile,
    pub geometry: Geometry,
    pub materials: Vec<Material>,
    pub material_names: Vec<String>,
    /// Emitted radiance per material (zero for non-emitters).
    pub emission: Vec<Vec3>,
    pub lights: Vec<AreaLight>,
    /// The lights ready for sampling, built once: next-event estimation and photon emission
    /// both read it.
    pub light_table: LightTable,
    /// BSDF per material (`None`: black, absorbs), built once for every pass
    /// ([`Scene::bsdf`]).
    pub bsdfs: Vec<Option<Bsdf>>,
    /// Albedo texture per material (MTL `map_Kd`, scene-file `texture`), `None` for most:
    /// [`Scene::bsdf_at`] multiplies its lookup into the diffuse lobe.
    pub albedo_maps: Vec<Option<AlbedoMap>>,
    pub textures: Vec<Texture>,
    /// Beer-Lambert absorption coefficient inside each material (zero but for absorbing
    /// glass), built once for every pass ([`Scene::transmittance_to`]).
    pub absorption: Vec<Vec3>,
    pub camera: Camera,
    /// FNV-1a hash of the scene file and every file it names, in order.
    pub content_hash: u64,
    /// Hash of what photons depend on: the files the scene names, the seed, meshes, spheres
    /// and materials (not the camera, `[render]` or `[estimate]`, so editing an estimator or
    /// the camera never invalidates a photon cache). Emission parameters are keyed apart.
    pub photon_hash: u64,
    /// `photon_hash` plus the camera and `[render]`: what a path-traced image depends on.
    pub image_hash: u64,
    /// What an image *means*: the named files, meshes, spheres, materials and camera, but not
    /// the seed or any sampling setting. Images with equal view hashes estimate the same
    /// picture and may be composited.
    pub view_hash: u64,
    /// What the scene's files ask for that photonflow approximates, one line each (file,
    /// material, what is drawn instead): commands print them as `warning:` lines.
    pub warnings: Vec<String>,
}

impl Scene {
    pub fn seed(&self) -> u64 {
        self.file.seed
    }

    pub fn render(&self) -> &RenderSettings {
        &self.file.render
    }

    /// Total emitted power of all lights (triangles, then point and spot lights), summed in
    /// f64.
    pub fn light_power(&self) -> Vec3 {
        let s = self
            .lights
            .iter()
            .fold(DVec3::ZERO, |s, l| s + l.power.as_dvec3());
        let t = &self.light_table;
        (self.lights.len()..t.len())
            .fold(s, |s, i| s + t.power(i))
            .as_vec3()
    }

    pub fn light_area(&self) -> f64 {
        // Folded from +0.0: an empty `sum` of f64 is -0.0, which `info` would print.
        self.lights.iter().fold(0.0, |a, l| a + l.area as f64)
    }

    pub fn material_of(&self, name: &str) -> Option<u32> {
        self.material_names
            .iter()
            .position(|n| n == name)
            .map(|i| i as u32)
    }
}
