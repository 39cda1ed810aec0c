//! The flags and help of the studies: Worksheet 7's deliverable (`worksheet`) and the
//! evidence ladders with their lab report (`evidence`).

use super::parse::parse_threads;
use std::path::PathBuf;

/// Worksheet 7's deliverable: the global map shown directly with the box kernel, with
/// Silverman's kernel, + the topological test, + boundary correction; errors against a
/// path-traced reference.
///
/// The four estimates share one traced photon set; their errors are measured over the
/// whole image and along the box's inner edges. The images and a Markdown summary of them
/// (README.md) go into --out.
#[derive(clap::Args)]
pub(crate) struct Worksheet {
    /// The scene file (TOML).
    #[arg(long, default_value = "scenes/cornell-spheres/analytic.toml")]
    pub(crate) scene: PathBuf,
    /// Photon paths (each stores about 2.3 global photons in the Cornell box).
    #[arg(long, default_value_t = 200_000)]
    pub(crate) photons: u64,
    /// Nearest photons per estimate.
    #[arg(long, default_value_t = 1000)]
    pub(crate) k: usize,
    /// Topological test tolerance.
    #[arg(long, default_value_t = 0.1)]
    pub(crate) topo: f32,
    /// Samples per pixel of the path-traced reference.
    #[arg(long, default_value_t = 1024)]
    pub(crate) reference_spp: u32,
    /// Where the images, the summary and the reference go.
    #[arg(long, default_value = "out/worksheet")]
    pub(crate) out: PathBuf,
    /// Directory of cached photon files.
    #[arg(long, default_value = "out/cache")]
    pub(crate) cache: PathBuf,
    /// Worker threads (default: all cores).
    #[arg(long, value_parser = parse_threads)]
    pub(crate) threads: Option<usize>,
}

/// What accuracy costs in time, bias and variance apart: each technique over a ladder of
/// budgets, --seeds independent runs each, against a reference.
///
/// The techniques: path, path+splat, the global map shown directly with the box and
/// Silverman kernels, + the topological test, + boundary correction, final gathering,
/// SPPM, and the caustic map against splatting on the caustic layer; and the global map's
/// k swept per kernel (k-sweep). The reference is path-traced (rendered once into --cache,
/// then reused) unless --reference gives any linear EXR.
///
/// For each: relative MSE in two conventions, RMSE, mean ratio, FLIP, and bias² and
/// variance per region, the regions found from the scene's geometry (caustic, edges and
/// corners, outer rim, glass sphere, open walls); bias² and variance maps as EXR and
/// false-colour PNG.
///
/// Writes the lab report report.html and report.md into --out (images, crops of the
/// caustic and corners, bias²/variance maps, SVG plots of error against time and of bias²
/// and variance against k, per-region bars, the boundary-bias correction measured),
/// evidence.md and evidence.json. --out is written whole beside its place and renamed into
/// it: a stopped run leaves the last whole report. The default run takes about 40 minutes
/// on 2 cores (measured: 40 min wall, 72 min CPU, reference included); see --quick.
#[derive(clap::Args)]
pub(crate) struct Evidence {
    /// The scene file (TOML).
    #[arg(default_value = "scenes/cornell-spheres/analytic.toml")]
    pub(crate) scene: PathBuf,
    /// A linear RGB EXR of the same view from any renderer (else a path-traced one,
    /// rendered once into --cache and reused).
    #[arg(long)]
    pub(crate) reference: Option<PathBuf>,
    /// The reference's second independent half: errors and bias² against the halves'
    /// mean, with the reference's noise taken out beside the plain figures.
    #[arg(long)]
    pub(crate) reference_b: Option<PathBuf>,
    /// Samples per pixel of the path-traced reference [default: 1024, 512 with --quick].
    #[arg(long)]
    pub(crate) reference_spp: Option<u32>,
    /// Independent runs (seeds 1..=N) per technique and budget [default: 8, 4 with
    /// --quick].
    #[arg(long)]
    pub(crate) seeds: Option<u32>,
    /// About 2 minutes on 2 cores in place of about 40, trading detail and certainty for
    /// time.
    ///
    /// About 1 minute once its reference is cached. The image at most 256 pixels on a
    /// side (the scene's view; unless --reference fixes the size), 4 seeds, a 512-spp
    /// reference, two budgets per technique and k in {50, 250, 1000}: bias² and variance
    /// are noisier, and errors sit nearer the reference's own noise.
    #[arg(long)]
    pub(crate) quick: bool,
    /// Multiply every budget of the ladder and the k sweep's photon counts by this.
    #[arg(long, default_value_t = 1.0)]
    pub(crate) budget_scale: f64,
    /// Only this technique (repeatable; its name in lower case with dashes, e.g.
    /// `path`, `caustic-map-k-nn`, or `k-sweep`).
    ///
    /// `--only path --only k-sweep` runs those two.
    #[arg(long)]
    pub(crate) only: Vec<String>,
    /// Where the report and its images go (replaced whole).
    #[arg(long, default_value = "out/evidence")]
    pub(crate) out: PathBuf,
    /// Where the path-traced reference is cached, as
    /// `reference-<settings hash>-<spp>spp/` (a run directory).
    #[arg(long, default_value = "out/cache")]
    pub(crate) cache: PathBuf,
    /// Worker threads (default: all cores).
    #[arg(long, value_parser = parse_threads)]
    pub(crate) threads: Option<usize>,
}
