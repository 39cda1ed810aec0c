//! PLY loading: one mesh in the three encodings, polygons, normals and texture coordinates,
//! files Mitsuba 3 wrote (`data/`), the `material` key, and every problem named with its file.

use super::{CAMERA, Scratch, close};
use crate::Scene;
use crate::load::ply::parse;
use glam::{Vec2, Vec3};
use std::path::Path;

/// A scene over `m.ply` under the scene-file material `white`, lit by a point light, with
/// `mesh` (more `[[mesh]]` keys) after `material`.
fn ply_toml(mesh: &str) -> String {
    format!(
        "{CAMERA}[[mesh]]\nply = \"m.ply\"\nmaterial = \"white\"\n{mesh}\n\
         [material.white]\ntype = \"lambertian\"\nalbedo = [0.5, 0.5, 0.5]\n\
         [[light]]\ntype = \"point\"\nposition = [0, 3, 0]\nintensity = [1, 1, 1]\n"
    )
}

/// A scene of `toml` with `m.ply` holding `ply`.
fn load_ply(name: &str, toml: &str, ply: &[u8]) -> Result<Scene, crate::SceneError> {
    let dir = Scratch::new(name, &[("s.toml", toml)]);
    std::fs::write(dir.path("m.ply"), ply).unwrap();
    Scene::load(dir.path("s.toml"))
}

fn ply_scene(name: &str, mesh: &str, ply: &[u8]) -> Scene {
    load_ply(name, &ply_toml(mesh), ply).unwrap_or_else(|e| panic!("{name}: {e}"))
}

/// `ply` refused with an error naming `m.ply` and saying `problem`.
fn ply_error(name: &str, ply: &[u8], problem: &str) {
    let err = match load_ply(name, &ply_toml(""), ply) {
        Ok(_) => panic!("{name}: loaded although broken"),
        Err(e) => e,
    };
    let text = err.to_string();
    assert!(
        err.file.ends_with("m.ply"),
        "{name}: names {:?}: {text}",
        err.file
    );
    assert!(
        text.contains(problem),
        "{name}: `{text}` does not say `{problem}`"
    );
    assert!(
        text.contains("(mesh 0 of "),
        "{name}: `{text}` does not name the scene"
    );
    assert!(!text.contains('\n'), "{name}: `{text}` spans lines");
}

/// A writer of PLY bodies: each value in the header's type, in ASCII (one entry per line)
/// or binary of either byte order.
struct Writer {
    format: &'static str,
    out: Vec<u8>,
}

impl Writer {
    fn new(format: &'static str, header: &str) -> Writer {
        let out = format!("ply\nformat {format} 1.0\n{header}end_header\n").into_bytes();
        Writer { format, out }
    }

    fn put(&mut self, ty: &str, x: f64) {
        macro_rules! bin {
            ($t:ty) => {{
                let v = x as $t;
                if self.format == "binary_big_endian" {
                    self.out.extend(v.to_be_bytes())
                } else {
                    self.out.extend(v.to_le_bytes())
                }
            }};
        }
        if self.format == "ascii" {
            self.out.extend(format!("{x} ").bytes());
            return;
        }
        match ty {
            "char" | "int8" => bin!(i8),
            "uchar" | "uint8" => bin!(u8),
            "short" | "int16" => bin!(i16),
            "ushort" | "uint16" => bin!(u16),
            "int" | "int32" => bin!(i32),
            "uint" | "uint32" => bin!(u32),
            "float" | "float32" => bin!(f32),
            "double" | "float64" => bin!(f64),
            _ => panic!("type {ty}"),
        }
    }

    fn list(&mut self, count: &str, item: &str, xs: &[f64]) {
        self.put(count, xs.len() as f64);
        for &x in xs {
            self.put(item, x);
        }
    }

    fn end(&mut self) {
        if self.format == "ascii" {
            self.out.push(b'\n');
        }
    }
}

/// The corners of a quad, a triangle and a convex pentagon, in the plane y = 0.
const CORNERS: [[f64; 3]; 12] = [
    [0.0, 0.0, 0.0],
    [1.0, 0.0, 0.0],
    [1.0, 0.0, 1.0],
    [0.0, 0.0, 1.0],
    [2.0, 0.0, 0.0],
    [3.0, 0.0, 0.0],
    [2.0, 0.0, 1.0],
    [4.0, 0.0, 0.0],
    [5.0, 0.0, 0.0],
    [5.5, 0.0, 0.5],
    [5.0, 0.0, 1.0],
    [4.0, 0.0, 1.0],
];

