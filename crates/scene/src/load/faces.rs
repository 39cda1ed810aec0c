//! What every mesh file shares once read: its vertices checked finite and put through the
//! mesh's transform, its normals through the inverse transpose (or replaced by `normals`),
//! its texture coordinates kept, its polygons triangulated (`polygon.rs`), turned over by
//! `flip_normals`, and written into the scene's mesh (on every core, with no copy of the
//! part). `obj.rs` and `ply.rs` each read their format into a [`Polygons`] and hand it here,
//! so both formats load the same faces the same way.

use super::{Builder, MAX_COORD};
use crate::error::SceneError;
use crate::file::{MeshDesc, NormalMode};
use geom::smooth_vertex_normals;
use glam::{DMat3, DMat4, DVec3, Vec2, Vec3};
use rayon::prelude::*;
use std::path::Path;

/// Makes a problem with a mesh file into its error (naming the file and the scene).
pub(super) type FileErr<'e> = &'e dyn Fn(String) -> SceneError;

/// A mesh file's polygons as its reader found them, over one material.
pub(super) struct Polygons<'a, P> {
    /// Who they are in messages (`object `floor``), or empty where the file is one object.
    pub label: &'a str,
    /// The number the file gives its first vertex (OBJ 1, PLY 0), for messages.
    pub first: usize,
    /// How the file names texture coordinates, for the warning when a texture lacks them.
    pub uv_keys: &'a str,
    /// x, y, z per vertex.
    pub positions: &'a [P],
    /// x, y, z per vertex, or none (any other length is ignored).
    pub normals: &'a [P],
    /// u, v per vertex, or none (any other length is ignored).
    pub texcoords: &'a [f32],
    /// The faces' vertex indices, one face after another.
    pub indices: &'a [u32],
    /// Each face's number of vertices; empty when every face is a triangle.
    pub arities: &'a [u32],
    /// The faces' material.
    pub material: u32,
}

impl<P: Copy + Into<f64>> Polygons<'_, P> {
    /// `what` about these polygons: `object `floor`: what`, or `what` alone.
    fn at(&self, what: String) -> String {
        if self.label.is_empty() {
            what
        } else {
            format!("{}: {what}", self.label)
        }
    }

    /// Vertex `v` (from 0) as the file numbers it.
    fn number(&self, v: usize) -> usize {
        v + self.first
    }
}

/// Three values from `c` as a point in f64.
fn dvec3<P: Copy + Into<f64>>(&[x, y, z]: &[P; 3]) -> DVec3 {
    DVec3::new(x.into(), y.into(), z.into())
}

