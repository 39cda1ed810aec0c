//! `flow`: the channel machinery every stage runs on, and progress for long work. Work over
//! `0..total` is cut into chunks of indices; workers compute chunks and send them over a
//! bounded crossbeam channel to one ordering stage that hands each result, in index order, to
//! its consumer ([`run_chunks`]), or to every [`Sink`] of a chunk. Memory stays flat however
//! large the run: a worker may only start a chunk it holds a *ticket* for, and tickets are
//! issued as chunks are consumed, so at most `window` chunks exist at any time (computed,
//! queued or waiting for their turn). It knows nothing of photons: the photon stage
//! (`photons`) and the splatting and SPPM passes (`render`) are built on it.

pub mod progress;

pub use progress::Progress;

use crossbeam_channel::{Receiver, Sender, bounded};
use std::collections::BTreeMap;
use std::sync::Arc;

/// A consumer of chunks. `consume` sees every chunk exactly once, in index order, on the
/// ordering thread; a slow sink slows the workers down (backpressure), it never buffers them.
pub trait Sink<T> {
    fn consume(&mut self, chunk: &Arc<T>) -> Result<(), String>;
}

/// What a run of [`run_chunks`] did.
pub struct Stats {
    /// Indices computed.
    pub total: u64,
    pub seconds: f64,
    /// Most chunks alive at once (the backpressure bound, tested).
    pub max_in_flight: usize,
}

/// Options of one run of [`run_chunks`].
pub struct PipelineOptions {
    pub threads: usize,
    /// Indices per chunk (the unit of work and of memory).
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

/// The pipeline's machinery for any per-chunk work: `0..total` in chunks of `opts.chunk`
/// indices, `work` on `opts.threads` workers, and `consume` on this thread for every result
/// in index order, with at most `opts.window` results alive at once.
pub fn run_chunks<T: Send>(
    total: u64,
    opts: &PipelineOptions,
    work: &(dyn Fn(std::ops::Range<u64>) -> T + Sync),
    consume: &mut dyn FnMut(T) -> Result<(), String>,
) -> Result<Stats, String> {
    let start = std::time::Instant::now();
    let ranges: Vec<std::ops::Range<u64>> = chunks(total, opts.chunk).collect();
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
                return Err("a worker stopped before its work was done".into());
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
    Ok(Stats {
        total,
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

/// `0..total` in consecutive ranges of `chunk` indices (the last one shorter).
pub fn chunks(total: u64, chunk: u64) -> impl Iterator<Item = std::ops::Range<u64>> {
    let chunk = chunk.max(1);
    (0..total.div_ceil(chunk)).map(move |k| k * chunk..((k + 1) * chunk).min(total))
}

#[cfg(test)]
mod tests;
