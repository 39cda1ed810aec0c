//! The one error type of the crate: every failure names the file or the sizes involved.

use std::fmt;
use std::path::PathBuf;

/// Everything that can go wrong in `film`. IO variants carry the path they were working on.
#[derive(Debug)]
pub enum FilmError {
    /// A file system operation failed; `what` says which step (e.g. "create temporary file").
    Io {
        path: PathBuf,
        what: &'static str,
        source: std::io::Error,
    },
    /// The EXR codec rejected the file (reading) or the image (writing).
    Exr {
        path: PathBuf,
        source: exr::error::Error,
    },
    /// The PNG encoder failed.
    Png {
        path: PathBuf,
        source: image::ImageError,
    },
    /// Two images (or an image and a mask) that must have equal sizes do not.
    SizeMismatch {
        what: &'static str,
        a: (usize, usize),
        b: (usize, usize),
    },
    /// An `Image` or `Mask` whose `data.len()` is not `width * height`.
    BadBuffer {
        what: &'static str,
        width: usize,
        height: usize,
        len: usize,
    },
    /// A metric over zero pixels (empty image or all-false mask) has no value.
    EmptyRegion,
    /// Bias and variance apart need at least two independent runs.
    TooFewRuns { runs: usize },
    /// A reference's two halves that are one image: they estimate no noise.
    IdenticalHalves,
    /// A file of f64 sums ([`crate::read_sums`]) that is not one, or is damaged.
    Sums { path: PathBuf, problem: String },
}

impl fmt::Display for FilmError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Io { path, what, source } => {
                write!(f, "{}: cannot {what}: {source}", path.display())
            }
            Self::Exr { path, source } => write!(f, "{}: EXR error: {source}", path.display()),
            Self::Png { path, source } => write!(f, "{}: PNG error: {source}", path.display()),
            Self::SizeMismatch { what, a, b } => {
                write!(
                    f,
                    "{what}: size mismatch {}x{} vs {}x{}",
                    a.0, a.1, b.0, b.1
                )
            }
            Self::BadBuffer {
                what,
                width,
                height,
                len,
            } => write!(
                f,
                "{what}: buffer holds {len} pixels but {width}x{height} needs {}",
                width.saturating_mul(*height)
            ),
            Self::EmptyRegion => write!(f, "metrics over an empty region (no pixels selected)"),
            Self::TooFewRuns { runs } => write!(
                f,
                "bias and variance need at least two independent runs, got {runs}"
            ),
            Self::IdenticalHalves => write!(
                f,
                "the reference's two halves are identical pixel for pixel: there is no noise to \
                 take out (the second half is a render with another seed)"
            ),
            Self::Sums { path, problem } => write!(f, "{}: {problem}", path.display()),
        }
    }
}

impl std::error::Error for FilmError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            Self::Io { source, .. } => Some(source),
            Self::Exr { source, .. } => Some(source),
            Self::Png { source, .. } => Some(source),
            _ => None,
        }
    }
}
