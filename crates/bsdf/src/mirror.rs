//! Perfect specular reflection (MTL illum 3).

use crate::{BsdfSample, specular_reflection};
use glam::Vec3;

/// A perfect mirror reflecting a constant fraction `reflectance` per channel, at every angle.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Mirror {
    pub reflectance: Vec3,
}

impl Mirror {
    pub fn sample(&self, wo: Vec3) -> Option<BsdfSample> {
        Some(specular_reflection(wo, self.reflectance))
    }
}
