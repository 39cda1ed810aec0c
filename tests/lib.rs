//! Shared helpers of the end-to-end tests (`it/`).

use std::path::{Path, PathBuf};

/// The repository's `scenes/` directory.
pub fn scenes_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes")
}

/// Load a scene from `scenes/`, panicking with the loader's message (a test failure).
pub fn load(rel: &str) -> scene::Scene {
    scene::Scene::load(scenes_dir().join(rel)).unwrap_or_else(|e| panic!("{e}"))
}
