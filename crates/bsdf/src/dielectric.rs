//! Smooth dielectric interface: glass, water (MTL illum 4/6/7 with `Ni`).

use crate::optics::{fresnel_dielectric, refract};
use crate::{BsdfSample, Flags, TransportMode};
use glam::Vec3;

/// A smooth boundary between media with relative index `eta` = n_inside / n_outside, the
/// inside being the side opposite the shading normal (+z). Both lobes are deltas.
///
/// `transmittance` is a factor on the transmitted lobe at every crossing, in each direction
/// (Mitsuba 3's `dielectric` `specular_transmittance`, MTL `Tf`): coloured glass whose
/// colour does not depend on how far light travels inside. Reflection is left as Fresnel
/// gives it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Dielectric {
    pub eta: f32,
    pub transmittance: Vec3,
}

impl Dielectric {
    /// Clear glass of relative index `eta`.
    pub const fn clear(eta: f32) -> Dielectric {
        Dielectric {
            eta,
            transmittance: Vec3::ONE,
        }
    }

    /// Picks reflection with probability `R` and transmission with `T = 1 - R` using `uc`,
    /// so the Fresnel weight cancels and each sample carries 1 (pbrt-v4 §9.5.1), times the
    /// transmittance on the transmitted lobe (which, as in Mitsuba, does not change the
    /// probabilities). Radiance is compressed into the narrower cone on entering a denser
    /// medium, so in [`TransportMode::Radiance`] transmission is scaled by `1/η'^2`; photons
    /// carry importance-like power that is not (pbrt-v4 §9.5.2, Veach 1997 §5.2).
    pub fn sample(&self, wo: Vec3, uc: f32, mode: TransportMode) -> Option<BsdfSample> {
        let r = fresnel_dielectric(wo.z, self.eta);
        let t = 1.0 - r;
        if uc < r {
            let wi = Vec3::new(-wo.x, -wo.y, wo.z);
            return Some(BsdfSample {
                f: Vec3::splat(r / wi.z.abs()),
                wi,
                pdf: r,
                flags: Flags::SPECULAR_REFLECTION,
                eta: 1.0,
            });
        }
        // `refract` flips the normal and eta itself when wo is inside.
        let (wi, etap) = refract(wo, Vec3::Z, self.eta)?;
        let mut ft = t / wi.z.abs();
        if mode == TransportMode::Radiance {
            ft /= etap * etap;
        }
        Some(BsdfSample {
            f: self.transmittance * ft,
            wi,
            pdf: t,
            flags: Flags::SPECULAR_TRANSMISSION,
            eta: etap,
        })
    }
}
