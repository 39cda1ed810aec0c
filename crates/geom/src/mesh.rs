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

    /// Append another mesh, shifting its indices. Normals and texture coordinates stay
    /// per-vertex: a part without them gets zeros (a zero normal `Geometry` reads as "use the
    /// face normal"; a part has no texture coordinates when its materials carry no texture, or
    /// its loader said so). The smaller part is moved into the larger,
    /// so a large mesh file loaded after a few small shapes is never held twice.
    pub fn append(&mut self, mut other: TriMesh) {
        let (n_self, n_other) = (self.positions.len(), other.positions.len());
        for t in &mut other.indices {
            *t = t.map(|i| i + n_self as u32);
        }
        let s = std::mem::take(self);
        *self = TriMesh {
            positions: concat(s.positions, n_self, other.positions, n_other, Vec3::ZERO),
            normals: concat(s.normals, n_self, other.normals, n_other, Vec3::ZERO),
            texcoords: concat(s.texcoords, n_self, other.texcoords, n_other, Vec2::ZERO),
            indices: concat(s.indices, 0, other.indices, 0, [0; 3]),
            materials: concat(s.materials, 0, other.materials, 0, 0),
        };
    }
}

/// `front` then `back`, per-vertex values of `n_front` and `n_back` vertices where a part's
/// empty list stands for `zero` at each of its vertices (empty when both are): the shorter
/// moved into the longer.
fn concat<T: Copy>(front: Vec<T>, n_front: usize, back: Vec<T>, n_back: usize, zero: T) -> Vec<T> {
    if front.is_empty() && back.is_empty() {
        return Vec::new();
    }
    let fill = |v: Vec<T>, n: usize| if v.is_empty() { vec![zero; n] } else { v };
    let (mut front, mut back) = (fill(front, n_front), fill(back, n_back));
    if back.len() > front.len() {
        back.splice(0..0, front);
        back
    } else {
        front.extend_from_slice(&back);
        front
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
