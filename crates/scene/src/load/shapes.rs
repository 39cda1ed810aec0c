//! Meshes generated rather than read: Mitsuba 3's `rectangle`, `cube` and `disk`, each in
//! its own space as Mitsuba defines it, placed by the mesh's transform.

use super::Builder;
use super::faces::Polygons;
use crate::error::SceneError;
use crate::file::{MeshDesc, ShapeKind};
use geom::TriMesh;
use glam::{DMat4, DVec3, Vec2, Vec3};

/// Segments of a disk's fan. Its radius is stretched so the polygon has the disc's area
/// (`n/2 sin(2 pi / n) r'^2 = pi r^2`): an emitting disk keeps its power exactly.
const DISK_SEGMENTS: u32 = 256;

impl Builder<'_> {
    /// Mesh `index`, a generated shape of material `own`, appended through `xf`.
    pub(super) fn load_shape(
        &mut self,
        index: usize,
        kind: ShapeKind,
        desc: &MeshDesc,
        xf: DMat4,
        own: Option<u32>,
    ) -> Result<(), SceneError> {
        let Some(mat) = own else {
            return Err(self.err(format!(
                "mesh {index} ({}): a generated shape needs `material` (it has no MTL)",
                desc.source()
            )));
        };
        let part = local(kind);
        if kind == ShapeKind::Disk {
            self.warnings.push(format!(
                "{}: mesh {index} (disk): drawn as a {DISK_SEGMENTS}-sided polygon of the \
                 disc's area",
                self.scene_path.display()
            ));
        }
        // Through the path every mesh file takes: transform, checks, flip, append.
        let positions: Vec<f32> = part.positions.iter().flat_map(|p| p.to_array()).collect();
        let texcoords: Vec<f32> = part.texcoords.iter().flat_map(|t| t.to_array()).collect();
        let indices: Vec<u32> = part.indices.iter().flatten().copied().collect();
        let label = format!("mesh {index} ({})", desc.source());
        let polygons = Polygons {
            label: &label,
            first: 0,
            uv_keys: "texture coordinates",
            positions: &positions,
            normals: &[],
            texcoords: &texcoords,
            indices: &indices,
            arities: &[],
            material: mat,
        };
        let scene = self.scene_path.to_path_buf();
        let err = |problem: String| SceneError::new(&scene, problem);
        self.append_polygons(&polygons, desc, xf, &scene, &err)
    }
}

/// Mitsuba 3's `cube` mesh (its vertex positions, texture coordinates and faces, as
/// `mi.traverse` lists them): 24 vertices, 4 per face, two triangles each.
const CUBE_POSITIONS: [[f32; 3]; 24] = [
    [1., -1., -1.],
    [1., -1., 1.],
    [-1., -1., 1.],
    [-1., -1., -1.],
    [1., 1., -1.],
    [-1., 1., -1.],
    [-1., 1., 1.],
    [1., 1., 1.],
    [1., -1., -1.],
    [1., 1., -1.],
    [1., 1., 1.],
    [1., -1., 1.],
    [1., -1., 1.],
    [1., 1., 1.],
    [-1., 1., 1.],
    [-1., -1., 1.],
    [-1., -1., 1.],
    [-1., 1., 1.],
    [-1., 1., -1.],
    [-1., -1., -1.],
    [1., 1., -1.],
    [1., -1., -1.],
    [-1., -1., -1.],
    [-1., 1., -1.],
];
/// Per face, Mitsuba's texture coordinates of its four vertices (the same on every face).
const CUBE_FACE_UV: [[f32; 2]; 4] = [[0., 1.], [1., 1.], [1., 0.], [0., 0.]];
/// Per face, its two triangles over its four vertices.
const CUBE_FACE_TRIANGLES: [[u32; 3]; 2] = [[0, 1, 2], [3, 0, 2]];

