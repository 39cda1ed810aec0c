//! Mitsuba 3's plugins as the scene file's tables: each plugin photonflow reads becomes the
//! mesh, sphere, material, light, camera or setting that means the same; each one it does
//! not is refused, naming file, line and element.

use super::props::{Color, Ids, Plugin};
use super::tree::Elem;
use crate::error::SceneError;
use crate::file::{
    CameraDesc, CheckerboardDesc, CheckerboardKind, LightDesc, MaterialDesc, MeshDesc, NormalMode,
    SamplerKind, SceneFile, ShapeKind, SphereDesc, TextureDesc,
};
use glam::{DMat3, DMat4, DVec3};
use std::collections::{BTreeMap, HashMap};
use std::path::{Path, PathBuf};

/// Mitsuba 3's film size when the file gives none.
const DEFAULT_SIZE: (u32, u32) = (768, 576);
/// Longest path photonflow follows when Mitsuba's is unbounded (`max_depth = -1`).
const UNBOUNDED_DEPTH: u32 = 64;

pub(super) struct Converter<'a> {
    ids: &'a Ids<'a>,
    /// The directory of the scene file: the scene file's names are relative to it.
    dir: PathBuf,
    pub file: SceneFile,
    pub warnings: Vec<String>,
    /// Each BSDF element converted once, by its address: shapes sharing a `<ref>` share
    /// the material.
    materials: HashMap<*const Elem, String>,
    /// BSDFs Mitsuba draws black from behind, which photonflow draws alike on both sides.
    one_sided: Vec<String>,
}

