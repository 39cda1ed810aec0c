//! The bytes of a photon file, encoded and decoded over slices (no IO here).
//!
//! ```text
//! offset        size  field                         (integers little-endian)
//! 0             8     magic "\x89PHOTON\n"           zero until `finish`: a temp file never reads as valid
//! 8             4     format version (FORMAT_VERSION)
//! 12            4     header length H (multiple of 32; first chunk starts here)
//! 16            4     record size (32)
//! 20            4     chunk capacity C (photons in every chunk but the last)
//! 24            8     stored photons S                 patched by `finish`
//! 32            8     emitted photon paths             patched by `finish`
//! 40            8     seed
//! 48            8     scene hash
//! 56            8     params hash
//! 64            4     chunk count N = ceil(S / C)      patched by `finish`
//! 68            1     map kind (1 global, 2 caustic)
//! 69            1     zero
//! 70            2     record layout length L
//! 72            4     params length P
//! 76            L     record layout (UTF-8), e.g. "pos:f32x3,power:f32x3,dir:oct16x2,surface:u32,le"
//! 76+L          P     emission parameters (UTF-8, serde_json; opaque to store)
//! ...                 zero padding
//! H-4           4     CRC-32 of bytes [0, H-4)
//! then N chunks, chunk i at H + i * (32 + 32 C):
//!   0           8     tag "PFCHUNK\0"
//!   8           4     chunk index i
//!   12          4     photon count (C, or S - (N-1) C for the last)
//!   16          8     index of the chunk's first photon (i C)
//!   24          4     zero
//!   28          4     CRC-32 of chunk bytes [0, 28) followed by the payload
//!   32          32 n  payload: n records, exactly `Photon`'s in-memory bytes
//! the file ends with the last payload: its length is H + 32 N + 32 S, known from the header.
//! ```
//!
//! Every offset of a record is a multiple of 32 (H, chunk headers and records are), so a record
//! never straddles a cache line and a page-aligned memory map casts to `&[Photon]` in place.

// A decoder of untrusted bytes: no input may reach a panic, so the lints that find the ways
// to one (unwrap, expect, indexing, explicit panics) are errors here; `cargo clippy` is the
// check.
#![cfg_attr(
    not(test),
    deny(
        clippy::unwrap_used,
        clippy::expect_used,
        clippy::indexing_slicing,
        clippy::panic,
        clippy::unreachable
    )
)]

use crate::error::Problem;
use crate::{MapKind, Photon};

pub const MAGIC: [u8; 8] = *b"\x89PHOTON\n";

/// Bumped whenever any byte above changes meaning; readers accept exactly this version.
pub const FORMAT_VERSION: u32 = 1;

/// The record's fields and their byte order. Records are cast, not decoded, so a file written
/// on a machine with the other byte order must be refused, not misread.
#[cfg(target_endian = "little")]
pub const RECORD_LAYOUT: &str = "pos:f32x3,power:f32x3,dir:oct16x2,surface:u32,le";
#[cfg(target_endian = "big")]
pub const RECORD_LAYOUT: &str = "pos:f32x3,power:f32x3,dir:oct16x2,surface:u32,be";

pub const RECORD_SIZE: u32 = std::mem::size_of::<Photon>() as u32;

/// 64 Ki photons = 2 MiB payload: large enough that the 32-byte chunk header is 0.0015% of the
/// file and a chunk is one big `read`, small enough that the streaming reader's buffer is small.
pub const DEFAULT_CHUNK_PHOTONS: u32 = 1 << 16;

/// Readers refuse larger chunks, so a corrupt header cannot ask for a huge buffer.
pub const MAX_CHUNK_PHOTONS: u32 = 1 << 22;

/// Headers above this are refused for the same reason (the parameters are a few kB).
pub const MAX_HEADER_LEN: u32 = 1 << 24;

