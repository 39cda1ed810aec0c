//! `store`: the photon record and the photon file. **API boundary**: the record layout and the
//! file format are versioned; nothing else in photonflow knows their bytes.
//!
//! Key decision: **the payload is plain 32-byte records, cast, never decoded.** A chunk's bytes
//! are exactly `[Photon]` in memory (`#[repr(C)]`, `Pod`), so reading is a memory map plus a
//! `bytemuck` cast, and the only per-byte work is the checksum. bincode was measured and
//! rejected for bulk photons: decoding is what every density run pays, and bincode decodes
//! field by field into a fresh `Vec`, over an order of magnitude slower than a cast, for no
//! gain in size (photons are floats: varints save nothing). The figures are in
//! `docs/benchmarks.md` (bench store).
//!
//! Checksums are CRC-32 (crc32fast), one per chunk and one for the header. CRC-32 detects
//! *every* error burst up to 32 bits, so any single changed byte is caught with certainty, not
//! with probability (a test flips every byte of a file); a non-cryptographic hash such as xxh3
//! is faster but promises nothing per pattern, and crc32fast is already in the build (png).
//! Files are published by rename, so `path` is complete or absent; see [`StoreWriter`].
//!
//! The byte map of the file is in `format.rs`.

pub mod bench;
mod error;
mod format;
mod read;
mod record;
mod space;
mod write;

pub use error::{Problem, StoreError};
pub use format::{DEFAULT_CHUNK_PHOTONS, FORMAT_VERSION, Header, RECORD_LAYOUT};
pub use read::{Expect, MappedStore, StoreReader, check};
pub use record::{MapKind, PerKind, Photon, oct_decode, oct_encode};
pub use space::free_space;
pub use write::StoreWriter;

#[cfg(test)]
mod tests;
