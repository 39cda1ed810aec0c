//! Visible points for progressive photon mapping (Hachisuka and Jensen 2009, "Stochastic
//! progressive photon mapping"; pbrt-v4 §16.2): each pass, one camera sample per pixel is
//! followed through specular surfaces to its first diffuse vertices (E S* D), where photons
//! will be gathered. At the first `splits` glass hits of its walk both Fresnel branches are
//! followed (weights R and T), so a pixel seeing glass has a visible point on each side every
//! pass instead of one branch chosen at random: the glass is smooth after one pass. Emission met on the way and direct light
//! by next-event estimation at the vertex are added here, so the photons need carry only
//! light that has bounced at least once.

use crate::photon::direct_at;
use crate::vertices::first_diffuse;
use glam::Vec3;
use math::Rng;
use rayon::prelude::*;
use scene::Scene;

/// Where one pixel's camera sample of a pass first met a diffuse surface.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct VisiblePoint {
    pub p: Vec3,
    /// Unit shading normal on the side the eye path arrived from.
    pub n: Vec3,
    /// Radiance sent to the pixel per unit irradiance at `p`: the specular chain's throughput
    /// times `albedo / π`.
    pub weight: Vec3,
    /// The Fresnel branches that led here (a heap index, 1 without a split): the same on
    /// every pass for the same chain of choices, so statistics can be kept per branch.
    pub branch: u32,
}

/// One pixel's camera sample of a pass.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PixelSample {
    /// Emission seen through specular chains, plus (when asked for) direct light at the
    /// visible point by next-event estimation.
    pub light: Vec3,
    /// In the order the walk found them (reflection before refraction).
    pub points: Vec<VisiblePoint>,
}

/// One sample per pixel, in pixel order. Pixel `p` draws from
/// `Rng::for_index(pass_seed(seed, pass), p)`: two numbers of jitter, three per hit of the
/// walk, three for next-event estimation, so the samples are the same for any thread count.
/// `direct`: add next-event estimation at the visible point (else photons must bring direct
/// light too). `splits`: the glass hits at which both branches are followed (0: one branch
/// chosen by Fresnel probability); next-event estimation draws three numbers per point, in
/// the order found.
pub fn visible_points(
    scene: &Scene,
    pass: u64,
    direct: bool,
    splits: u32,
    threads: Option<usize>,
) -> Vec<PixelSample> {
    let (w, h) = (scene.camera.width as usize, scene.camera.height as usize);
    let seed = crate::vertices::pass_seed(scene.seed(), pass);
    let row = |y: usize| -> Vec<PixelSample> {
        (0..w)
            .map(|x| {
                let pixel = (y * w + x) as u64;
                let mut rng = Rng::for_index(seed, pixel);
                let [jx, jy] = rng.uniform2();
                let ray = scene.camera.ray(x as f32 + jx, y as f32 + jy);
                let mut found = Vec::new();
                let emitted =
                    first_diffuse(scene, ray, splits, &mut rng, true, &mut |f| found.push(f));
                let mut out = PixelSample {
                    light: emitted,
                    points: Vec::with_capacity(found.len()),
                };
                for v in found {
                    let weight = v.beta * v.albedo / std::f32::consts::PI;
                    if direct {
                        out.light += direct_at(scene, &v, &mut rng) * weight;
                    }
                    out.points.push(VisiblePoint {
                        p: v.hit.point.p,
                        n: v.n,
                        weight,
                        branch: v.branch,
                    });
                }
                out
            })
            .collect()
    };
    let work = || -> Vec<PixelSample> { (0..h).into_par_iter().flat_map_iter(row).collect() };
    crate::render::on_threads(threads, work)
}
