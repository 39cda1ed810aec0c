//! Shared helpers of the end-to-end tests (`it/`).

pub mod alloc;
pub mod fuzz;

use std::path::{Path, PathBuf};

/// The repository's `scenes/` directory.
pub fn scenes_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes")
}

/// Load a scene from `scenes/`, panicking with the loader's message (a test failure).
pub fn load(rel: &str) -> scene::Scene {
    scene::Scene::load(scenes_dir().join(rel)).unwrap_or_else(|e| panic!("{e}"))
}

/// A scratch directory under the system's temporary directory, unique to this process and
/// `name`, removed when dropped.
pub struct TempDir(PathBuf);

impl TempDir {
    pub fn new(name: &str) -> TempDir {
        let d = std::env::temp_dir().join(format!("photonflow-it-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap_or_else(|e| panic!("{}: {e}", d.display()));
        TempDir(d)
    }

    pub fn path(&self) -> &Path {
        &self.0
    }
}

impl Drop for TempDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}
