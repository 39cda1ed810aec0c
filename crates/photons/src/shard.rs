//! Shards of one run, the directories they live in, and the merge of photon shards. Photon `i`
//! draws from the stream `(seed, i)` and pixel sample `s` from its own, so a run split into
//! index ranges can run anywhere and be put back together exactly:
//!
//! - `trace --shard I/N` traces photon paths `[I P / N, (I + 1) P / N)` of a run of `P` (powers
//!   already divided by `P`), into photon files whose header counts the shard's paths;
//!   merging concatenates them in shard order and writes the photon file the one-machine
//!   `trace` writes, byte for byte.
//! - image shards (`render --shard I/N`) are `render`'s; they share the directory format:
//!   a shard is a directory holding its results and `shard.json` ([`Manifest`]: scene hash,
//!   seed, parameter hash, shard `I/N`, range and counts), built under a temporary name and
//!   renamed into place, so a shard directory is complete or absent.

use crate::cache::{self, CacheKey};
use crate::sinks::StoreSink;
pub use composite::shards::ShardId;
use composite::shards::{Part, cover};
use emit::EmitParams;
use flow::{PipelineOptions, Progress};
use scene::Scene;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};
use store::{Header, MapKind, MappedStore, StoreWriter};
use temps::Temp;

/// The file that describes a shard directory.
pub const MANIFEST: &str = "shard.json";
pub const VERSION: u32 = 1;

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

pub fn hex(v: u64) -> String {
    format!("{v:016x}")
}

/// A fresh staging directory beside `out`, after refusing an `out` that is something other
/// than a shard (a shard is replaced whole: a requeued task writes its shard again). The
/// staging directories of `out` whose process is gone (kill -9) are removed first.
pub fn start(out: &Path) -> Result<Temp, String> {
    if out.exists() && !out.join(MANIFEST).is_file() {
        let empty = std::fs::read_dir(out).is_ok_and(|mut d| d.next().is_none());
        if !empty {
            return Err(format!(
                "{}: exists and is not a shard directory (no {MANIFEST}); choose another --out",
                out.display()
            ));
        }
    }
    if out.file_name().is_none() {
        return Err(format!("{}: --out needs a directory name", out.display()));
    }
    let parent = match out.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    std::fs::create_dir_all(parent)
        .map_err(|e| format!("{}: cannot create: {e}", parent.display()))?;
    for stale in temps::remove_stale_of(out) {
        eprintln!("{stale}");
    }
    Temp::dir(out).map_err(|e| {
        format!(
            "{}: cannot create a staging directory beside it: {e}",
            out.display()
        )
    })
}

/// Writes the manifest last into `tmp`, then renames `tmp` to `out`. An old shard there is
/// moved aside first and removed after; as a temp itself, it goes too if a signal comes
/// between the renames.
pub fn publish(tmp: Temp, out: &Path, m: &Manifest) -> Result<(), String> {
    let text = serde_json::to_string_pretty(m).map_err(|e| e.to_string())? + "\n";
    film::write_atomic(&tmp.path().join(MANIFEST), text.as_bytes()).map_err(|e| e.to_string())?;
    let old = if out.exists() {
        Some(Temp::aside(out).map_err(|e| format!("{}: cannot replace: {e}", out.display()))?)
    } else {
        None
    };
    if let Err(e) = tmp.publish(out) {
        // A failed replacement keeps the old shard.
        if let Some(old) = old {
            let _ = old.publish(out);
        }
        return Err(format!("{}: cannot rename into place: {e}", out.display()));
    }
    drop(old);
    Ok(())
}

/// `trace --shard I/N`: traces the shard's photon paths of a run of `params` into `out` (a
/// shard directory).
pub fn trace(
    scene: &Scene,
    params: &EmitParams,
    shard: ShardId,
    out: &Path,
    threads: usize,
) -> Result<Manifest, String> {
    let threads = threads.max(1);
    // Shards are ranges of photon paths: with more shards than paths some cover nothing,
    // and publishing those as finished work hides a mistyped N.
    if u64::from(shard.count) > params.photons {
        return Err(format!(
            "--shard {shard}: {} shards of a run of {} photon paths would leave shards with no \
             path; N must be at most {}",
            shard.count, params.photons, params.photons
        ));
    }
    let plan = emit::Plan::for_scene(scene, params)
        .map_err(|e| format!("{}: {e}", scene.path.display()))?;
    let key = CacheKey::new(scene, params);
    let kinds = cache::planned_kinds(&plan);
    let range = shard.range(params.photons);
    let tmp = start(out)?;
    let files: Vec<(MapKind, PathBuf)> = kinds
        .iter()
        .map(|&k| (k, tmp.path().join(format!("{}.photons", k.name()))))
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
            flow::Sink::consume(&mut store, &traced)?;
            progress.inc(traced.emitted);
            Ok(())
        },
    );
    // On failure `tmp` is dropped, and with it what was written.
    done?;
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
    publish(tmp, out, &m)?;
    Ok(m)
}

