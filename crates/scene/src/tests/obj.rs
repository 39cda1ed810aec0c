//! OBJ loading: missing and malformed files, vertices, usemtl lines, each named with its file.

use super::{GOOD_MTL, GOOD_OBJ, Scratch, error_of, scene_toml};
use crate::Scene;

#[test]
fn missing_obj_is_named() {
    error_of(
        "noobj",
        &[("s.toml", &scene_toml("gone.obj"))],
        "gone.obj",
        "cannot read OBJ file",
    );
}

#[test]
fn missing_mtl_is_named() {
    error_of(
        "nomtl",
        &[("s.toml", &scene_toml("a.obj")), ("a.obj", GOOD_OBJ)],
        "m.mtl",
        "cannot read MTL file",
    );
}

#[test]
fn nan_and_infinite_vertices_are_named() {
    for (tag, bad) in [("nan", "NaN"), ("inf", "inf")] {
        let obj = GOOD_OBJ.replace("v 1 0 1", &format!("v 1 {bad} 1"));
        error_of(
            tag,
            &[
                ("s.toml", &scene_toml("a.obj")),
                ("a.obj", &obj),
                ("m.mtl", GOOD_MTL),
            ],
            "a.obj",
            "vertex 3 is not finite",
        );
    }
}

#[test]
fn zero_normals_are_named() {
    // The third vertex of `floor` (in order of first use) takes the zero normal.
    let obj = GOOD_OBJ.replace(
        "f 1 2 3\nf 1 3 4",
        "vn 0 1 0\nvn 0 0 0\nf 1//1 2//1 3//2\nf 1//1 3//2 4//1",
    );
    error_of(
        "zeronormal",
        &[
            ("s.toml", &scene_toml("a.obj")),
            ("a.obj", &obj),
            ("m.mtl", GOOD_MTL),
        ],
        "a.obj",
        "object `floor`: normal 3 is zero or not finite",
    );
}

#[test]
fn broken_obj_and_mtl_syntax_are_named() {
    let obj = GOOD_OBJ.replace("f 1 2 3", "f 1 x 3");
    error_of(
        "badobj",
        &[
            ("s.toml", &scene_toml("a.obj")),
            ("a.obj", &obj),
            ("m.mtl", GOOD_MTL),
        ],
        "a.obj",
        "malformed OBJ",
    );
    let mtl = GOOD_MTL.replace("Kd 0.5 0.5 0.5", "Kd 0.5 zero 0.5");
    error_of(
        "badmtl",
        &[
            ("s.toml", &scene_toml("a.obj")),
            ("a.obj", GOOD_OBJ),
            ("m.mtl", &mtl),
        ],
        "m.mtl",
        "malformed MTL",
    );
    let obj = GOOD_OBJ.replace("f 1 3 4", "f 1 3 40");
    error_of(
        "badidx",
        &[
            ("s.toml", &scene_toml("a.obj")),
            ("a.obj", &obj),
            ("m.mtl", GOOD_MTL),
        ],
        "a.obj",
        "face vertex index out of bounds",
    );
}

/// A second mesh, not a light, scaled to about 1e19: its vertices used to reach the BVH
/// builder, which panicked. Every vertex is checked after the transform.
#[test]
fn huge_coordinates_of_any_mesh_are_refused() {
    let floor = "mtllib m.mtl\no big\nusemtl white\nv -1 0 -1\nv -1 0 1\nv 1 0 1\nf 1 2 3\n";
    let toml = scene_toml("a.obj") + "[[mesh]]\nobj = \"b.obj\"\nscale = 1e19\n";
    error_of(
        "huge2",
        &[
            ("s.toml", &toml),
            ("a.obj", GOOD_OBJ),
            ("b.obj", floor),
            ("m.mtl", GOOD_MTL),
        ],
        "b.obj",
        "beyond the 1e15 scene units",
    );
    let toml = scene_toml("a.obj")
        + "[[sphere]]\ncenter = [1e19, 0, 0]\nradius = 1\nmaterial = \"white\"\n";
    error_of(
        "hugesphere",
        &[("s.toml", &toml), ("a.obj", GOOD_OBJ), ("m.mtl", GOOD_MTL)],
        "s.toml",
        "sphere 0",
    );
}

/// Each way a face can lack a material has its own message.
#[test]
fn missing_materials_are_told_apart() {
    let mtl = ("m.mtl", GOOD_MTL);
    let toml = scene_toml("a.obj");
    error_of(
        "emptyobj",
        &[("s.toml", &toml), ("a.obj", ""), mtl],
        "a.obj",
        "the OBJ file is empty",
    );
    error_of(
        "nofaces",
        &[("s.toml", &toml), ("a.obj", "mtllib m.mtl\nv 0 0 0\n"), mtl],
        "a.obj",
        "holds no faces",
    );
    error_of(
        "nomtllib",
        &[
            ("s.toml", &toml),
            ("a.obj", &GOOD_OBJ.replace("mtllib m.mtl\n", "")),
            mtl,
        ],
        "a.obj",
        "`usemtl white` (line 2) names a material, but the OBJ names no MTL file",
    );
    error_of(
        "unknownmtl",
        &[
            ("s.toml", &toml),
            ("a.obj", &GOOD_OBJ.replace("usemtl white", "usemtl whyte")),
            mtl,
        ],
        "a.obj",
        "`usemtl whyte` (line 3): unknown material; m.mtl defines `white`, `light`",
    );
    error_of(
        "nousemtl",
        &[
            ("s.toml", &toml),
            ("a.obj", &GOOD_OBJ.replace("usemtl white\n", "")),
            mtl,
        ],
        "a.obj",
        "object `floor` has faces before any `usemtl` line",
    );
}

