//! Loading: a scene file and every file it names into a [`Scene`]. One room per concern:
//! `obj.rs` (OBJ meshes, their text read by `objtext/` on every core), `ply.rs` (PLY meshes), `faces.rs` (what both share: their
//! polygons checked, transformed, triangulated and appended), `mtl.rs` (the MTL table),
//! `materials.rs` (scene-file materials, textures, validation), `lights.rs` (emissive
//! triangles and the scene file's lights), `transform.rs` (the one transform helper),
//! `hash.rs` (cache keys). This file holds the entry points and the [`Builder`] they share,
//! and assembles the scene.

// A decoder of untrusted bytes: no input may reach a panic, so the lints that find the ways
// to one (unwrap, expect, indexing, explicit panics) are errors here and in every room below;
// `cargo clippy` is the check.
#![cfg_attr(
    not(test),
    deny(
        clippy::unwrap_used,
        clippy::expect_used,
        clippy::indexing_slicing,
        clippy::panic,
        clippy::unreachable
    )
)]

mod faces;
mod hash;
mod lights;
mod materials;
mod mtl;
mod obj;
pub(crate) mod objtext;
pub(crate) mod ply;
mod shapes;
mod transform;

pub use hash::fnv1a64;

use crate::camera::Camera;
use crate::error::SceneError;
use crate::file::SceneFile;
use crate::material::Material;
use crate::scene::AlbedoMap;
use crate::scene::Scene;
use crate::texture::Texture;
use geom::{Geometry, Sphere, TriMesh};
use glam::Vec3;
use hash::Fnv;
use std::collections::HashMap;
use std::path::{Path, PathBuf};

impl Scene {
    /// Load a scene file and every file it names.
    pub fn load(path: impl AsRef<Path>) -> Result<Scene, SceneError> {
        Scene::load_with(path, |_| {})
    }

    /// [`Scene::load`], with `edit` applied to the parsed file before anything is built or
    /// hashed (the command line's `--seed`, say): the scene is still loaded once.
    pub fn load_with(
        path: impl AsRef<Path>,
        edit: impl FnOnce(&mut SceneFile),
    ) -> Result<Scene, SceneError> {
        Scene::load_defined(path, &[], edit)
    }

    /// [`Scene::load_with`] for a scene file or a Mitsuba 3 XML scene (`.xml`), whose
    /// `$name` parameters `defines` sets (`-D name=value`) before its `<default>`s do.
    pub fn load_defined(
        path: impl AsRef<Path>,
        defines: &[(String, String)],
        edit: impl FnOnce(&mut SceneFile),
    ) -> Result<Scene, SceneError> {
        let path = path.as_ref();
        if crate::xml::is_xml(path) {
            let xml = crate::xml::read_xml(path, defines)?;
            let mut file = xml.file;
            edit(&mut file);
            // The file it means, as text: its hashes are the TOML scene's.
            let text = toml::to_string(&file)
                .map_err(|e| SceneError::new(path, format!("internal error: {e}")))?;
            let mut scene = Scene::build(path, file, &text)?;
            scene.warnings.splice(0..0, xml.warnings);
            return Ok(scene);
        }
        if let Some((name, _)) = defines.first() {
            return Err(SceneError::new(
                path,
                format!("-D {name}=...: parameters are for Mitsuba 3 XML scenes (.xml) only"),
            ));
        }
        let bytes = read_regular(path)
            .map_err(|e| SceneError::new(path, format!("cannot read scene file: {e}")))?;
        let text = String::from_utf8(bytes)
            .map_err(|_| SceneError::new(path, "cannot read scene file: it is not UTF-8 text"))?;
        Scene::from_toml_with(path, &text, edit)
    }

    /// Parse scene text as if it were read from `path` (mesh paths are relative to it).
    pub fn from_toml(path: &Path, text: &str) -> Result<Scene, SceneError> {
        Scene::from_toml_with(path, text, |_| {})
    }

    /// [`Scene::from_toml`] with `edit` applied to the parsed file first.
    pub fn from_toml_with(
        path: &Path,
        text: &str,
        edit: impl FnOnce(&mut SceneFile),
    ) -> Result<Scene, SceneError> {
        let mut file: SceneFile = toml::from_str(text).map_err(|e| {
            SceneError::new(
                path,
                format!("malformed scene file: {}", e.message()) + &location(text, e.span()),
            )
        })?;
        edit(&mut file);
        Scene::build(path, file, text)
    }

    /// The scene `file` read from `path` as `text`, built and hashed.
    fn build(path: &Path, file: SceneFile, text: &str) -> Result<Scene, SceneError> {
        // The builder hashes the files the scene names; the scene text joins per use below.
        let mut hash = Fnv::new();
        let mut scene = Builder::new(path, &file, &mut hash).build(file.clone())?;
        let (photon, image, view, content) = hash::scene_hashes(&file, hash.finish(), text);
        scene.photon_hash = photon;
        scene.image_hash = image;
        scene.view_hash = view;
        scene.content_hash = content;
        Ok(scene)
    }
}

