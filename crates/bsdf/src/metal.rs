//! The course's metal (MTL illum 11 with `Ks`): specular reflection scaled by a constant.

use crate::{BsdfSample, specular_reflection};
use glam::Vec3;

/// Specular reflection tinted by `Ks`, with no angular dependence. Optically the same as
/// [`crate::Mirror`] today, kept as its own variant so scene files map one-to-one and a rough
/// or Fresnel-weighted metal can replace it without touching mirrors; [`crate::Conductor`]
/// is the physically based alternative.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Metal {
    pub reflectance: Vec3,
}

impl Metal {
    pub fn sample(&self, wo: Vec3) -> Option<BsdfSample> {
        Some(specular_reflection(wo, self.reflectance))
    }
}
