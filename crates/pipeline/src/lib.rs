//! `pipeline`: the stages wired together as a library, so that everything a command does can
//! be called (and tested) in one process. The binary `photonflow` parses flags, picks paths
//! and calls [`render`] or [`trace`]; the end-to-end tests in `tests/` call the library the
//! same way.
//!
//! - [`settings`]: the scene file's `[photons]` and `[estimate]` tables, typed, with the
//!   command line's overrides; the resolved scene file every output directory holds.
//! - [`flow`]: the channel pipeline (emission workers → bounded channel → chunks in index
//!   order → [`flow::Sink`]s: the photon file writer, or any stage behind a channel).
//! - [`photon_cache`]: cached photon sets keyed by what they depend on, traced on demand,
//!   loaded as photon maps.
//! - [`maps`], [`gather_cache`], [`boundary`]: the photon maps behind the eye pass, the
//!   irradiance cache of final gathering, the boundary-bias correction.
//! - [`methods`]: one file per method, one `match` on `scene::Method`.
//! - [`output`]: a run's directory (EXR, PNG, layers, JSON, resolved scene).
//! - [`worksheet`]: worksheet 7's report.
//! - [`shard`]: a run split into shards by index ranges, and their exact merge.
//!
//! File IO happens only at paths the caller passes in.

pub mod accuracy;
pub mod bench;
pub mod boundary;
pub mod evidence;
pub mod flow;
pub mod gather_cache;
pub mod maps;
pub mod methods;
pub mod output;
pub mod photon_cache;
pub mod plots;
pub mod progress;
pub mod report;
pub mod settings;
pub mod shard;
pub mod splat;
pub mod worksheet;

#[cfg(test)]
mod tests;

pub use methods::{Photons, Rendered, Run};
pub use settings::{EstimateSettings, Overrides, Settings};

use progress::Progress;
use scene::Scene;
use std::path::{Path, PathBuf};

/// One `render` or `estimate` command.
pub struct RenderRequest<'a> {
    pub overrides: Overrides,
    pub cache: &'a Path,
    pub photons: Photons,
    pub threads: Option<usize>,
    /// Output directory; `None`: [`output::default_out`] of the label.
    pub out: Option<PathBuf>,
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
    let run = Run {
        scene,
        settings: &settings,
        cache: req.cache,
        photons: req.photons,
        threads: req.threads,
    };
    let label = req.label.clone().unwrap_or_else(|| settings.method.name());
    let out = req
        .out
        .clone()
        .unwrap_or_else(|| output::default_out(&scene.path, &label));
    // Everything that can refuse the run is checked before the render starts.
    let reference = match req.reference {
        Some(p) => Some((p, read_reference(scene, p)?)),
        None => None,
    };
    if !req.exposure.is_finite() {
        return Err(format!("--exposure {} must be finite", req.exposure));
    }
    // The bar starts with the eye pass's first finished tile, so tracing and loading photons
    // (which report on their own) neither share the terminal line nor its rate.
    let bar = std::sync::OnceLock::new();
    let work = methods::work(&run);
    let name = settings.method.name();
    let rendered = methods::render(&run, &|n| {
        bar.get_or_init(|| Progress::new(&name, work, "samples"))
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
    let img = output::read_exr(p)?;
    let (w, h) = (scene.camera.width as usize, scene.camera.height as usize);
    if (img.width, img.height) != (w, h) {
        return Err(format!(
            "{}: reference is {}x{}, the scene renders {w}x{h}",
            p.display(),
            img.width,
            img.height
        ));
    }
    let bad = img
        .data
        .iter()
        .filter(|px| !px.iter().all(|c| c.is_finite()))
        .count();
    if bad > 0 {
        return Err(format!(
            "{}: {bad} of {} reference pixels are not finite (NaN or infinity)",
            p.display(),
            img.data.len()
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
) -> Result<photon_cache::TraceOutput, String> {
    let settings = Settings::new(scene, overrides)?;
    let threads = threads.unwrap_or_else(rayon::current_num_threads);
    photon_cache::trace(scene, &settings.emit, cache, threads, force)
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
        "lights     {} emissive triangles, area {:.6}, power {:?}",
        s.lights.len(),
        s.light_area(),
        s.light_power().to_array()
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
