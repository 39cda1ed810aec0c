//! The scene file's schema. Field names are the TOML keys; `deny_unknown_fields` everywhere.
//!
//! ```toml
//! name = "cornell-spheres"
//! seed = 1
//! [camera]
//! eye = [-6.95, 6.86, 14.026]
//! look_at = [-6.95, 6.86, -6.99]
//! up = [0, 1, 0]
//! vfov = 53.13
//! width = 512
//! height = 512
//! [[mesh]]
//! obj = "CornellBox.obj"      # relative to the scene file
//! scale = 0.025               # a number or [x, y, z]
//! rotate = [0, 180, 0]        # degrees about x, then y, then z
//! emission = "ka"             # the course's MTL files keep emission in Ka
//! [[mesh]]
//! ply = "bunny.ply"           # or a PLY file, whose faces take a scene-file material
//! material = "silver"
//! [[sphere]]
//! center = [-10.505, 2.2907, -9.2368]
//! radius = 2.25
//! material = "silver"
//! [material.silver]
//! type = "metal"
//! reflectance = [0.96, 0.98, 0.96]
//! ```

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

use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

#[derive(Clone, Debug, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct SceneFile {
    #[serde(default)]
    pub name: String,
    /// Seed of every random stream of the run.
    #[serde(default)]
    pub seed: u64,
    pub camera: CameraDesc,
    #[serde(default)]
    pub render: RenderSettings,
    #[serde(default, rename = "mesh")]
    pub meshes: Vec<MeshDesc>,
    #[serde(default, rename = "sphere")]
    pub spheres: Vec<SphereDesc>,
    /// Materials by name. They override MTL materials of the same name.
    #[serde(default, rename = "material")]
    pub materials: BTreeMap<String, MaterialDesc>,
    /// Lights beside the emissive triangles (`[[light]]`: point, spot, directional with or
    /// without a sun disc, environment). Not written back when empty: scenes without them
    /// keep their hashes.
    #[serde(default, rename = "light", skip_serializing_if = "Vec::is_empty")]
    pub lights: Vec<LightDesc>,
    /// Photon-tracing parameters (`[photons]`). Opaque here: `render::settings` reads them
    /// into `emit::EmitParams` (with its own unknown-key check), so this crate stays below
    /// the stages.
    #[serde(default)]
    pub photons: toml::Table,
    /// The photon methods' parameters (`[estimate]`: `[estimate.global]`, `[estimate.splat]`,
    /// `[estimate.sppm]`, ...). Opaque here: `render::settings` types them per method.
    #[serde(default)]
    pub estimate: toml::Table,
}

#[derive(Clone, Debug, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct CameraDesc {
    pub eye: [f32; 3],
    pub look_at: [f32; 3],
    #[serde(default = "default_up")]
    pub up: [f32; 3],
    /// Vertical field of view in degrees.
    pub vfov: f32,
    pub width: u32,
    pub height: u32,
}

fn default_up() -> [f32; 3] {
    [0.0, 1.0, 0.0]
}

impl SceneFile {
    /// Every file name the scene file holds, relative to it unless absolute: meshes (`obj`,
    /// `ply`), image textures, environment maps. For moving a scene file (`convert`, a run's
    /// resolved `scene.toml`) and for cache keys, which read the files' contents instead.
    pub fn file_names_mut(&mut self) -> Vec<&mut String> {
        let mut out: Vec<&mut String> = Vec::new();
        for m in &mut self.meshes {
            out.extend([&mut m.obj, &mut m.ply].into_iter().flatten());
        }
        for m in self.materials.values_mut() {
            if let MaterialDesc::Lambertian {
                texture: Some(TextureDesc::File(t)),
                ..
            }
            | MaterialDesc::Glossy {
                texture: Some(TextureDesc::File(t)),
                ..
            }
            | MaterialDesc::Plastic {
                texture: Some(TextureDesc::File(t)),
                ..
            }
            | MaterialDesc::RoughPlastic {
                texture: Some(TextureDesc::File(t)),
                ..
            } = m
            {
                out.push(t);
            }
        }
        for l in &mut self.lights {
            if let LightDesc::Environment {
                filename: Some(f), ..
            } = l
            {
                out.push(f);
            }
        }
        out
    }
}

