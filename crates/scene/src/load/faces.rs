//! What every mesh file shares once read: its vertices checked finite and put through the
//! mesh's transform, its normals through the inverse transpose (or replaced by `normals`),
//! its texture coordinates kept, its polygons triangulated (`polygon.rs`), turned over by
//! `flip_normals`, and appended to the scene's mesh. `obj.rs` and `ply.rs` each read their format into a [`Polygons`] and hand
//! it here, so both formats load the same faces the same way.

use super::{Builder, MAX_COORD};
use crate::error::SceneError;
use crate::file::{MeshDesc, NormalMode};
use geom::{TriMesh, smooth_vertex_normals};
use glam::{DMat3, DMat4, DVec3, Vec2};
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
        let mut part = TriMesh::default();
        let corners = p.positions.as_chunks::<3>().0;
        // Every vertex on every core; the first bad one, if any, is found again below.
        let placed = |c: &[P; 3]| {
            let q = xf.transform_point3(dvec3(c));
            let ok = dvec3(c).is_finite() && q.is_finite() && q.abs().max_element() <= MAX_COORD;
            ok.then(|| q.as_vec3())
        };
        let all = corners.par_iter().map(placed).collect::<Option<Vec<_>>>();
        let checked = all.is_some();
        part.positions = all.unwrap_or_default();
        if !checked {
            for (v, c) in corners.iter().enumerate() {
                let q = dvec3(c);
                if !q.is_finite() {
                    return Err(oerr(p.at(format!(
                        "vertex {} is not finite ({:?})",
                        p.number(v),
                        q.to_array()
                    ))));
                }
                let q = xf.transform_point3(q);
                if !q.is_finite() || q.abs().max_element() > MAX_COORD {
                    return Err(oerr(p.at(format!(
                        "vertex {} lies at {:?} after the mesh's transform, beyond the \
                     {MAX_COORD:e} scene units photonflow can trace: check the scale",
                        p.number(v),
                        q.to_array()
                    ))));
                }
                part.positions.push(q.as_vec3());
            }
        }
        if matches!(desc.normals, NormalMode::Auto) && p.normals.len() == 3 * nv {
            let turned = |c: &[P; 3]| {
                let n = (nxf * dvec3(c)).normalize_or_zero();
                (n.is_finite() && n != DVec3::ZERO).then(|| n.as_vec3())
            };
            let normals = p.normals.as_chunks::<3>().0;
            match normals.par_iter().map(turned).collect::<Option<Vec<_>>>() {
                Some(all) => part.normals = all,
                None => {
                    let v = normals
                        .iter()
                        .position(|c| turned(c).is_none())
                        .unwrap_or(0);
                    return Err(oerr(
                        p.at(format!("normal {} is zero or not finite", p.number(v))),
                    ));
                }
            }
        }
        if p.indices.par_iter().any(|&i| i as usize >= nv) {
            return Err(oerr(p.at("face index out of range".to_string())));
        }
        let mut triangles = Vec::new();
        if p.arities.is_empty() {
            // Every face a triangle, which `triangulate` would push as it is.
            triangles = p.indices.as_chunks::<3>().0.to_vec();
        }
        let mut start = 0usize;
        for (f, &n) in p.arities.iter().enumerate() {
            let (f, n) = (p.number(f), n as usize);
            let Some(face) = p.indices.get(start..start.saturating_add(n)) else {
                return Err(oerr(p.at(format!("face {f} runs past the index list"))));
            };
            start += n;
            crate::polygon::triangulate(face, &part.positions, &mut triangles).map_err(|e| {
                oerr(if p.label.is_empty() {
                    format!("face {f}: {e}")
                } else {
                    format!("{}, face {f}: {e}", p.label)
                })
            })?;
        }
        if p.texcoords.len() == 2 * nv {
            for (v, &[u, w]) in p.texcoords.as_chunks::<2>().0.iter().enumerate() {
                if !(u.is_finite() && w.is_finite()) {
                    return Err(oerr(
                        p.at(format!("texture coordinate {} is not finite", p.number(v))),
                    ));
                }
                part.texcoords.push(Vec2::new(u, w));
            }
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
        part.materials = vec![p.material; triangles.len()];
        part.indices = triangles;
        if desc.normals == NormalMode::Smooth {
            part.normals = smooth_vertex_normals(&part.positions, &part.indices);
        }
        if desc.flip_normals {
            super::shapes::flip(&mut part);
        }
        self.mesh.append(part);
        Ok(())
    }
}
