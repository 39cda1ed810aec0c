//! A pixel's statistics in stochastic progressive photon mapping (Hachisuka and Jensen 2009,
//! "Stochastic progressive photon mapping"; pbrt-v4 §16.2): after each pass's M photons
//! within the radius R, with Φ their flux weighted by the visible point (β E π R²),
//!
//! `N' = N + α M`, `R' = R sqrt(N' / (N + M))`, `τ' = (τ + Φ) R'² / R²`,
//!
//! and after J passes the photon radiance is `τ / (J π R²)`. Only the fraction α of the new
//! photons is kept, and the flux is rescaled to the shrunken disc (the density is taken as
//! constant over it), so `τ / (π R²)` grows by exactly the pass's `β E`: the estimate is the
//! mean of the per-pass estimates, each at a smaller radius (bias vanishes) while N grows
//! without bound (variance vanishes).
//!
//! The arithmetic (f32 radius, f64 sums, and the order of every operation) is fixed: it is
//! what the `sppm` method's images are made of, bit for bit.

use glam::{DVec3, Vec3};
use std::f64::consts::PI;

/// One pixel's running statistics.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PixelStats {
    /// Accumulated photon count N (fractional: α M per pass).
    pub n: f64,
    /// Accumulated flux τ, already rescaled to the current radius.
    pub tau: DVec3,
    /// Current gather radius R.
    pub r: f32,
    /// Sum over passes of what the visible point sees without photons (emission, and direct
    /// light when estimated there). Kept here so that the pixel's whole value,
    /// `light / J + τ / (J π R²)`, is one type's: the caller adds each pass's.
    pub light: DVec3,
}

impl PixelStats {
    /// No photons yet, radius `r0`.
    pub fn new(r0: f32) -> PixelStats {
        PixelStats {
            n: 0.0,
            tau: DVec3::ZERO,
            r: r0,
            light: DVec3::ZERO,
        }
    }

    /// Adds one pass's emitted and directly estimated light (before any early return for a
    /// pixel without a visible point: its light still counts).
    pub fn add_light(&mut self, light: Vec3) {
        self.light += light.as_dvec3();
    }

    /// One pass's update from the `m` photons found within `self.r` and the irradiance `e`
    /// they estimate there, seen through the visible point's `weight` (β), with the
    /// fraction `alpha` of new photons kept. No photons: nothing changes (`e` is not read).
    pub fn update(&mut self, m: usize, e: Vec3, weight: Vec3, alpha: f64) {
        let m = m as f64;
        if m == 0.0 {
            return;
        }
        let n_new = self.n + alpha * m;
        let r_new = self.r as f64 * (n_new / (self.n + m)).sqrt();
        let r2 = (self.r as f64).powi(2);
        let phi = (weight * e).as_dvec3() * (PI * r2);
        self.tau = (self.tau + phi) * (r_new * r_new / r2);
        self.n = n_new;
        self.r = r_new as f32;
    }

    /// The mean over `passes` passes of the light accumulated by [`PixelStats::add_light`].
    pub fn light_radiance(&self, passes: u32) -> Vec3 {
        let j = passes.max(1) as f64;
        (self.light / j).as_vec3()
    }

    /// The photon radiance after `passes` passes, `τ / (J π R²)` (zero for a zero radius).
    pub fn photon_radiance(&self, passes: u32) -> Vec3 {
        let j = passes.max(1) as f64;
        let area = PI * (self.r as f64).powi(2);
        if area > 0.0 {
            (self.tau / (j * area)).as_vec3()
        } else {
            Vec3::ZERO
        }
    }
}
