//! Ideal diffuse reflection (MTL `Kd`, illum 1/2).

use crate::{BsdfSample, Flags, same_hemisphere};
use glam::Vec3;
use math::warp::sample_cosine_hemisphere;
use std::f32::consts::FRAC_1_PI;

/// `f = albedo / π` for `wi` on `wo`'s side, 0 across: a Lambertian surface reflects, it never
/// transmits, whichever side it is lit from (pbrt-v4 §9.2, `DiffuseBxDF`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Lambertian {
    pub albedo: Vec3,
}

impl Lambertian {
    pub fn f(&self, wo: Vec3, wi: Vec3) -> Vec3 {
        if same_hemisphere(wo, wi) {
            self.albedo * FRAC_1_PI
        } else {
            Vec3::ZERO
        }
    }

    /// `|cos θi| / π`: cosine sampling cancels `f · |cos θi|` up to the albedo, so every
    /// sample carries exactly the albedo (pbrt-v4 §9.2).
    pub fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        if same_hemisphere(wo, wi) {
            wi.z.abs() * FRAC_1_PI
        } else {
            0.0
        }
    }

    pub fn sample(&self, wo: Vec3, u: [f32; 2]) -> Option<BsdfSample> {
        let mut wi = sample_cosine_hemisphere(u);
        if wo.z < 0.0 {
            wi.z = -wi.z;
        }
        let pdf = wi.z.abs() * FRAC_1_PI;
        // u on the disk's rim gives a grazing wi the evaluation side calls "no hemisphere".
        if pdf == 0.0 {
            return None;
        }
        Some(BsdfSample {
            f: self.albedo * FRAC_1_PI,
            wi,
            pdf,
            flags: Flags::DIFFUSE_REFLECTION,
            eta: 1.0,
        })
    }
}
