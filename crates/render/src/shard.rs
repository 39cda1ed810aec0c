//! Image shards (`render --shard I/N`, `path` and `caustic-splat`) and `merge`. An image shard
//! renders the blocks of the run ([`crate::run::Accumulate`]: the path tracer's passes of
//! samples, splatting's passes) that start in the shard's range, and writes each block's f64
//! sums per pixel; merging adds every block from zero in block order, exactly as the
//! one-machine run adds them, and writes the same `image.exr` and `layers/`. The shard
//! directory format and photon shards are `photons::shard`'s.

use crate::methods;
use crate::run::Run;
use crate::settings::{Overrides, Settings};
use composite::shards::cover;
use flow::Progress;
use glam::DVec3;
pub use photons::shard::ShardId;
use photons::shard::{Input, MANIFEST, Manifest, VERSION, hex, publish, start};
use scene::Scene;
use std::ops::Range;
use std::path::{Path, PathBuf};

/// The f64 block sums of an image shard (`film::write_sums`), block by block, layer by layer.
pub const SUMS: &str = "sums.f64";

/// `render --shard I/N`: renders the shard's blocks of the run `run` describes into `out`.
pub fn render(run: &Run, shard: ShardId, out: &Path) -> Result<Manifest, String> {
    let (scene, settings) = (run.scene, run.settings);
    let method = settings.method;
    let blocks_fn = methods::row(method)
        .blocks
        .map_err(|why| format!("--shard cannot split `{method}`: {why}"))?;
    if settings.time.is_some() {
        return Err(
            "--shard with --time: a time budget makes the work depend on the machine; give \
             the full budget (--spp or --passes) instead"
                .into(),
        );
    }
    let scene_text = settings.resolved_scene_text(scene)?;
    let mut b = blocks_fn(run);
    let total = b.blocks.len() as u64;
    check_split(&b.blocks, b.unit, shard)?;
    let mine = shard.blocks(&b.blocks, b.blocks.last().map_or(0, |r| r.end));
    let layers = b.acc.layer_names();
    let tmp = start(out)?;
    let t0 = std::time::Instant::now();
    let (w, h) = (scene.camera.width as usize, scene.camera.height as usize);
    let mut planes = Vec::new();
    let mut count = 0;
    let work: u64 = b.blocks[mine.clone()].iter().map(|r| r.end - r.start).sum();
    let progress = Progress::new(&format!("{method} shard {shard}"), work, b.unit);
    for r in &b.blocks[mine.clone()] {
        let sums = b.acc.block(r.clone(), &|n| progress.inc(n))?;
        count += r.end - r.start;
        planes.extend(
            sums.into_iter()
                .map(|p| p.into_iter().map(|v| v.to_array()).collect::<Vec<_>>()),
        );
    }
    progress.finish();
    let sums = film::Sums {
        width: w,
        height: h,
        planes,
    };
    film::write_sums(&tmp.path().join(SUMS), &sums).map_err(|e| e.to_string())?;
    film::write_atomic(&tmp.path().join("scene.toml"), scene_text.as_bytes())
        .map_err(|e| e.to_string())?;
    let m = Manifest {
        photonflow_shard: VERSION,
        what: "image".into(),
        method: Some(method.name()),
        scene: scene.path.display().to_string(),
        scene_hash: hex(scene.view_hash),
        seed: scene.seed(),
        params_hash: hex(settings.hash(scene)),
        shard: shard.to_string(),
        unit: b.unit.into(),
        range: [mine.start as u64, mine.end as u64],
        total,
        blocks: b.blocks.iter().map(|r| [r.start, r.end]).collect(),
        layers,
        sets: Vec::new(),
        count,
        seconds: t0.elapsed().as_secs_f64(),
    };
    publish(tmp, out, &m)?;
    Ok(m)
}

/// Refuses a shard count that leaves some shard of the set without a block: blocks are never
/// split, so more shards than blocks (or uneven blocks split too finely) make empty shards,
/// which every task of the set would publish as finished work. The whole set is checked, not
/// only `shard`, so that its tasks all run or all refuse.
fn check_split(blocks: &[Range<u64>], unit: &str, shard: ShardId) -> Result<(), String> {
    let end = blocks.last().map_or(0, |r| r.end);
    let n = blocks.len();
    if shard.count as usize > n {
        return Err(format!(
            "--shard {shard}: the run has {n} blocks ({end} {unit}), which {} shards cannot \
             share without empty ones; N must be at most {n}",
            shard.count
        ));
    }
    let empty = |count: u32| {
        (0..count)
            .map(|index| ShardId { index, count })
            .find(|s| s.blocks(blocks, end).is_empty())
    };
    if let Some(e) = empty(shard.count) {
        // At most n tries of at most n shards each: n is the path tracer's few passes here
        // (blocks of equal size, splatting's passes, never leave a shard empty).
        let fits = (1..shard.count)
            .rev()
            .find(|&c| empty(c).is_none())
            .unwrap_or(1);
        return Err(format!(
            "--shard {shard}: the run's {n} blocks ({end} {unit}, of uneven sizes) leave shard \
             {e} without one; N must be at most {fits} here"
        ));
    }
    Ok(())
}

