//! `photonflow`: the one renderer binary. Each subcommand is a stage or a tool; `cargo xtask`
//! builds the binary in release and forwards a command to it (`bench <what>` as
//! `bench-<what>`, its output recorded). Errors print one line naming the file and the problem
//! and exit non-zero; nothing here panics on bad input.
//!
//! A command's or flag's help sits in its doc comment: the first paragraph is its line in
//! `-h`, the whole comment its `--help` (ripgrep's short and long help); [`long_helps`]
//! renders every `--help` for docs/commands.md.
//!
//! The command line lives in this library ([`run_args`]) so the end-to-end tests run every
//! command exactly as the binary does, in process; `main.rs` adds only what a process owns
//! (the Ctrl-C handler, printing the error, the exit code).

mod composite;
mod paths;

use clap::{Parser, Subcommand};
use render::settings::Knob;
use render::{Overrides, Photons, RenderRequest};
use scene::{Method, Scene};
use std::path::{Path, PathBuf};

/// Photon-mapping renderer.
///
/// Every parameter of a run lives in its scene file; flags only override it. `cargo xtask
/// <command>` builds this binary in release and runs it (`cargo xtask bench <what>` runs
/// `bench-<what>` and records its output). `photonflow <command> --help` gives a command's
/// details; docs/commands.md collects them all.
#[derive(Parser)]
#[command(name = "photonflow", version)]
struct Cli {
    #[command(subcommand)]
    cmd: Cmd,
}

