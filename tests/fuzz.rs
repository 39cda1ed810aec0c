//! Coverage-free fuzzing on stable Rust: random mutations of valid files (bit flips, byte
//! values, cut, repeated or deleted ranges, numbers replaced by extreme ones, keywords
//! inserted) fed to each loader. A case passes when the loader returns (a value or an
//! error) without panicking, within a few seconds, and without any single allocation larger
//! than a bound proportional to the input (no allocation sized by an unchecked header
//! field; `alloc::Tracking` measures them per thread). The `it` test binary runs a few
//! thousand cases per target; `cargo xtask fuzz --seconds N` runs the `fuzz` binary for
//! longer. A failing case is saved with its target and seed, so it replays exactly.

use crate::alloc;
use std::panic::AssertUnwindSafe;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

/// What a fuzz loop feeds its mutations to.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Target {
    /// The OBJ loader (through a scene that names the mutated OBJ).
    Obj,
    /// The MTL reader (the OBJ's material library).
    Mtl,
    /// The PLY reader, on a binary (little-endian) file with normals and texture
    /// coordinates, mutated as binary.
    Ply,
    /// The PLY reader on the same mesh in ASCII, mutated as text.
    PlyAscii,
    /// The scene file (TOML) and the settings tables the pipeline parses from it.
    Scene,
    /// The photon-file readers (streaming and memory-mapped).
    Photons,
    /// The EXR reader.
    Exr,
}

impl Target {
    pub const ALL: [Target; 7] = [
        Target::Obj,
        Target::Mtl,
        Target::Ply,
        Target::PlyAscii,
        Target::Scene,
        Target::Photons,
        Target::Exr,
    ];

    pub fn name(self) -> &'static str {
        match self {
            Target::Obj => "obj",
            Target::Mtl => "mtl",
            Target::Ply => "ply",
            Target::PlyAscii => "ply-ascii",
            Target::Scene => "scene",
            Target::Photons => "photons",
            Target::Exr => "exr",
        }
    }

    fn is_text(self) -> bool {
        matches!(
            self,
            Target::Obj | Target::Mtl | Target::PlyAscii | Target::Scene
        )
    }
}

/// How long a loop runs.
#[derive(Clone, Copy, Debug)]
pub enum Budget {
    Cases(u64),
    Seconds(f64),
}

/// What a loop saw.
#[derive(Clone, Debug, Default)]
pub struct Stats {
    pub cases: u64,
    /// Inputs the loader accepted (the rest it refused with an error).
    pub accepted: u64,
    /// The largest single allocation of any case, in bytes.
    pub largest_alloc: usize,
}

/// A single allocation may be at most this plus `ALLOC_PER_BYTE` times the input's size.
const ALLOC_BASE: usize = 16 << 20;
const ALLOC_PER_BYTE: usize = 256;
/// A case that takes longer than this is a hang.
const HANG: Duration = Duration::from_secs(20);

/// splitmix64 (Steele et al. 2014): the fuzzer's own generator, so a case replays from its
/// seed whatever the renderer's RNG does.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }
}

/// Numbers a parser must survive.
const NUMBERS: [&str; 14] = [
    "0",
    "-0",
    "-1",
    "1e39",
    "-1e39",
    "nan",
    "inf",
    "-inf",
    "1e-45",
    "4294967296",
    "18446744073709551616",
    "99999999999999999999999",
    "0x10",
    "",
];

/// Lines and words that mean something to one of the text formats.
const WORDS: [&str; 22] = [
    "f 1 2 3",
    "f -1 -2 -3",
    "f 1/1/1 2//2 3",
    "v 1e30 0 0",
    "vt 0.5",
    "usemtl nothing",
    "mtllib missing.mtl",
    "newmtl x",
    "Kd 0.5",
    "Ke 1e38 1e38 1e38",
    "illum 99",
    "[[mesh]]",
    "[[sphere]]",
    "width = 0",
    "radius = -1",
    "photons = 1000000000000",
    "element vertex 4000000000",
    "property list uchar int vertex_indices",
    "property float nx",
    "property list float int vertex_indices",
    "end_header",
    "255 0 1 2",
];

/// Interesting machine words for binary formats.
const WORDS_BIN: [u64; 8] = [
    0,
    1,
    0x7F,
    0xFF,
    0x7FFF_FFFF,
    0xFFFF_FFFF,
    0x8000_0000_0000_0000,
    u64::MAX,
];