/// ` (line N: `snippet`)` for a TOML error's span, or nothing.
fn location(text: &str, span: Option<std::ops::Range<usize>>) -> String {
    match span {
        Some(r) => {
            let before = text.as_bytes().get(..r.start).unwrap_or(text.as_bytes());
            let line = before.iter().filter(|&&b| b == b'\n').count() + 1;
            let snippet = text
                .get(r)
                .unwrap_or("")
                .lines()
                .next()
                .unwrap_or("")
                .trim();
            format!(" (line {line}: `{snippet}`)")
        }
        None => String::new(),
    }
}

/// What loading has gathered so far; each room adds to it.
struct Builder<'a> {
    scene_path: &'a Path,
    dir: PathBuf,
    hash: &'a mut Fnv,
    mesh: TriMesh,
    spheres: Vec<Sphere>,
    materials: Vec<Material>,
    names: Vec<String>,
    emission: Vec<Vec3>,
    by_name: HashMap<String, u32>,
    albedo_maps: Vec<Option<AlbedoMap>>,
    textures: Vec<Texture>,
    /// Textures by the path that named them: a texture several materials share loads once.
    texture_ids: HashMap<PathBuf, u32>,
    warnings: Vec<String>,
}

impl<'a> Builder<'a> {
    fn new(scene_path: &'a Path, file: &SceneFile, hash: &'a mut Fnv) -> Builder<'a> {
        let dir = scene_path
            .parent()
            .map(Path::to_path_buf)
            .unwrap_or_default();
        let mut b = Builder {
            scene_path,
            dir,
            hash,
            mesh: TriMesh::default(),
            spheres: Vec::new(),
            materials: Vec::new(),
            names: Vec::new(),
            emission: Vec::new(),
            by_name: HashMap::new(),
            albedo_maps: Vec::new(),
            textures: Vec::new(),
            texture_ids: HashMap::new(),
            warnings: Vec::new(),
        };
        // Scene-file materials first: they win over MTL materials of the same name.
        for (name, desc) in &file.materials {
            let (m, e) = materials::of_desc(desc);
            b.add_material(name, m, e);
        }
        b
    }

    fn err(&self, problem: impl Into<String>) -> SceneError {
        SceneError::new(self.scene_path, problem)
    }

    /// Material `id`'s entry in a per-material table. Every id in the mesh and the spheres came
    /// from `add_material` or `by_name`, so a miss is a loader bug: an error, never a panic.
    fn of_material<'t, T>(&self, table: &'t [T], id: u32) -> Result<&'t T, SceneError> {
        table.get(id as usize).ok_or_else(|| {
            self.err(format!(
                "internal error: material id {id} of {} materials",
                table.len()
            ))
        })
    }

    /// The scene: materials and their textures, meshes, spheres, camera, lights, in that
    /// order (each step's errors assume the ones before passed).
    fn build(mut self, file: SceneFile) -> Result<Scene, SceneError> {
        self.check_descs(&file)?;
        self.validate_materials()?;
        self.scene_file_textures(&file)?;
        for (i, m) in file.meshes.iter().enumerate() {
            self.load_mesh(i, m)?;
        }
        self.add_spheres(&file)?;
        let camera = self.camera(&file)?;
        let (lights, light_table) = self.lights(&file)?;
        // The hashes need the whole scene text: `Scene::from_toml` sets them.
        let mut geometry = Geometry::new(self.mesh, self.spheres);
        // Only a textured sphere reads its hits' `uv` (`Scene::texcoord`).
        geometry.set_sphere_uv(|m| {
            self.albedo_maps
                .get(m as usize)
                .is_some_and(Option::is_some)
        });
        Ok(Scene {
            path: self.scene_path.to_path_buf(),
            file,
            geometry,
            bsdfs: self.materials.iter().map(crate::world::bsdf_of).collect(),
            albedo_maps: self.albedo_maps,
            textures: self.textures,
            absorption: self.materials.iter().map(Material::absorption).collect(),
            warnings: self.warnings,
            materials: self.materials,
            material_names: self.names,
            emission: self.emission,
            lights,
            light_table,
            camera,
            content_hash: 0,
            photon_hash: 0,
            image_hash: 0,
            view_hash: 0,
        })
    }

    fn add_spheres(&mut self, file: &SceneFile) -> Result<(), SceneError> {
        for (i, s) in file.spheres.iter().enumerate() {
            let c = Vec3::from(s.center);
            if !(c.is_finite() && s.radius.is_finite() && s.radius > 0.0) {
                return Err(self.err(format!(
                    "sphere {i}: centre must be finite and radius a positive number (got {:?}, {})",
                    s.center, s.radius
                )));
            }
            if c.abs().max_element() as f64 + s.radius as f64 > MAX_COORD {
                return Err(self.err(format!(
                    "sphere {i} (centre {:?}, radius {}) reaches beyond the {MAX_COORD:e} scene \
                     units photonflow can trace",
                    s.center, s.radius
                )));
            }
            let Some(&mat) = self.by_name.get(&s.material) else {
                return Err(self.err(format!(
                    "sphere {i}: unknown material `{}` (known: {})",
                    s.material,
                    self.names.join(", ")
                )));
            };
            self.spheres.push(Sphere {
                center: c,
                radius: s.radius,
                material: mat,
            });
        }
        Ok(())
    }

    /// The camera, and the `[render]` settings checked beside it.
    fn camera(&self, file: &SceneFile) -> Result<Camera, SceneError> {
        let c = &file.camera;
        let camera = Camera::new(
            c.eye.into(),
            c.look_at.into(),
            c.up.into(),
            c.vfov,
            c.width,
            c.height,
        )
        .filter(|_| [c.eye, c.look_at, c.up].iter().flatten().all(|v| v.is_finite()))
        .ok_or_else(|| {
            self.err(format!(
                "camera: needs distinct finite eye and look_at, an up vector not along the view, \
                 0 < vfov < 180 and a non-empty image (got eye {:?}, look_at {:?}, up {:?}, vfov {}, {}x{})",
                c.eye, c.look_at, c.up, c.vfov, c.width, c.height
            ))
        })?;
        if c.width as u64 * c.height as u64 > 1 << 28 {
            return Err(self.err(format!("camera: {}x{} pixels is absurd", c.width, c.height)));
        }
        let r = &file.render;
        if r.spp == 0 || r.spp > 1 << 24 {
            return Err(self.err(format!("render.spp = {} must be in 1..=16777216", r.spp)));
        }
        if r.tile == 0 || r.tile > 4096 {
            return Err(self.err(format!("render.tile = {} must be in 1..=4096", r.tile)));
        }
        Ok(camera)
    }
}