#[derive(Subcommand)]
enum Cmd {
    /// Load a scene and print what it holds: triangles, spheres, lights and their power,
    /// materials.
    Info {
        /// The scene file (TOML).
        scene: PathBuf,
    },
    /// Single-thread ray casting throughput (closest hit), coherent and incoherent.
    ///
    /// Rays/s of camera rays (coherent) and random rays (incoherent) through the default
    /// BVH4; the rays are generated before the clock starts, and each kind is timed --runs
    /// times.
    BenchRays {
        /// The scene file (TOML).
        scene: PathBuf,
        /// Timed runs per kind; the median is reported.
        #[arg(long, default_value_t = 5)]
        runs: usize,
        /// Rays per run.
        #[arg(long, default_value_t = 1 << 20)]
        rays: usize,
        /// Also measure obvhs' CwBvh (spheres beside it) next to the default BVH4.
        #[arg(long)]
        compare: bool,
        /// Cast a saved ray set and check it against reference hits.
        ///
        /// Casts the rays of `DIR/coherent_rays.f32` and `DIR/incoherent_rays.f32` (rows of
        /// six little-endian f32: origin, direction) instead of generating them (`--rays` is
        /// then ignored); with `DIR/SET_hit_t.npy` also reports agreement with those
        /// closest-hit distances (inf = miss).
        #[arg(long, value_name = "DIR")]
        ray_dir: Option<PathBuf>,
        /// A peer's single-thread ray benchmark, timed alternately with ours.
        ///
        /// `NAME=CMD`: run by `sh -c CMD`, alternating with ours for `--runs` rounds; its
        /// `coherent`/`incoherent` lines' `X Mrays/s` are read and the ratios printed (use
        /// `--ray-dir` with the rays the peer casts, and run under `taskset -c N` so both
        /// share one core).
        #[arg(long, value_name = "NAME=CMD")]
        peer: Option<String>,
    },
    /// Photon paths/s on 1 and 2 threads, tracing alone and into photon files.
    BenchPhotons {
        /// The scene file (TOML).
        scene: PathBuf,
        /// Photon paths per run.
        #[arg(long, default_value_t = 1_000_000)]
        photons: u64,
        /// Timed runs; the median is reported.
        #[arg(long, default_value_t = 3)]
        runs: usize,
    },
    /// Write and read GB/s of a photon file (default 10M photons); plain records against
    /// bincode.
    BenchStore {
        /// Photons in the file.
        #[arg(long, default_value_t = 10_000_000)]
        photons: usize,
        /// Directory for the temporary file.
        #[arg(long, default_value = "out/bench")]
        dir: PathBuf,
    },
    /// Caustic photons traced with differentials and splatted onto eye vertices: photons/s on
    /// 1 and 2 threads, eye vertices, peak memory.
    BenchSplat {
        /// The scene file (TOML).
        scene: PathBuf,
        /// Caustic photon paths per run.
        #[arg(long, default_value_t = 1_000_000)]
        photons: u64,
        /// Timed runs; the median is reported.
        #[arg(long, default_value_t = 3)]
        runs: usize,
    },
    /// photonflow's sppm, path+splat and path against peer renderers at fixed time budgets,
    /// one table per scene.
    ///
    /// In one run, every image is scored by its relative MSE against a reference given as two
    /// independent halves, with the reference's noise taken out; per budget the table gives
    /// the best of each side, their error ratio and photonflow's time to the best peer's
    /// error over the peer's time. Runs and peer images go into --dir.
    ///
    /// `cargo xtask bench accuracy` without --case or --suite runs the suite
    /// scenes/bench-accuracy.toml: the worksheet box and McGuire's CornellBox-Original. Their
    /// reference halves are rendered by `BENCH=1 OUTDIR=DIR tests/references/make.sh
    /// cornell-spheres-analytic mcguire-original` (then --refs DIR).
    BenchAccuracy {
        /// SCENE.toml,REF_A.exr,REF_B.exr: a scene and its reference's two halves (same
        /// budget, other seeds). Repeatable.
        #[arg(long, value_parser = lab::accuracy::Case::parse)]
        case: Vec<lab::accuracy::Case>,
        /// A suite file of cases: `[[case]]` tables with `scene` (relative to the file),
        /// `reference_a` and `reference_b` (relative to --refs, else to the file).
        #[arg(long)]
        suite: Option<PathBuf>,
        /// Where the suite's reference halves are.
        #[arg(long)]
        refs: Option<PathBuf>,
        /// Time budgets in seconds, comma-separated.
        #[arg(long, value_delimiter = ',', default_value = "2,5,15,60")]
        budgets: Vec<f64>,
        /// A peer: NAME, a built-in peer, or NAME=COMMAND, any renderer. Repeatable.
        ///
        /// The built-in peers are tests/references/peer.sh's: mitsuba, luxcore, cycles,
        /// smallvcm-ppm, smallvcm-bpt and smallvcm-vcm (SmallVCM knows only the worksheet
        /// scene); they need PEERS and PEERS_VENV set, and Cycles BPY_VENV. NAME=COMMAND runs
        /// a shell command writing a linear EXR of the view of the scene file $SCENE to $OUT
        /// in about $BUDGET seconds.
        #[arg(long, value_parser = lab::accuracy::Peer::parse)]
        peer: Vec<lab::accuracy::Peer>,
        /// Where runs and peer images go.
        #[arg(long, default_value = "out/bench/accuracy")]
        dir: PathBuf,
    },
    /// k-NN queries/s for k = 50, 250, 1000 over 1M photons, for each index.
    BenchKnn {
        /// Photons on the faces of a unit cube.
        #[arg(long, default_value_t = 1_000_000)]
        photons: usize,
        /// Queries per index and k.
        #[arg(long, default_value_t = 20_000)]
        queries: usize,
    },
    /// Render an image by one method, with a progress bar (rate and time left).
    ///
    /// Writes into --out: image.exr (linear), image.png (tone-mapped with the course's gamma
    /// 1.8 and --exposure), the layers the image is made of under layers/, image.json (the
    /// settings, counts and timings; the error, with --reference) and scene.toml, the scene
    /// file with every flag applied, which renders the same image again bit for bit. The
    /// methods that run in passes also write the image at 1, 2, 4, 8, ... passes (the path
    /// tracer: samples per pixel) into snapshots/, with their seconds (and errors, with
    /// --reference) in image.json.
    ///
    /// path renders its samples in passes of 1, 1, 2, 4, ... samples per pixel, each at most
    /// an eighth of the run; its --passes N is --spp N. global-direct and final-gather trace
    /// the photon sets the scene needs (or reuse the cached ones), estimate and composite in
    /// one go. The splatting methods render the caustic layers: caustics seen directly (layer
    /// `caustic`) and through further diffuse bounces (`caustic_indirect`), caustic-splat
    /// alone, path+splat added to a path-traced image that leaves exactly those paths out;
    /// both run passes of new eye vertices and photons. sppm takes one camera sample per pixel
    /// and pass (so it refuses --spp), and its per-pixel radii shrink so that its error goes
    /// to zero.
    ///
    /// Why sppm is the default: on the worksheet scene it has 6.7 to 8.4 times less error than
    /// the best peer (SmallVCM's progressive photon mapping; Mitsuba 3, LuxCore, Cycles and
    /// SmallVCM's bidirectional methods further behind) at budgets of 2, 5, 15 and 60 s, and
    /// reaches that peer's 60-s error in 4.6 s (bench-accuracy, docs/benchmarks.md).
    Render {
        /// The scene file (TOML).
        scene: PathBuf,
        /// The method; its help is drawn from the method table (`command`).
        #[arg(long)]
        method: Option<Method>,
        #[command(flatten)]
        photon: PhotonArgs,
        #[command(flatten)]
        image: ImageArgs,
        /// Path tracer: leave out exactly the paths photon splatting owns (L S+ D S* E, D the
        /// first diffuse vertex from the eye), so a splatted caustic layer can be added.
        ///
        /// Render the caustic layer apart (caustic-splat) and `composite` the two runs.
        #[arg(long)]
        no_caustics: bool,
        /// Render only shard I of N (counted from 0) of the run, for `merge`.
        ///
        /// `path` shards by its passes of samples, `caustic-splat` by its passes; the shard
        /// goes into a shard directory (--out, default out/shards/...). `merge` puts the
        /// shards back together into the one-machine result, byte for byte.
        #[arg(long, value_parser = render::shard::ShardId::parse)]
        shard: Option<render::shard::ShardId>,
    },
    /// Estimate an image from the cached photon sets only (never traces).
    ///
    /// Swaps the estimator (--method, --k, --kernel, --topo, --boundary, --drop-kth) over the
    /// photon sets an earlier `trace` or `render` cached, without tracing them again. Writes
    /// what `render` writes.
    Estimate {
        /// The scene file (TOML).
        scene: PathBuf,
        /// A method that reads photon maps; its help is drawn from the method table.
        #[arg(long)]
        method: Option<Method>,
        #[command(flatten)]
        photon: PhotonArgs,
        #[command(flatten)]
        image: ImageArgs,
    },
    /// Worksheet 7's deliverable: the global map shown directly with the box kernel, with
    /// Silverman's kernel, + the topological test, + boundary correction; errors against a
    /// path-traced reference.
    ///
    /// The four estimates share one traced photon set; their errors are measured over the
    /// whole image and along the box's inner edges. The images and a Markdown summary of them
    /// (README.md) go into --out.
    Worksheet {
        /// The scene file (TOML).
        #[arg(long, default_value = "scenes/cornell-spheres/analytic.toml")]
        scene: PathBuf,
        /// Photon paths (each stores about 2.3 global photons in the Cornell box).
        #[arg(long, default_value_t = 200_000)]
        photons: u64,
        /// Nearest photons per estimate.
        #[arg(long, default_value_t = 1000)]
        k: usize,
        /// Topological test tolerance.
        #[arg(long, default_value_t = 0.1)]
        topo: f32,
        /// Samples per pixel of the path-traced reference.
        #[arg(long, default_value_t = 1024)]
        reference_spp: u32,
        /// Where the images, the summary and the reference go.
        #[arg(long, default_value = "out/worksheet")]
        out: PathBuf,
        /// Directory of cached photon files.
        #[arg(long, default_value = "out/cache")]
        cache: PathBuf,
        /// Worker threads (default: all cores).
        #[arg(long, value_parser = parse_threads)]
        threads: Option<usize>,
    },
    /// What accuracy costs in time, bias and variance apart: each technique over a ladder of
    /// budgets, --seeds independent runs each, against a reference.
    ///
    /// The techniques: path, path+splat, the global map shown directly with the box and
    /// Silverman kernels, + the topological test, + boundary correction, final gathering,
    /// SPPM, and the caustic map against splatting on the caustic layer; and the global map's
    /// k swept per kernel (k-sweep). The reference is path-traced (rendered once into --out,
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
    /// evidence.md and evidence.json. The default run takes about 40 minutes on 2 cores
    /// (measured: 40 min wall, 72 min CPU, reference included); see --quick.
    Evidence {
        /// The scene file (TOML).
        #[arg(default_value = "scenes/cornell-spheres/analytic.toml")]
        scene: PathBuf,
        /// A linear RGB EXR of the same view from any renderer (else a path-traced one,
        /// rendered once into --out and reused).
        #[arg(long)]
        reference: Option<PathBuf>,
        /// The reference's second independent half: errors and bias² against the halves'
        /// mean, with the reference's noise taken out beside the plain figures.
        #[arg(long)]
        reference_b: Option<PathBuf>,
        /// Samples per pixel of the path-traced reference [default: 1024, 512 with --quick].
        #[arg(long)]
        reference_spp: Option<u32>,
        /// Independent runs (seeds 1..=N) per technique and budget [default: 8, 4 with
        /// --quick].
        #[arg(long)]
        seeds: Option<u32>,
        /// About 2 minutes on 2 cores in place of about 40, trading detail and certainty for
        /// time.
        ///
        /// About 1 minute once its reference is cached. The image at most 256 pixels on a
        /// side (the scene's view; unless --reference fixes the size), 4 seeds, a 512-spp
        /// reference, two budgets per technique and k in {50, 250, 1000}: bias² and variance
        /// are noisier, and errors sit nearer the reference's own noise.
        #[arg(long)]
        quick: bool,
        /// Multiply every budget of the ladder and the k sweep's photon counts by this.
        #[arg(long, default_value_t = 1.0)]
        budget_scale: f64,
        /// Only this technique (repeatable; its name in lower case with dashes, e.g.
        /// `path`, `caustic-map-k-nn`, or `k-sweep`).
        ///
        /// `--only path --only k-sweep` runs those two.
        #[arg(long)]
        only: Vec<String>,
        /// Where the report, its images and the reference go.
        #[arg(long, default_value = "out/evidence")]
        out: PathBuf,
        /// Worker threads (default: all cores).
        #[arg(long, value_parser = parse_threads)]
        threads: Option<usize>,
    },
    /// Trace the photon sets a scene needs into the cache (or reuse them).
    ///
    /// The sets are the ones the scene's effects plan asks for, cached under a hash of what
    /// they depend on: they are reused while the scene and the parameters are unchanged.
    /// `estimate` reads them; `render` traces or reuses them itself.
    Trace {
        /// The scene file (TOML).
        scene: PathBuf,
        /// Seed of every random stream (default: the scene file's `seed`).
        #[arg(long)]
        seed: Option<u64>,
        /// Photon paths to emit (default: the scene's [photons] table).
        #[arg(long)]
        photons: Option<u64>,
        /// Cache directory of photon files.
        #[arg(long, default_value = "out/cache")]
        cache: PathBuf,
        /// Worker threads (default: all cores).
        #[arg(long, value_parser = parse_threads)]
        threads: Option<usize>,
        /// Trace even if the cache holds the sets.
        #[arg(long)]
        force: bool,
        /// Trace only shard I of N (counted from 0), for `merge`.
        ///
        /// Photon paths [I P / N, (I + 1) P / N) go into a shard directory (--out), not into
        /// the cache; `merge` puts the shards' photon sets into a cache directory.
        #[arg(long, value_parser = render::shard::ShardId::parse)]
        shard: Option<render::shard::ShardId>,
        /// The shard directory (default: out/shards/<scene dir>-<stem>-trace-I-of-N).
        #[arg(long, requires = "shard")]
        out: Option<PathBuf>,
    },
    /// Put the shards of one run (`trace --shard`, `render --shard`) back together into the
    /// result the one-machine run writes, byte for byte.
    ///
    /// Shards are read in shard order: photon sets go into a cache directory, images into a
    /// run directory. Refuses a missing, duplicated or overlapping shard, or shards of another
    /// scene, seed or parameter set.
    Merge {
        /// Shard directories (any order).
        #[arg(required = true)]
        inputs: Vec<PathBuf>,
        /// Photon shards: the cache directory to write the photon files into; image shards:
        /// the run directory to write.
        #[arg(long)]
        out: PathBuf,
    },
    /// Combine runs of one view: layers of one name averaged by their counts, layers of
    /// disjoint light-path classes summed.
    ///
    /// The inputs are runs' output directories (or their `image.exr` paths): independent runs
    /// of one method (another --seed each), or a path-traced image rendered with
    /// --no-caustics and a caustic-only layer (caustic-splat). Sums are in f64, in a fixed
    /// order. Refuses runs of another view or size, overlapping layers and runs sharing a
    /// seed. The result is a run directory of its own, which can be composited again.
    Composite {
        /// Runs' output directories (or their `image.exr` paths).
        #[arg(required = true)]
        inputs: Vec<PathBuf>,
        /// The run directory to write.
        #[arg(long)]
        out: PathBuf,
        /// Exposure of the PNG in stops.
        #[arg(long, default_value_t = 0.0, value_parser = parse_finite)]
        exposure: f32,
    },
    /// Error metrics of image A against reference B (linear EXR files): RMSE, relative MSE in
    /// two conventions, mean absolute error and LDR-FLIP.
    ///
    /// Given a second reference B2, an independent half of the same budget with another seed,
    /// the figures are against the halves' mean, with the reference's own noise taken out
    /// ((B - B2)²/4 per pixel), the plain figures beside. `evidence` takes such a second half
    /// as --reference-b, `bench-accuracy` in each --case.
    Compare {
        /// The image to score (linear EXR).
        a: PathBuf,
        /// The reference (linear EXR).
        b: PathBuf,
        /// The reference's second, independent half (linear EXR).
        b2: Option<PathBuf>,
        /// Restrict every figure to the pixel rectangle x0,y0,x1,y1 (half open).
        #[arg(long, value_parser = parse_rect)]
        mask: Option<[usize; 4]>,
    },
}

