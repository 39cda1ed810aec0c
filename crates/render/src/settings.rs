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
    pub light: LightSettings,
    pub vcm: VcmSettings,
}

/// `[estimate.vcm]`: vertex connection and merging, one light and one eye subpath per pixel
/// and pass.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct VcmSettings {
    /// Passes: pass `j` traces new subpaths, drawn from scrambled Sobol sequences as functions
    /// of `(seed, j, i)`; the image is their mean. A time budget sets the passes it made.
    pub passes: u32,
    /// Light subpaths per pass (0: one per pixel). Pixel `i`'s eye path connects to light
    /// path `i` modulo their number; every light path is joined to the camera and merged.
    pub light_paths: u64,
    /// Merging radius of the first pass in scene units (0: a pixel's footprint at the
    /// distance from the camera to the scene's centre).
    pub radius: f32,
    /// Radius reduction: pass `j` merges within `radius (j + 1)^((alpha - 1) / 2)`.
    pub alpha: f32,
    /// Bidirectional connections: each eye vertex joined to the light vertices of its
    /// pixel's light subpath (at least two vertices on each side). Off (the default), the
    /// weights count only the other strategies (path tracing with NEE, light tracing,
    /// merging), so the estimate stays whole, and an eye vertex saves a shadow ray and two
    /// BSDF evaluations per light vertex: at equal time the error is 0.82-0.84x of theirs
    /// with them on McGuire's Glossy box, the spot-lit box and the worksheet box at 128 x 128
    /// (5 s, two seeds each).
    pub bidirectional: bool,
    /// Which strategies add to the image (all by default). The MIS weights still count
    /// every strategy, so one switched off leaves out exactly its share of each path: the
    /// image shows what the others carry.
    pub strategies: VcmStrategies,
}

/// `[estimate.vcm.strategies]`: one switch per strategy.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct VcmStrategies {
    /// Emission an eye path hits (path tracing).
    pub hits: bool,
    /// Next-event estimation at eye vertices.
    pub nee: bool,
    /// Light vertices joined to the camera (light tracing).
    pub camera: bool,
    /// Eye vertices joined to their pixel's light vertices.
    pub connect: bool,
    /// Light vertices within the radius merged at eye vertices.
    pub merge: bool,
}

impl Default for VcmStrategies {
    fn default() -> Self {
        VcmStrategies {
            hits: true,
            nee: true,
            camera: true,
            connect: true,
            merge: true,
        }
    }
}

impl Default for VcmSettings {
    fn default() -> Self {
        VcmSettings {
            passes: 16,
            light_paths: 0,
            radius: 0.0,
            alpha: 0.75,
            bidirectional: false,
            strategies: VcmStrategies::default(),
        }
    }
}

/// `[estimate.light]`: light tracing, light paths connected to the camera.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct LightSettings {
    /// Light paths per pass (0: `[photons] photons`).
    pub photons: u64,
    /// Passes: pass `j` traces `photons` new paths, point `i` of the pass's scrambled Sobol
    /// sequence for path `i` (a function of `(seed, j, i)`); the image is their mean. A time
    /// budget sets the passes it made.
    pub passes: u32,
}

impl Default for LightSettings {
    fn default() -> Self {
        LightSettings {
            photons: 0,
            passes: 4,
        }
    }
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
    /// Boundary-bias correction of every pass's estimate (as `[estimate] boundary` does for
    /// the global map), with `[estimate.global] topo` or, where that is unset,
    /// [`SPPM_BOUNDARY_TOPO`]. Without it the radii, which shrink only as passes^(-1/6),
    /// leave the open rims of a scene a few percent dark after hundreds of passes.
    pub boundary: bool,
    /// Glass hits of a camera path at which both Fresnel branches get a visible point (each
    /// with its own statistics), instead of one branch chosen at random per pass; at most
    /// 8. 0 is the classic one point per pixel and pass.
    pub splits: u32,
    /// Each visible point starts from its own radius: the distance to its 128th nearest
    /// photon of its first pass, within half to four times the global start radius (smaller
    /// in a caustic, where a wide disc blurs, and wider where photons are sparse, where a
    /// small one is noisy). Off by default: on the worksheet scene it lowers the error of a
    /// given number of passes by 4-8% but its wider discs make a pass's gathering about
    /// twice as slow, so it loses at equal time. Off: every pixel starts from the global
    /// radius (Hachisuka and Jensen 2009).
    pub adaptive: bool,
}

