//! `photonflow`: the one renderer binary. Each subcommand is a stage or a tool; `cargo xtask`
//! chains them. Errors print one line naming the file and the problem and exit non-zero;
//! nothing here panics on bad input.
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

#[derive(Parser)]
#[command(name = "photonflow", about = "Photon-mapping renderer", version)]
struct Cli {
    #[command(subcommand)]
    cmd: Cmd,
}

#[derive(Subcommand)]
enum Cmd {
    /// Load a scene and print what it holds.
    Info { scene: PathBuf },
    /// Single-thread ray casting throughput (closest hit), coherent and incoherent.
    BenchRays {
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
        /// Cast the rays of `DIR/coherent_rays.f32` and `DIR/incoherent_rays.f32` (rows of
        /// six little-endian f32: origin, direction) instead of generating them (`--rays` is
        /// then ignored); with `DIR/SET_hit_t.npy` also report agreement with those
        /// closest-hit distances (inf = miss).
        #[arg(long, value_name = "DIR")]
        ray_dir: Option<PathBuf>,
        /// `NAME=CMD`: a peer's single-thread ray benchmark run by `sh -c CMD`, alternating
        /// with ours for `--runs` rounds; its `coherent`/`incoherent` lines' `X Mrays/s` are
        /// read and the ratios printed (use `--ray-dir` with the rays the peer casts).
        #[arg(long, value_name = "NAME=CMD")]
        peer: Option<String>,
    },
    /// Photon paths/s on 1 and 2 threads, tracing only and through the pipeline to files.
    BenchPhotons {
        scene: PathBuf,
        #[arg(long, default_value_t = 1_000_000)]
        photons: u64,
        #[arg(long, default_value_t = 3)]
        runs: usize,
    },
    /// Write/read throughput of a photon file (default 10M photons), and encodings compared.
    BenchStore {
        #[arg(long, default_value_t = 10_000_000)]
        photons: usize,
        /// Directory for the temporary file.
        #[arg(long, default_value = "out/bench")]
        dir: PathBuf,
    },
    /// Caustic photons traced with differentials and splatted onto eye vertices: photons/s on
    /// 1 and 2 threads, eye vertices, peak memory.
    BenchSplat {
        scene: PathBuf,
        #[arg(long, default_value_t = 1_000_000)]
        photons: u64,
        #[arg(long, default_value_t = 3)]
        runs: usize,
    },
    /// photonflow's sppm, path+splat and path and the peer renderers at fixed time budgets,
    /// in one run, each image's relative MSE against a reference given as two independent
    /// halves with the reference's noise taken out; per budget, the best of each side, their
    /// error ratio and photonflow's time to the best peer's error over the peer's time.
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
        /// A peer: NAME of the repository's peer runner (mitsuba, luxcore, cycles,
        /// smallvcm-ppm, smallvcm-bpt, smallvcm-vcm; it reads PEERS, PEERS_VENV and BPY_VENV)
        /// or NAME=COMMAND, a shell command writing a linear EXR of the view of the scene file
        /// $SCENE to $OUT in about $BUDGET seconds. Repeatable.
        #[arg(long, value_parser = lab::accuracy::Peer::parse)]
        peer: Vec<lab::accuracy::Peer>,
        /// Where runs and peer images go.
        #[arg(long, default_value = "out/bench/accuracy")]
        dir: PathBuf,
    },
    /// k-NN queries/s for k = 50, 250, 1000 for each index.
    BenchKnn {
        #[arg(long, default_value_t = 1_000_000)]
        photons: usize,
        #[arg(long, default_value_t = 20_000)]
        queries: usize,
    },
    /// Render an image. `--method path` is the path-traced reference; `global-direct` and
    /// `final-gather` chain trace (or reuse the cached photons) → estimate → composite.
    Render {
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
        #[arg(long)]
        no_caustics: bool,
        /// Render only shard I of N (counted from 0) of the run: `path` by its passes of
        /// samples, `caustic-splat` by its passes, into a shard directory (--out, default
        /// out/shards/...) for `merge`.
        #[arg(long, value_parser = render::shard::ShardId::parse)]
        shard: Option<render::shard::ShardId>,
    },
    /// Estimate an image from cached photon sets (never traces).
    Estimate {
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
    /// Silverman's kernel, and with the topological test; errors against a path-traced
    /// reference; a Markdown summary beside the images.
    Worksheet {
        #[arg(long, default_value = "scenes/cornell-spheres/analytic.toml")]
        scene: PathBuf,
        /// Photon paths (each stores about 2.3 global photons in the Cornell box).
        #[arg(long, default_value_t = 200_000)]
        photons: u64,
        #[arg(long, default_value_t = 1000)]
        k: usize,
        /// Topological test tolerance.
        #[arg(long, default_value_t = 0.1)]
        topo: f32,
        #[arg(long, default_value_t = 1024)]
        reference_spp: u32,
        #[arg(long, default_value = "out/worksheet")]
        out: PathBuf,
        #[arg(long, default_value = "out/cache")]
        cache: PathBuf,
        #[arg(long, value_parser = parse_threads)]
        threads: Option<usize>,
    },
    /// What accuracy costs in time, bias and variance apart: each technique over a ladder of
    /// budgets, `--seeds` independent runs each, against a reference; errors and bias^2 /
    /// variance per region (from the scene's geometry), maps as EXR and false-colour PNG.
    Evidence {
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
        /// A few minutes on 2 cores in place of about 45: the image at most 256 pixels on a
        /// side (the scene's view; unless --reference fixes the size), 4 seeds, a 512-spp
        /// reference, two budgets per technique and k in {50, 250, 1000}. Noisier bias^2 and
        /// variance, and errors nearer the reference's own noise.
        #[arg(long)]
        quick: bool,
        /// Multiply every budget of the ladder and the k sweep's photon counts by this.
        #[arg(long, default_value_t = 1.0)]
        budget_scale: f64,
        /// Only this technique (repeatable; its name in lower case with dashes, e.g.
        /// `path`, `caustic-map-k-nn`, or `k-sweep`).
        #[arg(long)]
        only: Vec<String>,
        #[arg(long, default_value = "out/evidence")]
        out: PathBuf,
        #[arg(long, value_parser = parse_threads)]
        threads: Option<usize>,
    },
    /// Trace the photon sets a scene needs into the cache (or reuse them).
    Trace {
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
        #[arg(long, value_parser = parse_threads)]
        threads: Option<usize>,
        /// Trace even if the cache holds the sets.
        #[arg(long)]
        force: bool,
        /// Trace only shard I of N (counted from 0): photon paths [I P / N, (I + 1) P / N),
        /// into a shard directory (--out) for `merge`, not into the cache.
        #[arg(long, value_parser = render::shard::ShardId::parse)]
        shard: Option<render::shard::ShardId>,
        /// The shard directory (default: out/shards/<scene dir>-<stem>-trace-I-of-N).
        #[arg(long, requires = "shard")]
        out: Option<PathBuf>,
    },
    /// Put the shards of one run (`trace --shard`, `render --shard`) back together, in shard
    /// order, into the result the one-machine run writes, byte for byte: photon sets into a
    /// cache directory, images into a run directory. Refuses a missing, duplicated or
    /// overlapping shard, or shards of another scene, seed or parameter set.
    Merge {
        /// Shard directories (any order).
        #[arg(required = true)]
        inputs: Vec<PathBuf>,
        /// Photon shards: the cache directory to write the photon files into; image shards:
        /// the run directory to write.
        #[arg(long)]
        out: PathBuf,
    },
    /// Combine runs of one view (their output directories or `image.exr` paths): layers of
    /// one name averaged by their counts, disjoint layers summed, in f64, in a fixed order.
    Composite {
        #[arg(required = true)]
        inputs: Vec<PathBuf>,
        #[arg(long)]
        out: PathBuf,
        /// Exposure of the PNG in stops.
        #[arg(long, default_value_t = 0.0, value_parser = parse_finite)]
        exposure: f32,
    },
    /// Error metrics of image A against reference B (linear EXR files); given a second
    /// reference B2, an independent half of the same budget with another seed, against the
    /// halves' mean with the reference's own noise taken out ((B - B2)²/4 per pixel), the plain
    /// figures beside.
    Compare {
        a: PathBuf,
        b: PathBuf,
        b2: Option<PathBuf>,
        /// Restrict to the pixel rectangle x0,y0,x1,y1 (half open).
        #[arg(long, value_parser = parse_rect)]
        mask: Option<[usize; 4]>,
    },
}