/// Image settings shared by `render` and `estimate`.
#[derive(clap::Args)]
struct ImageArgs {
    /// Samples per pixel; where it goes per method is drawn from the method table (`command`).
    #[arg(long)]
    spp: Option<u32>,
    /// Worker threads (default: all cores). The image does not depend on it.
    #[arg(long, value_parser = parse_threads)]
    threads: Option<usize>,
    /// Output directory (default: out/<scene dir>-<scene stem>-<method>).
    #[arg(long)]
    out: Option<PathBuf>,
    /// Exposure of the PNG in stops.
    #[arg(long, default_value_t = 0.0, value_parser = parse_finite)]
    exposure: f32,
}

/// Photon-mapping settings shared by `estimate` and `render`.
#[derive(clap::Args)]
struct PhotonArgs {
    /// Seed of every random stream (default: the scene file's `seed`); recorded in the
    /// outputs' `scene.toml` and `image.json`.
    #[arg(long)]
    seed: Option<u64>,
    /// Photon paths emitted (default: the scene's [photons] table).
    #[arg(long)]
    photons: Option<u64>,
    /// Directory of cached photon files.
    #[arg(long, default_value = "out/cache")]
    cache: PathBuf,
    /// Nearest photons per global-map estimate (default: [estimate.global] k, else 1000).
    #[arg(long)]
    k: Option<usize>,
    /// Kernel of the global-map estimate, by the scene file's `kind` names: uniform, cone,
    /// cone:K, gaussian, gaussian_jensen, epanechnikov, silverman, triweight.
    #[arg(long, value_parser = <density::Kernel as std::str::FromStr>::from_str)]
    kernel: Option<density::Kernel>,
    /// Topological test: keep photons whose direction from the estimation point is within
    /// |cos| < EPS of the tangent plane.
    #[arg(long)]
    topo: Option<f32>,
    /// Drop the k-th photon (Garcia et al. 2012).
    #[arg(long)]
    drop_kth: bool,
    /// Correct global-map estimates for boundary bias: divide by the share of the kernel's
    /// mass that lies on the surface (found by short probe rays).
    #[arg(long)]
    boundary: bool,
    /// Final-gather rays per sample (default: the scene's estimate.final_gather.rays, 16).
    #[arg(long)]
    gather_rays: Option<u32>,
    /// Final gathering reads irradiance precomputed at every N-th global photon
    /// (Christensen 1999); 0 estimates from the map at every gather hit (default: the
    /// scene's estimate.final_gather.cache, 4).
    #[arg(long)]
    gather_cache: Option<usize>,
    /// Passes of the progressive methods; where it goes per method is drawn from the method
    /// table (`command`).
    #[arg(long)]
    passes: Option<u32>,
    /// Seconds for the progressive methods' passes (the full help is drawn from the method
    /// table in `command`).
    #[arg(long)]
    time: Option<f64>,
    /// Compare with this linear EXR (the path-traced reference) and record the error.
    #[arg(long)]
    reference: Option<PathBuf>,
    /// Name of the output directory's method part.
    #[arg(long)]
    label: Option<String>,
}

