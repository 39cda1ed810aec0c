//! The benchmark commands' flags and help: ray casting, photon tracing, the photon store,
//! splatting, k-NN queries, and accuracy against peer renderers.

use std::path::PathBuf;

/// Single-thread ray casting throughput (closest hit), coherent and incoherent.
///
/// Rays/s of camera rays (coherent) and random rays (incoherent) through the default
/// BVH4; the rays are generated before the clock starts, and each kind is timed --runs
/// times.
#[derive(clap::Args)]
pub(crate) struct BenchRays {
    /// The scene file (TOML).
    pub(crate) scene: PathBuf,
    /// Timed runs per kind; the median is reported.
    #[arg(long, default_value_t = 5)]
    pub(crate) runs: usize,
    /// Rays per run.
    #[arg(long, default_value_t = 1 << 20)]
    pub(crate) rays: usize,
    /// Also measure obvhs' CwBvh (spheres beside it) next to the default BVH4.
    #[arg(long)]
    pub(crate) compare: bool,
    /// Cast a saved ray set and check it against reference hits.
    ///
    /// Casts the rays of `DIR/coherent_rays.f32` and `DIR/incoherent_rays.f32` (rows of
    /// six little-endian f32: origin, direction) instead of generating them (`--rays` is
    /// then ignored); with `DIR/SET_hit_t.npy` also reports agreement with those
    /// closest-hit distances (inf = miss).
    #[arg(long, value_name = "DIR")]
    pub(crate) ray_dir: Option<PathBuf>,
    /// A peer's single-thread ray benchmark, timed alternately with ours.
    ///
    /// `NAME=CMD`: run by `sh -c CMD`, alternating with ours for `--runs` rounds; its
    /// `coherent`/`incoherent` lines' `X Mrays/s` are read and the ratios printed (use
    /// `--ray-dir` with the rays the peer casts, and run under `taskset -c N` so both
    /// share one core).
    #[arg(long, value_name = "NAME=CMD")]
    pub(crate) peer: Option<String>,
}

/// Photon paths/s on 1 and 2 threads, tracing alone and into photon files.
#[derive(clap::Args)]
pub(crate) struct BenchPhotons {
    /// The scene file (TOML).
    pub(crate) scene: PathBuf,
    /// Photon paths per run.
    #[arg(long, default_value_t = 1_000_000)]
    pub(crate) photons: u64,
    /// Timed runs; the median is reported.
    #[arg(long, default_value_t = 3)]
    pub(crate) runs: usize,
}

/// Write and read GB/s of a photon file (default 10M photons); plain records against
/// bincode.
#[derive(clap::Args)]
pub(crate) struct BenchStore {
    /// Photons in the file.
    #[arg(long, default_value_t = 10_000_000)]
    pub(crate) photons: usize,
    /// Directory for the temporary file.
    #[arg(long, default_value = "out/bench")]
    pub(crate) dir: PathBuf,
}

/// Caustic photons traced with differentials and splatted onto eye vertices: photons/s on
/// 1 and 2 threads, eye vertices, peak memory.
#[derive(clap::Args)]
pub(crate) struct BenchSplat {
    /// The scene file (TOML).
    pub(crate) scene: PathBuf,
    /// Caustic photon paths per run.
    #[arg(long, default_value_t = 1_000_000)]
    pub(crate) photons: u64,
    /// Timed runs; the median is reported.
    #[arg(long, default_value_t = 3)]
    pub(crate) runs: usize,
}

