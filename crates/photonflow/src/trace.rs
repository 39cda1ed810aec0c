//! `trace`: the photon stage. Plans the sets the scene needs, reuses them from the cache when
//! an identical run made them, else traces them through the pipeline.

use crate::pipeline::{self, CacheKey, PipelineOptions};
use crate::progress::Progress;
use emit::{EmitParams, Plan};
use scene::Scene;
use std::path::{Path, PathBuf};
use store::MapKind;

pub struct TraceArgs {
    pub photons: Option<u64>,
    pub cache: PathBuf,
    pub threads: Option<usize>,
    pub force: bool,
}

/// What the stage produced: the photon files per kind, and whether they were reused.
pub struct TraceOutput {
    pub reused: bool,
    pub seconds: f64,
}

pub fn params(scene: &Scene, photons: Option<u64>) -> Result<EmitParams, String> {
    let mut p = pipeline::emit_params(scene)?;
    if let Some(n) = photons {
        p.photons = n;
    }
    if p.photons == 0 || p.photons > 1 << 40 {
        return Err(format!(
            "{}: photons = {} must be in 1..=2^40",
            scene.path.display(),
            p.photons
        ));
    }
    Ok(p)
}

pub fn trace(scene: &Scene, a: &TraceArgs) -> Result<TraceOutput, String> {
    let params = params(scene, a.photons)?;
    let plan =
        Plan::for_scene(scene, &params).map_err(|e| format!("{}: {e}", scene.path.display()))?;
    print!("{plan}");
    let key = CacheKey::new(scene, &params);
    let kinds = pipeline::planned_kinds(&plan);
    let files: Vec<(MapKind, PathBuf)> =
        kinds.iter().map(|&k| (k, key.file(&a.cache, k))).collect();
    save_plan(&a.cache, &key, &plan)?;
    if !a.force && pipeline::cached(&a.cache, &key, &kinds) {
        println!("reused cached photon sets (no tracing):");
        for (_, f) in &files {
            println!("  {}", f.display());
        }
        return Ok(TraceOutput {
            reused: true,
            seconds: 0.0,
        });
    }
    let threads = a.threads.unwrap_or_else(rayon::current_num_threads);
    if threads == 0 {
        return Err("--threads must be at least 1".into());
    }
    let progress = Progress::new("trace", params.photons, "photons");
    let stats = pipeline::run(
        scene,
        &params,
        &plan,
        &key,
        &files,
        &PipelineOptions::new(threads),
        &progress,
    )?;
    progress.finish();
    let bytes: u64 = files
        .iter()
        .map(|(_, f)| std::fs::metadata(f).map(|m| m.len()).unwrap_or(0))
        .sum();
    let stored = stats.stored[0] + stats.stored[1];
    println!(
        "traced {} photon paths in {:.2} s ({:.3} M paths/s on {threads} threads, at most {} chunks in memory); stored {} global, {} caustic ({:.1} bytes/photon)",
        stats.emitted,
        stats.seconds,
        stats.emitted as f64 / stats.seconds / 1e6,
        stats.max_in_flight,
        stats.stored[0],
        stats.stored[1],
        bytes as f64 / stored.max(1) as f64
    );
    for (_, f) in &files {
        println!("  {}", f.display());
    }
    Ok(TraceOutput {
        reused: false,
        seconds: stats.seconds,
    })
}

fn save_plan(dir: &Path, key: &CacheKey, plan: &Plan) -> Result<(), String> {
    std::fs::create_dir_all(dir)
        .map_err(|e| format!("{}: cannot create cache directory: {e}", dir.display()))?;
    let path = dir.join(format!(
        "{:016x}-{:016x}-plan.txt",
        key.scene_hash, key.params_hash
    ));
    film::write_atomic(&path, plan.to_string().as_bytes()).map_err(|e| e.to_string())
}
