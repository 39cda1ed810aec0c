//! Unit tests of the photon stage: the channel pipeline into photon files, its backpressure,
//! the cache, an in-memory stage beside the file writer.

use crate::cache::{self as pipeline, CacheKey};
use crate::sinks::{self, Sink, StoreSink};
use emit::{EmitParams, Plan};
use flow::{PipelineOptions, Progress};
use std::path::{Path, PathBuf};
use std::sync::Arc;
use store::{MapKind, MappedStore};

/// A stage on its own thread behind a bounded channel: the channel holds tracing back when
/// the stage falls behind.
struct ChannelSink<T>(crossbeam_channel::Sender<Arc<T>>);

impl<T> flow::Sink<T> for ChannelSink<T> {
    fn consume(&mut self, chunk: &Arc<T>) -> Result<(), String> {
        self.0
            .send(Arc::clone(chunk))
            .map_err(|_| "a stage stopped before its input did".to_string())
    }
}

/// Collects every chunk in memory: an in-process consumer beside the file writer.
#[derive(Default)]
struct CollectSink(emit::Traced);

impl flow::Sink<emit::Traced> for CollectSink {
    fn consume(&mut self, chunk: &Arc<emit::Traced>) -> Result<(), String> {
        self.0.append(emit::Traced::clone(chunk));
        Ok(())
    }
}

fn cornell() -> scene::Scene {
    let p =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/cornell-spheres/analytic.toml");
    scene::Scene::load(p).unwrap()
}

fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("photonflow-pipe-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    d
}

/// Runs the pipeline into `dir` and returns the photon files' bytes and the stats.
fn run(
    scene: &scene::Scene,
    params: &EmitParams,
    dir: &Path,
    threads: usize,
    chunk: u64,
    window: usize,
    consumer: Option<crossbeam_channel::Sender<std::sync::Arc<emit::Traced>>>,
) -> (Vec<Vec<u8>>, flow::Stats) {
    let plan = Plan::for_scene(scene, params).unwrap();
    let key = CacheKey::new(scene, params);
    let files: Vec<(MapKind, PathBuf)> = pipeline::planned_kinds(&plan)
        .into_iter()
        .map(|k| (k, key.file(dir, k)))
        .collect();
    let opts = PipelineOptions {
        threads,
        chunk,
        window,
    };
    let progress = Progress::new("test", params.photons, "photons");
    let mut store = StoreSink::create(&files, &|k| key.header(scene, k)).unwrap();
    let mut channel = consumer.map(ChannelSink);
    let mut sinks: Vec<&mut dyn Sink> = vec![&mut store];
    if let Some(c) = channel.as_mut() {
        sinks.push(c);
    }
    let stats = sinks::run(scene, params, &plan, &mut sinks, &opts, &progress).unwrap();
    drop(sinks);
    store.finish(params.photons).unwrap();
    let bytes = files
        .iter()
        .map(|(_, f)| std::fs::read(f).unwrap())
        .collect();
    (bytes, stats)
}

