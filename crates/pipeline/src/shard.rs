//! Shards of one run and their merge (issue 14). Photon `i` draws from the stream `(seed, i)`
//! and pixel sample `s` from its own, so a run split into index ranges can run anywhere and
//! be put back together exactly:
//!
//! - `trace --shard I/N` traces photon paths `[I P / N, (I + 1) P / N)` of a run of `P` (powers
//!   already divided by `P`), into photon files whose header counts the shard's paths;
//!   merging concatenates them in shard order and writes the photon file the one-machine
//!   `trace` writes, byte for byte.
//! - `render --shard I/N` (`path`, `caustic-splat`) renders the blocks of the run
//!   ([`crate::methods::Accumulate`]: the path tracer's passes of samples, splatting's
//!   passes) that start in the shard's range, and writes each block's f64 sums per pixel;
//!   merging adds every block from zero in block order, exactly as the one-machine run adds
//!   them, and writes the same `image.exr` and `layers/`.
//!
//! A shard is a directory: its results and `shard.json` ([`Manifest`]: scene hash, seed,
//! parameter hash, shard `I/N`, range and counts). It is built under a temporary name and
//! renamed into place, so a shard directory is complete or absent.

use crate::flow::{self, PipelineOptions, Sink, StoreSink};
use crate::methods::{self, Run};
use crate::photon_cache::{self, CacheKey};
use crate::progress::Progress;
use crate::settings::{Overrides, Settings};
pub use composite::shards::ShardId;
use composite::shards::{Part, cover};
use glam::DVec3;
use scene::Scene;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};
use store::{Header, MapKind, MappedStore, StoreWriter};

/// The file that describes a shard directory.
pub const MANIFEST: &str = "shard.json";
/// The f64 block sums of an image shard (`film::write_sums`), block by block, layer by layer.
pub const SUMS: &str = "sums.f64";
const VERSION: u32 = 1;

/// `shard.json`: what a shard holds and what it belongs to.
#[derive(Serialize, Deserialize, Clone, Debug)]
#[serde(deny_unknown_fields)]
pub struct Manifest {
    /// The manifest's version.
    pub photonflow_shard: u32,
    /// "photons" or "image".
    pub what: String,
    /// The method of an image shard.
    pub method: Option<String>,
    /// The scene file the shard was made from (for messages only).
    pub scene: String,
    /// Photons: `Scene::photon_hash`; images: `Scene::view_hash` (16 hex digits).
    pub scene_hash: String,
    pub seed: u64,
    /// Photons: the emission parameters' cache key; images: `Settings::hash`.
    pub params_hash: String,
    /// `I/N`, counted from 0.
    pub shard: String,
    /// What the range counts: "photon paths", "samples per pixel" or "passes".
    pub unit: String,
    /// Photons: the paths traced; images: the blocks rendered (indices into `blocks`).
    pub range: [u64; 2],
    /// Photons: paths of the whole run; images: blocks of the whole run.
    pub total: u64,
    /// Images: every block of the whole run (in `unit`), in the order they are added.
    #[serde(default)]
    pub blocks: Vec<[u64; 2]>,
    /// Images: the layers, in the order of each block's planes.
    #[serde(default)]
    pub layers: Vec<String>,
    /// Photons: the photon files (map kind names; the file is `<kind>.photons`).
    #[serde(default)]
    pub sets: Vec<String>,
    /// Photons: paths this shard emitted; images: samples per pixel or passes it rendered.
    pub count: u64,
    /// Seconds the shard's work took.
    pub seconds: f64,
}

/// Where a shard goes without `--out`: `out/shards/<scene dir>-<stem>-<what>-<I>-of-<N>`.
pub fn default_out(scene: &Path, what: &str, shard: ShardId) -> PathBuf {
    let run = crate::output::default_out(scene, what);
    let name = run.file_name().map(|n| n.to_string_lossy().into_owned());
    PathBuf::from("out").join("shards").join(format!(
        "{}-{}-of-{}",
        name.unwrap_or_default(),
        shard.index,
        shard.count
    ))
}

fn hex(v: u64) -> String {
    format!("{v:016x}")
}

