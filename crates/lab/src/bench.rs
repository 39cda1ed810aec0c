//! `bench-rays`: single-thread closest-hit throughput. Rays are generated before the clock
//! starts; each kind is timed `runs` times and the median reported (machines are shared and
//! noisy, so one run says little).

use geom::{BvhKind, Geometry, Isa, Ray};
use glam::Vec3;
use math::Rng;
use std::path::Path;
use std::time::Instant;

pub fn rays(
    path: &Path,
    runs: usize,
    count: usize,
    compare: bool,
    ray_dir: Option<&Path>,
    peer: Option<(&str, &str)>,
) -> Result<(), String> {
    if runs == 0 || count == 0 {
        return Err("--runs and --rays must be positive".into());
    }
    let s = scene::Scene::load(path).map_err(|e| e.to_string())?;
    // Each set: name, rays, and (ray files only) the reference's closest-hit distances.
    let mut sets: Vec<RaySet> = Vec::new();
    match ray_dir {
        None => {
            sets.push(("coherent", camera_rays(&s.camera, count), None));
            sets.push((
                "incoherent",
                random_rays(&s.geometry, count, s.seed()),
                None,
            ));
        }
        Some(dir) => {
            for name in ["coherent", "incoherent"] {
                let rays = read_ray_file(&dir.join(format!("{name}_rays.f32")))?;
                let t_file = dir.join(format!("{name}_hit_t.npy"));
                let reference = if t_file.exists() {
                    let t = read_npy_f32(&t_file)?;
                    if t.len() != rays.len() {
                        return Err(format!(
                            "{}: {} distances for {} rays",
                            t_file.display(),
                            t.len(),
                            rays.len()
                        ));
                    }
                    Some(t)
                } else {
                    None
                };
                sets.push((name, rays, reference));
            }
        }
    }
    println!(
        "scene {} ({} triangles, {} spheres), {} rays per run{}, median of {} runs, 1 thread; closest hits (distance and primitive, as Embree returns)",
        path.display(),
        s.geometry.mesh().len(),
        s.geometry.spheres().len(),
        sets[0].1.len(),
        ray_dir.map_or(String::new(), |d| format!(" from {}", d.display())),
        runs
    );
    if let Some(cpus) = allowed_cpus() {
        // A peer started from here inherits this set: run under `taskset -c N` so that both
        // are timed on the same core (the Embree script pins itself to the first it may use).
        println!("CPUs this process may run on: {cpus}");
    }
    // The baseline BVH4 and, where the processor has AVX2, the BVH8 (`PHOTONFLOW_ISA` does
    // not apply here: both are timed), in alternating rounds so that both see the same load.
    let mut kinds = vec![BvhKind::Bvh4];
    if Isa::best() == Isa::Avx2 {
        kinds.push(BvhKind::Bvh8);
    }
    if compare {
        kinds.push(BvhKind::CwBvh);
    }
    let geos: Vec<(Geometry, f64)> = kinds
        .iter()
        .map(|&kind| {
            let t0 = Instant::now();
            let geo = Geometry::with_bvh(
                s.geometry.mesh().clone(),
                s.geometry.spheres().to_vec(),
                kind,
            );
            (geo, t0.elapsed().as_secs_f64())
        })
        .collect();
    for (name, rays, reference) in &sets {
        let mut rates = vec![Vec::new(); geos.len()];
        let mut records = vec![Vec::new(); geos.len()];
        let mut hits = 0;
        for _ in 0..runs {
            for (k, (geo, _)) in geos.iter().enumerate() {
                let (rate, h) = median_rate(geo, rays, 1);
                hits = h;
                rates[k].push(rate);
                records[k].push(median_rate_with_record(geo, rays, 1));
            }
        }
        let medians: Vec<f64> = rates.iter_mut().map(|r| median(r)).collect();
        for (k, (geo, build)) in geos.iter().enumerate() {
            let record = median(&mut records[k]);
            println!(
                "{name:>10}: {:7.2} M rays/s  ({:?}, build {:.1} ms, {:.1}% hit; {record:.2} M/s with the surface record)",
                medians[k],
                geo.kind(),
                build * 1e3,
                100.0 * hits as f64 / rays.len() as f64
            );
            if let Some(t_ref) = reference {
                let a = agreement(geo, rays, t_ref);
                println!(
                    "{:>10}  vs reference hits: hit/miss agree on {:.4}% of rays; closest-hit distance within 1e-4 relative on {:.4}% of rays ({:.4}% of rays both hit)",
                    "",
                    100.0 * a.hit_miss as f64 / rays.len() as f64,
                    100.0 * a.agree as f64 / rays.len() as f64,
                    100.0 * a.t_close as f64 / a.both_hit.max(1) as f64,
                );
            }
        }
        if kinds.get(1) == Some(&BvhKind::Bvh8) {
            println!(
                "{:>10}  Bvh8 (AVX2) / Bvh4 (baseline): {:.2}x",
                "",
                medians[1] / medians[0]
            );
        }
    }
    if let Some((name, command)) = peer {
        peer_ratios(&s.geometry, &sets, runs, name, command)?;
    }
    Ok(())
}

