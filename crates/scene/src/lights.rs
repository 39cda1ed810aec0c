//! The light table: every pass that touches a light goes through [`LightTable`], built once
//! when the scene loads. It chooses a triangle by emitted power and a point uniform on it
//! (pbrt-v4 §12.6.2, §6.5.4), answers which light a primitive is and what it emits, converts
//! densities to solid angle for next-event estimation, and emits photons (cosine-weighted
//! about the emitting normal, Jensen 2001 §5.1). One table means one weighting of lights for
//! the eye pass and the photon pass. Random numbers come in as arguments (pbrt-v4's habit:
//! samplers never own a generator).
//!
//! Point and spot lights ([`DeltaLight`]) follow the triangles in the table's numbering.
//! They are delta lights (pbrt-v4 §12.1, §12.2): no ray ever hits one, so next-event
//! estimation alone reaches them (no MIS weight: [`LightSample::delta`]) and paths from them
//! through specular surfaces to a diffuse one are found only by photons.
//!
//! Lights at infinity ([`InfiniteLight`]: directional, sun disc, environment map) come last.
//! Their photons leave a disc of the scene's bounding-sphere radius `R` facing the light, so
//! their power is `π R²` times the irradiance they bring (pbrt-v4 §12.4, §12.5); a shadow ray
//! towards one ends beyond that sphere. A ray that leaves the scene sees the sun discs and
//! environment maps ([`LightTable::escaped`]).

use crate::{AreaLight, EnvMap};
use geom::{Bounds3, Prim, Ray, SurfacePoint, TriMesh};
use glam::{DVec3, Vec3};
use math::warp::{
    sample_cosine_hemisphere, sample_uniform_disk_concentric, sample_uniform_sphere,
    sample_uniform_triangle,
};
use math::{Distribution1D, Frame, power_heuristic};

/// Marks a triangle that is not a light in the table's lookup.
const NOT_A_LIGHT: u32 = u32::MAX;

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

/// A point sampled on a light, seen from a receiving point (next-event estimation).
#[derive(Clone, Copy, Debug)]
pub struct LightSample {
    /// Index of the chosen light (into `Scene::lights`).
    pub light: usize,
    /// The light point with its error bound (for shadow rays) and the light's emitting normal.
    pub point: SurfacePoint,
    /// Emitted radiance towards the receiver (the light faces it: never zero-sided).
    pub le: Vec3,
    /// Unit direction from the receiver to the light point.
    pub wi: Vec3,
    /// Distance from the receiver to the light point.
    pub dist: f32,
    /// Solid-angle density at the receiver, the light choice included. For a delta light
    /// (`delta`) the probability of choosing it, and `le` is then `I falloff / r²`: the
    /// estimate `f le cos / pdf` keeps its form.
    pub pdf: f32,
    /// A point or spot light: BSDF sampling can never hit it, so NEE takes weight 1.
    pub delta: bool,
}

/// A point or spot light, validated by scene loading (Mitsuba 3's `point` and `spot`).
#[derive(Clone, Copy, Debug)]
pub struct DeltaLight {
    pub position: Vec3,
    /// Radiant intensity on the axis (W/sr per channel).
    pub intensity: Vec3,
    /// `None` for a point light.
    pub spot: Option<Spot>,
}

/// A spot light's cone: angles in radians, `0 <= beam <= cutoff <= π/2`.
#[derive(Clone, Copy, Debug)]
pub struct Spot {
    /// `n` is the axis (towards `look_at`).
    pub frame: Frame,
    pub cutoff: f32,
    pub beam: f32,
}

impl Spot {
    /// Mitsuba 3's falloff: 1 within `beam` of the axis, linear in angle down to 0 at
    /// `cutoff`, 0 beyond. `local_z` is cos θ of a unit direction.
    pub fn falloff(&self, local_z: f32) -> f32 {
        if local_z <= self.cutoff.cos() {
            0.0
        } else if local_z >= self.beam.cos() {
            1.0
        } else {
            ((self.cutoff - local_z.clamp(-1.0, 1.0).acos()) / (self.cutoff - self.beam))
                .clamp(0.0, 1.0)
        }
    }

