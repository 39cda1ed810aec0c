//! Lights at infinity from one direction: Mitsuba 3's `directional` (pbrt-v4 §12.4, a delta
//! light) and a sun disc of small angular radius around it (a cone of uniform radiance, hit
//! by rays that leave the scene). Their photons leave a disc facing the light
//! ([`super::Sphere::emit_infinite`]).

use glam::{DVec3, Vec3};
use math::Frame;

/// `irradiance` on a surface facing the unit direction `to_light` (against the light's
/// travel).
#[derive(Clone, Copy, Debug)]
pub struct Directional {
    pub to_light: Vec3,
    pub irradiance: Vec3,
}

/// A disc of uniform `radiance` and angular radius `acos(cos_max)` about `frame.n` (towards
/// the light), sampled uniformly in its cone.
#[derive(Clone, Copy, Debug)]
pub struct Sun {
    pub frame: Frame,
    pub cos_max: f32,
    pub radiance: Vec3,
}

impl Sun {
    /// A sun disc bringing `irradiance` to a surface facing it: the disc's cone of half-angle
    /// `α` gives `E = π L sin²α`, so `L = E / (π sin²α)`.
    pub fn new(to_light: Vec3, irradiance: Vec3, angular_radius: f32) -> Sun {
        let cos_max = angular_radius.cos();
        let sin2 = angular_radius.sin().powi(2);
        Sun {
            frame: Frame::from_z(to_light),
            cos_max,
            radiance: irradiance / (std::f32::consts::PI * sin2),
        }
    }

    /// Radiance along a ray escaping in unit direction `d`.
    pub fn le(&self, d: Vec3) -> Vec3 {
        if d.dot(self.frame.n) >= self.cos_max {
            self.radiance
        } else {
            Vec3::ZERO
        }
    }

    /// A unit direction towards the light, uniform in the cone, its radiance and density.
    pub fn sample(&self, u: [f32; 2]) -> (Vec3, Vec3, f32) {
        let z = 1.0 - u[0] * (1.0 - self.cos_max);
        let r = (1.0 - z * z).max(0.0).sqrt();
        let phi = std::f32::consts::TAU * u[1];
        let local = Vec3::new(r * phi.cos(), r * phi.sin(), z);
        (
            self.frame.to_world(local).normalize(),
            self.radiance,
            1.0 / (std::f32::consts::TAU * (1.0 - self.cos_max)),
        )
    }

    /// Solid-angle density of [`Sun::sample`] at `d`.
    pub fn pdf(&self, d: Vec3) -> f32 {
        if d.dot(self.frame.n) >= self.cos_max {
            1.0 / (std::f32::consts::TAU * (1.0 - self.cos_max))
        } else {
            0.0
        }
    }

    /// `∫ L dω` over the sphere, f64.
    pub fn integral(&self) -> DVec3 {
        std::f64::consts::TAU * (1.0 - self.cos_max as f64) * self.radiance.as_dvec3()
    }
}
