//! Photon tracing: paths from the lights, stored at diffuse hits.

use crate::{EmitParams, Plan};
use bsdf::{Bsdf, DiffuseLobe, TransportMode};
use glam::Vec3;
use math::{Frame, Rng};
use rayon::prelude::*;
use scene::{Scene, sides_agree, surface_id};
use std::ops::Range;
use store::{MapKind, PerKind, Photon};

/// Mixed into the scene seed for photon streams, so photon `i` and the eye pass's sample `i`
/// never share random numbers ("emitphot" in ASCII).
pub const EMIT_STREAM: u64 = 0x656d_6974_7068_6f74;

/// Photons of a range of paths, in path order (and hit order within a path), one set per
/// map kind (`traced[MapKind::Global]`).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Traced {
    /// Paths emitted: the range's length, whatever was stored. Photon powers already carry
    /// the 1/N of the whole run's emitted count.
    pub emitted: u64,
    pub sets: PerKind<Vec<Photon>>,
}

impl Traced {
    /// Append the photons of the *next* range: concatenation in index order is the whole run.
    pub fn append(&mut self, mut next: Traced) {
        self.emitted += next.emitted;
        for k in MapKind::ALL {
            self.sets[k].append(&mut next.sets[k]);
        }
    }

    /// Photons stored in all sets.
    pub fn stored(&self) -> usize {
        self.sets.iter().map(|(_, s)| s.len()).sum()
    }
}

impl std::ops::Index<MapKind> for Traced {
    type Output = Vec<Photon>;
    fn index(&self, k: MapKind) -> &Vec<Photon> {
        &self.sets[k]
    }
}

/// Trace photon paths `range` (indices into `0..params.photons`) in increasing order. Path `i`
/// draws its numbers from `Rng::for_index(scene.seed() ^ EMIT_STREAM, i)` only, so the result
/// for a range is the concatenation of the results for any split of it.
///
/// Rules at a hit (material → BSDF in the shading frame of `hit.ns`; sides are decided with
/// the geometric normal, and a sample the two normals disagree about ends the path, so no
/// photon leaks through a surface):
/// - diffuse: store in the global set if `hit > 1 || store_direct`, in the caustic set if the
///   path so far is L S+ (at least one specular bounce, no diffuse one); then Russian roulette
///   (below) and a cosine-weighted direction;
/// - specular: `Φ *= f |cos θi| / pdf` of a [`TransportMode::Importance`] sample;
/// - black Lambertian: absorbed.
///
/// No adjoint shading-normal correction is applied (Veach 1997 §5.3): like pbrt-v4's SPPM
/// photon pass (§16.2), the throughput uses the shading-frame cosine only. It matters only
/// for interpolated normals (the tessellated spheres, which are specular: there
/// `f |cos| / pdf` is the reflectance or 1 either way).
///
/// Russian roulette survival is `P = max_c(ρ_c Φ_c) / max_c(Φ_c)` (Jensen 2001 ch. 5; the
/// albedo's largest component for a white photon), survivors carry `Φ ρ / P`, whose largest
/// component equals the incoming one: photon power never grows, so a few bright photons cannot
/// dominate an estimate. The mean albedo would let `Φ ρ / P` exceed `Φ` (a red wall scales a
/// photon's red by 2.7) and the channel-blind `max ρ` would keep tracing a red photon on a
/// green wall with zero power.
///
/// A path also ends when nothing it can still do reaches a planned set: a diffuse bounce when
/// only the caustic set is planned, everything when neither is.
pub fn trace_range(scene: &Scene, params: &EmitParams, plan: &Plan, range: Range<u64>) -> Traced {
    trace_pass(scene, params, plan, 0, range)
}

/// [`trace_range`] for pass `pass` of a progressive method: path `i` draws from the stream
/// `(seed, pass, i)` ([`crate::pass_stream`]); pass 0 is `trace_range` itself.
pub fn trace_pass(
    scene: &Scene,
    params: &EmitParams,
    plan: &Plan,
    pass: u64,
    range: Range<u64>,
) -> Traced {
    let mut out = Traced {
        emitted: range.end.saturating_sub(range.start),
        ..Traced::default()
    };
    if plan.is_empty() || params.max_depth == 0 {
        return out;
    }
    let tracer = Tracer {
        scene,
        params,
        plan,
        stream: crate::pass_stream(scene.seed(), pass),
    };
    for i in range {
        tracer.trace_path(i, &mut out);
    }
    out
}

/// [`trace_range`] over `0..params.photons` on rayon's current thread pool, `chunk` paths per
/// task, concatenated in index order: the same photons as one call to [`trace_range`].
pub fn trace_parallel(scene: &Scene, params: &EmitParams, plan: &Plan, chunk: u64) -> Traced {
    let parts: Vec<Traced> = flow::chunks(params.photons, chunk)
        .collect::<Vec<_>>()
        .into_par_iter()
        .map(|r| trace_range(scene, params, plan, r))
        .collect();
    let mut out = Traced::default();
    for p in parts {
        out.append(p);
    }
    out
}

