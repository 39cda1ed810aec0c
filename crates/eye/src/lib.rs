//! `eye`: the eye pass, a unidirectional path tracer that writes its estimate into film
//! layers split by *light-path type*.
//!
//! Key decision: **every contribution is classified by the path's regular expression at the
//! moment it is added, and lands in exactly one layer** (`emitted`, `direct`, `indirect`,
//! `caustic`, `caustic_indirect`; see [`Class`]). Why: the photon stage will estimate caustics
//! (paths `L S+ D S* E`) by splatting, and the two stages may only be added if they partition
//! path space. Keeping the classification inside the tracer, next to the MIS weights that
//! decide which strategy owns which path, makes that partition one `match` to audit; the
//! [`PathOptions::caustics`] switch removes exactly the caustic layers and leaves every other
//! layer bit for bit unchanged (the random stream never branches on it), so a caustic layer
//! made elsewhere can replace them without counting anything twice.
//!
//! Other decisions:
//! - Next-event estimation at every non-delta vertex, combined with BSDF sampling by the power
//!   heuristic (Veach 1997 ch. 9). Shadow rays are blocked by glass and mirrors, so NEE never
//!   produces caustics; a light reached by BSDF sampling through one or more specular bounces
//!   after a diffuse vertex is therefore a caustic with MIS weight 1.
//! - The path tracer's pixel sample `s` of pixel `p` draws from a [`math::SobolSampler`]
//!   (padded Owen-scrambled Sobol, a pure function of seed, pixel, `s` and dimension; the
//!   default) or `Rng::for_index(seed, s * pixels + p)` (`[render] sampler = "independent"`;
//!   the photon methods' eye passes always), tiles accumulate in private f64 buffers merged in
//!   tile order, so the film is bit-identical for any thread count (pbrt-v4 indexes samples
//!   by pixel and sample number the same way).
//! - Russian roulette from bounce `rr_depth` (5) judges the throughput times eta'^2 of the
//!   refractions taken (pbrt-v4's `etaScale`), survival capped at 0.95 like Mitsuba 3.
//! - Sampling takes its random numbers as arguments (`scene::LightTable::sample`); only the
//!   path loop owns a [`math::Sampler`].

mod path;
mod photon;
mod render;
mod vertices;
mod visible;

pub use film::Class;
pub use path::{PathOptions, PathTracer, Radiance};
pub use photon::{Irradiance, MapLookup, render_final_gather, render_global_direct};
pub use render::{RenderOptions, on_threads, render, render_into};
pub use vertices::{EyeVertex, VertexOptions, eye_vertices, pass_seed};
pub use visible::{PixelSample, VisiblePoint, visible_points};

#[cfg(test)]
mod tests;
