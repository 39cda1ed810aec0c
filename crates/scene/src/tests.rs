//! Unit tests, one module per feature of the crate, and what they share: the tree's scene
//! files, a small good scene (`GOOD_OBJ`, `GOOD_MTL`) that the error tests break one way each,
//! and scratch directories to load such scenes from.

use crate::Scene;
use glam::Vec3;
use std::path::{Path, PathBuf};

/// README.md's MTL table against its one statement, in `src/load/mtl.rs`.
mod docs;
/// The environment light against Mitsuba 3's `envmap`, closed forms and the chi-square test.
mod envmap;
/// Point, spot and infinite lights: power and photons; missing or absurd lights refused.
mod lights;
/// The scene file's glass keys: transmittance and absorption.
mod materials;
/// The MTL table: what each key and `illum` code draws, warns about or refuses.
mod mtl;
/// OBJ loading and its errors.
mod obj;
/// The parallel OBJ reader against tobj, on tricky and mutated files, in chunks of any size.
mod objtext;
/// PLY loading and its errors.
mod ply;
/// Faces to triangles.
mod polygon;
/// The scene file: malformed values, and which of its parts each hash keys.
mod scene_file;
/// Whole scenes: the tree's against the course worksheet's numbers, and the good scene.
mod scenes;
/// Textures: decoding, filtering, `map_Kd` and its errors.
mod textures;
/// Mitsuba 3 XML scenes: transforms against Mitsuba's, the worksheet in XML, parameters.
mod xml;

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

/// An image file's bytes, encoded by the `image` crate.
fn encoded(img: image::DynamicImage, format: image::ImageFormat) -> Vec<u8> {
    let mut bytes = std::io::Cursor::new(Vec::new());
    img.write_to(&mut bytes, format).unwrap();
    bytes.into_inner()
}
