//! The flags and help of the commands that make images and photon sets (`render`, `estimate`,
//! `trace`) and put shards together (`merge`), with the settings `render` and `estimate` share.

use super::parse::{parse_finite, parse_threads};
use render::Overrides;
use scene::Method;
use std::path::PathBuf;

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
/// Why vcm is the default: at 128 x 128 it has 0.38-0.79x sppm's error on the worksheet box,
/// 0.21-0.25x on McGuire's Original and 0.07-0.09x on its Glossy box at budgets of 2, 5, 15
/// and 60 s, and draws sharp caustics from point and spot lights without a density
/// estimate's blur; sppm in turn has 6.7 to 8.4 times less error than the best peer on the
/// worksheet (bench-accuracy, docs/benchmarks.md).
#[derive(clap::Args)]
pub(crate) struct Render {
    /// The scene file (TOML).
    pub(crate) scene: PathBuf,
    /// The method; its help is drawn from the method table (`command`).
    #[arg(long)]
    pub(crate) method: Option<Method>,
    #[command(flatten)]
    pub(crate) photon: PhotonArgs,
    #[command(flatten)]
    pub(crate) image: ImageArgs,
    /// Path tracer: leave out exactly the paths photon splatting owns (L S+ D S* E, D the
    /// first diffuse vertex from the eye), so a splatted caustic layer can be added.
    ///
    /// Render the caustic layer apart (caustic-splat) and `composite` the two runs.
    #[arg(long)]
    pub(crate) no_caustics: bool,
    /// Render only shard I of N (counted from 0) of the run, for `merge`.
    ///
    /// `path` shards by its passes of samples, `caustic-splat` and `light` by their passes; the shard
    /// goes into a shard directory (--out, default out/shards/...). `merge` puts the
    /// shards back together into the one-machine result, byte for byte.
    #[arg(long, value_parser = render::shard::ShardId::parse)]
    pub(crate) shard: Option<render::shard::ShardId>,
}

/// Estimate an image from the cached photon sets only (never traces).
///
/// Swaps the estimator (--method, --k, --kernel, --topo, --boundary, --drop-kth) over the
/// photon sets an earlier `trace` or `render` cached, without tracing them again. Writes
/// what `render` writes.
#[derive(clap::Args)]
pub(crate) struct Estimate {
    /// The scene file (TOML).
    pub(crate) scene: PathBuf,
    /// A method that reads photon maps; its help is drawn from the method table.
    #[arg(long)]
    pub(crate) method: Option<Method>,
    #[command(flatten)]
    pub(crate) photon: PhotonArgs,
    #[command(flatten)]
    pub(crate) image: ImageArgs,
}

/// Trace the photon sets a scene needs into the cache (or reuse them).
///
/// The sets are the ones the scene's effects plan asks for, cached under a hash of what
/// they depend on: they are reused while the scene and the parameters are unchanged.
/// `estimate` reads them; `render` traces or reuses them itself.
#[derive(clap::Args)]
pub(crate) struct Trace {
    /// The scene file (TOML).
    pub(crate) scene: PathBuf,
    /// Seed of every random stream (default: the scene file's `seed`).
    #[arg(long)]
    pub(crate) seed: Option<u64>,
    /// Photon paths to emit (default: the scene's [photons] table).
    #[arg(long)]
    pub(crate) photons: Option<u64>,
    /// Cache directory of photon files.
    #[arg(long, default_value = "out/cache")]
    pub(crate) cache: PathBuf,
    /// Worker threads (default: all cores).
    #[arg(long, value_parser = parse_threads)]
    pub(crate) threads: Option<usize>,
    /// Trace even if the cache holds the sets.
    #[arg(long)]
    pub(crate) force: bool,
    /// Trace only shard I of N (counted from 0), for `merge`.
    ///
    /// Photon paths [I P / N, (I + 1) P / N) go into a shard directory (--out), not into
    /// the cache; `merge` puts the shards' photon sets into a cache directory.
    #[arg(long, value_parser = render::shard::ShardId::parse)]
    pub(crate) shard: Option<render::shard::ShardId>,
    /// The shard directory (default: out/shards/<scene dir>-<stem>-trace-I-of-N).
    #[arg(long, requires = "shard")]
    pub(crate) out: Option<PathBuf>,
}

