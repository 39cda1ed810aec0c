use std::fs::File;
use std::io::{Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};
use temps::Temp;

use crate::Photon;
use crate::error::{Problem, StoreError};
use crate::format::{
    CHUNK_HEADER_LEN, DEFAULT_CHUNK_PHOTONS, Header, MAX_CHUNK_PHOTONS, encode_chunk_header,
    encode_header, header_len,
};

/// Streams photons into a photon file in constant memory (one chunk).
///
/// The file is written as a [`temps::Temp`] beside `path` with a zeroed magic;
/// [`StoreWriter::finish`] writes the real header, fsyncs and renames it to `path`. So `path`
/// either holds a complete, checksummed file or is untouched, whatever happens to this process;
/// the temp file is removed when an unfinished writer is dropped, by a signal handler, or by a
/// later run once this process is gone (see `temps`).
pub struct StoreWriter {
    path: PathBuf,
    /// Closed before `tmp` is removed (field order).
    file: Option<File>,
    /// `None` once published.
    tmp: Option<Temp>,
    header: Header,
    capacity: u32,
    /// Payload bytes of the chunk being filled.
    buf: Vec<u8>,
    chunks: u32,
    poisoned: bool,
}

impl StoreWriter {
    /// Starts a photon file for `header` (its counts are ignored: `finish` sets them).
    pub fn create(path: &Path, header: Header) -> Result<StoreWriter, StoreError> {
        StoreWriter::with_chunk_capacity(path, header, DEFAULT_CHUNK_PHOTONS)
    }

    /// As `create`, with `capacity` photons per chunk; tests use tiny chunks so that small
    /// files have many of them. Readers accept any capacity up to `MAX_CHUNK_PHOTONS`.
    pub(crate) fn with_chunk_capacity(
        path: &Path,
        mut header: Header,
        capacity: u32,
    ) -> Result<StoreWriter, StoreError> {
        assert!((1..=MAX_CHUNK_PHOTONS).contains(&capacity));
        if header.params.len() > (u32::MAX as usize) / 2 {
            return Err(StoreError::new(
                path,
                Problem::Corrupt("emission parameters too long".into()),
            ));
        }
        header.stored = 0;
        header.emitted = 0;
        let (tmp, mut file) = Temp::file(path).map_err(|e| StoreError::io(path, "create", e))?;
        let mut writer = StoreWriter {
            path: path.to_path_buf(),
            file: None,
            tmp: Some(tmp),
            header,
            capacity,
            buf: Vec::with_capacity(capacity as usize * 32),
            chunks: 0,
            poisoned: false,
        };
        // Zeros now, the header at `finish`: until then the file has no magic.
        let zeros = vec![0u8; header_len(&writer.header.params)];
        let written = file.write_all(&zeros);
        writer.file = Some(file);
        written.map_err(|e| writer.fail("write", e))?;
        Ok(writer)
    }

    /// What messages name: the file being written.
    fn tmp_path(&self) -> &Path {
        self.tmp.as_ref().map_or(&self.path, |t| t.path())
    }

    fn fail(&mut self, op: &'static str, e: std::io::Error) -> StoreError {
        self.poisoned = true;
        StoreError::io(self.tmp_path(), op, e)
    }

    /// Appends `photons`, writing each chunk as it fills.
    pub fn write(&mut self, mut photons: &[Photon]) -> Result<(), StoreError> {
        if self.poisoned {
            return Err(StoreError::new(self.tmp_path(), Problem::Poisoned));
        }
        while !photons.is_empty() {
            if self.buf.is_empty() && photons.len() >= self.capacity as usize {
                // A whole chunk in hand: write it from the caller's slice, skipping one copy.
                let (chunk, rest) = photons.split_at(self.capacity as usize);
                self.write_chunk(bytemuck::cast_slice(chunk))?;
                photons = rest;
                continue;
            }
            let in_buf = self.buf.len() / 32;
            let take = photons.len().min(self.capacity as usize - in_buf);
            self.buf
                .extend_from_slice(bytemuck::cast_slice(&photons[..take]));
            photons = &photons[take..];
            if in_buf + take == self.capacity as usize {
                self.flush_chunk()?;
            }
        }
        Ok(())
    }

    fn flush_chunk(&mut self) -> Result<(), StoreError> {
        let payload = std::mem::take(&mut self.buf);
        let done = self.write_chunk(&payload);
        self.buf = payload;
        self.buf.clear();
        done
    }

    /// Writes one chunk: its header, then `payload`, whole records.
    fn write_chunk(&mut self, payload: &[u8]) -> Result<(), StoreError> {
        if self.chunks == u32::MAX {
            self.poisoned = true;
            let too_many = Problem::Corrupt("too many chunks".into());
            return Err(StoreError::new(self.tmp_path(), too_many));
        }
        let mut head = [0u8; CHUNK_HEADER_LEN];
        encode_chunk_header(&mut head, self.chunks, self.header.stored, payload);
        let file = self.file.as_mut().expect("file is open until finish");
        if let Err(e) = file.write_all(&head).and_then(|_| file.write_all(payload)) {
            return Err(self.fail("write", e));
        }
        self.header.stored += (payload.len() / 32) as u64;
        self.chunks += 1;
        Ok(())
    }

    /// Photons written so far.
    pub fn stored(&self) -> u64 {
        self.header.stored + (self.buf.len() / 32) as u64
    }

    /// Completes the file: last chunk, header with the counts (`emitted` photon paths), fsync,
    /// then an atomic rename to `path` (replacing any file there).
    pub fn finish(mut self, emitted: u64) -> Result<(), StoreError> {
        if self.poisoned {
            return Err(StoreError::new(self.tmp_path(), Problem::Poisoned));
        }
        if !self.buf.is_empty() {
            self.flush_chunk()?;
        }
        self.header.emitted = emitted;
        let header = encode_header(&self.header, self.capacity, self.chunks);
        let mut file = self.file.take().expect("file is open until finish");
        let done = file
            .seek(SeekFrom::Start(0))
            .and_then(|_| file.write_all(&header))
            .map_err(|e| StoreError::io(self.tmp_path(), "write", e))
            // Data on disk before the name: after a crash the renamed file is complete.
            .and_then(|_| {
                file.sync_all()
                    .map_err(|e| StoreError::io(self.tmp_path(), "sync", e))
            });
        drop(file);
        done?;
        let tmp = self.tmp.take().expect("the temp file is kept until finish");
        tmp.publish(&self.path)
            .map_err(|e| StoreError::io(&self.path, "rename", e))?;
        // Best effort: makes the rename itself durable; some file systems refuse to sync a
        // directory, and the file is already complete either way.
        if let Some(dir) = self.path.parent() {
            let dir = if dir.as_os_str().is_empty() {
                Path::new(".")
            } else {
                dir
            };
            if let Ok(d) = File::open(dir) {
                let _ = d.sync_all();
            }
        }
        Ok(())
    }
}
