//! OBJ meshes: the file read whole (its MTL files through `mtl.rs`), each model's faces
//! under its material handed to `faces.rs` (triangulated, transformed, appended), every
//! problem named with its file and line. `load_mesh`, here, sends each mesh to its reader:
//! this file, `ply.rs` or `shapes.rs`.

use super::Builder;
use super::faces::{FileErr, Polygons};
use super::materials::{MTL_KEYS, Source};
use super::mtl::{convert_mtl, prescan};
use super::objtext::{self, ObjModel};
use super::read_regular;
use super::transform::transform;
use crate::error::SceneError;
use crate::file::{EmissionSource, MeshDesc, TfReading};
use glam::DMat4;
use std::collections::HashMap;
use std::io::BufReader;
use std::path::{Path, PathBuf};

/// An OBJ file as `objtext/` read it, with what its MTL files told.
struct Parsed {
    models: Vec<ObjModel>,
    materials: Vec<tobj::Material>,
    /// The `mtllib` names read, in order.
    mtl_files: Vec<String>,
    /// Which MTL file defines which materials: problems name the file at fault.
    defined_in: Vec<(PathBuf, Vec<String>)>,
    /// The first `usemtl` line of each name, and the number of lines that are neither blank
    /// nor comments.
    usemtl: Vec<(usize, String)>,
    lines: usize,
}

/// Which material a model's faces take: the mesh's own, or their MTL material's id.
enum Faces<'m> {
    Own(u32),
    Mtl(&'m [u32]),
}

/// Makes a problem with the OBJ file into its error (naming the file and the scene).
type ObjErr<'e> = FileErr<'e>;

