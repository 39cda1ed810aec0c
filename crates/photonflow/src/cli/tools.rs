//! The flags and help of the tools around runs: a scene's contents (`info`), combining runs
//! (`composite`) and scoring an image against a reference (`compare`).

use super::parse::{parse_finite, parse_rect};
use std::path::PathBuf;

/// Load a scene and print what it holds: triangles, spheres, lights and their power,
/// materials.
#[derive(clap::Args)]
pub(crate) struct Info {
    /// The scene file (TOML) or Mitsuba 3 scene (XML).
    pub(crate) scene: PathBuf,
}

/// Write the scene file (TOML) a Mitsuba 3 XML scene means: its meshes, textures and
/// environment maps referenced (relative to the new file), not copied.
///
/// What photonflow draws approximately or leaves out is said in `warning:` lines, as
/// rendering the XML says it; what it cannot draw is refused, naming the file, line and
/// element.
#[derive(clap::Args)]
pub(crate) struct Convert {
    /// The Mitsuba 3 scene (XML).
    pub(crate) scene: PathBuf,
    /// The scene file to write (TOML).
    #[arg(long)]
    pub(crate) out: PathBuf,
}

/// Combine runs of one view: layers of one name averaged by their counts, layers of
/// disjoint light-path classes summed.
///
/// The inputs are runs' output directories (or their `image.exr` paths): independent runs
/// of one method (another --seed each), or a path-traced image rendered with
/// --no-caustics and a caustic-only layer (caustic-splat). Sums are in f64, in a fixed
/// order. Refuses runs of another view or size, overlapping layers and runs sharing a
/// seed. The result is a run directory of its own, which can be composited again.
#[derive(clap::Args)]
pub(crate) struct Composite {
    /// Runs' output directories (or their `image.exr` paths).
    #[arg(required = true)]
    pub(crate) inputs: Vec<PathBuf>,
    /// The run directory to write.
    #[arg(long)]
    pub(crate) out: PathBuf,
    /// Exposure of the PNG in stops.
    #[arg(long, default_value_t = 0.0, value_parser = parse_finite)]
    pub(crate) exposure: f32,
}

/// Error metrics of image A against reference B (linear EXR files): RMSE, relative MSE in
/// two conventions, mean absolute error and LDR-FLIP.
///
/// Given a second reference B2, an independent half of the same budget with another seed,
/// the figures are against the halves' mean, with the reference's own noise taken out
/// ((B - B2)²/4 per pixel), the plain figures beside. `evidence` takes such a second half
/// as --reference-b, `bench-accuracy` in each --case.
#[derive(clap::Args)]
pub(crate) struct Compare {
    /// The image to score (linear EXR).
    pub(crate) a: PathBuf,
    /// The reference (linear EXR).
    pub(crate) b: PathBuf,
    /// The reference's second, independent half (linear EXR).
    pub(crate) b2: Option<PathBuf>,
    /// Restrict every figure to the pixel rectangle x0,y0,x1,y1 (half open).
    #[arg(long, value_parser = parse_rect)]
    pub(crate) mask: Option<[usize; 4]>,
}
