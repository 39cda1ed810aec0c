//! Light tracing: light paths connected to the camera (particle tracing; Veach 1997 §10.2,
//! pbrt-v4 §16.3's `t = 1` strategy, Mitsuba 3's `ptracer`). Every vertex where a connection
//! can carry light, the point on an area light and every non-delta surface vertex, is joined
//! to the pinhole by a shadow ray and adds to the pixel it projects to, weighted by the
//! camera's importance. A focus sharper than any density estimate's kernel is drawn as sharp
//! as the pixels: no estimate smears it.
//!
//! What it cannot draw: paths that reach the pinhole through a specular chain (`S+ E`: glass
//! and mirrors seen by the camera), since no connection to a point hits a delta lobe, and
//! emission seen directly from point, spot and distant lights, which no ray can hit.
//!
//! Paths follow the photon tracer's rules (`trace.rs`): Russian roulette on the albedo at a
//! Lambertian vertex, on the sample's weight at a glossy one; the flux is
//! `Φ_i / (p_i N)` at emission. Path `i` of pass `j` is point `i` of pass `j`'s own
//! scrambled Sobol sequence ([`math::SobolSampler`]: emission and scattering are 2-D strata
//! over the pass's paths, as a pixel's samples are over its passes in the path tracer; Keller
//! 1996, "Quasi-Monte Carlo methods for photorealistic image synthesis", §3), with its own
//! stream for roulette at glossy vertices, so a pass's splats are a pure function of the scene
//! and `(j, i)`.

use crate::trace::bounce;
use bsdf::TransportMode;
use film::Class;
use geom::SurfacePoint;
use glam::{DVec3, Vec3};
use math::{Frame, Rng, Sampler, SobolSampler};
use scene::{Light, Scene, sides_agree};
use std::ops::Range;

/// Mixed into a pass's stream so light paths never share numbers with the photon tracer's
/// paths of the same index ("lighttrc" in ASCII).
pub const LIGHT_STREAM: u64 = 0x6c69_6768_7474_7263;

/// One contribution of a light path to the image: the value added to pixel `pixel` (already
/// divided by the pass's path count), in the layer of `class`. In f64: the camera's
/// importance over a pixel's small area can lift a bright light's product past f32's range
/// even where the pixel's mean is far inside it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CameraSplat {
    pub pixel: u32,
    pub class: Class,
    pub value: DVec3,
}

/// The class of a light path's contribution at its `nd`-th non-delta vertex from the light,
/// connected straight to the eye, when its first non-delta vertex followed `first_specular`
/// specular bounces ([`Class`]'s partition read from the light).
fn class_of(first_specular: bool, nd: u32) -> Class {
    match (first_specular, nd) {
        (false, 0) => Class::Emitted,
        (false, 1) => Class::Direct,
        (false, _) => Class::Indirect,
        (true, 0 | 1) => Class::Caustic,
        (true, _) => Class::CausticIndirect,
    }
}

/// Traces light paths `range` of a pass of `photons` paths, `max_depth` hits at most, from the
/// stream `stream` (a pass's, see [`crate::pass_stream`]), and appends their contributions
/// to the camera in path order (and vertex order within a path).
pub fn trace_to_camera(
    scene: &Scene,
    photons: u64,
    max_depth: u32,
    stream: u64,
    range: Range<u64>,
    out: &mut Vec<CameraSplat>,
) {
    let t = Tracer {
        scene,
        photons,
        max_depth,
        stream: stream ^ LIGHT_STREAM,
        eye: SurfacePoint {
            p: scene.camera.eye,
            p_err: Vec3::ZERO,
            n: scene.camera.forward(),
        },
    };
    for i in range {
        t.path(i, out);
    }
}

struct Tracer<'a> {
    scene: &'a Scene,
    photons: u64,
    max_depth: u32,
    stream: u64,
    eye: SurfacePoint,
}

