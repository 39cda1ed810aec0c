//! The lights: one closed type, [`Light`], with one `match` per operation, and a file per
//! family (`area.rs`, `point.rs`, `distant.rs`, `environment.rs`), pbrt-v4's `Light` habit.
//! Every pass that touches a light goes through [`LightTable`], built once when the scene
//! loads: it chooses a light by emitted power (pbrt-v4 §12.6.2), answers which light a
//! primitive is and what it emits, converts densities to solid angle for next-event
//! estimation, and emits photons. One table means one weighting of lights for the eye pass
//! and the photon pass. Random numbers come in as arguments (pbrt-v4's habit: samplers never
//! own a generator).
//!
//! The table numbers emissive triangles first, then the point and spot lights, then the
//! lights at infinity, each in the order the scene file gives them. Lights at infinity
//! (directional, sun disc, environment) send photons from a disc of the scene's
//! bounding-sphere radius `R` facing the light, so their power is `π R²` times the
//! irradiance they bring (pbrt-v4 §12.4, §12.5); a shadow ray towards one ends beyond that
//! sphere. A ray that leaves the scene sees the sun discs and environment maps
//! ([`LightTable::escaped`]).
//!
//! A new light type is one file here, one arm of [`Light`] (the compiler then lists every
//! operation it must answer) and one arm of the scene file's `LightDesc`, which
//! `crates/scene/src/load/lights.rs` turns into it.

mod area;
mod distant;
mod environment;
mod point;

pub use area::{AreaLight, MIN_EMIT_COS, TriangleLight};
pub use distant::{Directional, Sun};
pub use environment::Environment;
pub use point::{PointLight, SpotLight};

use geom::{Bounds3, Prim, Ray, SurfacePoint, TriMesh};
use glam::{DVec3, Vec3};
use math::warp::sample_uniform_disk_concentric;
use math::{Distribution1D, Frame, power_heuristic};

/// Marks a triangle that is not a light in the table's lookup.
const NOT_A_LIGHT: u32 = u32::MAX;

/// Every kind of light photonflow renders.
#[derive(Clone, Debug)]
pub enum Light {
    Area(TriangleLight),
    Point(PointLight),
    Spot(SpotLight),
    Directional(Directional),
    Sun(Sun),
    Environment(Environment),
}

/// The scene's bounding sphere (pbrt-v4's `Bounds3::BoundingSphere`): where photons from
/// lights at infinity start and shadow rays towards them end.
#[derive(Clone, Copy, Debug)]
pub struct Sphere {
    pub center: Vec3,
    pub radius: f32,
}

/// What a photon's cells of position and direction measure, per unit of its light's share
/// `1 / (p_i N)`: photon differentials (`emit_diff`) are built from it. `frame`'s tangents
/// carry the positional spread `rho_x`, and `rho_w` is the angular one, both before the
/// user's smoothing scale.
#[derive(Clone, Copy, Debug)]
pub struct Spread {
    pub frame: Frame,
    pub rho_x: f64,
    pub rho_w: f64,
}

/// A point sampled on a light, seen from a receiving point (next-event estimation).
#[derive(Clone, Copy, Debug)]
pub struct LightSample {
    /// Index of the chosen light in the table.
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
    /// A point, spot or directional light: BSDF sampling can never hit it, so NEE takes
    /// weight 1.
    pub delta: bool,
}

/// The densities with which a light emits a ray leaving it along a direction, which the
/// combined method's MIS weights compare (Georgiev et al. 2012, "Light transport simulation
/// with vertex connection and merging", §4 and its technical report's Table 1; SmallVCM's
/// `Emit`/`Illuminate`/`GetRadiance`). The light's choice probability is included in both.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EmitPdfs {
    /// Density of emitting the ray: area (or disc) times direction density. Zero where the
    /// light cannot emit along it.
    pub emit: f32,
    /// Density of next-event estimation choosing the light's point: per unit area for a
    /// light at a position (1 for a point or spot light's only point), per unit solid angle
    /// for a light at infinity (1 for a directional light's only direction).
    pub direct: f32,
    /// Cosine between the ray and the light's normal (1 for lights without one).
    pub cos: f32,
}

