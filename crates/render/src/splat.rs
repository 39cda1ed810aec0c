//! Photon differential splatting onto eye vertices (Frisvad et al. 2014), the stage on the
//! channel pipeline: a pass's eye vertices (E S* D) are indexed once; caustic photons with
//! differentials (L S+ D, `emit`) are traced in chunks on the pipeline's workers, and each
//! photon adds to every eye vertex inside its footprint `Φ_p K(|M (y - x_p)|) |det M|`,
//! accepting only vertices on the same surface and side (the accumulation is
//! `density::splat`'s). With `indirect` on, each caustic path goes on past
//! its first diffuse hit and adds at every later diffuse hit (L S+ D (S* D)+) by a disc of
//! `indirect_radius` instead: after a diffuse bounce the photons no longer focus, and their
//! density is as smooth as a global photon map's, so the caustics seen through a diffuse
//! bounce (the path tracer's fireflies) come from photons landing where the eye looks,
//! not from eye paths that must find a small bright focus (the idea of Jensen's caustic and
//! global maps, 1996, kept free of any map).
//! No photon is stored in a map or a file: a chunk's photons live
//! only while its worker splats them, and what crosses the channel to the ordering stage is
//! the chunk's pixel contributions, added in chunk order (so the image is the same for any
//! thread count).

use crate::settings::SplatSettings;
use density::splat::{Receiver, Receivers, Scratch, SplatParams, SplatPhoton, splat};
use emit::{CausticPhoton, EmitParams};
use eye::{EyeVertex, VertexOptions};
use flow::{PipelineOptions, Stats};
use glam::{DVec3, Vec3};
use scene::Scene;

/// Eye vertices as the receivers splatting reads (`density::splat`), indexed: the levels by
/// spacing of `density::splat::Receivers` keep a splat at least as wide as the spacing of the
/// vertices that read it, per sampling density (see there).
pub fn receivers(vertices: Vec<EyeVertex>) -> Receivers {
    Receivers::new(
        vertices
            .into_iter()
            .map(|v| Receiver {
                pixel: v.pixel,
                p: v.p,
                ng: v.ng,
                weight: v.weight,
                spacing: v.spacing,
            })
            .collect(),
    )
}

/// A caustic photon as splatting reads it.
pub fn splat_photon(p: &CausticPhoton) -> SplatPhoton {
    SplatPhoton {
        position: p.position,
        normal: p.normal,
        flux: p.flux,
        a: p.a,
        b: p.b,
    }
}

/// The first eye vertices of pass `pass` (`spp` pixel samples each), indexed.
pub fn eye_index(
    scene: &Scene,
    s: &SplatSettings,
    spp: u32,
    pass: u64,
    threads: Option<usize>,
) -> Receivers {
    receivers(eye::eye_vertices(
        scene,
        &VertexOptions {
            spp,
            splits: s.splits,
            threads,
            pass,
        },
    ))
}

/// The radius of the disc by which photons after a diffuse bounce reach eye vertices: the
/// setting, or the largest footprint semi-axis.
pub fn indirect_radius(scene: &Scene, s: &SplatSettings) -> f32 {
    if s.indirect_radius > 0.0 {
        s.indirect_radius
    } else {
        max_radius(scene, s)
    }
}

/// The largest footprint semi-axis: the setting, or 2% of the scene's bounding diagonal.
pub fn max_radius(scene: &Scene, s: &SplatSettings) -> f32 {
    if s.max_radius > 0.0 {
        return s.max_radius;
    }
    let b = scene.geometry.bounds();
    let diag = (b.max - b.min).length();
    if diag.is_finite() && diag > 0.0 {
        0.02 * diag
    } else {
        1.0
    }
}

