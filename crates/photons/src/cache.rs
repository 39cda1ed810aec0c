//! The photon cache: plans the sets a scene needs, reuses them when an identical run made
//! them, else traces them through the channel pipeline into photon files; opens them again,
//! checked against their key, for whatever reads them.

use crate::sinks::{self, Sink, StoreSink};
use emit::{EmitParams, Plan};
use flow::{PipelineOptions, Progress};
use scene::Scene;
use std::path::{Path, PathBuf};
use store::{Expect, Header, MapKind, MappedStore};

/// Bump when `emit` changes which photons it stores or what they carry.
pub const PHOTON_TRACER_VERSION: u32 = 1;

/// Where the photon sets of one (scene, parameters) pair live in a cache directory: keyed by
/// `Scene::photon_hash` (files, seed, geometry, materials; not the camera or `[estimate]`),
/// the emission parameters and the tracer version.
pub struct CacheKey {
    pub scene_hash: u64,
    pub params_hash: u64,
    pub params_json: String,
}

impl CacheKey {
    pub fn new(scene: &Scene, params: &EmitParams) -> CacheKey {
        let params_json = serde_json::to_string(params).expect("EmitParams serialises");
        // The tracer's version joins the parameters: a change to how photons are traced
        // must not serve photon files made by the old rules.
        let keyed = format!("v{PHOTON_TRACER_VERSION} {params_json}");
        CacheKey {
            scene_hash: scene.photon_hash,
            params_hash: scene::fnv1a64(keyed.as_bytes()),
            params_json,
        }
    }

    pub fn file(&self, dir: &Path, kind: MapKind) -> PathBuf {
        dir.join(format!(
            "{:016x}-{:016x}-{}.photons",
            self.scene_hash,
            self.params_hash,
            kind.name()
        ))
    }

    pub fn plan_file(&self, dir: &Path) -> PathBuf {
        dir.join(format!(
            "{:016x}-{:016x}-plan.txt",
            self.scene_hash, self.params_hash
        ))
    }

    pub fn expect(&self, kind: MapKind) -> Expect {
        Expect {
            scene_hash: self.scene_hash,
            params_hash: self.params_hash,
            kind,
        }
    }

    /// The header a new photon file of `kind` starts with.
    pub fn header(&self, scene: &Scene, kind: MapKind) -> Header {
        Header::new(
            kind,
            scene.seed(),
            self.scene_hash,
            self.params_hash,
            self.params_json.clone(),
        )
    }
}

/// The sets a plan asks for, in [`MapKind::ALL`] order.
pub fn planned_kinds(plan: &Plan) -> Vec<MapKind> {
    MapKind::ALL
        .into_iter()
        .filter(|k| match k {
            MapKind::Global => plan.global,
            MapKind::Caustic => plan.caustic,
        })
        .collect()
}

/// Whether every planned set is in the cache, intact and made for exactly this key.
/// A file that exists but fails to open is reported and traced anew.
pub fn cached(dir: &Path, key: &CacheKey, kinds: &[MapKind]) -> bool {
    kinds.iter().all(|&k| {
        let path = key.file(dir, k);
        if !path.exists() {
            return false;
        }
        // Mapping checks every chunk's checksum (several GB/s), so a damaged file is traced
        // anew instead of failing later in the estimate.
        match MappedStore::open(&path).and_then(|r| r.check(&key.expect(k))) {
            Ok(()) => true,
            Err(e) => {
                eprintln!("warning: cached photon set unusable, tracing anew: {e}");
                false
            }
        }
    })
}

/// What the photon stage did.
pub struct TraceOutput {
    pub plan: Plan,
    pub key: CacheKey,
    pub files: Vec<(MapKind, PathBuf)>,
    /// The sets were in the cache: nothing was traced.
    pub reused: bool,
    pub seconds: f64,
}