impl<'a> Converter<'a> {
    pub fn new(ids: &'a Ids<'a>, path: &Path) -> Converter<'a> {
        let name = path
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        Converter {
            ids,
            dir: path.parent().map(Path::to_path_buf).unwrap_or_default(),
            file: SceneFile {
                name,
                seed: 0,
                camera: CameraDesc {
                    eye: [0.0; 3],
                    look_at: [0.0, 0.0, 1.0],
                    up: [0.0, 1.0, 0.0],
                    vfov: 0.0,
                    width: DEFAULT_SIZE.0,
                    height: DEFAULT_SIZE.1,
                },
                render: Default::default(),
                meshes: Vec::new(),
                spheres: Vec::new(),
                materials: BTreeMap::new(),
                lights: Vec::new(),
                photons: Default::default(),
                estimate: Default::default(),
            },
            warnings: Vec::new(),
            materials: HashMap::new(),
            one_sided: Vec::new(),
        }
    }

    /// The `<scene>`'s children, in order.
    pub fn scene(&mut self, root: &'a Elem) -> Result<(), SceneError> {
        let mut sensor = None;
        for c in &root.children {
            match c.tag.as_str() {
                "sensor" => {
                    if sensor.is_some() {
                        return Err(c.err("a second sensor: photonflow renders one camera"));
                    }
                    sensor = Some(c);
                    self.sensor(c)?;
                }
                "integrator" => self.integrator(c)?,
                "shape" => self.shape(c)?,
                "emitter" => self.emitter(c)?,
                // Declared for `<ref>`s; converted where used.
                "bsdf" | "texture" => {
                    if c.attr("id").is_none() {
                        self.warnings
                            .push(c.warning("has no `id`, so nothing uses it: left out"));
                    }
                }
                _ => {
                    return Err(c.err(
                        "not read by photonflow (it reads <sensor>, <integrator>, <shape>, \
                         <emitter>, <bsdf>, <texture>, <default>, <include>)",
                    ));
                }
            }
        }
        if sensor.is_none() {
            return Err(root.err("has no <sensor>: photonflow needs a camera"));
        }
        if !self.one_sided.is_empty() {
            self.warnings.push(format!(
                "one-sided in Mitsuba 3 (black seen from behind), drawn alike on both sides by \
                 photonflow (wrap in <bsdf type=\"twosided\"> to say so): {}",
                self.one_sided.join(", ")
            ));
        }
        Ok(())
    }

    fn sensor(&mut self, e: &'a Elem) -> Result<(), SceneError> {
        let p = Plugin::new(e, self.ids)?;
        if p.kind != "perspective" {
            return Err(p.err("photonflow has the `perspective` sensor only"));
        }
        let m = p.transform("to_world")?.unwrap_or(DMat4::IDENTITY);
        let lin = DMat3::from_mat4(m);
        if lin.determinant() <= 0.0 {
            return Err(p.err(
                "`to_world` mirrors the view (a negative scale): photonflow's camera cannot",
            ));
        }
        let eye = m.transform_point3(DVec3::ZERO);
        let forward = lin * DVec3::Z;
        let up = lin * DVec3::Y;
        let fov = p
            .float("fov")?
            .ok_or_else(|| p.err("needs `fov` (photonflow does not read `focal_length`)"))?;
        let axis = p.string("fov_axis")?.unwrap_or("x");
        for clip in ["near_clip", "far_clip"] {
            if p.float(clip)?.is_some() {
                self.warnings
                    .push(p.warning(format_args!("`{clip}`: photonflow does not clip: left out")));
            }
        }
        let (w, h) = match p.object("film")? {
            Some(f) => self.film(f)?,
            None => DEFAULT_SIZE,
        };
        if let Some(s) = p.object("sampler")? {
            self.sampler(s)?;
        }
        if !(fov > 0.0 && fov < 180.0) {
            return Err(p.err(format_args!("fov {fov}: must lie in (0, 180) degrees")));
        }
        let (wf, hf) = (w.max(1) as f64, h.max(1) as f64);
        let half = (fov.to_radians() / 2.0).tan();
        // tan(vfov / 2) from the fov along the axis Mitsuba 3 measures it on.
        let tan_v = match axis {
            "x" => half * hf / wf,
            "y" => half,
            "diagonal" => half * hf / wf.hypot(hf),
            "smaller" if w < h => half * hf / wf,
            "smaller" => half,
            "larger" if w > h => half * hf / wf,
            "larger" => half,
            other => {
                return Err(p.err(format_args!(
                    "fov_axis `{other}`: one of x, y, diagonal, smaller, larger"
                )));
            }
        };
        self.file.camera = CameraDesc {
            eye: eye.as_vec3().to_array(),
            look_at: (eye + forward).as_vec3().to_array(),
            up: up.as_vec3().to_array(),
            vfov: (2.0 * tan_v.atan()).to_degrees() as f32,
            width: w,
            height: h,
        };
        p.finish(&mut self.warnings);
        Ok(())
    }

    fn film(&mut self, e: &'a Elem) -> Result<(u32, u32), SceneError> {
        let p = Plugin::new(e, self.ids)?;
        if p.kind != "hdrfilm" {
            return Err(p.err("photonflow has the `hdrfilm` film only"));
        }
        let size = |k: &str, d: u32| -> Result<u32, SceneError> {
            match p.integer(k)? {
                None => Ok(d),
                Some(v) if (1..=1 << 16).contains(&v) => Ok(v as u32),
                Some(v) => Err(p.err(format_args!("{k} {v}: must be in 1..=65536"))),
            }
        };
        let w = size("width", DEFAULT_SIZE.0)?;
        let h = size("height", DEFAULT_SIZE.1)?;
        match p.object("rfilter")? {
            Some(f) => {
                let kind = f.attr("type").unwrap_or("?");
                if kind != "box" {
                    self.warnings.push(f.warning(
                        "photonflow's pixels are box-filtered (each sample counts in its pixel): \
                         drawn with a box",
                    ));
                }
                // A box has no parameters; any other filter's were warned about above.
            }
            None => self.warnings.push(p.warning(
                "no <rfilter>: Mitsuba 3's default is a Gaussian; photonflow's pixels are \
                 box-filtered",
            )),
        }
        // The pixel format is the output's, not the image's: photonflow writes RGB EXR.
        p.ignore("pixel_format");
        p.ignore("component_format");
        p.finish(&mut self.warnings);
        Ok((w, h))
    }

    fn sampler(&mut self, e: &'a Elem) -> Result<(), SceneError> {
        let p = Plugin::new(e, self.ids)?;
        self.file.render.sampler = match p.kind {
            "independent" => SamplerKind::Independent,
            "stratified" | "multijitter" | "orthogonal" | "ldsampler" => {
                self.warnings.push(p.warning(
                    "drawn with photonflow's Owen-scrambled Sobol sampler (the same image \
                     in expectation)",
                ));
                SamplerKind::Sobol
            }
            _ => return Err(p.err("not a sampler photonflow knows")),
        };
        if let Some(n) = p.integer("sample_count")? {
            if !(1..=1 << 24).contains(&n) {
                return Err(p.err(format_args!("sample_count {n}: must be in 1..=16777216")));
            }
            self.file.render.spp = n as u32;
        }
        // Seeds and jitter change the noise, not the image photonflow's seed draws.
        p.ignore("seed");
        p.ignore("jitter");
        p.finish(&mut self.warnings);
        Ok(())
    }

    fn integrator(&mut self, e: &'a Elem) -> Result<(), SceneError> {
        let p = Plugin::new(e, self.ids)?;
        if !matches!(
            p.kind,
            "path" | "volpath" | "volpathmis" | "ptracer" | "direct"
        ) {
            return Err(p.err(
                "photonflow reads the path length of `path`, `volpath`, `volpathmis`, \
                 `ptracer` and `direct` (its own methods do the rendering)",
            ));
        }
        if p.kind == "direct" {
            // Direct light only: one bounce.
            self.file.render.max_depth = 1;
        }
        if let Some(d) = p.integer("max_depth")? {
            // Mitsuba counts segments (1: emitters seen directly), photonflow bounces.
            self.file.render.max_depth = match d {
                -1 => UNBOUNDED_DEPTH,
                1..=1024 => d as u32 - 1,
                _ => return Err(p.err(format_args!("max_depth {d}: must be -1 or in 1..=1024"))),
            };
        }
        if let Some(d) = p.integer("rr_depth")? {
            if !(1..=1024).contains(&d) {
                return Err(p.err(format_args!("rr_depth {d}: must be in 1..=1024")));
            }
            self.file.render.rr_depth = d as u32;
        }
        if p.boolean("hide_emitters")? == Some(true) {
            return Err(p.err("hide_emitters: photonflow always shows the lights it sees"));
        }
        p.finish(&mut self.warnings);
        Ok(())
    }

    /// A file name as the scene file names it: relative to the scene file's directory, from
    /// the directory of the file that wrote it.
    fn path_of(&self, e: &Elem, name: &str) -> String {
        let p = e.at.dir().join(name);
        match p.strip_prefix(&self.dir) {
            Ok(rel) => rel.to_string_lossy().into_owned(),
            Err(_) => p.to_string_lossy().into_owned(),
        }
    }

    fn shape(&mut self, e: &'a Elem) -> Result<(), SceneError> {
        let p = Plugin::new(e, self.ids)?;
        let to_world = p.transform("to_world")?;
        let material = match p.object("bsdf")? {
            Some(b) => self.bsdf(b)?,
            None => self.default_material(),
        };
        let radiance = match p.object("emitter")? {
            Some(em) => {
                let ep = Plugin::new(em, self.ids)?;
                if ep.kind != "area" {
                    return Err(ep.err("a shape carries `area` emitters only"));
                }
                let r = ep.rgb("radiance", [1.0; 3])?;
                ep.finish(&mut self.warnings);
                Some(r)
            }
            None => None,
        };
        let flip = p.boolean("flip_normals")?.unwrap_or(false);
        if p.kind == "sphere" {
            return self.sphere(p, to_world, material, radiance, flip);
        }
        let mut mesh = MeshDesc {
            material: Some(material),
            radiance,
            flip_normals: flip,
            matrix: to_world.map(rows),
            ..MeshDesc::default()
        };
        match p.kind {
            "obj" => {
                let f = p
                    .string("filename")?
                    .ok_or_else(|| p.err("needs `filename`"))?;
                mesh.obj = Some(self.path_of(e, f));
                if p.boolean("flip_tex_coords")? == Some(false) {
                    return Err(p.err(
                        "flip_tex_coords false: photonflow reads OBJ texture coordinates as \
                         Mitsuba 3 does by default",
                    ));
                }
            }
            "rectangle" => mesh.shape = Some(ShapeKind::Rectangle),
            "cube" => mesh.shape = Some(ShapeKind::Cube),
            "disk" => mesh.shape = Some(ShapeKind::Disk),
            "ply" => {
                let f = p
                    .string("filename")?
                    .ok_or_else(|| p.err("needs `filename`"))?;
                mesh.ply = Some(self.path_of(e, f));
            }
            _ => {
                return Err(p.err(
                    "not a shape photonflow reads (obj, ply, rectangle, cube, disk, sphere)",
                ));
            }
        }
        if p.boolean("face_normals")? == Some(true) {
            mesh.normals = NormalMode::Flat;
        }
        p.finish(&mut self.warnings);
        self.file.meshes.push(mesh);
        Ok(())
    }

    fn sphere(
        &mut self,
        p: Plugin<'a>,
        to_world: Option<DMat4>,
        material: String,
        radiance: Option<[f32; 3]>,
        flip: bool,
    ) -> Result<(), SceneError> {
        if radiance.is_some() {
            return Err(p.err(
                "an area emitter on a sphere: photonflow's area lights are triangles (give \
                 the sphere as a mesh)",
            ));
        }
        if flip {
            return Err(p.err("flip_normals on a sphere: photonflow's spheres face outwards"));
        }
        let c = p.point("center")?.unwrap_or(DVec3::ZERO);
        let r = p.float_or("radius", 1.0)?;
        let m = to_world.unwrap_or(DMat4::IDENTITY);
        // The sphere stays analytic only if to_world keeps it a sphere: a rotation and a
        // uniform scale.
        let lin = DMat3::from_mat4(m);
        let s = lin.x_axis.length();
        // LᵀL = s² I: the columns orthogonal and of one length.
        let similar = (lin.transpose() * lin - DMat3::from_diagonal(DVec3::splat(s * s)))
            .to_cols_array()
            .iter()
            .all(|v| v.abs() <= 1e-6 * s * s);
        if !similar || s == 0.0 {
            return Err(p.err(
                "`to_world` stretches the sphere unevenly: photonflow's spheres stay spheres",
            ));
        }
        let centre = m.transform_point3(c);
        self.file.spheres.push(SphereDesc {
            center: centre.as_vec3().to_array(),
            radius: (r.abs() * s) as f32,
            material,
        });
        p.finish(&mut self.warnings);
        Ok(())
    }

    /// Mitsuba 3's BSDF for a shape without one: diffuse, reflectance 0.5.
    fn default_material(&mut self) -> String {
        let name = "default (diffuse 0.5)".to_string();
        self.file
            .materials
            .entry(name.clone())
            .or_insert(MaterialDesc::Lambertian {
                albedo: [0.5; 3],
                emission: [0.0; 3],
                texture: None,
            });
        name
    }

    /// The material a `<bsdf>` becomes, by name (converted once).
    fn bsdf(&mut self, e: &'a Elem) -> Result<String, SceneError> {
        if let Some(n) = self.materials.get(&(e as *const Elem)) {
            return Ok(n.clone());
        }
        let name = match e.attr("id") {
            Some(id) => id.to_string(),
            None => format!("{} (line {})", e.attr("type").unwrap_or("bsdf"), e.at.line),
        };
        let desc = self.material(e, false)?;
        self.file.materials.insert(name.clone(), desc);
        self.materials.insert(e as *const Elem, name.clone());
        Ok(name)
    }

    fn material(&mut self, e: &'a Elem, twosided: bool) -> Result<MaterialDesc, SceneError> {
        let p = Plugin::new(e, self.ids)?;
        let one_sided = |c: &mut Self| {
            if !twosided {
                c.one_sided.push(format!(
                    "{} ({} line {})",
                    e.describe(),
                    e.at.file.display(),
                    e.at.line
                ));
            }
        };
        let desc = match p.kind {
            "twosided" => {
                let inner = p.objects("bsdf")?;
                let [b] = inner.as_slice() else {
                    return Err(p.err(
                        "needs exactly one nested <bsdf> (photonflow draws both sides alike)",
                    ));
                };
                self.material(b, true)?
            }
            "diffuse" => {
                one_sided(self);
                match p.color("reflectance")? {
                    None => MaterialDesc::Lambertian {
                        albedo: [0.5; 3],
                        emission: [0.0; 3],
                        texture: None,
                    },
                    Some(Color::Rgb(albedo)) => MaterialDesc::Lambertian {
                        albedo,
                        emission: [0.0; 3],
                        texture: None,
                    },
                    Some(Color::Texture(t)) => MaterialDesc::Lambertian {
                        albedo: [1.0; 3],
                        emission: [0.0; 3],
                        texture: Some(self.texture(t)?),
                    },
                }
            }
            "dielectric" | "roughdielectric" => {
                let ior = ior(&p, 1.5046)?;
                let transmittance = p.rgb("specular_transmittance", [1.0; 3])?;
                if p.rgb("specular_reflectance", [1.0; 3])? != [1.0; 3] {
                    return Err(p.err(
                        "specular_reflectance other than 1: photonflow's glass reflects by \
                         Fresnel alone",
                    ));
                }
                if p.kind == "dielectric" {
                    MaterialDesc::Dielectric {
                        ior,
                        transmittance,
                        absorption: [0.0; 3],
                    }
                } else {
                    MaterialDesc::RoughDielectric {
                        ior,
                        alpha: self.alpha(&p)?,
                        transmittance,
                        absorption: [0.0; 3],
                    }
                }
            }
            "conductor" | "roughconductor" => {
                one_sided(self);
                let reflectance = p.rgb("specular_reflectance", [1.0; 3])?;
                let (eta, k, material) = conductor_index(&p)?;
                if p.kind == "conductor" {
                    MaterialDesc::Conductor {
                        reflectance,
                        eta,
                        k,
                        material,
                    }
                } else {
                    MaterialDesc::RoughConductor {
                        alpha: self.alpha(&p)?,
                        reflectance,
                        eta,
                        k,
                        material,
                    }
                }
            }
            "thindielectric" => {
                let ior = ior(&p, 1.5046)?;
                MaterialDesc::ThinDielectric {
                    ior,
                    reflectance: p.rgb("specular_reflectance", [1.0; 3])?,
                    transmittance: p.rgb("specular_transmittance", [1.0; 3])?,
                }
            }
            "plastic" | "roughplastic" => {
                one_sided(self);
                let ior = ior(&p, 1.49)?;
                let specular = p.rgb("specular_reflectance", [1.0; 3])?;
                let nonlinear = p.boolean("nonlinear")?.unwrap_or(false);
                let (diffuse, texture) = match p.color("diffuse_reflectance")? {
                    None => ([0.5; 3], None),
                    Some(Color::Rgb(d)) => (d, None),
                    Some(Color::Texture(t)) => ([1.0; 3], Some(self.texture(t)?)),
                };
                if p.kind == "plastic" {
                    MaterialDesc::Plastic {
                        diffuse,
                        specular,
                        ior,
                        nonlinear,
                        texture,
                    }
                } else {
                    MaterialDesc::RoughPlastic {
                        diffuse,
                        specular,
                        ior,
                        alpha: self.alpha(&p)?,
                        nonlinear,
                        texture,
                    }
                }
            }
            _ => {
                return Err(p.err(
                    "not a BSDF photonflow reads (diffuse, dielectric, thindielectric, \
                     roughdielectric, conductor, roughconductor, plastic, roughplastic, \
                     twosided)",
                ));
            }
        };
        p.finish(&mut self.warnings);
        Ok(desc)
    }

    /// A rough model's GGX roughness (`alpha`, or equal `alpha_u` and `alpha_v`).
    fn alpha(&mut self, p: &Plugin<'a>) -> Result<f32, SceneError> {
        match p.string("distribution")?.unwrap_or("beckmann") {
            "ggx" => {}
            "beckmann" => self.warnings.push(p.warning(
                "a Beckmann distribution (Mitsuba 3's default): drawn as GGX of the same alpha",
            )),
            other => return Err(p.err(format_args!("distribution `{other}`: ggx or beckmann"))),
        }
        // Visible-normal sampling changes the noise only.
        p.ignore("sample_visible");
        let a = match (p.float("alpha")?, p.float("alpha_u")?, p.float("alpha_v")?) {
            (Some(a), None, None) => a,
            (None, None, None) => 0.1,
            (None, Some(u), Some(v)) if u == v => u,
            _ => {
                return Err(p.err(
                    "anisotropic roughness (alpha_u other than alpha_v): photonflow's rough \
                     models are isotropic",
                ));
            }
        };
        Ok(a as f32)
    }

    /// A `bitmap` (as its file's name) or `checkerboard` texture, as a scene-file material
    /// reads it.
    fn texture(&mut self, t: &'a Elem) -> Result<TextureDesc, SceneError> {
        let p = Plugin::new(t, self.ids)?;
        let desc = match p.kind {
            "bitmap" => {
                let f = p
                    .string("filename")?
                    .ok_or_else(|| p.err("needs `filename`"))?;
                if p.boolean("raw")? == Some(true) {
                    return Err(p.err(
                        "raw true: photonflow decodes 8- and 16-bit images as sRGB (EXR as \
                         linear)",
                    ));
                }
                match p.string("filter_type")? {
                    None | Some("bilinear") => {}
                    Some(other) => {
                        return Err(p.err(format_args!(
                            "filter_type `{other}`: photonflow reads bilinear"
                        )));
                    }
                }
                match p.string("wrap_mode")? {
                    None | Some("repeat") => {}
                    Some(other) => {
                        return Err(p.err(format_args!("wrap_mode `{other}`: photonflow repeats")));
                    }
                }
                if p.transform("to_uv")?.is_some() {
                    return Err(p.err("a bitmap's to_uv: not read by photonflow"));
                }
                TextureDesc::File(self.path_of(t, f))
            }
            "checkerboard" => {
                let m = p.transform("to_uv")?.unwrap_or(DMat4::IDENTITY);
                // Mitsuba's `to_uv` is a 3 x 3 matrix on (u, v, 1): its first two rows.
                let row = |r: usize| [m.col(0)[r] as f32, m.col(1)[r] as f32, m.col(3)[r] as f32];
                TextureDesc::Checkerboard(CheckerboardDesc {
                    kind: CheckerboardKind::Checkerboard,
                    color0: p.rgb("color0", [0.4; 3])?,
                    color1: p.rgb("color1", [0.2; 3])?,
                    to_uv: [row(0), row(1)],
                })
            }
            _ => return Err(p.err("photonflow reads `bitmap` and `checkerboard` textures")),
        };
        p.finish(&mut self.warnings);
        Ok(desc)
    }

    fn emitter(&mut self, e: &'a Elem) -> Result<(), SceneError> {
        let p = Plugin::new(e, self.ids)?;
        let m = p.transform("to_world")?;
        let at = |v: DVec3| v.as_vec3().to_array();
        let light = match p.kind {
            "point" => {
                let pos = match (p.point("position")?, m) {
                    (Some(x), None) => x,
                    (None, m) => m.unwrap_or_default().transform_point3(DVec3::ZERO),
                    (Some(_), Some(_)) => {
                        return Err(p.err("give `position` or `to_world`, not both"));
                    }
                };
                LightDesc::Point {
                    position: at(pos),
                    intensity: p.rgb("intensity", [1.0; 3])?,
                }
            }
            "spot" => {
                let m = m.unwrap_or_default();
                let cutoff = p.float_or("cutoff_angle", 20.0)? as f32;
                if p.color("texture")?.is_some() {
                    return Err(p.err("a textured spot light: not read by photonflow"));
                }
                LightDesc::Spot {
                    position: at(m.transform_point3(DVec3::ZERO)),
                    look_at: at(m.transform_point3(DVec3::Z)),
                    intensity: p.rgb("intensity", [1.0; 3])?,
                    cutoff_angle: cutoff,
                    beam_width: p.float("beam_width")?.map(|b| b as f32),
                }
            }
            "directional" => {
                let dir = match (p.point("direction")?, m) {
                    (Some(d), None) => d,
                    (None, m) => DMat3::from_mat4(m.unwrap_or_default()) * DVec3::Z,
                    (Some(_), Some(_)) => {
                        return Err(p.err("give `direction` or `to_world`, not both"));
                    }
                };
                LightDesc::Directional {
                    direction: at(dir),
                    irradiance: p.rgb("irradiance", [1.0; 3])?,
                    angular_radius: None,
                }
            }
            "envmap" | "constant" => {
                let rotate = match m {
                    None => [0.0; 3],
                    Some(m) => euler_xyz(&p, m)?,
                };
                if p.kind == "constant" {
                    LightDesc::Environment {
                        filename: None,
                        radiance: Some(p.rgb("radiance", [1.0; 3])?),
                        scale: 1.0,
                        rotate,
                    }
                } else {
                    let f = p
                        .string("filename")?
                        .ok_or_else(|| p.err("needs `filename`"))?;
                    LightDesc::Environment {
                        filename: Some(self.path_of(e, f)),
                        radiance: None,
                        scale: p.float_or("scale", 1.0)? as f32,
                        rotate,
                    }
                }
            }
            "area" => return Err(p.err("an `area` emitter belongs inside a <shape>")),
            _ => {
                return Err(p.err(
                    "not an emitter photonflow reads (area, point, spot, directional, envmap, \
                     constant)",
                ));
            }
        };
        p.finish(&mut self.warnings);
        self.file.lights.push(light);
        Ok(())
    }
}