/// A shard directory given to `merge`, read and checked on its own.
pub struct Input {
    pub dir: PathBuf,
    pub m: Manifest,
    pub shard: ShardId,
}

pub fn read_input(p: &Path) -> Result<Input, String> {
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
    check_count(&m).map_err(|e| format!("{}: {e}", path.display()))?;
    Ok(Input { dir, m, shard })
}

/// A manifest's `count` is what its range holds (photon paths, or the samples or passes of
/// its blocks): a merge weighs the shard by it, so a forged count would weigh it wrongly.
fn check_count(m: &Manifest) -> Result<(), String> {
    let [a, b] = m.range;
    let (holds, what) = match m.what.as_str() {
        "photons" => (b - a, format!("its range {a}..{b} holds")),
        "image" => {
            if m.total != m.blocks.len() as u64 {
                return Err(format!(
                    "total {} blocks, but it lists {}",
                    m.total,
                    m.blocks.len()
                ));
            }
            // In range: a <= b <= total, checked by the caller.
            let mine = m.blocks.get(a as usize..b as usize).unwrap_or_default();
            let n = mine
                .iter()
                .map(|r| r[1].saturating_sub(r[0]))
                .fold(0u64, u64::saturating_add);
            (n, format!("its blocks {a}..{b} hold"))
        }
        // `merge` refuses what it does not know, naming it.
        _ => return Ok(()),
    };
    if m.count != holds {
        return Err(format!("count {}, but {what} {holds} {}", m.count, m.unit));
    }
    Ok(())
}

/// The shard directories `inputs`, each read and checked, and checked to be parts of one run
/// (what they hold, method, seed, scene and parameters), with `out` not among them; and the
/// parts they cover, for `composite::shards::cover`.
pub fn read_all(inputs: &[PathBuf], out: &Path) -> Result<(Vec<Input>, Vec<Part>), String> {
    if inputs.is_empty() {
        return Err("merge: no inputs given".into());
    }
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
    // Writing into a shard (or over a directory holding one) would change an input of this
    // very merge, or of the next one.
    if let Some(o) = resolve(out) {
        for i in &all {
            let Some(d) = resolve(&i.dir) else { continue };
            let problem = if o == d {
                "is an input"
            } else if o.starts_with(&d) {
                "lies inside the input shard"
            } else if d.starts_with(&o) {
                "contains the input shard"
            } else {
                continue;
            };
            let shard = if o == d {
                String::new()
            } else {
                format!(" {}", i.dir.display())
            };
            return Err(format!(
                "{}: the output directory {problem}{shard}; choose another --out",
                out.display()
            ));
        }
    }
    let parts: Vec<Part> = all
        .iter()
        .map(|i| Part {
            label: i.dir.join(MANIFEST).display().to_string(),
            shard: i.shard,
            range: i.m.range[0]..i.m.range[1],
        })
        .collect();
    Ok((all, parts))
}

/// Merges photon shards (`read_all`'s) into `out` as a cache directory.
pub fn merge_photons(all: &[Input], parts: &[Part], out: &Path) -> Result<String, String> {
    let total = all.first().map_or(0, |a| a.m.total);
    let order = cover(parts, total, &|s| s.range(total))?;
    merge_photon_files(all, &order, out)
}

/// `p` made absolute with its symbolic links and `..` resolved, also when it does not exist
/// yet (an output directory): its deepest existing ancestor canonicalised, the rest appended.
/// `None` if not even that resolves.
fn resolve(p: &Path) -> Option<PathBuf> {
    use std::path::Component;
    let abs = std::path::absolute(p).ok()?;
    let parts: Vec<Component> = abs.components().collect();
    // The longest prefix that exists (the root always does).
    let (k, mut real) = (0..=parts.len()).rev().find_map(|k| {
        let prefix: PathBuf = parts.get(..k)?.iter().collect();
        std::fs::canonicalize(prefix).ok().map(|r| (k, r))
    })?;
    // What is left does not exist: a `..` in it climbs lexically.
    for c in parts.get(k..)? {
        match c {
            Component::ParentDir => {
                real.pop();
            }
            Component::Normal(n) => real.push(n),
            _ => {}
        }
    }
    Some(real)
}

fn parse_hex(s: &str, file: &Path) -> Result<u64, String> {
    u64::from_str_radix(s, 16).map_err(|_| format!("{}: `{s}` is not a hash", file.display()))
}

fn merge_photon_files(all: &[Input], order: &[usize], out: &Path) -> Result<String, String> {
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
            } else if h.emitted != inp.m.count {
                // `read_input` held the manifest's count against its range already.
                Some(format!(
                    "counts {} emitted paths, but its shard.json's count is {}",
                    h.emitted, inp.m.count
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
    // A merge killed mid-write (kill -9) left its temp files: no run will finish or read them.
    for stale in temps::remove_stale(out) {
        eprintln!("{stale}");
    }
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