impl Tracer<'_> {
    fn path(&self, index: u64, out: &mut Vec<CameraSplat>) {
        let scene = self.scene;
        let mut rng = Rng::for_index(self.stream, index);
        // Paths past 2^32 of one pass start another scrambled sequence.
        let mut qmc = SobolSampler::new(math::mix64(self.stream ^ (index >> 32)), index as u32);
        // Fixed layout: 5 numbers to emit, then 3 per hit, used or not.
        let (u_light, u_pos, u_dir) = (qmc.uniform(), qmc.uniform2(), qmc.uniform2());
        let lights = &scene.light_table;
        let e = lights.emit(u_light, u_pos, u_dir, self.photons);
        // The point on an area light seen by the camera: emission seen directly, `L E`.
        if let Some(Light::Area(tri)) = lights.light(e.light) {
            self.connect_light(tri, &e.point, lights.pmf(e.light), out);
        }
        let mut flux = e.flux.as_vec3();
        let mut ray = e.ray;
        let mut specular = 0u32;
        let mut first_specular = false;
        let mut nd = 0u32;
        for _ in 0..self.max_depth {
            if !flux.cmpgt(Vec3::ZERO).any() {
                return;
            }
            let Some(hit) = scene.geometry.intersect(&ray) else {
                return;
            };
            flux *= scene.transmittance_to(&hit, &ray);
            let (uc, u) = (qmc.uniform(), qmc.uniform2());
            let Some(bsdf) = scene.bsdf_at(&hit) else {
                return;
            };
            let d = ray.d.normalize();
            if !bsdf.is_delta() {
                if nd == 0 {
                    first_specular = specular > 0;
                }
                nd += 1;
                self.connect(&hit, &bsdf, d, flux, class_of(first_specular, nd), out);
            }
            let Some((next, f, was_specular)) = bounce(&hit, bsdf, d, flux, uc, u, &mut rng) else {
                return;
            };
            specular += was_specular as u32;
            (ray, flux) = (next, f);
        }
    }

    /// A non-delta vertex reached with `flux` along unit `d`, joined to the eye: `flux f
    /// |cos θ_s| W_e cos θ_e / r²` (pbrt-v4 §16.3.3, `ConnectBDPT` with `t = 1`), `f` in
    /// [`TransportMode::Importance`] from the light's side to the eye's, both sides decided
    /// by the geometric normal as in the photon tracer.
    fn connect(
        &self,
        hit: &geom::Hit,
        bsdf: &bsdf::Bsdf,
        d: Vec3,
        flux: Vec3,
        class: Class,
        out: &mut Vec<CameraSplat>,
    ) {
        let cam = &self.scene.camera;
        let Some(proj) = cam.project(hit.point.p) else {
            return;
        };
        let ng = hit.point.n;
        let frame = Frame::from_z(hit.ns);
        let (wo, wi) = (-d, -proj.dir);
        let (wo_l, wi_l) = (frame.to_local(wo), frame.to_local(wi));
        if !sides_agree(wo, wi, ng, wo_l, wi_l) {
            return;
        }
        let f = bsdf.f(wo_l, wi_l, TransportMode::Importance);
        if f == Vec3::ZERO {
            return;
        }
        let weight = wi_l.z.abs() as f64 * importance(cam, &proj);
        let value = flux.as_dvec3() * f.as_dvec3() * weight;
        if !(value.is_finite() && value.cmpgt(DVec3::ZERO).any()) {
            return;
        }
        if self
            .scene
            .geometry
            .occluded(&hit.point.spawn_ray_to_point(&self.eye))
        {
            return;
        }
        out.push(CameraSplat {
            pixel: proj.pixel,
            class,
            value,
        });
    }

    /// The emitting point of an area light joined to the eye: `L_e A / (p_i N) cos θ_l W_e
    /// cos θ_e / r²` (the position alone was sampled, density `p_i / A`).
    fn connect_light(
        &self,
        tri: &scene::TriangleLight,
        point: &SurfacePoint,
        pmf: f64,
        out: &mut Vec<CameraSplat>,
    ) {
        let cam = &self.scene.camera;
        let Some(proj) = cam.project(point.p) else {
            return;
        };
        let le = tri.le(proj.dir);
        let cos_l = -proj.dir.dot(tri.normal);
        if le == Vec3::ZERO || cos_l <= 0.0 {
            return;
        }
        let share = tri.area as f64 / (pmf * self.photons as f64);
        let value = le.as_dvec3() * (share * cos_l as f64 * importance(cam, &proj));
        if !(value.is_finite() && value.cmpgt(DVec3::ZERO).any()) {
            return;
        }
        if self
            .scene
            .geometry
            .occluded(&point.spawn_ray_to_point(&self.eye))
        {
            return;
        }
        out.push(CameraSplat {
            pixel: proj.pixel,
            class: Class::Emitted,
            value,
        });
    }
}

/// The camera's importance times the pinhole's geometry term for the point `proj` sees:
/// `W_e cos θ_e / r²` (pbrt-v4 §16.1.1: the pinhole's `SampleWi` has density `r² / cos θ_e`).
fn importance(cam: &scene::Camera, proj: &scene::Projection) -> f64 {
    let d = proj.dist as f64;
    cam.importance(proj.cos) as f64 * proj.cos as f64 / (d * d)
}