/// Eye-pass settings. Every field has a default so a scene file may leave it out.
#[derive(Clone, Debug, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields, default)]
pub struct RenderSettings {
    /// Samples per pixel of the path tracer.
    pub spp: u32,
    /// Longest path (number of bounces) before it is cut.
    pub max_depth: u32,
    /// Russian roulette starts after this many bounces.
    pub rr_depth: u32,
    /// Where the path tracer's pixel samples draw their numbers (see [`SamplerKind`]).
    pub sampler: SamplerKind,
    /// Tile edge in pixels for parallel rendering (does not change the image).
    pub tile: u32,
    /// What `render` does without `--method` (see [`Method`]).
    pub method: Method,
    /// Whether the path tracer estimates the paths photon splatting owns, `L S+ D S* E` with
    /// `D` the first diffuse vertex from the eye (the `caustic` layer); off leaves exactly
    /// those out, so a splatted caustic layer can be composited in their place.
    pub caustics: bool,
}

/// The path tracer's sampler. `sobol`: the padded Owen-scrambled Sobol sequence, each
/// pixel's samples stratified in every pair of dimensions (less error per sample on smooth
/// integrands; the default). `independent`: a fresh PCG stream per pixel sample.
#[derive(Clone, Copy, Debug, Default, Deserialize, Serialize, PartialEq, Eq)]
#[serde(rename_all = "kebab-case")]
pub enum SamplerKind {
    #[default]
    Sobol,
    Independent,
}

/// How an image is made. The one place method names are spelled: the scene file, the
/// command line (`--method`, parsed through serde) and every output's JSON use these.
/// A photon method's knobs live in the scene file's `[estimate]` table.
#[derive(Clone, Copy, Debug, Default, Deserialize, Serialize, PartialEq, Eq, Hash)]
#[serde(rename_all = "kebab-case")]
pub enum Method {
    /// The path-traced reference (`render.spp`, `render.caustics`).
    Path,
    /// The global photon map shown directly at the first diffuse surface seen.
    GlobalDirect,
    /// The course framework's standard: direct light + caustic map + final gathering into
    /// the global map.
    FinalGather,
    /// The caustic layer alone, `L S+ D S* E`, by photon differential splatting onto eye
    /// vertices (no photon map); composite it with any method that leaves it out.
    CausticSplat,
    /// The path tracer without the paths splatting owns, plus the splatted caustic layer.
    #[serde(rename = "path+splat")]
    PathSplat,
    /// Stochastic progressive photon mapping (Hachisuka and Jensen 2009): visible points per
    /// pixel, photons in passes, radii shrinking per pixel; consistent.
    Sppm,
    /// Light tracing: light paths connected to the camera at every non-delta vertex
    /// (`[estimate.light]`); sharp caustics without a density estimate.
    Light,
    /// Vertex connection and merging (Georgiev et al. 2012): path tracing, next-event
    /// estimation, light tracing, merging (and, on request, bidirectional connections),
    /// weighted per path by MIS (`[estimate.vcm]`). The default: it reaches a given error
    /// first on the worksheet box and McGuire's boxes at every budget of `cargo xtask bench
    /// accuracy` (docs/benchmarks.md).
    #[default]
    Vcm,
}

impl Method {
    /// Every method, in declaration order.
    pub const ALL: [Method; 8] = [
        Method::Path,
        Method::GlobalDirect,
        Method::FinalGather,
        Method::CausticSplat,
        Method::PathSplat,
        Method::Sppm,
        Method::Light,
        Method::Vcm,
    ];

    /// The method's name as the scene file spells it.
    pub fn name(self) -> String {
        // A unit variant serialises to its name; serde is the one spelling.
        match toml::Value::try_from(self) {
            Ok(toml::Value::String(s)) => s,
            _ => format!("{self:?}"),
        }
    }
}

