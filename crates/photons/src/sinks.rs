//! Where traced chunks go: photon files ([`StoreSink`]) or any other `flow::Sink` of traced
//! chunks; [`run`] traces a run through them.

use emit::{EmitParams, Plan, Traced};
use flow::{PipelineOptions, Progress, Stats};
use scene::Scene;
use std::path::PathBuf;
use std::sync::Arc;
use store::{Header, MapKind, PerKind, StoreWriter};

/// A consumer of traced chunks (see `flow::Sink`).
pub trait Sink: flow::Sink<Traced> {}
impl<S: flow::Sink<Traced>> Sink for S {}

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

impl flow::Sink<Traced> for StoreSink {
    fn consume(&mut self, chunk: &Arc<Traced>) -> Result<(), String> {
        for (kind, w) in self.writers.iter_mut() {
            let photons = &chunk[*kind];
            self.stored[*kind] += photons.len() as u64;
            w.write(photons).map_err(|e| e.to_string())?;
        }
        Ok(())
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
) -> Result<Stats, String> {
    flow::run_chunks(
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