impl PhotonArgs {
    fn overrides(&self, method: Option<Method>, spp: Option<u32>) -> Overrides {
        Overrides {
            method,
            spp,
            photons: self.photons,
            k: self.k,
            kernel: self.kernel,
            topo: self.topo.map(Some),
            drop_kth: self.drop_kth.then_some(true),
            boundary: self.boundary.then_some(true),
            gather_rays: self.gather_rays,
            gather_cache: self.gather_cache,
            caustics: None,
            passes: self.passes,
            splat_photons: None,
            splat_indirect: None,
            time: self.time,
        }
    }
}

/// The one load of a command's scene, with `--seed` applied.
fn load(path: &Path, seed: Option<u64>) -> Result<Scene, String> {
    let scene = Scene::load_with(path, |f| {
        if let Some(s) = seed {
            f.seed = s;
        }
    })
    .map_err(|e| e.to_string())?;
    for w in &scene.warnings {
        eprintln!("warning: {w}");
    }
    Ok(scene)
}

/// `render` and `estimate`: the one path through the library, then a summary line.
fn render(scene: &Scene, req: RenderRequest) -> Result<(), String> {
    let r = render::render(scene, &req)?;
    println!(
        "rendered {} in {:.2} s; wrote {}/image.{{exr,png,json}}, layers/, scene.toml",
        r.settings.method,
        r.seconds,
        r.out.display()
    );
    if let Some(m) = &r.metrics {
        println!("against the reference: {m}");
    }
    Ok(())
}