impl std::fmt::Display for Method {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.name())
    }
}

impl std::str::FromStr for Method {
    type Err = String;
    fn from_str(s: &str) -> Result<Method, String> {
        use serde::de::IntoDeserializer;
        let de: serde::de::value::StrDeserializer<'_, serde::de::value::Error> =
            s.into_deserializer();
        Method::deserialize(de).map_err(|_| {
            let known: Vec<String> = Method::ALL.iter().map(|m| m.name()).collect();
            format!("unknown method `{s}` (known: {})", known.join(", "))
        })
    }
}

impl Default for RenderSettings {
    fn default() -> Self {
        RenderSettings {
            spp: 16,
            max_depth: 64,
            rr_depth: 5,
            sampler: SamplerKind::Sobol,
            tile: 16,
            method: Method::default(),
            caustics: true,
        }
    }
}

/// Where the MTL files keep emitted radiance.
#[derive(Clone, Copy, Debug, Default, Deserialize, Serialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum EmissionSource {
    /// `Ke`, the MTL standard.
    #[default]
    Ke,
    /// `Ka`, the course framework's convention.
    Ka,
}

/// How an OBJ mesh's MTL files mean `Tf` on glass (illum 4, 6, 7, 9): what each crossing of
/// the surface keeps is `Tf` or `1 - Tf`.
#[derive(Clone, Copy, Debug, Default, Deserialize, Serialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum TfReading {
    /// `Tf` is the fraction transmitted (the Wavefront MTL spec's transmission filter).
    #[default]
    Transmitted,
    /// `Tf` is the fraction taken away: the glass keeps `1 - Tf`, as G3D reads it (Morgan
    /// McGuire's renderer; the Cornell boxes of his Computer Graphics Archive are written so).
    Absorbed,
}

impl TfReading {
    fn is_default(&self) -> bool {
        *self == TfReading::default()
    }
}

/// How vertex normals are obtained.
#[derive(Clone, Copy, Debug, Default, Deserialize, Serialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum NormalMode {
    /// The file's normals if it has them, else flat.
    #[default]
    Auto,
    /// Face normals only.
    Flat,
    /// Angle-weighted vertex normals computed at load (ignores the file's normals).
    Smooth,
}

#[derive(Clone, Debug, Deserialize, Serialize, PartialEq)]
#[serde(untagged)]
pub enum Scale {
    Uniform(f32),
    PerAxis([f32; 3]),
}

impl Default for Scale {
    fn default() -> Self {
        Scale::Uniform(1.0)
    }
}

/// A mesh: an OBJ file (`obj`) or a generated shape (`shape`), placed by scale, rotation,
/// translation and then `matrix`. New keys are not written back when unset, so the scene
/// files that predate them keep their hashes.
#[derive(Clone, Debug, Default, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct MeshDesc {
    /// OBJ file, relative to the scene file.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub obj: Option<String>,
    /// PLY file, relative to the scene file, instead of `obj`: its faces take `material`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ply: Option<String>,
    /// A generated shape instead of a file (Mitsuba 3's `rectangle`, `cube`, `disk`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub shape: Option<ShapeKind>,
    #[serde(default)]
    pub scale: Scale,
    /// Rotation in degrees about x, then y, then z.
    #[serde(default)]
    pub rotate: [f32; 3],
    #[serde(default)]
    pub translate: [f32; 3],
    /// A 4x4 matrix (rows) applied after scale, rotation and translation: Mitsuba 3's
    /// `to_world`, as `convert` writes it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub matrix: Option<[[f64; 4]; 4]>,
    /// A scene-file material for every face, in place of the OBJ's own (whose MTL files
    /// are then not read).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub material: Option<String>,
    /// Emitted radiance (per channel) from the front of every face, the side its winding
    /// (counter-clockwise) faces: Mitsuba 3's `area` emitter. Needs `material`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub radiance: Option<[f32; 3]>,
    /// Reverses every face (and vertex normal): front and back swap.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub flip_normals: bool,
    #[serde(default)]
    pub emission: EmissionSource,
    #[serde(default)]
    pub normals: NormalMode,
    /// How the MTL's `Tf` is read on glass (default: the fraction transmitted). Left out of
    /// the serialized file when default, so scenes without it keep their hashes.
    #[serde(default, skip_serializing_if = "TfReading::is_default")]
    pub tf: TfReading,
}

