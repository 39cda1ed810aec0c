//! The parameters of a run, parsed once per command from the scene file: `[render]` (typed
//! by `scene`), `[photons]` (`emit::EmitParams`) and `[estimate]` ([`EstimateSettings`]).
//! `scene` keeps the last two opaque so it stays below the stages that own them; they are
//! parsed here and nowhere else. Flags only override ([`Overrides`]); the resolved settings
//! are written back into a scene file ([`Settings::resolved_scene`]) that reproduces the run.

use density::{EstimateParams, Kernel};
use emit::EmitParams;
use scene::{Method, Scene, SceneFile};
use serde::{Deserialize, Serialize};

/// The `[estimate]` table: every knob of the photon-map methods. Each method's own knobs sit
/// in a sub-table named after it (`[estimate.final_gather]`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct EstimateSettings {
    /// Samples per pixel of the photon-map eye passes (each already averages many photons).
    pub spp: u32,
    /// Correct global-map estimates for boundary bias: divide by the share of the kernel's
    /// mass that lies on the surface (needs `global.topo`).
    pub boundary: bool,
    /// The global map's estimate (course framework: k = 1000).
    pub global: EstimateParams,
    /// The caustic map's estimate (course framework: k = 250).
    pub caustic: EstimateParams,
    pub final_gather: FinalGatherSettings,
    pub splat: SplatSettings,
    pub sppm: SppmSettings,
}

/// `[estimate.sppm]`: stochastic progressive photon mapping (Hachisuka and Jensen 2009;
/// pbrt-v4 §16.2). Kernel, same-side and topological tests are `[estimate.global]`'s.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SppmSettings {
    /// Photon paths per pass (0: `[photons] photons`).
    pub photons: u64,
    /// Passes: each draws one new camera sample per pixel and `photons` new paths.
    pub passes: u32,
    /// The share of new photons a visible point keeps: radii shrink as
    /// `R' = R sqrt((N + alpha M) / (N + M))`; in (0, 1).
    pub alpha: f32,
    /// Start radius in scene units (0: automatic, from the scene's diffuse area, the photons
    /// per pass and the pixel footprint; see `sppm::start_radius`).
    pub radius: f32,
    /// Direct light by next-event estimation at the visible points (else photons carry it).
    pub direct: bool,
}

impl Default for SppmSettings {
    fn default() -> Self {
        SppmSettings {
            photons: 0,
            passes: 16,
            alpha: 2.0 / 3.0,
            radius: 0.0,
            direct: true,
        }
    }
}

/// `[estimate.splat]`: photon differential splatting (Frisvad et al. 2014).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SplatSettings {
    /// The smoothing parameter `s`: every differential at emission is scaled by it (1 tiles
    /// the lit area about once; larger is smoother).
    pub scale: f32,
    /// Caustic photon paths emitted (0: `[photons] photons`).
    pub photons: u64,
    /// Largest footprint semi-axis, in scene units (0: 2% of the scene's bounding diagonal).
    pub max_radius: f32,
    /// Dielectric hits at which eye paths follow both reflection and refraction.
    pub splits: u32,
    /// Isotropic splatting with this fixed radius in scene units instead of the photon
    /// differentials' footprints (0: differentials). For comparisons.
    pub isotropic_radius: f32,
    /// Photon passes: pass `j` traces `photons` new paths from streams `(seed, j, i)` onto
    /// new eye vertices; the layers are their mean. A run stopped by a time budget records
    /// the passes it made.
    pub passes: u32,
    /// Also follow each caustic path past its first diffuse hit and splat it at every
    /// later diffuse hit: caustics seen through a diffuse bounce (`caustic_indirect`), the
    /// path tracer's noisiest paths. When on, the path tracer of `path+splat` (and
    /// `--no-caustics`) leaves those paths out too.
    pub indirect: bool,
    /// Radius of the disc by which a photon after a diffuse bounce reaches eye vertices, in
    /// scene units (0: `max_radius`). A diffuse bounce spreads light too widely for finer
    /// detail to matter, and a wide disc keeps the estimate smooth.
    pub indirect_radius: f32,
}

impl Default for SplatSettings {
    fn default() -> Self {
        SplatSettings {
            scale: 1.0,
            photons: 0,
            max_radius: 0.0,
            splits: 2,
            isotropic_radius: 0.0,
            passes: 1,
            indirect: true,
            indirect_radius: 0.0,
        }
    }
}

/// `[estimate.final_gather]`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct FinalGatherSettings {
    /// Gather rays per pixel sample.
    pub rays: u32,
    /// Final gathering reads irradiance precomputed at every `cache`-th global photon
    /// (Christensen 1999); 0 estimates from the map at every gather hit.
    pub cache: usize,
}