/// `--threads`: 0 would leave no worker, whatever the command does first (a cache hit too).
fn parse_threads(s: &str) -> Result<usize, String> {
    match s.parse::<usize>() {
        Ok(0) => Err("must be at least 1".into()),
        Ok(n) => Ok(n),
        Err(e) => Err(e.to_string()),
    }
}

/// A number that must be finite (`--exposure`): NaN or infinity would make every pixel NaN.
fn parse_finite(s: &str) -> Result<f32, String> {
    match s.parse::<f32>() {
        Ok(x) if x.is_finite() => Ok(x),
        Ok(x) => Err(format!("{x} is not a finite number")),
        Err(e) => Err(e.to_string()),
    }
}

fn parse_rect(s: &str) -> Result<[usize; 4], String> {
    let v: Vec<usize> = s
        .split(',')
        .map(|t| t.trim().parse::<usize>().map_err(|e| format!("`{t}`: {e}")))
        .collect::<Result<_, _>>()?;
    <[usize; 4]>::try_from(v).map_err(|_| "expected x0,y0,x1,y1".to_string())
}

/// The widest `--help` gets, however wide the terminal: longer lines are hard to read, and
/// [`long_helps`] renders at this width.
pub const HELP_WIDTH: usize = 100;

/// The command line, with the help of the flags whose meaning depends on the method drawn
/// from the method table (`--method`'s list and default, where `--spp` and `--passes` go,
/// which counts `--time` only caps), so it never describes another set of methods.
pub fn command() -> clap::Command {
    use clap::CommandFactory;
    use render::methods::{ESTIMATE_DEFAULT, METHODS, MethodRow};
    let names = |rows: &mut dyn Iterator<Item = &MethodRow>| -> Vec<String> {
        rows.map(|r| r.method.name()).collect()
    };
    let lines = |rows: &mut dyn Iterator<Item = &MethodRow>| -> String {
        rows.map(|r| format!("\n  {}: {}", r.method, r.help))
            .collect()
    };
    let render_short = format!(
        "The method (default: the scene's render.method, else {}): {}",
        Method::default(),
        names(&mut METHODS.iter()).join(", ")
    );
    let render_long = format!(
        "The method (default: the scene's render.method, else {}):{}",
        Method::default(),
        lines(&mut METHODS.iter())
    );
    let maps = || METHODS.iter().filter(|r| r.reads_photon_maps());
    let estimate_short = format!(
        "{} (default: the scene's render.method when it is one of these, else \
         {ESTIMATE_DEFAULT})",
        names(&mut maps()).join(" or "),
    );
    let estimate_long = format!(
        "{estimate_short}. Of these, {ESTIMATE_DEFAULT} is the one `bench-accuracy` measured \
         reaching the path tracer's error:{}",
        lines(&mut maps())
    );
    // Where `--spp` and `--passes` go, per method, from the table.
    let knob_help = |what: &str, knob: fn(&MethodRow) -> Option<Knob>| {
        let places: Vec<String> = METHODS
            .iter()
            .map(|r| match knob(r) {
                Some(k) => format!("{}: {}", r.method, k.key()),
                None => format!("{}: refused", r.method),
            })
            .collect();
        let short = format!("{what} (default: the scene file's)");
        let long = format!("{what} (default: the scene file's; {})", places.join(", "));
        (short, long)
    };
    let (spp_short, spp_long) = knob_help("Samples per pixel", |r| r.spp);
    let (passes_short, passes_long) = knob_help("Passes of the progressive methods", |r| r.passes);
    let passes_long = format!("{passes_long}. A run stopped by --time records the passes made.");
    // Which flags give the count that --time then only caps, per progressive method.
    let counts: Vec<String> = METHODS
        .iter()
        .filter(|r| r.passes.is_some())
        .map(|r| {
            let flags: Vec<&str> = [("--spp", r.spp), ("--passes", r.passes)]
                .into_iter()
                .filter(|(_, k)| k.is_some_and(Knob::counts_passes))
                .map(|(f, _)| f)
                .collect();
            format!("{}: {}", r.method, flags.join(" or "))
        })
        .collect();
    let time_short = "Seconds to render for: a budget to use, past the scene file's count; with \
                      the count given too, a cap";
    let time_long = format!(
        "Seconds to render for, a budget to use: the progressive methods' passes go on past \
         the scene file's count until the time is used, and the run stops after the pass that \
         uses it, so the last pass overshoots by at most one pass. With the run's count given \
         too ({}) the time only caps it: the run stops at whichever comes first.\n\n\
         The path tracer's passes under a budget hold at most the samples 1/{:.0} of the \
         budget makes at the rate measured so far, so its last pass overshoots by about that \
         (or by one sample per pixel, if that takes longer); its snapshots are still written \
         at every power of two. A run that reaches the largest count its setting takes stops \
         there, with a warning that the budget was not used up.\n\n\
         The output's scene.toml and image.json record the passes made, so scene.toml renders \
         the same image again. Methods without passes refuse --time.",
        counts.join("; "),
        1.0 / render::passes::BUDGET_SHARE
    );
    let methodwise = |c: clap::Command, short: String, long: String| {
        c.mut_arg("method", |a| a.help(short).long_help(long))
            .mut_arg("spp", |a| {
                a.help(spp_short.clone()).long_help(spp_long.clone())
            })
            .mut_arg("passes", |a| {
                a.help(passes_short.clone()).long_help(passes_long.clone())
            })
            .mut_arg("time", |a| a.help(time_short).long_help(time_long.clone()))
    };
    // `mut_subcommands` keeps the commands' order, which docs/commands.md follows.
    Cli::command()
        .max_term_width(HELP_WIDTH)
        .mut_subcommands(|c| match c.get_name() {
            "render" => methodwise(c, render_short.clone(), render_long.clone()),
            "estimate" => methodwise(c, estimate_short.clone(), estimate_long.clone()),
            _ => c,
        })
}