/// Shapes a mesh can be generated as, each in its own space as Mitsuba 3 defines it.
#[derive(Clone, Copy, Debug, Deserialize, Serialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum ShapeKind {
    /// The square [-1, 1]^2 at z = 0, facing +z.
    Rectangle,
    /// The cube [-1, 1]^3, faces outwards.
    Cube,
    /// The unit disc at z = 0, facing +z (a fan of 256 triangles of the disc's area: a warning says so).
    Disk,
}

impl MeshDesc {
    /// What the mesh is made from, for messages: its file or its shape.
    pub fn source(&self) -> String {
        match (&self.obj, &self.ply, self.shape) {
            (Some(o), _, _) | (None, Some(o), _) => o.clone(),
            (None, None, Some(s)) => format!("{s:?}").to_lowercase(),
            (None, None, None) => "no source".into(),
        }
    }
}

#[derive(Clone, Debug, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct SphereDesc {
    pub center: [f32; 3],
    pub radius: f32,
    pub material: String,
}

/// A light that is not a mesh, in Mitsuba 3's units: `intensity` is radiant intensity
/// (W/sr per channel), angles are degrees.
#[derive(Clone, Debug, Deserialize, Serialize, PartialEq)]
#[serde(tag = "type", rename_all = "snake_case", deny_unknown_fields)]
pub enum LightDesc {
    /// Mitsuba 3's `point`: intensity `intensity` in every direction (pbrt-v4 §12.1).
    Point {
        position: [f32; 3],
        intensity: [f32; 3],
    },
    /// Mitsuba 3's `spot`: full intensity within `beam_width` of the axis towards `look_at`,
    /// falling linearly in angle to zero at `cutoff_angle` (pbrt-v4 §12.2 uses a smoothstep
    /// in cos θ instead; we follow Mitsuba).
    Spot {
        position: [f32; 3],
        look_at: [f32; 3],
        intensity: [f32; 3],
        #[serde(default = "default_cutoff")]
        cutoff_angle: f32,
        /// Default `cutoff_angle * 3/4`.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        beam_width: Option<f32>,
    },
    /// Mitsuba 3's `directional`: parallel light travelling along `direction`, `irradiance`
    /// (W/m² per channel) on a surface facing it (pbrt-v4 §12.4). With `angular_radius`
    /// (degrees, > 0) it is a sun disc of that radius and uniform radiance instead, which
    /// rays can hit and which casts soft shadows.
    Directional {
        direction: [f32; 3],
        irradiance: [f32; 3],
        #[serde(default, skip_serializing_if = "Option::is_none")]
        angular_radius: Option<f32>,
    },
    /// Light from infinitely far away: Mitsuba 3's `envmap` (a lat-long EXR or Radiance HDR
    /// image of radiance, `filename` relative to the scene file, times `scale`) or, with
    /// `radiance` instead, its `constant`. `rotate` turns it about x, y, z (degrees), as a
    /// mesh's `rotate` does: Mitsuba's `to_world`.
    Environment {
        #[serde(default, skip_serializing_if = "Option::is_none")]
        filename: Option<String>,
        #[serde(default, skip_serializing_if = "Option::is_none")]
        radiance: Option<[f32; 3]>,
        #[serde(default = "default_scale")]
        scale: f32,
        #[serde(default)]
        rotate: [f32; 3],
    },
}

impl LightDesc {
    /// The `type` key's value, for messages.
    pub fn kind(&self) -> &'static str {
        match self {
            LightDesc::Point { .. } => "point",
            LightDesc::Spot { .. } => "spot",
            LightDesc::Directional { .. } => "directional",
            LightDesc::Environment { .. } => "environment",
        }
    }
}

