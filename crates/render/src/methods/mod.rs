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
mod light;
pub(crate) mod path;
mod path_splat;
mod single_pass;
pub(crate) mod sppm;
mod vcm;

pub use sppm::start_radius;
pub use vcm::auto_radius as vcm_radius;

use crate::rendered::Rendered;
use crate::run::{BlocksFn, Run};
use crate::settings::{Flags, Knob, Overrides, Settings};
use scene::{Method, Scene};

type RenderFn = fn(&Run, &(dyn Fn(u64) + Sync)) -> Result<Rendered, String>;

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
    /// Light paths joined to the camera.
    LightPaths,
}

/// What a method's progress bar counts, in total.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Work {
    /// Pixel samples: width x height x the knob.
    PixelSamples(Knob),
    /// Caustic photon paths splatted: per pass x passes (`[estimate.splat]`).
    SplatPhotons,
    /// Light paths traced to the camera: per pass x passes (`[estimate.light]`).
    LightPhotons,
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
pub static METHODS: [MethodRow; 8] = [
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
    MethodRow {
        method: Method::Light,
        help: "light tracing: light paths joined to the camera at every non-delta vertex, in \
               passes; sharp caustics without a density estimate, but no light seen through \
               specular surfaces",
        table: "[estimate.light]",
        reads: &[Input::LightPaths],
        spp: None,
        passes: Some(Knob::LightPasses),
        work: Work::LightPhotons,
        whole_image: true,
        render: light::render,
        blocks: Ok(light::blocks),
    },
    MethodRow {
        method: Method::Vcm,
        help: "vertex connection and merging (Georgiev et al. 2012): path tracing, light \
               tracing, bidirectional connections and merging in passes, each path weighted \
               by MIS over all of them",
        table: "[estimate.vcm]",
        // Not `EyePaths`: `--no-caustics` configures the path tracer alone.
        reads: &[Input::LightPaths],
        // One eye and one light subpath per pixel and pass.
        spp: None,
        passes: Some(Knob::VcmPasses),
        work: Work::PixelSamples(Knob::VcmPasses),
        whole_image: true,
        render: vcm::render,
        blocks: Ok(vcm::blocks),
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
        Work::LightPhotons => {
            let per_pass = light::photons_per_pass(s);
            (
                per_pass.saturating_mul(s.estimate.light.passes as u64),
                "light paths",
            )
        }
    }
}
