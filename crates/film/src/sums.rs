//! Files of f64 per-pixel sums: what a shard of a render hands to `merge` (an EXR holds f32,
//! and the one-machine run adds f64 sums: a merge that is to match it bit for bit needs the
//! sums themselves). A file holds `planes` images of `[f64; 3]` per pixel, whole or not at all
//! (written atomically, checked by a CRC-32 over every byte).
//!
//! ```text
//! offset  size        field                      (little-endian)
//! 0       8           magic "PFSUMS\0\0"
//! 8       4           version (1)
//! 12      4           width
//! 16      4           height
//! 20      4           planes P
//! 24      24 w h P    f64 sums, plane by plane, row by row, r g b
//! end-4   4           CRC-32 of every byte before it
//! ```

// A decoder of untrusted bytes: no input may reach a panic (see `io.rs`).
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

use crate::FilmError;
use std::path::Path;

const MAGIC: [u8; 8] = *b"PFSUMS\0\0";
const VERSION: u32 = 1;
const HEAD: usize = 24;

/// Planes of f64 sums per pixel, all `width` x `height`.
#[derive(Clone, Debug, PartialEq)]
pub struct Sums {
    pub width: usize,
    pub height: usize,
    pub planes: Vec<Vec<[f64; 3]>>,
}

/// Writes `s` to `path` atomically (see [`crate::write_atomic`]).
pub fn write_sums(path: &Path, s: &Sums) -> Result<(), FilmError> {
    let bad = |problem: String| FilmError::Sums {
        path: path.to_owned(),
        problem,
    };
    let n = s.width.saturating_mul(s.height);
    if let Some(p) = s.planes.iter().find(|p| p.len() != n) {
        return Err(bad(format!(
            "a plane of {} pixels in a {}x{} file",
            p.len(),
            s.width,
            s.height
        )));
    }
    let dims: Vec<u32> = [s.width, s.height, s.planes.len()]
        .iter()
        .map(|&v| u32::try_from(v).map_err(|_| bad(format!("{v} does not fit 32 bits"))))
        .collect::<Result<_, _>>()?;
    let mut b = Vec::with_capacity(HEAD + 24 * n * s.planes.len() + 4);
    b.extend_from_slice(&MAGIC);
    b.extend_from_slice(&VERSION.to_le_bytes());
    for d in dims {
        b.extend_from_slice(&d.to_le_bytes());
    }
    for px in s.planes.iter().flatten() {
        for c in px {
            b.extend_from_slice(&c.to_le_bytes());
        }
    }
    let crc = crc32fast::hash(&b);
    b.extend_from_slice(&crc.to_le_bytes());
    crate::write_atomic(path, &b)
}

/// Reads a file [`write_sums`] wrote; refuses anything else (wrong magic or version, a
/// length the header does not predict, a checksum mismatch) naming the file.
pub fn read_sums(path: &Path) -> Result<Sums, FilmError> {
    let bad = |problem: String| FilmError::Sums {
        path: path.to_owned(),
        problem,
    };
    match std::fs::metadata(path) {
        Ok(m) if !m.is_file() => return Err(bad("not a regular file".into())),
        _ => {}
    }
    let b = std::fs::read(path).map_err(|e| FilmError::Io {
        path: path.to_owned(),
        what: "read",
        source: e,
    })?;
    let u32_at = |at: usize| -> Option<u32> {
        b.get(at..at + 4)
            .and_then(|s| s.try_into().ok())
            .map(u32::from_le_bytes)
    };
    if b.get(..8) != Some(&MAGIC[..]) {
        return Err(bad("not a file of f64 sums (bad magic)".into()));
    }
    let (Some(version), Some(w), Some(h), Some(p)) =
        (u32_at(8), u32_at(12), u32_at(16), u32_at(20))
    else {
        return Err(bad(format!("truncated: {} bytes", b.len())));
    };
    if version != VERSION {
        return Err(bad(format!("version {version}, expected {VERSION}")));
    }
    let (w, h, p) = (w as u128, h as u128, p as u128);
    let expected = HEAD as u128 + 24 * w * h * p + 4;
    if b.len() as u128 != expected {
        return Err(bad(format!(
            "{} bytes, but {w}x{h} pixels in {p} planes take {expected}",
            b.len()
        )));
    }
    let Some((body, crc)) = b.split_last_chunk::<4>() else {
        return Err(bad("truncated".into()));
    };
    if crc32fast::hash(body) != u32::from_le_bytes(*crc) {
        return Err(bad("checksum mismatch: the file is damaged".into()));
    }
    let n = (w * h) as usize;
    let values: Vec<f64> = body
        .get(HEAD..)
        .unwrap_or_default()
        .chunks_exact(8)
        .map(|c| {
            let mut a = [0u8; 8];
            a.copy_from_slice(c);
            f64::from_le_bytes(a)
        })
        .collect();
    let pixels: Vec<[f64; 3]> = values
        .chunks_exact(3)
        .filter_map(|c| <[f64; 3]>::try_from(c).ok())
        .collect();
    let planes = if n == 0 {
        vec![Vec::new(); p as usize]
    } else {
        pixels.chunks_exact(n).map(<[_]>::to_vec).collect()
    };
    Ok(Sums {
        width: w as usize,
        height: h as usize,
        planes,
    })
}