    /// `∫ falloff dω / 2π = ∫₀^c falloff(θ) sin θ dθ`, in closed form: `1 - cos β` inside the
    /// beam plus `∫_β^c (c - θ)/(c - β) sin θ dθ = cos β - (sin c - sin β)/(c - β)` across
    /// the ramp, `1 - (sin c - sin β)/(c - β)` in all (`1 - cos c` when `β = c`).
    pub fn solid_angle_fraction(&self) -> f64 {
        let (c, b) = (self.cutoff as f64, self.beam as f64);
        if c - b < 1e-9 {
            1.0 - c.cos()
        } else {
            1.0 - (c.sin() - b.sin()) / (c - b)
        }
    }
}

impl DeltaLight {
    /// Emitted power: `4π I` for a point light (pbrt-v4 §12.1), `2π I ∫ falloff sin θ dθ` for
    /// a spot (§12.2), in f64.
    pub fn power(&self) -> DVec3 {
        let frac = match &self.spot {
            None => 2.0,
            Some(s) => s.solid_angle_fraction(),
        };
        2.0 * std::f64::consts::PI * frac * self.intensity.as_dvec3()
    }

    /// Intensity towards unit direction `w` (leaving the light).
    pub fn intensity_towards(&self, w: Vec3) -> Vec3 {
        match &self.spot {
            None => self.intensity,
            Some(s) => self.intensity * s.falloff(s.frame.n.dot(w)),
        }
    }
}

/// A light at infinity, validated by scene loading.
#[derive(Clone, Debug)]
pub enum InfiniteLight {
    /// Mitsuba 3's `directional` (pbrt-v4 §12.4): `irradiance` on a surface facing the unit
    /// direction `to_light` (against the light's travel). A delta light.
    Directional { to_light: Vec3, irradiance: Vec3 },
    /// A disc of uniform `radiance` and angular radius `acos(cos_max)` about `frame.n`
    /// (towards the light), sampled uniformly in its cone.
    Sun {
        frame: Frame,
        cos_max: f32,
        radiance: Vec3,
    },
    /// Mitsuba 3's `envmap` or `constant` ([`EnvMap`]).
    Environment(Box<EnvMap>),
}

impl InfiniteLight {
    /// A sun disc bringing `irradiance` to a surface facing it: the disc's cone of half-angle
    /// `α` gives `E = π L sin²α`, so `L = E / (π sin²α)`.
    pub fn sun(to_light: Vec3, irradiance: Vec3, angular_radius: f32) -> InfiniteLight {
        let cos_max = angular_radius.cos();
        let sin2 = angular_radius.sin().powi(2);
        InfiniteLight::Sun {
            frame: Frame::from_z(to_light),
            cos_max,
            radiance: irradiance / (std::f32::consts::PI * sin2),
        }
    }

    pub fn is_delta(&self) -> bool {
        matches!(self, InfiniteLight::Directional { .. })
    }

    /// Radiance carried along a ray escaping in unit direction `d` (zero for a directional
    /// light: no ray hits it).
    #[inline]
    pub fn le(&self, d: Vec3) -> Vec3 {
        match self {
            InfiniteLight::Directional { .. } => Vec3::ZERO,
            InfiniteLight::Sun {
                frame,
                cos_max,
                radiance,
            } => {
                if d.dot(frame.n) >= *cos_max {
                    *radiance
                } else {
                    Vec3::ZERO
                }
            }
            InfiniteLight::Environment(env) => env.eval(d),
        }
    }