/// Every command's `--help` as the binary prints it on a terminal [`HELP_WIDTH`] columns wide
/// or wider, as (the command line, the text): `photonflow --help` first, then each command's
/// in the order of `photonflow --help`. docs/commands.md holds these.
pub fn long_helps() -> Vec<(String, String)> {
    let root = command();
    let names: Vec<String> = root
        .get_subcommands()
        .map(|c| c.get_name().to_string())
        .collect();
    let lines = std::iter::once(vec!["photonflow".to_string(), "--help".into()]).chain(
        names
            .into_iter()
            .map(|n| vec!["photonflow".to_string(), n, "--help".into()]),
    );
    lines
        .map(|args| {
            // Parsing `--help` always stops with the help as its "error", as the binary
            // prints it (`to_string` leaves out the terminal's colours).
            let text = match command().term_width(HELP_WIDTH).try_get_matches_from(&args) {
                Ok(_) => String::new(),
                Err(e) => e.render().to_string(),
            };
            (args.join(" "), text)
        })
        .collect()
}

/// Runs the command line `args` (the program name first) as the binary does. Returns the exit
/// code and, for a failure, the one line the binary prints on stderr (not printed here):
/// 2 for a usage error, 1 for a command that fails. Help and version go to stdout (exit 0).
pub fn run_args<I, T>(args: I) -> (u8, Option<String>)
where
    I: IntoIterator<Item = T>,
    T: Into<std::ffi::OsString> + Clone,
{
    let parsed = command()
        .try_get_matches_from(args)
        .and_then(|m| <Cli as clap::FromArgMatches>::from_arg_matches(&m));
    let cli = match parsed {
        Ok(c) => c,
        Err(e) => {
            use clap::error::ErrorKind;
            let code = e.exit_code() as u8;
            // clap's own usage errors span several lines; here they are one.
            return match e.kind() {
                ErrorKind::DisplayHelp
                | ErrorKind::DisplayVersion
                | ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand => {
                    let _ = e.print();
                    (code, None)
                }
                _ => {
                    let text = e.to_string();
                    let line: Vec<&str> = text
                        .lines()
                        .map(str::trim)
                        .take_while(|l| {
                            !l.starts_with("Usage:") && !l.starts_with("For more information")
                        })
                        .filter(|l| !l.is_empty())
                        .collect();
                    (code, Some(format!("{} (see --help)", line.join(" "))))
                }
            };
        }
    };
    match run(cli.cmd) {
        Ok(()) => (0, None),
        Err(e) => {
            // One line, whatever a library's message holds (a TOML error's excerpt, say).
            let line: Vec<&str> = e.lines().map(str::trim).filter(|l| !l.is_empty()).collect();
            (1, Some(format!("error: {}", line.join("; "))))
        }
    }
}

