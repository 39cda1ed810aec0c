//! Eye subpaths: one per pixel and pass, gathering from every strategy at each vertex.

use crate::light::LightVertex;
use crate::{Grid, Pass, SubPath, mis, weights};
use bsdf::{Bsdf, TransportMode};
use geom::Hit;
use glam::{DVec3, Vec3};
use math::{Frame, Rng};
use scene::{Scene, sides_agree};
use std::ops::Range;

/// Russian roulette never keeps a path with a higher probability than this (the path
/// tracer's bound), so paths between lossless mirrors still end.
const MAX_SURVIVAL: f32 = 0.95;

/// The light side of a pass, read by every eye path: the vertices in path order, where each
/// path's vertices start (`starts[i]..starts[i + 1]`), and the grid over them.
pub struct LightSide<'a> {
    pub vertices: &'a [LightVertex],
    pub starts: &'a [u32],
    pub grid: Option<&'a Grid>,
}

/// The eye paths of pixels `range` of `pass`: each pixel's estimate (one path), in order.
pub fn eye_paths(scene: &Scene, pass: &Pass, light: &LightSide, range: Range<u64>) -> Vec<DVec3> {
    range.map(|i| pixel(scene, pass, light, i)).collect()
}

/// What an eye vertex needs to weigh a strategy: the point, its frame and BSDF, the
/// direction the path came by.
struct Vertex<'a> {
    hit: &'a Hit,
    bsdf: Bsdf,
    frame: Frame,
    wo: Vec3,
    wo_l: Vec3,
}

impl Vertex<'_> {
    /// The BSDF towards unit `wi` with its forward density and the reverse one (of sampling
    /// `wo` given `wi`), and `|cos|` at `wi`; `None` where no light passes.
    fn eval(&self, wi: Vec3) -> Option<(Vec3, f32, f32, f32)> {
        let wi_l = self.frame.to_local(wi);
        if !sides_agree(self.wo, wi, self.hit.point.n, self.wo_l, wi_l) {
            return None;
        }
        let f = self.bsdf.f(self.wo_l, wi_l, TransportMode::Radiance);
        if f == Vec3::ZERO {
            return None;
        }
        Some((
            f,
            self.bsdf.pdf(self.wo_l, wi_l),
            self.bsdf.pdf(wi_l, self.wo_l),
            wi_l.z.abs(),
        ))
    }
}