/// A photon leaving a light.
#[derive(Clone, Copy, Debug)]
pub struct Emitted {
    /// Starts just off the light (offset past the point's error bound) with a unit direction.
    pub ray: Ray,
    /// Index of the light in the table.
    pub light: usize,
    /// The point on the light and its normal.
    pub point: SurfacePoint,
    /// Flux carried, `Φ_light / (p_light N)`, in f64.
    pub flux: DVec3,
}

impl Light {
    /// Emitted power, f64: `π A Le` for a triangle, `4π I` for a point light, `π R²` times
    /// [`Light::integral`] for a light at infinity.
    pub fn power(&self, sphere: &Sphere) -> DVec3 {
        match self {
            Light::Area(l) => l.power(),
            Light::Point(l) => l.power(),
            Light::Spot(l) => l.power(),
            Light::Directional(_) | Light::Sun(_) | Light::Environment(_) => {
                std::f64::consts::PI * (sphere.radius as f64).powi(2) * self.integral()
            }
        }
    }

    /// `∫ L dω` over the sphere of a light at infinity (the irradiance for a directional
    /// light), f64; zero for the others.
    pub fn integral(&self) -> DVec3 {
        match self {
            Light::Directional(l) => l.irradiance.as_dvec3(),
            Light::Sun(l) => l.integral(),
            Light::Environment(l) => l.map.radiance_integral(),
            Light::Area(_) | Light::Point(_) | Light::Spot(_) => DVec3::ZERO,
        }
    }

    /// True for a light no ray can hit: point, spot, directional.
    pub fn is_delta(&self) -> bool {
        match self {
            Light::Point(_) | Light::Spot(_) | Light::Directional(_) => true,
            Light::Area(_) | Light::Sun(_) | Light::Environment(_) => false,
        }
    }

    /// True for a light at infinity (directional, sun disc, environment).
    pub fn is_infinite(&self) -> bool {
        match self {
            Light::Directional(_) | Light::Sun(_) | Light::Environment(_) => true,
            Light::Area(_) | Light::Point(_) | Light::Spot(_) => false,
        }
    }

    /// Radiance a ray travelling along unit `d` receives from this light when it hits it (a
    /// triangle, one-sided) or escapes towards it (a sun disc, an environment); zero for
    /// delta lights.
    #[inline]
    pub fn le(&self, d: Vec3) -> Vec3 {
        match self {
            Light::Area(l) => l.le(d),
            Light::Sun(l) => l.le(d),
            Light::Environment(l) => l.map.eval(d),
            Light::Point(_) | Light::Spot(_) | Light::Directional(_) => Vec3::ZERO,
        }
    }

    /// Solid-angle density with which a light at infinity samples unit direction `d`
    /// (towards it); zero for the others and for a directional light.
    #[inline]
    pub fn pdf_dir(&self, d: Vec3) -> f32 {
        match self {
            Light::Sun(l) => l.pdf(d),
            Light::Environment(l) => l.map.pdf(d),
            Light::Area(_) | Light::Point(_) | Light::Spot(_) | Light::Directional(_) => 0.0,
        }
    }

    /// A direction towards a light at infinity, the radiance along it and its solid-angle
    /// density (1 for a directional light, whose "radiance" is then its irradiance).
    fn sample_dir(&self, u: [f32; 2]) -> (Vec3, Vec3, f32) {
        match self {
            Light::Directional(l) => (l.to_light, l.irradiance, 1.0),
            Light::Sun(l) => l.sample(u),
            Light::Environment(l) => l.map.sample(u),
            Light::Area(_) | Light::Point(_) | Light::Spot(_) => (Vec3::ZERO, Vec3::ZERO, 0.0),
        }
    }

    /// Next-event estimation from `from`: the light point, radiance towards `from`, unit
    /// direction and distance to it, and density (the choice probability `pmf` included).
    fn sample_li(
        &self,
        pmf: f64,
        from: Vec3,
        u: [f32; 2],
        sphere: &Sphere,
    ) -> Option<(SurfacePoint, Vec3, Vec3, f32, f32)> {
        let delta = |(p, le, wi, dist)| Some((p, le, wi, dist, pmf as f32));
        match self {
            Light::Area(l) => l.sample_li(pmf, from, u),
            Light::Point(l) => point::sample_li(l.position, |_| l.intensity, from).and_then(delta),
            Light::Spot(l) => {
                point::sample_li(l.position, |w| l.intensity_towards(w), from).and_then(delta)
            }
            Light::Directional(_) | Light::Sun(_) | Light::Environment(_) => {
                sphere.sample_infinite(self, pmf, from, u)
            }
        }
    }

