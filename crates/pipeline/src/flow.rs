//! The photon pipeline: emission workers → bounded crossbeam channel → one ordering stage
//! that puts chunks back in index order and hands each, in that order, to every [`Sink`]: the
//! photon file writer ([`StoreSink`]) is one consumer, a stage on its own thread behind a
//! channel ([`ChannelSink`]: a splatter, a k-NN builder) is another. Memory stays flat however
//! many photons are traced: a worker may only start a chunk it holds a *ticket* for, and
//! tickets are issued as chunks are consumed, so at most `window` chunks exist at any time
//! (traced, queued or waiting for their turn).

use crate::progress::Progress;
use crossbeam_channel::{Receiver, Sender, bounded};
use emit::{EmitParams, Plan, Traced};
use scene::Scene;
use std::collections::BTreeMap;
use std::path::PathBuf;
use std::sync::Arc;
use store::{Header, MapKind, PerKind, StoreWriter};

/// A consumer of traced chunks. `consume` sees every chunk exactly once, in index order, on
/// the ordering thread; a slow sink slows tracing down (backpressure), it never buffers it.
pub trait Sink {
    fn consume(&mut self, chunk: &Arc<Traced>) -> Result<(), String>;
}

/// Streams the planned sets into photon files (one per kind); [`StoreSink::finish`] records
/// the emitted count and renames them into place.
pub struct StoreSink {
    writers: Vec<(MapKind, StoreWriter)>,
    stored: PerKind<u64>,
}

impl StoreSink {
    /// `files`: one path per planned kind; `header` makes each file's header from its kind.
    pub fn create(
        files: &[(MapKind, PathBuf)],
        header: &dyn Fn(MapKind) -> Header,
    ) -> Result<StoreSink, String> {
        let mut writers = Vec::new();
        for (kind, path) in files {
            if let Some(dir) = path.parent() {
                std::fs::create_dir_all(dir).map_err(|e| {
                    format!("{}: cannot create cache directory: {e}", dir.display())
                })?;
            }
            writers.push((
                *kind,
                StoreWriter::create(path, header(*kind)).map_err(|e| e.to_string())?,
            ));
        }
        Ok(StoreSink {
            writers,
            stored: PerKind::default(),
        })
    }

    /// Photons written per kind so far.
    pub fn stored(&self) -> &PerKind<u64> {
        &self.stored
    }

    pub fn finish(self, emitted: u64) -> Result<(), String> {
        for (_, w) in self.writers {
            w.finish(emitted).map_err(|e| e.to_string())?;
        }
        Ok(())
    }
}

impl Sink for StoreSink {
    fn consume(&mut self, chunk: &Arc<Traced>) -> Result<(), String> {
        for (kind, w) in self.writers.iter_mut() {
            let photons = &chunk[*kind];
            self.stored[*kind] += photons.len() as u64;
            w.write(photons).map_err(|e| e.to_string())?;
        }
        Ok(())
    }
}

/// Forwards every chunk to a stage running on its own thread. The channel should be bounded:
/// the stage then holds tracing back when it falls behind.
pub struct ChannelSink(pub Sender<Arc<Traced>>);

impl Sink for ChannelSink {
    fn consume(&mut self, chunk: &Arc<Traced>) -> Result<(), String> {
        self.0
            .send(Arc::clone(chunk))
            .map_err(|_| "a photon stage stopped before the photons did".to_string())
    }
}

/// Collects every chunk in memory: an in-process consumer (a k-NN builder that needs no
/// photon file, or a test).
#[derive(Default)]
pub struct CollectSink(pub Traced);

impl Sink for CollectSink {
    fn consume(&mut self, chunk: &Arc<Traced>) -> Result<(), String> {
        self.0.append(Traced::clone(chunk));
        Ok(())
    }
}

pub struct TraceStats {
    pub emitted: u64,
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
}

impl PipelineOptions {
    pub fn new(threads: usize) -> PipelineOptions {
        PipelineOptions {
            threads: threads.max(1),
            chunk: 16_384,
            window: 2 * threads.max(1) + 2,
        }
    }
}

/// Traces `params.photons` paths on `opts.threads` workers and hands every chunk, in index
/// order, to each of `sinks` in turn.
pub fn run(
    scene: &Scene,
    params: &EmitParams,
    plan: &Plan,
    sinks: &mut [&mut dyn Sink],
    opts: &PipelineOptions,
    progress: &Progress,
) -> Result<TraceStats, String> {
    run_chunks(
        params.photons,
        opts,
        &|range| emit::trace_range(scene, params, plan, range),
        &mut |traced: Traced| {
            let traced = Arc::new(traced);
            for sink in sinks.iter_mut() {
                sink.consume(&traced)?;
            }
            progress.inc(traced.emitted);
            Ok(())
        },
    )
}

/// The pipeline's machinery for any per-chunk work: `0..total` in chunks of `opts.chunk`
/// indices, `work` on `opts.threads` workers, and `consume` on this thread for every result
/// in index order, with at most `opts.window` results alive at once.
pub fn run_chunks<T: Send>(
    total: u64,
    opts: &PipelineOptions,
    work: &(dyn Fn(std::ops::Range<u64>) -> T + Sync),
    consume: &mut dyn FnMut(T) -> Result<(), String>,
) -> Result<TraceStats, String> {
    let start = std::time::Instant::now();
    let ranges: Vec<std::ops::Range<u64>> = emit::chunks(total, opts.chunk).collect();
    let n = ranges.len();
    let window = opts.window.max(1);
    let (ticket_tx, ticket_rx) = bounded::<usize>(window);
    let (tx, rx) = bounded::<(usize, T)>(window);
    for t in 0..window.min(n) {
        ticket_tx.send(t).expect("receiver alive");
    }
    let mut max_in_flight = 0;
    let result = std::thread::scope(|s| -> Result<(), String> {
        // Owned by this closure, so an early error return drops them and every worker wakes
        // (a blocked `send` fails, the ticket loop ends) before the scope joins.
        let (rx, ticket_tx) = (rx, ticket_tx);
        for _ in 0..opts.threads.max(1) {
            let (ticket_rx, tx) = (ticket_rx.clone(), tx.clone());
            let ranges = &ranges;
            s.spawn(move || worker(work, ranges, ticket_rx, tx));
        }
        drop((ticket_rx, tx));
        let mut pending: BTreeMap<usize, T> = BTreeMap::new();
        let mut next = 0;
        while next < n {
            let Ok((i, item)) = rx.recv() else {
                return Err("a photon worker stopped before its work was done".into());
            };
            pending.insert(i, item);
            max_in_flight = max_in_flight.max(pending.len() + rx.len());
            while let Some(item) = pending.remove(&next) {
                consume(item)?;
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
    Ok(TraceStats {
        emitted: total,
        seconds: start.elapsed().as_secs_f64(),
        max_in_flight,
    })
}

fn worker<T: Send>(
    work: &(dyn Fn(std::ops::Range<u64>) -> T + Sync),
    ranges: &[std::ops::Range<u64>],
    tickets: Receiver<usize>,
    out: Sender<(usize, T)>,
) {
    for i in tickets {
        if out.send((i, work(ranges[i].clone()))).is_err() {
            return; // the consumer failed and hung up
        }
    }
}