/// Enough to read the magic, the version and the header length.
pub const PREFIX_LEN: usize = 16;
const FIXED_LEN: usize = 76;
pub const CHUNK_HEADER_LEN: usize = 32;
const CHUNK_TAG: [u8; 8] = *b"PFCHUNK\0";

/// What a photon file says about its photons. `emitted` (photon paths traced, including those
/// that stored nothing) is what estimators divide by; `stored` is the number of records.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Header {
    pub kind: MapKind,
    pub seed: u64,
    /// Hash of the scene content the photons were traced in (computed by the caller).
    pub scene_hash: u64,
    /// Hash of the emission parameters (computed by the caller).
    pub params_hash: u64,
    /// The emission parameters themselves, serde_json; store never parses them.
    pub params: String,
    pub emitted: u64,
    pub stored: u64,
}

impl Header {
    /// A header for [`crate::StoreWriter::create`]: the counts start at zero and are set by
    /// `finish`.
    pub fn new(
        kind: MapKind,
        seed: u64,
        scene_hash: u64,
        params_hash: u64,
        params: String,
    ) -> Header {
        Header {
            kind,
            seed,
            scene_hash,
            params_hash,
            params,
            emitted: 0,
            stored: 0,
        }
    }
}

/// Where the chunks are, derived from the header.
#[derive(Clone, Copy, Debug)]
pub struct Chunks {
    pub header_len: u64,
    pub capacity: u32,
    pub count: u32,
    pub stored: u64,
}

impl Chunks {
    pub fn photons_in(&self, i: u32) -> u32 {
        if i + 1 < self.count {
            self.capacity
        } else {
            (self.stored - u64::from(self.count - 1) * u64::from(self.capacity)) as u32
        }
    }

    /// Byte offset of chunk `i`'s header.
    pub fn offset(&self, i: u32) -> u64 {
        self.header_len + u64::from(i) * (CHUNK_HEADER_LEN as u64 + u64::from(self.capacity) * 32)
    }

    pub fn end(&self, i: u32) -> u64 {
        self.offset(i) + CHUNK_HEADER_LEN as u64 + u64::from(self.photons_in(i)) * 32
    }

    pub fn file_len(&self) -> u64 {
        self.header_len + u64::from(self.count) * CHUNK_HEADER_LEN as u64 + self.stored * 32
    }

    /// Refuses a file shorter or longer than its header says, naming the first chunk cut off.
    pub fn check_len(&self, len: u64) -> Result<(), Problem> {
        let expected = self.file_len();
        if len > expected {
            return Err(Problem::TrailingBytes { expected, len });
        }
        if len < expected {
            let i = (0..self.count).find(|&i| self.end(i) > len).unwrap_or(0);
            return Err(Problem::Truncated {
                chunk: Some((i, self.count)),
                end: self.end(i),
                len,
            });
        }
        Ok(())
    }
}

pub fn header_len(params: &str) -> usize {
    (FIXED_LEN + RECORD_LAYOUT.len() + params.len() + 4).next_multiple_of(32)
}

/// The complete header block (length `header_len(&h.params)`), ending in its checksum.
pub fn encode_header(h: &Header, capacity: u32, chunk_count: u32) -> Vec<u8> {
    let len = header_len(&h.params);
    let mut b = Vec::with_capacity(len);
    b.extend_from_slice(&MAGIC);
    b.extend_from_slice(&FORMAT_VERSION.to_le_bytes());
    b.extend_from_slice(&(len as u32).to_le_bytes());
    b.extend_from_slice(&RECORD_SIZE.to_le_bytes());
    b.extend_from_slice(&capacity.to_le_bytes());
    b.extend_from_slice(&h.stored.to_le_bytes());
    b.extend_from_slice(&h.emitted.to_le_bytes());
    b.extend_from_slice(&h.seed.to_le_bytes());
    b.extend_from_slice(&h.scene_hash.to_le_bytes());
    b.extend_from_slice(&h.params_hash.to_le_bytes());
    b.extend_from_slice(&chunk_count.to_le_bytes());
    b.push(h.kind as u8);
    b.push(0);
    b.extend_from_slice(&(RECORD_LAYOUT.len() as u16).to_le_bytes());
    b.extend_from_slice(&(h.params.len() as u32).to_le_bytes());
    debug_assert_eq!(b.len(), FIXED_LEN);
    b.extend_from_slice(RECORD_LAYOUT.as_bytes());
    b.extend_from_slice(h.params.as_bytes());
    b.resize(len - 4, 0);
    let crc = crc32fast::hash(&b);
    b.extend_from_slice(&crc.to_le_bytes());
    b
}