/// One to four random mutations of `input`.
fn mutate(input: &[u8], text: bool, rng: &mut Rng) -> Vec<u8> {
    let mut b = input.to_vec();
    for _ in 0..1 + rng.below(4) {
        let n = b.len();
        match rng.below(if text { 8 } else { 7 }) {
            0 if n > 0 => {
                let i = rng.below(n);
                b[i] ^= 1 << rng.below(8);
            }
            1 if n > 0 => {
                let i = rng.below(n);
                b[i] = rng.next() as u8;
            }
            2 if n > 0 => {
                let (i, len) = (rng.below(n), 1 + rng.below(64));
                b.drain(i..(i + len).min(n));
            }
            3 if n > 0 => {
                let (i, len) = (rng.below(n), 1 + rng.below(256));
                let piece: Vec<u8> = b[i..(i + len).min(n)].to_vec();
                let at = rng.below(n);
                b.splice(
                    at..at,
                    piece
                        .iter()
                        .copied()
                        .cycle()
                        .take(piece.len() * (1 + rng.below(8))),
                );
            }
            4 => b.truncate(rng.below(n + 1)),
            5 if text => {
                // A number token replaced by an extreme one.
                let starts: Vec<usize> = (0..n)
                    .filter(|&i| {
                        b[i].is_ascii_digit() && (i == 0 || !b[i - 1].is_ascii_alphanumeric())
                    })
                    .collect();
                if !starts.is_empty() {
                    let s = starts[rng.below(starts.len())];
                    let mut e = s;
                    while e < n && (b[e].is_ascii_digit() || b[e] == b'.' || b[e] == b'e') {
                        e += 1;
                    }
                    let with = NUMBERS[rng.below(NUMBERS.len())];
                    b.splice(s..e, with.bytes());
                }
            }
            5 | 6 if !text && n >= 8 => {
                // A header word (aligned, in the first 256 bytes most of the time) set.
                let span = if rng.below(4) > 0 { n.min(256) } else { n };
                let at = rng.below(span - 7.min(span)) & !3;
                let v = WORDS_BIN[rng.below(WORDS_BIN.len())];
                let wide = rng.below(2) == 0 && at + 8 <= n;
                let bytes = v.to_le_bytes();
                let len = if wide { 8 } else { 4 };
                b[at..at + len].copy_from_slice(&bytes[..len]);
            }
            6 | 7 if text => {
                let line = format!("\n{}\n", WORDS[rng.below(WORDS.len())]);
                let at = rng.below(n + 1);
                b.splice(at..at, line.bytes());
            }
            _ => {}
        }
    }
    b
}

/// The valid inputs each target mutates, and where the loader reads them.
struct Corpus {
    dir: PathBuf,
    obj: Vec<u8>,
    mtl: Vec<u8>,
    ply: Vec<u8>,
    ply_ascii: Vec<u8>,
    scene: Vec<u8>,
    photons: Vec<u8>,
    exr: Vec<u8>,
}

const OBJ: &str = "\
mtllib box.mtl
o floor
usemtl white
v -1 0 -1
v 1 0 -1
v 1 0 1
v -1 0 1
vn 0 1 0
vt 0 0
vt 1 0
vt 1 1
f 1/1/1 2/2/1 3/3/1
f 1//1 3//1 4//1
o light
usemtl lamp
v -0.2 1.9 -0.2
v 0.2 1.9 -0.2
v 0.2 1.9 0.2
v -0.2 1.9 0.2
f 5 6 7 8
o wall
usemtl red
v -1 0 -1
v -1 2 -1
v -1 2 1
v -1 0 1
f 9 10 11 12
";

const MTL: &str = "\
newmtl white
Kd 0.7 0.7 0.7
newmtl red
Kd 0.6 0.1 0.1
Ks 0 0 0
illum 2
newmtl lamp
Kd 0 0 0
Ka 10 10 10
";

const SCENE: &str = "\
name = \"fuzz\"
seed = 3

[camera]
eye = [0.0, 1.0, 3.0]
look_at = [0.0, 1.0, 0.0]
up = [0.0, 1.0, 0.0]
vfov = 50.0
width = 8
height = 8

[render]
spp = 1

[[mesh]]
obj = \"box.obj\"
scale = 1.0
emission = \"ka\"

[[mesh]]
ply = \"box.ply\"
material = \"grey\"
translate = [0.0, 0.5, 0.0]
normals = \"auto\"

[[sphere]]
center = [0.3, 0.3, 0.0]
radius = 0.3
material = \"glass\"

[material.glass]
type = \"dielectric\"
ior = 1.5

[material.grey]
type = \"lambertian\"
albedo = [0.5, 0.5, 0.5]

[photons]
photons = 1000
max_depth = 8

[estimate]
spp = 1

