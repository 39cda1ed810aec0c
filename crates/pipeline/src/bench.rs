//! `bench-rays`: single-thread closest-hit throughput. Rays are generated before the clock
//! starts; each kind is timed `runs` times and the median reported (machines are shared and
//! noisy, so one run says little).

use geom::{BvhKind, Geometry, Ray};
use glam::Vec3;
use math::Rng;
use std::path::Path;
use std::time::Instant;

pub fn rays(path: &Path, runs: usize, count: usize, compare: bool) -> Result<(), String> {
    if runs == 0 || count == 0 {
        return Err("--runs and --rays must be positive".into());
    }
    let s = scene::Scene::load(path).map_err(|e| e.to_string())?;
    let coherent = camera_rays(&s.camera, count);
    let incoherent = random_rays(&s.geometry, count, s.seed());
    println!(
        "scene {} ({} triangles, {} spheres), {} rays per run, median of {} runs, 1 thread",
        path.display(),
        s.geometry.mesh().len(),
        s.geometry.spheres().len(),
        count,
        runs
    );
    let mut kinds = vec![BvhKind::CwBvh];
    if compare {
        kinds.push(BvhKind::Bvh2);
    }
    for kind in kinds {
        let t0 = Instant::now();
        let geo = Geometry::with_bvh(
            s.geometry.mesh().clone(),
            s.geometry.spheres().to_vec(),
            kind,
        );
        let build = t0.elapsed();
        for (name, rays) in [("coherent", &coherent), ("incoherent", &incoherent)] {
            let (mrays, hits) = median_rate(&geo, rays, runs);
            println!(
                "{name:>10}: {mrays:7.2} M rays/s  ({kind:?}, build {:.1} ms, {:.1}% hit)",
                build.as_secs_f64() * 1e3,
                100.0 * hits as f64 / rays.len() as f64
            );
        }
    }
    Ok(())
}

fn median_rate(geo: &Geometry, rays: &[Ray], runs: usize) -> (f64, usize) {
    let mut rates = Vec::with_capacity(runs);
    let mut hits = 0;
    for _ in 0..runs {
        let t = Instant::now();
        hits = rays
            .iter()
            .filter(|r| std::hint::black_box(geo.intersect(r)).is_some())
            .count();
        rates.push(rays.len() as f64 / t.elapsed().as_secs_f64() / 1e6);
    }
    rates.sort_by(f64::total_cmp);
    (rates[runs / 2], hits)
}

/// Primary rays through a square grid of pixel centres covering the camera's image.
fn camera_rays(cam: &scene::Camera, count: usize) -> Vec<Ray> {
    let n = (count as f64).sqrt().ceil() as usize;
    let (w, h) = (cam.width as f32, cam.height as f32);
    (0..count)
        .map(|i| {
            let (x, y) = (i % n, i / n);
            cam.ray(
                (x as f32 + 0.5) / n as f32 * w,
                (y as f32 + 0.5) / n as f32 * h,
            )
        })
        .collect()
}

/// Origins uniform in the scene's bounding box, directions uniform on the sphere.
fn random_rays(geo: &Geometry, count: usize, seed: u64) -> Vec<Ray> {
    let b = geo.bounds();
    let mut rng = Rng::new(seed ^ 0xbe4c);
    (0..count)
        .map(|_| {
            let o = b.lerp(Vec3::new(rng.uniform(), rng.uniform(), rng.uniform()));
            let z = 1.0 - 2.0 * rng.uniform();
            let r = (1.0 - z * z).max(0.0).sqrt();
            let phi = std::f32::consts::TAU * rng.uniform();
            Ray::new(o, Vec3::new(r * phi.cos(), r * phi.sin(), z))
        })
        .collect()
}