#[test]
fn photon_files_are_bit_identical_for_any_thread_count_and_chunking() {
    let scene = cornell();
    let params = EmitParams {
        photons: 20_000,
        ..EmitParams::default()
    };
    let d = scratch("threads");
    let (one, _) = run(&scene, &params, &d.join("a"), 1, 4096, 4, None);
    let (two, _) = run(&scene, &params, &d.join("b"), 2, 777, 6, None);
    assert_eq!(one.len(), 2, "global and caustic sets");
    assert_eq!(one, two);
    // And the payload equals one single-threaded trace of the whole range.
    let plan = Plan::for_scene(&scene, &params).unwrap();
    let whole = emit::trace_range(&scene, &params, &plan, 0..params.photons);
    let key = CacheKey::new(&scene, &params);
    let g = MappedStore::open(&key.file(&d.join("a"), MapKind::Global)).unwrap();
    assert_eq!(g.to_vec(), whole[MapKind::Global]);
    assert_eq!(g.header().emitted, params.photons);
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn backpressure_bounds_the_chunks_in_flight_and_the_consumer_sees_everything_in_order() {
    let scene = cornell();
    let params = EmitParams {
        photons: 30_000,
        ..EmitParams::default()
    };
    let d = scratch("window");
    let (tx, rx) = crossbeam_channel::unbounded();
    // 150 chunks of 200 paths, at most 3 alive at once.
    let (_, stats) = run(&scene, &params, &d, 2, 200, 3, Some(tx));
    assert!(
        stats.max_in_flight <= 3,
        "{} chunks in flight",
        stats.max_in_flight
    );
    let got: Vec<std::sync::Arc<emit::Traced>> = rx.iter().collect();
    assert_eq!(got.len(), 150);
    let caustic: Vec<store::Photon> = got
        .iter()
        .flat_map(|t| t[MapKind::Caustic].iter().copied())
        .collect();
    let key = CacheKey::new(&scene, &params);
    let file = MappedStore::open(&key.file(&d, MapKind::Caustic)).unwrap();
    assert_eq!(
        caustic,
        file.to_vec(),
        "consumer and file see the same photons, in order"
    );
    assert_eq!(got.iter().map(|t| t.emitted).sum::<u64>(), params.photons);
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn the_cache_reuses_only_identical_runs() {
    let scene = cornell();
    let params = EmitParams {
        photons: 3_000,
        ..EmitParams::default()
    };
    let d = scratch("cache");
    let key = CacheKey::new(&scene, &params);
    let plan = Plan::for_scene(&scene, &params).unwrap();
    let kinds = pipeline::planned_kinds(&plan);
    assert!(!pipeline::cached(&d, &key, &kinds));
    run(&scene, &params, &d, 2, 1000, 4, None);
    assert!(pipeline::cached(&d, &key, &kinds));
    // Other parameters, or another scene: another key, not cached.
    let other = EmitParams {
        photons: 3_001,
        ..params.clone()
    };
    assert!(!pipeline::cached(
        &d,
        &CacheKey::new(&scene, &other),
        &kinds
    ));
    let text = std::fs::read_to_string(&scene.path)
        .unwrap()
        .replace("ior = 1.5", "ior = 1.6");
    let edited = scene::Scene::from_toml(&scene.path, &text).unwrap();
    assert!(!pipeline::cached(
        &d,
        &CacheKey::new(&edited, &params),
        &kinds
    ));
    // A damaged file is not reused.
    let f = key.file(&d, MapKind::Global);
    let mut bytes = std::fs::read(&f).unwrap();
    let last = bytes.len() - 1;
    bytes[last] ^= 1;
    std::fs::write(&f, bytes).unwrap();
    assert!(
        !pipeline::cached(&d, &key, &kinds),
        "a damaged set must be traced anew"
    );
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn an_in_memory_stage_sees_the_same_photons_as_the_file_writer() {
    // Two consumers of one run: the photon file writer and an in-memory collector (what a
    // k-NN builder or a splatter does with the chunks). Both see every photon, in order.
    let scene = cornell();
    let params = EmitParams {
        photons: 12_000,
        ..EmitParams::default()
    };
    let d = scratch("collect");
    let plan = Plan::for_scene(&scene, &params).unwrap();
    let key = CacheKey::new(&scene, &params);
    let files: Vec<(MapKind, PathBuf)> = pipeline::planned_kinds(&plan)
        .into_iter()
        .map(|k| (k, key.file(&d, k)))
        .collect();
    let mut store = StoreSink::create(&files, &|k| key.header(&scene, k)).unwrap();
    let mut collect = CollectSink::default();
    let opts = PipelineOptions {
        threads: 2,
        chunk: 1000,
        window: 4,
    };
    let stats = sinks::run(
        &scene,
        &params,
        &plan,
        &mut [&mut store as &mut dyn Sink, &mut collect],
        &opts,
        &Progress::hidden(),
    )
    .unwrap();
    store.finish(params.photons).unwrap();
    assert!(stats.max_in_flight <= 4);
    assert_eq!(collect.0.emitted, params.photons);
    for (kind, path) in &files {
        let file = MappedStore::open(path).unwrap();
        assert!(!collect.0[*kind].is_empty(), "{kind:?}");
        assert_eq!(file.to_vec(), collect.0[*kind], "{kind:?}");
    }
    let _ = std::fs::remove_dir_all(&d);
}