/// Mitsuba's texture coordinate `uv` as photonflow stores it. Mitsuba reads a `bitmap` with
/// `v = 0` at the image's top row, and flips an OBJ's `vt` at load to match; photonflow keeps
/// OBJ `vt` as written and reads `v = 0` at the bottom row, so a generated shape stores
/// `1 - v` and both read the same texel.
fn from_mitsuba(uv: [f32; 2]) -> Vec2 {
    Vec2::new(uv[0], 1.0 - uv[1])
}

/// The shape in its own space: flat-shaded triangles wound towards the front, with texture
/// coordinates as Mitsuba 3 gives them (but the disk's).
fn local(kind: ShapeKind) -> TriMesh {
    let mut m = TriMesh::default();
    match kind {
        ShapeKind::Rectangle => {
            // Mitsuba's `rectangle`: uv = (x + 1, y + 1) / 2.
            for (x, y) in [(-1., -1.), (1., -1.), (1., 1.), (-1., 1.)] {
                m.positions.push(Vec3::new(x, y, 0.0));
                m.texcoords
                    .push(from_mitsuba([(x + 1.) / 2., (y + 1.) / 2.]));
            }
            m.indices = vec![[0, 1, 2], [0, 2, 3]];
        }
        ShapeKind::Cube => {
            m.positions = CUBE_POSITIONS.iter().map(|&p| Vec3::from(p)).collect();
            for face in 0..6u32 {
                m.texcoords.extend(CUBE_FACE_UV.map(from_mitsuba));
                m.indices
                    .extend(CUBE_FACE_TRIANGLES.map(|t| t.map(|i| 4 * face + i)));
            }
        }
        ShapeKind::Disk => {
            let n = DISK_SEGMENTS as f64;
            let step = std::f64::consts::TAU / n;
            let r = (std::f64::consts::PI / (0.5 * n * step.sin())).sqrt();
            m.positions.push(Vec3::ZERO);
            for i in 0..DISK_SEGMENTS {
                let a = i as f64 * step;
                m.positions
                    .push(DVec3::new(r * a.cos(), r * a.sin(), 0.0).as_vec3());
                let next = 1 + (i + 1) % DISK_SEGMENTS;
                m.indices.push([0, 1 + i, next]);
            }
        }
    }
    m
}

#[cfg(test)]
mod tests {
    use super::*;

    fn area_and_normal_sum(m: &TriMesh) -> (f64, DVec3) {
        let mut area = 0.0;
        let mut n = DVec3::ZERO;
        for t in &m.indices {
            let [a, b, c] = t.map(|i| m.positions[i as usize].as_dvec3());
            let cr = (b - a).cross(c - a);
            area += cr.length() / 2.0;
            n += cr / 2.0;
        }
        (area, n)
    }

    #[test]
    fn shapes_have_their_areas_and_face_outwards() {
        // Rectangle [-1, 1]^2: area 4 facing +z.
        let (a, n) = area_and_normal_sum(&local(ShapeKind::Rectangle));
        assert!((a - 4.0).abs() < 1e-6 && (n - DVec3::new(0., 0., 4.)).length() < 1e-6);
        // Disk: area pi (the fan is stretched to it), facing +z.
        let (a, n) = area_and_normal_sum(&local(ShapeKind::Disk));
        assert!((a - std::f64::consts::PI).abs() < 1e-5, "{a}");
        assert!((n.z - a).abs() < 1e-9);
        // Cube [-1, 1]^3: area 24, closed (normals sum to zero), every face outwards: its
        // centre plus its normal lies farther from the origin.
        let cube = local(ShapeKind::Cube);
        let (a, n) = area_and_normal_sum(&cube);
        assert!((a - 24.0).abs() < 1e-6 && n.length() < 1e-6);
        for t in &cube.indices {
            let [p, q, r] = t.map(|i| cube.positions[i as usize].as_dvec3());
            let c = (p + q + r) / 3.0;
            let nn = (q - p).cross(r - p).normalize();
            assert!((c + nn).length() > c.length(), "face {t:?} faces inwards");
        }
    }
}
