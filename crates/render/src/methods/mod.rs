//! The methods, one file each, behind one table: [`METHODS`] has a row per method saying what
//! it reads, where `--spp` and `--passes` go, how the passes it made are recorded, what its
//! progress counts, whether it shards, and its `--help` line; everything else asks the row
//! ([`row`]). A method gets a [`Run`] (the scene, its settings, where photon sets are cached
//! and whether it may trace them) and returns [`Rendered`] layers, each tagged with the
//! light-path classes it estimates so that layers of separate runs can be composited without
//! counting a path twice. The progressive methods run in `crate::passes`' one loop.

mod caustic_splat;
mod final_gather;
mod global_direct;
mod path;
mod path_splat;
mod sppm;

pub use sppm::start_radius;

use crate::maps::Maps;
use crate::settings::{Flags, Knob, Overrides, Settings};
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

impl Rendered {
    /// Layers and facts, nothing else: no plan, passes, samples or snapshots.
    pub fn new(layers: Vec<Layer>, info: serde_json::Map<String, serde_json::Value>) -> Rendered {
        Rendered {
            layers,
            plan: None,
            info,
            passes: None,
            samples: None,
            snapshots: Vec::new(),
        }
    }
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

/// What a method reads besides the scene.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Input {
    /// Eye paths of the path tracer.
    EyePaths,
    /// Cached photon maps (`estimate` may run the method from them alone).
    PhotonMaps,
    /// Eye vertices (E S* D) that caustic photons are splatted onto.
    EyeVertices,
    /// SPPM's visible points, one per pixel and pass.
    VisiblePoints,
}

/// What a method's progress bar counts, in total.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Work {
    /// Pixel samples: width x height x the knob.
    PixelSamples(Knob),
    /// Caustic photon paths splatted: per pass x passes (`[estimate.splat]`).
    SplatPhotons,
}

/// One row of the method table: everything the rest of the program asks of a method.
pub struct MethodRow {
    pub method: Method,
    /// Its line in `--help` and in README's method list.
    pub help: &'static str,
    /// Its knobs in the scene file.
    pub table: &'static str,
    pub reads: &'static [Input],
    /// Where `--spp` goes (`None`: refused).
    pub spp: Option<Knob>,
    /// Where `--passes` goes and where the passes a run made are recorded (`None`: it
    /// renders in one go, and refuses `--passes` and `--time`). Samples per pixel a run
    /// made are recorded as `[render] spp`.
    pub passes: Option<Knob>,
    pub work: Work,
    /// It renders the whole image (else only the layers of the classes it names).
    pub whole_image: bool,
    pub render: RenderFn,
    /// Its run as independent blocks of work, which shards split (`Err`: it cannot be
    /// split exactly, and the string says why).
    pub blocks: Result<BlocksFn, &'static str>,
}

impl MethodRow {
    /// What [`Settings::parse`] needs of the row.
    pub fn flags(&self) -> Flags {
        Flags {
            spp: self.spp,
            passes: self.passes,
            path_tracer: self.reads.contains(&Input::EyePaths),
        }
    }

    /// It reads photon maps: `estimate` may run it from cached photon sets.
    pub fn reads_photon_maps(&self) -> bool {
        self.reads.contains(&Input::PhotonMaps)
    }
}

/// The method table: one row per `scene::Method`, in `Method::ALL`'s order. Nothing else
/// matches on `Method`.
pub static METHODS: [MethodRow; 6] = [
    MethodRow {
        method: Method::Path,
        help: "the path-traced reference: next-event estimation and BSDF sampling by MIS, in \
               passes of samples per pixel",
        table: "[render]",
        reads: &[Input::EyePaths],
        spp: Some(Knob::RenderSpp),
        // The path tracer's passes are samples per pixel.
        passes: Some(Knob::RenderSpp),
        work: Work::PixelSamples(Knob::RenderSpp),
        whole_image: true,
        render: path::render,
        blocks: Ok(path::blocks),
    },
    MethodRow {
        method: Method::GlobalDirect,
        help: "the global photon map shown directly at the first diffuse surface seen \
               (trace or reuse the photons, then estimate)",
        table: "[estimate.global]",
        reads: &[Input::PhotonMaps],
        spp: Some(Knob::EstimateSpp),
        passes: None,
        work: Work::PixelSamples(Knob::EstimateSpp),
        whole_image: true,
        render: global_direct::render,
        blocks: Err(PHOTON_MAP_SHARDS),
    },
    MethodRow {
        method: Method::FinalGather,
        help: "next-event estimation, the caustic map and final gathering into the global \
               map through an irradiance cache (Christensen 1999)",
        table: "[estimate.final_gather]",
        reads: &[Input::PhotonMaps],
        spp: Some(Knob::EstimateSpp),
        passes: None,
        work: Work::PixelSamples(Knob::EstimateSpp),
        whole_image: true,
        render: final_gather::render,
        blocks: Err(PHOTON_MAP_SHARDS),
    },
    MethodRow {
        method: Method::CausticSplat,
        help: "the caustic layers alone, by photon differential splatting onto eye vertices \
               (no photon map), in passes",
        table: "[estimate.splat]",
        reads: &[Input::EyeVertices],
        spp: Some(Knob::EstimateSpp),
        passes: Some(Knob::SplatPasses),
        work: Work::SplatPhotons,
        whole_image: false,
        render: caustic_splat::render,
        blocks: Ok(caustic_splat::blocks),
    },
    MethodRow {
        method: Method::PathSplat,
        help: "the path tracer without the paths splatting owns, plus the splatted caustic \
               layers, interleaved in passes",
        table: "[render] and [estimate.splat]",
        reads: &[Input::EyePaths, Input::EyeVertices],
        // The path tracer's samples; its splat's eye vertices take `[estimate] spp`.
        spp: Some(Knob::RenderSpp),
        passes: Some(Knob::SplatPasses),
        work: Work::PixelSamples(Knob::RenderSpp),
        whole_image: true,
        render: path_splat::render,
        blocks: Err(
            "path+splat interleaves two progressions: shard `path --no-caustics` and \
             `caustic-splat` apart and `composite` the two merged runs",
        ),
    },
    MethodRow {
        method: Method::Sppm,
        help: "stochastic progressive photon mapping (Hachisuka and Jensen 2009): new visible \
               points and photons every pass, radii shrinking per pixel; consistent",
        table: "[estimate.sppm]",
        reads: &[Input::VisiblePoints],
        // One camera sample per pixel and pass.
        spp: None,
        passes: Some(Knob::SppmPasses),
        work: Work::PixelSamples(Knob::SppmPasses),
        whole_image: true,
        render: sppm::render,
        blocks: Err(
            "sppm's passes depend on each other (every pass shrinks the radii the next one \
             gathers in), so no range of them can run apart: shard `caustic-splat` or \
             `path`, or render independent seeds and `composite` them",
        ),
    },
];