fn default_scale() -> f32 {
    1.0
}

fn default_cutoff() -> f32 {
    20.0
}

/// A material written in the scene file.
#[derive(Clone, Debug, Deserialize, Serialize, PartialEq)]
#[serde(tag = "type", rename_all = "snake_case", deny_unknown_fields)]
pub enum MaterialDesc {
    Lambertian {
        albedo: [f32; 3],
        #[serde(default)]
        emission: [f32; 3],
        /// An albedo texture that `albedo` multiplies, as MTL's `Kd` multiplies `map_Kd`: an
        /// image (PNG, JPEG, TGA or EXR, relative to the scene file) or a checkerboard.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        texture: Option<TextureDesc>,
    },
    Mirror {
        #[serde(default = "one3")]
        reflectance: [f32; 3],
    },
    Metal {
        reflectance: [f32; 3],
    },
    /// Smooth glass of index `ior`: `transmittance` (each in [0, 1]) scales refracted light
    /// at every crossing (Mitsuba 3's `specular_transmittance`); `absorption` (>= 0, per
    /// scene unit) attenuates light inside by `exp(-absorption * distance)` (Beer-Lambert).
    Dielectric {
        ior: f32,
        #[serde(default = "one3", skip_serializing_if = "is_one3")]
        transmittance: [f32; 3],
        #[serde(default, skip_serializing_if = "is_zero3")]
        absorption: [f32; 3],
    },
    /// A Lambertian `albedo` plus a GGX lobe of constant reflectance `specular` (no Fresnel)
    /// and roughness `alpha`: MTL `illum 2` given directly.
    Glossy {
        albedo: [f32; 3],
        specular: [f32; 3],
        alpha: f32,
        /// An albedo texture for the Lambertian part, as `lambertian`'s.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        texture: Option<TextureDesc>,
    },
    /// A rough metal (GGX, roughness `alpha`): reflectance `reflectance` times the Fresnel
    /// term of the complex index `eta + i k` where both are given, else times 1 (Mitsuba 3's
    /// `roughconductor`).
    RoughConductor {
        alpha: f32,
        #[serde(default = "one3")]
        reflectance: [f32; 3],
        #[serde(default)]
        eta: Option<[f32; 3]>,
        #[serde(default)]
        k: Option<[f32; 3]>,
        /// Mitsuba 3's named conductor (`"Au"`, `"Cu"`, ...: [`crate::mitsuba_conductor`])
        /// in place of `eta` and `k`; `"none"` is `reflectance` alone.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        material: Option<String>,
    },
    /// A polished metal (Mitsuba 3's `conductor`): specular reflection of `reflectance`
    /// times the Fresnel term of the complex index `eta + i k` where both are given, or of
    /// Mitsuba's named `material`, else times 1.
    Conductor {
        #[serde(default = "one3", skip_serializing_if = "is_one3")]
        reflectance: [f32; 3],
        #[serde(default, skip_serializing_if = "Option::is_none")]
        eta: Option<[f32; 3]>,
        #[serde(default, skip_serializing_if = "Option::is_none")]
        k: Option<[f32; 3]>,
        #[serde(default, skip_serializing_if = "Option::is_none")]
        material: Option<String>,
    },
    /// A `diffuse` base under a smooth dielectric coating of index `ior` (Mitsuba 3's
    /// `plastic`, `int_ior` over `ext_ior`): the coating's delta reflection times `specular`,
    /// the base seen through it with its internal reflections summed (`nonlinear`: Mitsuba's
    /// colour shift of those reflections). `texture` as `lambertian`'s, on `diffuse`.
    Plastic {
        diffuse: [f32; 3],
        #[serde(default = "one3", skip_serializing_if = "is_one3")]
        specular: [f32; 3],
        #[serde(default = "plastic_ior")]
        ior: f32,
        #[serde(default, skip_serializing_if = "is_false")]
        nonlinear: bool,
        #[serde(default, skip_serializing_if = "Option::is_none")]
        texture: Option<TextureDesc>,
    },
    /// [`MaterialDesc::Plastic`] under a GGX coating of roughness `alpha` (Mitsuba 3's
    /// `roughplastic` with `distribution = "ggx"`).
    RoughPlastic {
        diffuse: [f32; 3],
        #[serde(default = "one3", skip_serializing_if = "is_one3")]
        specular: [f32; 3],
        #[serde(default = "plastic_ior")]
        ior: f32,
        #[serde(default = "rough_plastic_alpha")]
        alpha: f32,
        #[serde(default, skip_serializing_if = "is_false")]
        nonlinear: bool,
        #[serde(default, skip_serializing_if = "Option::is_none")]
        texture: Option<TextureDesc>,
    },
    /// A thin slab of index `ior` (Mitsuba 3's `thindielectric`): reflects with the slab's
    /// summed Fresnel reflectance, transmits the rest straight through. `reflectance` and
    /// `transmittance` are factors on the two lobes.
    ThinDielectric {
        #[serde(default = "thin_ior")]
        ior: f32,
        #[serde(default = "one3", skip_serializing_if = "is_one3")]
        reflectance: [f32; 3],
        #[serde(default = "one3", skip_serializing_if = "is_one3")]
        transmittance: [f32; 3],
    },
    /// Rough glass (GGX, roughness `alpha`) of index `ior` (Mitsuba 3's `roughdielectric`),
    /// with the smooth glass's `transmittance` and `absorption`.
    RoughDielectric {
        ior: f32,
        alpha: f32,
        #[serde(default = "one3", skip_serializing_if = "is_one3")]
        transmittance: [f32; 3],
        #[serde(default, skip_serializing_if = "is_zero3")]
        absorption: [f32; 3],
    },
}