/// The quad, the triangle and the pentagon of [`CORNERS`] with normals and texture
/// coordinates, in `format`, with a vertex property, an element (with a list) and face
/// properties to read past, and every scalar type somewhere.
fn mixed(format: &'static str) -> Vec<u8> {
    let header = "comment made by the tests\nobj_info nothing\nelement vertex 12\n\
        property float x\nproperty int16 y\nproperty double z\nproperty uchar confidence\n\
        property float32 nx\nproperty float ny\nproperty float64 nz\n\
        property float u\nproperty float v\n\
        element edge 2\nproperty int vertex1\nproperty uint32 vertex2\n\
        property list ushort char tags\n\
        element face 3\nproperty uint8 flags\nproperty list uchar uint vertex_indices\n\
        property list int float texcoord\nproperty short extra\n";
    let mut w = Writer::new(format, header);
    for (v, [x, y, z]) in CORNERS.into_iter().enumerate() {
        let t = v as f64;
        for (ty, value) in [
            ("float", x),
            ("int16", y),
            ("double", z),
            ("uchar", 200.0),
            ("float", 0.0),
            ("float", 2.0),
            ("double", 0.0),
            ("float", t / 16.0),
            ("float", 0.75 - t / 32.0),
        ] {
            w.put(ty, value);
        }
        w.end();
    }
    for e in 0..2 {
        w.put("int", e as f64);
        w.put("uint32", 3.0);
        w.list("ushort", "char", &[-1.0, 7.0, -128.0]);
        w.end();
    }
    for face in [
        &[0.0, 1.0, 2.0, 3.0][..],
        &[4.0, 5.0, 6.0],
        &[7.0, 8.0, 9.0, 10.0, 11.0],
    ] {
        w.put("uint8", 1.0);
        w.list("uchar", "uint", face);
        w.list("int", "float", &[0.5; 6]);
        w.put("short", -3.0);
        w.end();
    }
    w.out
}

/// The same mesh in ASCII, little-endian and big-endian bodies loads to the same triangles,
/// normals and texture coordinates, and to the values written.
#[test]
fn ascii_and_binary_bodies_load_the_same_triangles() {
    let scenes: Vec<Scene> = ["ascii", "binary_little_endian", "binary_big_endian"]
        .into_iter()
        .map(|f| ply_scene(f, "translate = [0, 1, 0]", &mixed(f)))
        .collect();
    let m = scenes[0].geometry.mesh();
    // A quad, a triangle and a pentagon: 2 + 1 + 3 triangles.
    assert_eq!(m.len(), 6);
    for s in &scenes[1..] {
        let n = s.geometry.mesh();
        assert_eq!(
            (&m.positions, &m.normals, &m.texcoords, &m.indices),
            (&n.positions, &n.normals, &n.texcoords, &n.indices)
        );
    }
    assert_eq!((m.normals.len(), m.texcoords.len()), (12, 12));
    for (v, ((p, n), uv)) in m
        .positions
        .iter()
        .zip(&m.normals)
        .zip(&m.texcoords)
        .enumerate()
    {
        let t = v as f32;
        let [x, y, z] = CORNERS[v].map(|c| c as f32);
        assert_eq!(*p, Vec3::new(x, y + 1.0, z), "vertex {v}");
        assert_eq!(*n, Vec3::Y, "normal {v}");
        // `v` counts from the top in a PLY file: 1 - v here, as OBJ's `vt`.
        assert_eq!(*uv, Vec2::new(t / 16.0, 0.25 + t / 32.0), "uv {v}");
    }
    assert_eq!(
        m.indices,
        [
            [0, 1, 2],
            [0, 2, 3],
            [4, 5, 6],
            [7, 8, 9],
            [7, 9, 10],
            [7, 10, 11]
        ]
    );
    let area: f64 = (0..m.len()).map(|t| m.area(t) as f64).sum();
    assert!((area - (1.0 + 0.5 + 1.25)).abs() < 1e-6, "area {area}");
}