impl Builder<'_> {
    /// Mesh `index` of the scene file: read (or generated), its materials added, its faces
    /// appended.
    pub(super) fn load_mesh(&mut self, index: usize, desc: &MeshDesc) -> Result<(), SceneError> {
        let own = self.mesh_material(index, desc)?;
        let xf = transform(desc).ok_or_else(|| {
            self.err(format!(
                "mesh {index} ({}): transform must be finite and invertible (a non-zero \
                 scale; `matrix` affine, its last row 0 0 0 1)",
                desc.source()
            ))
        })?;
        match (&desc.obj, &desc.ply, desc.shape) {
            (Some(obj), None, None) => self.load_obj(index, obj, desc, xf, own),
            (None, Some(ply), None) => {
                // A PLY file has no materials: the scene file gives its one.
                let Some(own) = own else {
                    return Err(self.err(format!(
                        "mesh {index} ({ply}): a PLY mesh needs `material = \"name\"`: the file \
                         has no materials (known: {})",
                        self.names.join(", ")
                    )));
                };
                self.load_ply(index, desc, ply, xf, own)
            }
            (None, None, Some(kind)) => self.load_shape(index, kind, desc, xf, own),
            _ => Err(self.err(format!(
                "mesh {index}: give exactly one of `obj` or `ply` (a file) and `shape` \
                 (rectangle, cube, disk)"
            ))),
        }
    }

    fn load_obj(
        &mut self,
        index: usize,
        obj: &str,
        desc: &MeshDesc,
        xf: DMat4,
        own: Option<u32>,
    ) -> Result<(), SceneError> {
        let obj_path = self.dir.join(obj);
        // Every problem below names the file at fault and, after it, the scene that uses it.
        let of = format!("mesh {index} of {}", self.scene_path.display());
        let oerr = |problem: String| SceneError::new(&obj_path, format!("{problem} ({of})"));
        // A mesh given its own material reads no MTL file: every face is that material.
        let parsed = self.parse_obj(index, &obj_path, &of, own.is_none(), &oerr)?;
        let mat_ids = self.mtl_materials(&parsed, &obj_path, desc.emission, desc.tf)?;
        self.validate_materials().map_err(|e| oerr(e.problem))?;
        check_faces(&parsed, own.is_none(), &oerr)?;
        let faces = match own {
            Some(id) => Faces::Own(id),
            None => Faces::Mtl(&mat_ids),
        };
        for model in &parsed.models {
            self.append_model(model, desc, xf, &faces, &obj_path, &oerr)?;
        }
        Ok(())
    }

    /// Reads the OBJ file and the MTL files it names (each through [`prescan`]).
    fn parse_obj(
        &mut self,
        index: usize,
        obj_path: &Path,
        of: &str,
        read_mtl: bool,
        oerr: ObjErr,
    ) -> Result<Parsed, SceneError> {
        let bytes = read_regular(obj_path).map_err(|e| {
            SceneError::new(
                obj_path,
                format!(
                    "cannot read OBJ file (mesh {index} of {}): {e}",
                    self.scene_path.display()
                ),
            )
        })?;

        // tobj asks for MTL files by the name in `mtllib`; read them ourselves so a missing or
        // broken one is reported with its path.
        let obj_dir = obj_path.parent().map(Path::to_path_buf).unwrap_or_default();
        let mut mtl_error: Option<SceneError> = None;
        let mut mtl_bytes: Vec<u8> = Vec::new();
        let mut mtl_files: Vec<String> = Vec::new();
        // Which MTL file defines which materials: problems name the file at fault.
        let mut mtl_of: Vec<(PathBuf, Vec<String>)> = Vec::new();
        let load_mtl = |p: &Path| {
            if !read_mtl {
                return Ok(Default::default());
            }
            let mtl_path = obj_dir.join(p);
            match read_regular(&mtl_path) {
                Ok(b) => {
                    mtl_bytes.extend_from_slice(&b);
                    mtl_files.push(p.display().to_string());
                    let b = match prescan(&b) {
                        Ok(b) => b,
                        Err(problem) => {
                            mtl_error = Some(SceneError::new(
                                &mtl_path,
                                format!("malformed MTL file: {problem} ({of})"),
                            ));
                            return Err(tobj::LoadError::MaterialParseError);
                        }
                    };
                    tobj::load_mtl_buf(&mut BufReader::new(&b[..]))
                        .inspect(|(mats, _)| {
                            let names = mats.iter().map(|m| m.name.clone()).collect();
                            mtl_of.push((mtl_path.clone(), names));
                        })
                        .inspect_err(|e| {
                            mtl_error = Some(SceneError::new(
                                &mtl_path,
                                format!("malformed MTL file: {e} ({of})"),
                            ));
                        })
                }
                Err(e) => {
                    mtl_error = Some(SceneError::new(
                        &mtl_path,
                        format!(
                            "cannot read MTL file named by `mtllib` in {}: {e} ({of})",
                            obj_path.display()
                        ),
                    ));
                    Err(tobj::LoadError::OpenFileFailed)
                }
            }
        };
        // Faces come whole and are triangulated here (`polygon`): a fan is wrong for non-convex
        // faces and makes a hopeless BVH of a huge one. The text is read on every core and its
        // models formed, beside the file's hash (one sequential pass that needs only the
        // bytes): a core done with the one turns to the other, and the hash goes on while the
        // models are formed (one sequential pass too).
        let hash = &mut *self.hash;
        let (loaded, ()) = rayon::join(
            || objtext::form(objtext::read(&bytes, objtext::CHUNK), load_mtl),
            || hash.write(&bytes),
        );
        drop(bytes);
        if let Some(e) = mtl_error {
            return Err(e);
        }
        self.hash.write(&mtl_bytes);
        let text = loaded.map_err(|e| oerr(format!("malformed OBJ file: {e}")))?;
        let materials = text
            .materials
            .map_err(|e| oerr(format!("its materials failed to load: {e}")))?;
        Ok(Parsed {
            models: text.models,
            usemtl: text.usemtl,
            lines: text.lines,
            materials,
            mtl_files,
            defined_in: mtl_of,
        })
    }

    /// The OBJ's MTL materials as material ids (scene-file materials of the same name win),
    /// converted by the MTL table with their textures attached.
    fn mtl_materials(
        &mut self,
        parsed: &Parsed,
        obj_path: &Path,
        emission: EmissionSource,
        tf: TfReading,
    ) -> Result<Vec<u32>, SceneError> {
        let mats = &parsed.materials;
        // tobj's `usemtl` reads the last of several definitions of one name, as other loaders
        // do: an earlier one is skipped (with a warning) and shares the last one's id.
        let mut last: HashMap<&str, (usize, usize)> = HashMap::new();
        for (i, m) in mats.iter().enumerate() {
            let e = last.entry(m.name.as_str()).or_insert((i, 0));
            *e = (i, e.1 + 1);
        }
        let mut ids: Vec<Option<u32>> = Vec::with_capacity(mats.len());
        let defined_in = &parsed.defined_in;
        for (i, m) in mats.iter().enumerate() {
            let Some(&(_, times)) = last.get(m.name.as_str()).filter(|l| l.0 == i) else {
                ids.push(None);
                continue;
            };
            let id = match self.by_name.get(&m.name) {
                Some(&id) => id,
                None => {
                    let mtl = defined_in
                        .iter()
                        .rev()
                        .find(|(_, names)| names.contains(&m.name))
                        .map_or(obj_path.to_path_buf(), |(p, _)| p.clone());
                    let at = |p: String| format!("{}: material `{}`: {p}", mtl.display(), m.name);
                    if times > 1 {
                        self.warnings.push(at(format!(
                            "defined {times} times; the last definition is used, as other \
                             loaders do"
                        )));
                    }
                    let c = convert_mtl(m, emission, tf).map_err(|p| {
                        SceneError::new(&mtl, format!("material `{}`: {p}", m.name))
                    })?;
                    self.warnings.extend(c.warnings.into_iter().map(at));
                    let id = self.add_material(&m.name, c.material, c.emission);
                    if let Some(t) = &c.albedo_map {
                        let image = mtl.parent().unwrap_or(Path::new("")).join(t);
                        let warned = self
                            .attach_albedo_map(id, Source::File(&image), MTL_KEYS)
                            .map_err(|p| {
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
            ids.push(Some(id));
        }
        let of_last = |m: &tobj::Material| {
            let l = last.get(m.name.as_str())?.0;
            ids.get(l).copied().flatten()
        };
        ids.iter()
            .zip(mats)
            .map(|(id, m)| {
                id.or_else(|| of_last(m)).ok_or_else(|| {
                    SceneError::new(
                        obj_path,
                        format!("internal error: material `{}` has no id", m.name),
                    )
                })
            })
            .collect()
    }

    /// One model (an `o`/`g` group) of the OBJ, its faces appended to the scene's mesh
    /// (`faces.rs`) under its material.
    fn append_model(
        &mut self,
        model: &ObjModel,
        desc: &MeshDesc,
        xf: DMat4,
        faces: &Faces,
        obj_path: &Path,
        oerr: ObjErr,
    ) -> Result<(), SceneError> {
        let m = model;
        if m.indices.is_empty() {
            return Ok(());
        }
        let material = match (faces, m.material_id) {
            (Faces::Own(id), _) => *id,
            (Faces::Mtl(ids), Some(i)) => match ids.get(i) {
                Some(&id) => id,
                None => {
                    return Err(oerr(format!(
                        "object `{}` uses material index {i} that its MTL does not define",
                        model.name
                    )));
                }
            },
            (Faces::Mtl(_), None) => {
                return Err(oerr(format!(
                    "object `{}` has faces before any `usemtl` line, so they have no material",
                    model.name
                )));
            }
        };
        let label = format!("object `{}`", model.name);
        let polygons = Polygons {
            label: &label,
            first: 1,
            uv_keys: "`vt`",
            positions: &m.positions,
            normals: &m.normals,
            texcoords: &m.texcoords,
            indices: &m.indices,
            arities: &m.face_arities,
            material,
        };
        self.append_polygons(&polygons, desc, xf, obj_path, oerr)
    }
}

/// Each way a face can lack a material has its own message (tobj reports all of them as a
/// model without a material id); a file without faces is refused.
fn check_faces(parsed: &Parsed, materials_used: bool, oerr: ObjErr) -> Result<(), SceneError> {
    let Parsed {
        models,
        materials,
        mtl_files,
        usemtl,
        lines,
        ..
    } = parsed;
    for (line, name) in usemtl {
        if !materials_used || materials.iter().any(|m| &m.name == name) {
            continue;
        }
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
    if models.iter().all(|m| m.indices.is_empty()) {
        return Err(oerr(if *lines == 0 {
            "the OBJ file is empty: no vertices, no faces".to_string()
        } else {
            "the OBJ file holds no faces (no `f` line)".to_string()
        }));
    }
    Ok(())
}