/// A material's albedo texture: an image file's name, or a table for a procedural one.
#[derive(Clone, Debug, Deserialize, Serialize, PartialEq)]
#[serde(untagged)]
pub enum TextureDesc {
    /// An image, relative to the scene file.
    File(String),
    Checkerboard(CheckerboardDesc),
}

/// Mitsuba 3's `checkerboard`: `color0` where the fractional parts of the texture
/// coordinates (after `to_uv`) are both below or both above one half, `color1` elsewhere
/// (`texture = { type = "checkerboard", ... }`).
#[derive(Clone, Debug, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct CheckerboardDesc {
    #[serde(rename = "type")]
    pub kind: CheckerboardKind,
    #[serde(default = "checker0")]
    pub color0: [f32; 3],
    #[serde(default = "checker1")]
    pub color1: [f32; 3],
    /// Rows of the affine map from the surface's texture coordinates (as Mitsuba gives them:
    /// `v = 0` at an image's top) to the pattern's.
    #[serde(default = "identity_uv")]
    pub to_uv: [[f32; 3]; 2],
}

#[derive(Clone, Copy, Debug, Deserialize, Serialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum CheckerboardKind {
    Checkerboard,
}

fn checker0() -> [f32; 3] {
    [0.4; 3]
}

fn checker1() -> [f32; 3] {
    [0.2; 3]
}

fn identity_uv() -> [[f32; 3]; 2] {
    [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]
}

fn one3() -> [f32; 3] {
    [1.0; 3]
}

/// Mitsuba 3's default plastic coating: polypropylene (1.49) in air (1.000277).
fn plastic_ior() -> f32 {
    1.49 / 1.000_277
}

/// Mitsuba 3's default thin slab: BK7 glass (1.5046) in air (1.000277).
fn thin_ior() -> f32 {
    1.5046 / 1.000_277
}

/// Mitsuba 3's default `alpha` of `roughplastic`.
fn rough_plastic_alpha() -> f32 {
    0.1
}

fn is_false(b: &bool) -> bool {
    !*b
}

// Defaults are not written back: the hashes of a scene without coloured glass (its caches,
// its images' metadata) stay what they were before the keys existed.
fn is_one3(v: &[f32; 3]) -> bool {
    *v == [1.0; 3]
}

fn is_zero3(v: &[f32; 3]) -> bool {
    *v == [0.0; 3]
}
