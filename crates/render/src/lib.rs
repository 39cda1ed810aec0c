//! `render`: the eye side of photonflow wired as a library, so that everything a command
//! does can be called (and tested) in one process. The binary `photonflow` parses flags and
//! calls [`render`] or [`trace`]; `lab` and the end-to-end tests call it the same way.
//!
//! - [`settings`]: the scene file's `[photons]` and `[estimate]` tables, typed, with the
//!   command line's overrides; the resolved scene file every output directory holds.
//! - [`methods`]: the method table (one row per method: what it reads, where `--spp` and
//!   `--passes` go, how it shards) and one file per method; [`passes`]: the one progressive
//!   pass loop.
//! - [`maps`], [`gather_cache`], [`boundary`]: the photon maps behind the eye pass (loaded
//!   from the `photons` cache), the irradiance cache of final gathering, the boundary-bias
//!   correction.
//! - [`splat`]: the splatting stage on the channel pipeline (the accumulation itself is
//!   `density::splat`'s).
//! - [`output`]: a run's directory (EXR, PNG, layers, `image.json`, resolved scene).
//! - [`shard`]: image shards and `merge`.

pub mod boundary;
pub mod gather_cache;
pub mod maps;
pub mod methods;
pub mod output;
pub mod passes;
pub mod rendered;
pub mod run;
pub mod settings;
pub mod shard;
pub mod splat;

#[cfg(test)]
mod tests;

pub use rendered::{Layer, Rendered};
pub use run::{Photons, Run};
pub use settings::{EstimateSettings, MAX_TIME, Overrides, Settings, check_time};

use flow::Progress;
use scene::Scene;
use std::path::{Path, PathBuf};

/// One `render` or `estimate` command.
pub struct RenderRequest<'a> {
    pub overrides: Overrides,
    pub cache: &'a Path,
    pub photons: Photons,
    pub threads: Option<usize>,
    /// Output directory.
    pub out: PathBuf,
    pub exposure: f32,
    pub reference: Option<&'a Path>,
    /// The output directory's method part (default: the method's name).
    pub label: Option<String>,
}

/// What a command produced.
pub struct RenderSummary {
    pub out: PathBuf,
    pub settings: Settings,
    pub image: film::Image,
    pub metrics: Option<film::Metrics>,
    pub seconds: f64,
}

/// Renders `scene` with the request's settings and writes the run's directory.
pub fn render(scene: &Scene, req: &RenderRequest) -> Result<RenderSummary, String> {
    let t0 = std::time::Instant::now();
    let settings = Settings::new(scene, &req.overrides)?;
    settings.check_pass_photons(
        scene,
        &req.overrides,
        &methods::row(settings.method).flags(),
    )?;
    let run = Run {
        scene,
        settings: &settings,
        cache: req.cache,
        photons: req.photons,
        threads: req.threads,
    };
    let label = req.label.clone().unwrap_or_else(|| settings.method.name());
    let out = req.out.clone();
    // Everything that can refuse the run is checked before the render starts.
    let reference = match req.reference {
        Some(p) => Some((p, read_reference(scene, p)?)),
        None => None,
    };
    if !req.exposure.is_finite() {
        return Err(format!("--exposure {} must be finite", req.exposure));
    }
    output::check_out(&out)?;
    // The bar starts with the eye pass's first finished tile, so tracing and loading photons
    // (which report on their own) neither share the terminal line nor its rate.
    let bar = std::sync::OnceLock::new();
    let (work, unit) = methods::work(&run);
    let name = settings.method.name();
    // A time budget alone ends the passes, not a count a bar could fill.
    let open = settings.time.is_some_and(|b| !b.capped);
    let rendered = methods::render(&run, &|n| {
        bar.get_or_init(|| match open {
            true => Progress::unbounded(&name, unit),
            false => Progress::new(&name, work, unit),
        })
        .inc(n)
    })?;
    if let Some(p) = bar.into_inner() {
        p.finish();
    }
    let seconds = t0.elapsed().as_secs_f64();
    let (image, metrics) = output::write(
        scene,
        &settings,
        &rendered,
        &output::OutputOptions {
            out: &out,
            exposure: req.exposure,
            reference: reference.as_ref().map(|(p, i)| (*p, i)),
            label: &label,
            threads: run.threads(),
            seconds,
        },
    )?;
    Ok(RenderSummary {
        out,
        settings,
        image,
        metrics,
        seconds,
    })
}

/// A reference image for `scene`, refused unless it can serve: readable, of the scene's
/// size, every pixel finite (errors against NaN or infinity are undefined). Callers read it
/// before they write anything, so a run that cannot succeed leaves no output.
pub fn read_reference(scene: &Scene, p: &Path) -> Result<film::Image, String> {
    let img = output::read_finite(p, "reference pixels")?;
    let (w, h) = (scene.camera.width as usize, scene.camera.height as usize);
    if (img.width, img.height) != (w, h) {
        return Err(format!(
            "{}: reference is {}x{}, the scene renders {w}x{h}",
            p.display(),
            img.width,
            img.height
        ));
    }
    Ok(img)
}

/// Traces (or reuses) the photon sets `scene` needs into `cache`.
pub fn trace(
    scene: &Scene,
    overrides: &Overrides,
    cache: &Path,
    threads: Option<usize>,
    force: bool,
) -> Result<photons::TraceOutput, String> {
    let settings = Settings::new(scene, overrides)?;
    let threads = threads.unwrap_or_else(rayon::current_num_threads);
    photons::trace(scene, &settings.emit, cache, threads, force)
}

/// `trace --shard I/N`: the shard's photon paths of the run `overrides` describe, into `out`.
pub fn trace_shard(
    scene: &Scene,
    overrides: &Overrides,
    shard: photons::shard::ShardId,
    out: &Path,
    threads: Option<usize>,
) -> Result<photons::shard::Manifest, String> {
    let settings = Settings::new(scene, overrides)?;
    let threads = threads.unwrap_or_else(rayon::current_num_threads);
    photons::shard::trace(scene, &settings.emit, shard, out, threads)
}

/// What a scene holds, for `photonflow info`: triangles, spheres, lights and their power,
/// materials, bounds, camera, content hash.
pub fn describe(s: &Scene) -> String {
    use std::fmt::Write as _;
    let mut o = String::new();
    let m = s.geometry.mesh();
    let _ = writeln!(o, "scene      {} ({})", s.path.display(), s.file.name);
    let _ = writeln!(o, "triangles  {}", m.len());
    let _ = writeln!(o, "spheres    {}", s.geometry.spheres().len());
    let _ = writeln!(
        o,
        "lights     {}",
        s.light_table.summary(s.light_area(), s.light_power())
    );
    for (name, mat) in s.material_names.iter().zip(&s.materials) {
        let _ = writeln!(o, "material   {name}: {mat:?}");
    }
    let b = s.geometry.bounds();
    let _ = writeln!(
        o,
        "bounds     {:?} .. {:?}",
        b.min.to_array(),
        b.max.to_array()
    );
    let _ = writeln!(
        o,
        "camera     {}x{}, vfov {}",
        s.camera.width, s.camera.height, s.camera.vfov_deg
    );
    let _ = writeln!(o, "hash       {:016x}", s.content_hash);
    o
}
