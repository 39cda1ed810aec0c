//! Caustic photons with differentials (Schjøth et al. 2007, "Photon differentials"; Frisvad
//! et al. 2014, "Photon differential splatting for rendering caustics"): each path starts
//! from [`emit_diff`] at an area light and carries its differentials (Igehy 1999) through
//! mirror, metal and glass to its first diffuse hit after at least one specular bounce
//! (L S+ D), where the transferred positional derivatives are the two axes of the photon's
//! footprint. Paths whose first hit is diffuse (direct light) carry no caustic and end there.
//! On request a caustic path goes on past its first diffuse hit, by cosine sampling and the
//! photon tracer's Russian roulette, and is a caustic photon again at every later diffuse hit
//! (L S+ D (S* D)+: caustics that light other surfaces), without differentials.
//!
//! Photon `i` draws the same random numbers as [`crate::trace_range`]'s photon `i` (5 to
//! emit, 3 per hit), so a splatted caustic photon and the caustic map's photon of the same
//! index follow the same path and carry the same flux.

use crate::diff::{emit_diff, mesh_dn, reflect_diff, refract_diff, sphere_dn, transfer};
use crate::{EMIT_STREAM, EmitParams};
use bsdf::{Bsdf, DiffuseLobe, Lambertian};
use geom::{Hit, Prim};
use glam::Vec3;
use math::Rng;
use scene::{Scene, surface_id};
use std::ops::Range;

/// A caustic photon at its first diffuse hit, with its footprint.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CausticPhoton {
    pub position: Vec3,
    /// Unit geometric normal of the surface, on the side the photon arrived from.
    pub normal: Vec3,
    /// [`scene::surface_id`] of the primitive hit.
    pub surface: u32,
    /// Flux, already divided by the number of paths emitted.
    pub flux: Vec3,
    /// Footprint semi-axes in the tangent plane: the positional derivatives after the last
    /// transfer (`∂x/∂u`, `∂x/∂v`, scaled by the smoothing parameter at emission).
    pub a: Vec3,
    pub b: Vec3,
    /// Index of the path in its pass: a random number of its own for choices made later
    /// (`math::mix64` of it), whatever the chunking.
    pub path: u64,
    /// Diffuse hits of the path so far, this one included: 1 at the first (L S+ D), where
    /// the footprint is `a`, `b`; more after further diffuse bounces (L S+ D (S* D)+), where
    /// `a` and `b` are zero.
    pub diffuse: u32,
}

/// The caustic photons of paths `range` (indices into `0..params.photons`) of pass `pass`,
/// in index order (each path's hits in order); `indirect` follows each path on past its
/// first diffuse hit (cosine sampling and the photon tracer's Russian roulette), adding a
/// photon at every later diffuse hit. `scale` is the smoothing parameter `s` of [`emit_diff`]. Photon `i` of
/// pass `j` draws from the stream `(seed, j, i)` alone ([`pass_stream`]), so the result is a
/// pure function of the scene's seed, the pass and the indices, like [`crate::trace_range`].
pub fn trace_caustics(
    scene: &Scene,
    params: &EmitParams,
    scale: f32,
    pass: u64,
    range: Range<u64>,
    indirect: bool,
) -> Vec<CausticPhoton> {
    let mut out = Vec::new();
    if params.max_depth == 0 {
        return out;
    }
    let stream = pass_stream(scene.seed(), pass);
    for i in range {
        trace_one(scene, params, scale, stream, i, indirect, &mut out);
    }
    out
}

