//! Scene loading against the course worksheet's numbers for its scene (restated in each
//! test), and every kind of bad input.

use crate::{Light, Material, Scene};
use glam::Vec3;
use std::path::{Path, PathBuf};

fn scenes_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes")
}

fn load(rel: &str) -> Scene {
    let p = scenes_dir().join(rel);
    Scene::load(&p).unwrap_or_else(|e| panic!("{e}"))
}

fn close(a: Vec3, b: Vec3, tol: f32) -> bool {
    (a - b).abs().max_element() <= tol
}

#[test]
fn tessellated_cornell_matches_the_worksheet_scene() {
    let s = load("cornell-spheres/tessellated.toml");
    // Box: 6 quads = 12 triangles; each UV sphere 2 * 64 * 63 = 8064.
    assert_eq!(s.geometry.mesh().len(), 12 + 2 * 8064);
    assert_eq!(s.geometry.spheres().len(), 0);
    assert_eq!(
        s.lights.len(),
        2,
        "the light quad is two emissive triangles"
    );
    check_light(&s);
    // Every sphere vertex lies 2.25 (= 90 * 0.025) from its transformed centre.
    let m = s.geometry.mesh();
    for (name, c) in [
        ("silver", Vec3::new(-10.505, 2.29075, -9.23675)),
        ("glass", Vec3::new(-3.272, 2.29, -6.2395)),
    ] {
        let id = s.material_of(name).unwrap();
        let tris: Vec<usize> = (0..m.len()).filter(|&t| m.materials[t] == id).collect();
        assert_eq!(tris.len(), 8064, "{name}");
        for &t in &tris {
            for p in m.vertices(t) {
                assert!(((p - c).length() - 2.25).abs() < 2e-5, "{name}: {p:?}");
            }
            // Smooth normals are radial and the winding faces out.
            let [a, _, _] = m.indices[t];
            assert!(m.normals[a as usize].dot((m.positions[a as usize] - c).normalize()) > 0.9999);
            assert!(m.face_normal(t).dot(m.vertices(t)[0] - c) > 0.0);
        }
    }
    assert_eq!(
        s.materials[s.material_of("silver").unwrap() as usize],
        Material::Metal {
            reflectance: Vec3::new(0.96, 0.98, 0.96)
        }
    );
    assert_eq!(
        s.materials[s.material_of("glass").unwrap() as usize],
        Material::glass(1.5)
    );
    assert_eq!(
        s.materials[s.material_of("red").unwrap() as usize],
        Material::Lambertian {
            albedo: Vec3::new(0.9, 0.0, 0.0)
        }
    );
}

#[test]
fn analytic_cornell_matches_the_worksheet_scene() {
    let s = load("cornell-spheres/analytic.toml");
    assert_eq!(s.geometry.mesh().len(), 12);
    assert_eq!(s.geometry.spheres().len(), 2);
    assert_eq!(s.lights.len(), 2);
    check_light(&s);
    let sp = s.geometry.spheres();
    assert!(close(
        sp[0].center,
        Vec3::new(-10.505, 2.2907, -9.2368),
        1e-4
    ));
    // The worksheet gives 2.2901 for 0.025 * 91.60 = 2.29: rounding in the source.
    assert!(close(
        sp[1].center,
        Vec3::new(-3.2720, 2.2901, -6.2395),
        2e-4
    ));
    assert!(sp.iter().all(|s| s.radius == 2.25));
    // Camera of the course: 53.13 degrees puts the image plane at [-0.5, 0.5] at distance 1.
    let c = &s.camera;
    assert_eq!((c.width, c.height), (512, 512));
    let corner = c.ray(0.0, 0.0).d;
    let d = corner / corner.dot(c.forward());
    assert!(
        (d.y - 0.5).abs() < 1e-4 && (d.x + 0.5).abs() < 1e-4,
        "{d:?}"
    );
}

fn check_light(s: &Scene) {
    // Area 130 mm x 105 mm x 0.025^2 = 8.53125; power = pi A Le.
    assert!(
        (s.light_area() - 8.53125).abs() < 1e-5,
        "area {}",
        s.light_area()
    );
    let le = Vec3::new(36.8, 31.2, 16.0);
    let expect = (std::f64::consts::PI * 8.53125) as f32 * le;
    assert!(
        close(s.light_power(), expect, 1e-3),
        "{:?} vs {expect:?}",
        s.light_power()
    );
    assert!(close(s.light_power(), Vec3::new(986.3, 836.2, 428.8), 0.1));
    for l in &s.lights {
        assert_eq!(l.le, le);
        assert!(close(l.normal, Vec3::NEG_Y, 1e-6), "faces down");
        for p in s.geometry.mesh().vertices(l.triangle as usize) {
            assert!((p.y - 13.7175).abs() < 1e-5);
            assert!(
                (-8.575..=-5.325).contains(&p.x) && (-8.3..=-5.675).contains(&p.z),
                "{p:?}"
            );
        }
    }
    // 0.0025 below the ceiling.
    let ceiling = s.material_of("white").unwrap();
    let m = s.geometry.mesh();
    let top = (0..m.len())
        .filter(|&t| m.materials[t] == ceiling)
        .flat_map(|t| m.vertices(t))
        .map(|p| p.y)
        .fold(f32::MIN, f32::max);
    assert!((top - 13.72).abs() < 1e-5 && ((top - 13.7175) - 0.0025).abs() < 1e-5);
}

#[test]
fn every_scene_in_the_tree_loads() {
    for rel in [
        "cornell-spheres/tessellated.toml",
        "cornell-spheres/analytic.toml",
        "cornell-spheres/coloured-glass.toml",
        "furnace/furnace.toml",
        "plane-light/plane-light.toml",
        "corner/corner.toml",
    ] {
        let s = load(rel);
        assert!(
            !s.lights.is_empty() && s.light_power().min_element() > 0.0,
            "{rel}"
        );
    }
}

#[test]
fn content_hash_changes_with_any_input() {
    let a = load("cornell-spheres/analytic.toml");
    let b = load("cornell-spheres/analytic.toml");
    assert_eq!(a.content_hash, b.content_hash);
    let text = std::fs::read_to_string(scenes_dir().join("cornell-spheres/analytic.toml")).unwrap();
    let edited = text.replace("ior = 1.5", "ior = 1.51");
    let c = Scene::from_toml(&scenes_dir().join("cornell-spheres/analytic.toml"), &edited).unwrap();
    assert_ne!(a.content_hash, c.content_hash);
    assert_ne!(
        a.photon_hash, c.photon_hash,
        "a material change changes the photons"
    );
    // The camera, [render] and [estimate] do not change photons; the camera changes images.
    let d = Scene::from_toml(
        &scenes_dir().join("cornell-spheres/analytic.toml"),
        &(text.replace("vfov = 53.13", "vfov = 50") + "\n[estimate.global]\nk = 20\n"),
    )
    .unwrap();
    assert_ne!(a.content_hash, d.content_hash);
    assert_eq!(a.photon_hash, d.photon_hash);
    assert_ne!(a.image_hash, d.image_hash);
    let e = Scene::from_toml(
        &scenes_dir().join("cornell-spheres/analytic.toml"),
        &(text.clone() + "\n[estimate.global]\nk = 20\n"),
    )
    .unwrap();
    assert_eq!(a.image_hash, e.image_hash);
}

/// A scratch directory with the given files; removed on drop.
struct Scratch(PathBuf);