/// The peer and our default BVH (this process's instruction set) in alternating rounds (peer, then ours, `runs` times), so
/// both see the same machine load; medians of each and their ratio. The peer is a shell
/// command printing lines with `coherent` or `incoherent` and a rate `X Mrays/s` (or
/// `M rays/s`), one thread (e.g. Embree 4 through its Python bindings, pinned to one CPU).
fn peer_ratios(
    geometry: &Geometry,
    sets: &[RaySet],
    runs: usize,
    name: &str,
    command: &str,
) -> Result<(), String> {
    let geo = Geometry::with_bvh(
        geometry.mesh().clone(),
        geometry.spheres().to_vec(),
        BvhKind::for_isa(Isa::active()),
    );
    let mut theirs: Vec<Vec<f64>> = vec![Vec::new(); sets.len()];
    let mut ours: Vec<Vec<f64>> = vec![Vec::new(); sets.len()];
    for _ in 0..runs {
        let out = std::process::Command::new("sh")
            .arg("-c")
            .arg(command)
            .output()
            .map_err(|e| format!("peer {name}: {e}"))?;
        if !out.status.success() {
            return Err(format!("peer {name}: `{command}` failed ({})", out.status));
        }
        let text = String::from_utf8_lossy(&out.stdout);
        for (i, (set, rays, _)) in sets.iter().enumerate() {
            let rate = peer_rate(&text, set)
                .ok_or_else(|| format!("peer {name}: no `{set} ... Mrays/s` line in its output"))?;
            theirs[i].push(rate);
            ours[i].push(median_rate(&geo, rays, 1).0);
        }
    }
    println!("against {name}, {runs} alternating rounds (medians, M rays/s):");
    for (i, (set, _, _)) in sets.iter().enumerate() {
        let (t, o) = (median(&mut theirs[i]), median(&mut ours[i]));
        println!(
            "{set:>10}: {name} {t:7.2}, photonflow {o:7.2}, ratio {:.2}x",
            o / t
        );
    }
    Ok(())
}

/// `Cpus_allowed_list` from `/proc/self/status` (Linux), e.g. `0-1` or `1`.
fn allowed_cpus() -> Option<String> {
    proc_status("Cpus_allowed_list")
}

/// The value of `key` in `/proc/self/status` (Linux only; `None` elsewhere).
fn proc_status(key: &str) -> Option<String> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    status
        .lines()
        .find_map(|l| l.strip_prefix(key)?.strip_prefix(':'))
        .map(|v| v.trim().to_string())
}

/// The rate on the first line that starts with `set` (after spaces) and holds `Mrays/s`.
pub fn peer_rate(text: &str, set: &str) -> Option<f64> {
    text.lines()
        .filter(|l| {
            let l = l.trim_start();
            l.starts_with(set)
                && !(set == "coherent" && l.starts_with("incoherent"))
                && (l.contains("Mrays/s") || l.contains("M rays/s"))
        })
        .find_map(|l| {
            let head = l.split("M rays/s").next()?.split("Mrays/s").next()?;
            head.split_whitespace().last()?.parse::<f64>().ok()
        })
}