/// Plans the sets, then reuses them from `dir` or traces them there (always when `force`).
pub fn trace(
    scene: &Scene,
    params: &EmitParams,
    dir: &Path,
    threads: usize,
    force: bool,
) -> Result<TraceOutput, String> {
    if threads == 0 {
        return Err("--threads must be at least 1".into());
    }
    let plan =
        Plan::for_scene(scene, params).map_err(|e| format!("{}: {e}", scene.path.display()))?;
    print!("{plan}");
    let key = CacheKey::new(scene, params);
    let kinds = planned_kinds(&plan);
    let files: Vec<(MapKind, PathBuf)> = kinds.iter().map(|&k| (k, key.file(dir, k))).collect();
    std::fs::create_dir_all(dir)
        .map_err(|e| format!("{}: cannot create cache directory: {e}", dir.display()))?;
    // A run killed mid-write (kill -9) left its temp files: no run will finish or read them.
    for stale in temps::remove_stale(dir) {
        eprintln!("{stale}");
    }
    let write_plan = || {
        film::write_atomic(&key.plan_file(dir), plan.to_string().as_bytes())
            .map_err(|e| e.to_string())
    };
    if !force && cached(dir, &key, &kinds) {
        write_plan()?;
        println!("reused cached photon sets (no tracing):");
        for (_, f) in &files {
            println!("  {}", f.display());
        }
        return Ok(TraceOutput {
            plan,
            key,
            files,
            reused: true,
            seconds: 0.0,
        });
    }
    // Refused runs write nothing, the plan included.
    check_space(scene, params, &plan, dir)?;
    write_plan()?;
    let progress = Progress::new("trace", params.photons, "photons");
    let mut store = StoreSink::create(&files, &|k| key.header(scene, k))?;
    let stats = sinks::run(
        scene,
        params,
        &plan,
        &mut [&mut store as &mut dyn Sink],
        &PipelineOptions::new(threads),
        &progress,
    )?;
    let stored = store.stored().clone();
    store.finish(params.photons)?;
    progress.finish();
    let bytes: u64 = files
        .iter()
        .map(|(_, f)| std::fs::metadata(f).map(|m| m.len()).unwrap_or(0))
        .sum();
    let all: u64 = stored.iter().map(|(_, n)| n).sum();
    println!(
        "traced {} photon paths in {:.2} s ({:.3} M paths/s on {threads} threads, at most {} chunks in memory); stored {} global, {} caustic ({:.1} bytes/photon)",
        stats.total,
        stats.seconds,
        stats.total as f64 / stats.seconds / 1e6,
        stats.max_in_flight,
        stored[MapKind::Global],
        stored[MapKind::Caustic],
        bytes as f64 / all.max(1) as f64
    );
    for (_, f) in &files {
        println!("  {}", f.display());
    }
    Ok(TraceOutput {
        plan,
        key,
        files,
        reused: false,
        seconds: stats.seconds,
    })
}

/// Photon paths of the pilot that measures photons stored per path before a trace.
const PILOT_PATHS: u64 = 4096;

/// Refuses a trace whose photon files could not fit on the cache's file system, before any
/// work: the first [`PILOT_PATHS`] paths of the run are traced to measure the photons stored
/// per path, and the files' size projected from it (32-byte records; headers are noise).
/// A run of 1e12 paths used to start tracing and fail days later, or fill the disk.
fn check_space(scene: &Scene, params: &EmitParams, plan: &Plan, dir: &Path) -> Result<(), String> {
    let Some(free) = store::free_space(dir) else {
        return Ok(());
    };
    let pilot = params.photons.min(PILOT_PATHS);
    let stored = emit::trace_range(scene, params, plan, 0..pilot).stored() as f64;
    let per_path = stored / pilot as f64;
    let record = std::mem::size_of::<store::Photon>() as f64;
    let bytes = params.photons as f64 * per_path * record;
    if bytes <= free as f64 {
        return Ok(());
    }
    let limit = (free as f64 / (per_path * record)).floor();
    Err(format!(
        "{}: {} photon paths would write about {:.3e} bytes of photon files ({per_path:.2} \
         photons per path over the first {pilot} paths, {record} bytes each), but {} has \
         {free} bytes free: at most about {limit:.3e} paths fit",
        scene.path.display(),
        params.photons,
        bytes,
        dir.display()
    ))
}

/// Opens the cached set `kind` of `key` in `dir`, every chunk's checksum and the header's key
/// checked (never traces: a missing set is an error that says to run `trace`).
pub fn open(dir: &Path, key: &CacheKey, kind: MapKind) -> Result<MappedStore, String> {
    let path = key.file(dir, kind);
    if !path.exists() {
        return Err(format!(
            "{}: no cached photon set for this scene and these parameters; run `trace` first",
            path.display()
        ));
    }
    let store = MappedStore::open(&path).map_err(|e| e.to_string())?;
    store.check(&key.expect(kind)).map_err(|e| e.to_string())?;
    Ok(store)
}