[estimate.global]
k = 50
kernel = { kind = \"silverman\" }
topo = 0.1
";

impl Corpus {
    fn new(dir: &Path) -> Result<Corpus, String> {
        std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
        let photons_path = dir.join("valid.photons");
        let header = store::Header::new(
            store::MapKind::Global,
            7,
            0x1234,
            0x5678,
            r#"{"photons":100}"#.into(),
        );
        let mut w = store::StoreWriter::create(&photons_path, header).map_err(|e| e.to_string())?;
        let photons: Vec<store::Photon> = (0..100)
            .map(|i| store::Photon {
                pos: [i as f32 * 0.01, 0.0, 0.5],
                power: [0.01; 3],
                dir: store::oct_encode(glam::Vec3::NEG_Y),
                surface: i % 3,
            })
            .collect();
        w.write(&photons).map_err(|e| e.to_string())?;
        w.finish(150).map_err(|e| e.to_string())?;
        let exr_path = dir.join("valid.exr");
        let img = film::Image::from_fn(8, 6, |x, y| [x as f32 * 0.1, y as f32, 0.5]);
        film::write_exr(&exr_path, &img).map_err(|e| e.to_string())?;
        let read = |p: &Path| std::fs::read(p).map_err(|e| format!("{}: {e}", p.display()));
        Ok(Corpus {
            dir: dir.to_path_buf(),
            obj: OBJ.as_bytes().to_vec(),
            mtl: MTL.as_bytes().to_vec(),
            ply: crate::ply::write(crate::ply::Format::Little, &ply_mesh()),
            ply_ascii: crate::ply::write(crate::ply::Format::Ascii, &ply_mesh()),
            scene: SCENE.as_bytes().to_vec(),
            photons: read(&photons_path)?,
            exr: read(&exr_path)?,
        })
    }

    fn valid(&self, t: Target) -> &[u8] {
        match t {
            Target::Obj => &self.obj,
            Target::Mtl => &self.mtl,
            Target::Ply => &self.ply,
            Target::PlyAscii => &self.ply_ascii,
            Target::Scene => &self.scene,
            Target::Photons => &self.photons,
            Target::Exr => &self.exr,
        }
    }

    /// Writes the case's files (the mutated one and the valid others) and runs the loader:
    /// `Ok(true)` accepted, `Ok(false)` refused with an error.
    fn load(&self, t: Target, input: &[u8]) -> std::io::Result<bool> {
        let d = &self.dir;
        let file = |name: &str, valid: &[u8]| {
            std::fs::write(d.join(name), if t_is(t, name) { input } else { valid })
        };
        Ok(match t {
            Target::Obj | Target::Mtl | Target::Ply | Target::PlyAscii | Target::Scene => {
                file("box.obj", &self.obj)?;
                file("box.mtl", &self.mtl)?;
                file("box.ply", &self.ply)?;
                file("scene.toml", &self.scene)?;
                match scene::Scene::load(d.join("scene.toml")) {
                    Ok(s) => {
                        // The tables the pipeline reads from the scene file, parsed too.
                        render::Settings::new(&s, &render::Overrides::default()).is_ok()
                    }
                    Err(_) => false,
                }
            }
            Target::Photons => {
                let p = d.join("case.photons");
                std::fs::write(&p, input)?;
                let streamed = store::StoreReader::open(&p).and_then(|r| r.read_all());
                let mapped = store::MappedStore::open(&p).map(|m| m.to_vec());
                streamed.is_ok() && mapped.is_ok()
            }
            Target::Exr => {
                let p = d.join("case.exr");
                std::fs::write(&p, input)?;
                film::read_exr(&p).is_ok()
            }
        })
    }
}

fn t_is(t: Target, name: &str) -> bool {
    matches!(
        (t, name),
        (Target::Obj, "box.obj")
            | (Target::Mtl, "box.mtl")
            | (Target::Ply | Target::PlyAscii, "box.ply")
            | (Target::Scene, "scene.toml")
    )
}

/// The PLY target's mesh: a box's five faces (quads) and a triangle in its top, with
/// normals and texture coordinates.
fn ply_mesh() -> crate::ply::Mesh {
    let mut m = crate::ply::Mesh::default();
    let quads = [
        ([0.0, -0.5, 0.0], [0.0, -1.0, 0.0]),
        ([-0.5, 0.0, 0.0], [-1.0, 0.0, 0.0]),
        ([0.5, 0.0, 0.0], [1.0, 0.0, 0.0]),
        ([0.0, 0.0, -0.5], [0.0, 0.0, -1.0]),
        ([0.0, 0.0, 0.5], [0.0, 0.0, 1.0]),
    ];
    for (c, n) in quads {
        let axis = n.iter().position(|x: &f32| *x != 0.0).unwrap_or(0);
        let (a, b) = ((axis + 1) % 3, (axis + 2) % 3);
        let base = m.positions.len() as i32;
        for (s, t) in [(-0.5, -0.5), (0.5, -0.5), (0.5, 0.5), (-0.5, 0.5)] {
            let mut p: [f32; 3] = c;
            p[a] += s;
            p[b] += t;
            m.positions.push(p);
            m.normals.push(n);
            m.uvs.push([s + 0.5, t + 0.5]);
        }
        m.faces.push((base..base + 4).collect());
    }
    let base = m.positions.len() as i32;
    for p in [[-0.2, 0.5, -0.2], [0.2, 0.5, -0.2], [0.0, 0.5, 0.2]] {
        m.positions.push(p);
        m.normals.push([0.0, 1.0, 0.0]);
        m.uvs.push([0.5, 0.5]);
    }
    m.faces.push(vec![base, base + 1, base + 2]);
    m
}

/// Runs `target`'s loop from `seed` in `dir` (a scratch directory) for `budget`. A failure
/// names the case, its seed and where its input was saved.
pub fn run(target: Target, seed: u64, budget: Budget, dir: &Path) -> Result<Stats, String> {
    let corpus = Corpus::new(dir)?;
    let valid = corpus.valid(target).to_vec();
    let mut stats = Stats::default();
    let t0 = Instant::now();
    // A watchdog: a case running past `HANG` is a hang; the input is saved first (below),
    // so the process can end with the case on disk.
    let current = Arc::new(AtomicU64::new(u64::MAX));
    let started = Arc::new(Mutex::new(Instant::now()));
    let done = Arc::new(AtomicU64::new(0));
    let watchdog = {
        let (current, started, done) = (current.clone(), started.clone(), done.clone());
        let saved = dir.join(format!("hang-{}.bin", target.name()));
        std::thread::spawn(move || {
            while done.load(Ordering::Relaxed) == 0 {
                std::thread::sleep(Duration::from_millis(200));
                let case = current.load(Ordering::Relaxed);
                let since = started.lock().map(|s| s.elapsed()).unwrap_or_default();
                if case != u64::MAX && since > HANG {
                    eprintln!(
                        "fuzz {}: case {case} has run {since:?}: a hang (input: {})",
                        target.name(),
                        saved.display()
                    );
                    std::process::abort();
                }
            }
        })
    };
    let result = (|| {
        for case in 0.. {
            match budget {
                Budget::Cases(n) if case >= n => break,
                Budget::Seconds(s) if t0.elapsed().as_secs_f64() >= s => break,
                _ => {}
            }
            let mut rng = Rng(seed ^ (case.wrapping_mul(0xA24B_AED4_963E_E407)));
            let input = mutate(&valid, target.is_text(), &mut rng);
            let _ = std::fs::write(dir.join(format!("hang-{}.bin", target.name())), &input);
            if let Ok(mut s) = started.lock() {
                *s = Instant::now();
            }
            current.store(case, Ordering::Relaxed);
            alloc::take_largest();
            let outcome =
                std::panic::catch_unwind(AssertUnwindSafe(|| corpus.load(target, &input)));
            let largest = alloc::take_largest();
            current.store(u64::MAX, Ordering::Relaxed);
            let fail = |what: String| {
                let p = dir.join(format!("crash-{}-{seed}-{case}.bin", target.name()));
                let _ = std::fs::write(&p, &input);
                format!(
                    "fuzz {} seed {seed} case {case}: {what} (input saved as {})",
                    target.name(),
                    p.display()
                )
            };
            match outcome {
                Err(p) => {
                    let msg = p
                        .downcast_ref::<String>()
                        .cloned()
                        .or_else(|| p.downcast_ref::<&str>().map(|s| s.to_string()))
                        .unwrap_or_default();
                    return Err(fail(format!("panicked: {msg}")));
                }
                Ok(Err(e)) => return Err(fail(format!("cannot write the case: {e}"))),
                Ok(Ok(accepted)) => stats.accepted += accepted as u64,
            }
            let bound = ALLOC_BASE + ALLOC_PER_BYTE * input.len();
            if largest > bound {
                return Err(fail(format!(
                    "allocated {largest} bytes at once for a {}-byte input (bound {bound})",
                    input.len()
                )));
            }
            stats.largest_alloc = stats.largest_alloc.max(largest);
            stats.cases += 1;
        }
        Ok(())
    })();
    done.store(1, Ordering::Relaxed);
    let _ = watchdog.join();
    result.map(|()| stats)
}