/// Photon paths per second through `emit::trace_range` on 1 and 2 threads (chunks of 16k
/// paths handed out by index, as the pipeline does), and through the whole pipeline into
/// photon files. Median of `runs`.
pub fn photons(path: &Path, count: u64, runs: usize) -> Result<(), String> {
    let s = scene::Scene::load(path).map_err(|e| e.to_string())?;
    let params = crate::Settings::new(
        &s,
        &crate::Overrides {
            photons: Some(count),
            ..Default::default()
        },
    )?
    .emit;
    let plan = emit::Plan::for_scene(&s, &params).map_err(|e| e.to_string())?;
    println!(
        "scene {}, {count} photon paths per run, median of {runs} runs",
        path.display()
    );
    for threads in [1usize, 2] {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .map_err(|e| e.to_string())?;
        let mut rates = Vec::new();
        let mut stored = 0;
        for _ in 0..runs.max(1) {
            let t = Instant::now();
            let chunks: Vec<_> = emit::chunks(count, 16_384).collect();
            let traced: Vec<emit::Traced> = pool.install(|| {
                use rayon::prelude::*;
                chunks
                    .par_iter()
                    .map(|r| emit::trace_range(&s, &params, &plan, r.clone()))
                    .collect()
            });
            rates.push(count as f64 / t.elapsed().as_secs_f64());
            stored = traced.iter().map(emit::Traced::stored).sum();
        }
        rates.sort_by(f64::total_cmp);
        println!(
            "trace only, {threads} thread(s): {:6.3} M paths/s ({:.2} stored photons per path)",
            rates[rates.len() / 2] / 1e6,
            stored as f64 / count as f64
        );
    }
    let dir = std::env::temp_dir().join(format!("photonflow-bench-{}", std::process::id()));
    for threads in [1usize, 2] {
        let mut rates = Vec::new();
        for _ in 0..runs.max(1) {
            use crate::flow::{self, PipelineOptions, Sink, StoreSink};
            let key = crate::photon_cache::CacheKey::new(&s, &params);
            let files: Vec<_> = crate::photon_cache::planned_kinds(&plan)
                .into_iter()
                .map(|k| (k, key.file(&dir, k)))
                .collect();
            let progress = crate::progress::Progress::hidden();
            let mut store = StoreSink::create(&files, &|k| key.header(&s, k))?;
            let stats = flow::run(
                &s,
                &params,
                &plan,
                &mut [&mut store as &mut dyn Sink],
                &PipelineOptions::new(threads),
                &progress,
            )?;
            store.finish(params.photons)?;
            rates.push(count as f64 / stats.seconds);
        }
        rates.sort_by(f64::total_cmp);
        println!(
            "pipeline to photon files, {threads} thread(s): {:6.3} M paths/s",
            rates[rates.len() / 2] / 1e6
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
    Ok(())
}

/// Write and read throughput of a photon file, and plain records against bincode.
pub fn store(photons: usize, dir: &Path) -> Result<(), String> {
    std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    let b = store::bench::bench_store(dir, photons).map_err(|e| e.to_string())?;
    println!(
        "photon file: {} photons, {} bytes ({:.4} bytes/photon) in {}",
        b.photons,
        b.file_bytes,
        b.bytes_per_photon,
        dir.display()
    );
    println!("   write (fsync + rename): {:6.2} GB/s", b.write_gbs);
    println!(
        "   write (page cache)    : {:6.2} GB/s",
        b.write_unsynced_gbs
    );
    println!("   streaming read        : {:6.2} GB/s", b.stream_read_gbs);
    println!("   mapped read (+ CRCs)  : {:6.2} GB/s", b.mapped_read_gbs);
    let e = store::bench::bench_encodings(photons.min(10_000_000));
    println!(
        "encodings of {} photons: plain records encode {:.2} / decode {:.2} GB/s; bincode encode {:.2} / decode {:.2} GB/s ({} bytes); bincode fixint encode {:.2} / decode {:.2} GB/s",
        e.photons,
        e.plain_encode_gbs,
        e.plain_decode_gbs,
        e.bincode_encode_gbs,
        e.bincode_decode_gbs,
        e.bincode_bytes,
        e.bincode_fixint_encode_gbs,
        e.bincode_fixint_decode_gbs
    );
    Ok(())
}

/// k-NN queries per second over synthetic photons on the faces of a unit cube, per index.
pub fn knn(photons: usize, queries: usize) -> Result<(), String> {
    println!("{photons} photons on the unit cube's faces, {queries} queries, 1 thread");
    for r in density::bench::bench_knn(photons, &[50, 250, 1000], queries, 7) {
        println!(
            "{:>9} k = {:4}: {:10.0} queries/s (build {:.3} s)",
            r.name, r.k, r.queries_per_s, r.build_s
        );
    }
    let res = 128;
    println!(
        "kd-tree, the global map shown directly: {res}x{res} pixel-order queries (hint carried \
         from pixel to pixel) and the same points shuffled"
    );
    for r in density::bench::bench_coherent(photons, &[50, 250, 1000], res, 7) {
        println!(
            "{:>9} k = {:4}: k-NN {:9.0} /s, hinted {:9.0} /s; irradiance {:9.0} /s, hinted {:9.0} /s",
            if r.coherent { "pixels" } else { "shuffled" },
            r.k,
            r.knn_per_s,
            r.hinted_per_s,
            r.irradiance_per_s,
            r.irradiance_hinted_per_s
        );
    }
    Ok(())
}

/// Peak resident memory of this process so far (Linux `VmHWM`), in MiB; `None` elsewhere.
fn peak_rss_mib() -> Option<f64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kb: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb / 1024.0)
}