    /// A unit direction towards the light, the radiance along it, and its solid-angle
    /// density (1 for a directional light, whose "radiance" is then its irradiance).
    fn sample(&self, u: [f32; 2]) -> (Vec3, Vec3, f32) {
        match self {
            InfiniteLight::Directional {
                to_light,
                irradiance,
            } => (*to_light, *irradiance, 1.0),
            InfiniteLight::Sun {
                frame,
                cos_max,
                radiance,
            } => {
                let z = 1.0 - u[0] * (1.0 - cos_max);
                let r = (1.0 - z * z).max(0.0).sqrt();
                let phi = std::f32::consts::TAU * u[1];
                let local = Vec3::new(r * phi.cos(), r * phi.sin(), z);
                (
                    frame.to_world(local).normalize(),
                    *radiance,
                    1.0 / (std::f32::consts::TAU * (1.0 - cos_max)),
                )
            }
            InfiniteLight::Environment(env) => env.sample(u),
        }
    }

    /// Solid-angle density of [`InfiniteLight::sample`] at unit direction `d`.
    #[inline]
    pub fn pdf(&self, d: Vec3) -> f32 {
        match self {
            InfiniteLight::Directional { .. } => 0.0,
            InfiniteLight::Sun { frame, cos_max, .. } => {
                if d.dot(frame.n) >= *cos_max {
                    1.0 / (std::f32::consts::TAU * (1.0 - cos_max))
                } else {
                    0.0
                }
            }
            InfiniteLight::Environment(env) => env.pdf(d),
        }
    }

    /// Solid angle a photon's direction cell covers per unit of `1 / N` at direction `d`
    /// (zero for a directional light, whose photons are parallel): `1 / pdf`.
    pub fn direction_cell(&self, d: Vec3) -> f64 {
        match self {
            InfiniteLight::Directional { .. } => 0.0,
            _ => {
                let pdf = self.pdf(d) as f64;
                if pdf > 0.0 { 1.0 / pdf } else { 0.0 }
            }
        }
    }

    /// `∫ L dω` over the sphere (the irradiance for a directional light), f64: its power
    /// through a disc of radius `R` is `π R²` times this.
    pub fn integral(&self) -> DVec3 {
        match self {
            InfiniteLight::Directional { irradiance, .. } => irradiance.as_dvec3(),
            InfiniteLight::Sun {
                cos_max, radiance, ..
            } => std::f64::consts::TAU * (1.0 - *cos_max as f64) * radiance.as_dvec3(),
            InfiniteLight::Environment(env) => env.radiance_integral(),
        }
    }
}

#[derive(Clone, Debug)]
struct InfiniteEntry {
    light: InfiniteLight,
    power: DVec3,
    pmf: f64,
}

