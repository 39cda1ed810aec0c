//! `store`: the photon record and the photon file. **API boundary**: the record layout and the
//! file format are versioned; nothing else in photonflow knows their bytes.
//!
//! Key decision: **the payload is plain 32-byte records, cast, never decoded.** A chunk's bytes
//! are exactly `[Photon]` in memory (`#[repr(C)]`, `Pod`), so reading is a memory map plus a
//! `bytemuck` cast, and the only per-byte work is the checksum. Measured on this machine
//! (`bench::bench_encodings`, release, 10M photons = 320 MB, 2 shared cores, ranges over runs):
//!
//! | encoding                      | bytes/photon | encode GB/s | decode GB/s |
//! |-------------------------------|--------------|-------------|-------------|
//! | plain records (copy / cast)   | 32           | 5.5 - 6.5   | 15 - 18     |
//! | bincode 2 + serde, varint     | 32.7         | 1.4 - 2.7   | 0.46 - 0.70 |
//! | bincode 2 + serde, fixed int  | 32           | 7.8 - 10    | 0.50 - 0.85 |
//!
//! Decoding is what every density run pays, and bincode decodes 20-35x slower than a cast,
//! field by field into a fresh `Vec`, for no gain in size (photons are floats: varints save
//! nothing). Through files (`bench::bench_store`, same photons): 32.0005 bytes per photon on
//! disk; the mapped read (map, verify every checksum, read every photon) runs at 5.5 - 8.5
//! GB/s on a quiet machine (3.8 - 5.5 under load), the streaming read at 4.6 - 7.1; writing
//! runs at 1.8 - 2.6 GB/s into the page cache and 1.1 - 1.6 GB/s with the final fsync, which
//! the disk bounds.
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
mod write;

pub use error::{Problem, StoreError};
pub use format::{DEFAULT_CHUNK_PHOTONS, FORMAT_VERSION, Header, RECORD_LAYOUT};
pub use read::{Expect, MappedStore, StoreReader, check};
pub use record::{MapKind, Photon, oct_decode, oct_encode};
pub use write::StoreWriter;

#[cfg(test)]
mod tests;