impl Default for FinalGatherSettings {
    fn default() -> Self {
        FinalGatherSettings { rays: 16, cache: 4 }
    }
}

const GLOBAL_K: usize = 1000;
const CAUSTIC_K: usize = 250;

impl Default for EstimateSettings {
    fn default() -> Self {
        EstimateSettings {
            spp: 1,
            boundary: false,
            global: EstimateParams {
                k: GLOBAL_K,
                ..EstimateParams::default()
            },
            caustic: EstimateParams {
                k: CAUSTIC_K,
                ..EstimateParams::default()
            },
            final_gather: FinalGatherSettings::default(),
            splat: SplatSettings::default(),
            sppm: SppmSettings::default(),
        }
    }
}

/// Command-line overrides of scene-file settings; `None` leaves the file's value.
#[derive(Clone, Debug, Default)]
pub struct Overrides {
    pub method: Option<Method>,
    /// Samples per pixel of whichever method runs.
    pub spp: Option<u32>,
    pub photons: Option<u64>,
    /// Global-map estimate.
    pub k: Option<usize>,
    pub kernel: Option<Kernel>,
    /// `Some(None)` switches the topological test off.
    pub topo: Option<Option<f32>>,
    pub drop_kth: Option<bool>,
    pub boundary: Option<bool>,
    pub gather_rays: Option<u32>,
    pub gather_cache: Option<usize>,
    /// Whether the path tracer follows caustic paths (`render.caustics`).
    pub caustics: Option<bool>,
    /// Passes of the progressive methods: `[estimate.sppm] passes`, `[estimate.splat]
    /// passes`, or the path tracer's samples per pixel.
    pub passes: Option<u32>,
    /// Caustic paths per splatting pass (`[estimate.splat] photons`).
    pub splat_photons: Option<u64>,
    /// Whether splatted caustic paths go on past their first diffuse hit
    /// (`[estimate.splat] indirect`).
    pub splat_indirect: Option<bool>,
    /// Stop the progressive methods' passes once this many seconds have passed (after at
    /// least one); not a setting of the scene file, which records the passes made instead.
    pub time: Option<f64>,
}

/// Everything a run needs besides the scene's geometry.
#[derive(Clone, Debug, PartialEq)]
pub struct Settings {
    pub method: Method,
    /// Time budget of the progressive passes (see [`Overrides::time`]).
    pub time: Option<f64>,
    /// `[render]`, with `spp` and `caustics` overridden for the path tracer.
    pub render: scene::RenderSettings,
    pub emit: EmitParams,
    pub estimate: EstimateSettings,
}

/// A setting that a method-dependent flag sets: where `--spp` and `--passes` go, and where the
/// passes a run made are recorded (the method table, `crate::methods::METHODS`, says which).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Knob {
    /// `[render] spp`: the path tracer's samples per pixel.
    RenderSpp,
    /// `[estimate] spp`: samples per pixel of the photon methods' eye passes.
    EstimateSpp,
    /// `[estimate.splat] passes`.
    SplatPasses,
    /// `[estimate.sppm] passes`.
    SppmPasses,
}

impl Knob {
    /// The scene-file key, for messages.
    pub const fn key(self) -> &'static str {
        match self {
            Knob::RenderSpp => "render.spp",
            Knob::EstimateSpp => "estimate.spp",
            Knob::SplatPasses => "estimate.splat.passes",
            Knob::SppmPasses => "estimate.sppm.passes",
        }
    }

    pub fn get(self, s: &Settings) -> u32 {
        match self {
            Knob::RenderSpp => s.render.spp,
            Knob::EstimateSpp => s.estimate.spp,
            Knob::SplatPasses => s.estimate.splat.passes,
            Knob::SppmPasses => s.estimate.sppm.passes,
        }
    }

    pub fn set(self, s: &mut Settings, v: u32) {
        match self {
            Knob::RenderSpp => s.render.spp = v,
            Knob::EstimateSpp => s.estimate.spp = v,
            Knob::SplatPasses => s.estimate.splat.passes = v,
            Knob::SppmPasses => s.estimate.sppm.passes = v,
        }
    }
}

/// What the method table says of a method's flags, for [`Settings::parse`].
#[derive(Clone, Copy, Debug)]
pub struct Flags {
    /// Where `--spp` goes (`None`: the method takes no `--spp`).
    pub spp: Option<Knob>,
    /// Where `--passes` goes (`None`: the method has no passes, nor `--time`).
    pub passes: Option<Knob>,
    /// It runs the path tracer, which `--no-caustics` configures.
    pub path_tracer: bool,
}

