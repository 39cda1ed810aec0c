//! The methods, one file each, behind one dispatch: [`spec`] matches `scene::Method` and
//! nothing else does; everything else asks the [`MethodSpec`] it returns. A method gets a [`Run`] (the scene, its settings, where photon sets are
//! cached and whether it may trace them) and returns [`Rendered`] layers, each tagged with
//! the light-path classes it estimates so that layers of separate runs can be composited
//! without counting a path twice.

mod caustic_splat;
mod final_gather;
mod global_direct;
mod path;
mod path_splat;
mod sppm;

pub use sppm::start_radius;

use crate::maps::Maps;
use crate::settings::Settings;
use emit::Plan;
use film::{Film, Image, Normalize};
use photons::cache::{self as photon_cache, CacheKey};
use scene::{Method, Scene};
use std::path::Path;
use store::MapKind;

/// Where a photon method gets its photon sets.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Photons {
    /// Reuse the cached sets or trace them (`render`).
    TraceOrReuse,
    /// Cached sets only, never trace (`estimate`: swap the estimator alone).
    CacheOnly,
}

/// One run's inputs.
pub struct Run<'a> {
    pub scene: &'a Scene,
    pub settings: &'a Settings,
    /// Photon cache directory.
    pub cache: &'a Path,
    pub photons: Photons,
    /// Worker threads (`None`: all cores). Never changes an image.
    pub threads: Option<usize>,
}

impl Run<'_> {
    pub fn threads(&self) -> usize {
        self.threads.unwrap_or_else(rayon::current_num_threads)
    }

    pub(crate) fn render_options(&self, spp: u32) -> eye::RenderOptions {
        eye::RenderOptions {
            spp,
            first_sample: 0,
            caustics: true,
            caustic_indirect: true,
            threads: self.threads,
            tile: self.settings.render.tile,
        }
    }
}

/// One layer of an image: its name, the light-path classes (`film::Class`) it estimates, its
/// pixels (already divided by the sample count), and its weight when runs are composited:
/// samples per pixel for layers the eye pass estimates alone, photon paths for layers made
/// from photons.
pub struct Layer {
    pub name: String,
    pub classes: Vec<film::Class>,
    pub image: Image,
    pub count: u64,
    pub count_kind: CountKind,
}

/// What a method made.
pub struct Rendered {
    pub layers: Vec<Layer>,
    /// The effects plan, for photon methods.
    pub plan: Option<Plan>,
    /// Method-specific facts for `image.json` (settings used, photon counts, timings).
    pub info: serde_json::Map<String, serde_json::Value>,
    /// Photon passes made, for progressive methods (the resolved scene records them).
    pub passes: Option<u32>,
    /// Path-traced samples per pixel made (recorded as `render.spp`: a time budget may stop
    /// the path tracer early).
    pub samples: Option<u32>,
    /// The image after 1, 2, 4, 8, ... passes and the last, for progressive methods: one
    /// run gives an error-against-time series.
    pub snapshots: Vec<Snapshot>,
}

/// A progressive method's image after some passes.
pub struct Snapshot {
    pub passes: u32,
    /// Seconds since the passes began.
    pub seconds: f64,
    pub layers: Vec<Layer>,
}

/// What a layer's count counts: the compositing stage's own type, so `image.json` is spelled
/// in one place.
pub use composite::CountKind;

/// What the rest of the program needs to know of a method.
pub struct MethodSpec {
    pub render: RenderFn,
    /// Its run as independent blocks of work, which shards split (`None`: it cannot be
    /// split exactly, and the string says why).
    pub blocks: Result<BlocksFn, &'static str>,
    /// It reads photon maps: `estimate` may run it from cached photon sets.
    pub photon_maps: bool,
    /// Its samples per pixel (and `--spp`) are `[estimate] spp` (else `[render] spp`, the
    /// path tracer's).
    pub estimate_spp: bool,
    /// Its progress counts splatted photons (else pixel samples).
    pub splat_progress: bool,
}

type RenderFn = fn(&Run, &(dyn Fn(u64) + Sync)) -> Result<Rendered, String>;

/// A method's run as blocks: an accumulator, the blocks of the whole run in the order they
/// are added, and what their indices count.
pub type BlocksFn = for<'a> fn(&'a Run<'a>) -> Blocks<'a>;

