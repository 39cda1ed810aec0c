//! Light subpaths: emitted, traced, their non-delta vertices stored for connections and
//! merging and joined to the camera (light tracing, the `t = 1` strategy).

use crate::surface::Surface;
use crate::{Pass, SubPath, mis, weights};
use bsdf::{Bsdf, TransportMode};
use geom::{Ray, SurfacePoint};
use glam::{DVec3, Vec3};
use math::{Frame, Sampler, SobolSampler, mix64};
use scene::Scene;
use std::ops::Range;

/// A stored light vertex: where a light subpath reached a non-delta surface.
#[derive(Clone, Copy, Debug)]
pub struct LightVertex {
    /// Position, its error bound and the geometric normal.
    pub point: SurfacePoint,
    /// The shading normal the BSDF's frame is built on.
    pub ns: Vec3,
    /// Unit direction back towards the previous vertex.
    pub wo: Vec3,
    /// Throughput on arrival (emission over the densities so far, the BSDF here excluded).
    pub throughput: Vec3,
    pub bsdf: Bsdf,
    /// Segments from the light.
    pub length: u32,
    pub d_vcm: f32,
    pub d_vc: f32,
    pub d_vm: f32,
    /// `SubPath::joins` at the vertex: 0 where a connection ending here is a bidirectional
    /// one and the pass has none, else 1.
    pub joins: f32,
}

/// A light vertex's contribution through the camera to pixel `pixel` (already over the
/// pass's path count and MIS-weighted), in f64 as the light tracer's splats are.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CameraSplat {
    pub pixel: u32,
    pub value: DVec3,
}

/// What merging reads of a light vertex, kept in the grid beside its position (40 bytes of
/// the vertex's 136, see [`crate::Grid`]).
#[derive(Clone, Copy, Debug, Default)]
pub struct Merged {
    /// Unit direction back towards the previous vertex.
    pub wo: Vec3,
    pub throughput: Vec3,
    pub length: u32,
    pub(crate) sums: weights::Sums,
}

impl LightVertex {
    /// Its position and what merging reads of it, for [`crate::Grid::build`].
    pub fn merged(&self) -> (Vec3, Merged) {
        let m = Merged {
            wo: self.wo,
            throughput: self.throughput,
            length: self.length,
            sums: self.sums(),
        };
        (self.point.p, m)
    }

    /// Its surface, seen from the light's side.
    pub(crate) fn surface(&self) -> Surface {
        Surface::new(
            self.bsdf,
            self.ns,
            self.point.n,
            self.wo,
            TransportMode::Importance,
        )
    }

    pub(crate) fn sums(&self) -> weights::Sums {
        weights::Sums {
            d_vcm: self.d_vcm,
            d_vc: self.d_vc,
            d_vm: self.d_vm,
            joins: self.joins,
        }
    }
}

/// Traces light subpaths `range` of `pass`: appends their vertices in path order to
/// `vertices`, each path's vertex count to `counts`, and their camera splats to `splats`.
pub fn light_paths(
    scene: &Scene,
    pass: &Pass,
    range: Range<u64>,
    vertices: &mut Vec<LightVertex>,
    counts: &mut Vec<u32>,
    splats: &mut Vec<CameraSplat>,
) {
    let eye = SurfacePoint {
        p: scene.camera.eye,
        p_err: Vec3::ZERO,
        n: scene.camera.forward(),
    };
    for i in range {
        let before = vertices.len();
        trace(scene, pass, &eye, i, vertices, splats);
        counts.push((vertices.len() - before) as u32);
    }
}