/// Quads and larger polygons are triangulated as an OBJ's are (`polygon.rs`), non-convex
/// ones too, with the polygon's area.
#[test]
fn polygons_are_triangulated_with_their_area() {
    // A unit square and an L of three unit squares (non-convex), both in the plane y = 0.
    let ply = "ply\nformat ascii 1.0\nelement vertex 10\nproperty float x\nproperty float y\n\
        property float z\nelement face 2\nproperty list uchar int vertex_indices\nend_header\n\
        0 0 0\n1 0 0\n1 0 1\n0 0 1\n\
        2 0 0\n4 0 0\n4 0 1\n3 0 1\n3 0 2\n2 0 2\n\
        4 0 1 2 3\n6 4 5 6 7 8 9\n";
    let s = ply_scene("polygons", "", ply.as_bytes());
    let m = s.geometry.mesh();
    assert_eq!(m.len(), 2 + 4);
    let area = |r: std::ops::Range<usize>| r.map(|t| m.area(t) as f64).sum::<f64>();
    assert!((area(0..2) - 1.0).abs() < 1e-6, "square: {}", area(0..2));
    assert!((area(2..6) - 3.0).abs() < 1e-6, "L: {}", area(2..6));
    assert!(m.normals.is_empty() && m.texcoords.is_empty());
}

/// `normals`: the file's under `auto` (through the transform's inverse transpose), none under
/// `flat`, computed under `smooth`; `flip_normals` turns faces over; the transform applies to
/// the vertices.
#[test]
fn normals_follow_the_mesh_keys() {
    let ply = mixed("binary_little_endian");
    let auto = ply_scene("auto", "scale = [2, 1, 1]\nrotate = [0, 0, 90]", &ply);
    let m = auto.geometry.mesh();
    // The file's normals are +y; turned 90 degrees about z they point along -x.
    assert!(
        m.normals.iter().all(|n| close(*n, Vec3::NEG_X, 1e-6)),
        "{:?}",
        m.normals
    );
    // Vertex 9 = (5.5, 0, 0.5): scaled (11, 0, 0.5), turned (0, 11, 0.5).
    assert!(
        close(m.positions[9], Vec3::new(0.0, 11.0, 0.5), 1e-6),
        "{}",
        m.positions[9]
    );
    // `flip_normals`: every face turned over, its vertex normals too.
    let plain = ply_scene("plain", "", &ply);
    let flipped = ply_scene("flip", "flip_normals = true", &ply);
    let (p, f) = (plain.geometry.mesh(), flipped.geometry.mesh());
    assert!(
        f.normals.iter().all(|n| *n == Vec3::NEG_Y),
        "{:?}",
        f.normals
    );
    let turned: Vec<[u32; 3]> = p.indices.iter().map(|&[a, b, c]| [a, c, b]).collect();
    assert_eq!(f.indices, turned);
    let flat = ply_scene("flat", "normals = \"flat\"", &ply);
    assert!(flat.geometry.mesh().normals.is_empty());
    let smooth = ply_scene("smooth", "normals = \"smooth\"", &ply);
    let n = &smooth.geometry.mesh().normals;
    assert_eq!(n.len(), 12);
    assert!(n.iter().all(|n| (n.length() - 1.0).abs() < 1e-5));
}

fn data(f: &str) -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("src/tests/data")
        .join(f)
}

/// `data/mitsuba-cube.ply`, written by Mitsuba 3.9.1 (`mi.load_dict({'type': 'cube'})
/// .write_ply(...)`, binary little-endian, texture coordinates as `s t`): the cube
/// [-1, 1]^3, 24 vertices, 12 triangles, area 24, each vertex normal its face's outward
/// normal, texture coordinates in the unit square.
#[test]
fn a_cube_mitsuba_wrote_has_its_area_and_normals() {
    let bytes = std::fs::read(data("mitsuba-cube.ply")).unwrap();
    let s = ply_scene("cube", "", &bytes);
    let m = s.geometry.mesh();
    assert_eq!((m.positions.len(), m.len()), (24, 12));
    let area: f64 = (0..m.len()).map(|t| m.area(t) as f64).sum();
    assert!((area - 24.0).abs() < 1e-5, "area {area}");
    assert!(
        m.positions.iter().all(|p| p.abs() == Vec3::ONE),
        "{:?}",
        m.positions
    );
    for (t, tri) in m.indices.iter().enumerate() {
        let [a, b, c] = m.vertices(t);
        let face = (b - a).cross(c - a).normalize();
        // Outward: the face's normal points the way its centre lies from the cube's.
        assert!(face.dot(a + b + c) > 0.0, "triangle {t} faces inwards");
        for &i in tri {
            assert!(
                close(m.normals[i as usize], face, 1e-6),
                "triangle {t} vertex {i}"
            );
        }
    }
    assert_eq!(m.texcoords.len(), 24);
    assert!(
        m.texcoords
            .iter()
            .all(|uv| uv.min_element() >= 0.0 && uv.max_element() <= 1.0)
    );
}