/// `merge`: the shards `inputs` put back together into `out`: photon sets into `out` as a
/// cache directory, images into `out` as a run directory. Everything is read and checked
/// before anything is written.
pub fn merge(inputs: &[PathBuf], out: &Path) -> Result<String, String> {
    let (all, parts) = photons::shard::read_all(inputs, out)?;
    let a = &all[0];
    match a.m.what.as_str() {
        "photons" => photons::shard::merge_photons(&all, &parts, out),
        "image" => {
            let blocks: Vec<std::ops::Range<u64>> = a.m.blocks.iter().map(|b| b[0]..b[1]).collect();
            let end = blocks.last().map_or(0, |r| r.end);
            let expect = |s: ShardId| {
                let r = s.blocks(&blocks, end);
                r.start as u64..r.end as u64
            };
            let order = cover(&parts, a.m.total, &expect)?;
            merge_image(&all, &order, out)
        }
        other => Err(format!(
            "{}: holds `{other}`, neither photons nor an image",
            a.dir.display()
        )),
    }
}

fn merge_image(all: &[Input], order: &[usize], out: &Path) -> Result<String, String> {
    crate::output::check_out(out)?;
    let a = &all[0];
    let scene_file = a.dir.join("scene.toml");
    // The shard's resolved scene: its settings are the run's, flags and all.
    let scene = Scene::load(&scene_file).map_err(|e| e.to_string())?;
    let settings = Settings::new(&scene, &Overrides::default())?;
    let m0 = a.dir.join(MANIFEST);
    if hex(scene.view_hash) != a.m.scene_hash
        || scene.seed() != a.m.seed
        || hex(settings.hash(&scene)) != a.m.params_hash
    {
        return Err(format!(
            "{}: the scene (or a file it names) changed since {} was rendered",
            scene_file.display(),
            m0.display()
        ));
    }
    let run = Run {
        scene: &scene,
        settings: &settings,
        cache: Path::new("."),
        photons: crate::run::Photons::CacheOnly,
        threads: Some(1),
    };
    let blocks_fn = methods::row(settings.method)
        .blocks
        .map_err(|why| format!("{}: {why}", m0.display()))?;
    let mut b = blocks_fn(&run);
    let blocks: Vec<[u64; 2]> = b.blocks.iter().map(|r| [r.start, r.end]).collect();
    if blocks != a.m.blocks || b.acc.layer_names() != a.m.layers {
        return Err(format!(
            "{}: its blocks or layers are not those this photonflow renders for its scene",
            m0.display()
        ));
    }
    let (w, h) = (scene.camera.width as usize, scene.camera.height as usize);
    let nl = a.m.layers.len();
    // Read and check every shard's sums before any output; added one shard at a time.
    let mut sums = Vec::with_capacity(order.len());
    for &i in order {
        let inp = &all[i];
        let path = inp.dir.join(SUMS);
        let s = film::read_sums(&path).map_err(|e| e.to_string())?;
        let nb = (inp.m.range[1] - inp.m.range[0]) as usize;
        if (s.width, s.height, s.planes.len()) != (w, h, nb * nl) {
            return Err(format!(
                "{}: {}x{} in {} planes, but the shard's {nb} blocks of {nl} layers of the \
                 {w}x{h} view need {}",
                path.display(),
                s.width,
                s.height,
                s.planes.len(),
                nb * nl
            ));
        }
        // The checksum only says the bytes are the ones written: a NaN written with its CRC
        // resealed would pass it, and turn every pixel it is added to into NaN.
        if let Some((k, i, v)) = s.planes.iter().enumerate().find_map(|(k, p)| {
            p.iter()
                .position(|v| !v.iter().all(|c| c.is_finite()))
                .map(|i| (k, i, p[i]))
        }) {
            return Err(format!(
                "{}: plane {k} (layer {}), pixel ({}, {}) holds {:?}: a render's sums are finite",
                path.display(),
                a.m.layers.get(k % nl.max(1)).map_or("?", |l| l.as_str()),
                i % w.max(1),
                i / w.max(1),
                v
            ));
        }
        sums.push(s);
    }
    let mut seconds = 0.0;
    for (&i, s) in order.iter().zip(sums) {
        let inp = &all[i];
        seconds += inp.m.seconds;
        let first = inp.m.range[0] as usize;
        let mut planes = s.planes.into_iter();
        for r in &b.blocks[first..inp.m.range[1] as usize] {
            let block: Vec<Vec<DVec3>> = planes
                .by_ref()
                .take(nl)
                .map(|p| p.into_iter().map(DVec3::from_array).collect())
                .collect();
            b.acc.add(&block, r.end - r.start);
        }
    }
    let rendered = b.acc.finish(seconds);
    let label = settings.method.name();
    crate::output::write(
        &scene,
        &settings,
        &rendered,
        &crate::output::OutputOptions {
            out,
            exposure: 0.0,
            reference: None,
            label: &label,
            threads: 0,
            seconds,
        },
    )?;
    Ok(format!(
        "merged {} shards of {label} ({} {}) into {}/image.{{exr,png,json}}, layers/, scene.toml",
        order.len(),
        b.blocks.last().map_or(0, |r| r.end),
        a.m.unit,
        out.display()
    ))
}