impl Scratch {
    fn new(name: &str, files: &[(&str, &str)]) -> Scratch {
        let dir =
            std::env::temp_dir().join(format!("photonflow-scene-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        for (f, text) in files {
            std::fs::write(dir.join(f), text).unwrap();
        }
        Scratch(dir)
    }
    fn path(&self, f: &str) -> PathBuf {
        self.0.join(f)
    }
}

impl Drop for Scratch {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

const CAMERA: &str =
    "[camera]\neye = [0, 1, 3]\nlook_at = [0, 0, 0]\nvfov = 60\nwidth = 8\nheight = 8\n";
const GOOD_OBJ: &str = "mtllib m.mtl\no floor\nusemtl white\nv -1 0 -1\nv -1 0 1\nv 1 0 1\nv 1 0 -1\nf 1 2 3\nf 1 3 4\n\
o light\nusemtl light\nv -0.1 1 -0.1\nv 0.1 1 -0.1\nv 0.1 1 0.1\nv -0.1 1 0.1\nf 5 6 7\nf 5 7 8\n";
const GOOD_MTL: &str = "newmtl white\nKd 0.5 0.5 0.5\nnewmtl light\nKd 0 0 0\nKe 4 4 4\n";

fn scene_toml(obj: &str) -> String {
    format!("{CAMERA}[[mesh]]\nobj = \"{obj}\"\n")
}

/// Load a scene from files and return the error text, which must name `file`.
fn error_of(name: &str, files: &[(&str, &str)], file: &str, problem: &str) {
    let dir = Scratch::new(name, files);
    let err = match Scene::load(dir.path("s.toml")) {
        Ok(_) => panic!("{name}: loaded although broken"),
        Err(e) => e,
    };
    let text = err.to_string();
    assert!(
        err.file.ends_with(file),
        "{name}: error names {:?}, not {file}: {text}",
        err.file
    );
    assert!(
        text.contains(problem),
        "{name}: `{text}` does not say `{problem}`"
    );
}

#[test]
fn the_good_scene_used_below_loads() {
    let dir = Scratch::new(
        "good",
        &[
            ("s.toml", &scene_toml("a.obj")),
            ("a.obj", GOOD_OBJ),
            ("m.mtl", GOOD_MTL),
        ],
    );
    let s = Scene::load(dir.path("s.toml")).unwrap();
    assert_eq!(s.lights.len(), 2);
    assert!((s.light_area() - 0.04).abs() < 1e-6);
}

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
fn unknown_illum_code_is_named() {
    let mtl = GOOD_MTL.replace("Kd 0.5 0.5 0.5", "Kd 0.5 0.5 0.5\nillum 42");
    error_of(
        "illum",
        &[
            ("s.toml", &scene_toml("a.obj")),
            ("a.obj", GOOD_OBJ),
            ("m.mtl", &mtl),
        ],
        "m.mtl",
        "unknown illum code 42",
    );
}

#[test]
fn a_scene_without_light_is_refused_with_a_hint() {
    let mtl = GOOD_MTL.replace("Ke 4 4 4", "Ka 4 4 4");
    error_of(
        "nolight",
        &[
            ("s.toml", &scene_toml("a.obj")),
            ("a.obj", GOOD_OBJ),
            ("m.mtl", &mtl),
        ],
        "s.toml",
        "no light",
    );
    error_of(
        "nolight2",
        &[
            ("s.toml", &scene_toml("a.obj")),
            ("a.obj", GOOD_OBJ),
            ("m.mtl", &mtl),
        ],
        "s.toml",
        "emission = \"ka\"",
    );
}

#[test]
fn zero_area_light_is_refused() {
    let obj = GOOD_OBJ
        .replace("v 0.1 1 0.1", "v -0.1 1 -0.1")
        .replace("v 0.1 1 -0.1", "v -0.1 1 -0.1");
    error_of(
        "zeroarea",
        &[
            ("s.toml", &scene_toml("a.obj")),
            ("a.obj", &obj),
            ("m.mtl", GOOD_MTL),
        ],
        "s.toml",
        "zero-area light",
    );
}

#[test]
fn malformed_toml_values_are_named_with_their_line() {
    let toml = scene_toml("a.obj").replace("vfov = 60", "vfov = \"wide\"");
    error_of(
        "toml",
        &[("s.toml", &toml), ("a.obj", GOOD_OBJ), ("m.mtl", GOOD_MTL)],
        "s.toml",
        "line 4",
    );
    let toml = scene_toml("a.obj") + "spp = 4\n";
    error_of(
        "unknown-key",
        &[("s.toml", &toml), ("a.obj", GOOD_OBJ), ("m.mtl", GOOD_MTL)],
        "s.toml",
        "unknown field `spp`",
    );
    let toml = scene_toml("a.obj") + "[render]\nspp = 0\n";
    error_of(
        "spp0",
        &[("s.toml", &toml), ("a.obj", GOOD_OBJ), ("m.mtl", GOOD_MTL)],
        "s.toml",
        "render.spp = 0",
    );
    let toml = scene_toml("a.obj").replace("look_at = [0, 0, 0]", "look_at = [0, 1, 3]");
    error_of(
        "camera",
        &[("s.toml", &toml), ("a.obj", GOOD_OBJ), ("m.mtl", GOOD_MTL)],
        "s.toml",
        "camera",
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

#[test]
fn absurd_light_power_or_size_is_refused_not_overflowed() {
    // Finite emission times area can overflow f32 power, which used to panic downstream.
    let mtl = GOOD_MTL.replace("Ke 4 4 4", "Ke 3e38 3e38 3e38");
    let toml = scene_toml("a.obj").replace("obj = \"a.obj\"", "obj = \"a.obj\"\nscale = 4");
    error_of(
        "power",
        &[("s.toml", &toml), ("a.obj", GOOD_OBJ), ("m.mtl", &mtl)],
        "s.toml",
        "overflows f32",
    );
    let mtl = GOOD_MTL.replace("Ke 4 4 4", "Ke 3e38 0 0");
    let toml = scene_toml("a.obj").replace("obj = \"a.obj\"", "obj = \"a.obj\"\nscale = 40");
    error_of(
        "power1",
        &[("s.toml", &toml), ("a.obj", GOOD_OBJ), ("m.mtl", &mtl)],
        "s.toml",
        "overflows f32",
    );
    let toml = scene_toml("a.obj").replace("obj = \"a.obj\"", "obj = \"a.obj\"\nscale = 1e25");
    error_of(
        "huge",
        &[("s.toml", &toml), ("a.obj", GOOD_OBJ), ("m.mtl", GOOD_MTL)],
        "a.obj",
        "check the scale",
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

/// `Kd 0.5` is grey (a real MTL variant; tobj alone panics on it); two numbers are an error.
#[test]
fn one_number_mtl_colour_is_grey() {
    let dir = Scratch::new(
        "grey",
        &[
            ("s.toml", &scene_toml("a.obj")),
            ("a.obj", GOOD_OBJ),
            ("m.mtl", &GOOD_MTL.replace("Kd 0.5 0.5 0.5", "Kd 0.25")),
        ],
    );
    let s = Scene::load(dir.path("s.toml")).unwrap();
    let white = s.material_of("white").unwrap() as usize;
    assert_eq!(
        s.materials[white],
        Material::Lambertian {
            albedo: Vec3::splat(0.25)
        }
    );
    error_of(
        "grey2",
        &[
            ("s.toml", &scene_toml("a.obj")),
            ("a.obj", GOOD_OBJ),
            ("m.mtl", &GOOD_MTL.replace("Kd 0.5 0.5 0.5", "Kd 0.5 0.5")),
        ],
        "m.mtl",
        "line 2: `Kd` needs one number (grey) or three (RGB), got 2",
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

/// An OBJ of the light and one face of `pts` (x, z at y = `y(i)`), material `white`.
fn face_obj(pts: &[(f64, f64)], y: impl Fn(usize) -> f64) -> String {
    let light = "o light\nusemtl light\nv -0.1 1 -0.1\nv 0.1 1 -0.1\nv 0.1 1 0.1\nv -0.1 1 0.1\nf 1 2 3\nf 1 3 4\n";
    let mut o = format!("mtllib m.mtl\n{light}o face\nusemtl white\n");
    for (i, (x, z)) in pts.iter().enumerate() {
        o += &format!("v {x} {} {z}\n", y(i));
    }
    o += "f";
    for i in 0..pts.len() {
        o += &format!(" {}", i + 5);
    }
    o + "\n"
}

/// The face's triangles (those of material `white`) and their total area, or the load error.
fn face_area(obj: &str) -> Result<(usize, f64), String> {
    // One directory per call: the tests that call this run in parallel.
    static CALLS: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
    let call = CALLS.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let dir = Scratch::new(
        &format!("poly-{call}"),
        &[
            ("s.toml", &scene_toml("a.obj")),
            ("a.obj", obj),
            ("m.mtl", GOOD_MTL),
        ],
    );
    let s = Scene::load(dir.path("s.toml")).map_err(|e| e.to_string())?;
    let m = s.geometry.mesh();
    let white = s.material_of("white").unwrap();
    let tris: Vec<usize> = (0..m.len()).filter(|&t| m.materials[t] == white).collect();
    Ok((tris.len(), tris.iter().map(|&t| m.area(t) as f64).sum()))
}

/// Faces are triangulated in (near) linear time: a convex face of 200k vertices loads at
/// once (a fan of it took minutes to build a BVH over), a non-convex face is ear-clipped
/// into the right area, and a huge non-convex face is refused, not clipped for hours.
#[test]
fn polygons_triangulate_fast_and_right() {
    let face = |pts: &[(f64, f64)]| face_obj(pts, |_| 0.0);
    let area_of = face_area;
    // An L of area 3: a fan from its first vertex (tobj's) covers 4, outside the L.
    let l = [
        (0.0, 2.0),
        (0.0, 0.0),
        (2.0, 0.0),
        (2.0, 1.0),
        (1.0, 1.0),
        (1.0, 2.0),
    ];
    let (n, a) = area_of(&face(&l)).unwrap();
    assert_eq!(n, 4);
    assert!((a - 3.0).abs() < 1e-5, "L-shape area {a}");
    // A circle of 200k vertices written with 7 decimals (rounding dents everywhere).
    let n = 200_000;
    let circle: Vec<(f64, f64)> = (0..n)
        .map(|i| {
            let t = std::f64::consts::TAU * i as f64 / n as f64;
            (
                (t.cos() * 1e7).round() / 1e7,
                -(t.sin() * 1e7).round() / 1e7,
            )
        })
        .collect();
    // Rounding puts runs of vertices on exactly straight lines (near the axes, where one
    // coordinate moves by a step of the 7th decimal or none between neighbours): those are
    // not corners, and the face is triangulated by the others. Counted here on the f32
    // coordinates the loader reads, each vertex against its neighbours.
    let read: Vec<[f64; 2]> = circle
        .iter()
        .map(|&(x, z)| [x, z].map(|c| f64::from(format!("{c}").parse::<f32>().unwrap())))
        .collect();
    let inside = (0..n)
        .filter(|&i| {
            let [a, b, c] = [read[(i + n - 1) % n], read[i], read[(i + 1) % n]];
            let (u, v) = ([b[0] - a[0], b[1] - a[1]], [c[0] - b[0], c[1] - b[1]]);
            u[0] * v[1] - u[1] * v[0] == 0.0 && u[0] * v[0] + u[1] * v[1] > 0.0
        })
        .count();
    assert!(
        inside > 0 && inside < n / 10,
        "{inside} vertices on straight runs"
    );
    // Work done, not seconds: every corner is in exactly one fan triangle (speed is the
    // bad-input table's timeout's business, and a benchmark's).
    let (tris, a) = area_of(&face(&circle)).unwrap();
    assert_eq!(tris, n - inside - 2);
    assert!((a - std::f64::consts::PI).abs() < 1e-3, "circle area {a}");
    // The same circle with a notch: non-convex and far too big to ear-clip.
    let mut notched = circle.clone();
    notched[n / 2] = (0.0, 0.0);
    let e = area_of(&face(&notched)).unwrap_err();
    assert!(e.contains("a non-convex face of 200000 vertices"), "{e}");
}

/// Vertices inside straight edges are not corners: a face along a square's edges is two
/// triangles (it used to be n - 2, most of zero area, and a BVH over 400k of those took
/// minutes), a non-convex face with long straight edges is clipped by its corners (it used to
/// be refused as too big to clip), and what only looks straight in the face's plane, or a
/// face with no area, keeps what it had.
#[test]
fn straight_edges_are_triangulated_by_their_corners() {
    // A square of side 2 with `q` vertices per edge, corners included, counter-clockwise.
    let square = |q: usize| -> Vec<(f64, f64)> {
        let t = |i: usize| -1.0 + 2.0 * i as f64 / q as f64;
        let mut p = Vec::new();
        p.extend((0..q).map(|i| (t(i), -1.0)));
        p.extend((0..q).map(|i| (1.0, t(i))));
        p.extend((0..q).map(|i| (-t(i), 1.0)));
        p.extend((0..q).map(|i| (-1.0, -t(i))));
        p
    };
    let flat = |_| 0.0;
    let (tris, a) = face_area(&face_obj(&square(25_000), flat)).unwrap();
    assert_eq!(tris, 2);
    assert!((a - 4.0).abs() < 1e-6, "square area {a}");
    // Vertex 0 repeated, and the run across the wrap-around (the last edge into the first).
    let mut sq = square(50);
    sq.rotate_left(25);
    sq.insert(0, sq[0]);
    let (tris, a) = face_area(&face_obj(&sq, flat)).unwrap();
    assert_eq!(tris, 2);
    assert!((a - 4.0).abs() < 1e-6, "rotated square area {a}");
    // An L of area 3 with 1000 vertices per unit of edge: 6 corners, 4 triangles.
    let corners: [(f64, f64); 6] = [
        (0.0, 2.0),
        (0.0, 0.0),
        (2.0, 0.0),
        (2.0, 1.0),
        (1.0, 1.0),
        (1.0, 2.0),
    ];
    let mut l = Vec::new();
    for (k, &(x0, z0)) in corners.iter().enumerate() {
        let (x1, z1) = corners[(k + 1) % corners.len()];
        let steps = 1000 * (x1 - x0).abs().max((z1 - z0).abs()) as usize;
        l.extend((0..steps).map(|i| {
            let f = i as f64 / steps as f64;
            (x0 + f * (x1 - x0), z0 + f * (z1 - z0))
        }));
    }
    assert_eq!(l.len(), 8000);
    let (tris, a) = face_area(&face_obj(&l, flat)).unwrap();
    assert_eq!(tris, 4);
    assert!((a - 3.0).abs() < 1e-5, "L area {a}");
    // Straight seen from above, but the edge z = -1 zigzags in y: its 8 vertices stay, the
    // 7 inside each other edge go.
    let sq = square(8);
    let zigzag = |i: usize| if i < 8 && i % 2 == 1 { 0.01 } else { 0.0 };
    let (tris, _) = face_area(&face_obj(&sq, zigzag)).unwrap();
    assert_eq!(tris, sq.len() - 3 * 7 - 2);
    // A face of 20 vertices on one line has no area: one triangle of it, not 18.
    let line: Vec<(f64, f64)> = (0..20).map(|i| (i as f64 * 0.1, 0.0)).collect();
    let (tris, a) = face_area(&face_obj(&line, flat)).unwrap();
    assert_eq!((tris, a), (1, 0.0));
}

/// The floor's material `white` of [`GOOD_MTL`] given `lines` instead, loaded with emission
/// from `emission` (`ke`, `ka`): the material, and the warnings.
fn white_as(lines: &str, emission: &str) -> Result<(Material, Vec<String>), String> {
    let mtl = GOOD_MTL.replace("Kd 0.5 0.5 0.5", lines);
    let mtl = if emission == "ka" {
        mtl.replace("Ke 4 4 4", "Ka 4 4 4")
    } else {
        mtl
    };
    let toml = format!("{}emission = \"{emission}\"\n", scene_toml("a.obj"));
    let dir = Scratch::new(
        "mtl-conventions",
        &[("s.toml", &toml), ("a.obj", GOOD_OBJ), ("m.mtl", &mtl)],
    );
    match Scene::load(dir.path("s.toml")) {
        Ok(s) => {
            let id = s.material_names.iter().position(|n| n == "white").unwrap();
            Ok((s.materials[id].clone(), s.warnings.clone()))
        }
        Err(e) => {
            assert!(e.file.ends_with("m.mtl"), "{e}: names {:?}", e.file);
            assert!(e.to_string().contains("material `white`"), "{e}");
            Err(e.to_string())
        }
    }
}

/// The MTL table of `Material`'s docs, row by row: what each key draws, which approximations
/// warn (naming the file and material) and what is refused (naming file, material and key).
#[test]
fn mtl_files_follow_the_documented_table() {
    let v = |x: f32| Vec3::splat(x);
    let ok = |lines: &str| white_as(lines, "ke").unwrap_or_else(|e| panic!("{lines}: {e}"));
    let quiet = |lines: &str| {
        let (m, w) = ok(lines);
        assert!(w.is_empty(), "{lines}: {w:?}");
        m
    };
    let warned = |lines: &str, what: &str| {
        let (m, w) = ok(lines);
        assert!(
            w.iter()
                .any(|w| w.contains(what) && w.contains("m.mtl: material `white`")),
            "{lines}: no warning saying `{what}`: {w:?}"
        );
        m
    };
    let refused = |lines: &str, emission: &str, key: &str| match white_as(lines, emission) {
        Ok(m) => panic!("{lines}: accepted as {m:?}"),
        Err(e) => assert!(e.contains(key), "{lines}: `{e}` does not name `{key}`"),
    };
    // Diffuse.
    assert_eq!(
        quiet("Kd 0.5 0.5 0.5\nillum 1"),
        Material::Lambertian { albedo: v(0.5) }
    );
    assert_eq!(
        quiet("Kd 0.5 0.5 0.5\nillum 0"),
        Material::Lambertian { albedo: v(0.5) }
    );
    warned(
        "Kd 0.5 0.5 0.5\nKs 0.3 0.3 0.3\nillum 1",
        "`Ks 0.3 0.3 0.3` is not drawn",
    );
    // Glossy: Walter et al.'s alpha = sqrt(2 / (Ns + 2)).
    assert_eq!(
        quiet("Kd 0.5 0.5 0.5\nKs 0.3 0.3 0.3\nNs 200\nillum 2"),
        Material::Glossy {
            albedo: v(0.5),
            specular: v(0.3),
            alpha: (2.0f32 / 202.0).sqrt()
        }
    );
    // McGuire's glossy box: Kd 0.66 + Ks 0.9 scaled to sum to 1 in each channel.
    let Material::Glossy {
        albedo, specular, ..
    } = warned(
        "Kd 0.66 0.66 0.66\nKs 0.9 0.9 0.9\nNs 40\nillum 2",
        "exceeds 1",
    )
    else {
        panic!("not glossy")
    };
    assert!((albedo.x - 0.66 / 1.56).abs() < 1e-6 && (specular.x - 0.9 / 1.56).abs() < 1e-6);
    // Scaled sums that round a hair above 1 still load; a mirror-like exponent takes the
    // smallest roughness.
    for (kd, ks) in [
        ("0.66 0.33 0.1", "0.9 0.8 0.95"),
        ("0.7 0.61 0.57", "0.31 0.77 0.83"),
    ] {
        warned(&format!("Kd {kd}\nKs {ks}\nNs 10\nillum 2"), "exceeds 1");
    }
    let Material::Glossy { alpha, .. } = quiet("Kd 0.3 0.3 0.3\nKs 0.7 0.7 0.7\nNs 1e12\nillum 2")
    else {
        panic!("not glossy")
    };
    assert_eq!(alpha, 1e-4);
    assert_eq!(
        quiet("Kd 0.5 0.5 0.5\nKs 0 0 0\nillum 2"),
        Material::Lambertian { albedo: v(0.5) }
    );
    // Mirrors.
    assert_eq!(
        quiet("Kd 0 0 0\nKs 0.9 0.8 0.7\nillum 3"),
        Material::Mirror {
            reflectance: Vec3::new(0.9, 0.8, 0.7)
        }
    );
    assert_eq!(
        quiet("Kd 0 0 0\nillum 3"),
        Material::Mirror {
            reflectance: v(1.0)
        }
    );
    warned(
        "Kd 0 0 0\nKs 0.9 0.9 0.9\nillum 5",
        "illum 5 (Fresnel reflection)",
    );
    warned("Kd 0 0 0\nKs 0.9 0.9 0.9\nillum 8", "illum 8");
    warned(
        "Kd 0.5 0.5 0.5\nKs 0.9 0.9 0.9\nillum 3",
        "`Kd 0.5 0.5 0.5` is not used",
    );
    // Glass.
    assert_eq!(quiet("Ni 1.33\nillum 7"), Material::glass(1.33));
    assert_eq!(quiet("Ni 1.5\nillum 4"), Material::glass(1.5));
    assert_eq!(quiet("Kd 0.5 0.5 0.5\nNi 1.4\nd 0.2"), Material::glass(1.4));
    assert_eq!(
        warned("illum 4", "drawn with index 1.5"),
        Material::glass(1.5)
    );
    warned("Ni 1.5\nillum 6", "illum 6");
    warned("Ni 1.5\nillum 9", "illum 9");
    warned(
        "Ni 1.5\nKs 0.5 0.5 0.5\nillum 7",
        "glass reflects by the Fresnel",
    );
    assert_eq!(quiet("Ni 1.5\nTr 0.9\nillum 7"), Material::glass(1.5));
    // Course metal.
    assert_eq!(
        quiet("Ks 0.96 0.98 0.96\nillum 11"),
        Material::Metal {
            reflectance: Vec3::new(0.96, 0.98, 0.96)
        }
    );
    // Warned and drawn without.
    warned("Kd 0.5 0.5 0.5\nbump n.png", "`bump n.png`");
    warned("Kd 0.5 0.5 0.5\nrefl r.png", "`refl r.png`");
    warned("Kd 0.5 0.5 0.5\nTf 0.5 0.5 0.5", "`Tf 0.5 0.5 0.5`");
    // Refused, naming the key.
    refused("Kd 0.5 0.5 0.5\nillum 10", "ke", "illum 10");
    refused("Kd 0.5 0.5 0.5\nillum 12", "ke", "unknown illum code 12");
    refused(
        "Kd 0.5 0.5 0.5\nmap_Kd wood.png",
        "ke",
        "`map_Kd wood.png`: ",
    ); // missing
    refused(
        "Kd 0.5 0.5 0.5\nKs 0.5 0.5 0.5\nmap_Ks s.png\nillum 2",
        "ke",
        "map_Ks",
    );
    // Coloured glass: `Tf` is the transmittance (grey with one number); out of [0, 1] refused.
    let tinted = |ior: f32, t: Vec3| Material::Dielectric {
        ior,
        transmittance: t,
        absorption: Vec3::ZERO,
    };
    assert_eq!(
        quiet("Ni 1.5\nTf 0.9 0.5 0.5\nillum 7"),
        tinted(1.5, Vec3::new(0.9, 0.5, 0.5))
    );
    assert_eq!(quiet("Ni 1.5\nTf 0.25\nillum 4"), tinted(1.5, v(0.25)));
    assert_eq!(
        quiet("Kd 0.5 0.5 0.5\nNi 1.4\nd 0.2\nTf 0.2 0.4 0.6"),
        tinted(1.4, Vec3::new(0.2, 0.4, 0.6))
    );
    refused("Ni 1.5\nTf 1.2 0.5 0.5\nillum 7", "ke", "`Tf 1.2 0.5 0.5`");
    refused(
        "Ni 1.5\nTf -0.1 0.5 0.5\nillum 9",
        "ke",
        "must lie in [0, 1]",
    );
    refused("Ni 1.5\nTf nan 0.5 0.5\nillum 4", "ke", "`Tf nan 0.5 0.5`");
    refused("Kd 0.5 0.5 0.5\nd 0.5", "ke", "opacity 0.5");
    refused("Kd 0.5 0.5 0.5\nTr 0.5", "ke", "opacity 0.5");
    refused("Kd 0.5 0.5 0.5\nPr 0.5", "ke", "`Pr 0.5`");
    refused(
        "Kd 0.5 0.5 0.5\nNs -1\nKs 0.5 0.5 0.5\nillum 2",
        "ke",
        "`Ns -1`",
    );
    // A lamp with both Ka and Ke, emission read from Ka: Ke would be dropped.
    refused(
        "Kd 0 0 0\nKa 12 12 12\nKe 5 5 5",
        "ka",
        "`Ke 5 5 5` is not read",
    );
}

/// An image file's bytes, encoded by the `image` crate.
fn encoded(img: image::DynamicImage, format: image::ImageFormat) -> Vec<u8> {
    let mut bytes = std::io::Cursor::new(Vec::new());
    img.write_to(&mut bytes, format).unwrap();
    bytes.into_inner()
}

/// A `w` x `h` 8-bit RGB image with texel `(x, y)` (row 0 at the top) `f(x, y)`.
fn rgb8(w: u32, h: u32, f: impl Fn(u32, u32) -> [u8; 3]) -> image::DynamicImage {
    image::DynamicImage::ImageRgb8(image::RgbImage::from_fn(w, h, |x, y| image::Rgb(f(x, y))))
}

/// sRGB's decoding (IEC 61966-2-1) in f64, written out apart from the renderer's.
fn srgb8(v: u8) -> f32 {
    let c = v as f64 / 255.0;
    (if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }) as f32
}

#[test]
fn textures_decode_to_linear_and_filter_bilinearly() {
    use crate::Texture;
    use glam::Vec2;
    // 8-bit sRGB → linear, per texel, row 0 at the top.
    let px = |x: u32, y: u32| [[188, 20, 0], [255, 128, 3]][((x + y) % 2) as usize];
    let png = encoded(rgb8(2, 2, px), image::ImageFormat::Png);
    let t = Texture::decode(&png, Path::new("t.png")).unwrap();
    assert_eq!((t.width, t.height), (2, 2));
    for (i, c) in t.texels.iter().enumerate() {
        let want = px(i as u32 % 2, i as u32 / 2).map(srgb8);
        assert!(
            close(*c, Vec3::from(want), 1e-6),
            "texel {i}: {c} != {want:?}"
        );
    }
    // Bilinear with texel centres at half-integers, v up the image: the centre of texel
    // (x, y) is uv ((x + 0.5) / w, 1 - (y + 0.5) / h) and reads it exactly.
    let at = |x: usize, y: usize| t.texels[y * 2 + x];
    for (x, y) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
        let uv = Vec2::new((x as f32 + 0.5) / 2.0, 1.0 - (y as f32 + 0.5) / 2.0);
        assert!(close(t.eval(uv), at(x, y), 1e-6), "centre of ({x}, {y})");
    }
    // Midway between all four: their mean. Repeat: whole periods away reads the same.
    let mean = (at(0, 0) + at(1, 0) + at(0, 1) + at(1, 1)) / 4.0;
    assert!(close(t.eval(Vec2::splat(0.5)), mean, 1e-6));
    let uv = Vec2::new(0.3, 0.8);
    assert!(close(t.eval(uv + Vec2::new(3.0, -2.0)), t.eval(uv), 1e-5));
    // Across the edge u = 0 the left column blends with the right one (wrap, not clamp).
    let edge = t.eval(Vec2::new(0.0, 0.75));
    assert!(close(edge, (at(0, 0) + at(1, 0)) / 2.0, 1e-6), "{edge}");
    // Float images are linear already; grey ones read as equal channels.
    let exr = image::DynamicImage::ImageRgb32F(image::Rgb32FImage::from_fn(1, 1, |_, _| {
        image::Rgb([0.3, 0.6, 0.9])
    }));
    let t = Texture::decode(
        &encoded(exr, image::ImageFormat::OpenExr),
        Path::new("t.exr"),
    )
    .unwrap();
    assert!(close(t.texels[0], Vec3::new(0.3, 0.6, 0.9), 1e-6));
    let grey =
        image::DynamicImage::ImageLuma8(image::GrayImage::from_fn(1, 1, |_, _| image::Luma([100])));
    let t = Texture::decode(&encoded(grey, image::ImageFormat::Png), Path::new("t.png")).unwrap();
    assert!(close(t.texels[0], Vec3::splat(srgb8(100)), 1e-6));
    // TGA exactly, JPEG (lossy) within two levels of a flat colour.
    let flat = rgb8(8, 8, |_, _| [200, 120, 40]);
    let t = Texture::decode(
        &encoded(flat.clone(), image::ImageFormat::Tga),
        Path::new("t.tga"),
    )
    .unwrap();
    assert!(close(
        t.texels[0],
        Vec3::from([200, 120, 40].map(srgb8)),
        1e-6
    ));
    let t = Texture::decode(&encoded(flat, image::ImageFormat::Jpeg), Path::new("t.jpg")).unwrap();
    let tol = srgb8(202) - srgb8(200);
    assert!(close(
        t.texels[27],
        Vec3::from([200, 120, 40].map(srgb8)),
        tol
    ));
    // Not an image, or an empty one: one line saying so.
    let e = Texture::decode(b"P3 this is not an image", Path::new("t.png")).unwrap_err();
    assert!(
        e.contains("not a PNG, JPEG, TGA, EXR or Radiance HDR"),
        "{e}"
    );
}

/// The albedo of `scene` seen straight down at `(x, z)` of the y = 0 floor.
fn floor_albedo(scene: &Scene, x: f32, z: f32) -> Vec3 {
    let ray = geom::Ray::new(Vec3::new(x, 0.5, z), Vec3::NEG_Y);
    let hit = scene.geometry.intersect(&ray).expect("the floor");
    scene
        .bsdf_at(&hit)
        .and_then(|b| b.diffuse_albedo())
        .unwrap()
}

#[test]
fn map_kd_multiplies_kd_at_the_obj_texture_coordinates() {
    // The floor of GOOD_OBJ spans x, z in [-1, 1]; vt u = (x + 1) / 2, v = (1 - z) / 2 ... as
    // given per corner below, so the texture's left column lies at x < 0, its top row at z < 0.
    let obj = GOOD_OBJ.replace(
        "v 1 0 -1\nf 1 2 3\nf 1 3 4\n",
        "v 1 0 -1\nvt 0 1\nvt 0 0\nvt 1 0\nvt 1 1\nf 1/1 2/2 3/3\nf 1/1 3/3 4/4\n",
    );
    let px = |x: u32, y: u32| {
        [
            [[250, 10, 10], [10, 250, 10]],
            [[10, 10, 250], [128, 128, 128]],
        ][y as usize][x as usize]
    };
    let png = encoded(rgb8(2, 2, px), image::ImageFormat::Png);
    // Each scene in a directory of its own: a test's scratch directories share a name.
    let n = std::cell::Cell::new(0);
    let setup = |mtl: &str, obj: &str, toml: &str| {
        n.set(n.get() + 1);
        let dir = Scratch::new(
            &format!("map-kd-{}", n.get()),
            &[("s.toml", toml), ("a.obj", obj), ("m.mtl", mtl)],
        );
        std::fs::write(dir.path("t.png"), &png).unwrap();
        dir
    };
    let mtl = GOOD_MTL.replace("Kd 0.5 0.5 0.5", "Kd 0.5 0.5 0.5\nmap_Kd t.png");
    let dir = setup(&mtl, &obj, &scene_toml("a.obj"));
    let s = Scene::load(dir.path("s.toml")).unwrap_or_else(|e| panic!("{e}"));
    assert!(s.warnings.is_empty(), "{:?}", s.warnings);
    // Texel centres at x, z = +-0.5: Kd times the decoded texel.
    for (x, z, tx, ty) in [
        (-0.5, -0.5, 0, 0),
        (0.5, -0.5, 1, 0),
        (-0.5, 0.5, 0, 1),
        (0.5, 0.5, 1, 1),
    ] {
        let want = 0.5 * Vec3::from(px(tx, ty).map(srgb8));
        let got = floor_albedo(&s, x, z);
        assert!(close(got, want, 1e-5), "({x}, {z}): {got} != {want}");
    }
    // The image's bytes key the caches: another texture, another photon set.
    let other = encoded(rgb8(2, 2, |_, _| [1, 2, 3]), image::ImageFormat::Png);
    let dir2 = setup(&mtl, &obj, &scene_toml("a.obj"));
    std::fs::write(dir2.path("t.png"), &other).unwrap();
    let s2 = Scene::load(dir2.path("s.toml")).unwrap();
    assert_ne!(s.photon_hash, s2.photon_hash);
    assert_ne!(s.content_hash, s2.content_hash);
    // No `Kd`: the texture as it is.
    let s = Scene::load(
        setup(
            &GOOD_MTL.replace("Kd 0.5 0.5 0.5", "map_Kd t.png"),
            &obj,
            &scene_toml("a.obj"),
        )
        .path("s.toml"),
    )
    .unwrap();
    assert!(close(
        floor_albedo(&s, 0.5, 0.5),
        Vec3::splat(srgb8(128)),
        1e-5
    ));
    // The scene file's `texture` key does the same for its own materials.
    let toml = format!(
        "{}[material.white]\ntype = \"lambertian\"\nalbedo = [0.5, 0.5, 0.5]\ntexture = \"t.png\"\n",
        scene_toml("a.obj")
    );
    let s = Scene::load(setup(GOOD_MTL, &obj, &toml).path("s.toml")).unwrap();
    assert!(close(
        floor_albedo(&s, -0.5, 0.5),
        0.5 * Vec3::from(px(0, 1).map(srgb8)),
        1e-5
    ));
    // Glossy: `Kd` x the brightest texel + `Ks` above 1 (an EXR texel of 2) scales both
    // there, with a warning.
    let bright = image::DynamicImage::ImageRgb32F(image::Rgb32FImage::from_fn(1, 1, |_, _| {
        image::Rgb([2.0, 0.5, 0.5])
    }));
    let glossy = GOOD_MTL.replace(
        "Kd 0.5 0.5 0.5",
        "Kd 0.5 0.5 0.5\nKs 0.4 0.4 0.4\nNs 100\nillum 2\nmap_Kd t.exr",
    );
    let dir = setup(&glossy, &obj, &scene_toml("a.obj"));
    std::fs::write(
        dir.path("t.exr"),
        encoded(bright, image::ImageFormat::OpenExr),
    )
    .unwrap();
    let s = Scene::load(dir.path("s.toml")).unwrap();
    assert!(
        s.warnings.iter().any(|w| w.contains("brightest texel")),
        "{:?}",
        s.warnings
    );
    let id = s.material_of("white").unwrap() as usize;
    let Material::Glossy { specular, .. } = s.materials[id] else {
        panic!("not glossy")
    };
    // Red: 0.5 x 2 + 0.4 = 1.4 → Ks 0.4 / 1.4 and albedo 1 / 1.4; green and blue untouched.
    assert!(
        close(specular, Vec3::new(0.4 / 1.4, 0.4, 0.4), 1e-6),
        "{specular}"
    );
    let a = floor_albedo(&s, 0.5, 0.5);
    assert!(close(a, Vec3::new(1.0 / 1.4, 0.25, 0.25), 1e-6), "{a}");
    // Warned: a texture on a mirror, a mesh without `vt`.
    let mirror = GOOD_MTL.replace("Kd 0.5 0.5 0.5", "Ks 1 1 1\nillum 3\nmap_Kd t.png");
    let s = Scene::load(setup(&mirror, &obj, &scene_toml("a.obj")).path("s.toml")).unwrap();
    assert!(
        s.warnings
            .iter()
            .any(|w| w.contains("only diffuse and glossy")),
        "{:?}",
        s.warnings
    );
    let s = Scene::load(setup(&mtl, GOOD_OBJ, &scene_toml("a.obj")).path("s.toml")).unwrap();
    assert!(
        s.warnings
            .iter()
            .any(|w| w.contains("no texture coordinates")),
        "{:?}",
        s.warnings
    );
}

#[test]
fn missing_or_broken_textures_are_named() {
    let with = |line: &str, image: Option<&[u8]>| {
        let mtl = GOOD_MTL.replace("Kd 0.5 0.5 0.5", line);
        let dir = Scratch::new(
            "bad-texture",
            &[
                ("s.toml", &scene_toml("a.obj")),
                ("a.obj", GOOD_OBJ),
                ("m.mtl", &mtl),
            ],
        );
        if let Some(b) = image {
            std::fs::write(dir.path("t.png"), b).unwrap();
        }
        match Scene::load(dir.path("s.toml")) {
            Ok(_) => panic!("{line}: loaded"),
            Err(e) => {
                assert!(e.file.ends_with("m.mtl"), "{e}");
                e.to_string()
            }
        }
    };
    let e = with("map_Kd gone.png", None);
    assert!(
        e.contains("material `white`")
            && e.contains("map_Kd gone.png")
            && e.contains("gone.png: cannot read it"),
        "{e}"
    );
    let e = with("map_Kd t.png", Some(b"not an image at all"));
    assert!(
        e.contains("t.png") && e.contains("not a PNG, JPEG, TGA, EXR or Radiance HDR"),
        "{e}"
    );
    let e = with("map_Kd -s 2 2 1 t.png", None);
    assert!(e.contains("texture options"), "{e}");
    let e = with(
        "Kd 0.5 0.5 0.5\nmap_Ks t.png\nKs 0.5 0.5 0.5\nillum 2",
        None,
    );
    assert!(e.contains("only `map_Kd`"), "{e}");
    // The scene file's key names the scene file.
    let toml = format!(
        "{}[material.white]\ntype = \"lambertian\"\nalbedo = [0.5, 0.5, 0.5]\ntexture = \"gone.png\"\n",
        scene_toml("a.obj")
    );
    let dir = Scratch::new(
        "bad-texture-toml",
        &[("s.toml", &toml), ("a.obj", GOOD_OBJ), ("m.mtl", GOOD_MTL)],
    );
    let e = Scene::load(dir.path("s.toml")).err().unwrap();
    assert!(
        e.file.ends_with("s.toml") && e.problem.contains("texture `gone.png`"),
        "{e}"
    );
}

/// The scene file's coloured and absorbing glass: keys, defaults, the hash of clear glass
/// unchanged by writing the defaults out, and Beer-Lambert read at the surface a segment
/// ends on, from the inside only.
#[test]
fn glass_transmittance_and_absorption_keys() {
    let path = scenes_dir().join("cornell-spheres/analytic.toml");
    let text = std::fs::read_to_string(&path).unwrap();
    let a = Scene::from_toml(&path, &text).unwrap();
    let glass = a.material_of("glass").unwrap();
    assert_eq!(a.materials[glass as usize], Material::glass(1.5));
    assert_eq!(a.absorption[glass as usize], Vec3::ZERO);
    let defaults = text.replace(
        "ior = 1.5",
        "ior = 1.5\ntransmittance = [1, 1, 1]\nabsorption = [0, 0, 0]",
    );
    let b = Scene::from_toml(&path, &defaults).unwrap();
    assert_eq!(
        (a.photon_hash, a.image_hash, a.view_hash),
        (b.photon_hash, b.image_hash, b.view_hash),
        "clear glass written out in full hashes as before"
    );
    let coloured = text.replace(
        "ior = 1.5",
        "ior = 1.5\ntransmittance = [0.9, 0.6, 0.3]\nabsorption = [0.5, 0.25, 0]",
    );
    let c = Scene::from_toml(&path, &coloured).unwrap();
    assert_eq!(
        c.materials[glass as usize],
        Material::Dielectric {
            ior: 1.5,
            transmittance: Vec3::new(0.9, 0.6, 0.3),
            absorption: Vec3::new(0.5, 0.25, 0.0),
        }
    );
    assert_ne!(a.photon_hash, c.photon_hash);
    let Some(bsdf::Bsdf::Dielectric(d)) = c.bsdf(glass) else {
        panic!("not a dielectric")
    };
    assert_eq!(d.transmittance, Vec3::new(0.9, 0.6, 0.3));

    // The glass sphere (centre (-3.272, 2.29, -6.2395), radius 2.25): a chord through its
    // centre from inside is attenuated by exp(-σ 2r); the same segment arriving from outside,
    // or ending on the (non-absorbing) wall, is not.
    let centre = Vec3::new(-3.272, 2.29, -6.2395);
    let from_inside = geom::Ray::new(centre - Vec3::new(0.0, 0.0, 2.2), Vec3::new(0.0, 0.0, 2.0));
    let hit = c.geometry.intersect(&from_inside).unwrap();
    assert_eq!(hit.material, glass);
    let t = hit.t * 2.0;
    assert!((t - 4.45).abs() < 1e-4, "{t}");
    let want = (-Vec3::new(0.5, 0.25, 0.0) * t).exp();
    let got = c.transmittance_to(&hit, &from_inside);
    assert!((got - want).abs().max_element() < 1e-6, "{got} vs {want}");
    let from_outside = geom::Ray::new(centre + Vec3::new(0.0, 0.0, 4.0), Vec3::NEG_Z);
    let hit = c.geometry.intersect(&from_outside).unwrap();
    assert_eq!(hit.material, glass);
    assert_eq!(c.transmittance_to(&hit, &from_outside), Vec3::ONE);
    // Rough glass takes the same keys.
    let rough = text.replace(
        "type = \"dielectric\"\nior = 1.5",
        "type = \"rough_dielectric\"\nior = 1.5\nalpha = 0.1\nabsorption = [1, 2, 3]",
    );
    let r = Scene::from_toml(&path, &rough).unwrap();
    assert_eq!(r.absorption[glass as usize], Vec3::new(1.0, 2.0, 3.0));
}

#[test]
fn glass_keys_out_of_range_name_the_file_and_material() {
    for (key, problem) in [
        ("absorption = [-0.5, 0, 0]", "absorption"),
        ("absorption = [nan, 0, 0]", "absorption"),
        ("absorption = [inf, 0, 0]", "absorption"),
        ("transmittance = [1.5, 1, 1]", "transmittance"),
        ("transmittance = [-0.1, 1, 1]", "transmittance"),
    ] {
        let toml = format!(
            "{}[material.tinted]\ntype = \"dielectric\"\nior = 1.5\n{key}\n",
            scene_toml("a.obj")
        );
        error_of(
            "glass-keys",
            &[("s.toml", &toml), ("a.obj", GOOD_OBJ), ("m.mtl", GOOD_MTL)],
            "s.toml",
            "material `tinted`",
        );
        let dir = Scratch::new(
            "glass-keys-2",
            &[("s.toml", &toml), ("a.obj", GOOD_OBJ), ("m.mtl", GOOD_MTL)],
        );
        let e = Scene::load(dir.path("s.toml")).err().unwrap().to_string();
        assert!(e.contains(problem) && !e.contains('\n'), "{key}: {e}");
    }
}

// The environment light's tests live in tests/envmap.rs.
mod envmap;

/// The good scene with its lamp dark and `lights` (TOML `[[light]]` tables) added.
fn delta_scene(name: &str, lights: &str) -> (Scratch, Scene) {
    let mtl = GOOD_MTL.replace("Ke 4 4 4", "Ke 0 0 0");
    let toml = scene_toml("a.obj") + lights;
    let dir = Scratch::new(
        name,
        &[("s.toml", &toml), ("a.obj", GOOD_OBJ), ("m.mtl", &mtl)],
    );
    let s = Scene::load(dir.path("s.toml")).unwrap_or_else(|e| panic!("{e}"));
    (dir, s)
}

/// Summed flux of `n x n` stratified photons (centres of a grid over `u_dir`), f64.
fn emitted_power(s: &Scene, n: u32) -> glam::DVec3 {
    let total = (n * n) as u64;
    let mut sum = glam::DVec3::ZERO;
    for i in 0..n {
        for j in 0..n {
            let u = [(i as f32 + 0.5) / n as f32, (j as f32 + 0.5) / n as f32];
            let e = s.light_table.emit(0.5, [0.5, 0.5], u, total);
            assert!(e.ray.d.is_normalized(), "{:?}", e.ray.d);
            sum += e.flux;
        }
    }
    sum
}

/// A point light's power is `4π I`; its photons, summed, carry exactly that (each carries
/// `Φ / N`). Broken to `2π I` (a hemisphere) the sum misses by 50%.
#[test]
fn point_light_power_and_photons() {
    let (_d, s) = delta_scene(
        "point",
        "[[light]]\ntype = \"point\"\nposition = [0, 0.5, 0]\nintensity = [1, 2, 3]\n",
    );
    assert!(s.lights.is_empty());
    assert_eq!(s.light_table.len(), 1);
    let want = 4.0 * std::f64::consts::PI * glam::DVec3::new(1.0, 2.0, 3.0);
    let got = s.light_table.total_power();
    assert!(((got - want) / want).abs().max_element() < 1e-6, "{got}");
    let sum = emitted_power(&s, 100);
    let rel = ((sum - want) / want).abs().max_element();
    eprintln!("point light: photon power {sum} against 4 pi I = {want}: {rel:.2e}");
    assert!(rel < 1e-3, "{rel}");
    // NEE: `I / r²` towards a point 2 below it, chosen with probability 1.
    let ls = s
        .light_table
        .sample(Vec3::new(0.0, -1.5, 0.0), 0.3, [0.2, 0.7])
        .unwrap();
    assert!(ls.delta && ls.pdf == 1.0 && ls.dist == 2.0);
    assert!(close(ls.le, Vec3::new(0.25, 0.5, 0.75), 1e-6), "{}", ls.le);
}

/// A spot's power `2π I ∫ falloff sin θ dθ` in closed form against a midpoint quadrature of
/// Mitsuba's falloff, and its photons' summed flux against it (stratified in `cos θ`, so the
/// falloff's kinks cost a little). Measured: closed form against quadrature 3.2e-9
/// relative, photons 1.3e-6 (a point light's photons: 1.3e-13).
#[test]
fn spot_light_power_and_photons() {
    let (_d, s) = delta_scene(
        "spot",
        "[[light]]\ntype = \"spot\"\nposition = [0, 0.5, 0]\nlook_at = [0.3, 0, 0]\n\
         intensity = [1, 2, 3]\ncutoff_angle = 40\nbeam_width = 15\n",
    );
    let Some(Light::Spot(spot)) = s.light_table.light(0).cloned() else {
        panic!("not a spot light")
    };
    // Midpoint rule over θ in f64, with Mitsuba's falloff written out.
    let (c, b) = (40f64.to_radians(), 15f64.to_radians());
    let n = 200_000;
    let quad: f64 = (0..n)
        .map(|k| {
            let t = (k as f64 + 0.5) / n as f64 * c;
            let f = if t <= b { 1.0 } else { (c - t) / (c - b) };
            f * t.sin() * c / n as f64
        })
        .sum();
    let closed = spot.solid_angle_fraction();
    eprintln!("spot: closed form {closed}, quadrature {quad}");
    assert!((closed - quad).abs() / quad < 1e-6);
    let want = std::f64::consts::TAU * quad * glam::DVec3::new(1.0, 2.0, 3.0);
    let got = s.light_table.total_power();
    assert!(
        ((got - want) / want).abs().max_element() < 1e-6,
        "{got} {want}"
    );
    let sum = emitted_power(&s, 300);
    let rel = ((sum - want) / want).abs().max_element();
    eprintln!("spot: photon power {sum} against {want}: {rel:.2e}");
    assert!(rel < 1e-3, "{rel}");
    // Every photon leaves inside the cutoff cone.
    let axis = spot.frame.n;
    for i in 0..64 {
        let e = s
            .light_table
            .emit(0.5, [0.5; 2], [i as f32 / 64.0, 0.3], 64);
        assert!(e.ray.d.dot(axis) >= c.cos() as f32 - 1e-6);
    }
    // The falloff: 1 inside the beam, half way down the ramp at its middle, 0 past the cutoff.
    assert_eq!(spot.falloff(10f32.to_radians().cos()), 1.0);
    assert!((spot.falloff(27.5f32.to_radians().cos()) - 0.5).abs() < 1e-4);
    assert_eq!(spot.falloff(41f32.to_radians().cos()), 0.0);
}

#[test]
fn bad_delta_lights_are_named() {
    let cases = [
        (
            "type = \"point\"\nposition = [0, 1, 0]\nintensity = [1, nan, 1]",
            "light 0 (point): intensity must be finite and >= 0",
        ),
        (
            "type = \"spot\"\nposition = [0, 1, 0]\nlook_at = [0, 0, 0]\nintensity = [1, 1, 1]\ncutoff_angle = 95",
            "light 0 (spot): cutoff_angle = 95 must be in (0, 90] degrees",
        ),
        (
            "type = \"spot\"\nposition = [0, 1, 0]\nlook_at = [0, 0, 0]\nintensity = [1, 1, 1]\nbeam_width = 30",
            "light 0 (spot): beam_width = 30 must be in [0, cutoff_angle = 20] degrees",
        ),
    ];
    for (i, (light, problem)) in cases.iter().enumerate() {
        let toml = scene_toml("a.obj") + "[[light]]\n" + light + "\n";
        error_of(
            &format!("bad-delta-{i}"),
            &[("s.toml", &toml), ("a.obj", GOOD_OBJ), ("m.mtl", GOOD_MTL)],
            "s.toml",
            problem,
        );
    }
}

/// An EXR file to write beside a scene: name, width, height and texel function.
type ExrFile<'a> = (&'a str, u32, u32, &'a dyn Fn(u32, u32) -> [f32; 3]);

/// The good scene with its lamp dark, `lights` added and `exr` (name, width, height, texel
/// function) written beside it as a float EXR.
fn infinite_scene(name: &str, lights: &str, exr: Option<ExrFile>) -> (Scratch, Scene) {
    let mtl = GOOD_MTL.replace("Ke 4 4 4", "Ke 0 0 0");
    let toml = scene_toml("a.obj") + lights;
    let dir = Scratch::new(
        name,
        &[("s.toml", &toml), ("a.obj", GOOD_OBJ), ("m.mtl", &mtl)],
    );
    if let Some((file, w, h, f)) = exr {
        let img = image::DynamicImage::ImageRgb32F(image::Rgb32FImage::from_fn(w, h, |x, y| {
            image::Rgb(f(x, y))
        }));
        std::fs::write(dir.path(file), encoded(img, image::ImageFormat::OpenExr)).unwrap();
    }
    let s = Scene::load(dir.path("s.toml")).unwrap_or_else(|e| panic!("{e}"));
    (dir, s)
}

/// `∫ L dω` over the sphere of light `i` at infinity, by the midpoint rule in `(cos θ, φ)`
/// (uniform in solid angle), f64.
fn radiance_quadrature(s: &Scene, i: usize, n: usize) -> glam::DVec3 {
    let l = s.light_table.light(i).unwrap();
    let mut sum = glam::DVec3::ZERO;
    for a in 0..n {
        let z = 1.0 - 2.0 * (a as f64 + 0.5) / n as f64;
        let r = (1.0 - z * z).sqrt();
        for b in 0..2 * n {
            let phi = std::f64::consts::PI * (b as f64 + 0.5) / n as f64;
            let d = glam::DVec3::new(r * phi.cos(), z, r * phi.sin()).as_vec3();
            sum += l.le(d).as_dvec3();
        }
    }
    sum * (4.0 * std::f64::consts::PI / (2 * n * n) as f64)
}

/// Lights at infinity: the photons' summed flux equals `LightTable::power`, and that power
/// equals the closed form `π R² ∫ L dω` with `R` the half-diagonal of the scene's bounds (the
/// good scene spans [-1, 1] x [0, 1] x [-1, 1]: `R = 1.5`): `π R² E` for a directional light,
/// `π R² 2E/(1 + cos α)` for a sun disc, `π R² 4π L` for a constant environment (given as a
/// colour or as a constant image), and for a non-constant image the quadrature of its
/// radiance over the sphere. Point and spot lights: `point_light_power_and_photons` and
/// `spot_light_power_and_photons` above. Measured: powers against the closed forms 0 to
/// 3.4e-8 relative (the sun 5.7e-6: its `cos α` in f32); photon sums over a 1000 x 1000
/// grid of `u_dir` 4e-12 to 6e-9 (environments 4e-8), the non-constant image 2.8e-4 (1.0e-3
/// on a 300 x 300 grid: the grid's error at the patch edges, falling as 1/n), the
/// quadrature of the non-constant image 3.4e-8. Tried: the photons' disc area `R²` in
/// place of `π R²` (`emit_infinite`) fails the first case, the directional light's photon
/// sum, by 68%.
#[test]
fn infinite_light_power_and_photons() {
    use glam::DVec3;
    use std::f64::consts::PI;
    let e = DVec3::new(1.0, 2.0, 3.0);
    let l = DVec3::new(0.25, 0.5, 1.0);
    let alpha = 5f64.to_radians();
    let grad = |x: u32, y: u32| [1.0 + x as f32, 0.5 + 2.0 * y as f32, 3.0 + (x * y) as f32];
    let cases: [(&str, String, Option<ExrFile>, DVec3); 5] = [
        (
            "directional",
            "type = \"directional\"\ndirection = [1, -2, 0.5]\nirradiance = [1, 2, 3]\n".into(),
            None,
            e,
        ),
        (
            "sun",
            "type = \"directional\"\ndirection = [1, -2, 0.5]\nirradiance = [1, 2, 3]\n\
             angular_radius = 5\n"
                .into(),
            None,
            2.0 * e / (1.0 + alpha.cos()),
        ),
        (
            "constant environment",
            "type = \"environment\"\nradiance = [0.25, 0.5, 1]\n".into(),
            None,
            4.0 * PI * l,
        ),
        (
            "constant image environment",
            "type = \"environment\"\nfilename = \"env.exr\"\nscale = 0.5\nrotate = [10, 20, 30]\n"
                .into(),
            Some(("env.exr", 8, 5, &|_, _| [0.5, 1.0, 2.0])),
            4.0 * PI * l,
        ),
        (
            "image environment",
            "type = \"environment\"\nfilename = \"env.exr\"\nscale = 2\n".into(),
            Some(("env.exr", 6, 4, &grad)),
            DVec3::ZERO, // the quadrature below
        ),
    ];
    for (k, (what, light, exr, integral)) in cases.into_iter().enumerate() {
        let (_d, s) = infinite_scene(
            &format!("infinite-power-{k}"),
            &format!("[[light]]\n{light}"),
            exr,
        );
        assert!(s.lights.is_empty() && s.light_table.len() == 1, "{what}");
        let b = s.geometry.bounds();
        let half_diag = (0.5 * (b.max - b.min)).length();
        let r = s.light_table.scene_radius();
        assert!(
            (r - 1.5).abs() < 1e-6 && (r - half_diag).abs() < 1e-6,
            "{what}: R = {r}"
        );
        let integral = if integral == DVec3::ZERO {
            let q = radiance_quadrature(&s, 0, 1000);
            let int = s.light_table.light(0).unwrap().integral();
            let rel = ((q - int) / int).abs().max_element();
            eprintln!("{what}: ∫ L dω {int}, quadrature {q}: {rel:.1e}");
            assert!(rel < 1e-4, "{what}: {int} against quadrature {q}");
            q
        } else {
            integral
        };
        let want = PI * 1.5f64.powi(2) * integral;
        let got = s.light_table.power(0);
        let rel_power = ((got - want) / want).abs().max_element();
        let sum = emitted_power(&s, 1000);
        let rel_sum = ((sum - got) / got).abs().max_element();
        eprintln!(
            "{what}: power {got} against {want}: {rel_power:.1e}; photons {sum}: {rel_sum:.1e}"
        );
        assert!(rel_power < 1e-4, "{what}: power {got} against {want}");
        assert!(rel_sum < 1e-3, "{what}: photons {sum} against {got}");
        assert_eq!(s.light_table.total_power(), got, "{what}");
    }
}
