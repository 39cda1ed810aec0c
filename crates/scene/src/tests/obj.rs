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