impl Settings {
    /// Parses the scene's tables and applies `o`, the method-dependent flags where `flags` of
    /// the method (`o`'s, else the scene's) say. Errors name the scene file. Callers use
    /// `Settings::new`, which asks the method table for `flags`.
    pub fn parse(
        scene: &Scene,
        o: &Overrides,
        flags: &dyn Fn(Method) -> Flags,
    ) -> Result<Settings, String> {
        let file = &scene.file;
        let err = |m: String| format!("{}: {m}", scene.path.display());
        let mut emit: EmitParams = toml::Value::Table(file.photons.clone())
            .try_into()
            .map_err(|e| err(format!("[photons]: {e}")))?;
        let mut estimate = parse_estimate(&file.estimate).map_err(err)?;
        let mut render = file.render.clone();
        let method = o.method.unwrap_or(render.method);
        render.method = method;
        if let Some(n) = o.photons {
            emit.photons = n;
        }
        let flags = flags(method);
        if o.caustics.is_some() && !flags.path_tracer {
            return Err(format!(
                "--no-caustics applies to the path tracer; {method} takes caustics from photons"
            ));
        }
        if let Some(c) = o.caustics {
            render.caustics = c;
        }
        let g = &mut estimate.global;
        if let Some(k) = o.k {
            g.k = k;
        }
        if let Some(kern) = o.kernel {
            g.kernel = kern;
        }
        if let Some(topo) = o.topo {
            g.topo = topo;
        }
        if let Some(d) = o.drop_kth {
            g.drop_kth = d;
        }
        if let Some(b) = o.boundary {
            estimate.boundary = b;
        }
        if let Some(r) = o.gather_rays {
            estimate.final_gather.rays = r;
        }
        if let Some(c) = o.gather_cache {
            estimate.final_gather.cache = c;
        }
        if let Some(n) = o.splat_photons {
            estimate.splat.photons = n;
        }
        if let Some(i) = o.splat_indirect {
            estimate.splat.indirect = i;
        }
        if let Some(t) = o.time
            && !(t > 0.0 && t.is_finite())
        {
            return Err(format!("--time {t} must be a positive number of seconds"));
        }
        if o.time.is_some() && flags.passes.is_none() {
            return Err(format!(
                "--time: {method} renders in one go, without passes to stop after (the \
                 progressive methods take it)"
            ));
        }
        let mut s = Settings {
            method,
            time: o.time,
            render,
            emit,
            estimate,
        };
        for (flag, value, knob) in [
            ("--spp", o.spp, flags.spp),
            ("--passes", o.passes, flags.passes),
        ] {
            match (value, knob) {
                (Some(v), Some(k)) => k.set(&mut s, v),
                (Some(_), None) => {
                    return Err(format!(
                        "{flag}: {method} takes no {flag} (see `photonflow render --help`)"
                    ));
                }
                (None, _) => {}
            }
        }
        s.validate().map_err(err)?;
        Ok(s)
    }

    /// What an image made with these settings depends on: the scene's view and seed
    /// (`image_hash` without the file's `[render]`) and every setting after the flags. Equal
    /// hashes, equal images (the worksheet reuses its reference on it).
    pub fn hash(&self, scene: &Scene) -> u64 {
        let text = format!(
            "{:016x} {} {:?} {:?} {:?}",
            scene.view_hash,
            scene.seed(),
            toml::to_string(&self.render).unwrap_or_default(),
            toml::to_string(&self.emit).unwrap_or_default(),
            toml::to_string(&self.estimate).unwrap_or_default(),
        );
        scene::fnv1a64(text.as_bytes())
    }