/// A fresh temporary directory beside `out`, after refusing an `out` that is something
/// other than a shard (a shard is replaced whole: a requeued task writes its shard again).
fn start(out: &Path) -> Result<PathBuf, String> {
    if out.exists() && !out.join(MANIFEST).is_file() {
        let empty = std::fs::read_dir(out).is_ok_and(|mut d| d.next().is_none());
        if !empty {
            return Err(format!(
                "{}: exists and is not a shard directory (no {MANIFEST}); choose another --out",
                out.display()
            ));
        }
    }
    let name = out
        .file_name()
        .ok_or_else(|| format!("{}: --out needs a directory name", out.display()))?;
    let parent = match out.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    let tmp = parent.join(format!(
        ".{}.tmp-{}",
        name.to_string_lossy(),
        std::process::id()
    ));
    let _ = std::fs::remove_dir_all(&tmp);
    std::fs::create_dir_all(&tmp).map_err(|e| format!("{}: cannot create: {e}", tmp.display()))?;
    Ok(tmp)
}

/// Writes the manifest last into `tmp`, then renames `tmp` to `out` (an old shard there is
/// moved aside first and removed after).
fn publish(tmp: &Path, out: &Path, m: &Manifest) -> Result<(), String> {
    let text = serde_json::to_string_pretty(m).map_err(|e| e.to_string())? + "\n";
    film::write_atomic(&tmp.join(MANIFEST), text.as_bytes()).map_err(|e| e.to_string())?;
    let old = tmp.with_extension("old");
    if out.exists() {
        std::fs::rename(out, &old)
            .map_err(|e| format!("{}: cannot replace: {e}", out.display()))?;
    }
    std::fs::rename(tmp, out)
        .map_err(|e| format!("{}: cannot rename into place: {e}", out.display()))?;
    let _ = std::fs::remove_dir_all(&old);
    Ok(())
}

/// `trace --shard I/N`: traces the shard's photon paths of the run `overrides` describe into
/// `out` (a shard directory).
pub fn trace(
    scene: &Scene,
    overrides: &Overrides,
    shard: ShardId,
    out: &Path,
    threads: Option<usize>,
) -> Result<Manifest, String> {
    let settings = Settings::new(scene, overrides)?;
    let params = &settings.emit;
    let threads = threads.unwrap_or_else(rayon::current_num_threads).max(1);
    let plan = emit::Plan::for_scene(scene, params)
        .map_err(|e| format!("{}: {e}", scene.path.display()))?;
    let key = CacheKey::new(scene, params);
    let kinds = photon_cache::planned_kinds(&plan);
    let range = shard.range(params.photons);
    let tmp = start(out)?;
    let files: Vec<(MapKind, PathBuf)> = kinds
        .iter()
        .map(|&k| (k, tmp.join(format!("{}.photons", k.name()))))
        .collect();
    let t0 = std::time::Instant::now();
    let progress = Progress::new("trace shard", range.end - range.start, "photons");
    let mut store = StoreSink::create(&files, &|k| key.header(scene, k))?;
    let a = range.start;
    let done = flow::run_chunks(
        range.end - range.start,
        &PipelineOptions::new(threads),
        &|r| emit::trace_range(scene, params, &plan, a + r.start..a + r.end),
        &mut |traced| {
            let traced = std::sync::Arc::new(traced);
            store.consume(&traced)?;
            progress.inc(traced.emitted);
            Ok(())
        },
    );
    if let Err(e) = done {
        let _ = std::fs::remove_dir_all(&tmp);
        return Err(e);
    }
    // Each file's header counts the shard's paths; its photons carry 1/P of the whole run.
    store.finish(range.end - range.start)?;
    progress.finish();
    let m = Manifest {
        photonflow_shard: VERSION,
        what: "photons".into(),
        method: None,
        scene: scene.path.display().to_string(),
        scene_hash: hex(key.scene_hash),
        seed: scene.seed(),
        params_hash: hex(key.params_hash),
        shard: shard.to_string(),
        unit: "photon paths".into(),
        range: [range.start, range.end],
        total: params.photons,
        blocks: Vec::new(),
        layers: Vec::new(),
        sets: kinds.iter().map(|k| k.name().to_string()).collect(),
        count: range.end - range.start,
        seconds: t0.elapsed().as_secs_f64(),
    };
    publish(&tmp, out, &m)?;
    Ok(m)
}

