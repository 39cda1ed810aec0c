//! `film`: where radiance lands. Samples and photon estimates accumulate into named layers,
//! layers resolve to images, images are composited, written (EXR/PNG) and compared.
//!
//! Key decisions:
//! - **Sums in f64, results in f32.** A layer keeps per-pixel `[f64; 3]` sums and an f64
//!   weight: after millions of samples an f32 sum stops absorbing small contributions
//!   (a sample below ~1e-7 of the running sum vanishes), which biases converged images.
//!   Only the resolved [`Image`] is f32 per element, which is what EXR stores and what
//!   metrics need.
//! - **Deterministic tiles.** Workers accumulate into private [`TileBuffer`]s over the
//!   rectangles from [`tiles`], which partition the image; [`Film::merge_tile`] adds each
//!   tile into pixels no other tile touches. Each pixel thus sees the same additions in the
//!   same order whatever the thread schedule, so the film is bit-identical run to run
//!   (with `math`'s counter-based RNG this makes whole renders reproducible).
//! - **The caller picks every path**, and writes are atomic (temp file + rename, see
//!   [`write_atomic`]); failures are [`FilmError`]s naming the file, never panics.
//! - **Light-path classes are spelled once**, here ([`Class`]): the eye pass names its layers
//!   by them and compositing reads them back from `image.json`, so both sides share one
//!   type, one order and one set of names.

mod bias;
mod class;
mod error;
mod film;
mod flip;
mod halves;
mod img;
mod io;
mod metrics;
mod sums;

pub use bias::{BiasVariance, RegionSums};
pub use class::Class;
pub use error::FilmError;
pub use film::{Film, Layer, Normalize, Rect, TileBuffer, tiles};
pub use flip::{FlipMap, flip};
pub use halves::{Halves, HalvesMetrics, metrics_halves};
pub use img::{Image, composite};
pub use io::{ToneMap, read_exr, write_atomic, write_exr, write_png};
pub use metrics::{Mask, Metrics, RELMSE_EPSILON, metrics};
pub use sums::{Sums, read_sums, write_sums};

#[cfg(test)]
mod tests;
