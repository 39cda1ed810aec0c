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

use bytemuck::Zeroable;
use std::fs::File;
use std::io::{ErrorKind, Read};
use std::ops::Range;
use std::path::{Path, PathBuf};

use crate::error::{Problem, StoreError};
use crate::format::{
    CHUNK_HEADER_LEN, Chunks, Header, PREFIX_LEN, check_chunk, decode_header, decode_prefix,
};
use crate::{MapKind, Photon};

/// Reads and validates a header from `file` (positioned at 0), leaving it at the first chunk.
fn read_header(path: &Path, file: &mut File) -> Result<(Header, Chunks), StoreError> {
    let len = file
        .metadata()
        .map_err(|e| StoreError::io(path, "stat", e))?
        .len();
    let mut prefix = vec![0u8; PREFIX_LEN.min(len as usize)];
    file.read_exact(&mut prefix)
        .map_err(|e| StoreError::io(path, "read", e))?;
    let header_len = decode_prefix(&prefix, len).map_err(|p| StoreError::new(path, p))?;
    let mut block = prefix;
    block.resize(header_len as usize, 0);
    // `decode_prefix` read PREFIX_LEN bytes and admits no shorter header.
    let Some(rest) = block.get_mut(PREFIX_LEN..) else {
        let end = PREFIX_LEN as u64;
        return Err(StoreError::new(
            path,
            Problem::Truncated {
                chunk: None,
                end,
                len,
            },
        ));
    };
    file.read_exact(rest)
        .map_err(|e| StoreError::io(path, "read", e))?;
    let (header, chunks) = decode_header(&block).map_err(|p| StoreError::new(path, p))?;
    chunks
        .check_len(len)
        .map_err(|p| StoreError::new(path, p))?;
    Ok((header, chunks))
}

/// Reads a photon file chunk by chunk, verifying each chunk's checksum as it goes.
///
/// `open` validates the header and the file's length (so truncation is refused before any
/// photon is read); each `next_chunk` verifies that chunk.
pub struct StoreReader {
    path: PathBuf,
    file: File,
    header: Header,
    chunks: Chunks,
    next: u32,
    head: [u8; CHUNK_HEADER_LEN],
}

/// Opens a photon file, refusing anything but a regular file first: opening a FIFO blocks
/// until a writer comes, and a device may never end.
fn open_regular(path: &Path) -> Result<File, StoreError> {
    let meta = std::fs::metadata(path).map_err(|e| StoreError::io(path, "open", e))?;
    if !meta.is_file() {
        let what = if meta.is_dir() {
            "a directory"
        } else {
            "a FIFO, socket or device"
        };
        return Err(StoreError::new(path, Problem::NotRegularFile(what)));
    }
    File::open(path).map_err(|e| StoreError::io(path, "open", e))
}

impl StoreReader {
    pub fn open(path: &Path) -> Result<StoreReader, StoreError> {
        let mut file = open_regular(path)?;
        let (header, chunks) = read_header(path, &mut file)?;
        Ok(StoreReader {
            path: path.to_path_buf(),
            file,
            header,
            chunks,
            next: 0,
            head: [0; CHUNK_HEADER_LEN],
        })
    }

    pub fn header(&self) -> &Header {
        &self.header
    }

    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Refuses the file if it was made for another scene, parameters or map (see [`check`]).
    pub fn check(&self, expect: &Expect) -> Result<(), StoreError> {
        check(&self.path, &self.header, expect)
    }

    /// Replaces `buf`'s contents with the next chunk's photons; `Ok(false)` after the last.
    pub fn next_chunk(&mut self, buf: &mut Vec<Photon>) -> Result<bool, StoreError> {
        let i = self.next;
        if i == self.chunks.count {
            return Ok(false);
        }
        let n = self.chunks.photons_in(i) as usize;
        buf.clear();
        buf.resize(n, Photon::zeroed());
        let truncated = |e: std::io::Error, path: &Path, chunks: &Chunks| {
            if e.kind() == ErrorKind::UnexpectedEof {
                // Only if the file shrank after `open` checked its length.
                let len = std::fs::metadata(path).map(|m| m.len()).unwrap_or(0);
                let problem = Problem::Truncated {
                    chunk: Some((i, chunks.count)),
                    end: chunks.end(i),
                    len,
                };
                StoreError::new(path, problem)
            } else {
                StoreError::io(path, "read", e)
            }
        };
        let payload: &mut [u8] = bytemuck::cast_slice_mut(buf.as_mut_slice());
        self.file
            .read_exact(&mut self.head)
            .and_then(|_| self.file.read_exact(payload))
            .map_err(|e| truncated(e, &self.path, &self.chunks))?;
        check_chunk(&self.head, payload, i, &self.chunks)
            .map_err(|p| StoreError::new(&self.path, p))?;
        self.next += 1;
        Ok(true)
    }

    /// All remaining photons, verified.
    pub fn read_all(mut self) -> Result<Vec<Photon>, StoreError> {
        let mut all = Vec::with_capacity(self.header.stored as usize);
        let mut buf = Vec::new();
        while self.next_chunk(&mut buf)? {
            all.extend_from_slice(&buf);
        }
        Ok(all)
    }
}