/// The seed of pass `pass`'s photon streams: pass 0 is the photon tracer's own
/// (`seed ^ EMIT_STREAM`, so its photons are the caustic map's), later passes are mixed
/// apart by a splitmix64 step (Steele et al. 2014) of the pass number.
pub fn pass_stream(seed: u64, pass: u64) -> u64 {
    let base = seed ^ EMIT_STREAM;
    if pass == 0 {
        return base;
    }
    let mut z = pass.wrapping_mul(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    base ^ z ^ (z >> 31)
}

/// Derivatives of the shading normal at `hit` for the positional derivatives `dx`, `dy`
/// (already transferred to the surface): the curvature that focuses a caustic.
fn normal_derivatives(scene: &Scene, hit: &Hit, dx: Vec3, dy: Vec3) -> (Vec3, Vec3) {
    match hit.prim {
        Prim::Sphere(s) => {
            let r = scene.geometry.spheres()[s as usize].radius;
            (sphere_dn(dx, r), sphere_dn(dy, r))
        }
        Prim::Triangle(t) => {
            let mesh = scene.geometry.mesh();
            if mesh.normals.is_empty() {
                return (Vec3::ZERO, Vec3::ZERO); // flat facets: no curvature
            }
            let idx = mesh.indices[t as usize];
            let ns = idx.map(|i| mesh.normals[i as usize]);
            let p = mesh.vertices(t as usize);
            let [b1, b2] = hit.uv;
            let b = [1.0 - b1 - b2, b1, b2];
            (mesh_dn(dx, p, ns, b), mesh_dn(dy, p, ns, b))
        }
    }
}

fn trace_one(
    scene: &Scene,
    params: &EmitParams,
    scale: f32,
    stream: u64,
    index: u64,
    indirect: bool,
    out: &mut Vec<CausticPhoton>,
) {
    let mut rng = Rng::for_index(stream, index);
    // The layout of `trace_range`: 5 numbers to emit, then 3 per hit, used or not.
    let (u_light, u_pos, u_dir) = (rng.uniform(), rng.uniform2(), rng.uniform2());
    let (e, mut rd) = emit_diff(
        &scene.light_table,
        u_light,
        u_pos,
        u_dir,
        params.photons,
        scale,
    );
    let mut flux = e.flux.as_vec3();
    let mut ray = e.ray;
    let mut specular_bounces = 0u32;
    let mut diffuse = 0u32;
    for _ in 0..params.max_depth {
        if !flux.cmpgt(Vec3::ZERO).any() {
            return;
        }
        let Some(hit) = scene.geometry.intersect(&ray) else {
            return;
        };
        // Beer-Lambert along the segment, as in `trace_range`, so both tracers carry the same
        // flux.
        flux *= scene.transmittance_to(&hit, &ray);
        if !flux.cmpgt(Vec3::ZERO).any() {
            return;
        }
        let (uc, u) = (rng.uniform(), rng.uniform2());
        let Some(bsdf) = scene.bsdf_at(&hit) else {
            return;
        };
        let d = ray.d.normalize();
        let ng = hit.point.n;
        if diffuse == 0 {
            // Move the differentials onto the surface's plane: the footprint on this surface.
            rd.o = ray.o;
            rd.d = d;
            rd = transfer(&rd, hit.t, ng);
            if !rd.is_finite() {
                return;
            }
        }
        if !bsdf.is_delta() {
            // A non-delta hit ends the specular chain from the light. Where the surface has
            // a diffuse lobe this is a caustic photon if the path so far is L S+ (D S*)*
            // (the differentials mean something only at the first); a glossy surface first
            // (L S+ G) is the path tracer's, as L D is.
            if diffuse == 0 && (specular_bounces == 0 || bsdf.diffuse_albedo().is_none()) {
                return;
            }
            if bsdf.diffuse_albedo().is_some() {
                diffuse += 1;
                let first = diffuse == 1;
                out.push(CausticPhoton {
                    position: hit.point.p,
                    normal: if d.dot(ng) < 0.0 { ng } else { -ng },
                    surface: surface_id(hit.prim),
                    flux,
                    a: if first { rd.dodu } else { Vec3::ZERO },
                    b: if first { rd.dodv } else { Vec3::ZERO },
                    path: index,
                    diffuse,
                });
            }
            if !indirect {
                return;
            }
            // Leaving the caustic's own receiver, only its diffuse lobe carries the caustic
            // on: light its glossy lobe sends on (L S+ G ...) is the path tracer's. So a
            // Glossy surface goes on as its Lambertian part, chosen with its sampling
            // probability (`uc` rescaled stays uniform for the roulette below).
            let wo_local = math::Frame::from_z(hit.ns).to_local(-d);
            let (bsdf, uc) = match bsdf.diffuse_lobe(wo_local) {
                Some(DiffuseLobe {
                    albedo,
                    probability: pd,
                    rest: Some(_),
                }) if diffuse == 1 => {
                    if uc >= pd {
                        return;
                    }
                    flux /= pd;
                    (Bsdf::Lambertian(Lambertian { albedo }), uc / pd)
                }
                _ => (bsdf, uc),
            };
            // On past it as the photon tracer goes (`trace_range`): Russian roulette on the
            // albedo at a Lambertian bounce, on the sample's weight at a glossy one.
            if let Some(DiffuseLobe {
                albedo, rest: None, ..
            }) = bsdf.diffuse_lobe(wo_local)
            {
                let survive = (albedo * flux).max_element() / flux.max_element();
                if uc >= survive {
                    return;
                }
                flux = flux * albedo / survive;
            }
            let Some((wi, s)) = crate::trace::scatter(&hit, bsdf, d, uc, u) else {
                return;
            };
            if !bsdf.is_diffuse() {
                let Some(f) = crate::trace::glossy_roulette(flux, &s, &mut rng) else {
                    return;
                };
                flux = f;
            }
            ray = hit.point.spawn_ray(wi);
            continue;
        }
        let Some((wi, s)) = crate::trace::scatter(&hit, bsdf, d, uc, u) else {
            return;
        };
        flux *= s.weight();
        specular_bounces += 1;
        if diffuse == 0 {
            let (dndu, dndv) = normal_derivatives(scene, &hit, rd.dodu, rd.dodv);
            let n = hit.ns;
            rd = match (s.is_transmission(), bsdf.glass_eta()) {
                (true, Some(glass_eta)) => {
                    // Entering when the photon arrives on the shading normal's side (the
                    // dielectric's own convention).
                    let eta = if d.dot(n) < 0.0 {
                        1.0 / glass_eta
                    } else {
                        glass_eta
                    };
                    refract_diff(&rd, n, dndu, dndv, eta)
                        .unwrap_or_else(|| reflect_diff(&rd, n, dndu, dndv))
                }
                _ => reflect_diff(&rd, n, dndu, dndv),
            };
            // The sampled direction is the one traced; the differentials follow it.
            rd.d = wi;
        }
        ray = hit.point.spawn_ray(wi);
    }
}
