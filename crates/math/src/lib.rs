//! `math`: the vocabulary every renderer crate shares and that knows nothing of scenes,
//! materials or photons (Mitsuba's habit: its `core/` library sits below `render/`).
//!
//! Key decision: random numbers are *counter based*. A photon's or a pixel sample's stream is
//! a pure function of `(seed, index)` ([`Rng::for_index`]), so any work split over threads
//! reproduces the same numbers bit for bit (pbrt-v4's habit in SPPM: a photon's samples are
//! indexed by the photon's number, not drawn from a shared stream).
//! Vectors are `glam`'s; this crate adds what glam lacks.

pub mod analytic;
mod cache;
pub mod chi2;
mod frame;
mod rng;
pub mod sampler;
pub mod warp;

pub use cache::prefetch;
pub use frame::Frame;
pub use rng::{Rng, mix64};
pub use sampler::{Sampler, SobolSampler};
pub use warp::{Distribution1D, Distribution2D, power_heuristic};

#[cfg(test)]
mod tests;