/// A photon file mapped into memory: chunks are `&[Photon]` straight from the page cache, no
/// copy and no decoding.
///
/// `open` verifies every chunk's checksum once, which reads the whole file: CRC-32 with
/// PCLMULQDQ runs several times faster than the mapped read as a whole (`docs/benchmarks.md`,
/// bench store), so this costs little, and the map is then trusted. The map is populated
/// (`MAP_POPULATE`) since that pass touches every page anyway.
pub struct MappedStore {
    path: PathBuf,
    map: memmap2::Mmap,
    header: Header,
    /// Byte ranges of the chunk payloads within `map`.
    payloads: Vec<Range<usize>>,
}

impl MappedStore {
    pub fn open(path: &Path) -> Result<MappedStore, StoreError> {
        let file = open_regular(path)?;
        let len = file
            .metadata()
            .map_err(|e| StoreError::io(path, "stat", e))?
            .len();
        if len == 0 {
            // Mapping zero bytes fails; an empty file is simply not ours.
            return Err(StoreError::new(path, Problem::NotPhotonFile));
        }
        // SAFETY: a mapped file must not change while mapped. Photon files are never modified
        // after the rename that publishes them (writers only ever write temp files), and they
        // live in photonflow's own cache directory, which nothing else writes.
        #[allow(unsafe_code)]
        let map = unsafe { memmap2::MmapOptions::new().populate().map(&file) }
            .map_err(|e| StoreError::io(path, "map", e))?;
        let err = |p| StoreError::new(path, p);
        let bytes: &[u8] = &map;
        let prefix = bytes.get(..PREFIX_LEN).unwrap_or(bytes);
        let header_len = decode_prefix(prefix, len).map_err(err)?;
        // `decode_prefix` checked the header against the file's length.
        let truncated = |chunk, end| err(Problem::Truncated { chunk, end, len });
        let block = bytes
            .get(..header_len as usize)
            .ok_or_else(|| truncated(None, header_len))?;
        let (header, chunks) = decode_header(block).map_err(err)?;
        chunks.check_len(len).map_err(err)?;
        let mut payloads = Vec::with_capacity(chunks.count as usize);
        for i in 0..chunks.count {
            let at = chunks.offset(i) as usize;
            let body = at + CHUNK_HEADER_LEN..chunks.end(i) as usize;
            // `check_len` checked every chunk against the file's length.
            let (Some(head), Some(payload)) = (
                bytes.get(at..body.start).and_then(|h| h.try_into().ok()),
                bytes.get(body.clone()),
            ) else {
                return Err(truncated(Some((i, chunks.count)), chunks.end(i)));
            };
            check_chunk(head, payload, i, &chunks).map_err(err)?;
            // Offsets are multiples of 32 and the map is page-aligned; checked once here so
            // `chunks` can cast without failing.
            bytemuck::try_cast_slice::<u8, Photon>(payload)
                .map_err(|e| err(Problem::Corrupt(format!("chunk {} misaligned: {e}", i + 1))))?;
            payloads.push(body);
        }
        Ok(MappedStore {
            path: path.to_path_buf(),
            map,
            header,
            payloads,
        })
    }

    pub fn header(&self) -> &Header {
        &self.header
    }

    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Refuses the file if it was made for another scene, parameters or map (see [`check`]).
    pub fn check(&self, expect: &Expect) -> Result<(), StoreError> {
        check(&self.path, &self.header, expect)
    }

    /// The photons, one verified chunk at a time, in file order.
    pub fn chunks(&self) -> impl Iterator<Item = &[Photon]> + '_ {
        // `open` checked every range against this map and its cast, so the fallback (an
        // empty chunk) is never taken: it stands where a panic would otherwise be.
        self.payloads.iter().map(|r| {
            self.map
                .get(r.clone())
                .and_then(|b| bytemuck::try_cast_slice(b).ok())
                .unwrap_or_default()
        })
    }

    pub fn to_vec(&self) -> Vec<Photon> {
        let mut all = Vec::with_capacity(self.header.stored as usize);
        for c in self.chunks() {
            all.extend_from_slice(c);
        }
        all
    }
}

/// What a caller needs a photon file to have been made for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Expect {
    pub scene_hash: u64,
    pub params_hash: u64,
    pub kind: MapKind,
}

/// Refuses a valid photon file made for another scene, other emission parameters or the other
/// map, saying which; `path` is the file the header came from, for the message.
pub fn check(path: &Path, header: &Header, expect: &Expect) -> Result<(), StoreError> {
    let mismatch = |what: String| Err(StoreError::new(path, Problem::Mismatch(what)));
    if header.scene_hash != expect.scene_hash {
        return mismatch(format!(
            "made for another scene (scene hash {:016x}, expected {:016x})",
            header.scene_hash, expect.scene_hash
        ));
    }
    if header.params_hash != expect.params_hash {
        return mismatch(format!(
            "made with other emission parameters (params hash {:016x}, expected {:016x})",
            header.params_hash, expect.params_hash
        ));
    }
    if header.kind != expect.kind {
        return mismatch(format!(
            "holds the {:?} photon map, expected the {:?} one",
            header.kind, expect.kind
        ));
    }
    Ok(())
}