    /// A photon: ray, point on the light, flux `Φ_i / (p_i N)` in the mean (`power` is
    /// `Φ_i`; a triangle's photons all carry that share, as [`LightTable::flux`] gives it).
    fn emit(
        &self,
        u_pos: [f32; 2],
        u_dir: [f32; 2],
        pmf: f64,
        power: DVec3,
        photons: u64,
        sphere: &Sphere,
    ) -> (Ray, SurfacePoint, DVec3) {
        match self {
            Light::Area(l) => {
                let (ray, point) = l.emit(u_pos, u_dir);
                (ray, point, power / (pmf * photons as f64))
            }
            Light::Point(l) => l.emit(u_dir, pmf, photons),
            Light::Spot(l) => l.emit(u_dir, pmf, photons),
            Light::Directional(_) | Light::Sun(_) | Light::Environment(_) => {
                sphere.emit_infinite(self, u_pos, u_dir, pmf, photons)
            }
        }
    }

    /// The cells of a photon leaving along unit `d` (see [`Spread`]); `n` is the number of
    /// photon paths and `pmf` this light's choice probability.
    pub fn spread(&self, d: Vec3, pmf: f64, n: f64, sphere: &Sphere) -> Spread {
        let angular = |cell: f64| (cell / (pmf * n) / std::f64::consts::PI).sqrt();
        let (frame, rho_x, rho_w) = match self {
            Light::Area(l) => l.spread(d, pmf, n),
            // No positional extent; a direction cell of `cone / (N p_i)` (`4π/N` for one point
            // light; for a spot, its cutoff cone over its photons), `ρ_ω = sqrt(cell / π)`.
            Light::Point(_) => (Frame::from_z(d), 0.0, angular(4.0 * std::f64::consts::PI)),
            Light::Spot(l) => (Frame::from_z(d), 0.0, angular(l.cone())),
            // The origin is uniform on a disc of radius `R` facing the light, a cell of
            // `π R² / (p_i N)`, so `ρ_x = R / sqrt(p_i N)` along the disc's tangents; the
            // direction cell is `1 / (p_i N pdf_dir)`, zero for a directional light: its
            // photons are parallel and their footprint stays the disc's spacing.
            Light::Directional(_) | Light::Sun(_) | Light::Environment(_) => {
                let rho_x = sphere.radius as f64 / (pmf * n).sqrt();
                let pdf = self.pdf_dir(-d) as f64;
                let cell = if pdf > 0.0 { 1.0 / pdf } else { 0.0 };
                (Frame::from_z(-d), rho_x, angular(cell))
            }
        };
        Spread {
            frame,
            rho_x,
            rho_w,
        }
    }

    /// What each method does with this light, one line for the effects plan; `None` for an
    /// emissive triangle, the case every method is built around.
    pub fn plan_line(&self) -> Option<String> {
        let delta = |kind: &str| {
            format!(
                "{kind}: next-event estimation and photons; never hit by rays; caustics \
                 through specular surfaces only by photons (the path tracer's caustic \
                 layer from it is zero)"
            )
        };
        let infinite = "next-event estimation with MIS against BSDF sampling, seen by \
                        camera rays and rays that leave the scene; photons from a disc \
                        covering the scene's bounding sphere";
        Some(match self {
            Light::Area(_) => return None,
            Light::Point(_) => delta("point light"),
            Light::Spot(_) => delta("spot light"),
            Light::Directional(_) => {
                delta("directional light")
                    + "; photons from a disc covering the scene's bounding sphere"
            }
            Light::Sun(_) => format!("sun disc: {infinite}"),
            Light::Environment(Environment { file: Some(f), .. }) => format!(
                "environment map ({f}): importance-sampled by luminance (pbrt-v4 §12.5.2); \
                 {infinite}"
            ),
            Light::Environment(_) => format!("constant environment: {infinite}"),
        })
    }