fn pixel(scene: &Scene, pass: &Pass, light: &LightSide, index: u64) -> DVec3 {
    let cam = &scene.camera;
    let w = cam.width as u64;
    let mut rng = Rng::for_index(pass.eye_stream, index);
    let [jx, jy] = rng.uniform2();
    let mut ray = cam.ray((index % w) as f32 + jx, (index / w) as f32 + jy);
    let cos = ray.d.normalize().dot(cam.forward());
    // The camera's density per unit solid angle over a pass's pixel samples (`W_e cos`).
    let camera_pdf_w = cam.importance(cos) * cos;
    let mut path = SubPath::start(mis(pass.light_paths as f32 / camera_pdf_w), 0.0, 0.0);
    let lights = &scene.light_table;
    let on = pass.opts.strategies;
    let mut sum = DVec3::ZERO;
    let mut eta_scale = 1.0f32;
    let range = |i: u64| {
        let s = light.starts.get(i as usize).copied().unwrap_or(0) as usize;
        let e = light.starts.get(i as usize + 1).copied().unwrap_or(0) as usize;
        light.vertices.get(s..e).unwrap_or(&[])
    };
    let own = range(index);
    loop {
        let Some(hit) = scene.geometry.intersect(&ray) else {
            if on.hits {
                sum += escaped(scene, &path, ray.d.normalize());
            }
            break;
        };
        path.throughput *= scene.transmittance_to(&hit, &ray);
        let d = ray.d.normalize();
        let frame = Frame::from_z(hit.ns);
        let wo = -d;
        let wo_l = frame.to_local(wo);
        let dist = hit.t * ray.d.length();
        path.arrive(dist * dist, wo_l.z, true);
        if on.hits
            && let Some(l) = lights.light_of(hit.prim)
            && let le = lights.le(l, d)
            && le != Vec3::ZERO
        {
            // Emission seen directly has no other strategy (none joins a light's own
            // point to the camera).
            let w = if path.length == 1 {
                1.0
            } else {
                let p = lights.emit_pdfs(l, wo);
                weights::hit(path.sums(), p.direct, p.emit, path.direct())
            };
            sum += (path.throughput * le * w).as_dvec3();
        }
        if path.length >= pass.max_len {
            break;
        }
        let u_pick = rng.uniform();
        let u_light = rng.uniform2();
        let u_lobe = rng.uniform();
        let u_dir = rng.uniform2();
        let u_rr = rng.uniform();
        let Some(bsdf) = scene.bsdf_at(&hit) else {
            break;
        };
        let v = Vertex {
            hit: &hit,
            bsdf,
            frame,
            wo,
            wo_l,
        };
        if !bsdf.is_delta() {
            let beta = path.throughput.as_dvec3();
            if on.nee {
                sum += beta * nee(scene, pass, &path, &v, u_pick, u_light).as_dvec3();
            }
            if on.connect {
                for lv in own {
                    if lv.length + 1 + path.length > pass.max_len {
                        break;
                    }
                    sum += beta * connect(scene, pass, &path, &v, lv);
                }
            }
            if let (true, Some(grid)) = (on.merge, light.grid) {
                sum += beta * merge(pass, &path, &v, light.vertices, grid);
            }
        }
        if wo_l.z * wo.dot(hit.point.n) <= 0.0 {
            break;
        }
        let Some(s) = bsdf.sample(wo_l, u_lobe, u_dir, TransportMode::Radiance) else {
            break;
        };
        let wi = frame.to_world(s.wi).normalize();
        if !sides_agree(wo, wi, hit.point.n, wo_l, s.wi) {
            break;
        }
        let rev = if s.is_specular() {
            s.pdf
        } else {
            bsdf.pdf(s.wi, wo_l)
        };
        path.scatter(&s, rev, pass);
        if s.is_transmission() {
            eta_scale *= s.eta * s.eta;
        }
        // Russian roulette as the path tracer plays it (on the throughput outside glass,
        // pbrt-v4 §14.1.4's `etaScale`).
        if path.length >= pass.opts.rr_depth {
            let q = (path.throughput * eta_scale)
                .max_element()
                .min(MAX_SURVIVAL);
            if u_rr >= q || q.is_nan() {
                break;
            }
            path.throughput /= q;
        }
        if !path.throughput.cmpgt(Vec3::ZERO).any() {
            break;
        }
        path.length += 1;
        ray = hit.point.spawn_ray(wi);
    }
    sum
}

/// Emission of the lights at infinity seen along unit `d` by a path that left the scene,
/// each weighted against the strategies that could have made it (Eq. 46 of the report, per
/// light).
fn escaped(scene: &Scene, path: &SubPath, d: Vec3) -> DVec3 {
    let lights = &scene.light_table;
    let mut sum = DVec3::ZERO;
    for (i, l) in lights.lights().enumerate() {
        if !l.is_infinite() {
            continue;
        }
        let le = l.le(d);
        if le == Vec3::ZERO {
            continue;
        }
        let w = if path.length == 1 {
            1.0
        } else {
            let p = lights.emit_pdfs(i, -d);
            weights::hit(path.sums(), p.direct, p.emit, path.direct())
        };
        sum += (path.throughput * le * w).as_dvec3();
    }
    sum
}

