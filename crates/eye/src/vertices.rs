//! Eye vertices: where camera paths first meet a diffuse surface after any number of specular
//! bounces (E S* D), the points at which photon splatting (and SPPM's visible points)
//! estimate radiance. Through glass both reflection and refraction are followed, weighted by
//! Fresnel, for the first few dielectric hits (the course framework's two splits), then one
//! of them is chosen with Fresnel probability (Russian roulette), so 1-spp images through the
//! glass sphere are not speckled.

use bsdf::{Bsdf, TransportMode};
use geom::Ray;
use glam::Vec3;
use math::{Frame, Rng};
use rayon::prelude::*;
use scene::{Scene, sides_agree, surface_id};

/// The first diffuse vertex of one eye path.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EyeVertex {
    /// Pixel index `y * width + x`.
    pub pixel: u32,
    pub p: Vec3,
    /// Unit geometric normal, on the side the eye path arrived from.
    pub ng: Vec3,
    pub surface: u32,
    /// Radiance sent to the pixel per unit irradiance at `p`: the specular chain's throughput
    /// times `albedo / π`, divided by the samples per pixel (a pixel's value is the sum over
    /// its vertices of `weight × E`).
    pub weight: Vec3,
    /// The distance between neighbouring vertices here: the pixel's footprint on the
    /// surface, `distance × pixel angle / |cos θ|`, over `sqrt(spp)`. Splats thinner than
    /// this would fall between vertices.
    pub spacing: f32,
}

/// How eye vertices are made.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct VertexOptions {
    pub spp: u32,
    /// Dielectric hits at which both branches are followed (later ones choose one).
    pub splits: u32,
    /// Worker threads (`None`: rayon's global pool). Never changes the vertices.
    pub threads: Option<usize>,
}

/// The eye vertices of every pixel sample, in pixel order, then sample order, then branch
/// order (reflection before refraction). Pixel sample `s` of pixel `p` draws from
/// `Rng::for_index(seed, p * spp + s)` after two numbers for its jitter, like every eye pass,
/// so the list is the same for any thread count.
pub fn eye_vertices(scene: &Scene, opts: &VertexOptions) -> Vec<EyeVertex> {
    let (w, h) = (scene.camera.width as usize, scene.camera.height as usize);
    let spp = opts.spp.max(1);
    // Angle one pixel subtends at the image centre.
    let pixel_angle = 2.0 * (scene.camera.vfov_deg.to_radians() * 0.5).tan() / h as f32;
    let per_sample = pixel_angle / (spp as f32).sqrt();
    let row = |y: usize| -> Vec<EyeVertex> {
        let mut out = Vec::new();
        for x in 0..w {
            let pixel = (y * w + x) as u64;
            for s in 0..spp as u64 {
                let mut rng = Rng::for_index(scene.seed(), pixel * spp as u64 + s);
                let [jx, jy] = rng.uniform2();
                let ray = scene.camera.ray(x as f32 + jx, y as f32 + jy);
                let start = Branch {
                    ray,
                    beta: Vec3::splat(1.0 / spp as f32),
                    length: 0.0,
                    depth: 0,
                    splits: 0,
                };
                follow(
                    scene,
                    opts,
                    start,
                    pixel as u32,
                    per_sample,
                    &mut rng,
                    &mut out,
                );
            }
        }
        out
    };
    let work = || -> Vec<EyeVertex> { (0..h).into_par_iter().flat_map_iter(row).collect() };
    match opts.threads {
        Some(n) => match rayon::ThreadPoolBuilder::new().num_threads(n).build() {
            Ok(pool) => pool.install(work),
            Err(_) => work(),
        },
        None => work(),
    }
}

struct Branch {
    ray: Ray,
    beta: Vec3,
    /// Path length from the camera so far.
    length: f32,
    depth: u32,
    splits: u32,
}

/// Follows one eye path through specular surfaces, depth first, pushing the diffuse vertices
/// it reaches.
fn follow(
    scene: &Scene,
    opts: &VertexOptions,
    start: Branch,
    pixel: u32,
    per_sample: f32,
    rng: &mut Rng,
    out: &mut Vec<EyeVertex>,
) {
    let max_depth = scene.render().max_depth;
    let mut stack = vec![start];
    while let Some(b) = stack.pop() {
        if b.depth > max_depth || b.beta == Vec3::ZERO || !b.beta.is_finite() {
            continue;
        }
        let Some(hit) = scene.geometry.intersect(&b.ray) else {
            continue;
        };
        // Black surfaces absorb.
        let Some(bsdf) = scene.bsdf(hit.material) else {
            continue;
        };
        let d = b.ray.d.normalize();
        let wo = -d;
        let ng = hit.point.n;
        let length = b.length + hit.t * b.ray.d.length();
        if let Bsdf::Lambertian(l) = bsdf {
            let cos = wo.dot(ng).abs().max(0.1);
            out.push(EyeVertex {
                pixel,
                p: hit.point.p,
                ng: if wo.dot(ng) >= 0.0 { ng } else { -ng },
                surface: surface_id(hit.prim),
                weight: b.beta * l.albedo / std::f32::consts::PI,
                spacing: length * per_sample / cos,
            });
            continue;
        }
        let frame = Frame::from_z(hit.ns);
        let wo_l = frame.to_local(wo);
        let split = matches!(bsdf, Bsdf::Dielectric(_)) && b.splits < opts.splits;
        // Both Fresnel branches (weights R and T / eta^2), or one chosen by `uc`.
        let (uc, u) = (rng.uniform(), rng.uniform2());
        let samples = if split {
            let r = bsdf.sample(wo_l, 0.0, u, TransportMode::Radiance);
            let t = bsdf.sample(wo_l, 1.0, u, TransportMode::Radiance);
            // Pushed refraction first so reflection is followed first (the stack is LIFO).
            [
                t.filter(|t| t.is_transmission())
                    .map(|t| (t, t.f * t.wi.z.abs())),
                r.filter(|r| r.is_reflection())
                    .map(|r| (r, r.f * r.wi.z.abs())),
            ]
        } else {
            [
                bsdf.sample(wo_l, uc, u, TransportMode::Radiance)
                    .map(|s| (s, s.weight())),
                None,
            ]
        };
        for (s, weight) in samples.into_iter().flatten() {
            let wi = frame.to_world(s.wi);
            if !sides_agree(wo, wi, ng, wo_l, s.wi) {
                continue;
            }
            stack.push(Branch {
                ray: hit.point.spawn_ray(wi),
                beta: b.beta * weight,
                length,
                depth: b.depth + 1,
                splits: b.splits + split as u32,
            });
        }
    }
}