/// `render --shard I/N`: renders the shard's blocks of the run `run` describes into `out`.
pub fn render(run: &Run, shard: ShardId, out: &Path) -> Result<Manifest, String> {
    let (scene, settings) = (run.scene, run.settings);
    let method = settings.method;
    let blocks_fn = methods::spec(method)
        .blocks
        .map_err(|why| format!("--shard cannot split `{method}`: {why}"))?;
    if settings.time.is_some() {
        return Err(
            "--shard with --time: a time budget makes the work depend on the machine; give \
             the full budget (--spp or --passes) instead"
                .into(),
        );
    }
    let resolved = settings.resolved_scene(scene)?;
    let scene_text = toml::to_string(&resolved).map_err(|e| {
        format!(
            "{}: the resolved scene does not serialise: {e}",
            scene.path.display()
        )
    })?;
    let mut b = blocks_fn(run);
    let total = b.blocks.len() as u64;
    let mine = shard.blocks(&b.blocks, b.blocks.last().map_or(0, |r| r.end));
    let layers = b.acc.layer_names();
    let tmp = start(out)?;
    let t0 = std::time::Instant::now();
    let (w, h) = (scene.camera.width as usize, scene.camera.height as usize);
    let mut planes = Vec::new();
    let mut count = 0;
    let work: u64 = b.blocks[mine.clone()].iter().map(|r| r.end - r.start).sum();
    let progress = Progress::new(&format!("{method} shard {shard}"), work, b.unit);
    for r in &b.blocks[mine.clone()] {
        let sums = b.acc.block(r.clone(), &|n| progress.inc(n))?;
        count += r.end - r.start;
        planes.extend(
            sums.into_iter()
                .map(|p| p.into_iter().map(|v| v.to_array()).collect::<Vec<_>>()),
        );
    }
    progress.finish();
    let sums = film::Sums {
        width: w,
        height: h,
        planes,
    };
    film::write_sums(&tmp.join(SUMS), &sums).map_err(|e| e.to_string())?;
    film::write_atomic(&tmp.join("scene.toml"), scene_text.as_bytes())
        .map_err(|e| e.to_string())?;
    let m = Manifest {
        photonflow_shard: VERSION,
        what: "image".into(),
        method: Some(method.name()),
        scene: scene.path.display().to_string(),
        scene_hash: hex(scene.view_hash),
        seed: scene.seed(),
        params_hash: hex(settings.hash(scene)),
        shard: shard.to_string(),
        unit: b.unit.into(),
        range: [mine.start as u64, mine.end as u64],
        total,
        blocks: b.blocks.iter().map(|r| [r.start, r.end]).collect(),
        layers,
        sets: Vec::new(),
        count,
        seconds: t0.elapsed().as_secs_f64(),
    };
    publish(&tmp, out, &m)?;
    Ok(m)
}

/// A shard directory given to `merge`, read and checked on its own.
struct Input {
    dir: PathBuf,
    m: Manifest,
    shard: ShardId,
}

fn read_input(p: &Path) -> Result<Input, String> {
    let dir = if p.file_name().is_some_and(|n| n == MANIFEST) {
        p.parent().unwrap_or(Path::new(".")).to_path_buf()
    } else {
        p.to_path_buf()
    };
    let path = dir.join(MANIFEST);
    if !dir.is_dir() {
        return Err(format!("{}: not a shard directory", dir.display()));
    }
    if std::fs::metadata(&path).is_ok_and(|m| !m.is_file()) {
        return Err(format!("{}: not a regular file", path.display()));
    }
    let text = std::fs::read_to_string(&path).map_err(|e| {
        format!(
            "{}: cannot read ({e}): not a complete shard (its task may still run or have failed)",
            path.display()
        )
    })?;
    let m: Manifest = serde_json::from_str(&text)
        .map_err(|e| format!("{}: not a shard manifest: {e}", path.display()))?;
    if m.photonflow_shard != VERSION {
        return Err(format!(
            "{}: shard format {}, this photonflow reads {VERSION}",
            path.display(),
            m.photonflow_shard
        ));
    }
    let shard = ShardId::parse(&m.shard).map_err(|e| format!("{}: shard {e}", path.display()))?;
    if m.range[0] > m.range[1] || m.range[1] > m.total {
        return Err(format!(
            "{}: range {:?} lies outside 0..{}",
            path.display(),
            m.range,
            m.total
        ));
    }
    Ok(Input { dir, m, shard })
}