const PHOTON_MAP_SHARDS: &str = "the photon-map methods estimate from one photon map: shard \
    `trace`, `merge` its photon sets into the cache, then `estimate`";

/// What `estimate` runs when the scene's method reads no photon maps: of the methods that
/// read them, the one `cargo xtask bench accuracy` measured to reach the 256-spp path
/// tracer's error (in 0.12x its time on the worksheet scene, `docs/benchmarks.md`); the global
/// map shown directly keeps its density estimate's bias at any budget.
pub const ESTIMATE_DEFAULT: Method = Method::FinalGather;

/// The method's row of [`METHODS`].
pub fn row(method: Method) -> &'static MethodRow {
    // Every method has its row (tested), so the fallback is never taken.
    METHODS
        .iter()
        .find(|r| r.method == method)
        .unwrap_or(&METHODS[0])
}

/// The methods and their help lines, one per line, for `--help`.
pub fn help() -> String {
    METHODS
        .iter()
        .map(|r| format!("{}: {}", r.method, r.help))
        .collect::<Vec<_>>()
        .join("\n")
}

impl Settings {
    /// Parses the scene's tables and applies `o`: the flags whose place depends on the method
    /// go where its row of the method table says. Errors name the scene file or the flag.
    pub fn new(scene: &Scene, o: &Overrides) -> Result<Settings, String> {
        Settings::parse(scene, o, &|m| row(m).flags())
    }

    /// Samples per pixel of the method's eye pass (one for SPPM's visible points).
    pub fn spp(&self) -> u32 {
        row(self.method).spp.map_or(1, |k| k.get(self))
    }

    /// These settings with the passes and samples per pixel a run made recorded, so the
    /// resolved scene file reproduces a run a time budget stopped.
    pub fn with_made(&self, r: &Rendered) -> Settings {
        let mut s = self.clone();
        if let (Some(p), Some(k)) = (r.passes, row(self.method).passes) {
            k.set(&mut s, p);
        }
        if let Some(n) = r.samples {
            Knob::RenderSpp.set(&mut s, n);
        }
        s
    }
}

/// Runs the method the settings name.
pub fn render(run: &Run, progress: &(dyn Fn(u64) + Sync)) -> Result<Rendered, String> {
    if run.threads == Some(0) {
        return Err("--threads must be at least 1".into());
    }
    (row(run.settings.method).render)(run, progress)
}

/// Total work of a run for a progress bar, and what it counts.
pub fn work(run: &Run) -> (u64, &'static str) {
    let s = run.settings;
    let pixels = run.scene.camera.width as u64 * run.scene.camera.height as u64;
    match row(s.method).work {
        Work::PixelSamples(k) => (pixels * k.get(s) as u64, "samples"),
        Work::SplatPhotons => {
            let sp = &s.estimate.splat;
            let per_pass = if sp.photons > 0 {
                sp.photons
            } else {
                s.emit.photons
            };
            (per_pass.saturating_mul(sp.passes as u64), "photons")
        }
    }
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
    put("kernel", s.estimate.global.kernel.to_string().into());
    put("boundary_correction", s.estimate.boundary.into());
    put(
        "trace",
        if inputs.reused { "reused" } else { "traced" }.into(),
    );
    put("time_trace_s", inputs.seconds_trace.into());
    put("time_load_and_index_s", inputs.seconds_load.into());
    j
}