fn run(cmd: Cmd) -> Result<(), String> {
    match cmd {
        Cmd::Info { scene } => info(&scene),
        Cmd::BenchRays {
            scene,
            runs,
            rays,
            compare,
            ray_dir,
            peer,
        } => {
            let peer = match &peer {
                Some(p) => Some(
                    p.split_once('=')
                        .ok_or_else(|| format!("--peer {p}: expected NAME=CMD"))?,
                ),
                None => None,
            };
            lab::bench::rays(&scene, runs, rays, compare, ray_dir.as_deref(), peer)
        }
        Cmd::Render {
            scene,
            method,
            photon,
            image,
            no_caustics,
            shard,
        } => {
            let s = load(&scene, photon.seed)?;
            let overrides = Overrides {
                caustics: no_caustics.then_some(false),
                ..photon.overrides(method, image.spp)
            };
            if let Some(shard) = shard {
                return render_shard(&s, &overrides, &photon, &image, shard);
            }
            let out = out_dir(&s, &overrides, &photon, image.out);
            render(
                &s,
                RenderRequest {
                    overrides,
                    cache: &photon.cache,
                    photons: Photons::TraceOrReuse,
                    threads: image.threads,
                    out,
                    exposure: image.exposure,
                    reference: photon.reference.as_deref(),
                    label: photon.label.clone(),
                },
            )
        }
        Cmd::Estimate {
            scene,
            method,
            photon,
            image,
        } => {
            let reads_maps = |m: Method| render::methods::row(m).reads_photon_maps();
            if let Some(m) = method
                && !reads_maps(m)
            {
                return Err(format!(
                    "estimate reads photon maps: use `render --method {m}` for `{m}`"
                ));
            }
            let s = load(&scene, photon.seed)?;
            // A scene whose method reads no photon maps gets the best photon-map method.
            let method = method.unwrap_or(match s.render().method {
                m if reads_maps(m) => m,
                _ => render::methods::ESTIMATE_DEFAULT,
            });
            let overrides = photon.overrides(Some(method), image.spp);
            let out = out_dir(&s, &overrides, &photon, image.out);
            render(
                &s,
                RenderRequest {
                    overrides,
                    cache: &photon.cache,
                    photons: Photons::CacheOnly,
                    threads: image.threads,
                    out,
                    exposure: image.exposure,
                    reference: photon.reference.as_deref(),
                    label: photon.label.clone(),
                },
            )
        }
        Cmd::Composite {
            inputs,
            out,
            exposure,
        } => composite::run(&inputs, &out, exposure),
        Cmd::Compare { a, b, b2, mask } => {
            let img = render::output::read_finite(&a, "pixels")?;
            let (text, reference) = match b2 {
                Some(b2) => {
                    let (m, mean) = render::output::compare_halves(&a, &b, &b2, mask)?;
                    (m.to_string(), mean)
                }
                None => (
                    render::output::compare(&a, &b, mask)?.to_string(),
                    render::output::read_finite(&b, "pixels")?,
                ),
            };
            let flip = render::output::compare_flip(&img, &reference, mask)
                .map_err(|e| format!("{}: {e}", a.display()))?;
            println!("{text} flip={flip:.5}");
            Ok(())
        }
        Cmd::BenchPhotons {
            scene,
            photons,
            runs,
        } => lab::bench::photons(&scene, photons, runs),
        Cmd::BenchStore { photons, dir } => lab::bench::store(photons, &dir),
        Cmd::BenchSplat {
            scene,
            photons,
            runs,
        } => lab::bench::splat(&scene, photons, runs),
        Cmd::BenchKnn { photons, queries } => lab::bench::knn(photons, queries),
        Cmd::BenchAccuracy {
            mut case,
            suite,
            refs,
            budgets,
            peer,
            dir,
        } => {
            if let Some(suite) = suite {
                case.extend(lab::accuracy::read_suite(&suite, refs.as_deref())?);
            }
            lab::accuracy::accuracy(&case, &budgets, &peer, &dir)
        }
        Cmd::Evidence {
            scene,
            reference,
            reference_b,
            reference_spp,
            seeds,
            quick,
            budget_scale,
            only,
            out,
            threads,
        } => lab::evidence(&lab::evidence::EvidenceArgs {
            scene,
            reference,
            reference_b,
            reference_spp: reference_spp.unwrap_or(if quick {
                lab::evidence::QUICK_REFERENCE_SPP
            } else {
                lab::evidence::REFERENCE_SPP
            }),
            seeds: seeds.unwrap_or(if quick {
                lab::evidence::QUICK_SEEDS
            } else {
                lab::evidence::SEEDS
            }),
            quick,
            budget_scale,
            only,
            out,
            threads,
        }),
        Cmd::Worksheet {
            scene,
            photons,
            k,
            topo,
            reference_spp,
            out,
            cache,
            threads,
        } => {
            let s = load(&scene, None)?;
            lab::worksheet::run(
                &s,
                &lab::worksheet::WorksheetArgs {
                    scene,
                    photons,
                    k,
                    topo,
                    reference_spp,
                    out,
                    cache,
                    threads,
                },
            )
        }
        Cmd::Trace {
            scene,
            seed,
            photons,
            cache,
            threads,
            force,
            shard,
            out,
        } => {
            let s = load(&scene, seed)?;
            let overrides = Overrides {
                photons,
                ..Overrides::default()
            };
            if let Some(shard) = shard {
                let out = out.unwrap_or_else(|| paths::shard_out(&scene, "trace", shard));
                let m = render::trace_shard(&s, &overrides, shard, &out, threads)?;
                println!(
                    "traced shard {shard}: photon paths {}..{} of {} in {:.2} s into {}",
                    m.range[0],
                    m.range[1],
                    m.total,
                    m.seconds,
                    out.display()
                );
                return Ok(());
            }
            render::trace(&s, &overrides, &cache, threads, force).map(|_| ())
        }
        Cmd::Merge { inputs, out } => {
            println!("{}", render::shard::merge(&inputs, &out)?);
            Ok(())
        }
    }
}