/// `int_ior / ext_ior`, each a number or one of Mitsuba 3's named materials (`int_ior`
/// defaults to `int_default`, `ext_ior` to air).
fn ior(p: &Plugin, int_default: f64) -> Result<f32, SceneError> {
    let side = |key: &str, default: f64| -> Result<f64, SceneError> {
        if p.tag_of(key) != Some("string") {
            return Ok(p.float(key)?.unwrap_or(default));
        }
        match p.string(key)? {
            None => Ok(default),
            Some(name) => crate::mitsuba_ior(name).map(f64::from).ok_or_else(|| {
                p.err(format_args!(
                    "{key} `{name}`: not one of Mitsuba 3's named indices"
                ))
            }),
        }
    };
    let int = side("int_ior", int_default)?;
    let ext = side("ext_ior", 1.000277)?;
    if !(int > 0.0 && ext > 0.0) {
        return Err(p.err("int_ior and ext_ior must be positive"));
    }
    Ok((int / ext) as f32)
}

/// A conductor's complex index: `eta` and `k` given, or Mitsuba 3's named `material` (the
/// scene file checks the name; `none`, the default, is a perfect mirror).
type Index = (Option<[f32; 3]>, Option<[f32; 3]>, Option<String>);
fn conductor_index(p: &Plugin) -> Result<Index, SceneError> {
    let eta = p.color("eta")?;
    let k = p.color("k")?;
    let material = p.string("material")?;
    match (eta, k, material) {
        (None, None, None) => Ok((None, None, None)),
        (Some(Color::Rgb(e)), Some(Color::Rgb(k)), None) => Ok((Some(e), Some(k), None)),
        (None, None, Some(m)) => {
            if m != "none" && crate::mitsuba_conductor(m).is_none() {
                return Err(p.err(format_args!(
                    "material `{m}`: not one of Mitsuba 3's named conductors"
                )));
            }
            Ok((None, None, Some(m.to_string())))
        }
        _ => Err(p.err("give both `eta` and `k` as <rgb>, or `material`")),
    }
}