/// The middle value of `v` (the upper one of an even count), sorting it in place.
pub(crate) fn median(v: &mut [f64]) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// A named ray set and, from ray files, the reference's closest-hit distances.
type RaySet = (&'static str, Vec<Ray>, Option<Vec<f32>>);

/// How our closest hits compare with a reference's distances (`inf` = miss).
struct Agreement {
    /// Rays both call a hit, or both a miss.
    hit_miss: usize,
    both_hit: usize,
    /// Rays both hit with `|t - t_ref| <= 1e-4 t_ref`.
    t_close: usize,
    /// Rays both miss or both hit within that tolerance.
    agree: usize,
}

fn agreement(geo: &Geometry, rays: &[Ray], t_ref: &[f32]) -> Agreement {
    let mut a = Agreement {
        hit_miss: 0,
        both_hit: 0,
        t_close: 0,
        agree: 0,
    };
    for (r, &tr) in rays.iter().zip(t_ref) {
        match (geo.intersect(r), tr.is_finite()) {
            (None, false) => {
                a.hit_miss += 1;
                a.agree += 1;
            }
            (Some(h), true) => {
                a.hit_miss += 1;
                a.both_hit += 1;
                if (h.t - tr).abs() <= 1e-4 * tr {
                    a.t_close += 1;
                    a.agree += 1;
                }
            }
            _ => {}
        }
    }
    a
}

/// Rays as raw little-endian f32 rows `ox oy oz dx dy dz` (the peers' ray-file format).
pub fn read_ray_file(path: &Path) -> Result<Vec<Ray>, String> {
    let bytes = std::fs::read(path).map_err(|e| format!("{}: {e}", path.display()))?;
    if bytes.is_empty() || bytes.len() % 24 != 0 {
        return Err(format!(
            "{}: {} bytes is not a positive whole number of 24-byte rays (6 little-endian f32)",
            path.display(),
            bytes.len()
        ));
    }
    let f: Vec<f32> = bytes
        .chunks_exact(4)
        .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
        .collect();
    f.chunks_exact(6)
        .enumerate()
        .map(|(i, r)| {
            let (o, d) = (Vec3::new(r[0], r[1], r[2]), Vec3::new(r[3], r[4], r[5]));
            if !(o.is_finite() && d.is_finite()) || d == Vec3::ZERO {
                return Err(format!(
                    "{}: ray {i} has a non-finite origin or direction or a zero direction",
                    path.display()
                ));
            }
            Ok(Ray::new(o, d))
        })
        .collect()
}

/// A 1-D little-endian f32 `.npy` array (NumPy format 1.0-3.0: magic, version, header
/// length, a text header naming dtype and shape, then the raw data).
pub fn read_npy_f32(path: &Path) -> Result<Vec<f32>, String> {
    let err = |m: &str| format!("{}: {m}", path.display());
    let bytes = std::fs::read(path).map_err(|e| err(&e.to_string()))?;
    if bytes.len() < 10 || &bytes[..6] != b"\x93NUMPY" {
        return Err(err("not a .npy file"));
    }
    let (len, start) = match bytes[6] {
        1 => (u16::from_le_bytes([bytes[8], bytes[9]]) as usize, 10),
        2 | 3 if bytes.len() >= 12 => (
            u32::from_le_bytes([bytes[8], bytes[9], bytes[10], bytes[11]]) as usize,
            12,
        ),
        _ => return Err(err("unsupported .npy version")),
    };
    let header = bytes
        .get(start..start + len)
        .and_then(|h| std::str::from_utf8(h).ok())
        .ok_or_else(|| err("truncated .npy header"))?;
    let compact: String = header.chars().filter(|c| !c.is_whitespace()).collect();
    if !compact.contains("'descr':'<f4'") || !compact.contains("'fortran_order':False") {
        return Err(err("expected a little-endian f32 ('<f4') array in C order"));
    }
    let shape = compact
        .split("'shape':(")
        .nth(1)
        .and_then(|s| s.split(')').next())
        .ok_or_else(|| err("no shape in the .npy header"))?;
    let n: usize = shape
        .trim_end_matches(',')
        .parse()
        .map_err(|_| err("expected a 1-D array"))?;
    let data = &bytes[start + len..];
    if data.len() != 4 * n {
        return Err(err(&format!(
            "{} data bytes for {n} f32 values",
            data.len()
        )));
    }
    Ok(data
        .chunks_exact(4)
        .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
        .collect())
}

/// Closest hits per second (distance and primitive: what Embree's `rtcIntersect1`
/// returns), median of `runs`, and the number of rays that hit.
fn median_rate(geo: &Geometry, rays: &[Ray], runs: usize) -> (f64, usize) {
    median_rate_of(rays, runs, |r| geo.closest(r).is_some())
}

/// As [`median_rate`], with the surface record (`Geometry::intersect`) the renderer uses.
fn median_rate_with_record(geo: &Geometry, rays: &[Ray], runs: usize) -> f64 {
    median_rate_of(rays, runs, |r| geo.intersect(r).is_some()).0
}

fn median_rate_of(rays: &[Ray], runs: usize, cast: impl Fn(&Ray) -> bool) -> (f64, usize) {
    let mut rates = Vec::with_capacity(runs);
    let mut hits = 0;
    for _ in 0..runs {
        let t = Instant::now();
        hits = rays
            .iter()
            .filter(|r| std::hint::black_box(cast(std::hint::black_box(r))))
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
    let params = render::Settings::new(
        &s,
        &render::Overrides {
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
            let chunks: Vec<_> = flow::chunks(count, 16_384).collect();
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
            use flow::PipelineOptions;
            use photons::sinks::{self, Sink, StoreSink};
            let key = photons::cache::CacheKey::new(&s, &params);
            let files: Vec<_> = photons::cache::planned_kinds(&plan)
                .into_iter()
                .map(|k| (k, key.file(&dir, k)))
                .collect();
            let progress = flow::Progress::hidden();
            let mut store = StoreSink::create(&files, &|k| key.header(&s, k))?;
            let stats = sinks::run(
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
    let rows = density::bench::bench_knn(photons, &[50, 250, 1000], queries, 7);
    for r in &rows {
        println!(
            "{:>10} k = {:4}: {:10.0} queries/s (build {:.3} s)",
            r.name, r.k, r.queries_per_s, r.build_s
        );
    }
    // Ours against each kiddo release's own query, per k (same run, interleaved passes).
    let rate = |name: &str, k: usize| {
        rows.iter()
            .find(|r| r.name == name && r.k == k)
            .map(|r| r.queries_per_s)
    };
    for k in [50, 250, 1000] {
        for ours in ["kd_map", "kd_tree"] {
            if let (Some(o), Some(k5), Some(k6)) =
                (rate(ours, k), rate("kiddo_raw", k), rate("kiddo6_raw", k))
            {
                println!(
                    "k = {k:4}: {ours:>7} {:.2}x kiddo 5, {:.2}x kiddo 6",
                    o / k5,
                    o / k6
                );
            }
        }
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
    let kb: f64 = proc_status("VmHWM")?
        .split_whitespace()
        .next()?
        .parse()
        .ok()?;
    Some(kb / 1024.0)
}

/// `bench-splat`: caustic photons traced with differentials and splatted onto the eye
/// vertices, photons/s on 1 and 2 threads (median of `runs`), the number of eye vertices, and
/// the peak memory before and after splatting ten times more photons (flat if no photon is
/// kept).
pub fn splat(path: &Path, photons: u64, runs: usize) -> Result<(), String> {
    use render::splat::{Splatter, eye_index};
    let s = scene::Scene::load(path).map_err(|e| e.to_string())?;
    let settings = render::Settings::new(&s, &render::Overrides::default())?;
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

/// The height field of `bench-load`: a grid of `w` x `h` quads (two triangles each) over
/// [-1, 1]^2 in x and z, as an OBJ of positions and faces only (39 bytes a triangle).
fn height_field_obj(w: usize, h: usize) -> String {
    use std::fmt::Write;
    let mut s = String::with_capacity(40 * 2 * w * h);
    s += "# photonflow bench-load height field\n";
    for j in 0..=h {
        let z = -1.0 + 2.0 * j as f64 / h as f64;
        for i in 0..=w {
            let x = -1.0 + 2.0 * i as f64 / w as f64;
            let y = 0.2 + 0.1 * (9.0 * x).sin() * (7.0 * z).cos();
            let _ = writeln!(s, "v {x:.6} {y:.6} {z:.6}");
        }
    }
    let row = w + 1;
    for j in 0..h {
        for i in 0..w {
            let a = j * row + i + 1;
            let (b, c, d) = (a + 1, a + row, a + row + 1);
            let _ = writeln!(s, "f {a} {c} {b}\nf {b} {c} {d}");
        }
    }
    s
}

/// The scene around a mesh: a box of side 4 seen from inside, a square light under its top.
fn load_scene(obj: &str) -> String {
    format!(
        "name = \"bench-load\"\nseed = 1\n[camera]\neye = [0.0, 1.0, 3.0]\n\
         look_at = [0.0, 0.0, 0.0]\nvfov = 50.0\nwidth = 32\nheight = 32\n\
         [material.white]\ntype = \"lambertian\"\nalbedo = [0.8, 0.8, 0.8]\n\
         [[mesh]]\nshape = \"cube\"\nmaterial = \"white\"\nscale = 2.0\nflip_normals = true\n\
         [[mesh]]\nshape = \"rectangle\"\nmaterial = \"white\"\nscale = 0.5\n\
         rotate = [90, 0, 0]\ntranslate = [0, 1.9, 0]\nradiance = [10, 10, 10]\n\
         [[mesh]]\nobj = \"{obj}\"\nmaterial = \"white\"\n"
    )
}

/// Mitsuba 3's side of `bench-load`: the same OBJ and scene through `load_dict`.
const MITSUBA_LOAD: &str = r#"import sys, time, resource
import mitsuba as mi
mi.set_variant("llvm_ad_rgb")
t1 = time.perf_counter()
shape = mi.load_dict({"type": "obj", "filename": sys.argv[1], "bsdf": {"type": "diffuse"}})
t2 = time.perf_counter()
T = mi.ScalarTransform4f
scene = mi.load_dict({"type": "scene", "mesh": shape,
    "box": {"type": "cube", "to_world": T().scale(2.0), "flip_normals": True},
    "light": {"type": "rectangle",
              "to_world": T().translate([0, 1.9, 0]).rotate([1, 0, 0], 90).scale(0.5),
              "emitter": {"type": "area", "radiance": 10.0}}})
t3 = time.perf_counter()
print(f"parse {t2 - t1} build {t3 - t2} total {t3 - t1} peak_kib {resource.getrusage(resource.RUSAGE_SELF).ru_maxrss}")
"#;

/// One load's figures: parse, build and total seconds, peak MiB.
type LoadRun = [f64; 4];

/// One load in a fresh process (`who`'s): the figures it prints, or why it gave none.
fn load_run(child: &mut std::process::Command, who: &str) -> Result<LoadRun, String> {
    let out = child
        .output()
        .map_err(|e| format!("{who}: {:?}: {e}", child.get_program()))?;
    load_figures(&String::from_utf8_lossy(&out.stdout)).ok_or_else(|| {
        format!(
            "{who}'s load failed: {}",
            String::from_utf8_lossy(&out.stderr)
        )
    })
}

/// Reads `parse P build B total T peak_kib K` from a run's output.
fn load_figures(out: &str) -> Option<LoadRun> {
    let line = out.lines().rev().find(|l| l.starts_with("parse "))?;
    let w: Vec<&str> = line.split_whitespace().collect();
    let num = |k: &str| -> Option<f64> {
        let i = w.iter().position(|x| *x == k)?;
        w.get(i + 1)?.parse().ok()
    };
    Some([
        num("parse")?,
        num("build")?,
        num("total")?,
        num("peak_kib")? / 1024.0,
    ])
}

/// `bench-load --child SCENE`: loads the scene once and prints its figures.
pub fn load_child(scene: &Path) -> Result<(), String> {
    let start = Instant::now();
    let s = scene::Scene::load(scene).map_err(|e| e.to_string())?;
    let total = start.elapsed().as_secs_f64();
    let build = s.geometry.build_seconds();
    let kib = proc_status("VmHWM")
        .and_then(|v| v.split_whitespace().next()?.parse::<f64>().ok())
        .ok_or("no VmHWM in /proc/self/status")?;
    println!(
        "parse {} build {build} total {total} peak_kib {kib} triangles {}",
        total - build,
        s.geometry.mesh().len()
    );
    Ok(())
}

/// `bench-load`: per mesh size, `runs` loads by photonflow and (with `PEERS_VENV`) Mitsuba 3
/// alternately, each in its own process; medians of parse, build, total and peak memory.
pub fn load(sizes: &[usize], runs: usize, dir: &Path) -> Result<(), String> {
    std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    let exe = std::env::current_exe().map_err(|e| e.to_string())?;
    let python = std::env::var_os("PEERS_VENV").map(|v| Path::new(&v).join("bin/python"));
    let script = dir.join("mitsuba_load.py");
    std::fs::write(&script, MITSUBA_LOAD).map_err(|e| format!("{}: {e}", script.display()))?;
    println!(
        "| triangles | loader | parse s | BVH s | total s | peak MB | bytes/triangle | total / Mitsuba | peak / Mitsuba |"
    );
    println!("|---|---|---|---|---|---|---|---|---|");
    for &n in sizes {
        // w x h quads, w = 2h: 2 w h = n triangles (rounded).
        let h = ((n as f64 / 4.0).sqrt().round() as usize).max(1);
        let w = (n / (2 * h)).max(1);
        let tris = 2 * w * h;
        let obj = dir.join(format!("height-{w}x{h}.obj"));
        if !obj.exists() {
            let tmp = dir.join(format!(".height-{w}x{h}.obj.tmp"));
            std::fs::write(&tmp, height_field_obj(w, h))
                .and_then(|()| std::fs::rename(&tmp, &obj))
                .map_err(|e| format!("{}: {e}", obj.display()))?;
        }
        let toml = dir.join(format!("height-{w}x{h}.toml"));
        std::fs::write(&toml, load_scene(&format!("height-{w}x{h}.obj")))
            .map_err(|e| format!("{}: {e}", toml.display()))?;
        let mut ours: Vec<LoadRun> = Vec::new();
        let mut theirs: Vec<LoadRun> = Vec::new();
        for _ in 0..runs.max(1) {
            let mut child = std::process::Command::new(&exe);
            child.args(["bench-load", "--child"]).arg(&toml);
            ours.push(load_run(&mut child, "photonflow")?);
            if let Some(py) = &python {
                let mut child = std::process::Command::new(py);
                child.arg(&script).arg(&obj);
                theirs.push(load_run(&mut child, "Mitsuba")?);
            }
        }
        let median = |runs: &[LoadRun], k: usize| {
            let mut v: Vec<f64> = runs.iter().map(|r| r[k]).collect();
            if v.is_empty() {
                f64::NAN
            } else {
                median(&mut v)
            }
        };
        let ours_m: Vec<f64> = (0..4).map(|k| median(&ours, k)).collect();
        let theirs_m: Vec<f64> = (0..4).map(|k| median(&theirs, k)).collect();
        let row = |who: &str, m: &[f64], ratio: String| {
            println!(
                "| {tris} | {who} | {:.2} | {:.2} | {:.2} | {:.0} | {:.0} | {ratio} |",
                m[0],
                m[1],
                m[2],
                m[3] * 1.048576,
                m[3] * 1048576.0 / tris as f64
            );
        };
        if theirs.is_empty() {
            row("photonflow", &ours_m, "| ".to_string());
        } else {
            row(
                "photonflow",
                &ours_m,
                format!(
                    "{:.2} | {:.2}",
                    ours_m[2] / theirs_m[2],
                    ours_m[3] / theirs_m[3]
                ),
            );
            row("Mitsuba 3", &theirs_m, "1 | 1".to_string());
        }
    }
    println!(
        "\nmedians of {} run(s) per loader, alternating, each a fresh process; peak: VmHWM \
         (photonflow), ru_maxrss (Mitsuba: Python and the JIT included); Mitsuba's parse is \
         `load_dict` of the OBJ, its BVH the scene's `load_dict` around it",
        runs.max(1)
    );
    Ok(())
}
