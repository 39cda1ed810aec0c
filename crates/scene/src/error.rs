use std::fmt;
use std::path::{Path, PathBuf};

/// A scene that cannot be loaded: which file, and what is wrong with it.
#[derive(Debug, Clone, PartialEq)]
pub struct SceneError {
    pub file: PathBuf,
    pub problem: String,
}

impl SceneError {
    pub fn new(file: impl AsRef<Path>, problem: impl Into<String>) -> SceneError {
        SceneError {
            file: file.as_ref().to_path_buf(),
            problem: problem.into(),
        }
    }
}

impl fmt::Display for SceneError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}: {}", self.file.display(), self.problem)
    }
}

impl std::error::Error for SceneError {}