    /// One line for `info`: the kind and what defines it; `None` for an emissive triangle
    /// (counted, not listed).
    pub fn summary(&self) -> Option<String> {
        let v = |v: Vec3| v.to_array();
        Some(match self {
            Light::Area(_) => return None,
            Light::Point(l) => format!(
                "point at {:?}, intensity {:?}",
                v(l.position),
                v(l.intensity)
            ),
            Light::Spot(l) => format!(
                "spot at {:?} along {:?}, intensity {:?}, cutoff {}°, beam {}°",
                v(l.position),
                v(l.frame.n),
                v(l.intensity),
                l.cutoff.to_degrees(),
                l.beam.to_degrees()
            ),
            Light::Directional(l) => format!(
                "directional towards {:?}, irradiance {:?}",
                v(-l.to_light),
                v(l.irradiance)
            ),
            Light::Sun(l) => format!(
                "sun disc towards {:?}, angular radius {}°, radiance {:?}",
                v(-l.frame.n),
                l.cos_max.acos().to_degrees(),
                v(l.radiance)
            ),
            Light::Environment(Environment { file: Some(f), .. }) => {
                format!("environment map {f}")
            }
            Light::Environment(_) => "constant environment".to_string(),
        })
    }
}

impl Sphere {
    /// The bounding sphere of `bounds`, of radius 0 when they are empty.
    fn of(bounds: Bounds3) -> Sphere {
        if bounds.is_empty() {
            Sphere {
                center: Vec3::ZERO,
                radius: 0.0,
            }
        } else {
            let c = 0.5 * (bounds.min + bounds.max);
            Sphere {
                center: c,
                radius: (bounds.max - c).length(),
            }
        }
    }

    /// A direction towards a light at infinity, its shadow ray ending past the bounding
    /// sphere (pbrt-v4 §12.4: `p + wi · 2R`, here from `from`'s own distance).
    fn sample_infinite(
        &self,
        light: &Light,
        pmf: f64,
        from: Vec3,
        u: [f32; 2],
    ) -> Option<(SurfacePoint, Vec3, Vec3, f32, f32)> {
        let (wi, le, pdf_dir) = light.sample_dir(u);
        let pdf = if light.is_delta() {
            pmf as f32
        } else {
            pmf as f32 * pdf_dir
        };
        if le == Vec3::ZERO || !(pdf.is_finite() && pdf > 0.0) || !wi.is_finite() {
            return None;
        }
        let dist = 2.0 * (self.radius + (from - self.center).length());
        let point = SurfacePoint {
            p: from + dist * wi,
            p_err: Vec3::ZERO,
            n: -wi,
        };
        Some((point, le, wi, dist, pdf))
    }

    /// A photon from a light at infinity (pbrt-v4 §12.4, §12.5 `SampleLe`): `u_dir` picks
    /// the direction towards the light, `u_pos` a point uniform on the disc of radius `R`
    /// facing it, tangent to the bounding sphere; the photon travels away from the light.
    /// Flux `L π R² / (pdf_dir p_i N)` (`E π R² / (p_i N)` for a directional light), whose
    /// mean is `Φ_i / (p_i N)`.
    fn emit_infinite(
        &self,
        light: &Light,
        u_pos: [f32; 2],
        u_dir: [f32; 2],
        pmf: f64,
        photons: u64,
    ) -> (Ray, SurfacePoint, DVec3) {
        let (to_light, le, pdf_dir) = light.sample_dir(u_dir);
        let frame = Frame::from_z(to_light);
        let disc = sample_uniform_disk_concentric(u_pos);
        let r = self.radius;
        // Just outside the sphere, so the first surface met is the scene's.
        let o = self.center + r * (disc.x * frame.s + disc.y * frame.t) + 1.0001 * r * to_light;
        let area = std::f64::consts::PI * (r as f64).powi(2);
        let flux = if pdf_dir > 0.0 && pdf_dir.is_finite() {
            le.as_dvec3() * area / (pdf_dir as f64 * pmf * photons as f64)
        } else {
            DVec3::ZERO
        };
        let point = SurfacePoint {
            p: o,
            p_err: Vec3::ZERO,
            n: -to_light,
        };
        (Ray::new(o, -to_light), point, flux)
    }
}

