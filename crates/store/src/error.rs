use std::fmt;
use std::path::{Path, PathBuf};

/// Why a photon file could not be written, read or used. Its message always starts with the
/// file's path: the user's next step is to look at (or delete) that file.
#[derive(Debug)]
pub struct StoreError {
    pub path: PathBuf,
    pub problem: Problem,
}

/// What went wrong. Chunk numbers are zero-based here and shown one-based ("chunk 1 of 3").
#[derive(Debug)]
#[non_exhaustive]
pub enum Problem {
    Io {
        op: &'static str,
        error: std::io::Error,
    },
    NotPhotonFile,
    /// A directory, FIFO, socket or device where a photon file should be (never opened: a
    /// FIFO would block).
    NotRegularFile(&'static str),
    /// A format version this build does not read (`reads`: the one it does).
    Version {
        found: u32,
        reads: u32,
    },
    /// A record layout this build does not read (`reads`: the one it does).
    Layout {
        found: String,
        size: u32,
        reads: &'static str,
    },
    /// The file ends before `end`; `chunk` is `(index, count)`, or `None` inside the header.
    Truncated {
        chunk: Option<(u32, u32)>,
        end: u64,
        len: u64,
    },
    TrailingBytes {
        expected: u64,
        len: u64,
    },
    HeaderChecksum,
    ChunkChecksum {
        chunk: u32,
        of: u32,
    },
    Corrupt(String),
    /// A valid file made for something else (see [`crate::check`]).
    Mismatch(String),
    /// A writer used after one of its writes failed.
    Poisoned,
}

impl StoreError {
    pub(crate) fn new(path: &Path, problem: Problem) -> StoreError {
        StoreError {
            path: path.to_path_buf(),
            problem,
        }
    }

    pub(crate) fn io(path: &Path, op: &'static str, error: std::io::Error) -> StoreError {
        StoreError::new(path, Problem::Io { op, error })
    }
}

impl fmt::Display for Problem {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Problem::Io { op, error } => write!(f, "cannot {op}: {error}"),
            Problem::NotPhotonFile => write!(f, "not a photon file (bad magic)"),
            Problem::NotRegularFile(what) => write!(f, "not a regular file (it is {what})"),
            Problem::Version { found, reads } => {
                write!(f, "format version {found}, this build reads {reads}")
            }
            Problem::Layout { found, size, reads } => write!(
                f,
                "record layout \"{found}\" ({size} bytes), this build reads \"{reads}\" (32 bytes)"
            ),
            Problem::Truncated {
                chunk: Some((i, n)),
                end,
                len,
            } => write!(
                f,
                "truncated: chunk {} of {n} ends at byte {end} but file has {len}",
                i + 1
            ),
            Problem::Truncated {
                chunk: None,
                end,
                len,
            } => write!(f, "truncated: header ends at byte {end} but file has {len}"),
            Problem::TrailingBytes { expected, len } => write!(
                f,
                "trailing bytes: the header accounts for {expected} bytes but file has {len}"
            ),
            Problem::HeaderChecksum => write!(f, "checksum mismatch in the header"),
            Problem::ChunkChecksum { chunk, of } => {
                write!(f, "checksum mismatch in chunk {} of {of}", chunk + 1)
            }
            Problem::Corrupt(what) => write!(f, "corrupt: {what}"),
            Problem::Mismatch(what) => write!(f, "{what}"),
            Problem::Poisoned => write!(f, "an earlier write to this file failed"),
        }
    }
}

impl fmt::Display for StoreError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}: {}", self.path.display(), self.problem)
    }
}

impl std::error::Error for StoreError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match &self.problem {
            Problem::Io { error, .. } => Some(error),
            _ => None,
        }
    }
}
