//! The hashes that key caches and name what an image means (see [`Scene`]'s fields): FNV-1a
//! of the files a scene names and of the parts of the scene file each depends on.

use crate::file::{
    CameraDesc, LightDesc, MaterialDesc, MeshDesc, RenderSettings, SceneFile, SphereDesc,
};

/// 64-bit FNV-1a: a stable, dependency-free content hash (not for security).
pub(super) struct Fnv(u64);

impl Fnv {
    pub(super) fn new() -> Fnv {
        Fnv(0xcbf2_9ce4_8422_2325)
    }
    pub(super) fn write(&mut self, bytes: &[u8]) {
        // Length prefix so ("ab", "c") and ("a", "bc") differ.
        for b in (bytes.len() as u64).to_le_bytes().iter().chain(bytes) {
            self.0 ^= *b as u64;
            self.0 = self.0.wrapping_mul(0x0100_0000_01b3);
        }
    }
    pub(super) fn finish(&self) -> u64 {
        self.0
    }
}

/// FNV-1a of a byte string (exposed for photon-cache keys built from parameters).
pub fn fnv1a64(bytes: &[u8]) -> u64 {
    let mut h = Fnv::new();
    h.write(bytes);
    h.finish()
}

/// The hashes of a scene whose named files hashed to `files`, parsed from `text` into `file`
/// (after any edit): `(photon, image, view, content)` as [`crate::Scene`] documents them.
pub(super) fn scene_hashes(file: &SceneFile, files: u64, text: &str) -> (u64, u64, u64, u64) {
    let inputs = |f: &SceneFile, camera: bool, seed: bool, render: bool| -> String {
        #[derive(serde::Serialize)]
        struct Inputs<'a> {
            files: u64,
            seed: u64,
            meshes: &'a [MeshDesc],
            spheres: &'a [SphereDesc],
            materials: &'a std::collections::BTreeMap<String, MaterialDesc>,
            #[serde(skip_serializing_if = "<[_]>::is_empty")]
            lights: &'a [LightDesc],
            camera: Option<&'a CameraDesc>,
            render: Option<&'a RenderSettings>,
        }
        // Files count by content (`files`), not by the path that names them, so a resolved
        // scene file with absolute paths keeps its caches.
        let mut f = f.clone();
        for name in f.file_names_mut() {
            name.clear();
        }
        toml::to_string(&Inputs {
            files,
            seed: if seed { f.seed } else { 0 },
            meshes: &f.meshes,
            spheres: &f.spheres,
            materials: &f.materials,
            lights: &f.lights,
            camera: camera.then_some(&f.camera),
            render: render.then_some(&f.render),
        })
        .unwrap_or_default()
    };
    let photon = fnv1a64(inputs(file, false, true, false).as_bytes());
    let image = fnv1a64(inputs(file, true, true, true).as_bytes());
    let view = fnv1a64(inputs(file, true, false, false).as_bytes());
    let mut all = Fnv::new();
    all.write(&files.to_le_bytes());
    all.write(text.as_bytes());
    // An edit after parsing (a flag) changes the content too.
    all.write(toml::to_string(file).unwrap_or_default().as_bytes());
    (photon, image, view, all.finish())
}