/// Largest coordinate (scene units, after a mesh's transform) of any vertex or sphere. The
/// BVH builder and the intersection code work in f32: surface areas of boxes and edge cross
/// products multiply two coordinate differences (up to (2x)^2, times 6 summed over a box's
/// faces), which overflows f32's 3.4e38 near |x| = 3.7e18, and obvhs panics on the infinite
/// areas. 1e15 keeps three orders of magnitude below that and still admits any real scene
/// in metres or millimetres.
pub(crate) const MAX_COORD: f64 = 1e15;

/// Reads a file a scene names, refusing anything but a regular file before opening it:
/// opening a FIFO blocks until a writer comes, and a device may never end.
pub(crate) fn read_regular(path: &Path) -> std::io::Result<Vec<u8>> {
    let meta = std::fs::metadata(path)?;
    if !meta.is_file() {
        let t = meta.file_type();
        let what = if t.is_dir() {
            "a directory"
        } else if t.is_symlink() {
            "a symbolic link"
        } else {
            "a FIFO, socket or device"
        };
        return Err(std::io::Error::other(format!(
            "it is {what}, not a regular file"
        )));
    }
    #[cfg(unix)]
    if meta.len() >= READ_PIECE as u64 * 2 {
        return read_pieces(path);
    }
    std::fs::read(path)
}

/// Bytes each task of [`read_pieces`] reads.
const READ_PIECE: usize = 4 << 20;

/// A large file read in pieces on every core: most of a read's time is the kernel copying
/// into fresh pages, which a single reader leaves to one core. A file whose length changes
/// meanwhile is read again whole, as `std::fs::read` reads it.
#[cfg(unix)]
fn read_pieces(path: &Path) -> std::io::Result<Vec<u8>> {
    use rayon::prelude::*;
    use std::os::unix::fs::FileExt;
    let file = std::fs::File::open(path)?;
    let len = usize::try_from(file.metadata()?.len()).map_err(std::io::Error::other)?;
    let mut bytes = vec![0u8; len];
    let read = bytes
        .par_chunks_mut(READ_PIECE)
        .enumerate()
        .try_for_each(|(i, piece)| file.read_exact_at(piece, (i * READ_PIECE) as u64));
    match read {
        Err(e) if e.kind() == std::io::ErrorKind::UnexpectedEof => std::fs::read(path),
        Err(e) => Err(e),
        Ok(()) if file.read_at(&mut [0], len as u64)? != 0 => std::fs::read(path),
        Ok(()) => Ok(bytes),
    }
}