/// Image settings shared by `render` and `estimate`.
#[derive(clap::Args)]
struct ImageArgs {
    /// Samples per pixel (default: the scene file's render.spp for `path`, estimate.spp
    /// (default 1) for the photon methods, which already average many photons per estimate).
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
    /// Photon passes of the progressive methods (caustic-splat, path+splat; default: the
    /// scene's estimate.splat.passes, 1).
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

/// The command line, with `--method`'s help drawn from the method table (each method's
/// line, and the default the scene file falls back on), so it never lists another set.
pub fn command() -> clap::Command {
    use clap::CommandFactory;
    let methods = render::methods::help()
        .lines()
        .map(|l| format!("  {l}"))
        .collect::<Vec<_>>()
        .join("\n");
    let render_help = format!(
        "The method (default: the scene's render.method, else {}):\n{methods}",
        Method::default()
    );
    let maps: Vec<String> = render::methods::METHODS
        .iter()
        .filter(|r| r.reads_photon_maps())
        .map(|r| r.method.name())
        .collect();
    let estimate_help = format!(
        "{} (default: the scene's render.method when it is one of these, else {})",
        maps.join(" or "),
        render::methods::ESTIMATE_DEFAULT
    );
    // Where `--spp` and `--passes` go, per method, from the table.
    let knob_help = |what: &str, knob: fn(&render::methods::MethodRow) -> Option<Knob>| {
        let places: Vec<String> = render::methods::METHODS
            .iter()
            .map(|r| match knob(r) {
                Some(k) => format!("{}: {}", r.method, k.key()),
                None => format!("{}: refused", r.method),
            })
            .collect();
        format!("{what} (default: the scene file's; {})", places.join(", "))
    };
    let spp_help = knob_help("Samples per pixel", |r| r.spp);
    let passes_help = knob_help(
        "Passes of the progressive methods (a run stopped by --time records those made)",
        |r| r.passes,
    );
    // Which flags give the count that --time then only caps, per progressive method.
    let counts: Vec<String> = render::methods::METHODS
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
    let time_help = format!(
        "Seconds to render for, a budget to use: the progressive methods' passes go on \
         past the scene file's count until the time is used, and the last one overshoots it \
         by about one pass (the path tracer's passes are sized to 1/32 of the budget). With \
         the run's count given too ({}) the time only caps it: the run stops at whichever \
         comes first. The output's scene.toml and image.json record the passes made; \
         methods without passes refuse it",
        counts.join("; ")
    );
    Cli::command()
        .mut_subcommand("render", |c| {
            c.mut_arg("method", |a| a.help(render_help))
                .mut_arg("spp", |a| a.help(spp_help.clone()))
                .mut_arg("passes", |a| a.help(passes_help.clone()))
                .mut_arg("time", |a| a.help(time_help.clone()))
        })
        .mut_subcommand("estimate", |c| {
            c.mut_arg("method", |a| a.help(estimate_help))
                .mut_arg("spp", |a| a.help(spp_help.clone()))
                .mut_arg("passes", |a| a.help(passes_help.clone()))
                .mut_arg("time", |a| a.help(time_help.clone()))
        })
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
