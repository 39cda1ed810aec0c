//! Area-light sampling: a triangle by emitted power, a point uniform on it (pbrt-v4 §12.6.2,
//! §6.5.4), densities converted to solid angle at the receiving point.

use geom::{Prim, SurfacePoint};
use glam::Vec3;
use scene::{LightChooser, LightPoint, Scene};

/// Marks a triangle that is not a light in [`LightSampler`]'s lookup table.
const NOT_A_LIGHT: u32 = u32::MAX;

#[derive(Clone, Copy, Debug)]
struct Emitter {
    normal: Vec3,
    area: f32,
    le: Vec3,
}

/// A point sampled on a light, seen from a receiving point.
#[derive(Clone, Copy, Debug)]
pub struct LightSample {
    /// Index of the chosen light (into `scene.lights`).
    pub light: usize,
    /// The light point with its error bound (for shadow rays) and the light's emitting normal.
    pub point: SurfacePoint,
    /// Emitted radiance towards the receiver (the light faces it: never zero-sided).
    pub le: Vec3,
    /// Unit direction from the receiver to the light point.
    pub wi: Vec3,
    /// Distance from the receiver to the light point.
    pub dist: f32,
    /// Solid-angle density at the receiver, the light choice included.
    pub pdf: f32,
}

/// Chooses an emissive triangle with probability proportional to its power (sum of RGB, in
/// f64) and a uniform point on it (`scene::LightChooser`, shared with photon emission), and
/// converts the density to solid angle at the receiver.
#[derive(Clone, Debug)]
pub struct LightSampler {
    emitters: Vec<Emitter>,
    chooser: LightChooser,
    /// Light index of each mesh triangle, or `NOT_A_LIGHT`.
    light_of_triangle: Vec<u32>,
}

impl LightSampler {
    /// The sampler over `scene.lights` (the loader guarantees at least one light).
    pub fn new(scene: &Scene) -> LightSampler {
        let mesh = scene.geometry.mesh();
        let mut light_of_triangle = vec![NOT_A_LIGHT; mesh.len()];
        let emitters: Vec<Emitter> = scene
            .lights
            .iter()
            .enumerate()
            .map(|(i, l)| {
                light_of_triangle[l.triangle as usize] = i as u32;
                Emitter {
                    normal: l.normal,
                    area: l.area,
                    le: l.le,
                }
            })
            .collect();
        LightSampler {
            emitters,
            // Scene loading guarantees a light with positive, finite power.
            chooser: LightChooser::new(scene).expect("a loaded scene has a light"),
            light_of_triangle,
        }
    }

    /// Number of emissive triangles.
    pub fn len(&self) -> usize {
        self.emitters.len()
    }

    /// Always false for a loaded scene (it has at least one light).
    pub fn is_empty(&self) -> bool {
        self.emitters.is_empty()
    }

    /// The light index of a primitive, if it is an emissive triangle.
    pub fn light_of(&self, prim: Prim) -> Option<usize> {
        match prim {
            Prim::Triangle(t) => match self.light_of_triangle.get(t as usize) {
                Some(&i) if i != NOT_A_LIGHT => Some(i as usize),
                _ => None,
            },
            Prim::Sphere(_) => None,
        }
    }

    /// Radiance a ray travelling along `d` receives from light `light` (one-sided emission:
    /// zero when the ray hits the back).
    pub fn le(&self, light: usize, d: Vec3) -> Vec3 {
        let e = &self.emitters[light];
        if d.dot(e.normal) < 0.0 {
            e.le
        } else {
            Vec3::ZERO
        }
    }

    /// Samples a light point as seen from `from`: `u_pick` chooses the triangle, `u` the point.
    /// `None` when the point cannot send light to `from` (it sees the light's back or lies in
    /// its plane), which NEE counts as a zero contribution.
    pub fn sample(&self, from: Vec3, u_pick: f32, u: [f32; 2]) -> Option<LightSample> {
        let LightPoint {
            light: i,
            pmf,
            point,
        } = self.chooser.sample(u_pick, u);
        let e = &self.emitters[i];
        let p = point.p;
        let to = p - from;
        let dist2 = to.length_squared();
        if dist2 <= 0.0 || !dist2.is_finite() {
            return None;
        }
        let dist = dist2.sqrt();
        let wi = to / dist;
        let cos_light = -wi.dot(e.normal);
        if cos_light <= 0.0 || cos_light.is_nan() {
            return None;
        }
        let pdf = pmf as f32 / e.area * dist2 / cos_light;
        if !(pdf.is_finite() && pdf > 0.0) {
            return None;
        }
        Some(LightSample {
            light: i,
            point,
            le: e.le,
            wi,
            dist,
            pdf,
        })
    }

    /// Solid-angle density with which [`LightSampler::sample`] from `from` produces the point
    /// `to` on light `light` (the MIS weight of a BSDF-sampled hit). Zero from behind.
    pub fn pdf(&self, light: usize, from: Vec3, to: Vec3) -> f32 {
        let e = &self.emitters[light];
        let d = to - from;
        let dist2 = d.length_squared();
        if dist2 <= 0.0 || !dist2.is_finite() {
            return 0.0;
        }
        let cos_light = -d.dot(e.normal) / dist2.sqrt();
        if cos_light <= 0.0 || cos_light.is_nan() {
            return 0.0;
        }
        self.chooser.pmf(light) as f32 / e.area * dist2 / cos_light
    }

    /// [`LightSampler::pdf`] for a BSDF-sampled hit, 0 if the hit is not on a light.
    pub fn pdf_hit(&self, hit: &geom::Hit, from: Vec3) -> f32 {
        match self.light_of(hit.prim) {
            Some(i) => self.pdf(i, from, hit.point.p),
            None => 0.0,
        }
    }
}
