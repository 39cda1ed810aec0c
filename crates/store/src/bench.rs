//! Throughput of the photon file and of the encodings it could have used, for
//! `cargo xtask bench store`, which records its output in `docs/benchmarks.md`. Timings are
//! wall clock and only reported, never asserted.
//!
//! All rates are in GB/s (1e9 bytes) of *records*, 32 bytes per photon, whatever the encoding's
//! own size, so the rates compare directly.

use std::hint::black_box;
use std::path::Path;
use std::time::Instant;

use bytemuck::Zeroable;
use glam::Vec3;
use serde::{Deserialize, Serialize};

use crate::{Header, MapKind, MappedStore, Photon, StoreError, StoreReader, StoreWriter};

/// Throughput of one file written and read back by every path.
#[derive(Clone, Debug)]
pub struct StoreBench {
    pub photons: u64,
    pub file_bytes: u64,
    pub bytes_per_photon: f64,
    /// `StoreWriter` from `create` to `finish`, which includes fsync and rename: bound by the
    /// disk.
    pub write_gbs: f64,
    /// `create` and every `write`, before `finish`: chunking, checksums and the page cache.
    pub write_unsynced_gbs: f64,
    /// `StoreReader::open` and `next_chunk` over the whole file (page cache warm).
    pub stream_read_gbs: f64,
    /// `MappedStore::open` (map + every checksum) and a pass over every photon.
    pub mapped_read_gbs: f64,
}

/// Encoding and decoding one `Vec<Photon>` in memory, no files.
#[derive(Clone, Debug)]
pub struct EncodingBench {
    pub photons: u64,
    /// Plain records: the bytes are the records (`bytemuck`); encoding copies them into a
    /// buffer. Encoders write into preallocated buffers, so page faults are not timed.
    pub plain_bytes: u64,
    pub plain_encode_gbs: f64,
    /// Cast the bytes back to `&[Photon]` and read every record.
    pub plain_decode_gbs: f64,
    /// bincode 2 through serde, standard config (varint integers).
    pub bincode_bytes: u64,
    pub bincode_encode_gbs: f64,
    pub bincode_decode_gbs: f64,
    /// bincode 2 through serde with fixed-width integers (same size as plain records).
    pub bincode_fixint_encode_gbs: f64,
    pub bincode_fixint_decode_gbs: f64,
}

/// Deterministic, varied photons (a hash of the index), so no encoding sees constant data.
pub fn synthetic_photons(first: u64, n: usize) -> Vec<Photon> {
    (0..n as u64)
        .map(|i| {
            let mut h = (first + i).wrapping_mul(0x9E37_79B9_7F4A_7C15);
            let mut f = || {
                h ^= h >> 29;
                h = h.wrapping_mul(0xBF58_476D_1CE4_E5B9);
                (h >> 40) as f32 / (1u64 << 24) as f32
            };
            let pos = Vec3::new(f(), f(), f()) * 10.0 - 5.0;
            let power = Vec3::new(f(), f(), f()) * 1e-3;
            let dir = (Vec3::new(f(), f(), f()) - 0.5).normalize_or(Vec3::Z);
            Photon::new(pos, power, dir, (first + i) as u32 % 100_000)
        })
        .collect()
}

fn gbs(bytes: u64, secs: f64) -> f64 {
    bytes as f64 / secs.max(1e-9) / 1e9
}

/// Sums one field of every photon, so a read cannot be optimised away.
fn touch(photons: &[Photon]) -> f32 {
    photons.iter().map(|p| p.power[0]).sum()
}

/// Writes `photons` synthetic photons to a file in `dir`, reads it back by streaming and by
/// mapping, checks both reads saw the same photons, and deletes the file.
pub fn bench_store(dir: &Path, photons: usize) -> Result<StoreBench, StoreError> {
    let path = dir.join(format!("store-bench-{}.photons", std::process::id()));
    let block = synthetic_photons(0, 1 << 16);
    let header = Header::new(MapKind::Global, 1, 2, 3, "{\"bench\":true}".into());
    let record_bytes = photons as u64 * 32;

    let t = Instant::now();
    let mut w = StoreWriter::create(&path, header)?;
    let mut left = photons;
    while left > 0 {
        let n = left.min(block.len());
        w.write(&block[..n])?;
        left -= n;
    }
    let unsynced = t.elapsed().as_secs_f64();
    w.finish(photons as u64 * 3)?;
    let write = t.elapsed().as_secs_f64();
    let file_bytes = std::fs::metadata(&path)
        .map_err(|e| StoreError::io(&path, "stat", e))?
        .len();

    let result = (|| {
        let t = Instant::now();
        let mut r = StoreReader::open(&path)?;
        let mut buf = Vec::new();
        let mut sum_stream = 0.0f32;
        while r.next_chunk(&mut buf)? {
            sum_stream += touch(black_box(&buf));
        }
        let stream = t.elapsed().as_secs_f64();

        let t = Instant::now();
        let m = MappedStore::open(&path)?;
        let sum_mapped: f32 = m.chunks().map(|c| touch(black_box(c))).sum();
        let mapped = t.elapsed().as_secs_f64();
        assert_eq!(
            sum_stream, sum_mapped,
            "the two readers saw different photons"
        );
        Ok(StoreBench {
            photons: photons as u64,
            file_bytes,
            bytes_per_photon: file_bytes as f64 / photons.max(1) as f64,
            write_gbs: gbs(record_bytes, write),
            write_unsynced_gbs: gbs(record_bytes, unsynced),
            stream_read_gbs: gbs(record_bytes, stream),
            mapped_read_gbs: gbs(record_bytes, mapped),
        })
    })();
    let _ = std::fs::remove_file(&path);
    result
}

