//! Photon emission from the scene's area lights.

use geom::{Ray, SurfacePoint};
use glam::{DVec3, Vec3};
use math::Frame;
use math::warp::sample_cosine_hemisphere;
use scene::{LightChooser, LightPoint, Scene};

/// Samples photon origins and directions: a light by power and a point uniform by area
/// (`scene::LightChooser`, shared with next-event estimation), then a cosine-weighted
/// direction about the emitting side's normal (Jensen 2001 §5.1; pbrt-v4 §12.6.2 for the
/// power distribution). Random numbers come in as arguments (anchor A1.2).
#[derive(Clone, Debug)]
pub struct LightSampler {
    chooser: LightChooser,
    /// Per light: the scene's area and the frame about the emitting normal.
    areas: Vec<f32>,
    frames: Vec<Frame>,
    total: DVec3,
}

/// A photon leaving a light.
#[derive(Clone, Copy, Debug)]
pub struct Emitted {
    /// Starts just off the light (offset past the point's error bound) with a unit direction.
    pub ray: Ray,
    /// Index into the scene's `lights`.
    pub light: usize,
    /// The point on the light and its normal.
    pub point: SurfacePoint,
    /// Flux carried, `Φ_light / (p_light N)`, in f64.
    pub flux: DVec3,
}

impl LightSampler {
    /// `None` when the scene has no light with positive power (the plan reports that).
    pub fn new(scene: &Scene) -> Option<LightSampler> {
        let chooser = LightChooser::new(scene)?;
        let total = (0..chooser.len()).fold(DVec3::ZERO, |s, i| s + chooser.power(i));
        Some(LightSampler {
            chooser,
            areas: scene.lights.iter().map(|l| l.area).collect(),
            frames: scene
                .lights
                .iter()
                .map(|l| Frame::from_z(l.normal))
                .collect(),
            total,
        })
    }

    /// Total emitted power of all lights, RGB, f64.
    pub fn total_power(&self) -> DVec3 {
        self.total
    }

    pub fn len(&self) -> usize {
        self.chooser.len()
    }

    /// Always false: [`LightSampler::new`] refuses a scene without lights.
    pub fn is_empty(&self) -> bool {
        self.chooser.is_empty()
    }

    /// Probability of emitting from light `i`.
    pub fn pmf(&self, i: usize) -> f64 {
        self.chooser.pmf(i)
    }

    /// Power of light `i`, `π A Le`.
    pub fn power(&self, i: usize) -> DVec3 {
        self.chooser.power(i)
    }

    /// Vertices of light triangle `i`.
    pub fn vertices(&self, i: usize) -> [Vec3; 3] {
        self.chooser.vertices(i)
    }

    /// Area of light triangle `i` (the scene's value).
    pub fn area(&self, i: usize) -> f32 {
        self.areas[i]
    }

    /// Frame of light `i`: `n` is the emitting side's normal, `s` and `t` its tangents.
    pub fn frame(&self, i: usize) -> Frame {
        self.frames[i]
    }

    /// Flux of a photon from light `i` when `photons` paths are emitted in all: the
    /// unbiased estimate `Φ_i / (p_i N)` of its share (Jensen 2001 §5.1, "multiple lights"; the
    /// framework's `Φ_light · #lights / #shots` is the uniform-choice special case). With
    /// `p_i ∝ |Φ_i|` and one emission colour it equals `Φ_total / N` for every light.
    pub fn flux(&self, i: usize, photons: u64) -> DVec3 {
        self.chooser.power(i) / (self.chooser.pmf(i) * photons as f64)
    }

    /// Emit one photon: `u_light` picks the light, `u_pos` the point (Heitz's triangle map),
    /// `u_dir` the direction (Malley's method about the light's normal).
    pub fn sample(&self, u_light: f32, u_pos: [f32; 2], u_dir: [f32; 2], photons: u64) -> Emitted {
        let LightPoint {
            light: i, point, ..
        } = self.chooser.sample(u_light, u_pos);
        let d = self.frames[i]
            .to_world(sample_cosine_hemisphere(u_dir))
            .normalize();
        Emitted {
            ray: point.spawn_ray(d),
            light: i,
            point,
            flux: self.flux(i, photons),
        }
    }
}