    fn validate(&self) -> Result<(), String> {
        let e = &self.estimate;
        if self.emit.photons == 0 || self.emit.photons > 1 << 40 {
            return Err(format!(
                "photons = {} must be in 1..=2^40",
                self.emit.photons
            ));
        }
        if self.render.spp == 0 || self.render.spp > 1 << 24 {
            return Err(format!(
                "render.spp = {} must be in 1..=16777216",
                self.render.spp
            ));
        }
        if e.spp == 0 || e.spp > 1 << 20 {
            return Err(format!("estimate.spp = {} must be in 1..=1048576", e.spp));
        }
        for (name, p) in [("global", &e.global), ("caustic", &e.caustic)] {
            if p.k == 0 || p.k > 1 << 20 {
                return Err(format!(
                    "estimate.{name}.k = {} must be in 1..=1048576",
                    p.k
                ));
            }
            if let Some(eps) = p.topo
                && !(eps > 0.0 && eps <= 1.0)
            {
                return Err(format!("estimate.{name}.topo = {eps} must be in (0, 1]"));
            }
            if p.r_max.is_nan() || p.r_max <= 0.0 {
                return Err(format!(
                    "estimate.{name}.r_max = {} must be positive",
                    p.r_max
                ));
            }
        }
        if e.final_gather.rays > 1 << 16 {
            return Err(format!(
                "estimate.final_gather.rays = {} is absurd (at most 65536)",
                e.final_gather.rays
            ));
        }
        let sp = &e.splat;
        if !(sp.scale > 0.0 && sp.scale <= 1e3) {
            return Err(format!(
                "estimate.splat.scale = {} must be in (0, 1000]",
                sp.scale
            ));
        }
        if !(sp.isotropic_radius >= 0.0 && sp.isotropic_radius.is_finite()) {
            return Err(format!(
                "estimate.splat.isotropic_radius = {} must be finite and >= 0",
                sp.isotropic_radius
            ));
        }
        if !(sp.max_radius >= 0.0 && sp.max_radius.is_finite()) {
            return Err(format!(
                "estimate.splat.max_radius = {} must be finite and >= 0",
                sp.max_radius
            ));
        }
        if sp.passes == 0 || sp.passes > 1 << 20 {
            return Err(format!(
                "estimate.splat.passes = {} must be in 1..=1048576",
                sp.passes
            ));
        }
        let sm = &e.sppm;
        if sm.passes == 0 || sm.passes > 1 << 20 || sm.photons > 1 << 40 {
            return Err(format!(
                "estimate.sppm: passes = {} must be in 1..=1048576 and photons = {} at most 2^40",
                sm.passes, sm.photons
            ));
        }
        if !(sm.alpha > 0.0 && sm.alpha < 1.0 && sm.radius >= 0.0 && sm.radius.is_finite()) {
            return Err(format!(
                "estimate.sppm: alpha = {} must be in (0, 1) and radius = {} finite and >= 0",
                sm.alpha, sm.radius
            ));
        }
        if sp.photons > 1 << 40 || sp.splits > 16 {
            return Err(format!(
                "estimate.splat: photons = {} (at most 2^40) or splits = {} (at most 16) is absurd",
                sp.photons, sp.splits
            ));
        }
        if e.boundary && e.global.topo.is_none() {
            return Err(
                "boundary correction needs the topological test (estimate.global.topo, or \
                 --topo EPS): the correction divides by the share of the disc on this surface, \
                 so photons from other surfaces must be excluded first or they are amplified too"
                    .into(),
            );
        }
        Ok(())
    }

    /// The scene file with these settings written in, mesh paths made absolute: rendering it
    /// again reproduces the run bit for bit (the thread count never changes an image).
    pub fn resolved_scene(&self, scene: &Scene) -> Result<SceneFile, String> {
        let mut f = scene.file.clone();
        f.render = self.render.clone();
        let table = |v: Result<toml::Value, toml::ser::Error>| match v {
            Ok(toml::Value::Table(t)) => Ok(t),
            Ok(other) => Err(format!("settings serialise to {other}, not a table")),
            Err(e) => Err(format!("settings do not serialise: {e}")),
        };
        f.photons = table(toml::Value::try_from(&self.emit))?;
        f.estimate = table(toml::Value::try_from(&self.estimate))?;
        let dir = scene.path.parent().unwrap_or(std::path::Path::new(""));
        for m in &mut f.meshes {
            let p = dir.join(&m.obj);
            let abs = std::path::absolute(&p).map_err(|e| format!("{}: {e}", p.display()))?;
            m.obj = abs.to_string_lossy().into_owned();
        }
        Ok(f)
    }
}

/// `[estimate]` with the framework's per-map defaults of k filled in where a sub-table leaves
/// k out (a bare `[estimate.global]` table would otherwise take `EstimateParams`' k = 50).
fn parse_estimate(t: &toml::Table) -> Result<EstimateSettings, String> {
    let mut t = t.clone();
    for (map, k) in [("global", GLOBAL_K), ("caustic", CAUSTIC_K)] {
        if let Some(v) = t.get_mut(map) {
            let toml::Value::Table(sub) = v else {
                return Err(format!("[estimate.{map}] must be a table, not {v}"));
            };
            sub.entry("k").or_insert(toml::Value::Integer(k as i64));
        }
    }
    toml::Value::Table(t)
        .try_into()
        .map_err(|e| format!("[estimate]: {e}"))
}