#[derive(Clone, Copy, Debug)]
struct DeltaEntry {
    light: DeltaLight,
    power: DVec3,
    pmf: f64,
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

#[derive(Clone, Copy, Debug)]
struct Entry {
    vertices: [Vec3; 3],
    normal: Vec3,
    area: f32,
    le: Vec3,
    /// Frame about the emitting normal (photon directions).
    frame: Frame,
    /// `π A Le` in f64 from the scene's f32 area and radiance (no f32 rounding of the product).
    power: DVec3,
    /// This light's share of the summed RGB power.
    pmf: f64,
}

/// The scene's emissive triangles, ready for sampling (see the module docs).
#[derive(Clone, Debug)]
pub struct LightTable {
    distribution: Distribution1D,
    entries: Vec<Entry>,
    /// Point and spot lights: light `entries.len() + j` is `deltas[j]`.
    deltas: Vec<DeltaEntry>,
    /// Lights at infinity, after the point and spot lights.
    infinite: Vec<InfiniteEntry>,
    /// The scene's bounding sphere (pbrt-v4's `Bounds3::BoundingSphere`): where photons from
    /// lights at infinity start and shadow rays towards them end.
    center: Vec3,
    radius: f32,
    /// Light index of each mesh triangle, or `NOT_A_LIGHT`.
    light_of_triangle: Vec<u32>,
    total: DVec3,
}

impl LightTable {
    /// `None` when no light has positive, finite power (scene loading refuses such scenes) or
    /// a light names a triangle `mesh` lacks (loading builds lights from the mesh's triangles).
    // Built from loaded data: the loaders' lints (see `load.rs`) hold here too.
    #[cfg_attr(
        not(test),
        deny(
            clippy::unwrap_used,
            clippy::expect_used,
            clippy::indexing_slicing,
            clippy::panic,
            clippy::unreachable
        )
    )]
    pub fn new(
        mesh: &TriMesh,
        lights: &[AreaLight],
        deltas: &[DeltaLight],
        infinite: &[InfiniteLight],
        bounds: Bounds3,
    ) -> Option<LightTable> {
        let (center, radius) = if bounds.is_empty() {
            (Vec3::ZERO, 0.0)
        } else {
            let c = 0.5 * (bounds.min + bounds.max);
            (c, (bounds.max - c).length())
        };
        let radius_ok = radius.is_finite() && radius > 0.0;
        if !infinite.is_empty() && !radius_ok {
            return None;
        }
        let disc = std::f64::consts::PI * (radius as f64).powi(2);
        let power: Vec<DVec3> = lights
            .iter()
            .map(|l| std::f64::consts::PI * l.area as f64 * l.le.as_dvec3())
            .chain(deltas.iter().map(DeltaLight::power))
            .chain(infinite.iter().map(|l| disc * l.integral()))
            .collect();
        let weights: Vec<f64> = power.iter().map(|p| p.element_sum()).collect();
        let sum: f64 = weights.iter().sum();
        if weights.is_empty() || !sum.is_finite() || sum <= 0.0 {
            return None;
        }
        let mut light_of_triangle = vec![NOT_A_LIGHT; mesh.len()];
        for (i, l) in lights.iter().enumerate() {
            *light_of_triangle.get_mut(l.triangle as usize)? = i as u32;
        }
        let entries = lights
            .iter()
            .zip(&power)
            .zip(&weights)
            .map(|((l, &power), w)| Entry {
                vertices: mesh.vertices(l.triangle as usize),
                normal: l.normal,
                area: l.area,
                le: l.le,
                frame: Frame::from_z(l.normal),
                power,
                pmf: w / sum,
            })
            .collect();
        let deltas: Vec<DeltaEntry> = deltas
            .iter()
            .zip(power.iter().skip(lights.len()))
            .zip(weights.iter().skip(lights.len()))
            .map(|((&light, &power), w)| DeltaEntry {
                light,
                power,
                pmf: w / sum,
            })
            .collect();
        let skip = lights.len() + deltas.len();
        let infinite = infinite
            .iter()
            .zip(power.iter().skip(skip))
            .zip(weights.iter().skip(skip))
            .map(|((light, &power), w)| InfiniteEntry {
                light: light.clone(),
                power,
                pmf: w / sum,
            })
            .collect();
        Some(LightTable {
            distribution: Distribution1D::new(&weights),
            entries,
            deltas,
            infinite,
            center,
            radius,
            light_of_triangle,
            total: power.iter().fold(DVec3::ZERO, |s, p| s + *p),
        })
    }

    /// Number of lights: emissive triangles, then point and spot lights, then lights at
    /// infinity.
    pub fn len(&self) -> usize {
        self.entries.len() + self.deltas.len() + self.infinite.len()
    }

    /// Always false: [`LightTable::new`] refuses a scene without lights.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Whether light `i` is a point, spot or directional light (never hit by a ray).
    pub fn is_delta(&self, i: usize) -> bool {
        match self.infinite_entry(i) {
            Some(e) => e.light.is_delta(),
            None => i >= self.entries.len(),
        }
    }

    /// The point or spot light with index `i`, if it is one.
    pub fn delta(&self, i: usize) -> Option<&DeltaLight> {
        let j = i.checked_sub(self.entries.len())?;
        self.deltas.get(j).map(|d| &d.light)
    }

    fn infinite_entry(&self, i: usize) -> Option<&InfiniteEntry> {
        let k = i.checked_sub(self.entries.len() + self.deltas.len())?;
        self.infinite.get(k)
    }

    /// The light at infinity with index `i`, if it is one.
    pub fn infinite(&self, i: usize) -> Option<&InfiniteLight> {
        self.infinite_entry(i).map(|e| &e.light)
    }

    /// Whether any light sits at infinity (escaped rays may then carry light).
    pub fn has_infinite(&self) -> bool {
        !self.infinite.is_empty()
    }

    /// Radius of the scene's bounding sphere, the disc photons from infinity start on.
    pub fn scene_radius(&self) -> f32 {
        self.radius
    }

    /// Probability of choosing light `i`.
    pub fn pmf(&self, i: usize) -> f64 {
        if let Some(e) = self.infinite_entry(i) {
            return e.pmf;
        }
        match i.checked_sub(self.entries.len()) {
            Some(j) => self.deltas[j].pmf,
            None => self.entries[i].pmf,
        }
    }

    /// Power of light `i` (`π A Le` for a triangle, [`DeltaLight::power`], `π R²` times
    /// [`InfiniteLight::integral`]), f64.
    pub fn power(&self, i: usize) -> DVec3 {
        if let Some(e) = self.infinite_entry(i) {
            return e.power;
        }
        match i.checked_sub(self.entries.len()) {
            Some(j) => self.deltas[j].power,
            None => self.entries[i].power,
        }
    }

    /// Radiance a ray leaving the scene along unit `d` receives from the lights at infinity
    /// (sun discs and environment maps), unweighted: for camera rays and specular chains,
    /// which next-event estimation cannot produce.
    #[inline]
    pub fn escaped(&self, d: Vec3) -> Vec3 {
        self.infinite.iter().map(|e| e.light.le(d)).sum()
    }

    /// [`LightTable::escaped`] after a non-delta bounce whose BSDF density was `pdf_bsdf`:
    /// each light weighted by the power heuristic against next-event estimation's density
    /// of that direction (its choice probability times its own density; Veach 1997 §9.2).
    #[inline]
    pub fn escaped_mis(&self, d: Vec3, pdf_bsdf: f32) -> Vec3 {
        self.infinite
            .iter()
            .map(|e| {
                let le = e.light.le(d);
                if le == Vec3::ZERO {
                    return Vec3::ZERO;
                }
                le * power_heuristic(1, pdf_bsdf, 1, e.pmf as f32 * e.light.pdf(d))
            })
            .sum()
    }

    /// Total emitted power of all lights, RGB, f64.
    pub fn total_power(&self) -> DVec3 {
        self.total
    }

    pub fn vertices(&self, i: usize) -> [Vec3; 3] {
        self.entries[i].vertices
    }

    /// Area of light triangle `i` (the scene's value).
    pub fn area(&self, i: usize) -> f32 {
        self.entries[i].area
    }

    /// Frame of light `i`: `n` is the emitting side's normal, `s` and `t` its tangents.
    pub fn frame(&self, i: usize) -> Frame {
        self.entries[i].frame
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
        let e = &self.entries[light];
        if d.dot(e.normal) < 0.0 {
            e.le
        } else {
            Vec3::ZERO
        }
    }

    /// `u_light` chooses the light, `u_pos` the point (Heitz's triangle map). A point or spot
    /// light's point is its position, exact (no error bound); `n` is then meaningless.
    /// The point `u_pos` picks on triangle, point or spot light `i` (chosen by the caller
    /// from the table's distribution, once).
    fn sample_point(&self, i: usize, u_pos: [f32; 2]) -> LightPoint {
        if let Some(j) = i.checked_sub(self.entries.len()) {
            let d = &self.deltas[j];
            return LightPoint {
                light: i,
                pmf: d.pmf,
                point: SurfacePoint {
                    p: d.light.position,
                    p_err: Vec3::ZERO,
                    n: Vec3::Z,
                },
            };
        }
        let e = &self.entries[i];
        let v = e.vertices;
        let b = sample_uniform_triangle(u_pos);
        LightPoint {
            light: i,
            pmf: e.pmf,
            point: SurfacePoint {
                p: b.x * v[0] + b.y * v[1] + b.z * v[2],
                p_err: SurfacePoint::barycentric_error(b.to_array(), v),
                n: e.normal,
            },
        }
    }

    /// Samples a light point as seen from `from`: `u_pick` chooses the triangle, `u` the point.
    /// `None` when the point cannot send light to `from` (it sees the light's back or lies in
    /// its plane), which NEE counts as a zero contribution.
    pub fn sample(&self, from: Vec3, u_pick: f32, u: [f32; 2]) -> Option<LightSample> {
        let i = self.distribution.sample(u_pick).0;
        if let Some(e) = self.infinite_entry(i) {
            return self.sample_infinite(i, e, from, u);
        }
        let LightPoint {
            light: i,
            pmf,
            point,
        } = self.sample_point(i, u);
        let to = point.p - from;
        let dist2 = to.length_squared();
        if dist2 <= 0.0 || !dist2.is_finite() {
            return None;
        }
        let dist = dist2.sqrt();
        let wi = to / dist;
        if let Some(d) = self.delta(i) {
            // Irradiance-like `I falloff / r²` over the choice probability (pbrt-v4 §12.1's
            // `SampleLi`): no density in solid angle exists.
            let le = d.intensity_towards(-wi) / dist2;
            if le == Vec3::ZERO || !le.is_finite() {
                return None;
            }
            return Some(LightSample {
                light: i,
                point,
                le,
                wi,
                dist,
                pdf: pmf as f32,
                delta: true,
            });
        }
        let e = &self.entries[i];
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
            delta: false,
        })
    }

    /// A direction towards a light at infinity, its shadow ray ending past the scene's
    /// bounding sphere (pbrt-v4 §12.4: `p + wi · 2R`, here from `from`'s own distance).
    fn sample_infinite(
        &self,
        i: usize,
        e: &InfiniteEntry,
        from: Vec3,
        u: [f32; 2],
    ) -> Option<LightSample> {
        let (wi, le, pdf_dir) = e.light.sample(u);
        let delta = e.light.is_delta();
        let pdf = if delta {
            e.pmf as f32
        } else {
            e.pmf as f32 * pdf_dir
        };
        if le == Vec3::ZERO || !(pdf.is_finite() && pdf > 0.0) || !wi.is_finite() {
            return None;
        }
        let dist = 2.0 * (self.radius + (from - self.center).length());
        Some(LightSample {
            light: i,
            point: SurfacePoint {
                p: from + dist * wi,
                p_err: Vec3::ZERO,
                n: -wi,
            },
            le,
            wi,
            dist,
            pdf,
            delta,
        })
    }

    /// Solid-angle density with which [`LightTable::sample`] from `from` produces the point
    /// `to` on light `light` (the MIS weight of a BSDF-sampled hit). Zero from behind.
    pub fn pdf(&self, light: usize, from: Vec3, to: Vec3) -> f32 {
        let e = &self.entries[light];
        let d = to - from;
        let dist2 = d.length_squared();
        if dist2 <= 0.0 || !dist2.is_finite() {
            return 0.0;
        }
        let cos_light = -d.dot(e.normal) / dist2.sqrt();
        if cos_light <= 0.0 || cos_light.is_nan() {
            return 0.0;
        }
        e.pmf as f32 / e.area * dist2 / cos_light
    }

    /// Flux of a photon from light `i` when `photons` paths are emitted in all: the
    /// unbiased estimate `Φ_i / (p_i N)` of its share (Jensen 2001 §5.1, "multiple lights"; the
    /// course framework's `Φ_light · #lights / #shots` is the uniform-choice special case).
    /// With `p_i ∝ |Φ_i|` and one emission colour it equals `Φ_total / N` for every light.
    pub fn flux(&self, i: usize, photons: u64) -> DVec3 {
        self.power(i) / (self.pmf(i) * photons as f64)
    }

    /// Emit one photon: `u_light` picks the light, `u_pos` the point (Heitz's triangle map),
    /// `u_dir` the direction (Malley's method about the light's normal). A point light sends
    /// it uniformly over the sphere, a spot uniformly in its cutoff cone weighted by the
    /// falloff (Mitsuba 3's `sample_ray`); both carry `I falloff / (pdf_dir p_i N)`, whose
    /// mean is `Φ_i / (p_i N)` (pbrt-v4 §12.1, §12.2 `SampleLe`).
    pub fn emit(&self, u_light: f32, u_pos: [f32; 2], u_dir: [f32; 2], photons: u64) -> Emitted {
        let i = self.distribution.sample(u_light).0;
        if let Some(e) = self.infinite_entry(i) {
            return self.emit_infinite(i, e, u_pos, u_dir, photons);
        }
        let LightPoint {
            light: i,
            point,
            pmf,
        } = self.sample_point(i, u_pos);
        if let Some(l) = self.delta(i) {
            let (d, pdf_dir) = match &l.spot {
                None => (sample_uniform_sphere(u_dir), 0.25 / std::f64::consts::PI),
                Some(s) => {
                    let cos_c = s.cutoff.cos();
                    let z = 1.0 - u_dir[0] * (1.0 - cos_c);
                    let r = (1.0 - z * z).max(0.0).sqrt();
                    let phi = std::f32::consts::TAU * u_dir[1];
                    let local = Vec3::new(r * phi.cos(), r * phi.sin(), z);
                    let pdf = 1.0 / (std::f64::consts::TAU * (1.0 - cos_c as f64));
                    (s.frame.to_world(local).normalize(), pdf)
                }
            };
            let flux = l.intensity_towards(d).as_dvec3() / (pdf_dir * pmf * photons as f64);
            return Emitted {
                ray: Ray::new(point.p, d),
                light: i,
                point,
                flux,
            };
        }
        let d = self.entries[i]
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

    /// A photon from a light at infinity (pbrt-v4 §12.4, §12.5 `SampleLe`): `u_dir` picks
    /// the direction towards the light, `u_pos` a point uniform on the disc of radius `R`
    /// facing it, tangent to the bounding sphere; the photon travels away from the light.
    /// Flux `L π R² / (pdf_dir p_i N)` (`E π R² / (p_i N)` for a directional light), whose
    /// mean is `Φ_i / (p_i N)`.
    fn emit_infinite(
        &self,
        i: usize,
        e: &InfiniteEntry,
        u_pos: [f32; 2],
        u_dir: [f32; 2],
        photons: u64,
    ) -> Emitted {
        let (to_light, le, pdf_dir) = e.light.sample(u_dir);
        let frame = Frame::from_z(to_light);
        let disc = sample_uniform_disk_concentric(u_pos);
        let r = self.radius;
        // Just outside the sphere, so the first surface met is the scene's.
        let o = self.center + r * (disc.x * frame.s + disc.y * frame.t) + 1.0001 * r * to_light;
        let area = std::f64::consts::PI * (r as f64).powi(2);
        let flux = if pdf_dir > 0.0 && pdf_dir.is_finite() {
            le.as_dvec3() * area / (pdf_dir as f64 * e.pmf * photons as f64)
        } else {
            DVec3::ZERO
        };
        Emitted {
            ray: Ray::new(o, -to_light),
            light: i,
            point: SurfacePoint {
                p: o,
                p_err: Vec3::ZERO,
                n: -to_light,
            },
            flux,
        }
    }
}
