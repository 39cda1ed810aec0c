//! A thin dielectric slab (a window pane, a soap film): Mitsuba 3's `thindielectric`.

use crate::optics::fresnel_dielectric;
use crate::{BsdfSample, Flags};
use glam::Vec3;

/// Two parallel smooth interfaces of relative index `eta` so close together that light
/// leaves where it entered. Summing the rays bounced between the faces, `R + T² R (1 + R² +
/// R⁴ + ...)`, the slab reflects `R' = R + T² R / (1 - R²) = 2R / (1 + R)` (with `T = 1 - R`)
/// and transmits `T' = 1 - R'` straight through, undeflected (pbrt-v4's `ThinDielectricBxDF`,
/// Mitsuba 3's `thindielectric`). Both lobes are deltas, the same from
/// either side. `reflectance` and `transmittance` are factors on the two lobes (Mitsuba's
/// `specular_reflectance` and `specular_transmittance`) that leave the probabilities alone.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ThinDielectric {
    pub eta: f32,
    pub reflectance: Vec3,
    pub transmittance: Vec3,
}

impl ThinDielectric {
    /// A clear slab of relative index `eta`.
    pub const fn clear(eta: f32) -> ThinDielectric {
        ThinDielectric {
            eta,
            reflectance: Vec3::ONE,
            transmittance: Vec3::ONE,
        }
    }

    /// The slab's total reflectance `R' = 2R / (1 + R)` at `|cos θ|`.
    #[inline]
    pub fn reflectance_at(&self, cos_theta: f32) -> f32 {
        let r = fresnel_dielectric(cos_theta.abs(), self.eta);
        2.0 * r / (1.0 + r)
    }

    /// Picks reflection with probability `R'` and transmission with `T' = 1 - R'`, so each
    /// sample carries its lobe's factor. Transmission crosses no index change (`eta` 1): no
    /// `1/η²` in either transport mode.
    pub fn sample(&self, wo: Vec3, uc: f32) -> Option<BsdfSample> {
        let r = self.reflectance_at(wo.z);
        if uc < r {
            let wi = Vec3::new(-wo.x, -wo.y, wo.z);
            return Some(BsdfSample {
                f: self.reflectance * (r / wi.z.abs()),
                wi,
                pdf: r,
                flags: Flags::SPECULAR_REFLECTION,
                eta: 1.0,
            });
        }
        let t = 1.0 - r;
        let wi = -wo;
        Some(BsdfSample {
            f: self.transmittance * (t / wi.z.abs()),
            wi,
            pdf: t,
            flags: Flags::SPECULAR_TRANSMISSION,
            eta: 1.0,
        })
    }
}