/// `data/mitsuba-quad.ply` is Mitsuba 3.9.1's `write_ply` of `data/quad.obj`: it loads to
/// the OBJ's triangles, positions and texture coordinates (Mitsuba keeps `v` from the top in
/// a PLY file, 1 minus the OBJ's `vt`).
#[test]
fn a_ply_mitsuba_wrote_from_an_obj_loads_as_the_obj() {
    let dir = Scratch::new("mitsuba-quad", &[]);
    for f in ["quad.obj", "quad.mtl", "mitsuba-quad.ply"] {
        std::fs::copy(data(f), dir.path(f)).unwrap();
    }
    let light = "[material.white]\ntype = \"lambertian\"\nalbedo = [0.5, 0.5, 0.5]\n\
        [[light]]\ntype = \"point\"\nposition = [0, 3, 0]\nintensity = [1, 1, 1]\n";
    std::fs::write(
        dir.path("obj.toml"),
        format!("{CAMERA}[[mesh]]\nobj = \"quad.obj\"\n{light}"),
    )
    .unwrap();
    std::fs::write(
        dir.path("ply.toml"),
        format!("{CAMERA}[[mesh]]\nply = \"mitsuba-quad.ply\"\nmaterial = \"white\"\n{light}"),
    )
    .unwrap();
    let obj = Scene::load(dir.path("obj.toml")).unwrap();
    let ply = Scene::load(dir.path("ply.toml")).unwrap();
    let (o, p) = (obj.geometry.mesh(), ply.geometry.mesh());
    assert_eq!(o.len(), 2);
    assert_eq!((&o.positions, &o.indices), (&p.positions, &p.indices));
    assert_eq!(o.texcoords.len(), p.texcoords.len());
    for (a, b) in o.texcoords.iter().zip(&p.texcoords) {
        assert!((*a - *b).abs().max_element() < 1e-6, "uv {a} against {b}");
    }
    assert_eq!(
        o.materials, p.materials,
        "the OBJ's `white` is the scene file's"
    );
}

/// `parse` reads the header's types and aliases and skips what it does not use.
#[test]
fn parse_reads_what_it_needs() {
    let m = parse(&mixed("binary_big_endian")).unwrap();
    assert_eq!(m.arities, [4, 3, 5]);
    assert_eq!(m.indices, (0..12).collect::<Vec<u32>>());
    assert_eq!(m.positions.len(), 36);
    // `vertex_index` is the other spelling; `s t` and `texture_u texture_v` the other pairs.
    let other = "ply\r\nformat ascii 1.0\r\nelement vertex 3\r\nproperty float x\r\n\
        property float y\r\nproperty float z\r\nproperty float texture_u\r\n\
        property float texture_v\r\nelement face 1\r\nproperty list uchar int vertex_index\r\n\
        end_header\r\n0 0 0 0 1\r\n1 0 0 1 1\r\n0 1 0 0 0\r\n3 0 1 2\r\n";
    let m = parse(other.as_bytes()).unwrap();
    assert_eq!(m.texcoords, [0.0, 0.0, 1.0, 0.0, 0.0, 1.0]);
    assert_eq!(m.indices, [0, 1, 2]);
}

/// A header of the good little mesh (one triangle) with `body` appended.
fn tri(format: &str, body: &[u8]) -> Vec<u8> {
    let mut b = format!(
        "ply\nformat {format} 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
         property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
    )
    .into_bytes();
    b.extend(body);
    b
}

