//! `math`: the vocabulary every renderer crate shares and that knows nothing of scenes,
//! materials or photons (style anchor A2.1: Mitsuba's `core/` vs `render/` split).
//!
//! Key decision: random numbers are *counter based*. A photon's or a pixel sample's stream is
//! a pure function of `(seed, index)` ([`Rng::for_index`]), so any work split over threads
//! reproduces the same numbers bit for bit (anchor A1.8, pbrt-v4's SPPM photon indexing).
//! Vectors are `glam`'s; this crate adds what glam lacks.

pub mod chi2;
mod frame;
mod rng;
pub mod warp;

pub use frame::Frame;
pub use rng::{Rng, mix64};
pub use warp::{Distribution1D, power_heuristic};

#[cfg(test)]
mod tests;