/// A serde mirror of `Photon`: store's types never derive serde (only `store` knows the bytes,
/// and it writes them explicitly), so the comparison needs its own struct.
#[derive(Clone, Copy, Serialize, Deserialize)]
struct SerdePhoton {
    pos: [f32; 3],
    power: [f32; 3],
    dir: u32,
    surface: u32,
}

/// Best of three runs of `f`, in seconds (the first may pay for page faults).
fn best_of_3(mut f: impl FnMut()) -> f64 {
    (0..3)
        .map(|_| {
            let t = Instant::now();
            f();
            t.elapsed().as_secs_f64()
        })
        .fold(f64::INFINITY, f64::min)
}

/// Encodes and decodes `photons` synthetic photons as plain records and with bincode 2.
pub fn bench_encodings(photons: usize) -> EncodingBench {
    let v = synthetic_photons(0, photons);
    let record_bytes = photons as u64 * 32;

    let mut plain = vec![0u8; record_bytes as usize];
    let plain_encode = best_of_3(|| plain.copy_from_slice(black_box(bytemuck::cast_slice(&v))));
    let plain_decode = best_of_3(|| {
        // A `Vec<u8>` need not be 4-aligned: cast in place when it is (always, in practice),
        // copy otherwise.
        let s = match bytemuck::try_cast_slice::<u8, Photon>(&plain) {
            Ok(s) => touch(black_box(s)),
            Err(_) => {
                let mut copy = vec![Photon::zeroed(); plain.len() / 32];
                bytemuck::cast_slice_mut::<Photon, u8>(&mut copy).copy_from_slice(&plain);
                touch(&copy)
            }
        };
        black_box(s);
    });

    let mirror: Vec<SerdePhoton> = v
        .iter()
        .map(|p| SerdePhoton {
            pos: p.pos,
            power: p.power,
            dir: p.dir,
            surface: p.surface,
        })
        .collect();
    let standard = bincode::config::standard();
    let fixint = bincode::config::standard().with_fixed_int_encoding();
    // Room for the worst case: a varint u32 takes up to 5 bytes, plus the length prefix.
    let mut enc = vec![0u8; photons * 40 + 16];
    let mut n = 0;
    let bincode_encode = best_of_3(|| {
        n = bincode::serde::encode_into_slice(black_box(&mirror), &mut enc, standard)
            .expect("encode");
    });
    enc.truncate(n);
    let bincode_decode = best_of_3(|| {
        let (d, _): (Vec<SerdePhoton>, usize) =
            bincode::serde::decode_from_slice(black_box(&enc), standard).expect("decode");
        black_box(d.iter().map(|p| p.power[0]).sum::<f32>());
    });
    let bincode_bytes = enc.len() as u64;
    let mut enc_fix = vec![0u8; photons * 32 + 16];
    let fix_encode = best_of_3(|| {
        n = bincode::serde::encode_into_slice(black_box(&mirror), &mut enc_fix, fixint)
            .expect("encode");
    });
    enc_fix.truncate(n);
    let fix_decode = best_of_3(|| {
        let (d, _): (Vec<SerdePhoton>, usize) =
            bincode::serde::decode_from_slice(black_box(&enc_fix), fixint).expect("decode");
        black_box(d.iter().map(|p| p.power[0]).sum::<f32>());
    });

    EncodingBench {
        photons: photons as u64,
        plain_bytes: plain.len() as u64,
        plain_encode_gbs: gbs(record_bytes, plain_encode),
        plain_decode_gbs: gbs(record_bytes, plain_decode),
        bincode_bytes,
        bincode_encode_gbs: gbs(record_bytes, bincode_encode),
        bincode_decode_gbs: gbs(record_bytes, bincode_decode),
        bincode_fixint_encode_gbs: gbs(record_bytes, fix_encode),
        bincode_fixint_decode_gbs: gbs(record_bytes, fix_decode),
    }
}
