//! Choosing a point on the scene's lights: a triangle by emitted power, then a point uniform
//! on it (pbrt-v4 §12.6.2, §6.5.4). Next-event estimation (`eye`) and photon emission
//! (`emit`) both start here, so they weigh lights identically.

use crate::Scene;
use geom::SurfacePoint;
use glam::{DVec3, Vec3};
use math::Distribution1D;
use math::warp::sample_uniform_triangle;

/// A point chosen on a light.
#[derive(Clone, Copy, Debug)]
pub struct LightPoint {
    /// Index into `Scene::lights`.
    pub light: usize,
    /// Probability of having chosen this light.
    pub pmf: f64,
    /// The point with its error bound (for rays leaving or reaching it); `n` is the light's
    /// emitting normal.
    pub point: SurfacePoint,
}

/// The power distribution over a scene's light triangles.
#[derive(Clone, Debug)]
pub struct LightChooser {
    distribution: Distribution1D,
    vertices: Vec<[Vec3; 3]>,
    normals: Vec<Vec3>,
    /// `π A Le` in f64 from the scene's f32 area and radiance (no f32 rounding of the product).
    power: Vec<DVec3>,
    /// Each light's share of the summed RGB power.
    pmf: Vec<f64>,
}

impl LightChooser {
    /// `None` when no light has positive, finite power (scene loading refuses such scenes).
    pub fn new(scene: &Scene) -> Option<LightChooser> {
        let mesh = scene.geometry.mesh();
        let power: Vec<DVec3> = scene
            .lights
            .iter()
            .map(|l| std::f64::consts::PI * l.area as f64 * l.le.as_dvec3())
            .collect();
        let weights: Vec<f64> = power.iter().map(|p| p.element_sum()).collect();
        let sum: f64 = weights.iter().sum();
        if weights.is_empty() || !sum.is_finite() || sum <= 0.0 {
            return None;
        }
        Some(LightChooser {
            distribution: Distribution1D::new(&weights),
            vertices: scene
                .lights
                .iter()
                .map(|l| mesh.vertices(l.triangle as usize))
                .collect(),
            normals: scene.lights.iter().map(|l| l.normal).collect(),
            pmf: weights.iter().map(|w| w / sum).collect(),
            power,
        })
    }

    pub fn len(&self) -> usize {
        self.power.len()
    }

    /// Always false: [`LightChooser::new`] refuses a scene without lights.
    pub fn is_empty(&self) -> bool {
        self.power.is_empty()
    }

    /// Probability of choosing light `i`.
    pub fn pmf(&self, i: usize) -> f64 {
        self.pmf[i]
    }

    /// Power `π A Le` of light `i`, f64.
    pub fn power(&self, i: usize) -> DVec3 {
        self.power[i]
    }

    pub fn vertices(&self, i: usize) -> [Vec3; 3] {
        self.vertices[i]
    }

    /// `u_light` chooses the light, `u_pos` the point (Heitz's triangle map).
    pub fn sample(&self, u_light: f32, u_pos: [f32; 2]) -> LightPoint {
        let (i, _, _) = self.distribution.sample(u_light);
        let v = self.vertices[i];
        let b = sample_uniform_triangle(u_pos);
        LightPoint {
            light: i,
            pmf: self.pmf[i],
            point: SurfacePoint {
                p: b.x * v[0] + b.y * v[1] + b.z * v[2],
                p_err: SurfacePoint::barycentric_error(b.to_array(), v),
                n: self.normals[i],
            },
        }
    }
}