/// photonflow's sppm, vcm, path+splat, path and light against peer renderers at fixed time
/// budgets, one table per scene.
///
/// In one run, every image is scored by its relative MSE against a reference given as two
/// independent halves, with the reference's noise taken out; per budget the table gives
/// the best of each side, their error ratio and photonflow's time to the best peer's
/// error over the peer's time. Runs, peer images and the tables (tables.md) go into
/// --dir, written whole beside it and renamed into place when every case is done.
///
/// `cargo xtask bench accuracy` without --case or --suite runs the suite
/// scenes/bench-accuracy.toml: the worksheet box and McGuire's CornellBox-Original. Their
/// reference halves are rendered by `BENCH=1 OUTDIR=DIR tests/references/make.sh
/// cornell-spheres-analytic mcguire-original` (then --refs DIR).
#[derive(clap::Args)]
pub(crate) struct BenchAccuracy {
    /// SCENE.toml,REF_A.exr,REF_B.exr: a scene and its reference's two halves (same
    /// budget, other seeds). Repeatable.
    #[arg(long, value_parser = lab::accuracy::Case::parse)]
    pub(crate) case: Vec<lab::accuracy::Case>,
    /// A suite file of cases: `[[case]]` tables with `scene` (relative to the file),
    /// `reference_a` and `reference_b` (relative to --refs, else to the file).
    #[arg(long)]
    pub(crate) suite: Option<PathBuf>,
    /// Where the suite's reference halves are.
    #[arg(long)]
    pub(crate) refs: Option<PathBuf>,
    /// Time budgets in seconds, comma-separated.
    #[arg(long, value_delimiter = ',', default_value = "2,5,15,60")]
    pub(crate) budgets: Vec<f64>,
    /// photonflow's methods to run, comma-separated, in the table's order (default: sppm,
    /// vcm, path+splat, path, light).
    #[arg(long, value_delimiter = ',')]
    pub(crate) methods: Vec<scene::Method>,
    /// A peer: NAME, a built-in peer, or NAME=COMMAND, any renderer. Repeatable.
    ///
    /// The built-in peers are tests/references/peer.sh's: mitsuba, mitsuba-ptracer (its
    /// light tracer), luxcore, cycles, smallvcm-ppm, smallvcm-bpt and smallvcm-vcm (SmallVCM
    /// knows only the worksheet scene); they need PEERS and PEERS_VENV set, and Cycles BPY_VENV. NAME=COMMAND runs
    /// a shell command writing a linear EXR of the view of the scene file $SCENE to $OUT
    /// in about $BUDGET seconds.
    #[arg(long, value_parser = lab::accuracy::Peer::parse)]
    pub(crate) peer: Vec<lab::accuracy::Peer>,
    /// Worker threads of photonflow's runs (default: all cores); peers get it as $THREADS
    /// (0: all cores).
    #[arg(long)]
    pub(crate) threads: Option<usize>,
    /// Where runs, peer images and the tables go (replaced whole).
    #[arg(long, default_value = "out/bench/accuracy")]
    pub(crate) dir: PathBuf,
}

/// k-NN queries/s for k = 50, 250, 1000 over 1M photons, for each index.
#[derive(clap::Args)]
pub(crate) struct BenchKnn {
    /// Photons on the faces of a unit cube.
    #[arg(long, default_value_t = 1_000_000)]
    pub(crate) photons: usize,
    /// Queries per index and k.
    #[arg(long, default_value_t = 20_000)]
    pub(crate) queries: usize,
}

/// Load time and peak memory of generated meshes of 0.1M, 1M and 4M triangles, beside Mitsuba
/// 3 loading the same files.
///
/// Each mesh is a height field written as an OBJ (deterministic; generated once into --dir)
/// in a box under an area light. Every run loads the scene in a fresh process (`info`'s
/// load: OBJ parse and the mesh appended, then the BVH), which reports its parse and build
/// time and its peak resident memory (VmHWM). With PEERS_VENV set, Mitsuba 3 (`llvm_ad_rgb`,
/// `load_dict` of the OBJ, then of the scene around it) runs alternately with it, its
/// interpreter's start-up and the variant's set-up not counted; its peak (ru_maxrss) holds
/// Python and the JIT.
#[derive(clap::Args)]
pub(crate) struct BenchLoad {
    /// Triangle counts, comma-separated.
    #[arg(long, value_delimiter = ',', default_value = "100000,1000000,4000000")]
    pub(crate) sizes: Vec<usize>,
    /// Runs per mesh and loader (alternating); medians are reported.
    #[arg(long, default_value_t = 3)]
    pub(crate) runs: usize,
    /// Where the generated meshes are kept.
    #[arg(long, default_value = "out/bench/load")]
    pub(crate) dir: PathBuf,
    /// Load this scene once and print its times and peak memory (what each run does).
    #[arg(long, hide = true)]
    pub(crate) child: Option<PathBuf>,
}

/// The path tracer's efficiency against Mitsuba 3's at equal samples per pixel.
///
/// Per scene and sample count, --runs runs of `render --method path --spp N` (seeds 1, 2,
/// ...) and, with PEERS and PEERS_VENV set, of Mitsuba 3's path tracer
/// (`tests/references/peer.sh mitsuba` at those spp), alternating, each a fresh process timed
/// from start to finish. Both are unbiased, so a run's error is its noise: the per-pixel
/// variance over the runs relative to the squared mean of all runs (+ 0.01). Prints wall
/// seconds (median), that relMSE, the efficiency 1 / (relMSE x seconds), its ratio to
/// Mitsuba's and the ratio of the image means. Images go to --dir.
#[derive(clap::Args)]
pub(crate) struct BenchPath {
    /// Scene files, comma-separated.
    #[arg(
        long,
        value_delimiter = ',',
        default_value = "scenes/cornell-spheres/analytic.toml,scenes/mcguire/original.toml"
    )]
    pub(crate) scenes: Vec<PathBuf>,
    /// Samples per pixel, comma-separated.
    #[arg(long, value_delimiter = ',', default_value = "64,256")]
    pub(crate) spp: Vec<u32>,
    /// Runs per renderer, scene and spp (at least 2: the noise is measured between them).
    #[arg(long, default_value_t = 2)]
    pub(crate) runs: usize,
    /// Where the runs' images go.
    #[arg(long, default_value = "out/bench/path")]
    pub(crate) dir: PathBuf,
}