fn le(vertices: &[f32], face: &[i32]) -> Vec<u8> {
    let mut b: Vec<u8> = vertices.iter().flat_map(|x| x.to_le_bytes()).collect();
    b.push(face.len() as u8);
    b.extend(face.iter().flat_map(|i| i.to_le_bytes()));
    b
}

const VERTS: [f32; 9] = [0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0];

/// Every problem with a PLY file is one line naming the file, the scene and the problem.
#[test]
fn broken_ply_files_are_named() {
    let good = tri("binary_little_endian", &le(&VERTS, &[0, 1, 2]));
    assert_eq!(ply_scene("good", "", &good).geometry.mesh().len(), 1);
    let cut = &good[..good.len() - 3];
    ply_error("cut", cut, "the file is cut short");
    let n = good.len();
    ply_error(
        "cut-vertices",
        &good[..n - 20],
        "element `vertex` claims 3 entries",
    );
    let no_end = String::from_utf8_lossy(&tri("ascii", b"")).replace("end_header\n", "");
    ply_error("noend", no_end.as_bytes(), "no `end_header` line");
    ply_error("notply", b"solid cube\nendsolid\n", "not a PLY file");
    ply_error("empty", b"", "not a PLY file");
    let mut nan = VERTS;
    nan[4] = f32::NAN;
    ply_error(
        "nan",
        &tri("binary_little_endian", &le(&nan, &[0, 1, 2])),
        "vertex 1 is not finite",
    );
    ply_error(
        "index",
        &tri("binary_little_endian", &le(&VERTS, &[0, 1, 3])),
        "face 0: vertex index 3 out of range (the file has 3 vertices)",
    );
    ply_error(
        "negative",
        &tri("binary_little_endian", &le(&VERTS, &[0, -1, 2])),
        "vertex index -1 is negative",
    );
    let absurd = String::from_utf8_lossy(&good).replace("vertex 3", "vertex 4000000000000000");
    ply_error(
        "absurd",
        absurd.as_bytes(),
        "claims 4000000000000000 entries",
    );
    let overlong =
        String::from_utf8_lossy(&good).replace("vertex 3", "vertex 99999999999999999999999");
    ply_error("overlong", overlong.as_bytes(), "is not a whole number");
    let mut long_list = tri("binary_little_endian", &le(&VERTS, &[0, 1, 2]));
    let at = long_list.len() - 13;
    long_list[at] = 200;
    ply_error("list", &long_list, "list `vertex_indices` claims 200 items");
    ply_error(
        "format",
        &tri("binary_middle_endian", &le(&VERTS, &[0, 1, 2])),
        "unknown format `binary_middle_endian`",
    );
    let text = String::from_utf8_lossy(&good).into_owned();
    for (name, from, to, problem) in [
        ("version", "1.0", "2.0", "version 2.0"),
        (
            "count-type",
            "list uchar int",
            "list float int",
            "must be an integer type, not `float`",
        ),
        (
            "index-type",
            "list uchar int",
            "list uchar float",
            "vertex indices are integers",
        ),
        ("type", "float z", "quad z", "unknown type `quad`"),
        (
            "no-z",
            "property float z\n",
            "",
            "element `vertex` has no property `z` (it has: x, y)",
        ),
        (
            "no-list",
            "vertex_indices",
            "corners",
            "element `face` has no `vertex_indices` list",
        ),
        (
            "no-faces",
            "element face 1",
            "element face 0",
            "holds no faces",
        ),
        (
            "no-vertex",
            "element vertex",
            "element point",
            "no `element vertex`",
        ),
        (
            "keyword",
            "end_header",
            "elements\nend_header",
            "not a header line PLY knows",
        ),
        (
            "early-property",
            "element vertex 3\n",
            "",
            "a property before any `element` line",
        ),
    ] {
        ply_error(name, text.replacen(from, to, 1).as_bytes(), problem);
    }
    ply_error(
        "ascii-word",
        &tri("ascii", b"0 0 0\n1 zero 0\n0 0 1\n3 0 1 2\n"),
        "element `vertex` entry 1: line 11: `zero` is not a number",
    );
    ply_error(
        "ascii-cut",
        &tri("ascii", b"0 0 0\n1 0 0\n0 0 1\n3 0 1"),
        "cut short",
    );
}