/// A FIFO (or any non-regular file) named by a scene is refused before it is opened, which
/// would block until a writer came.
#[cfg(unix)]
#[test]
fn non_regular_files_are_refused_without_opening() {
    let dir = Scratch::new(
        "fifo",
        &[("s.toml", &scene_toml("a.obj")), ("m.mtl", GOOD_MTL)],
    );
    let made = std::process::Command::new("mkfifo")
        .arg(dir.path("a.obj"))
        .status()
        .unwrap();
    assert!(made.success());
    let err = Scene::load(dir.path("s.toml")).err().unwrap();
    assert!(err.file.ends_with("a.obj"), "{err}");
    assert!(err.to_string().contains("not a regular file"), "{err}");
}

/// `threads` rayon threads running `f`.
fn on_threads<T: Send>(threads: usize, f: impl FnOnce() -> T + Send) -> T {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap()
        .install(f)
}

/// A height field of `w` x `h` quads as OBJ text: plain `v` and `f` lines (the quick path),
/// then a group whose faces carry texture and normal indices, one with quads, one with
/// relative indices (the general path).
fn big_obj(w: usize, h: usize) -> String {
    use std::fmt::Write;
    let mut s = String::from("mtllib m.mtl\nusemtl white\n");
    for j in 0..=h {
        for i in 0..=w {
            let (x, z) = (i as f64 / w as f64, j as f64 / h as f64);
            let y = 0.1 * (9.0 * x).sin() * (7.0 * z).cos();
            let _ = writeln!(s, "v {x:.6} {y:.6} {z:.7}");
        }
    }
    let row = w + 1;
    for j in 0..h {
        for i in 0..w {
            let a = j * row + i + 1;
            let (b, c, d) = (a + 1, a + row, a + row + 1);
            let _ = writeln!(s, "f {a} {c} {b}\nf {b}\t{c} {d}");
        }
    }
    s += "vt 0 0\nvt 1 0\nvt 0 1\nvn 0 1 0\ng textured\nf 1/1/1 2/2/1 3/3/1\nf 3/3 2/2 4/1\n";
    let _ = writeln!(
        s,
        "g quads\nusemtl light\nf 1 2 {} {}\nf -1 -2 -3",
        row + 2,
        row + 1
    );
    s
}

/// Large files are read in pieces on every core: the same bytes as one sequential read,
/// on any number of threads, at and around the sizes where the pieces change.
#[test]
fn large_files_read_whole_on_any_thread_count() {
    let piece = 4 << 20;
    let dir = Scratch::new("pieces", &[]);
    for len in [2 * piece - 1, 2 * piece, 2 * piece + 1, 3 * piece + 12345] {
        let bytes: Vec<u8> = (0..len).map(|i| (i * 7 + i / 4093) as u8).collect();
        let path = dir.path("big.bin");
        std::fs::write(&path, &bytes).unwrap();
        for threads in [1, 2, 3] {
            let got = on_threads(threads, || crate::load::read_regular(&path)).unwrap();
            assert!(got == bytes, "{len} bytes on {threads} threads");
        }
    }
}

/// A large OBJ (several text chunks, read in pieces) loads to the same mesh, bit for bit,
/// and the same hashes on 1, 2 and 3 threads.
#[test]
fn a_large_obj_loads_the_same_on_any_thread_count() {
    let obj = big_obj(420, 320);
    assert!(obj.len() > 9 << 20, "{} bytes", obj.len());
    let dir = Scratch::new(
        "bigobj",
        &[
            ("s.toml", &scene_toml("a.obj")),
            ("a.obj", &obj),
            ("m.mtl", GOOD_MTL),
        ],
    );
    let bits = |v: &[glam::Vec3]| v.iter().map(|p| p.to_array().map(f32::to_bits)).collect();
    let seen = |threads| {
        let s = on_threads(threads, || Scene::load(dir.path("s.toml"))).unwrap();
        let m = s.geometry.mesh();
        let uv: Vec<[u32; 2]> = m
            .texcoords
            .iter()
            .map(|t| t.to_array().map(f32::to_bits))
            .collect();
        let hashes = [s.content_hash, s.photon_hash, s.image_hash, s.view_hash];
        let positions: Vec<[u32; 3]> = bits(&m.positions);
        let normals: Vec<[u32; 3]> = bits(&m.normals);
        (
            positions,
            normals,
            uv,
            m.indices.clone(),
            m.materials.clone(),
            hashes,
        )
    };
    let one = seen(1);
    assert_eq!(one.3.len(), 2 * 420 * 320 + 2 + 2 + 1);
    for threads in [2, 3] {
        assert!(seen(threads) == one, "{threads} threads");
    }
}