/// The `N` bytes of `b` from `at`. Callers check a block's length before reading its fields,
/// so a field past the end is a decoder bug; it is still an error, never a panic.
fn field<const N: usize>(b: &[u8], at: usize) -> Result<[u8; N], Problem> {
    b.get(at..)
        .and_then(|rest| rest.first_chunk::<N>())
        .copied()
        .ok_or_else(|| {
            Problem::Corrupt(format!(
                "a {N}-byte field at byte {at} runs past the {}-byte block",
                b.len()
            ))
        })
}

fn u32_at(b: &[u8], at: usize) -> Result<u32, Problem> {
    field(b, at).map(u32::from_le_bytes)
}

fn u64_at(b: &[u8], at: usize) -> Result<u64, Problem> {
    field(b, at).map(u64::from_le_bytes)
}

/// Checks magic and version (in that order, before anything whose meaning the version could
/// change) and returns the header length. `b` is the file's first bytes, `len` its length.
pub fn decode_prefix(b: &[u8], len: u64) -> Result<u64, Problem> {
    if b.first_chunk::<8>() != Some(&MAGIC) {
        return Err(Problem::NotPhotonFile);
    }
    if b.len() < PREFIX_LEN {
        return Err(Problem::Truncated {
            chunk: None,
            end: PREFIX_LEN as u64,
            len,
        });
    }
    let version = u32_at(b, 8)?;
    if version != FORMAT_VERSION {
        return Err(Problem::Version {
            found: version,
            reads: FORMAT_VERSION,
        });
    }
    let header_len = u32_at(b, 12)?;
    let least = (FIXED_LEN + 4).next_multiple_of(32) as u32;
    if header_len < least || !header_len.is_multiple_of(32) || header_len > MAX_HEADER_LEN {
        return Err(Problem::Corrupt(format!(
            "impossible header length {header_len}"
        )));
    }
    if u64::from(header_len) > len {
        return Err(Problem::Truncated {
            chunk: None,
            end: header_len.into(),
            len,
        });
    }
    Ok(header_len.into())
}