/// The topological test SPPM's boundary correction uses when `[estimate.global] topo` is
/// unset: the correction counts only photons on the visible point's own surface.
pub const SPPM_BOUNDARY_TOPO: f32 = 0.1;

impl Default for SppmSettings {
    fn default() -> Self {
        SppmSettings {
            photons: 0,
            passes: 16,
            alpha: 2.0 / 3.0,
            radius: 0.0,
            direct: true,
            boundary: true,
            splits: 2,
            adaptive: false,
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
    /// Caustic photon paths emitted per pass (0: `[photons] photons`). Four passes of 50,000
    /// by default: the worksheet scene's 200,000 paths, in passes whose footprints shrink.
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
    /// Footprints shrink from pass to pass so the mean of the passes converges (Knaus and
    /// Zwicker 2011, probabilistic progressive photon mapping): pass `j` scales every
    /// footprint axis, `max_radius` and `indirect_radius` by `sqrt(prod_{i=1..j} (i + alpha)
    /// / (i + 1))`, about `j^((alpha - 1) / 2)`. In (0, 1]; 1 keeps them fixed (the mean
    /// then converges to a blurred image).
    pub alpha: f32,
}

impl Default for SplatSettings {
    fn default() -> Self {
        SplatSettings {
            scale: 1.0,
            photons: 50_000,
            max_radius: 0.0,
            splits: 2,
            isotropic_radius: 0.0,
            passes: 4,
            indirect: true,
            indirect_radius: 0.0,
            alpha: 2.0 / 3.0,
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
            light: LightSettings::default(),
            vcm: VcmSettings::default(),
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
    /// Seconds for the progressive methods' passes ([`Budget`]); not a setting of the scene
    /// file, which records the passes made instead.
    pub time: Option<f64>,
}

/// The longest time budget a run takes, in seconds: 7 days. Past it no progressive method
/// reaches its budget before its largest count (2^20 SPPM passes take about 2.6 hours on 2
/// cores at the worksheet's size), so such a budget only hides a typo; longer runs give a
/// count.
pub const MAX_TIME: f64 = 7.0 * 24.0 * 3600.0;

/// The problem with `t` as a time budget given by `flag`, if any.
pub fn check_time(flag: &str, t: f64) -> Result<(), String> {
    if !(t > 0.0 && t.is_finite()) {
        return Err(format!("{flag} {t} must be a positive number of seconds"));
    }
    if t > MAX_TIME {
        // `1e300` as given, not its 301 digits.
        return Err(format!(
            "{flag} {t:e} is past the {MAX_TIME} s (7-day) bound on a time budget: give a \
             count (--passes, --spp) for longer runs"
        ));
    }
    Ok(())
}

/// `--time`: a budget of seconds for the progressive passes, which run until it is used (at
/// least one pass runs; the last one ends past it).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Budget {
    pub seconds: f64,
    /// The run's count was given too (`--passes`, or the path tracer's `--spp`): the time
    /// only caps it, and the run stops at whichever comes first. Otherwise the passes go on
    /// past the scene file's count, which is only a default, until the time is used.
    pub capped: bool,
}

/// Everything a run needs besides the scene's geometry.
#[derive(Clone, Debug, PartialEq)]
pub struct Settings {
    pub method: Method,
    /// Time budget of the progressive passes.
    pub time: Option<Budget>,
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
    /// `[estimate.light] passes`.
    LightPasses,
    /// `[estimate.vcm] passes`.
    VcmPasses,
}

impl Knob {
    /// The scene-file key, for messages.
    pub const fn key(self) -> &'static str {
        match self {
            Knob::RenderSpp => "render.spp",
            Knob::EstimateSpp => "estimate.spp",
            Knob::SplatPasses => "estimate.splat.passes",
            Knob::SppmPasses => "estimate.sppm.passes",
            Knob::LightPasses => "estimate.light.passes",
            Knob::VcmPasses => "estimate.vcm.passes",
        }
    }

    /// The problem with `v` as this setting's value, if any (the caller names the file's key
    /// or the flag): the same bounds for both.
    pub fn check(self, v: u32) -> Result<(), String> {
        count_in(v.into(), self.max().into(), &self.max().to_string())
    }

    /// The largest value the setting takes: where a run that a time budget alone ends must
    /// stop, so the scene file recording its count stays valid.
    pub const fn max(self) -> u32 {
        match self {
            Knob::RenderSpp => 1 << 24,
            Knob::EstimateSpp
            | Knob::SplatPasses
            | Knob::SppmPasses
            | Knob::LightPasses
            | Knob::VcmPasses => 1 << 20,
        }
    }

    /// `key = max`, for messages.
    pub fn at_max(self) -> String {
        format!("{} = {}", self.key(), self.max())
    }

    /// It counts a progressive run's passes (the path tracer's samples are its passes'
    /// unit): given as a flag with `--time`, the time only caps that count.
    pub const fn counts_passes(self) -> bool {
        !matches!(self, Knob::EstimateSpp)
    }

    pub fn get(self, s: &Settings) -> u32 {
        match self {
            Knob::RenderSpp => s.render.spp,
            Knob::EstimateSpp => s.estimate.spp,
            Knob::SplatPasses => s.estimate.splat.passes,
            Knob::SppmPasses => s.estimate.sppm.passes,
            Knob::LightPasses => s.estimate.light.passes,
            Knob::VcmPasses => s.estimate.vcm.passes,
        }
    }

    pub fn set(self, s: &mut Settings, v: u32) {
        match self {
            Knob::RenderSpp => s.render.spp = v,
            Knob::EstimateSpp => s.estimate.spp = v,
            Knob::SplatPasses => s.estimate.splat.passes = v,
            Knob::SppmPasses => s.estimate.sppm.passes = v,
            Knob::LightPasses => s.estimate.light.passes = v,
            Knob::VcmPasses => s.estimate.vcm.passes = v,
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
        let flags = flags(method);
        // A flag's value is refused as the flag's, before the file is blamed for anything.
        o.check()?;
        if let Some(n) = o.photons {
            emit.photons = n;
        }
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
        if let Some(t) = o.time {
            check_time("--time", t)?;
        }
        if o.time.is_some() && flags.passes.is_none() {
            return Err(format!(
                "--time: {method} renders in one go, without passes to stop after (the \
                 progressive methods take it)"
            ));
        }
        // The count is the flags' only when it is one the progressive loop counts (not
        // caustic-splat's `--spp`, its eye vertices per pixel and pass).
        let capped = [(o.spp, flags.spp), (o.passes, flags.passes)]
            .iter()
            .any(|(v, k)| v.is_some() && k.is_some_and(Knob::counts_passes));
        let mut s = Settings {
            method,
            time: o.time.map(|seconds| Budget { seconds, capped }),
            render,
            emit,
            estimate,
        };
        // Where `--spp` and `--passes` are two counts that progress together (path+splat: the
        // path tracer's samples and the splatting passes), `--passes N` alone is N of the
        // method's passes: the samples keep the scene file's ratio to the passes.
        let mut spp = o.spp;
        if let (None, Some(n), Some(ks), Some(kp)) = (o.spp, o.passes, flags.spp, flags.passes)
            && ks != kp
            && ks.counts_passes()
            && kp.counts_passes()
        {
            let per_pass = ks.get(&s) as f64 / kp.get(&s).max(1) as f64;
            let v = (n as f64 * per_pass).round().clamp(1.0, ks.max() as f64) as u32;
            spp = Some(v);
        }
        for (flag, value, knob) in [
            ("--spp", spp, flags.spp),
            ("--passes", o.passes, flags.passes),
        ] {
            match (value, knob) {
                (Some(v), Some(k)) => {
                    k.check(v).map_err(|p| format!("{flag} {v}: {p}"))?;
                    k.set(&mut s, v);
                }
                (Some(_), None) => {
                    return Err(format!(
                        "{flag}: {method} takes no {flag} (see `photonflow render --help`)"
                    ));
                }
                (None, _) => {}
            }
        }
        s.validate(scene).map_err(err)?;
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

    /// Checks the resolved settings, every key against its bounds whatever the method (the
    /// flags' values were checked as flags first, so what fails here is the file's). Errors
    /// name one key each; the caller prefixes the scene file.
    fn validate(&self, scene: &Scene) -> Result<(), String> {
        let e = &self.estimate;
        let key = |k: &str, v: &dyn std::fmt::Display, r: Result<(), String>| {
            r.map_err(|p| format!("{k} = {v} {p}"))
        };
        key(
            "photons",
            &self.emit.photons,
            check_photons(self.emit.photons),
        )?;
        for k in [
            Knob::RenderSpp,
            Knob::EstimateSpp,
            Knob::SplatPasses,
            Knob::SppmPasses,
            Knob::LightPasses,
            Knob::VcmPasses,
        ] {
            let v = k.get(self);
            key(k.key(), &v, k.check(v))?;
        }
        for (name, p) in [("global", &e.global), ("caustic", &e.caustic)] {
            key(&format!("estimate.{name}.k"), &p.k, check_k(p.k))?;
            if let Some(eps) = p.topo {
                key(&format!("estimate.{name}.topo"), &eps, check_topo(eps))?;
            }
            if p.r_max.is_nan() || p.r_max <= 0.0 {
                return Err(format!(
                    "estimate.{name}.r_max = {} must be positive",
                    p.r_max
                ));
            }
        }
        let rays = e.final_gather.rays;
        key("estimate.final_gather.rays", &rays, check_gather_rays(rays))?;
        let sp = &e.splat;
        if !(sp.scale > 0.0 && sp.scale <= 1e3) {
            return Err(format!(
                "estimate.splat.scale = {} must be in (0, 1000]",
                sp.scale
            ));
        }
        for (name, r) in [
            ("isotropic_radius", sp.isotropic_radius),
            ("max_radius", sp.max_radius),
            // 0 is the automatic radius; a negative or NaN one used to become it silently.
            ("indirect_radius", sp.indirect_radius),
        ] {
            if !(r >= 0.0 && r.is_finite()) {
                return Err(format!(
                    "estimate.splat.{name} = {r} must be finite and >= 0 (0: automatic)"
                ));
            }
        }
        if !(sp.alpha > 0.0 && sp.alpha <= 1.0) {
            return Err(format!(
                "estimate.splat.alpha = {} must be in (0, 1]",
                sp.alpha
            ));
        }
        if sp.photons > 1 << 40 {
            return Err(format!(
                "estimate.splat.photons = {} is absurd (at most 2^40)",
                sp.photons
            ));
        }
        if e.light.photons > 1 << 40 {
            return Err(format!(
                "estimate.light.photons = {} is absurd (at most 2^40)",
                e.light.photons
            ));
        }
        let v = &e.vcm;
        if v.light_paths > 1 << 32 {
            return Err(format!(
                "estimate.vcm.light_paths = {} is absurd (at most 2^32: a pass keeps every \
                 light vertex in memory)",
                v.light_paths
            ));
        }
        if !(v.radius >= 0.0 && v.radius.is_finite()) {
            return Err(format!(
                "estimate.vcm.radius = {} must be finite and >= 0 (0: automatic)",
                v.radius
            ));
        }
        if !(v.alpha > 0.0 && v.alpha <= 1.0) {
            return Err(format!(
                "estimate.vcm.alpha = {} must be in (0, 1]",
                v.alpha
            ));
        }
        if sp.splits > 16 {
            return Err(format!(
                "estimate.splat.splits = {} is absurd (at most 16)",
                sp.splits
            ));
        }
        let sm = &e.sppm;
        key(
            "estimate.sppm.photons",
            &sm.photons,
            check_sppm_photons(sm.photons),
        )?;
        if !(sm.alpha > 0.0 && sm.alpha < 1.0) {
            return Err(format!(
                "estimate.sppm.alpha = {} must be in (0, 1)",
                sm.alpha
            ));
        }
        if sm.splits > 8 {
            return Err(format!(
                "estimate.sppm.splits = {} is absurd (at most 8)",
                sm.splits
            ));
        }
        check_sppm_radius(sm.radius, scene)
            .map_err(|p| format!("estimate.sppm.radius = {} {p}", sm.radius))?;
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

    /// Refuses SPPM passes of more photon paths than one pass can map when they come from
    /// `[photons] photons` (or `--photons`, named as the flag), as they do with
    /// `[estimate.sppm] photons` at 0 (that key is bounded in every command). For the commands
    /// that run SPPM only: `trace` of the same scene writes photon files, which the space on
    /// disk bounds instead. `flags` are the method's ([`Settings::parse`]).
    pub fn check_pass_photons(
        &self,
        scene: &Scene,
        o: &Overrides,
        flags: &Flags,
    ) -> Result<(), String> {
        if !traces_per_pass(flags) || self.estimate.sppm.photons > 0 {
            return Ok(());
        }
        let n = self.emit.photons;
        check_sppm_photons(n).map_err(|p| {
            let what = format!("is sppm's pass size (estimate.sppm.photons is 0), so it {p}");
            match o.photons {
                Some(_) => format!("--photons {n}: {what}"),
                None => format!("{}: photons = {n}: {what}", scene.path.display()),
            }
        })
    }

    /// [`Settings::resolved_scene`] as the text of a scene file.
    pub fn resolved_scene_text(&self, scene: &Scene) -> Result<String, String> {
        toml::to_string(&self.resolved_scene(scene)?).map_err(|e| {
            format!(
                "{}: the resolved scene does not serialise: {e}",
                scene.path.display()
            )
        })
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
        for name in f.file_names_mut() {
            let p = dir.join(&*name);
            let abs = std::path::absolute(&p).map_err(|e| format!("{}: {e}", p.display()))?;
            *name = abs.to_string_lossy().into_owned();
        }
        Ok(f)
    }
}

impl Overrides {
    /// Refuses a flag's value that the scene file's key would be refused for, naming the flag
    /// ("--k 0: must be in 1..=1048576"), not the file that does not hold it. `--spp` and
    /// `--passes` are checked where [`Settings::parse`] knows their knob; `--photons` as
    /// SPPM's paths per pass by [`Settings::check_pass_photons`].
    fn check(&self) -> Result<(), String> {
        let flag = |name: &str, v: &dyn std::fmt::Display, r: Result<(), String>| {
            r.map_err(|p| format!("{name} {v}: {p}"))
        };
        if let Some(n) = self.photons {
            flag("--photons", &n, check_photons(n))?;
        }
        if let Some(k) = self.k {
            flag("--k", &k, check_k(k))?;
        }
        if let Some(Some(eps)) = self.topo {
            flag("--topo", &eps, check_topo(eps))?;
        }
        if let Some(r) = self.gather_rays {
            flag("--gather-rays", &r, check_gather_rays(r))?;
        }
        Ok(())
    }
}

/// The bounds of one setting: `Err` holds the problem without the key's name, so the scene
/// file's key ("estimate.global.k = 0 must be ...") and a flag ("--k 0: must be ...") share
/// the same words.
fn count_in(v: u64, max: u64, shown: &str) -> Result<(), String> {
    if v == 0 || v > max {
        Err(format!("must be in 1..={shown}"))
    } else {
        Ok(())
    }
}

fn check_photons(n: u64) -> Result<(), String> {
    count_in(n, 1 << 40, "2^40")
}

fn check_k(k: usize) -> Result<(), String> {
    count_in(k as u64, 1 << 20, "1048576")
}

fn check_topo(eps: f32) -> Result<(), String> {
    if eps > 0.0 && eps <= 1.0 {
        Ok(())
    } else {
        Err("must be in (0, 1]".into())
    }
}

fn check_gather_rays(rays: u32) -> Result<(), String> {
    match rays {
        // Without gather rays the `indirect` layer is black yet still claims indirect light,
        // so a composite would take it for an estimate of it.
        0 => Err(
            "must be at least 1: final gathering estimates indirect light by its \
             gather rays, and none leaves it out of the image"
                .into(),
        ),
        r if r > 1 << 16 => Err("is absurd (at most 65536)".into()),
        _ => Ok(()),
    }
}

/// Most photon paths one SPPM pass may trace. A pass keeps every photon it stores in memory
/// (32 bytes each) under one kd-tree that indexes with u32 (`MAX_MAP_PHOTONS`), and SPPM stores
/// about one photon per diffuse bounce: in a closed scene a path makes one or more, so a pass
/// of more paths than the index holds would hold more photons than it can index, and even at
/// one photon per four paths 34 GB of them. Bounded in paths, which the settings say, not in
/// photons, which only tracing would tell. 1e12 paths per pass used to be accepted, and ran
/// for days towards running out of memory.
pub const MAX_SPPM_PHOTONS: u64 = crate::maps::MAX_MAP_PHOTONS;

/// `estimate.sppm.photons` (0: `[photons] photons`).
fn check_sppm_photons(n: u64) -> Result<(), String> {
    if n > MAX_SPPM_PHOTONS {
        Err(format!(
            "must be at most {MAX_SPPM_PHOTONS} photon paths per pass (one pass's photons, \
             about one per diffuse bounce, go into one in-memory kd-tree that u32 indexes)"
        ))
    } else {
        Ok(())
    }
}

/// The method runs SPPM's passes, each of which traces `estimate.sppm.photons` (or
/// `[photons] photons`) new paths: the method table says so by where `--passes` goes, so
/// nothing here matches on `Method`.
fn traces_per_pass(flags: &Flags) -> bool {
    flags.passes == Some(Knob::SppmPasses)
}

/// `estimate.sppm.radius` (0: automatic): finite, >= 0, and at most the scene's bounding
/// diagonal. Visible points and photons all lie inside the scene's bounds, so a disc of the
/// diagonal's radius already gathers every photon of a pass; a wider one gathers no more and
/// only divides them over more area (at 1e30 the area itself overflowed f32 and indirect light
/// vanished). The diagonal is the tightest bound that refuses nothing that could matter.
fn check_sppm_radius(r: f32, scene: &Scene) -> Result<(), String> {
    if !(r >= 0.0 && r.is_finite()) {
        return Err("must be finite and >= 0 (0: automatic)".into());
    }
    let b = scene.geometry.bounds();
    let diagonal = (b.max - b.min).length();
    if diagonal.is_finite() && r > diagonal {
        return Err(format!(
            "exceeds the scene's bounding diagonal ({diagonal}): a disc that wide already \
             holds every photon, and a wider one only dilutes them (0: automatic)"
        ));
    }
    // Without bounds to compare with, at least pi r^2 must stay finite in f32.
    if !(std::f32::consts::PI * r * r).is_finite() {
        return Err("is so large that pi r^2 overflows f32".into());
    }
    Ok(())
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