/// A 4x4 matrix as the scene file's rows.
fn rows(m: DMat4) -> [[f64; 4]; 4] {
    m.transpose().to_cols_array_2d()
}

/// The scene file's `rotate` (degrees about x, then y, then z) of the rotation `m`.
fn euler_xyz(p: &Plugin, m: DMat4) -> Result<[f32; 3], SceneError> {
    let r = DMat3::from_mat4(m);
    let ortho = (r.transpose() * r - DMat3::IDENTITY)
        .to_cols_array()
        .iter()
        .all(|v| v.abs() < 1e-6);
    if !ortho || r.determinant() < 0.0 || m.w_axis.truncate() != DVec3::ZERO {
        return Err(
            p.err("`to_world` of an environment must be a rotation (no scale, no translation)")
        );
    }
    // R = Rz(c) Ry(b) Rx(a): R[2][0] = -sin b (row 2, column 0).
    let (r20, r21, r22) = (r.x_axis.z, r.y_axis.z, r.z_axis.z);
    let b = (-r20).clamp(-1.0, 1.0).asin();
    let (a, c) = if r20.abs() < 1.0 - 1e-12 {
        (r21.atan2(r22), r.x_axis.y.atan2(r.x_axis.x))
    } else {
        // Gimbal lock: only a - c (or a + c) is defined; put it all in a.
        ((-r.z_axis.y).atan2(r.y_axis.y), 0.0)
    };
    Ok([a, b, c].map(|x| x.to_degrees() as f32))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn euler_angles_rebuild_the_rotation() {
        use crate::xml::tree::Loc;
        let e = Elem {
            tag: "emitter".into(),
            attrs: vec![("type".into(), "envmap".into())],
            children: Vec::new(),
            at: Loc {
                file: std::rc::Rc::new(PathBuf::from("t.xml")),
                line: 1,
            },
        };
        let ids = Ids::new();
        let p = Plugin::new(&e, &ids).unwrap();
        for (axis, angle) in [
            (DVec3::new(1.0, 2.0, 3.0), 40.0f64),
            (DVec3::Y, 90.0),
            (DVec3::new(-1.0, 0.3, 0.2), 170.0),
            (DVec3::X, -30.0),
        ] {
            let m = DMat4::from_axis_angle(axis.normalize(), angle.to_radians());
            let [a, b, c] = euler_xyz(&p, m).unwrap().map(|x| (x as f64).to_radians());
            let back =
                DMat3::from_rotation_z(c) * DMat3::from_rotation_y(b) * DMat3::from_rotation_x(a);
            let d = (back - DMat3::from_mat4(m)).to_cols_array();
            assert!(d.iter().all(|v| v.abs() < 1e-6), "{axis} {angle}: {d:?}");
        }
    }
}