/// `merge`: the shards `inputs` put back together into `out`: photon sets into `out` as a
/// cache directory, images into `out` as a run directory. Everything is read and checked
/// before anything is written.
pub fn merge(inputs: &[PathBuf], out: &Path) -> Result<String, String> {
    let Some(first) = inputs.first() else {
        return Err("merge: no inputs given".into());
    };
    let mut all = Vec::with_capacity(inputs.len());
    for p in inputs {
        all.push(read_input(p)?);
    }
    let a = &all[0];
    // One run: every shard must agree with the first on what it is a part of.
    for b in &all[1..] {
        let name = b.dir.join(MANIFEST);
        let differs = |what: &str, x: &dyn std::fmt::Display, y: &dyn std::fmt::Display| {
            format!(
                "{}: {what} {x}, but {} has {y}: shards of another run",
                name.display(),
                a.dir.join(MANIFEST).display()
            )
        };
        if b.m.what != a.m.what {
            return Err(differs("holds", &b.m.what, &a.m.what));
        }
        if b.m.method != a.m.method {
            let f = |m: &Option<String>| m.clone().unwrap_or_default();
            return Err(differs("method", &f(&b.m.method), &f(&a.m.method)));
        }
        if b.m.seed != a.m.seed {
            return Err(differs("seed", &b.m.seed, &a.m.seed));
        }
        if b.m.scene_hash != a.m.scene_hash {
            return Err(differs("scene hash", &b.m.scene_hash, &a.m.scene_hash));
        }
        if b.m.params_hash != a.m.params_hash
            || b.m.total != a.m.total
            || b.m.blocks != a.m.blocks
            || b.m.layers != a.m.layers
            || b.m.sets != a.m.sets
        {
            return Err(differs(
                "parameter hash",
                &b.m.params_hash,
                &a.m.params_hash,
            ));
        }
    }
    if out.exists() && all.iter().any(|i| same_dir(&i.dir, out)) {
        return Err(format!(
            "{}: the output directory is an input; choose another --out",
            out.display()
        ));
    }
    let parts: Vec<Part> = all
        .iter()
        .map(|i| Part {
            label: i.dir.join(MANIFEST).display().to_string(),
            shard: i.shard,
            range: i.m.range[0]..i.m.range[1],
        })
        .collect();
    match a.m.what.as_str() {
        "photons" => {
            let total = a.m.total;
            let order = cover(&parts, total, &|s| s.range(total))?;
            merge_photons(&all, &order, out)
        }
        "image" => {
            let blocks: Vec<std::ops::Range<u64>> = a.m.blocks.iter().map(|b| b[0]..b[1]).collect();
            let end = blocks.last().map_or(0, |r| r.end);
            let expect = |s: ShardId| {
                let r = s.blocks(&blocks, end);
                r.start as u64..r.end as u64
            };
            let order = cover(&parts, a.m.total, &expect)?;
            merge_image(&all, &order, out)
        }
        other => Err(format!(
            "{}: holds `{other}`, neither photons nor an image",
            first.display()
        )),
    }
}

fn same_dir(a: &Path, b: &Path) -> bool {
    match (std::fs::canonicalize(a), std::fs::canonicalize(b)) {
        (Ok(x), Ok(y)) => x == y,
        _ => false,
    }
}

fn parse_hex(s: &str, file: &Path) -> Result<u64, String> {
    u64::from_str_radix(s, 16).map_err(|_| format!("{}: `{s}` is not a hash", file.display()))
}

fn merge_photons(all: &[Input], order: &[usize], out: &Path) -> Result<String, String> {
    let a = &all[0];
    let m0 = a.dir.join(MANIFEST);
    let (scene_hash, params_hash) = (
        parse_hex(&a.m.scene_hash, &m0)?,
        parse_hex(&a.m.params_hash, &m0)?,
    );
    let mut kinds = Vec::new();
    for name in &a.m.sets {
        let k = MapKind::ALL
            .into_iter()
            .find(|k| k.name() == name)
            .ok_or_else(|| format!("{}: unknown photon set `{name}`", m0.display()))?;
        kinds.push(k);
    }
    // Every file mapped (every chunk's checksum checked) and its header held against its
    // manifest before the first byte of output.
    let mut stores: Vec<Vec<MappedStore>> = Vec::new();
    let mut params = None;
    for &i in order {
        let inp = &all[i];
        let mut row = Vec::new();
        for &k in &kinds {
            let path = inp.dir.join(format!("{}.photons", k.name()));
            let s = MappedStore::open(&path).map_err(|e| e.to_string())?;
            let h = s.header();
            let problem = if h.kind != k {
                Some(format!("holds the {} set", h.kind.name()))
            } else if h.seed != inp.m.seed {
                Some(format!(
                    "seed {}, its shard.json says {}",
                    h.seed, inp.m.seed
                ))
            } else if h.scene_hash != scene_hash || h.params_hash != params_hash {
                Some("was traced for another scene or parameters than its shard.json says".into())
            } else if h.emitted != inp.m.count || inp.m.count != inp.m.range[1] - inp.m.range[0] {
                Some(format!(
                    "counts {} emitted paths, its shard covers {}",
                    h.emitted,
                    inp.m.range[1] - inp.m.range[0]
                ))
            } else {
                None
            };
            if let Some(p) = problem {
                return Err(format!("{}: {p}", path.display()));
            }
            match &params {
                None => params = Some(h.params.clone()),
                Some(p) if *p != h.params => {
                    return Err(format!(
                        "{}: emission parameters differ from the other shards'",
                        path.display()
                    ));
                }
                Some(_) => {}
            }
            row.push(s);
        }
        stores.push(row);
    }
    let key = CacheKey {
        scene_hash,
        params_hash,
        params_json: params.unwrap_or_default(),
    };
    std::fs::create_dir_all(out)
        .map_err(|e| format!("{}: cannot create cache directory: {e}", out.display()))?;
    let mut written = Vec::new();
    let mut stored = 0;
    for (j, &k) in kinds.iter().enumerate() {
        let path = key.file(out, k);
        let header = Header::new(
            k,
            a.m.seed,
            scene_hash,
            params_hash,
            key.params_json.clone(),
        );
        let mut w = StoreWriter::create(&path, header).map_err(|e| e.to_string())?;
        for row in &stores {
            for chunk in row[j].chunks() {
                w.write(chunk).map_err(|e| e.to_string())?;
            }
        }
        stored += w.stored();
        w.finish(a.m.total).map_err(|e| e.to_string())?;
        written.push(path.display().to_string());
    }
    Ok(format!(
        "merged {} shards: {} photon paths, {stored} photons into {}",
        order.len(),
        a.m.total,
        written.join(", ")
    ))
}

