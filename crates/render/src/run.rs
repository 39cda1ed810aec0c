//! What every method gets and shares: a [`Run`] (the scene, its settings, where photon sets
//! are cached and whether it may trace them), the block accumulation that shards split
//! ([`Accumulate`]), and the helpers of the photon-map methods (their maps, their facts).

use crate::maps::Maps;
use crate::rendered::{CountKind, Layer, Rendered};
use crate::settings::Settings;
use emit::Plan;
use film::{Film, Normalize};
use photons::cache::{self as photon_cache, CacheKey};
use scene::Scene;
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