/// The scene file's side: one of `obj` and `ply`, and a PLY mesh's `material`.
#[test]
fn the_mesh_keys_are_checked() {
    let good = tri("binary_little_endian", &le(&VERTS, &[0, 1, 2]));
    let refused = |name: &str, toml: String, problem: &str| {
        let err = load_ply(name, &toml, &good)
            .err()
            .unwrap_or_else(|| panic!("{name}"));
        assert!(err.file.ends_with("s.toml"), "{name}: {err}");
        assert!(
            err.to_string().contains(problem),
            "{name}: `{err}` lacks `{problem}`"
        );
    };
    refused(
        "nomat",
        ply_toml("").replace("material = \"white\"\n", ""),
        "mesh 0 (m.ply): a PLY mesh needs `material = \"name\"`: the file has no materials \
         (known: white)",
    );
    refused(
        "unknownmat",
        ply_toml("").replace("material = \"white\"", "material = \"whyte\""),
        "mesh 0 (m.ply): unknown material `whyte`",
    );
    let one_of = "give exactly one of `obj` or `ply` (a file) and `shape`";
    refused("both", ply_toml("obj = \"a.obj\""), one_of);
    refused("shape-too", ply_toml("shape = \"cube\""), one_of);
    refused(
        "neither",
        ply_toml("").replace("ply = \"m.ply\"\n", ""),
        one_of,
    );
    // `radiance` makes the PLY's faces emit, as an OBJ's under `material`.
    let lit = load_ply("radiance", &ply_toml("radiance = [2, 2, 2]"), &good).unwrap();
    assert_eq!(lit.lights.len(), 1);
    let missing = Scratch::new("noply", &[("s.toml", &ply_toml(""))]);
    let err = Scene::load(missing.path("s.toml")).err().unwrap();
    assert!(err.file.ends_with("m.ply"), "{err}");
    assert!(
        err.to_string().contains("cannot read PLY file (mesh 0 of "),
        "{err}"
    );
}

/// A PLY mesh's file counts by content in the hashes, as an OBJ's does, and an emissive
/// scene-file material makes its triangles lights.
#[test]
fn ply_content_keys_the_hashes_and_emits() {
    let a = ply_scene(
        "hash-a",
        "",
        &tri("binary_little_endian", &le(&VERTS, &[0, 1, 2])),
    );
    let mut moved = VERTS;
    moved[0] = 0.5;
    let b = ply_scene(
        "hash-b",
        "",
        &tri("binary_little_endian", &le(&moved, &[0, 1, 2])),
    );
    assert_ne!(a.photon_hash, b.photon_hash);
    assert_ne!(a.content_hash, b.content_hash);
    let toml = ply_toml("").replace(
        "albedo = [0.5, 0.5, 0.5]",
        "albedo = [0, 0, 0]\nemission = [2, 2, 2]",
    );
    let s = load_ply(
        "emits",
        &toml,
        &tri("ascii", b"0 0 0\n1 0 0\n0 0 1\n3 0 1 2\n"),
    )
    .unwrap();
    assert_eq!(s.lights.len(), 1);
}

/// A Mitsuba 3 XML scene's `<shape type="ply">` is a PLY mesh of its BSDF: the cube Mitsuba
/// wrote, placed by `to_world`.
#[test]
fn xml_ply_shapes_load() {
    let xml = r#"<scene version="3.0.0">
    <sensor type="perspective"><float name="fov" value="40"/>
        <film type="hdrfilm"><integer name="width" value="8"/><integer name="height" value="8"/><rfilter type="box"/></film>
    </sensor>
    <shape type="ply"><string name="filename" value="cube.ply"/>
        <transform name="to_world"><scale value="0.5"/><translate z="5"/></transform>
        <bsdf type="diffuse"/>
    </shape>
    <emitter type="point"><point name="position" x="0" y="0" z="0"/></emitter>
</scene>"#;
    let dir = Scratch::new("xml-ply", &[("s.xml", xml)]);
    std::fs::copy(data("mitsuba-cube.ply"), dir.path("cube.ply")).unwrap();
    let s = Scene::load(dir.path("s.xml")).unwrap_or_else(|e| panic!("{e}"));
    let m = s.geometry.mesh();
    assert_eq!(m.len(), 12);
    let area: f64 = (0..m.len()).map(|t| m.area(t) as f64).sum();
    assert!((area - 6.0).abs() < 1e-5, "area {area}");
    assert!(m.positions.iter().all(|p| (p.z - 5.0).abs() <= 0.5 + 1e-6));
    assert_eq!(s.file.meshes[0].ply.as_deref(), Some("cube.ply"));
}