/// Next-event estimation, weighted against BSDF sampling and every strategy that reaches
/// the light from its side (Eq. 44 of the report; SmallVCM's `DirectIllumination`).
fn nee(scene: &Scene, pass: &Pass, path: &SubPath, v: &Vertex, u_pick: f32, u: [f32; 2]) -> Vec3 {
    let lights = &scene.light_table;
    let Some(ls) = lights.sample(v.hit.point.p, u_pick, u) else {
        return Vec3::ZERO;
    };
    let Some((f, dir_pdf, rev_pdf, cos)) = v.eval(ls.wi) else {
        return Vec3::ZERO;
    };
    let p = lights.emit_pdfs(ls.light, -ls.wi);
    if p.cos <= 0.0 {
        return Vec3::ZERO;
    }
    // NEE's density per unit solid angle at the receiver, choice included.
    let direct_w = if lights.is_finite(ls.light) {
        p.direct * ls.dist * ls.dist / p.cos
    } else {
        p.direct
    };
    let bsdf_pdf = if ls.delta { 0.0 } else { dir_pdf };
    let w = weights::nee(
        pass,
        path.sums(),
        bsdf_pdf,
        rev_pdf,
        cos,
        direct_w,
        p.emit,
        p.cos,
        path.diffuse == 0,
    );
    let c = f * ls.le * (cos * w / ls.pdf);
    if !(c.is_finite() && c.cmpgt(Vec3::ZERO).any()) {
        return Vec3::ZERO;
    }
    if scene
        .geometry
        .occluded(&v.hit.point.spawn_ray_to_point(&ls.point))
    {
        return Vec3::ZERO;
    }
    c
}

/// The eye vertex joined to light vertex `lv` by a shadow ray (Eq. 45 of the report).
fn connect(scene: &Scene, pass: &Pass, path: &SubPath, v: &Vertex, lv: &LightVertex) -> DVec3 {
    let to = lv.point.p - v.hit.point.p;
    let dist2 = to.length_squared();
    if !(dist2 > 0.0 && dist2.is_finite()) {
        return DVec3::ZERO;
    }
    let d = to / dist2.sqrt();
    let Some((f_eye, eye_dir, eye_rev, cos_eye)) = v.eval(d) else {
        return DVec3::ZERO;
    };
    let frame = Frame::from_z(lv.ns);
    let (wo_l, wi_l) = (frame.to_local(lv.wo), frame.to_local(-d));
    if !sides_agree(lv.wo, -d, lv.point.n, wo_l, wi_l) {
        return DVec3::ZERO;
    }
    let f_light = lv.bsdf.f(wo_l, wi_l, TransportMode::Importance);
    if f_light == Vec3::ZERO {
        return DVec3::ZERO;
    }
    let cos_light = wi_l.z.abs();
    let light_dir = lv.bsdf.pdf(wo_l, wi_l);
    let light_rev = lv.bsdf.pdf(wi_l, wo_l);
    // Each side's density of sampling the other's vertex, per unit area there.
    let eye_dir_a = eye_dir * cos_light / dist2;
    let light_dir_a = light_dir * cos_eye / dist2;
    let w = weights::connect(
        pass,
        path.sums(),
        eye_dir_a,
        eye_rev,
        lv.sums(),
        light_dir_a,
        light_rev,
    );
    let g = cos_eye * cos_light / dist2;
    let c = (f_eye * f_light * lv.throughput).as_dvec3() * (g * w) as f64;
    if !(c.is_finite() && c.cmpgt(DVec3::ZERO).any()) {
        return DVec3::ZERO;
    }
    if scene
        .geometry
        .occluded(&v.hit.point.spawn_ray_to_point(&lv.point))
    {
        return DVec3::ZERO;
    }
    c
}

/// The light vertices within the radius merged at the eye vertex with the uniform kernel
/// (Eq. 47 of the report): photon mapping's density estimate as one more strategy.
fn merge(pass: &Pass, path: &SubPath, v: &Vertex, vertices: &[LightVertex], grid: &Grid) -> DVec3 {
    let p = v.hit.point.p;
    let mut sum = DVec3::ZERO;
    grid.query(p, |i| {
        let Some(lv) = vertices.get(i) else {
            return;
        };
        // A light vertex one segment from the light is direct light, which NEE and BSDF
        // sampling alone weigh at the first non-delta eye vertex.
        let direct = lv.length == 1 && path.diffuse == 0;
        if direct || lv.length + path.length > pass.max_len || !grid.within(p, lv.point.p) {
            return;
        }
        let Some((f, dir, rev, _)) = v.eval(lv.wo) else {
            return;
        };
        let w = weights::merge(pass, path.sums(), dir, rev, lv.sums());
        let c = (f * lv.throughput).as_dvec3() * w as f64;
        if c.is_finite() {
            sum += c;
        }
    });
    sum * pass.vm_norm as f64
}
