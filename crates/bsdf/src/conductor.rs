//! Smooth conductor with the exact unpolarised Fresnel term (pbrt-v4 §9.3.6), Mitsuba 3's
//! `conductor`.

use crate::{BsdfSample, optics::fresnel_conductor, specular_reflection};
use glam::Vec3;

/// A polished metal given by its complex index of refraction `eta + i k` per RGB channel
/// (e.g. measured data at 650/550/450 nm, or Mitsuba 3's named materials), times a
/// `reflectance` factor (Mitsuba's `specular_reflectance`; 1 for the bare metal).
/// Reflectance rises to 1 at grazing angles, which the constant-`Ks` [`crate::Metal`] lacks.
/// Both sides reflect, as [`crate::Metal`]'s do (`|cos θ|`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Conductor {
    pub eta: Vec3,
    pub k: Vec3,
    pub reflectance: Vec3,
}

impl Conductor {
    pub fn sample(&self, wo: Vec3) -> Option<BsdfSample> {
        Some(specular_reflection(
            wo,
            self.reflectance * fresnel_conductor(wo.z, self.eta, self.k),
        ))
    }
}