/// A photon's bounce at `hit` (arriving along unit `d`): the BSDF sampled in
/// [`TransportMode::Importance`] in the shading frame of `hit.ns`, with sides decided by the
/// geometric normal; `None` (absorbed) when the two normals disagree about the side the
/// photon arrives on or leaves by, so no photon leaks through a surface. Returns the new
/// unit direction and the sample.
pub(crate) fn scatter(
    hit: &geom::Hit,
    bsdf: Bsdf,
    d: Vec3,
    uc: f32,
    u: [f32; 2],
) -> Option<(Vec3, bsdf::BsdfSample)> {
    let ng = hit.point.n;
    let wo = -d;
    let frame = Frame::from_z(hit.ns);
    let wo_local = frame.to_local(wo);
    if wo_local.z * wo.dot(ng) <= 0.0 {
        return None;
    }
    let s = bsdf.sample(wo_local, uc, u, TransportMode::Importance)?;
    let wi = frame.to_world(s.wi).normalize();
    sides_agree(wo, wi, ng, wo_local, s.wi).then_some((wi, s))
}

/// A photon's way on from `hit`, reached along unit `d` with `flux`, by the rules of
/// [`trace_range`]: Russian roulette on the albedo at a Lambertian vertex, the BSDF sampled
/// ([`scatter`]), the sample's weight after a specular bounce and roulette on it after a
/// glossy one. `None` when the photon ends; else its next ray, its flux and whether the
/// bounce was specular. The photon tracer and the light tracer share it, so their paths
/// follow the same rules.
pub(crate) fn bounce(
    hit: &geom::Hit,
    bsdf: Bsdf,
    d: Vec3,
    mut flux: Vec3,
    uc: f32,
    u: [f32; 2],
    rng: &mut Rng,
) -> Option<(geom::Ray, Vec3, bool)> {
    let wo_local = Frame::from_z(hit.ns).to_local(-d);
    if let Some(DiffuseLobe {
        albedo, rest: None, ..
    }) = bsdf.diffuse_lobe(wo_local)
    {
        let survive = (albedo * flux).max_element() / flux.max_element();
        if uc >= survive {
            return None;
        }
        flux = flux * albedo / survive;
    }
    let (wi, s) = scatter(hit, bsdf, d, uc, u)?;
    if s.is_specular() {
        flux *= s.weight();
    } else if !bsdf.is_diffuse() {
        flux = glossy_roulette(flux, &s, rng)?;
    }
    Some((hit.point.spawn_ray(wi), flux, s.is_specular()))
}

/// A photon's flux after a glossy bounce: the sample's weight, then Russian roulette on the
/// share of the flux it keeps (Jensen 2001 §5.3 for the diffuse case); `None` when the
/// photon ends. Its number is drawn here, at glossy hits only, so scenes without them keep
/// their streams.
pub(crate) fn glossy_roulette(flux: Vec3, s: &bsdf::BsdfSample, rng: &mut Rng) -> Option<Vec3> {
    let kept = flux * s.weight();
    let survive = (kept.max_element() / flux.max_element()).min(1.0);
    (rng.uniform() < survive).then(|| kept / survive)
}

struct Tracer<'a> {
    scene: &'a Scene,
    params: &'a EmitParams,
    plan: &'a Plan,
    /// Seed of the pass's photon streams.
    stream: u64,
}

impl Tracer<'_> {
    fn trace_path(&self, index: u64, out: &mut Traced) {
        let mut rng = Rng::for_index(self.stream, index);
        // Fixed layout: 5 numbers to emit, then 3 per hit, used or not.
        let (u_light, u_pos, u_dir) = (rng.uniform(), rng.uniform2(), rng.uniform2());
        let e = self
            .scene
            .light_table
            .emit(u_light, u_pos, u_dir, self.params.photons);
        let mut flux = e.flux.as_vec3();
        let mut ray = e.ray;
        let mut specular_bounces = 0u32;
        // Non-delta bounces: a photon is a caustic photon only while it has made none.
        let mut diffuse_bounces = 0u32;
        for hit_index in 0..self.params.max_depth {
            // Black photons (a channel-less mirror, say) carry nothing; NaN fails this too.
            if !flux.cmpgt(Vec3::ZERO).any() {
                return;
            }
            let Some(hit) = self.scene.geometry.intersect(&ray) else {
                return;
            };
            // Beer-Lambert along the segment just traced, when it ran inside absorbing glass:
            // a deterministic factor, so the roulettes below (relative to the flux they
            // receive) stay unbiased.
            flux *= self.scene.transmittance_to(&hit, &ray);
            if !flux.cmpgt(Vec3::ZERO).any() {
                return;
            }
            let (uc, u) = (rng.uniform(), rng.uniform2());
            let Some(bsdf) = self.scene.bsdf_at(&hit) else {
                return;
            };
            let d = ray.d.normalize();
            // Photons are stored where a surface has a diffuse lobe (Lambertian, or the
            // Glossy model's Lambertian part), the lobe photon estimates read.
            if bsdf.diffuse_albedo().is_some() {
                let photon = || Photon::new(hit.point.p, flux, d, surface_id(hit.prim));
                if self.plan.global && (hit_index > 0 || self.params.store_direct) {
                    out.sets[MapKind::Global].push(photon());
                }
                if self.plan.caustic && specular_bounces > 0 && diffuse_bounces == 0 {
                    out.sets[MapKind::Caustic].push(photon());
                }
            }
            if !bsdf.is_delta() {
                // Past a non-delta bounce only the global set can gain photons; past the last
                // hit, nothing.
                if !self.plan.global || hit_index + 1 == self.params.max_depth {
                    return;
                }
                diffuse_bounces += 1;
            }
            let Some((next, f, specular)) = bounce(&hit, bsdf, d, flux, uc, u, &mut rng) else {
                return;
            };
            specular_bounces += specular as u32;
            (ray, flux) = (next, f);
        }
    }
}