/// `--out`, or `out/<scene dir>-<scene stem>-<label or method>`.
fn out_dir(scene: &Scene, o: &Overrides, photon: &PhotonArgs, out: Option<PathBuf>) -> PathBuf {
    out.unwrap_or_else(|| {
        let method = o.method.unwrap_or(scene.render().method);
        let label = photon.label.clone().unwrap_or_else(|| method.name());
        paths::run_out(&scene.path, &label)
    })
}

/// `render --shard`: the shard's blocks of the run into a shard directory.
fn render_shard(
    scene: &Scene,
    overrides: &Overrides,
    photon: &PhotonArgs,
    image: &ImageArgs,
    shard: render::shard::ShardId,
) -> Result<(), String> {
    let settings = render::Settings::new(scene, overrides)?;
    let label = photon
        .label
        .clone()
        .unwrap_or_else(|| settings.method.name());
    let out = image
        .out
        .clone()
        .unwrap_or_else(|| paths::shard_out(&scene.path, &label, shard));
    let run = render::Run {
        scene,
        settings: &settings,
        cache: &photon.cache,
        photons: Photons::TraceOrReuse,
        threads: image.threads,
    };
    let m = render::shard::render(&run, shard, &out)?;
    println!(
        "rendered shard {shard} of {}: {} {} in {:.2} s into {}",
        settings.method,
        m.count,
        m.unit,
        m.seconds,
        out.display()
    );
    Ok(())
}

fn info(path: &Path) -> Result<(), String> {
    print!("{}", render::describe(&load(path, None)?));
    Ok(())
}
