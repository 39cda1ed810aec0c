//! Smooth conductor with the exact unpolarised Fresnel term (pbrt-v4 §9.3.6).

use crate::{BsdfSample, optics::fresnel_conductor, specular_reflection};
use glam::Vec3;

/// A polished metal given by its complex index of refraction `eta + i k` per RGB channel
/// (e.g. measured data at 650/550/450 nm). Reflectance rises to 1 at grazing angles, which
/// the constant-`Ks` [`crate::Metal`] lacks.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Conductor {
    pub eta: Vec3,
    pub k: Vec3,
}

impl Conductor {
    pub fn sample(&self, wo: Vec3) -> Option<BsdfSample> {
        Some(specular_reflection(
            wo,
            fresnel_conductor(wo.z, self.eta, self.k),
        ))
    }
}