/// A binary PLY of `n` x `n` vertices (with a skipped property, normals and texture
/// coordinates) and faces of 3, 4 and 5 corners with a list to read past; `bad` replaces
/// one face's first index.
fn grid(format: &'static str, n: usize, bad: Option<(usize, f64)>) -> Vec<u8> {
    let faces = (n - 2) * (n - 1);
    let header = format!(
        "element vertex {}\nproperty float x\nproperty uchar quality\nproperty double y\n\
         property float z\nproperty float nx\nproperty float ny\nproperty float nz\n\
         property float u\nproperty float v\n\
         element face {faces}\nproperty list uchar int vertex_indices\n\
         property list ushort float extra\n",
        n * n
    );
    let mut w = Writer::new(format, &header);
    for k in 0..n * n {
        let (i, j) = ((k % n) as f64, (k / n) as f64);
        for (ty, x) in [
            ("float", i / 3.0),
            ("uchar", 7.0),
            ("double", (i * j).sin()),
            ("float", j / 7.0),
            ("float", 0.0),
            ("float", 1.0),
            ("float", 0.0),
            ("float", i / n as f64),
            ("float", j / n as f64),
        ] {
            w.put(ty, x);
        }
    }
    let mut f = 0;
    for j in 0..n - 2 {
        for i in 0..n - 1 {
            let a = (j * n + i) as f64;
            let n = n as f64;
            let mut face = match (i + j) % 3 {
                0 => vec![a, a + 1.0, a + n],
                1 => vec![a, a + 1.0, a + n + 1.0, a + n],
                _ => vec![a, a + 1.0, a + n + 1.0, a + 2.0 * n, a + n],
            };
            if let Some((_, v)) = bad.filter(|b| b.0 == f) {
                face[0] = v;
            }
            w.list("uchar", "int", &face);
            w.list("ushort", "float", &vec![0.5; f % 3]);
            f += 1;
        }
    }
    w.out
}

/// A binary body read on every core, in tasks of any size, on 1, 2 and 3 threads, gives the
/// mesh of the sequential reading bit for bit, and its errors word for word.
#[test]
fn binary_bodies_read_in_parallel_as_in_order() {
    use crate::load::ply::{BLOCK, parse_with};
    type Bits = (Vec<u64>, Vec<u64>, Vec<u32>, Vec<u32>, Vec<u32>);
    let bits = |r: &Result<crate::load::ply::PlyMesh, String>| -> Result<Bits, String> {
        match r {
            Ok(m) => {
                let b = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
                let t: Vec<u32> = m.texcoords.iter().map(|x| x.to_bits()).collect();
                let (ix, ar) = (m.indices.clone(), m.arities.clone());
                Ok((b(&m.positions), b(&m.normals), t, ix, ar))
            }
            Err(e) => Err(e.clone()),
        }
    };
    for format in ["binary_little_endian", "binary_big_endian"] {
        let good = grid(format, 90, None);
        let late = 90 * 80;
        let mut cut = good.clone();
        cut.truncate(good.len() - 100);
        let files = [
            good,
            grid(format, 90, Some((late, -1.0))),
            grid(format, 90, Some((late, 1e7))),
            cut,
        ];
        for (k, file) in files.iter().enumerate() {
            let want = parse_with(file, 0);
            assert_eq!(
                want.is_ok(),
                k == 0,
                "{format} file {k}: {:?}",
                want.as_ref().err()
            );
            for threads in [1, 2, 3] {
                let pool = rayon::ThreadPoolBuilder::new()
                    .num_threads(threads)
                    .build()
                    .unwrap();
                for block in [1, 7, 1000, BLOCK] {
                    let got = pool.install(|| parse_with(file, block));
                    if let Ok(m) = &got {
                        assert_eq!(m.parallel, 2, "{format}: vertices and faces in parallel");
                    }
                    assert!(
                        bits(&got) == bits(&want),
                        "{format} file {k}, {threads} threads, block {block}: {:?} {:?}",
                        got.as_ref().err(),
                        want.as_ref().err()
                    );
                }
            }
        }
    }
}
