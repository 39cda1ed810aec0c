use crate::Bounds3;
use glam::{Vec2, Vec3};

/// All triangles of a scene in world space, in one indexed mesh.
#[derive(Clone, Debug, Default)]
pub struct TriMesh {
    pub positions: Vec<Vec3>,
    /// Per-vertex shading normals: empty (flat shading) or one per position.
    pub normals: Vec<Vec3>,
    /// Per-vertex texture coordinates (OBJ `vt`): empty or one per position.
    pub texcoords: Vec<Vec2>,
    pub indices: Vec<[u32; 3]>,
    /// Material id of each triangle.
    pub materials: Vec<u32>,
}

impl TriMesh {
    pub fn len(&self) -> usize {
        self.indices.len()
    }

    pub fn is_empty(&self) -> bool {
        self.indices.is_empty()
    }

    pub fn vertices(&self, tri: usize) -> [Vec3; 3] {
        let [a, b, c] = self.indices[tri];
        [
            self.positions[a as usize],
            self.positions[b as usize],
            self.positions[c as usize],
        ]
    }

    /// Unnormalised geometric normal `(p1 - p0) x (p2 - p0)`: its length is twice the area.
    pub fn face_normal(&self, tri: usize) -> Vec3 {
        let [p0, p1, p2] = self.vertices(tri);
        (p1 - p0).cross(p2 - p0)
    }

    /// Texture coordinate at barycentrics `(b1, b2)` of triangle `tri`; `None` where the mesh
    /// has no texture coordinates.
    pub fn texcoord(&self, tri: usize, [b1, b2]: [f32; 2]) -> Option<Vec2> {
        let [a, b, c] = self.indices.get(tri)?.map(|i| i as usize);
        let (ta, tb, tc) = (
            self.texcoords.get(a)?,
            self.texcoords.get(b)?,
            self.texcoords.get(c)?,
        );
        Some((1.0 - b1 - b2) * *ta + b1 * *tb + b2 * *tc)
    }

    pub fn area(&self, tri: usize) -> f32 {
        // f64 cross product: light areas feed the power table, and thin slivers lose digits.
        let [p0, p1, p2] = self.vertices(tri).map(|p| p.as_dvec3());
        0.5 * (p1 - p0).cross(p2 - p0).length() as f32
    }

    pub fn bounds(&self) -> Bounds3 {
        self.positions
            .iter()
            .fold(Bounds3::EMPTY, |b, &p| b.union_point(p))
    }

    /// Append another mesh, shifting its indices. Normals stay per-vertex: a flat mesh joined
    /// to a smooth one gets its face normals as vertex normals only if needed, so we keep a
    /// flag per triangle instead (see `Geometry`). Here: fill missing normals with zero,
    /// which `Geometry` reads as "use the face normal".
    pub fn append(&mut self, other: &TriMesh) {
        let base = self.positions.len() as u32;
        let self_has = !self.normals.is_empty();
        let other_has = !other.normals.is_empty();
        if self_has || other_has {
            if !self_has {
                self.normals = vec![Vec3::ZERO; self.positions.len()];
            }
            if other_has {
                self.normals.extend_from_slice(&other.normals);
            } else {
                self.normals
                    .extend(std::iter::repeat_n(Vec3::ZERO, other.positions.len()));
            }
        }
        // Texture coordinates likewise: zero where a part has none (its materials carry no
        // texture, or the loader said so).
        let self_uv = !self.texcoords.is_empty();
        let other_uv = !other.texcoords.is_empty();
        if self_uv || other_uv {
            if !self_uv {
                self.texcoords = vec![Vec2::ZERO; self.positions.len()];
            }
            if other_uv {
                self.texcoords.extend_from_slice(&other.texcoords);
            } else {
                self.texcoords
                    .extend(std::iter::repeat_n(Vec2::ZERO, other.positions.len()));
            }
        }
        self.positions.extend_from_slice(&other.positions);
        self.indices.extend(
            other
                .indices
                .iter()
                .map(|t| [t[0] + base, t[1] + base, t[2] + base]),
        );
        self.materials.extend_from_slice(&other.materials);
    }
}

impl TriMesh {
    /// `append`, taking `other`: when it is the larger, `self` is put in front of it instead of
    /// it being copied behind `self` (a large mesh file loaded after a few small shapes is not
    /// held twice). The same mesh either way.
    pub fn append_owned(&mut self, mut other: TriMesh) {
        if other.positions.len() <= self.positions.len() {
            self.append(&other);
            return;
        }
        let base = self.positions.len();
        for t in &mut other.indices {
            *t = t.map(|i| i + base as u32);
        }
        if !self.normals.is_empty() || !other.normals.is_empty() {
            let front = std::mem::take(&mut self.normals);
            let front = if front.is_empty() {
                vec![Vec3::ZERO; base]
            } else {
                front
            };
            if other.normals.is_empty() {
                other.normals = vec![Vec3::ZERO; other.positions.len()];
            }
            other.normals.splice(0..0, front);
        }
        if !self.texcoords.is_empty() || !other.texcoords.is_empty() {
            let front = std::mem::take(&mut self.texcoords);
            let front = if front.is_empty() {
                vec![Vec2::ZERO; base]
            } else {
                front
            };
            if other.texcoords.is_empty() {
                other.texcoords = vec![Vec2::ZERO; other.positions.len()];
            }
            other.texcoords.splice(0..0, front);
        }
        other
            .positions
            .splice(0..0, std::mem::take(&mut self.positions));
        other
            .indices
            .splice(0..0, std::mem::take(&mut self.indices));
        other
            .materials
            .splice(0..0, std::mem::take(&mut self.materials));
        *self = other;
    }
}

/// Angle-weighted vertex normals (Thürmer & Wüthrich 1998, "Computing vertex normals from
/// polygonal facets"): each face adds its unit normal times the corner angle, so normals do
/// not depend on how a surface is split into triangles. The course's sphere meshes carry no
/// normals and get theirs this way at load. Degenerate faces add nothing.
pub fn smooth_vertex_normals(positions: &[Vec3], indices: &[[u32; 3]]) -> Vec<Vec3> {
    let mut acc = vec![glam::DVec3::ZERO; positions.len()];
    for tri in indices {
        let p = tri.map(|i| positions[i as usize].as_dvec3());
        let n = (p[1] - p[0]).cross(p[2] - p[0]);
        let len = n.length();
        if len == 0.0 || !len.is_finite() {
            continue;
        }
        let n = n / len;
        for k in 0..3 {
            let e1 = (p[(k + 1) % 3] - p[k]).normalize_or_zero();
            let e2 = (p[(k + 2) % 3] - p[k]).normalize_or_zero();
            let angle = e1.dot(e2).clamp(-1.0, 1.0).acos();
            acc[tri[k] as usize] += angle * n;
        }
    }
    acc.into_iter()
        .map(|n| n.normalize_or_zero().as_vec3())
        .collect()
}