impl Builder<'_> {
    /// `p`'s faces triangulated, its vertices and normals transformed by `xf`, appended to
    /// the scene's mesh. `file` is the mesh file, for warnings.
    pub(super) fn append_polygons<P: Copy + Into<f64> + Sync>(
        &mut self,
        p: &Polygons<P>,
        desc: &MeshDesc,
        xf: DMat4,
        file: &Path,
        oerr: FileErr,
    ) -> Result<(), SceneError> {
        if p.indices.is_empty() {
            return Ok(());
        }
        let nxf = DMat3::from_mat4(xf).inverse().transpose();
        let nv = p.positions.len() / 3;
        // The part is written straight into the scene's mesh on every core: no copy of it is
        // made, and no part of the mesh is moved. An error ends the load, so a part left half
        // written is never seen.
        let mesh = &mut self.mesh;
        let base = mesh.positions.len();
        let corners = p.positions.as_chunks::<3>().0;
        let placed = |c: &[P; 3]| {
            let q = xf.transform_point3(dvec3(c));
            let ok = dvec3(c).is_finite() && q.is_finite() && q.abs().max_element() <= MAX_COORD;
            ok.then(|| q.as_vec3())
        };
        // A vertex that fails is NaN here (no placed vertex is) and found again below.
        let nan = Vec3::splat(f32::NAN);
        (mesh.positions).par_extend(corners.par_iter().map(|c| placed(c).unwrap_or(nan)));
        let positions = mesh.positions.get(base..).unwrap_or_default();
        // The first vertex that failed, and why.
        if let Some(v) = positions.par_iter().position_first(|q| q.x.is_nan()) {
            let q = corners.get(v).map(dvec3).unwrap_or(DVec3::NAN);
            let why = if q.is_finite() {
                format!(
                    "lies at {:?} after the mesh's transform, beyond the {MAX_COORD:e} scene \
                     units photonflow can trace: check the scale",
                    xf.transform_point3(q).to_array()
                )
            } else {
                format!("is not finite ({:?})", q.to_array())
            };
            return Err(oerr(p.at(format!("vertex {} {why}", p.number(v)))));
        }
        let mut normals = Vec::new();
        if matches!(desc.normals, NormalMode::Auto) && p.normals.len() == 3 * nv {
            let turned = |c: &[P; 3]| {
                let n = (nxf * dvec3(c)).normalize_or_zero();
                (n.is_finite() && n != DVec3::ZERO).then(|| n.as_vec3())
            };
            let given = p.normals.as_chunks::<3>().0;
            normals = given.par_iter().map(|c| turned(c).unwrap_or(nan)).collect();
            if let Some(v) = normals.par_iter().position_first(|n| n.x.is_nan()) {
                return Err(oerr(
                    p.at(format!("normal {} is zero or not finite", p.number(v))),
                ));
            }
        }
        if p.indices.par_iter().any(|&i| i as usize >= nv) {
            return Err(oerr(p.at("face index out of range".to_string())));
        }
        // Every face a triangle (`triangulate` would push each as it is), or the faces
        // triangulated.
        let mut triangulated = Vec::new();
        let mut start = 0usize;
        for (f, &n) in p.arities.iter().enumerate() {
            let (f, n) = (p.number(f), n as usize);
            let Some(face) = p.indices.get(start..start.saturating_add(n)) else {
                return Err(oerr(p.at(format!("face {f} runs past the index list"))));
            };
            start += n;
            crate::polygon::triangulate(face, positions, &mut triangulated).map_err(|e| {
                oerr(if p.label.is_empty() {
                    format!("face {f}: {e}")
                } else {
                    format!("{}, face {f}: {e}", p.label)
                })
            })?;
        }
        let triangles = match p.arities {
            [] => p.indices.as_chunks::<3>().0,
            _ => &triangulated[..],
        };
        let mut texcoords = Vec::new();
        if p.texcoords.len() == 2 * nv {
            let uv = p.texcoords.as_chunks::<2>().0;
            if let Some(v) = uv
                .par_iter()
                .position_first(|c| !c.iter().all(|x| x.is_finite()))
            {
                return Err(oerr(
                    p.at(format!("texture coordinate {} is not finite", p.number(v))),
                ));
            }
            texcoords = uv.par_iter().map(|&[u, w]| Vec2::new(u, w)).collect();
        } else if self
            .albedo_maps
            .get(p.material as usize)
            .is_some_and(Option::is_some)
        {
            // Mitsuba 3 reads a mesh without texture coordinates at its barycentrics.
            let who = if p.label.is_empty() {
                "the mesh".to_string()
            } else {
                p.label.to_string()
            };
            self.warnings.push(format!(
                "{}: {who} has no texture coordinates ({}) for the texture of material `{}`: \
                 read at each triangle's barycentric coordinates",
                file.display(),
                p.uv_keys,
                self.names
                    .get(p.material as usize)
                    .map_or("?", String::as_str)
            ));
        }
        if desc.normals == NormalMode::Smooth {
            normals = smooth_vertex_normals(positions, triangles);
        }
        let mesh = &mut self.mesh;
        let (off, flip) = (base as u32, desc.flip_normals);
        if flip {
            normals.par_iter_mut().for_each(|n| *n = -*n);
        }
        (mesh.indices).par_extend(triangles.par_iter().map(|&[a, b, c]| {
            let t = if flip { [a, c, b] } else { [a, b, c] };
            t.map(|i| i + off)
        }));
        let count = triangles.len();
        (mesh.materials).par_extend(rayon::iter::repeat_n(p.material, count));
        // Per-vertex values stay one per vertex: a part without them gets zeros (as
        // `TriMesh::append` gives them), and all of them are none while none has any.
        extend_per_vertex(&mut mesh.normals, normals, base, nv, Vec3::ZERO);
        extend_per_vertex(&mut mesh.texcoords, texcoords, base, nv, Vec2::ZERO);
        Ok(())
    }
}

/// `part`'s per-vertex values (of `n` vertices) after `all`'s (of `before` vertices), where an
/// empty list stands for `zero` at each of its vertices (left empty while both are).
fn extend_per_vertex<T: Copy + Send + Sync>(
    all: &mut Vec<T>,
    part: Vec<T>,
    before: usize,
    n: usize,
    zero: T,
) {
    if all.is_empty() && part.is_empty() {
        return;
    }
    if all.is_empty() {
        if before == 0 {
            *all = part;
            return;
        }
        all.resize(before, zero);
    }
    if part.is_empty() {
        all.par_extend(rayon::iter::repeat_n(zero, n));
    } else {
        all.par_extend(part);
    }
}