#[derive(Clone, Debug)]
struct Entry {
    light: Light,
    power: DVec3,
    /// This light's share of the summed RGB power.
    pmf: f64,
}

/// The scene's lights, ready for sampling (see the module docs).
#[derive(Clone, Debug)]
pub struct LightTable {
    distribution: Distribution1D,
    entries: Vec<Entry>,
    /// Index of the first light at infinity: they come last.
    first_infinite: usize,
    sphere: Sphere,
    /// Light index of each mesh triangle, or `NOT_A_LIGHT`.
    light_of_triangle: Vec<u32>,
    total: DVec3,
    /// Indices of the point, spot and directional lights.
    delta: Vec<usize>,
}

impl LightTable {
    /// The table of `lights`: emissive triangles (of `mesh`), then point and spot lights, then
    /// lights at infinity, as loading builds them. `None` when no light has positive, finite
    /// power (scene loading refuses such scenes), a light at infinity has no scene of
    /// positive extent to shine on, or a light names a triangle `mesh` lacks.
    // Built from loaded data: the loaders' lints (see `crates/scene/src/load/mod.rs`) hold here too.
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
        area: &[AreaLight],
        others: Vec<Light>,
        bounds: Bounds3,
    ) -> Option<LightTable> {
        let sphere = Sphere::of(bounds);
        let radius_ok = sphere.radius.is_finite() && sphere.radius > 0.0;
        let mut lights: Vec<Light> = area
            .iter()
            .map(|l| Light::Area(TriangleLight::new(mesh.vertices(l.triangle as usize), l)))
            .collect();
        // Numbered by family whatever the order they come in: delta lights, then infinity.
        let (infinite, deltas): (Vec<Light>, Vec<Light>) =
            others.into_iter().partition(Light::is_infinite);
        if !infinite.is_empty() && !radius_ok {
            return None;
        }
        lights.extend(deltas);
        let first_infinite = lights.len();
        lights.extend(infinite);
        let power: Vec<DVec3> = lights.iter().map(|l| l.power(&sphere)).collect();
        let weights: Vec<f64> = power.iter().map(|p| p.element_sum()).collect();
        let sum: f64 = weights.iter().sum();
        if weights.is_empty() || !sum.is_finite() || sum <= 0.0 {
            return None;
        }
        let mut light_of_triangle = vec![NOT_A_LIGHT; mesh.len()];
        for (i, l) in area.iter().enumerate() {
            *light_of_triangle.get_mut(l.triangle as usize)? = i as u32;
        }
        let total = power.iter().fold(DVec3::ZERO, |s, p| s + *p);
        let entries: Vec<Entry> = lights
            .into_iter()
            .zip(&power)
            .zip(&weights)
            .map(|((light, &power), w)| Entry {
                light,
                power,
                pmf: w / sum,
            })
            .collect();
        let delta = (0..entries.len())
            .filter(|&i| entries.get(i).is_some_and(|e| e.light.is_delta()))
            .collect();
        Some(LightTable {
            distribution: Distribution1D::new(&weights),
            entries,
            first_infinite,
            sphere,
            light_of_triangle,
            total,
            delta,
        })
    }

    /// Number of lights: emissive triangles, then point and spot lights, then lights at
    /// infinity.
    pub fn len(&self) -> usize {
        self.entries.len()
    }

    /// Always false: [`LightTable::new`] refuses a scene without lights.
    pub fn is_empty(&self) -> bool {
        self.entries.is_empty()
    }

    /// Light `i`, if there is one.
    pub fn light(&self, i: usize) -> Option<&Light> {
        self.entries.get(i).map(|e| &e.light)
    }

    /// Every light, in the table's order.
    pub fn lights(&self) -> impl Iterator<Item = &Light> {
        self.entries.iter().map(|e| &e.light)
    }

    /// Whether light `i` is a point, spot or directional light (never hit by a ray).
    pub fn is_delta(&self, i: usize) -> bool {
        self.entries[i].light.is_delta()
    }

    fn infinite(&self) -> &[Entry] {
        self.entries.get(self.first_infinite..).unwrap_or(&[])
    }

    /// Whether any light sits at infinity (escaped rays may then carry light).
    pub fn has_infinite(&self) -> bool {
        !self.infinite().is_empty()
    }

    /// The scene's bounding sphere, where photons from infinity start.
    pub fn sphere(&self) -> &Sphere {
        &self.sphere
    }

    /// Radius of the scene's bounding sphere, the disc photons from infinity start on.
    pub fn scene_radius(&self) -> f32 {
        self.sphere.radius
    }

    /// Probability of choosing light `i`.
    pub fn pmf(&self, i: usize) -> f64 {
        self.entries[i].pmf
    }

    /// Power of light `i` ([`Light::power`]), f64.
    pub fn power(&self, i: usize) -> DVec3 {
        self.entries[i].power
    }

    /// Radiance a ray leaving the scene along unit `d` receives from the lights at infinity
    /// (sun discs and environment maps), unweighted: for camera rays and specular chains,
    /// which next-event estimation cannot produce.
    #[inline]
    pub fn escaped(&self, d: Vec3) -> Vec3 {
        self.infinite().iter().map(|e| e.light.le(d)).sum()
    }

    /// [`LightTable::escaped`] after a non-delta bounce whose BSDF density was `pdf_bsdf`:
    /// each light weighted by the power heuristic against next-event estimation's density
    /// of that direction (its choice probability times its own density; Veach 1997 §9.2).
    #[inline]
    pub fn escaped_mis(&self, d: Vec3, pdf_bsdf: f32) -> Vec3 {
        self.infinite()
            .iter()
            .map(|e| {
                let le = e.light.le(d);
                if le == Vec3::ZERO {
                    return Vec3::ZERO;
                }
                le * power_heuristic(1, pdf_bsdf, 1, e.pmf as f32 * e.light.pdf_dir(d))
            })
            .sum()
    }

    /// Total emitted power of all lights, RGB, f64.
    pub fn total_power(&self) -> DVec3 {
        self.total
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

    /// Radiance a ray travelling along `d` receives from light `light` where it hits it
    /// (one-sided emission: zero when the ray hits the back).
    pub fn le(&self, light: usize, d: Vec3) -> Vec3 {
        self.entries[light].light.le(d)
    }

    /// Samples a light point as seen from `from`: `u_pick` chooses the light, `u` the point.
    /// `None` when the point cannot send light to `from` (it sees the light's back or lies in
    /// its plane), which NEE counts as a zero contribution.
    pub fn sample(&self, from: Vec3, u_pick: f32, u: [f32; 2]) -> Option<LightSample> {
        let i = self.distribution.sample(u_pick).0;
        self.sample_of(i, self.entries[i].pmf, from, u)
    }

    /// Light `i`'s sample seen from `from`, the light chosen with probability `pmf`.
    fn sample_of(&self, i: usize, pmf: f64, from: Vec3, u: [f32; 2]) -> Option<LightSample> {
        let light = &self.entries.get(i)?.light;
        let (point, le, wi, dist, pdf) = light.sample_li(pmf, from, u, &self.sphere)?;
        Some(LightSample {
            light: i,
            point,
            le,
            wi,
            dist,
            pdf,
            delta: light.is_delta(),
        })
    }

    /// Whether the scene has a point, spot or directional light.
    pub fn has_delta(&self) -> bool {
        !self.delta.is_empty()
    }

    /// Each delta light (point, spot, directional) as seen from `from`, chosen with
    /// probability 1: a delta light has one sample, so a sum over them needs no random
    /// numbers. Occlusion is the caller's to test.
    pub fn delta_samples(&self, from: Vec3) -> impl Iterator<Item = LightSample> + '_ {
        self.delta
            .iter()
            .filter_map(move |&i| self.sample_of(i, 1.0, from, [0.5, 0.5]))
    }

    /// Solid-angle density with which [`LightTable::sample`] from `from` produces the point
    /// `to` on emissive triangle `light` (the MIS weight of a BSDF-sampled hit). Zero from
    /// behind, and for lights that are not triangles.
    pub fn pdf(&self, light: usize, from: Vec3, to: Vec3) -> f32 {
        let e = &self.entries[light];
        match &e.light {
            Light::Area(l) => l.pdf(e.pmf, from, to),
            _ => 0.0,
        }
    }

    /// Flux of a photon from light `i` when `photons` paths are emitted in all: the
    /// unbiased estimate `Φ_i / (p_i N)` of its share (Jensen 2001 §5.1, "multiple lights"; the
    /// course framework's `Φ_light · #lights / #shots` is the uniform-choice special case).
    /// With `p_i ∝ |Φ_i|` and one emission colour it equals `Φ_total / N` for every light.
    pub fn flux(&self, i: usize, photons: u64) -> DVec3 {
        self.power(i) / (self.pmf(i) * photons as f64)
    }

    /// Emit one photon: `u_light` picks the light, `u_pos` the point, `u_dir` the direction
    /// (each light's `emit`).
    pub fn emit(&self, u_light: f32, u_pos: [f32; 2], u_dir: [f32; 2], photons: u64) -> Emitted {
        let i = self.distribution.sample(u_light).0;
        let e = &self.entries[i];
        let (ray, point, flux) = e
            .light
            .emit(u_pos, u_dir, e.pmf, e.power, photons, &self.sphere);
        Emitted {
            ray,
            light: i,
            point,
            flux,
        }
    }

    /// [`EmitPdfs`] of light `light` emitting along unit `d` (leaving it), for a ray that
    /// leaves a triangle light or one at infinity; zeros where the light cannot send it.
    pub fn emit_pdfs(&self, light: usize, d: Vec3) -> EmitPdfs {
        let e = &self.entries[light];
        let pmf = e.pmf as f32;
        let disc = 1.0 / (std::f32::consts::PI * self.sphere.radius * self.sphere.radius);
        let (emit, direct, cos) = match &e.light {
            Light::Area(l) => {
                let cos = d.dot(l.normal);
                if cos <= 0.0 {
                    (0.0, 0.0, 0.0)
                } else {
                    (
                        cos * std::f32::consts::FRAC_1_PI / l.area,
                        1.0 / l.area,
                        cos,
                    )
                }
            }
            Light::Point(_) => (0.25 * std::f32::consts::FRAC_1_PI, 1.0, 1.0),
            Light::Spot(l) => {
                let inside = l.frame.n.dot(d) > l.cutoff.cos();
                (if inside { 1.0 / l.cone() as f32 } else { 0.0 }, 1.0, 1.0)
            }
            Light::Directional(_) => (disc, 1.0, 1.0),
            Light::Sun(_) | Light::Environment(_) => {
                let p = e.light.pdf_dir(-d);
                (p * disc, p, 1.0)
            }
        };
        EmitPdfs {
            emit: emit * pmf,
            direct: direct * pmf,
            cos,
        }
    }

    /// Whether light `i` sits at a position (a triangle, point or spot light), so densities
    /// towards it convert between area and solid angle.
    pub fn is_finite(&self, i: usize) -> bool {
        !self.entries[i].light.is_infinite()
    }

    /// The cells of photon `e` (see [`Spread`]) when `photons` paths are emitted in all.
    pub fn spread(&self, e: &Emitted, photons: u64) -> Spread {
        let entry = &self.entries[e.light];
        let n = photons.max(1) as f64;
        entry.light.spread(e.ray.d, entry.pmf, n, &self.sphere)
    }

    /// `info`'s summary: the counts by kind on one line, then one line per light that is not
    /// a triangle.
    pub fn summary(&self, triangle_area: f64, power: Vec3) -> String {
        let count = |f: fn(&Light) -> bool| self.lights().filter(|l| f(l)).count();
        let triangles = count(|l| matches!(l, Light::Area(_)));
        let (points, spots) = (
            count(|l| matches!(l, Light::Point(_))),
            count(|l| matches!(l, Light::Spot(_))),
        );
        let mut s = format!("{triangles} emissive triangles, area {triangle_area:.6}");
        if points + spots > 0 {
            s += &format!(", {points} point and {spots} spot lights");
        }
        if self.has_infinite() {
            s += &format!(
                ", {} directional, {} sun and {} environment lights (scene radius {})",
                count(|l| matches!(l, Light::Directional(_))),
                count(|l| matches!(l, Light::Sun(_))),
                count(|l| matches!(l, Light::Environment(_))),
                self.sphere.radius
            );
        }
        s += &format!(", power {:?}", power.to_array());
        for l in self.lights().filter_map(Light::summary) {
            s += &format!("\nlight      {l}");
        }
        s
    }
}
