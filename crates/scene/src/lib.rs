//! `scene`: turns a scene file into a ready-to-trace [`Scene`].
//!
//! Key decision: **one TOML file holds every parameter of a run** (Tungsten's habit: one
//! JSON scene file per render): mesh files and their transforms, spheres, materials, camera,
//! seed and render settings. Its keys are the `snake_case` names of the Rust fields (as
//! Mitsuba 3's scene keys are its plugin parameters' names) and unknown
//! keys are errors, so a typo never silently falls back to a default.
//!
//! Loading never panics: every problem is a [`SceneError`] naming the file and what is wrong
//! with it. This crate reads exactly the files its scene file names (OBJ meshes, the MTL
//! files they name, textures and environment maps) and nothing else.
//!
//! Rooms: `load/` turns files into a [`Scene`] (one file per format or concern), `lights/`
//! is the closed [`Light`] type with a file per family and the [`LightTable`] over them,
//! `scene.rs` the loaded scene, `world.rs` what passes ask of a surface, `material.rs`,
//! `texture.rs`, `envmap.rs`, `camera.rs`, `polygon.rs` and `file.rs` (the scene file's
//! schema) one thing each.

mod camera;
mod envmap;
mod error;
mod file;
mod lights;
mod load;
mod material;
mod mitsuba_tables;
mod polygon;
mod scene;
mod texture;
mod world;
mod xml;

pub use camera::{Camera, Projection};
pub use envmap::EnvMap;
pub use error::SceneError;
pub use file::{
    CameraDesc, CheckerboardDesc, CheckerboardKind, EmissionSource, LightDesc, MaterialDesc,
    MeshDesc, Method, NormalMode, RenderSettings, SamplerKind, SceneFile, ShapeKind, SphereDesc,
    TextureDesc, TfReading,
};
pub use lights::{
    AreaLight, Directional, EmitPdfs, Emitted, Environment, Light, LightSample, LightTable,
    MIN_EMIT_COS, PointLight, SpotLight, Spread, Sun, TriangleLight,
};
pub use load::fnv1a64;
pub use material::{ALPHA_RANGE, Material};
pub use mitsuba_tables::{mitsuba_conductor, mitsuba_ior};
pub use scene::{AlbedoMap, Scene};
pub use texture::{Checkerboard, Texture, srgb_to_linear};
pub use world::{SPHERE_BIT, bsdf_of, sides_agree, surface_id};
pub use xml::{XmlScene, is_xml, read_xml};

#[cfg(test)]
mod tests;
