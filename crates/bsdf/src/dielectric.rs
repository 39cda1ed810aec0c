//! Smooth dielectric interface: glass, water (MTL illum 4/6/7 with `Ni`).

use crate::optics::{fresnel_dielectric, refract};
use crate::{BsdfSample, Flags, TransportMode};
use glam::Vec3;

/// A smooth boundary between media with relative index `eta` = n_inside / n_outside, the
/// inside being the side opposite the shading normal (+z). Both lobes are deltas.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Dielectric {
    pub eta: f32,
}

impl Dielectric {
    /// Picks reflection with probability `R` and transmission with `T = 1 - R` using `uc`,
    /// so the Fresnel weight cancels and each sample carries 1 (pbrt-v4 §9.5.1). Radiance is
    /// compressed into the narrower cone on entering a denser medium, so in
    /// [`TransportMode::Radiance`] transmission is scaled by `1/η'^2`; photons carry
    /// importance-like power that is not (pbrt-v4 §9.5.2, Veach 1997 §5.2).
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
            f: Vec3::splat(ft),
            wi,
            pdf: t,
            flags: Flags::SPECULAR_TRANSMISSION,
            eta: etap,
        })
    }
}
