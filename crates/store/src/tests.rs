//! Unit tests, one module per part of the crate.

/// The file: round trips, corruption, truncation, foreign files, versions, temp files.
mod file;
/// The record: octahedral directions, field layout.
mod record;
