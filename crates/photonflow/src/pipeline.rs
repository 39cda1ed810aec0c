//! The photon pipeline: emission workers → bounded crossbeam channel → one writer stage that
//! puts chunks back in index order, streams them into photon files and forwards them to an
//! optional consumer. Memory stays flat however many photons are traced: a worker may only
//! start a chunk it holds a *ticket* for, and tickets are issued as chunks are written, so at
//! most `window` chunks exist at any time (traced, queued or waiting for their turn).

use crate::progress::Progress;
use crossbeam_channel::{Receiver, Sender, bounded};
use emit::{EmitParams, Plan, Traced};
use scene::Scene;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use store::{Expect, Header, MapKind, MappedStore, StoreWriter};

/// Bump when `emit` changes which photons it stores or what they carry.
pub const PHOTON_TRACER_VERSION: u32 = 1;

/// Where the photon sets of one (scene, parameters) pair live in a cache directory.
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
        let k = match kind {
            MapKind::Global => "global",
            MapKind::Caustic => "caustic",
        };
        dir.join(format!(
            "{:016x}-{:016x}-{k}.photons",
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
}

/// The sets a plan asks for.
pub fn planned_kinds(plan: &Plan) -> Vec<MapKind> {
    let mut v = Vec::new();
    if plan.global {
        v.push(MapKind::Global);
    }
    if plan.caustic {
        v.push(MapKind::Caustic);
    }
    v
}

/// Reads emit parameters from the scene's `[photons]` table.
pub fn emit_params(scene: &Scene) -> Result<EmitParams, String> {
    toml::Value::Table(scene.file.photons.clone())
        .try_into()
        .map_err(|e| format!("{}: [photons]: {e}", scene.path.display()))
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

pub struct TraceStats {
    pub emitted: u64,
    pub stored: [u64; 2],
    pub seconds: f64,
    /// Most chunks alive at once (the backpressure bound, tested).
    pub max_in_flight: usize,
}

/// Options of one pipeline run.
pub struct PipelineOptions {
    pub threads: usize,
    /// Photon paths per chunk (the unit of work and of memory).
    pub chunk: u64,
    /// Chunks alive at most.
    pub window: usize,
    /// Receives every chunk, in index order, after it is written (a consuming stage).
    pub consumer: Option<Sender<Arc<Traced>>>,
}

impl PipelineOptions {
    pub fn new(threads: usize) -> PipelineOptions {
        PipelineOptions {
            threads: threads.max(1),
            chunk: 16_384,
            window: 2 * threads.max(1) + 2,
            consumer: None,
        }
    }
}

/// Traces `params.photons` paths and writes the planned sets to `files` (one per kind, in
/// `planned_kinds` order), forwarding every chunk, in index order, to `opts.consumer`.
pub fn run(
    scene: &Scene,
    params: &EmitParams,
    plan: &Plan,
    key: &CacheKey,
    files: &[(MapKind, PathBuf)],
    opts: &PipelineOptions,
    progress: &Progress,
) -> Result<TraceStats, String> {
    let start = std::time::Instant::now();
    let mut writers = Vec::new();
    for (kind, path) in files {
        if let Some(dir) = path.parent() {
            std::fs::create_dir_all(dir)
                .map_err(|e| format!("{}: cannot create cache directory: {e}", dir.display()))?;
        }
        let header = Header::new(
            *kind,
            scene.seed(),
            key.scene_hash,
            key.params_hash,
            key.params_json.clone(),
        );
        writers.push((
            *kind,
            StoreWriter::create(path, header).map_err(|e| e.to_string())?,
        ));
    }
    let ranges: Vec<std::ops::Range<u64>> = emit::chunks(params.photons, opts.chunk).collect();
    let n = ranges.len();
    let window = opts.window.max(1);
    let (ticket_tx, ticket_rx) = bounded::<usize>(window);
    let (tx, rx) = bounded::<(usize, Traced)>(window);
    for t in 0..window.min(n) {
        ticket_tx.send(t).expect("receiver alive");
    }
    let mut max_in_flight = 0;
    let mut stored = [0u64; 2];
    let result = std::thread::scope(|s| -> Result<(), String> {
        // Owned by this closure, so an early error return drops them and every worker wakes
        // (a blocked `send` fails, the ticket loop ends) before the scope joins.
        let (rx, ticket_tx) = (rx, ticket_tx);
        for _ in 0..opts.threads {
            let (ticket_rx, tx) = (ticket_rx.clone(), tx.clone());
            let ranges = &ranges;
            s.spawn(move || worker(scene, params, plan, ranges, ticket_rx, tx));
        }
        drop((ticket_rx, tx));
        let mut pending: BTreeMap<usize, Traced> = BTreeMap::new();
        let mut next = 0;
        while next < n {
            let Ok((i, traced)) = rx.recv() else {
                return Err("a photon worker stopped before its work was done".into());
            };
            pending.insert(i, traced);
            max_in_flight = max_in_flight.max(pending.len() + rx.len());
            while let Some(traced) = pending.remove(&next) {
                for (kind, w) in writers.iter_mut() {
                    let photons = match kind {
                        MapKind::Global => &traced.global,
                        MapKind::Caustic => &traced.caustic,
                    };
                    stored[(*kind == MapKind::Caustic) as usize] += photons.len() as u64;
                    w.write(photons).map_err(|e| e.to_string())?;
                }
                progress.inc(traced.emitted);
                if let Some(c) = &opts.consumer {
                    // A consumer that hung up only loses its copy; the files are still written.
                    let _ = c.send(Arc::new(traced));
                }
                next += 1;
                if next + window - 1 < n {
                    // Tickets are never more than `window`: the channel cannot be full.
                    let _ = ticket_tx.send(next + window - 1);
                }
            }
        }
        drop(ticket_tx);
        Ok(())
    });
    result?;
    for (_, w) in writers {
        w.finish(params.photons).map_err(|e| e.to_string())?;
    }
    Ok(TraceStats {
        emitted: params.photons,
        stored,
        seconds: start.elapsed().as_secs_f64(),
        max_in_flight,
    })
}

fn worker(
    scene: &Scene,
    params: &EmitParams,
    plan: &Plan,
    ranges: &[std::ops::Range<u64>],
    tickets: Receiver<usize>,
    out: Sender<(usize, Traced)>,
) {
    for i in tickets {
        let traced = emit::trace_range(scene, params, plan, ranges[i].clone());
        if out.send((i, traced)).is_err() {
            return; // the writer failed and hung up
        }
    }
}