/// `bench-splat`: caustic photons traced with differentials and splatted onto the eye
/// vertices, photons/s on 1 and 2 threads (median of `runs`), the number of eye vertices, and
/// the peak memory before and after splatting ten times more photons (flat if no photon is
/// kept).
pub fn splat(path: &Path, photons: u64, runs: usize) -> Result<(), String> {
    use crate::splat::{Splatter, eye_index};
    let s = scene::Scene::load(path).map_err(|e| e.to_string())?;
    let settings = crate::Settings::new(&s, &crate::Overrides::default())?;
    let sp = settings.estimate.splat;
    let mut params = settings.emit.clone();
    params.photons = photons;
    let t0 = Instant::now();
    let eyes = eye_index(&s, &sp, settings.estimate.spp, 0, None);
    println!(
        "scene {}, {} eye vertices in {:.3} s, {photons} caustic photon paths per run (indirect: {}), median of {runs}",
        path.display(),
        eyes.len(),
        sp.indirect,
        t0.elapsed().as_secs_f64()
    );
    let (w, h) = (s.camera.width as usize, s.camera.height as usize);
    let splatter = Splatter {
        scene: &s,
        params: &params,
        settings: &sp,
        eyes: &eyes,
    };
    for threads in [1usize, 2] {
        let mut rates = Vec::new();
        for run in 0..runs.max(1) {
            let mut images = [
                vec![glam::DVec3::ZERO; w * h],
                vec![glam::DVec3::ZERO; w * h],
            ];
            let stats = splatter.pass(run as u64, &mut images, threads, &|_| {})?;
            rates.push(photons as f64 / stats.seconds);
        }
        rates.sort_by(f64::total_cmp);
        println!(
            "splat, {threads} thread(s): {:6.3} M photon paths/s",
            rates[rates.len() / 2] / 1e6
        );
    }
    let before = peak_rss_mib();
    let mut many = params.clone();
    many.photons = photons * 10;
    let mut images = [
        vec![glam::DVec3::ZERO; w * h],
        vec![glam::DVec3::ZERO; w * h],
    ];
    Splatter {
        scene: &s,
        params: &many,
        settings: &sp,
        eyes: &eyes,
    }
    .pass(0, &mut images, 2, &|_| {})?;
    match (before, peak_rss_mib()) {
        (Some(a), Some(b)) => println!(
            "peak memory: {a:.1} MiB after {photons} photons per pass, {b:.1} MiB after {} in one pass",
            photons * 10
        ),
        _ => println!("peak memory: not available on this system"),
    }
    Ok(())
}