/// Put the shards of one run (`trace --shard`, `render --shard`) back together into the
/// result the one-machine run writes, byte for byte.
///
/// Shards are read in shard order: photon sets go into a cache directory, images into a
/// run directory. Refuses a missing, duplicated or overlapping shard, or shards of another
/// scene, seed or parameter set.
#[derive(clap::Args)]
pub(crate) struct Merge {
    /// Shard directories (any order).
    #[arg(required = true)]
    pub(crate) inputs: Vec<PathBuf>,
    /// Photon shards: the cache directory to write the photon files into; image shards:
    /// the run directory to write.
    #[arg(long)]
    pub(crate) out: PathBuf,
}

/// Image settings shared by `render` and `estimate`.
#[derive(clap::Args)]
pub(crate) struct ImageArgs {
    /// Samples per pixel; where it goes per method is drawn from the method table (`command`).
    #[arg(long)]
    pub(crate) spp: Option<u32>,
    /// Worker threads (default: all cores). The image does not depend on it.
    #[arg(long, value_parser = parse_threads)]
    pub(crate) threads: Option<usize>,
    /// Output directory (default: out/<scene dir>-<scene stem>-<method>).
    #[arg(long)]
    pub(crate) out: Option<PathBuf>,
    /// Exposure of the PNG in stops.
    #[arg(long, default_value_t = 0.0, value_parser = parse_finite)]
    pub(crate) exposure: f32,
}

/// Photon-mapping settings shared by `estimate` and `render`.
#[derive(clap::Args)]
pub(crate) struct PhotonArgs {
    /// Seed of every random stream (default: the scene file's `seed`); recorded in the
    /// outputs' `scene.toml` and `image.json`.
    #[arg(long)]
    pub(crate) seed: Option<u64>,
    /// Photon paths emitted (default: the scene's [photons] table).
    #[arg(long)]
    pub(crate) photons: Option<u64>,
    /// Directory of cached photon files.
    #[arg(long, default_value = "out/cache")]
    pub(crate) cache: PathBuf,
    /// Nearest photons per global-map estimate (default: [estimate.global] k, else 1000).
    #[arg(long)]
    pub(crate) k: Option<usize>,
    /// Kernel of the global-map estimate, by the scene file's `kind` names: uniform, cone,
    /// cone:K, gaussian, gaussian_jensen, epanechnikov, silverman, triweight.
    #[arg(long, value_parser = <density::Kernel as std::str::FromStr>::from_str)]
    pub(crate) kernel: Option<density::Kernel>,
    /// Topological test: keep photons whose direction from the estimation point is within
    /// |cos| < EPS of the tangent plane.
    #[arg(long)]
    pub(crate) topo: Option<f32>,
    /// Drop the k-th photon (Garcia et al. 2012).
    #[arg(long)]
    pub(crate) drop_kth: bool,
    /// Correct global-map estimates for boundary bias: divide by the share of the kernel's
    /// mass that lies on the surface (found by short probe rays).
    #[arg(long)]
    pub(crate) boundary: bool,
    /// Final-gather rays per sample (default: the scene's estimate.final_gather.rays, 16).
    #[arg(long)]
    pub(crate) gather_rays: Option<u32>,
    /// Final gathering reads irradiance precomputed at every N-th global photon
    /// (Christensen 1999); 0 estimates from the map at every gather hit (default: the
    /// scene's estimate.final_gather.cache, 4).
    #[arg(long)]
    pub(crate) gather_cache: Option<usize>,
    /// Passes of the progressive methods; where it goes per method is drawn from the method
    /// table (`command`).
    #[arg(long)]
    pub(crate) passes: Option<u32>,
    /// Seconds for the progressive methods' passes (the full help is drawn from the method
    /// table in `command`).
    #[arg(long)]
    pub(crate) time: Option<f64>,
    /// Compare with this linear EXR (the path-traced reference) and record the error.
    #[arg(long)]
    pub(crate) reference: Option<PathBuf>,
    /// Name of the output directory's method part.
    #[arg(long)]
    pub(crate) label: Option<String>,
}

impl PhotonArgs {
    pub(crate) fn overrides(&self, method: Option<Method>, spp: Option<u32>) -> Overrides {
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