/// What [`BlocksFn`] returns.
pub struct Blocks<'a> {
    pub acc: Box<dyn Accumulate + 'a>,
    pub blocks: Vec<std::ops::Range<u64>>,
    /// What block indices count: "samples per pixel" or "passes".
    pub unit: &'static str,
}

/// A run accumulated block by block: the one-machine run renders every block and adds it;
/// a shard renders some and writes their sums; a merge adds every shard's sums in order.
/// Both add with [`Accumulate::add`] from zero in block order, so they agree bit for bit.
pub trait Accumulate {
    /// The layers, in the order a block's sums come in.
    fn layer_names(&self) -> Vec<String>;
    /// f64 sums per pixel of `block` alone, per layer.
    fn block(
        &mut self,
        block: std::ops::Range<u64>,
        progress: &(dyn Fn(u64) + Sync),
    ) -> Result<Vec<Vec<glam::DVec3>>, String>;
    /// Adds a block's sums (`n` indices of it).
    fn add(&mut self, sums: &[Vec<glam::DVec3>], n: u64);
    /// The run after every block was added; `seconds` the time its blocks took.
    fn finish(&self, seconds: f64) -> Rendered;
}

/// The one `match` on `scene::Method`.
pub fn spec(method: Method) -> MethodSpec {
    // (render, photon maps, estimate spp, splat progress)
    let (render, photon_maps, estimate_spp, splat_progress): (RenderFn, bool, bool, bool) =
        match method {
            Method::Path => (path::render, false, false, false),
            Method::GlobalDirect => (global_direct::render, true, true, false),
            Method::FinalGather => (final_gather::render, true, true, false),
            Method::CausticSplat => (caustic_splat::render, false, true, true),
            // The path tracer's spp; its splat's eye vertices take `[estimate] spp`.
            Method::PathSplat => (path_splat::render, false, false, false),
            // One camera sample per pixel and pass; progress counts them.
            Method::Sppm => (sppm::render, false, false, false),
        };
    let blocks: Result<BlocksFn, &'static str> = match method {
        Method::Path => Ok(path::blocks),
        Method::CausticSplat => Ok(caustic_splat::blocks),
        Method::Sppm => Err(
            "sppm's passes depend on each other (every pass shrinks the radii the next one \
             gathers in), so no range of them can run apart: shard `caustic-splat` or \
             `path`, or render independent seeds and `composite` them",
        ),
        Method::PathSplat => Err(
            "path+splat interleaves two progressions: shard `path --no-caustics` and \
             `caustic-splat` apart and `composite` the two merged runs",
        ),
        Method::GlobalDirect | Method::FinalGather => Err(
            "the photon-map methods estimate from one photon map: shard `trace`, `merge` \
             its photon sets into the cache, then `estimate`",
        ),
    };
    MethodSpec {
        render,
        blocks,
        photon_maps,
        estimate_spp,
        splat_progress,
    }
}

/// Runs the method the settings name.
pub fn render(run: &Run, progress: &(dyn Fn(u64) + Sync)) -> Result<Rendered, String> {
    if run.threads == Some(0) {
        return Err("--threads must be at least 1".into());
    }
    (spec(run.settings.method).render)(run, progress)
}

/// Total work units (samples) of a run, for a progress bar.
pub fn work(run: &Run) -> u64 {
    let (w, h) = (
        run.scene.camera.width as u64,
        run.scene.camera.height as u64,
    );
    let samples = match run.settings.method {
        Method::Sppm => run.settings.estimate.sppm.passes,
        _ => run.settings.spp(),
    };
    w * h * samples as u64
}

/// How one film layer is described: name, classes, count, count kind.
pub(crate) type LayerSpec<'a> = (&'a str, &'a [film::Class], u64, CountKind);

/// The film's layers divided by `spp`, tagged with their classes and counts. A layer the film
/// lacks is an error (an image silently missing light is worse than none).
pub(crate) fn layers(film: &Film, spp: u32, specs: &[LayerSpec]) -> Result<Vec<Layer>, String> {
    specs
        .iter()
        .map(|&(name, cls, count, count_kind)| {
            let layer = film
                .layer(name)
                .ok_or_else(|| format!("the eye pass wrote no `{name}` layer"))?;
            Ok(Layer {
                name: name.to_string(),
                classes: cls.to_vec(),
                image: layer.resolve(Normalize::Constant(spp as f64)),
                count,
                count_kind,
            })
        })
        .collect()
}

