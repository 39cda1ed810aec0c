//! Eye subpaths: one per pixel and pass, gathering from every strategy at each vertex.

use crate::light::{LightVertex, Merged};
use crate::surface::Surface;
use crate::{Grid, Pass, SubPath, mis, weights};
use bsdf::TransportMode;
use geom::Hit;
use glam::{DVec3, Vec3};
use math::{Frame, Sampler, SobolSampler, mix64};
use scene::Scene;
use std::ops::Range;

/// Russian roulette never keeps a path with a higher probability than this (the path
/// tracer's bound), so paths between lossless mirrors still end.
const MAX_SURVIVAL: f32 = 0.95;

/// The light side of a pass, read by every eye path: the vertices in path order, where each
/// path's vertices start (`starts[i]..starts[i + 1]`), and the grid over them.
pub struct LightSide<'a> {
    pub vertices: &'a [LightVertex],
    pub starts: &'a [u32],
    pub grid: Option<&'a Grid<Merged>>,
}

/// The eye paths of pixels `range` of `pass`: each pixel's estimate (one path), in order.
pub fn eye_paths(scene: &Scene, pass: &Pass, light: &LightSide, range: Range<u64>) -> Vec<DVec3> {
    range.map(|i| pixel(scene, pass, light, i)).collect()
}

/// An eye vertex: the hit (for shadow rays) and its surface.
struct Vertex<'a> {
    hit: &'a Hit,
    surface: Surface,
}

fn pixel(scene: &Scene, pass: &Pass, light: &LightSide, index: u64) -> DVec3 {
    let cam = &scene.camera;
    let w = cam.width as u64;
    // Pass `j` is sample `j` of the pixel's own scrambled Sobol sequence, as in the path
    // tracer (pbrt-v4 §8.7.5's padded Sobol sampler).
    let mut rng = SobolSampler::new(mix64(pass.eye_seed ^ mix64(index)), pass.index as u32);
    let [jx, jy] = rng.uniform2();
    let mut ray = cam.ray((index % w) as f32 + jx, (index / w) as f32 + jy);
    let cos = ray.d.normalize().dot(cam.forward());
    // The camera's density per unit solid angle over a pass's pixel samples (`W_e cos`).
    let camera_pdf_w = cam.importance(cos) * cos;
    let mut path = SubPath::start(pass, mis(pass.light_paths as f32 / camera_pdf_w), 0.0, 0.0);
    let lights = &scene.light_table;
    let on = pass.opts.strategies;
    let mut sum = DVec3::ZERO;
    let mut eta_scale = 1.0f32;
    let range = |i: u64| {
        let s = light.starts.get(i as usize).copied().unwrap_or(0) as usize;
        let e = light.starts.get(i as usize + 1).copied().unwrap_or(0) as usize;
        light.vertices.get(s..e).unwrap_or(&[])
    };
    // Fewer light paths than pixels: pixel `i` joins light path `i mod N`, so every eye path
    // still has one independent light subpath to connect to, as the weights assume.
    let own = range(index % pass.light_paths.max(1));
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
            surface: Surface {
                bsdf,
                frame,
                ng: hit.point.n,
                wo,
                wo_l,
                mode: TransportMode::Radiance,
            },
        };
        if !bsdf.is_delta() {
            let beta = path.throughput.as_dvec3();
            if on.nee {
                sum += beta * nee(scene, pass, &path, &v, u_pick, u_light).as_dvec3();
            }
            if on.connect && pass.opts.bidirectional {
                for lv in own {
                    if lv.length + 1 + path.length > pass.max_len {
                        break;
                    }
                    sum += beta * connect(scene, pass, &path, &v, lv);
                }
            }
            if let (true, Some(grid)) = (on.merge, light.grid) {
                sum += beta * merge(pass, &path, &v, grid);
            }
        }
        let Some((wi, s, rev)) = v.surface.sample(u_lobe, u_dir) else {
            break;
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
    let Some(e) = v.surface.eval(ls.wi) else {
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
    let bsdf_pdf = if ls.delta { 0.0 } else { e.dir };
    let w = weights::nee(
        pass,
        path.sums(),
        bsdf_pdf,
        e.rev,
        e.cos,
        direct_w,
        p.emit,
        p.cos,
        path.diffuse == 0,
    );
    let c = e.f * ls.le * (e.cos * w / ls.pdf);
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
    let Some(eye) = v.surface.eval(d) else {
        return DVec3::ZERO;
    };
    let Some(light) = lv.surface().eval(-d) else {
        return DVec3::ZERO;
    };
    // Each side's density of sampling the other's vertex, per unit area there.
    let eye_dir_a = eye.dir * light.cos / dist2;
    let light_dir_a = light.dir * eye.cos / dist2;
    let w = weights::connect(
        pass,
        path.sums(),
        eye_dir_a,
        eye.rev,
        lv.sums(),
        light_dir_a,
        light.rev,
    );
    let g = eye.cos * light.cos / dist2;
    let c = (eye.f * light.f * lv.throughput).as_dvec3() * (g * w) as f64;
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
fn merge(pass: &Pass, path: &SubPath, v: &Vertex, grid: &Grid<Merged>) -> DVec3 {
    let mut sum = DVec3::ZERO;
    let eye = path.sums();
    grid.query(v.hit.point.p, |lv| {
        // A light vertex one segment from the light is direct light, which NEE and BSDF
        // sampling alone weigh at the first non-delta eye vertex.
        let direct = lv.length == 1 && path.diffuse == 0;
        if direct || lv.length + path.length > pass.max_len {
            return;
        }
        let Some(e) = v.surface.eval(lv.wo) else {
            return;
        };
        let w = weights::merge(pass, eye, e.dir, e.rev, lv.sums);
        let c = (e.f * lv.throughput).as_dvec3() * w as f64;
        if c.is_finite() {
            sum += c;
        }
    });
    sum * pass.vm_norm as f64
}
