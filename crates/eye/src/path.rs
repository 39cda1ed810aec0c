//! The path loop: NEE + BSDF sampling with MIS, Russian roulette, and the classification of
//! every contribution into one [`Class`].

use bsdf::TransportMode;
use film::Class;
use geom::Ray;
use glam::Vec3;
use math::{Frame, Sampler, power_heuristic};
use scene::{Scene, sides_agree};

/// One path's radiance estimate, split by [`Class`].
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Radiance {
    /// Indexed by `Class as usize`, in [`Class::ALL`] order.
    pub parts: [Vec3; 5],
}

impl Radiance {
    pub fn get(&self, part: Class) -> Vec3 {
        self.parts[part as usize]
    }

    /// The sum of all parts: the full estimate.
    pub fn total(&self) -> Vec3 {
        self.parts.iter().sum()
    }

    #[inline]
    fn add(&mut self, part: Class, v: Vec3) {
        self.parts[part as usize] += v;
    }
}

/// What the path loop needs besides the scene.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PathOptions {
    /// Longest path in bounces: emission is counted at hits after at most `max_depth`
    /// bounces and NEE at vertices reached after fewer.
    pub max_depth: u32,
    /// Russian roulette applies once this many bounces have been made.
    pub rr_depth: u32,
    /// When false, the paths photon splatting owns at first eye vertices are left out:
    /// `L S+ D S* E` with `D` the first non-delta vertex from the eye ([`Class::Caustic`]
    /// stays zero); nothing else changes.
    pub caustics: bool,
    /// When false, caustics seen after a further diffuse bounce are left out too:
    /// `L S+ D (S* D)+ S* E` ([`Class::CausticIndirect`] stays zero), which splatting onto
    /// later eye vertices owns. So `path` without both plus both splatted layers is the
    /// whole image.
    pub caustic_indirect: bool,
}

impl PathOptions {
    /// Whether a path tracer with these options estimates `part`.
    pub const fn estimates(&self, part: Class) -> bool {
        match part {
            Class::Caustic => self.caustics,
            Class::CausticIndirect => self.caustic_indirect,
            _ => true,
        }
    }

    /// Depths from the scene's `[render]` settings, caustics on.
    pub fn from_scene(scene: &Scene) -> PathOptions {
        let r = scene.render();
        PathOptions {
            max_depth: r.max_depth,
            rr_depth: r.rr_depth,
            caustics: true,
            caustic_indirect: true,
        }
    }
}

/// The path tracer over a loaded scene (its BSDFs and light table, built once at load).
/// Shared read-only by all render threads.
pub struct PathTracer<'a> {
    scene: &'a Scene,
    opts: PathOptions,
}

/// Russian roulette never survives with a probability above this, so paths trapped between
/// lossless mirrors still end (pbrt-v4 stops at the same value's complement in spirit).
pub(crate) const MAX_SURVIVAL: f32 = 0.95;