/// Photon maps for a photon method: the plan's sets `needed` (traced or reused, or read from
/// the cache only), after refusing settings that would silently darken a layer.
pub(crate) struct PhotonInputs<'a> {
    pub plan: Plan,
    pub maps: Maps<'a>,
    pub seconds_trace: f64,
    pub reused: bool,
    pub seconds_load: f64,
}

pub(crate) fn photon_inputs<'a>(
    run: &Run<'a>,
    needs_caustic: bool,
) -> Result<PhotonInputs<'a>, String> {
    let scene = run.scene;
    let s = run.settings;
    let params = &s.emit;
    let plan =
        Plan::for_scene(scene, params).map_err(|e| format!("{}: {e}", scene.path.display()))?;
    // These methods read the global map as the full light arriving at a surface, direct hits
    // included; final gathering also needs the caustic map wherever the scene can make
    // caustics. A missing set would silently darken a layer, so it is an error.
    let mut params_per_kind = store::PerKind::default();
    params_per_kind[MapKind::Global] = s.estimate.global;
    params_per_kind[MapKind::Caustic] = s.estimate.caustic;
    // A scene with no diffuse surface (all black, or only mirrors and glass) is valid: no
    // photon can be stored or seen, every photon layer is black, and the plan says why.
    if params.global && !plan.global {
        print!("{plan}");
        return Ok(PhotonInputs {
            plan,
            maps: Maps {
                maps: store::PerKind::default(),
                params: params_per_kind,
                boundary: None,
                gather_cache: None,
            },
            seconds_trace: 0.0,
            reused: true,
            seconds_load: 0.0,
        });
    }
    let incomplete = if !plan.global {
        Some("[photons] global = false: the effects plan traces no global photons")
    } else if !params.store_direct {
        Some(
            "[photons] store_direct = false leaves direct light out of the global map these methods read",
        )
    } else if needs_caustic && !params.caustic && scene.materials.iter().any(|m| m.is_specular()) {
        Some("[photons] caustic = false leaves the caustic layer of final gathering empty")
    } else {
        None
    };
    if let Some(why) = incomplete {
        return Err(format!("{}: {why}", scene.path.display()));
    }
    let (seconds_trace, reused) = match run.photons {
        Photons::TraceOrReuse => {
            let t = photon_cache::trace(scene, params, run.cache, run.threads(), false)?;
            (t.seconds, t.reused)
        }
        Photons::CacheOnly => (0.0, true),
    };
    let t0 = std::time::Instant::now();
    let key = CacheKey::new(scene, params);
    let kinds: Vec<MapKind> = if needs_caustic {
        photon_cache::planned_kinds(&plan)
    } else {
        vec![MapKind::Global]
    };
    let maps = crate::maps::load(run.cache, &key, &kinds)?;
    Ok(PhotonInputs {
        plan,
        maps: Maps {
            maps,
            params: params_per_kind,
            boundary: s.estimate.boundary.then_some(scene),
            gather_cache: None,
        },
        seconds_trace,
        reused,
        seconds_load: t0.elapsed().as_secs_f64(),
    })
}

/// The JSON facts every photon method records.
pub(crate) fn photon_info(
    run: &Run,
    inputs: &PhotonInputs,
) -> serde_json::Map<String, serde_json::Value> {
    let s = run.settings;
    let count = |k: MapKind| inputs.maps.maps[k].as_ref().map_or(0, |m| m.len());
    let mut j = serde_json::Map::new();
    let mut put = |k: &str, v: serde_json::Value| {
        j.insert(k.to_string(), v);
    };
    put("spp", s.estimate.spp.into());
    put("photons_emitted", s.emit.photons.into());
    put("global_photons", count(MapKind::Global).into());
    put("caustic_photons", count(MapKind::Caustic).into());
    put("global_estimate", serde_json::json!(s.estimate.global));
    put("caustic_estimate", serde_json::json!(s.estimate.caustic));
    put(
        "kernel",
        crate::settings::kernel_name(s.estimate.global.kernel).into(),
    );
    put("boundary_correction", s.estimate.boundary.into());
    put(
        "trace",
        if inputs.reused { "reused" } else { "traced" }.into(),
    );
    put("time_trace_s", inputs.seconds_trace.into());
    put("time_load_and_index_s", inputs.seconds_load.into());
    j
}
