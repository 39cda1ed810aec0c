//! The environment light: an [`EnvMap`] (a lat-long image or a constant colour at infinity,
//! Mitsuba 3's `envmap` and `constant`), importance-sampled by luminance (pbrt-v4 §12.5.2).

use crate::envmap::EnvMap;

/// An environment map and the image it was read from (`None` for a constant colour).
#[derive(Clone, Debug)]
pub struct Environment {
    pub map: Box<EnvMap>,
    pub file: Option<String>,
}
