// A decoder of untrusted bytes: no input may reach a panic, so the lints that find the ways
// to one (unwrap, expect, indexing, explicit panics) are errors here; `cargo clippy` is the
// check.
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

use crate::file::{EmissionSource, MaterialDesc, MeshDesc, NormalMode, Scale, SceneFile};
use crate::material::ALPHA_RANGE;
use crate::{
    Camera, DeltaLight, EnvMap, InfiniteLight, LightDesc, LightTable, Material, RenderSettings,
    SceneError, Spot, Texture,
};
use bsdf::Bsdf;
use geom::{Geometry, Sphere, TriMesh, smooth_vertex_normals};
use glam::{DMat3, DMat4, DVec3, Mat3, Vec2, Vec3};
use math::Frame;
use std::cell::RefCell;
use std::collections::HashMap;
use std::io::BufReader;
use std::path::{Path, PathBuf};

/// One emissive triangle. Emission is one-sided, towards `normal`.
#[derive(Clone, Debug, PartialEq)]
pub struct AreaLight {
    pub triangle: u32,
    pub area: f32,
    /// Emitted radiance.
    pub le: Vec3,
    /// Unit normal of the emitting side.
    pub normal: Vec3,
    /// Emitted power `pi * area * le` of a Lambertian emitter.
    pub power: Vec3,
}

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
        let path = path.as_ref();
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
        // The builder hashes the files the scene names; the scene text joins per use below.
        let mut hash = Fnv::new();
        let mut scene = Builder::new(path, &file, &mut hash).build(file.clone())?;
        let files = hash.finish();
        let inputs = |f: &SceneFile, camera: bool, seed: bool, render: bool| -> String {
            #[derive(serde::Serialize)]
            struct Inputs<'a> {
                files: u64,
                seed: u64,
                meshes: &'a [crate::MeshDesc],
                spheres: &'a [crate::SphereDesc],
                materials: &'a std::collections::BTreeMap<String, crate::MaterialDesc>,
                #[serde(skip_serializing_if = "<[_]>::is_empty")]
                lights: &'a [crate::LightDesc],
                camera: Option<&'a crate::CameraDesc>,
                render: Option<&'a RenderSettings>,
            }
            // Mesh files count by content (`files`), not by the path that names them, so a
            // resolved scene file with absolute paths keeps its caches.
            let meshes: Vec<crate::MeshDesc> = f
                .meshes
                .iter()
                .map(|m| crate::MeshDesc {
                    obj: String::new(),
                    ..m.clone()
                })
                .collect();
            toml::to_string(&Inputs {
                files,
                seed: if seed { f.seed } else { 0 },
                meshes: &meshes,
                spheres: &f.spheres,
                materials: &f.materials,
                lights: &f.lights,
                camera: camera.then_some(&f.camera),
                render: render.then_some(&f.render),
            })
            .unwrap_or_default()
        };
        scene.photon_hash = fnv1a64(inputs(&file, false, true, false).as_bytes());
        scene.image_hash = fnv1a64(inputs(&file, true, true, true).as_bytes());
        scene.view_hash = fnv1a64(inputs(&file, true, false, false).as_bytes());
        let mut all = Fnv::new();
        all.write(&files.to_le_bytes());
        all.write(text.as_bytes());
        // An edit after parsing (a flag) changes the content too.
        all.write(toml::to_string(&file).unwrap_or_default().as_bytes());
        scene.content_hash = all.finish();
        Ok(scene)
    }
}

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
            let (m, e) = match desc {
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
            };
            b.add_material(name, m, e);
        }
        b
    }

    fn add_material(&mut self, name: &str, m: Material, e: Vec3) -> u32 {
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
        let bytes = read_regular(path).map_err(|e| format!("cannot read it: {e}"))?;
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
    fn attach_albedo_map(&mut self, id: u32, path: &Path) -> Result<Option<String>, String> {
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

    fn build(mut self, file: SceneFile) -> Result<Scene, SceneError> {
        self.validate_materials()?;
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
        for (i, m) in file.meshes.iter().enumerate() {
            self.load_mesh(i, m)?;
        }
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

        let mut lights = Vec::new();
        for (t, &mat) in self.mesh.materials.iter().enumerate() {
            let e = *self.of_material(&self.emission, mat)?;
            if e.max_element() <= 0.0 {
                continue;
            }
            let area = self.mesh.area(t);
            // In f64: an f32 cross product of a huge triangle overflows while normalising.
            let [p0, p1, p2] = self.mesh.vertices(t).map(|p| p.as_dvec3());
            let n = (p1 - p0).cross(p2 - p0).normalize_or_zero().as_vec3();
            let name = self.of_material(&self.names, mat)?;
            if area.is_infinite() || !n.is_finite() {
                return Err(self.err(format!(
                    "light triangle {t} (material `{name}`) is too large for f32 (area {area}): \
                     check the mesh's scale"
                )));
            }
            if area.is_nan() || area <= 0.0 || n == Vec3::ZERO {
                return Err(self.err(format!(
                    "zero-area light: triangle {t} (material `{name}`) emits but has no area"
                )));
            }
            let power = (std::f64::consts::PI * area as f64 * e.as_dvec3()).as_vec3();
            if !power.is_finite() {
                return Err(self.err(format!(
                    "light triangle {t} (material `{name}`): power pi * area * Le = {} x {:?} \
                     overflows f32",
                    std::f64::consts::PI * area as f64,
                    e.to_array()
                )));
            }
            lights.push(AreaLight {
                triangle: t as u32,
                area,
                le: e,
                normal: n,
                power,
            });
        }
        let total = lights
            .iter()
            .fold(DVec3::ZERO, |a, l| a + l.power.as_dvec3());
        if !total.as_vec3().is_finite() {
            return Err(self.err(format!(
                "the lights' total power {:?} overflows f32: emission or light size is absurd",
                total.to_array()
            )));
        }
        let deltas = self.delta_lights(&file.lights)?;
        let infinite = self.infinite_lights(&file.lights)?;
        if lights.is_empty() && deltas.is_empty() && infinite.is_empty() {
            let hint = if file.meshes.iter().any(|m| m.emission == EmissionSource::Ke) {
                " (hint: the course's MTL files keep emission in Ka: set emission = \"ka\" on the mesh)"
            } else {
                ""
            };
            return Err(self.err(format!(
                "the scene has no light: no triangle emits and no [[light]] is given{hint}"
            )));
        }
        for s in &self.spheres {
            if self.of_material(&self.emission, s.material)?.max_element() > 0.0 {
                return Err(self.err("emissive spheres are not supported: lights are triangles"));
            }
        }

        let bounds = self.spheres.iter().fold(self.mesh.bounds(), |b, s| {
            b.union_point(s.center - Vec3::splat(s.radius))
                .union_point(s.center + Vec3::splat(s.radius))
        });
        if !infinite.is_empty() && (bounds.is_empty() || !(bounds.max - bounds.min).is_finite()) {
            return Err(self
                .err("a light at infinity needs a scene of finite, non-empty extent to shine on"));
        }
        let Some(light_table) = LightTable::new(&self.mesh, &lights, &deltas, &infinite, bounds)
        else {
            return Err(self.err("the lights' total power is zero: no light can be sampled"));
        };
        if !light_table.total_power().as_vec3().is_finite() {
            return Err(self.err(
                "the lights' total power overflows f32: a light's value is absurd for the scene's size",
            ));
        }
        // The hashes need the whole scene text: `Scene::from_toml` sets them.
        Ok(Scene {
            path: self.scene_path.to_path_buf(),
            file,
            geometry: Geometry::new(self.mesh, self.spheres),
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

    /// The scene file's point and spot lights, checked one by one (Mitsuba 3's `point` and
    /// `spot`; angles in degrees there, radians here).
    fn delta_lights(&self, descs: &[LightDesc]) -> Result<Vec<DeltaLight>, SceneError> {
        let mut out = Vec::with_capacity(descs.len());
        for (i, desc) in descs.iter().enumerate() {
            let bad = |what: &str| self.err(format!("light {i} ({}): {what}", desc.kind()));
            let (position, intensity) = match desc {
                LightDesc::Point {
                    position,
                    intensity,
                }
                | LightDesc::Spot {
                    position,
                    intensity,
                    ..
                } => (Vec3::from(*position), Vec3::from(*intensity)),
                LightDesc::Directional { .. } | LightDesc::Environment { .. } => continue,
            };
            if !position.is_finite() {
                return Err(bad("position must be finite"));
            }
            if !intensity.is_finite() || intensity.min_element() < 0.0 {
                return Err(bad("intensity must be finite and >= 0"));
            }
            if intensity.max_element() <= 0.0 {
                return Err(bad(
                    "intensity must not be zero: the light would emit nothing",
                ));
            }
            let spot = match *desc {
                LightDesc::Point { .. }
                | LightDesc::Directional { .. }
                | LightDesc::Environment { .. } => None,
                LightDesc::Spot {
                    look_at,
                    cutoff_angle,
                    beam_width,
                    ..
                } => {
                    let axis = (Vec3::from(look_at) - position).normalize_or_zero();
                    if !Vec3::from(look_at).is_finite() || axis == Vec3::ZERO {
                        return Err(bad("look_at must be finite and differ from position"));
                    }
                    if !(cutoff_angle > 0.0 && cutoff_angle <= 90.0) {
                        return Err(bad(&format!(
                            "cutoff_angle = {cutoff_angle} must be in (0, 90] degrees"
                        )));
                    }
                    let beam = beam_width.unwrap_or(cutoff_angle * 0.75);
                    if !(beam >= 0.0 && beam <= cutoff_angle) {
                        return Err(bad(&format!(
                            "beam_width = {beam} must be in [0, cutoff_angle = {cutoff_angle}] degrees"
                        )));
                    }
                    Some(Spot {
                        frame: Frame::from_z(axis),
                        cutoff: cutoff_angle.to_radians(),
                        beam: beam.to_radians(),
                    })
                }
            };
            let light = DeltaLight {
                position,
                intensity,
                spot,
            };
            if !light.power().as_vec3().is_finite() {
                return Err(bad("power overflows f32: intensity is absurd"));
            }
            out.push(light);
        }
        Ok(out)
    }

    /// The scene file's directional lights and environment maps, checked one by one, numbered
    /// as in the file like the point and spot lights. An environment image is read (and
    /// hashed) here, relative to the scene file.
    fn infinite_lights(&mut self, descs: &[LightDesc]) -> Result<Vec<InfiniteLight>, SceneError> {
        let mut out = Vec::new();
        for (i, desc) in descs.iter().enumerate() {
            let bad = |b: &Self, what: &str| b.err(format!("light {i} ({}): {what}", desc.kind()));
            match desc {
                LightDesc::Point { .. } | LightDesc::Spot { .. } => {}
                LightDesc::Directional {
                    direction,
                    irradiance,
                    angular_radius,
                } => {
                    let to_light = -Vec3::from(*direction).normalize_or_zero();
                    if !Vec3::from(*direction).is_finite() || to_light == Vec3::ZERO {
                        return Err(bad(self, "direction must be finite and not zero"));
                    }
                    let e = Vec3::from(*irradiance);
                    if !e.is_finite() || e.min_element() < 0.0 {
                        return Err(bad(self, "irradiance must be finite and >= 0"));
                    }
                    if e.max_element() <= 0.0 {
                        return Err(bad(
                            self,
                            "irradiance must not be zero: the light would emit nothing",
                        ));
                    }
                    out.push(match *angular_radius {
                        None => InfiniteLight::Directional {
                            to_light,
                            irradiance: e,
                        },
                        Some(a) if a > 0.0 && a <= 90.0 => {
                            InfiniteLight::sun(to_light, e, a.to_radians())
                        }
                        Some(a) => {
                            return Err(bad(
                                self,
                                &format!("angular_radius = {a} must be in (0, 90] degrees"),
                            ));
                        }
                    });
                }
                LightDesc::Environment {
                    filename,
                    radiance,
                    scale,
                    rotate,
                } => {
                    if !(scale.is_finite() && *scale > 0.0) {
                        return Err(bad(
                            self,
                            &format!("scale = {scale} must be finite and > 0"),
                        ));
                    }
                    let r = Vec3::from(*rotate);
                    if !r.is_finite() {
                        return Err(bad(self, "rotate must be finite"));
                    }
                    let to_world = Mat3::from_rotation_z(r.z.to_radians())
                        * Mat3::from_rotation_y(r.y.to_radians())
                        * Mat3::from_rotation_x(r.x.to_radians());
                    let env = match (filename, radiance) {
                        (Some(_), Some(_)) | (None, None) => {
                            return Err(bad(
                                self,
                                "give either filename (an image) or radiance (a constant colour)",
                            ));
                        }
                        (None, Some(c)) => EnvMap::constant(Vec3::from(*c), *scale, to_world)
                            .map_err(|e| bad(self, &e))?,
                        (Some(f), None) => {
                            let path = self.dir.join(f);
                            let bytes = read_regular(&path).map_err(|e| {
                                bad(
                                    self,
                                    &format!(
                                        "environment map `{f}` ({}): cannot read it: {e}",
                                        path.display()
                                    ),
                                )
                            })?;
                            self.hash.write(&bytes);
                            let t = Texture::decode(&bytes, &path).map_err(|e| {
                                bad(
                                    self,
                                    &format!("environment map `{f}` ({}): {e}", path.display()),
                                )
                            })?;
                            EnvMap::from_image(t.width, t.height, t.texels, *scale, to_world)
                                .map_err(|e| bad(self, &format!("environment map `{f}`: {e}")))?
                        }
                    };
                    out.push(InfiniteLight::Environment(Box::new(env)));
                }
            }
        }
        Ok(out)
    }

    fn validate_materials(&self) -> Result<(), SceneError> {
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

    fn load_mesh(&mut self, index: usize, desc: &MeshDesc) -> Result<(), SceneError> {
        let obj_path = self.dir.join(&desc.obj);
        let bytes = read_regular(&obj_path).map_err(|e| {
            SceneError::new(
                &obj_path,
                format!(
                    "cannot read OBJ file (mesh {index} of {}): {e}",
                    self.scene_path.display()
                ),
            )
        })?;
        self.hash.write(&bytes);

        // tobj asks for MTL files by the name in `mtllib`; read them ourselves so a missing or
        // broken one is reported with its path.
        let obj_dir = obj_path.parent().map(Path::to_path_buf).unwrap_or_default();
        // Every problem below names the file at fault and, after it, the scene that uses it.
        let of = format!("mesh {index} of {}", self.scene_path.display());
        let mtl_error: RefCell<Option<SceneError>> = RefCell::new(None);
        let mtl_bytes: RefCell<Vec<u8>> = RefCell::new(Vec::new());
        let mtl_files: RefCell<Vec<String>> = RefCell::new(Vec::new());
        // Which MTL file defines which materials: problems name the file at fault.
        let mtl_of: RefCell<Vec<(PathBuf, Vec<String>)>> = RefCell::new(Vec::new());
        let loaded = tobj::load_obj_buf(
            &mut BufReader::new(&bytes[..]),
            // Faces come whole and are triangulated here (`polygon`): tobj's fan is wrong for
            // non-convex faces and makes a hopeless BVH of a huge one.
            &tobj::LoadOptions {
                triangulate: false,
                single_index: true,
                ignore_points: true,
                ignore_lines: true,
            },
            |p| {
                let mtl_path = obj_dir.join(p);
                match read_regular(&mtl_path) {
                    Ok(b) => {
                        mtl_bytes.borrow_mut().extend_from_slice(&b);
                        mtl_files.borrow_mut().push(p.display().to_string());
                        let b = match grey_colours(&b) {
                            Ok(b) => b,
                            Err(problem) => {
                                *mtl_error.borrow_mut() = Some(SceneError::new(
                                    &mtl_path,
                                    format!("malformed MTL file: {problem} ({of})"),
                                ));
                                return Err(tobj::LoadError::MaterialParseError);
                            }
                        };
                        tobj::load_mtl_buf(&mut BufReader::new(&b[..]))
                            .inspect(|(mats, _)| {
                                let names = mats.iter().map(|m| m.name.clone()).collect();
                                mtl_of.borrow_mut().push((mtl_path.clone(), names));
                            })
                            .inspect_err(|e| {
                                *mtl_error.borrow_mut() = Some(SceneError::new(
                                    &mtl_path,
                                    format!("malformed MTL file: {e} ({of})"),
                                ));
                            })
                    }
                    Err(e) => {
                        *mtl_error.borrow_mut() = Some(SceneError::new(
                            &mtl_path,
                            format!(
                                "cannot read MTL file named by `mtllib` in {}: {e} ({of})",
                                obj_path.display()
                            ),
                        ));
                        Err(tobj::LoadError::OpenFileFailed)
                    }
                }
            },
        );
        if let Some(e) = mtl_error.into_inner() {
            return Err(e);
        }
        self.hash.write(&mtl_bytes.into_inner());
        let oerr = |problem: String| SceneError::new(&obj_path, format!("{problem} ({of})"));
        let (models, materials) = loaded.map_err(|e| oerr(format!("malformed OBJ file: {e}")))?;
        let materials =
            materials.map_err(|e| oerr(format!("its materials failed to load: {e}")))?;

        // MTL materials → ids (scene-file materials of the same name win).
        let mut mat_ids = Vec::with_capacity(materials.len());
        let defined_in = mtl_of.into_inner();
        for m in &materials {
            let id = match self.by_name.get(&m.name) {
                Some(&id) => id,
                None => {
                    let mtl = defined_in
                        .iter()
                        .rev()
                        .find(|(_, names)| names.contains(&m.name))
                        .map_or(obj_path.clone(), |(p, _)| p.clone());
                    let at = |p: String| format!("{}: material `{}`: {p}", mtl.display(), m.name);
                    let c = convert_mtl(m, desc.emission).map_err(|p| {
                        SceneError::new(&mtl, format!("material `{}`: {p}", m.name))
                    })?;
                    self.warnings.extend(c.warnings.into_iter().map(at));
                    let id = self.add_material(&m.name, c.material, c.emission);
                    if let Some(t) = &c.albedo_map {
                        let image = mtl.parent().unwrap_or(Path::new("")).join(t);
                        let warned = self.attach_albedo_map(id, &image).map_err(|p| {
                            SceneError::new(
                                &mtl,
                                format!(
                                    "material `{}`: `map_Kd {t}`: {}: {p}",
                                    m.name,
                                    image.display()
                                ),
                            )
                        })?;
                        self.warnings.extend(warned.map(at));
                    }
                    id
                }
            };
            mat_ids.push(id);
        }
        self.validate_materials().map_err(|e| oerr(e.problem))?;

        // Each way a face can lack a material has its own message: tobj reports all of them
        // as a model without a material id.
        let directives = obj_directives(&bytes);
        for (line, name) in &directives.usemtl {
            if materials.iter().any(|m| &m.name == name) {
                continue;
            }
            let mtl_files = mtl_files.borrow();
            return Err(oerr(if mtl_files.is_empty() {
                format!(
                    "`usemtl {name}` (line {line}) names a material, but the OBJ names no MTL \
                     file (no `mtllib` line)"
                )
            } else {
                format!(
                    "`usemtl {name}` (line {line}): unknown material; {} define{} {}",
                    mtl_files.join(", "),
                    if mtl_files.len() == 1 { "s" } else { "" },
                    if materials.is_empty() {
                        "none".to_string()
                    } else {
                        materials
                            .iter()
                            .map(|m| format!("`{}`", m.name))
                            .collect::<Vec<_>>()
                            .join(", ")
                    }
                )
            }));
        }
        if models.iter().all(|m| m.mesh.indices.is_empty()) {
            return Err(oerr(if directives.lines == 0 {
                "the OBJ file is empty: no vertices, no faces".to_string()
            } else {
                "the OBJ file holds no faces (no `f` line)".to_string()
            }));
        }

        let xf = transform(desc).ok_or_else(|| {
            self.err(format!(
                "mesh {index} ({}): transform must be finite with a non-zero scale",
                desc.obj
            ))
        })?;
        let nxf = DMat3::from_mat4(xf).inverse().transpose();
        for model in &models {
            let m = &model.mesh;
            if m.indices.is_empty() {
                continue;
            }
            let nv = m.positions.len() / 3;
            let mut part = TriMesh::default();
            for (v, &[x, y, z]) in m.positions.as_chunks::<3>().0.iter().enumerate() {
                let p = DVec3::new(x as f64, y as f64, z as f64);
                if !p.is_finite() {
                    return Err(oerr(format!(
                        "object `{}`: vertex {} is not finite ({:?})",
                        model.name,
                        v + 1,
                        p.to_array()
                    )));
                }
                let q = xf.transform_point3(p);
                if !q.is_finite() || q.abs().max_element() > MAX_COORD {
                    return Err(oerr(format!(
                        "object `{}`: vertex {} lies at {:?} after the mesh's transform, beyond \
                         the {MAX_COORD:e} scene units photonflow can trace: check the scale",
                        model.name,
                        v + 1,
                        q.to_array()
                    )));
                }
                part.positions.push(q.as_vec3());
            }
            let use_file_normals =
                matches!(desc.normals, NormalMode::Auto) && m.normals.len() == 3 * nv;
            if use_file_normals {
                for (v, &[x, y, z]) in m.normals.as_chunks::<3>().0.iter().enumerate() {
                    let n = DVec3::new(x as f64, y as f64, z as f64);
                    let n = (nxf * n).normalize_or_zero();
                    if !n.is_finite() || n == DVec3::ZERO {
                        return Err(oerr(format!(
                            "object `{}`: normal {} is zero or not finite",
                            model.name,
                            v + 1
                        )));
                    }
                    part.normals.push(n.as_vec3());
                }
            }
            let mat = match m.material_id.map(|i| (i, mat_ids.get(i))) {
                Some((_, Some(&id))) => id,
                Some((i, None)) => {
                    return Err(oerr(format!(
                        "object `{}` uses material index {i} that its MTL does not define",
                        model.name
                    )));
                }
                None => {
                    return Err(oerr(format!(
                        "object `{}` has faces before any `usemtl` line, so they have no material",
                        model.name
                    )));
                }
            };
            if m.indices.iter().any(|&i| i as usize >= nv) {
                return Err(oerr(format!(
                    "object `{}`: face index out of range",
                    model.name
                )));
            }
            // All triangles (no arities) or one arity per face.
            let arities: Box<dyn Iterator<Item = usize>> = if m.face_arities.is_empty() {
                Box::new(std::iter::repeat_n(3, m.indices.len() / 3))
            } else {
                Box::new(m.face_arities.iter().map(|&a| a as usize))
            };
            let mut start = 0usize;
            let mut triangles = Vec::new();
            for (f, n) in arities.enumerate() {
                let Some(face) = m.indices.get(start..start.saturating_add(n)) else {
                    return Err(oerr(format!(
                        "object `{}`: face {} runs past the index list",
                        model.name,
                        f + 1
                    )));
                };
                start += n;
                crate::polygon::triangulate(face, &part.positions, &mut triangles)
                    .map_err(|p| oerr(format!("object `{}`, face {}: {p}", model.name, f + 1)))?;
            }
            if m.texcoords.len() == 2 * nv {
                for (v, &[u, w]) in m.texcoords.as_chunks::<2>().0.iter().enumerate() {
                    if !(u.is_finite() && w.is_finite()) {
                        return Err(oerr(format!(
                            "object `{}`: texture coordinate {} is not finite",
                            model.name,
                            v + 1
                        )));
                    }
                    part.texcoords.push(Vec2::new(u, w));
                }
            } else if self
                .albedo_maps
                .get(mat as usize)
                .is_some_and(Option::is_some)
            {
                // Mitsuba 3 reads a mesh without texture coordinates at its barycentrics.
                self.warnings.push(format!(
                    "{}: object `{}` has no texture coordinates (`vt`) for the texture of \
                     material `{}`: read at each triangle's barycentric coordinates",
                    obj_path.display(),
                    model.name,
                    self.names.get(mat as usize).map_or("?", String::as_str)
                ));
            }
            part.materials = vec![mat; triangles.len()];
            part.indices = triangles;
            if desc.normals == NormalMode::Smooth {
                part.normals = smooth_vertex_normals(&part.positions, &part.indices);
            }
            self.mesh.append(&part);
        }
        Ok(())
    }
}

/// Largest coordinate (scene units, after a mesh's transform) of any vertex or sphere. The
/// BVH builder and the intersection code work in f32: surface areas of boxes and edge cross
/// products multiply two coordinate differences (up to (2x)^2, times 6 summed over a box's
/// faces), which overflows f32's 3.4e38 near |x| = 3.7e18, and obvhs panics on the infinite
/// areas. 1e15 keeps three orders of magnitude below that and still admits any real scene
/// in metres or millimetres.
pub const MAX_COORD: f64 = 1e15;

/// Reads a file a scene names, refusing anything but a regular file before opening it:
/// opening a FIFO blocks until a writer comes, and a device may never end.
fn read_regular(path: &Path) -> std::io::Result<Vec<u8>> {
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
    std::fs::read(path)
}

/// An OBJ file's `usemtl` lines (1-based line number, material name, first use of each name)
/// and its number of non-blank, non-comment lines, read as tobj reads them.
struct ObjDirectives {
    usemtl: Vec<(usize, String)>,
    lines: usize,
}

fn obj_directives(bytes: &[u8]) -> ObjDirectives {
    let mut d = ObjDirectives {
        usemtl: Vec::new(),
        lines: 0,
    };
    for (i, line) in String::from_utf8_lossy(bytes).lines().enumerate() {
        let line = line.trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        d.lines += 1;
        if line.split_whitespace().next() == Some("usemtl") {
            let name = line.split_once(' ').unwrap_or_default().1.trim();
            if !name.is_empty() && !d.usemtl.iter().any(|(_, n)| n == name) {
                d.usemtl.push((i + 1, name.to_string()));
            }
        }
    }
    d
}

/// MTL colours (`Ka`, `Kd`, `Ks`, `Ke`, `Tf`) given with one number are grey, a variant real
/// MTL files use: written out as three numbers here, since tobj panics on fewer than three.
/// Two numbers or none is an error naming the line.
fn grey_colours(bytes: &[u8]) -> Result<Vec<u8>, String> {
    let Ok(text) = std::str::from_utf8(bytes) else {
        return Err("not UTF-8 text".into());
    };
    let mut out = String::with_capacity(text.len() + 64);
    for (i, line) in text.split_inclusive('\n').enumerate() {
        let mut words = line.split_whitespace();
        let key = words.next();
        if let Some(key @ ("Ka" | "Kd" | "Ks" | "Ke" | "Tf")) = key {
            let args: Vec<&str> = words.collect();
            let numbers = args.iter().take_while(|w| w.parse::<f32>().is_ok()).count();
            match (args.as_slice(), numbers) {
                ([v], 1) => {
                    out.push_str(&format!("{key} {v} {v} {v}\n"));
                    continue;
                }
                ([], _) | ([_, _], 2) => {
                    return Err(format!(
                        "line {}: `{key}` needs one number (grey) or three (RGB), got {}",
                        i + 1,
                        args.len()
                    ));
                }
                _ => {}
            }
        }
        out.push_str(line);
    }
    Ok(out.into_bytes())
}

fn in_unit(v: Vec3) -> bool {
    v.is_finite() && v.min_element() >= 0.0 && v.max_element() <= 1.0
}

fn non_negative(v: Vec3) -> bool {
    v.is_finite() && v.min_element() >= 0.0
}

/// An MTL material turned into one of photonflow's: the material, its emission, and a line
/// for each thing it approximates (printed as `warning:` lines).
struct Converted {
    material: Material,
    emission: Vec3,
    /// `map_Kd`'s file name, relative to the MTL file.
    albedo_map: Option<String>,
    warnings: Vec<String>,
}

/// MTL keys that change a surface's look but that photonflow does not read: a file that sets
/// one is refused (`error`) or warned about (`warning`), never silently drawn otherwise.
const UNREAD_KEYS: [(&str, &str); 12] = [
    ("Pr", "error"),
    ("Pm", "error"),
    ("Ps", "error"),
    ("Pc", "error"),
    ("Pcr", "error"),
    ("aniso", "error"),
    ("anisor", "error"),
    ("map_Pr", "error"),
    ("map_Pm", "error"),
    ("refl", "warning"),
    ("disp", "warning"),
    ("decal", "warning"),
];

/// The MTL → material mapping of the table in `Material`'s docs (the MTL spec's `illum`
/// models, the course framework's `illum 11` metal and `Ka` emission). `Err` is one line
/// naming the key at fault.
fn convert_mtl(m: &tobj::Material, emission: EmissionSource) -> Result<Converted, String> {
    let v = |a: Option<[f32; 3]>| a.map(Vec3::from).unwrap_or(Vec3::ZERO);
    let mut warnings = Vec::new();
    // The MTL spec multiplies `map_Kd` by `Kd`; a texture without a `Kd` is drawn as it is.
    let albedo_map = m.diffuse_texture.clone();
    let kd = match (m.diffuse, &albedo_map) {
        (None, Some(_)) => Vec3::ONE,
        (kd, _) => v(kd),
    };
    if let Some(t) = &albedo_map {
        if t.trim_start().starts_with('-') {
            return Err(format!(
                "`map_Kd {t}`: texture options (-s, -o, -clamp, ...) are not read; give the \
                 image file alone"
            ));
        }
        if kd == Vec3::ZERO {
            warnings.push(format!(
                "`map_Kd {t}` with `Kd 0 0 0`: the MTL spec multiplies the two, so the surface \
                 is black"
            ));
        }
    }
    let e = match emission {
        EmissionSource::Ke => v(m.emissive),
        EmissionSource::Ka => {
            if let Some(ke) = m.emissive.filter(|k| k.iter().any(|&c| c != 0.0)) {
                return Err(format!(
                    "`Ke {} {} {}` is not read: the scene file reads emission from `Ka` \
                     (emission = \"ka\"); drop `Ke`, or set emission = \"ke\" and move the \
                     emission there",
                    ke[0], ke[1], ke[2]
                ));
            }
            v(m.ambient)
        }
    };
    // `Tr` is `1 - d` (some exporters write one, some the other).
    let tr = match m.unknown_param.get("Tr") {
        Some(t) => Some(
            t.trim()
                .parse::<f32>()
                .map_err(|_| format!("`Tr {t}`: not a number"))?,
        ),
        None => None,
    };
    let opacity = m.dissolve.or(tr.map(|t| 1.0 - t)).unwrap_or(1.0);
    if !(0.0..=1.0).contains(&opacity) {
        return Err(format!("`d`/`Tr`: opacity {opacity} must lie in [0, 1]"));
    }
    let tf_text = m.unknown_param.get("Tf").map_or("", String::as_str);
    let tf = match m.unknown_param.get("Tf") {
        Some(t) => {
            let c: Vec<f32> = t
                .split_whitespace()
                .filter_map(|w| w.parse().ok())
                .collect();
            match c.as_slice() {
                &[r, g, b] if t.split_whitespace().count() == 3 => Some(Vec3::new(r, g, b)),
                _ => {
                    return Err(format!(
                        "`Tf {t}`: needs three numbers (an RGB transmission filter)"
                    ));
                }
            }
        }
        None => None,
    };
    for (key, severity) in UNREAD_KEYS {
        if let Some(val) = m.unknown_param.get(key) {
            let what = format!("`{key} {val}`: photonflow does not read this key");
            if severity == "error" {
                return Err(what);
            }
            warnings.push(format!("{what}; the surface is drawn without it"));
        }
    }
    for (key, tex) in [
        ("map_Ks", &m.specular_texture),
        ("map_d", &m.dissolve_texture),
    ] {
        if let Some(t) = tex {
            return Err(format!(
                "`{key} {t}`: of the texture maps only `map_Kd` is rendered; remove the line \
                 to draw the material's constant value"
            ));
        }
    }
    for (key, tex) in [
        ("bump", &m.normal_texture),
        ("map_Ns", &m.shininess_texture),
    ] {
        if let Some(t) = tex {
            warnings.push(format!(
                "`{key} {t}`: not rendered; the surface is drawn without it"
            ));
        }
    }
    let ni = m.optical_density;
    let ks_given = m.specular.map(Vec3::from);
    let ks = ks_given.unwrap_or(Vec3::ZERO);
    let illum = m.illumination_model;
    let glass_illum = matches!(illum, Some(4 | 6 | 7 | 9));
    // The course's convention: `Ni > 1` on a partly transparent material without an `illum`
    // that says otherwise is glass.
    let course_glass =
        matches!(illum, None | Some(0..=2)) && opacity < 1.0 && ni.is_some_and(|n| n > 1.0);
    if opacity < 1.0 && !(glass_illum || course_glass) {
        return Err(format!(
            "opacity {opacity} (`d`/`Tr`): partly transparent surfaces are rendered only as \
             glass (illum 4, 6, 7 or 9 with `Ni`)"
        ));
    }
    let glassy = glass_illum || course_glass;
    if glassy && tf.is_some_and(|t| !in_unit(t)) {
        return Err(format!(
            "`Tf {tf_text}`: the transmission filter of glass must lie in [0, 1] in each channel"
        ));
    }
    if !glassy && tf.is_some_and(|t| t != Vec3::ONE) {
        warnings.push(format!(
            "`Tf {}`: a transmission filter is read only for glass; illum {} is opaque",
            tf_text,
            illum.map_or("(none)".to_string(), |c| c.to_string())
        ));
    }
    let mirror = |warnings: &mut Vec<String>, why: &str| {
        if !why.is_empty() {
            warnings.push(why.to_string());
        }
        if kd.max_element() > 0.0 {
            warnings.push(format!(
                "`Kd {} {} {}` is not used: illum {} draws a mirror of reflectance `Ks`",
                kd.x,
                kd.y,
                kd.z,
                illum.unwrap_or(0)
            ));
        }
        // The peers' mapping: `Ks`, or a perfect mirror where `Ks` is absent or black.
        let reflectance = if ks.max_element() > 0.0 {
            ks
        } else {
            Vec3::ONE
        };
        Material::Mirror { reflectance }
    };
    let glass = |warnings: &mut Vec<String>, why: &str| {
        if !why.is_empty() {
            warnings.push(why.to_string());
        }
        let ior = match ni {
            Some(n) if n > 1.0 => n,
            _ => {
                warnings.push(format!(
                    "glass without an index above 1 (`Ni {}`): drawn with index 1.5",
                    ni.map_or("absent".to_string(), |n| n.to_string())
                ));
                1.5
            }
        };
        if ks_given.is_some_and(|k| k != Vec3::ONE) {
            warnings.push(format!(
                "`Ks {} {} {}` is not used: glass reflects by the Fresnel equations",
                ks.x, ks.y, ks.z
            ));
        }
        // `Tf` scales refracted light at every crossing: Mitsuba 3's
        // `specular_transmittance`, which the peers' mapping gives it too.
        Material::Dielectric {
            ior,
            transmittance: tf.unwrap_or(Vec3::ONE),
            absorption: Vec3::ZERO,
        }
    };
    let mat = match illum {
        _ if course_glass => glass(&mut warnings, ""),
        Some(2) if ks.max_element() > 0.0 => {
            let ns = m.shininess.unwrap_or(0.0);
            if !(ns.is_finite() && ns >= 0.0) {
                return Err(format!("`Ns {ns}`: the Phong exponent must be >= 0"));
            }
            let (g, scaled) = bsdf::Glossy::from_mtl(kd, ks, ns);
            if scaled {
                warnings.push(format!(
                    "`Kd` + `Ks` exceeds 1 in a channel ({} {} {}): both scaled there to sum \
                     to 1",
                    kd.x + ks.x,
                    kd.y + ks.y,
                    kd.z + ks.z
                ));
            }
            Material::Glossy {
                albedo: g.albedo,
                specular: g.specular,
                // A Phong exponent past 2e8 would be a mirror: the smallest roughness
                // the GGX models take.
                alpha: g.alpha.max(*ALPHA_RANGE.start()),
            }
        }
        None | Some(0..=2) => {
            if ks.max_element() > 0.0 {
                warnings.push(format!(
                    "`Ks {} {} {}` is not drawn: only illum 2 turns on the specular term \
                     (illum {})",
                    ks.x,
                    ks.y,
                    ks.z,
                    illum.map_or("absent".to_string(), |c| c.to_string())
                ));
            }
            Material::Lambertian { albedo: kd }
        }
        Some(3) => mirror(&mut warnings, ""),
        Some(5) => mirror(
            &mut warnings,
            "illum 5 (Fresnel reflection): drawn as a mirror of constant reflectance `Ks`",
        ),
        Some(8) => mirror(
            &mut warnings,
            "illum 8 (reflection without ray tracing): drawn as a ray-traced mirror",
        ),
        Some(4 | 7) => glass(&mut warnings, ""),
        Some(6) => glass(
            &mut warnings,
            "illum 6 (refraction, Fresnel off): drawn as glass with Fresnel reflection",
        ),
        Some(9) => glass(
            &mut warnings,
            "illum 9 (glass without ray-traced reflection): drawn as glass with Fresnel \
             reflection",
        ),
        Some(10) => {
            return Err(
                "illum 10 (a shadow matte: shadows cast onto invisible surfaces) \
                        is not rendered"
                    .into(),
            );
        }
        Some(11) => Material::Metal {
            reflectance: ks_given.unwrap_or(Vec3::ONE),
        },
        Some(c) => {
            return Err(format!(
                "unknown illum code {c} (the MTL spec's 0-10 and the course's 11 metal)"
            ));
        }
    };
    Ok(Converted {
        material: mat,
        emission: e,
        albedo_map,
        warnings,
    })
}

/// Scale, then rotate about x, y, z (degrees), then translate. Built in f64 with entries that
/// are zero to 1e-12 snapped to zero, so a 180-degree turn keeps axis-aligned walls exact.
fn transform(d: &MeshDesc) -> Option<DMat4> {
    let s = match d.scale {
        Scale::Uniform(s) => DVec3::splat(s as f64),
        Scale::PerAxis(a) => DVec3::new(a[0] as f64, a[1] as f64, a[2] as f64),
    };
    let r = DVec3::new(d.rotate[0] as f64, d.rotate[1] as f64, d.rotate[2] as f64);
    let t = DVec3::new(
        d.translate[0] as f64,
        d.translate[1] as f64,
        d.translate[2] as f64,
    );
    if !(s.is_finite() && r.is_finite() && t.is_finite()) || s.x * s.y * s.z == 0.0 {
        return None;
    }
    let rot = DMat3::from_rotation_z(r.z.to_radians())
        * DMat3::from_rotation_y(r.y.to_radians())
        * DMat3::from_rotation_x(r.x.to_radians());
    let snap = |c: DVec3| {
        DVec3::from_array(c.to_array().map(|x| {
            if x.abs() < 1e-12 {
                0.0
            } else if (x.abs() - 1.0).abs() < 1e-12 {
                x.signum()
            } else {
                x
            }
        }))
    };
    let rot = DMat3::from_cols(snap(rot.x_axis), snap(rot.y_axis), snap(rot.z_axis));
    Some(DMat4::from_translation(t) * DMat4::from_mat3(rot * DMat3::from_diagonal(s)))
}

/// 64-bit FNV-1a: a stable, dependency-free content hash (not for security).
struct Fnv(u64);

impl Fnv {
    fn new() -> Fnv {
        Fnv(0xcbf2_9ce4_8422_2325)
    }
    fn write(&mut self, bytes: &[u8]) {
        // Length prefix so ("ab", "c") and ("a", "bc") differ.
        for b in (bytes.len() as u64).to_le_bytes().iter().chain(bytes) {
            self.0 ^= *b as u64;
            self.0 = self.0.wrapping_mul(0x0100_0000_01b3);
        }
    }
    fn finish(&self) -> u64 {
        self.0
    }
}

/// FNV-1a of a byte string (exposed for photon-cache keys built from parameters).
pub fn fnv1a64(bytes: &[u8]) -> u64 {
    let mut h = Fnv::new();
    h.write(bytes);
    h.finish()
}
