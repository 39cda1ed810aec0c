//! Photon emission from the scene's area lights.

use geom::{Ray, SurfacePoint};
use glam::{DVec3, Vec3};
use math::warp::{sample_cosine_hemisphere, sample_uniform_triangle};
use math::{Distribution1D, Frame};
use scene::Scene;

/// One light triangle, ready to sample.
#[derive(Clone, Debug)]
struct Light {
    vertices: [Vec3; 3],
    /// The scene's area of the triangle.
    area: f32,
    frame: Frame,
    /// `π A Le` in f64 from the scene's f32 area and radiance: no f32 rounding of the product,
    /// so the flux identity `Φ_i / (p_i N) = Φ_total / N` holds to f64 precision.
    power: DVec3,
    /// Probability of choosing this light: its share of the summed RGB power.
    pmf: f64,
}

/// Samples photon origins and directions: a light by power, a point uniform by area, a
/// cosine-weighted direction about the emitting side's normal (Jensen 2001 §5.1; pbrt-v4
/// §12.6.2 for the power distribution). Random numbers come in as arguments (anchor A1.2).
#[derive(Clone, Debug)]
pub struct LightSampler {
    lights: Vec<Light>,
    distribution: Distribution1D,
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
        let mesh = scene.geometry.mesh();
        let mut lights: Vec<Light> = scene
            .lights
            .iter()
            .map(|l| Light {
                vertices: mesh.vertices(l.triangle as usize),
                area: l.area,
                frame: Frame::from_z(l.normal),
                power: std::f64::consts::PI * l.area as f64 * l.le.as_dvec3(),
                pmf: 0.0,
            })
            .collect();
        let weights: Vec<f64> = lights.iter().map(|l| l.power.element_sum()).collect();
        let sum: f64 = weights.iter().sum();
        if lights.is_empty() || !sum.is_finite() || sum <= 0.0 {
            return None;
        }
        for (l, w) in lights.iter_mut().zip(&weights) {
            l.pmf = w / sum;
        }
        let total = lights.iter().fold(DVec3::ZERO, |s, l| s + l.power);
        Some(LightSampler {
            lights,
            distribution: Distribution1D::new(&weights),
            total,
        })
    }

    /// Total emitted power of all lights, RGB, f64.
    pub fn total_power(&self) -> DVec3 {
        self.total
    }

    pub fn len(&self) -> usize {
        self.lights.len()
    }

    /// Always false: [`LightSampler::new`] refuses a scene without lights.
    pub fn is_empty(&self) -> bool {
        self.lights.is_empty()
    }

    /// Probability of emitting from light `i`.
    pub fn pmf(&self, i: usize) -> f64 {
        self.lights[i].pmf
    }

    /// Power of light `i`, `π A Le`.
    pub fn power(&self, i: usize) -> DVec3 {
        self.lights[i].power
    }

    /// Vertices of light triangle `i`.
    pub fn vertices(&self, i: usize) -> [Vec3; 3] {
        self.lights[i].vertices
    }

    /// Area of light triangle `i` (the scene's value).
    pub fn area(&self, i: usize) -> f32 {
        self.lights[i].area
    }

    /// Frame of light `i`: `n` is the emitting side's normal, `s` and `t` its tangents.
    pub fn frame(&self, i: usize) -> Frame {
        self.lights[i].frame
    }

    /// Flux of a photon from light `i` when `photons` paths are emitted in all: the
    /// unbiased estimate `Φ_i / (p_i N)` of its share (Jensen 2001 §5.1, "multiple lights"; the
    /// framework's `Φ_light · #lights / #shots` is the uniform-choice special case). With
    /// `p_i ∝ |Φ_i|` and one emission colour it equals `Φ_total / N` for every light.
    pub fn flux(&self, i: usize, photons: u64) -> DVec3 {
        let l = &self.lights[i];
        l.power / (l.pmf * photons as f64)
    }

    /// Emit one photon: `u_light` picks the light, `u_pos` the point (Heitz's triangle map),
    /// `u_dir` the direction (Malley's method about the light's normal).
    pub fn sample(&self, u_light: f32, u_pos: [f32; 2], u_dir: [f32; 2], photons: u64) -> Emitted {
        let (i, _, _) = self.distribution.sample(u_light);
        let l = &self.lights[i];
        let b = sample_uniform_triangle(u_pos);
        let [v0, v1, v2] = l.vertices;
        let p = b.x * v0 + b.y * v1 + b.z * v2;
        let point = SurfacePoint {
            p,
            p_err: SurfacePoint::barycentric_error(b.to_array(), l.vertices),
            n: l.frame.n,
        };
        let d = l
            .frame
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