/// Decodes the whole header block `b` (as long as `decode_prefix` said), checksum first.
pub fn decode_header(b: &[u8]) -> Result<(Header, Chunks), Problem> {
    let n = b.len();
    // `decode_prefix` admits no header this short; a caller that skipped it gets an error.
    let (body, crc) = match b.split_last_chunk::<4>() {
        Some((body, crc)) if n >= FIXED_LEN + 4 => (body, u32::from_le_bytes(*crc)),
        _ => {
            return Err(Problem::Corrupt(format!(
                "a header of {n} bytes is shorter than its fixed fields"
            )));
        }
    };
    if crc32fast::hash(body) != crc {
        return Err(Problem::HeaderChecksum);
    }
    // Past the checksum, a bad field means a writer bug or a forged file, not bit rot.
    let corrupt = |what: &str| Problem::Corrupt(what.to_string());
    let layout_len = u16::from_le_bytes(field(b, 70)?) as usize;
    let params_len = u32_at(b, 72)? as usize;
    let strings_end = FIXED_LEN + layout_len + params_len;
    // The strings end within `body` (before the checksum), then zero padding.
    let (Some(layout), Some(params), Some(padding)) = (
        body.get(FIXED_LEN..FIXED_LEN + layout_len),
        body.get(FIXED_LEN + layout_len..strings_end),
        body.get(strings_end..),
    ) else {
        return Err(corrupt("header strings overrun the header"));
    };
    let record_size = u32_at(b, 16)?;
    if layout != RECORD_LAYOUT.as_bytes() || record_size != RECORD_SIZE {
        return Err(Problem::Layout {
            found: String::from_utf8_lossy(layout).into_owned(),
            size: record_size,
            reads: RECORD_LAYOUT,
        });
    }
    let params = String::from_utf8(params.to_vec())
        .map_err(|_| corrupt("emission parameters are not UTF-8"))?;
    let [kind, reserved] = field(b, 68)?;
    let kind = match kind {
        1 => MapKind::Global,
        2 => MapKind::Caustic,
        k => return Err(Problem::Corrupt(format!("unknown map kind {k}"))),
    };
    if reserved != 0 || padding.iter().any(|&x| x != 0) {
        return Err(corrupt("non-zero reserved header bytes"));
    }
    let capacity = u32_at(b, 20)?;
    if capacity == 0 || capacity > MAX_CHUNK_PHOTONS {
        return Err(Problem::Corrupt(format!(
            "impossible chunk capacity {capacity}"
        )));
    }
    let stored = u64_at(b, 24)?;
    let count = u32_at(b, 64)?;
    if stored.div_ceil(capacity.into()) != count.into() {
        return Err(Problem::Corrupt(format!(
            "{stored} photons cannot fill {count} chunks of {capacity}"
        )));
    }
    let header = Header {
        kind,
        seed: u64_at(b, 40)?,
        scene_hash: u64_at(b, 48)?,
        params_hash: u64_at(b, 56)?,
        params,
        emitted: u64_at(b, 32)?,
        stored,
    };
    let chunks = Chunks {
        header_len: n as u64,
        capacity,
        count,
        stored,
    };
    Ok((header, chunks))
}

/// Fills the chunk header `head` for a chunk whose payload is `payload`.
pub fn encode_chunk_header(
    head: &mut [u8; CHUNK_HEADER_LEN],
    index: u32,
    first: u64,
    payload: &[u8],
) {
    head[0..8].copy_from_slice(&CHUNK_TAG);
    head[8..12].copy_from_slice(&index.to_le_bytes());
    head[12..16].copy_from_slice(&((payload.len() / 32) as u32).to_le_bytes());
    head[16..24].copy_from_slice(&first.to_le_bytes());
    head[24..28].fill(0);
    let mut crc = crc32fast::Hasher::new();
    crc.update(&head[..28]);
    crc.update(payload);
    head[28..32].copy_from_slice(&crc.finalize().to_le_bytes());
}

/// Verifies chunk `i` of `chunks` given its header bytes and its payload (whose length the file
/// header fixes, so a corrupt count cannot make us read the wrong bytes).
pub fn check_chunk(
    head: &[u8; CHUNK_HEADER_LEN],
    payload: &[u8],
    i: u32,
    chunks: &Chunks,
) -> Result<(), Problem> {
    let mut crc = crc32fast::Hasher::new();
    crc.update(&head[..28]);
    crc.update(payload);
    if crc.finalize() != u32_at(head, 28)? {
        return Err(Problem::ChunkChecksum {
            chunk: i,
            of: chunks.count,
        });
    }
    let first = u64::from(i) * u64::from(chunks.capacity);
    let consistent = head[0..8] == CHUNK_TAG
        && u32_at(head, 8)? == i
        && u32_at(head, 12)? == chunks.photons_in(i)
        && u64_at(head, 16)? == first
        && u32_at(head, 24)? == 0;
    if !consistent {
        return Err(Problem::Corrupt(format!(
            "chunk {} of {} has a header that disagrees with the file header",
            i + 1,
            chunks.count
        )));
    }
    Ok(())
}