/// The factor on pass `pass`'s footprint axes (0-based): the square root of Knaus and
/// Zwicker's (2011) `r_{j+1}^2 = r_j^2 (j + alpha) / (j + 1)`. Its square falls about as
/// `j^(alpha - 1)`, so a pass's bias shrinks while the mean of `J` passes keeps a variance
/// falling about as `J^(-alpha)`; both go to zero. Computed in f64 from pass 1 on, so the
/// factor of a pass depends on its number alone (shards, budgets).
pub fn shrink(alpha: f32, pass: u64) -> f32 {
    let a = alpha as f64;
    let mut r2 = 1.0f64;
    for i in 1..=pass {
        r2 *= (i as f64 + a) / (i as f64 + 1.0);
    }
    r2.sqrt() as f32
}

/// What a splatting pass needs: the scene, its caustic paths' parameters (`params.photons`
/// per pass, `params.max_depth`), the splat settings and the indexed eye vertices.
pub struct Splatter<'a> {
    pub scene: &'a Scene,
    pub params: &'a EmitParams,
    pub settings: &'a SplatSettings,
    pub eyes: &'a Receivers,
}

/// One chunk's photon count and its `(pixel, radiance)` pairs: `[0]` from photons at their
/// first diffuse hit, `[1]` from photons after further diffuse bounces.
type Chunk = (u64, [Vec<(u32, DVec3)>; 2]);

impl Splatter<'_> {
    /// One pass of the caustic layers: the caustic paths of pass `pass` splatted onto the eye
    /// vertices and added to `images` (one f64 RGB sum per pixel; `[0]` the `caustic` layer,
    /// `[1]` `caustic_indirect`, left alone unless the settings' `indirect` is on) in chunk
    /// order.
    pub fn pass(
        &self,
        pass: u64,
        images: &mut [Vec<DVec3>; 2],
        threads: usize,
        progress: &(dyn Fn(u64) + Sync),
    ) -> Result<Stats, String> {
        let (scene, params, s, eyes) = (self.scene, self.params, self.settings, self.eyes);
        if s.indirect && images[1].len() != images[0].len() {
            return Err("splatting caustic_indirect needs an image for it".into());
        }
        let shrink = shrink(s.alpha, pass);
        let max_r = max_radius(scene, s) * shrink;
        let indirect_r = indirect_radius(scene, s) * shrink;
        let isotropic_r = s.isotropic_radius * shrink;
        let scale = s.scale * shrink;
        let work = |range: std::ops::Range<u64>| -> Chunk {
            let n = range.end - range.start;
            let photons = emit::trace_caustics(scene, params, scale, pass, range, s.indirect);
            let (first, bounced): (Vec<CausticPhoton>, Vec<CausticPhoton>) =
                photons.into_iter().partition(|p| p.diffuse == 1);
            let mut out = [Vec::new(), Vec::new()];
            let mut scratch = Scratch::default();
            let first_params = SplatParams::new(max_r, isotropic_r);
            let bounced_params = SplatParams::new(indirect_r, indirect_r);
            let (first, bounced) = (first.iter(), bounced.iter());
            splat(
                eyes,
                first.map(splat_photon),
                &first_params,
                &mut scratch,
                &mut out[0],
            );
            splat(
                eyes,
                bounced.map(splat_photon),
                &bounced_params,
                &mut scratch,
                &mut out[1],
            );
            (n, out)
        };
        flow::run_chunks(
            params.photons,
            &PipelineOptions::new(threads),
            &work,
            &mut |(n, contributions): Chunk| {
                for (image, contributions) in images.iter_mut().zip(contributions) {
                    for (pixel, v) in contributions {
                        if v.is_finite() {
                            image[pixel as usize] += v;
                        }
                    }
                }
                progress(n);
                Ok(())
            },
        )
    }
}

/// Pixels of an f64 sum as an f32 image.
pub fn to_image(scene: &Scene, pixels: &[DVec3]) -> film::Image {
    let w = scene.camera.width as usize;
    film::Image::from_fn(w, scene.camera.height as usize, |x, y| {
        let v: Vec3 = pixels[y * w + x].as_vec3();
        v.to_array()
    })
}