fn merge_image(all: &[Input], order: &[usize], out: &Path) -> Result<String, String> {
    let a = &all[0];
    let scene_file = a.dir.join("scene.toml");
    // The shard's resolved scene: its settings are the run's, flags and all.
    let scene = Scene::load(&scene_file).map_err(|e| e.to_string())?;
    let settings = Settings::new(&scene, &Overrides::default())?;
    let m0 = a.dir.join(MANIFEST);
    if hex(scene.view_hash) != a.m.scene_hash
        || scene.seed() != a.m.seed
        || hex(settings.hash(&scene)) != a.m.params_hash
    {
        return Err(format!(
            "{}: the scene (or a file it names) changed since {} was rendered",
            scene_file.display(),
            m0.display()
        ));
    }
    let run = Run {
        scene: &scene,
        settings: &settings,
        cache: Path::new("."),
        photons: methods::Photons::CacheOnly,
        threads: Some(1),
    };
    let blocks_fn = methods::spec(settings.method)
        .blocks
        .map_err(|why| format!("{}: {why}", m0.display()))?;
    let mut b = blocks_fn(&run);
    let blocks: Vec<[u64; 2]> = b.blocks.iter().map(|r| [r.start, r.end]).collect();
    if blocks != a.m.blocks || b.acc.layer_names() != a.m.layers {
        return Err(format!(
            "{}: its blocks or layers are not those this photonflow renders for its scene",
            m0.display()
        ));
    }
    let (w, h) = (scene.camera.width as usize, scene.camera.height as usize);
    let nl = a.m.layers.len();
    // Read and check every shard's sums before any output; added one shard at a time.
    let mut sums = Vec::with_capacity(order.len());
    for &i in order {
        let inp = &all[i];
        let path = inp.dir.join(SUMS);
        let s = film::read_sums(&path).map_err(|e| e.to_string())?;
        let nb = (inp.m.range[1] - inp.m.range[0]) as usize;
        if (s.width, s.height, s.planes.len()) != (w, h, nb * nl) {
            return Err(format!(
                "{}: {}x{} in {} planes, but the shard's {nb} blocks of {nl} layers of the \
                 {w}x{h} view need {}",
                path.display(),
                s.width,
                s.height,
                s.planes.len(),
                nb * nl
            ));
        }
        sums.push(s);
    }
    let mut seconds = 0.0;
    for (&i, s) in order.iter().zip(sums) {
        let inp = &all[i];
        seconds += inp.m.seconds;
        let first = inp.m.range[0] as usize;
        let mut planes = s.planes.into_iter();
        for r in &b.blocks[first..inp.m.range[1] as usize] {
            let block: Vec<Vec<DVec3>> = planes
                .by_ref()
                .take(nl)
                .map(|p| p.into_iter().map(DVec3::from_array).collect())
                .collect();
            b.acc.add(&block, r.end - r.start);
        }
    }
    let rendered = b.acc.finish(seconds);
    let label = settings.method.name();
    crate::output::write(
        &scene,
        &settings,
        &rendered,
        &crate::output::OutputOptions {
            out,
            exposure: 0.0,
            reference: None,
            label: &label,
            threads: 0,
            seconds,
        },
    )?;
    Ok(format!(
        "merged {} shards of {label} ({} {}) into {}/image.{{exr,png,json}}, layers/, scene.toml",
        order.len(),
        b.blocks.last().map_or(0, |r| r.end),
        a.m.unit,
        out.display()
    ))
}
