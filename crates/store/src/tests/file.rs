use std::path::{Path, PathBuf};

use crate::bench::synthetic_photons;
use crate::error::Problem;
use crate::format::{DEFAULT_CHUNK_PHOTONS, FORMAT_VERSION};
use crate::{
    Expect, Header, MapKind, MappedStore, Photon, StoreError, StoreReader, StoreWriter, check,
};

/// A fresh directory per test, removed on drop (also when the test fails).
struct TempDir(PathBuf);

impl TempDir {
    fn new(name: &str) -> TempDir {
        let dir = std::env::temp_dir().join(format!("store-test-{}-{name}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        TempDir(dir)
    }

    fn path(&self, file: &str) -> PathBuf {
        self.0.join(file)
    }

    fn listing(&self) -> Vec<String> {
        let mut v: Vec<String> = std::fs::read_dir(&self.0)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        v.sort();
        v
    }
}

impl Drop for TempDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

fn header() -> Header {
    Header::new(
        MapKind::Caustic,
        0xDEAD_BEEF_0123_4567,
        0x1111_2222_3333_4444,
        0x5555_6666_7777_8888,
        r#"{"photons":1000,"max_depth":8}"#.to_string(),
    )
}

fn expect() -> Expect {
    Expect {
        scene_hash: 0x1111_2222_3333_4444,
        params_hash: 0x5555_6666_7777_8888,
        kind: MapKind::Caustic,
    }
}

/// Writes `photons` in uneven slices (so writes straddle chunk boundaries) with `capacity`
/// photons per chunk, and `emitted = 3 * len + 1`.
fn write(path: &Path, photons: &[Photon], capacity: u32) {
    let mut w = StoreWriter::with_chunk_capacity(path, header(), capacity).unwrap();
    let mut rest = photons;
    let mut step = 1;
    while !rest.is_empty() {
        let (now, later) = rest.split_at(step.min(rest.len()));
        w.write(now).unwrap();
        rest = later;
        step = step * 3 + 1;
    }
    assert_eq!(w.stored(), photons.len() as u64);
    w.finish(3 * photons.len() as u64 + 1).unwrap();
}

fn read_streaming(path: &Path) -> Result<(Header, Vec<Photon>), StoreError> {
    let r = StoreReader::open(path)?;
    let h = r.header().clone();
    Ok((h, r.read_all()?))
}

fn read_mapped(path: &Path) -> Result<(Header, Vec<Photon>), StoreError> {
    let m = MappedStore::open(path)?;
    Ok((m.header().clone(), m.to_vec()))
}

fn bits(photons: &[Photon]) -> &[u8] {
    bytemuck::cast_slice(photons)
}

/// Both readers refuse `path`; returns both errors.
fn refused(path: &Path) -> [StoreError; 2] {
    let s = read_streaming(path).err();
    let m = read_mapped(path).err();
    match (s, m) {
        (Some(s), Some(m)) => [s, m],
        (s, m) => panic!(
            "{}: streaming {:?}, mapped {:?}: both must refuse",
            path.display(),
            s.map(|e| e.to_string()),
            m.map(|e| e.to_string())
        ),
    }
}

#[test]
fn round_trip_is_exact_for_counts_around_chunk_sizes() {
    let dir = TempDir::new("round-trip");
    for capacity in [7, DEFAULT_CHUNK_PHOTONS] {
        let c = capacity as usize;
        for n in [0, 1, c - 1, c, c + 1, 3 * c + 2] {
            let photons = synthetic_photons(n as u64, n);
            let path = dir.path(&format!("{capacity}-{n}.photons"));
            write(&path, &photons, capacity);
            for (how, read) in [
                ("streaming", read_streaming as fn(&Path) -> _),
                ("mapped", read_mapped),
            ] {
                let (h, got) = read(&path).unwrap();
                let want = Header {
                    emitted: 3 * n as u64 + 1,
                    stored: n as u64,
                    ..header()
                };
                assert_eq!(h, want, "{how}, capacity {capacity}, {n} photons");
                assert!(
                    bits(&got) == bits(&photons),
                    "{how}, capacity {capacity}, {n} photons"
                );
            }
            // Every chunk but the last is full, and the mapped chunks are the streamed ones.
            let m = MappedStore::open(&path).unwrap();
            let mut r = StoreReader::open(&path).unwrap();
            let mut buf = Vec::new();
            let mut chunks = 0;
            for mapped in m.chunks() {
                assert!(r.next_chunk(&mut buf).unwrap());
                assert!(bits(mapped) == bits(&buf));
                chunks += 1;
            }
            assert!(!r.next_chunk(&mut buf).unwrap());
            assert_eq!(chunks, n.div_ceil(c));
            let size = std::fs::metadata(&path).unwrap().len() as usize;
            let header_len = crate::format::header_len(&header().params);
            assert_eq!(size, header_len + 32 * chunks + 32 * n);
        }
    }
}

/// A file of 3 chunks (capacity 4: 4 + 4 + 2 photons).
fn small_file(dir: &TempDir) -> (PathBuf, Vec<u8>) {
    let path = dir.path("small.photons");
    write(&path, &synthetic_photons(0, 10), 4);
    let bytes = std::fs::read(&path).unwrap();
    (path, bytes)
}

#[test]
fn every_single_byte_change_is_refused_by_both_readers() {
    let dir = TempDir::new("flip");
    let (path, bytes) = small_file(&dir);
    assert!(read_streaming(&path).is_ok() && read_mapped(&path).is_ok());
    let bad = dir.path("bad.photons");
    for i in 0..bytes.len() {
        // Two changes per byte: one bit, and all bits.
        for flip in [0x01u8, 0xff] {
            let mut b = bytes.clone();
            b[i] ^= flip;
            std::fs::write(&bad, &b).unwrap();
            let [s, m] = refused(&bad);
            assert!(s.to_string().starts_with(&bad.display().to_string()), "{s}");
            assert!(m.to_string().starts_with(&bad.display().to_string()), "{m}");
        }
    }
}

#[test]
fn a_payload_change_names_its_chunk() {
    let dir = TempDir::new("flip-chunk");
    let (path, mut bytes) = small_file(&dir);
    let header_len = crate::format::header_len(&header().params);
    // Chunk 2 of 3 starts after chunk 1 (32 + 4 * 32 bytes); change its second photon.
    bytes[header_len + 160 + 32 + 40] ^= 4;
    std::fs::write(&path, &bytes).unwrap();
    for e in refused(&path) {
        assert!(
            matches!(e.problem, Problem::ChunkChecksum { chunk: 1, of: 3 }),
            "{e}"
        );
        assert!(
            e.to_string().ends_with("checksum mismatch in chunk 2 of 3"),
            "{e}"
        );
    }
}

#[test]
fn truncation_anywhere_is_refused_by_both_readers() {
    let dir = TempDir::new("truncate");
    let (_, bytes) = small_file(&dir);
    let header_len = crate::format::header_len(&header().params);
    let chunk = 32 + 4 * 32;
    let mut cuts: Vec<usize> = vec![0, 1, 7, 8, 15, 16, 40, header_len - 1, header_len];
    for c in 0..3 {
        let at = header_len + c * chunk;
        cuts.extend([at, at + 1, at + 31, at + 32, at + 33, at + 64]);
    }
    cuts.push(bytes.len() - 1);
    let bad = dir.path("cut.photons");
    for cut in cuts.into_iter().filter(|&c| c < bytes.len()) {
        std::fs::write(&bad, &bytes[..cut]).unwrap();
        for e in refused(&bad) {
            let is_truncated = matches!(e.problem, Problem::Truncated { .. });
            let foreign = matches!(e.problem, Problem::NotPhotonFile);
            // Cut inside the magic, the file is simply not ours.
            assert!(is_truncated || (cut < 8 && foreign), "cut at {cut}: {e}");
        }
    }
    // The message says which chunk and where.
    let cut = header_len + chunk + 50;
    std::fs::write(&bad, &bytes[..cut]).unwrap();
    for e in refused(&bad) {
        let want = format!(
            "truncated: chunk 2 of 3 ends at byte {} but file has {cut}",
            header_len + 2 * chunk
        );
        assert!(e.to_string().ends_with(&want), "{e}");
    }
    // And bytes past the end are refused too.
    let mut long = bytes.clone();
    long.extend_from_slice(&[0; 32]);
    std::fs::write(&bad, &long).unwrap();
    for e in refused(&bad) {
        assert!(matches!(e.problem, Problem::TrailingBytes { .. }), "{e}");
    }
}

#[test]
fn foreign_files_are_not_photon_files() {
    let dir = TempDir::new("foreign");
    let mut random = vec![0u8; 4096];
    let mut x = 0x2545_F491_4F6C_DD1Du64;
    for b in random.iter_mut() {
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        *b = x as u8;
    }
    let files: [(&str, &[u8]); 4] = [
        ("empty", b""),
        ("random", &random),
        (
            "png",
            b"\x89PNG\r\n\x1a\n\0\0\0\rIHDR\0\0\0\x01\0\0\0\x01\x08\x02\0\0\0",
        ),
        ("text", b"# scene\n[camera]\nfov = 40\n"),
    ];
    for (name, bytes) in files {
        let path = dir.path(name);
        std::fs::write(&path, bytes).unwrap();
        for e in refused(&path) {
            assert!(matches!(e.problem, Problem::NotPhotonFile), "{name}: {e}");
            assert_eq!(
                e.to_string(),
                format!("{}: not a photon file (bad magic)", path.display())
            );
        }
    }
}

/// Rewrites the version field and the header checksum, so only the version is wrong.
fn with_version(bytes: &[u8], version: u32) -> Vec<u8> {
    let mut b = bytes.to_vec();
    b[8..12].copy_from_slice(&version.to_le_bytes());
    let n = u32::from_le_bytes(b[12..16].try_into().unwrap()) as usize;
    let crc = crc32fast::hash(&b[..n - 4]);
    b[n - 4..n].copy_from_slice(&crc.to_le_bytes());
    b
}

#[test]
fn other_format_versions_are_refused() {
    let dir = TempDir::new("version");
    let (path, bytes) = small_file(&dir);
    // The patch alone keeps the file valid: the checksum is recomputed.
    std::fs::write(&path, with_version(&bytes, FORMAT_VERSION)).unwrap();
    assert!(read_streaming(&path).is_ok() && read_mapped(&path).is_ok());
    for v in [FORMAT_VERSION - 1, FORMAT_VERSION + 1] {
        std::fs::write(&path, with_version(&bytes, v)).unwrap();
        for e in refused(&path) {
            assert!(
                matches!(e.problem, Problem::Version { found, .. } if found == v),
                "{e}"
            );
            let want = format!("format version {v}, this build reads {FORMAT_VERSION}");
            assert!(e.to_string().ends_with(&want), "{e}");
        }
    }
}

#[test]
fn another_record_layout_is_refused() {
    let dir = TempDir::new("layout");
    let (path, mut bytes) = small_file(&dir);
    // "...,le" -> "...,be", checksum recomputed: a file from a big-endian machine.
    let at = 76 + crate::RECORD_LAYOUT.len() - 2;
    bytes[at] = if bytes[at] == b'l' { b'b' } else { b'l' };
    let n = u32::from_le_bytes(bytes[12..16].try_into().unwrap()) as usize;
    let crc = crc32fast::hash(&bytes[..n - 4]);
    bytes[n - 4..n].copy_from_slice(&crc.to_le_bytes());
    std::fs::write(&path, &bytes).unwrap();
    for e in refused(&path) {
        assert!(matches!(e.problem, Problem::Layout { .. }), "{e}");
    }
}

#[test]
fn check_refuses_files_made_for_something_else() {
    let dir = TempDir::new("check");
    let (path, _) = small_file(&dir);
    let r = StoreReader::open(&path).unwrap();
    let m = MappedStore::open(&path).unwrap();
    r.check(&expect()).unwrap();
    m.check(&expect()).unwrap();
    let cases = [
        (
            Expect {
                scene_hash: 1,
                ..expect()
            },
            "made for another scene (scene hash 1111222233334444, expected 0000000000000001)",
        ),
        (
            Expect {
                params_hash: 2,
                ..expect()
            },
            "made with other emission parameters (params hash 5555666677778888, expected 0000000000000002)",
        ),
        (
            Expect {
                kind: MapKind::Global,
                ..expect()
            },
            "holds the Caustic photon map, expected the Global one",
        ),
    ];
    for (e, msg) in cases {
        for err in [
            r.check(&e).unwrap_err(),
            m.check(&e).unwrap_err(),
            check(&path, r.header(), &e).unwrap_err(),
        ] {
            assert_eq!(err.to_string(), format!("{}: {msg}", path.display()));
        }
    }
}

#[test]
fn an_unfinished_writer_leaves_nothing_and_a_finished_one_one_file() {
    let dir = TempDir::new("atomic");
    let path = dir.path("map.photons");
    let photons = synthetic_photons(0, 100);

    let mut w = StoreWriter::with_chunk_capacity(&path, header(), 8).unwrap();
    w.write(&photons).unwrap();
    // Mid-write: only the temp file exists, and it does not read as a photon file.
    let names = dir.listing();
    assert_eq!(names.len(), 1);
    assert!(names[0].starts_with(".map.photons.tmp-"), "{names:?}");
    let [e, _] = refused(&dir.path(&names[0]));
    assert!(matches!(e.problem, Problem::NotPhotonFile), "{e}");
    drop(w);
    assert!(dir.listing().is_empty(), "{:?}", dir.listing());

    write(&path, &photons, 8);
    assert_eq!(dir.listing(), ["map.photons"]);
    // A second finished writer replaces the file whole.
    write(&path, &photons[..10], 8);
    assert_eq!(dir.listing(), ["map.photons"]);
    assert_eq!(read_mapped(&path).unwrap().1.len(), 10);
}

#[test]
fn errors_name_the_file() {
    let dir = TempDir::new("names");
    let missing = dir.path("missing.photons");
    for e in refused(&missing) {
        assert!(matches!(e.problem, Problem::Io { .. }), "{e}");
        assert!(
            e.to_string().starts_with(&missing.display().to_string()),
            "{e}"
        );
        assert!(std::error::Error::source(&e).is_some());
    }
    let nowhere = dir.path("no-such-dir").join("map.photons");
    let e = StoreWriter::create(&nowhere, header()).err().unwrap();
    assert!(
        e.to_string()
            .contains(&dir.path("no-such-dir").display().to_string()),
        "{e}"
    );
}

#[test]
fn bench_store_reads_back_what_it_wrote() {
    // Throughput is printed by `cargo xtask bench store`, never asserted; this checks sizes.
    let dir = TempDir::new("bench");
    let b = crate::bench::bench_store(&dir.0, 70_000).unwrap();
    let header_len = crate::format::header_len("{\"bench\":true}") as u64;
    assert_eq!(b.file_bytes, header_len + 2 * 32 + 70_000 * 32);
    assert!(b.bytes_per_photon < 32.01);
    assert!(dir.listing().is_empty());
}

/// A writer's temp file is one of `temps`': a signal handler removes it at once (the sweep of
/// a dead process's temps is `temps`' own test).
#[test]
fn a_writers_temp_file_is_removed_on_a_signal() {
    let dir = TempDir::new("live");
    let mut w = StoreWriter::with_chunk_capacity(&dir.path("live.photons"), header(), 8).unwrap();
    w.write(&synthetic_photons(0, 20)).unwrap();
    let names = dir.listing();
    assert_eq!(names.len(), 1);
    assert_eq!(
        temps::owner(&names[0]),
        Some(std::process::id()),
        "{names:?}"
    );
    // What the signal handler calls, limited to this test's directory: other tests write too.
    assert_eq!(temps::remove_live_under(&dir.0).files, 1);
    assert!(dir.listing().is_empty(), "{:?}", dir.listing());
    // The writer then fails or is dropped without harm.
    drop(w);
    assert!(crate::free_space(&dir.0).is_some_and(|b| b > 0));
}