fn trace(
    scene: &Scene,
    pass: &Pass,
    eye: &SurfacePoint,
    index: u64,
    vertices: &mut Vec<LightVertex>,
    splats: &mut Vec<CameraSplat>,
) {
    let lights = &scene.light_table;
    // The pass's light subpaths are one scrambled Sobol sequence (2-D strata per pair of
    // dimensions; past 2^32 paths, another one), as the light tracer's are.
    let mut rng = SobolSampler::new(mix64(pass.light_stream ^ (index >> 32)), index as u32);
    // Fixed layout: 5 numbers to emit, then 4 per hit, used or not.
    let (u_light, u_pos, u_dir) = (rng.uniform(), rng.uniform2(), rng.uniform2());
    let e = lights.emit(u_light, u_pos, u_dir, 1);
    let pdfs = lights.emit_pdfs(e.light, e.ray.d);
    let throughput = e.flux.as_vec3();
    if !(pdfs.emit > 0.0 && throughput.is_finite() && throughput.cmpgt(Vec3::ZERO).any()) {
        return;
    }
    let finite = lights.is_finite(e.light);
    let delta = lights.is_delta(e.light);
    // The technical report's Eqs. 31-33 (SmallVCM's `GenerateLightSample`): a light that
    // BSDF sampling can never hit has no `dVC` term.
    let d_vc = if delta {
        0.0
    } else {
        mis(if finite { pdfs.cos } else { 1.0 } / pdfs.emit)
    };
    let mut path = SubPath {
        throughput,
        ..SubPath::start(
            pass,
            mis(pdfs.direct / pdfs.emit),
            d_vc,
            d_vc * pass.vc_factor,
        )
    };
    let mut ray: Ray = e.ray;
    loop {
        let Some(hit) = scene.geometry.intersect(&ray) else {
            return;
        };
        path.throughput *= scene.transmittance_to(&hit, &ray);
        let (uc, u, u_rr) = (rng.uniform(), rng.uniform2(), rng.uniform());
        let Some(bsdf) = scene.bsdf_at(&hit) else {
            return;
        };
        let d = ray.d.normalize();
        let frame = Frame::from_z(hit.ns);
        let wo = -d;
        let wo_l = frame.to_local(wo);
        let dist = hit.t * ray.d.length();
        path.arrive(dist * dist, wo_l.z, path.length > 1 || finite);
        if !bsdf.is_delta() {
            let v = LightVertex {
                point: hit.point,
                ns: hit.ns,
                wo,
                throughput: path.throughput,
                bsdf,
                length: path.length,
                d_vcm: path.d_vcm,
                d_vc: path.d_vc,
                d_vm: path.d_vm,
                joins: path.joins(),
            };
            // A vertex one segment from the light, seen by the camera, is direct light at
            // the first surface seen: NEE and BSDF sampling weigh it alone.
            if pass.opts.strategies.camera
                && path.length > 1
                && path.length < pass.max_len
                && let Some(s) = to_camera(scene, pass, &v, eye)
            {
                splats.push(s);
            }
            vertices.push(v);
        }
        if path.length + 2 > pass.max_len {
            return;
        }
        let surface = Surface {
            bsdf,
            frame,
            ng: hit.point.n,
            wo,
            wo_l,
            mode: TransportMode::Importance,
        };
        let Some((wi, s, rev)) = surface.sample(uc, u) else {
            return;
        };
        let before = path.throughput.max_element();
        path.scatter(&s, rev, pass);
        // Russian roulette on the share of the throughput the bounce keeps, so survivors
        // never carry more than they arrived with (Jensen 2001 §5.3's rule for photons).
        if path.length >= pass.opts.rr_depth {
            let q = (path.throughput.max_element() / before).min(1.0);
            if u_rr >= q || q.is_nan() {
                return;
            }
            path.throughput /= q;
        }
        if !path.throughput.cmpgt(Vec3::ZERO).any() {
            return;
        }
        path.length += 1;
        ray = hit.point.spawn_ray(wi);
    }
}

/// Light vertex `v` joined to the pinhole: its throughput times the BSDF towards the eye and
/// the camera's density of seeing it, weighted against every other strategy (the technical
/// report's Eq. 44; pbrt-v4 §16.3.3's `t = 1`).
fn to_camera(
    scene: &Scene,
    pass: &Pass,
    v: &LightVertex,
    eye: &SurfacePoint,
) -> Option<CameraSplat> {
    let cam = &scene.camera;
    let proj = cam.project(v.point.p)?;
    let e = v.surface().eval(-proj.dir)?;
    // The camera's density of this point per unit area, over all of a pass's pixel samples:
    // `W_e cos_e` per unit solid angle (the importance is per pixel), then to area.
    let dist2 = proj.dist * proj.dist;
    let camera_pdf_a = cam.importance(proj.cos) * proj.cos * e.cos / dist2;
    let weight = weights::camera(pass, v.sums(), camera_pdf_a, e.rev);
    let value = v.throughput.as_dvec3()
        * e.f.as_dvec3()
        * (camera_pdf_a as f64 / pass.light_paths as f64)
        * weight as f64;
    if !(value.is_finite() && value.cmpgt(DVec3::ZERO).any()) {
        return None;
    }
    if scene.geometry.occluded(&v.point.spawn_ray_to_point(eye)) {
        return None;
    }
    Some(CameraSplat {
        pixel: proj.pixel,
        value,
    })
}