impl<'a> PathTracer<'a> {
    pub fn new(scene: &'a Scene, opts: PathOptions) -> PathTracer<'a> {
        PathTracer { scene, opts }
    }

    /// Whether this tracer estimates `part` (the two caustic switches can drop a part).
    pub fn estimates(&self, part: Class) -> bool {
        self.opts.estimates(part)
    }

    /// Radiance arriving along `-ray.d` at `ray.o`, estimated by one path whose random
    /// numbers all come from `rng` (independent or low-discrepancy: see [`Sampler`]). Every vertex draws the same seven uniforms whatever
    /// happens there, so options that only drop contributions (caustics) never shift the
    /// stream.
    pub fn li<S: Sampler>(&self, ray: Ray, rng: &mut S) -> Radiance {
        let geometry = &self.scene.geometry;
        let lights = &self.scene.light_table;
        let mut out = Radiance::default();
        let mut ray = ray;
        let mut beta = Vec3::ONE;
        // Product of eta'^2 over the refractions taken: `beta` carries 1/eta'^2 per
        // refraction (radiance is compressed entering glass), so Russian roulette judges
        // `beta * eta_scale`, which is back to the real throughput outside the glass. Without
        // it a path inside the glass sphere survives with 0.44x the probability and leaves
        // with 2.3x the weight: fireflies (pbrt-v4 §14.1.4, "etaScale").
        let mut eta_scale = 1.0f32;
        // Non-delta vertices passed so far (the current one included once counted).
        let mut diffuse_vertices = 0u32;
        // Bounces that sampled a diffuse lobe, and whether the last non-delta bounce did:
        // a specular chain from a diffuse lobe to the light is what photon splatting owns
        // (a caustic), from a glossy lobe the path tracer keeps it.
        let mut diffuse_lobes = 0u32;
        let mut last_lobe_diffuse = false;
        // Where the last bounce left and its BSDF pdf, if that bounce was non-delta: a light
        // hit then competes with NEE and is MIS-weighted. `None` after a specular bounce.
        let mut from_diffuse: Option<(Vec3, f32)> = None;
        let mut bounces = 0u32;
        loop {
            let hit = geometry.intersect(&ray);
            // Emission found by the path itself: an emissive triangle hit, or the lights at
            // infinity seen by a ray that leaves the scene. `mis` is its contribution
            // MIS-weighted against next-event estimation, read only after a non-delta bounce.
            let (le, mis) = match &hit {
                Some(hit) => {
                    // Beer-Lambert along the segment just traced, inside absorbing glass.
                    beta *= self.scene.transmittance_to(hit, &ray);
                    match lights.light_of(hit.prim) {
                        Some(light) => {
                            let le = lights.le(light, ray.d);
                            let mis = |(p, pdf_bsdf): (Vec3, f32)| {
                                let pdf_light = lights.pdf(light, p, hit.point.p);
                                beta * le * power_heuristic(1, pdf_bsdf, 1, pdf_light)
                            };
                            (le, from_diffuse.map(mis))
                        }
                        None => (Vec3::ZERO, None),
                    }
                }
                None => {
                    let d = ray.d.normalize();
                    let le = lights.escaped(d);
                    let mis = |(_, pdf_bsdf): (Vec3, f32)| beta * lights.escaped_mis(d, pdf_bsdf);
                    (le, from_diffuse.filter(|_| le != Vec3::ZERO).map(mis))
                }
            };
            if le != Vec3::ZERO {
                if diffuse_vertices == 0 {
                    out.add(Class::Emitted, beta * le);
                } else if let Some(c) = mis {
                    out.add(direct_or_indirect(diffuse_vertices), c);
                } else if !last_lobe_diffuse {
                    // Specular chain from a glossy lobe to the light (L S+ G ...): no caustic
                    // photon ends on a glossy lobe, so the path tracer keeps it.
                    out.add(direct_or_indirect(diffuse_vertices), beta * le);
                } else if diffuse_lobes > 1 {
                    // Specular chain from a diffuse vertex to the light: NEE's shadow rays
                    // cannot follow it, so BSDF sampling owns it (weight 1).
                    if self.opts.caustic_indirect {
                        out.add(Class::CausticIndirect, beta * le);
                    }
                } else if self.opts.caustics {
                    out.add(Class::Caustic, beta * le);
                }
            }
            let Some(hit) = hit else {
                break;
            };
            if bounces >= self.opts.max_depth {
                break;
            }

            let u_pick = rng.uniform();
            let u_light = rng.uniform2();
            let u_lobe = rng.uniform();
            let u_dir = rng.uniform2();
            let u_rr = rng.uniform();

            // Black surfaces absorb: nothing more can be added along this path.
            let Some(bsdf) = self.scene.bsdf_at(&hit) else {
                break;
            };
            let ng = hit.point.n;
            let frame = Frame::from_z(hit.ns);
            let wo = -ray.d.normalize();
            let wo_l = frame.to_local(wo);

            if !bsdf.is_delta() {
                diffuse_vertices += 1;
                if let Some(ls) = lights.sample(hit.point.p, u_pick, u_light) {
                    let wi_l = frame.to_local(ls.wi);
                    let f = bsdf.f(wo_l, wi_l, TransportMode::Radiance);
                    if f != Vec3::ZERO
                        && sides_agree(wo, ls.wi, ng, wo_l, wi_l)
                        && !geometry.occluded(&hit.point.spawn_ray_to_point(&ls.point))
                    {
                        // A point or spot light is never hit by BSDF sampling: NEE alone
                        // reaches it, weight 1 (pbrt-v4 §12.1).
                        let w = if ls.delta {
                            1.0
                        } else {
                            power_heuristic(1, ls.pdf, 1, bsdf.pdf(wo_l, wi_l))
                        };
                        let c = beta * f * ls.le * (wi_l.z.abs() * w / ls.pdf);
                        out.add(direct_or_indirect(diffuse_vertices), c);
                    }
                }
            }

            // One lobe at a time, weighted by it alone, so each path has one class (a
            // Glossy surface's diffuse part is a caustic receiver, its GGX part not).
            let Some((s, diffuse_lobe, pdf_all)) =
                bsdf.sample_lobe(wo_l, u_lobe, u_dir, TransportMode::Radiance)
            else {
                break;
            };
            let wi = frame.to_world(s.wi);
            if !sides_agree(wo, wi, ng, wo_l, s.wi) {
                break;
            }
            beta *= s.weight();
            if s.is_transmission() {
                eta_scale *= s.eta * s.eta;
            }
            if !s.is_specular() {
                diffuse_lobes += diffuse_lobe as u32;
                last_lobe_diffuse = diffuse_lobe;
            } else if !bsdf.is_delta() {
                // A plastic's coating reflection: a delta lobe of a surface photons treat as a
                // receiver (never part of a caustic photon's specular chain), so a chain from
                // it to a light is the path tracer's, as one from a glossy lobe is.
                last_lobe_diffuse = false;
            }
            // MIS against next-event estimation weighs the whole BSDF's density, the one
            // NEE's own weight reads.
            from_diffuse = if s.is_specular() {
                None
            } else {
                Some((hit.point.p, pdf_all))
            };
            ray = hit.point.spawn_ray(wi);
            bounces += 1;

            if beta == Vec3::ZERO {
                break;
            }
            if bounces >= self.opts.rr_depth {
                let q = (beta * eta_scale).max_element().min(MAX_SURVIVAL);
                if u_rr >= q || q.is_nan() {
                    break;
                }
                beta /= q;
            }
        }
        out
    }
}

#[inline]
fn direct_or_indirect(diffuse_vertices: u32) -> Class {
    if diffuse_vertices == 1 {
        Class::Direct
    } else {
        Class::Indirect
    }
}
