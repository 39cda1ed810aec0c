//! Eye passes that read photon maps: the global map visualised directly, and the course
//! framework's standard (next-event estimation for direct light, the caustic map, and final
//! gathering into the global map; Jensen 2001, §9.3 "Rendering"). The maps themselves belong
//! to the density stage; this module sees them only through [`Irradiance`], so `eye` and
//! `density` stay independent of each other.

use crate::RenderOptions;
use crate::render::render_layers;
use film::Film;
use geom::Ray;
use glam::Vec3;
use math::{Frame, Rng, warp};
use scene::Scene;

/// Which photon map a lookup reads.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MapLookup {
    Global,
    Caustic,
}

/// Irradiance estimates from photon maps, supplied by the caller.
pub trait Irradiance: Sync {
    /// Irradiance at `p` on a surface whose unit normal `n` faces the side light is gathered
    /// from.
    fn irradiance(&self, map: MapLookup, p: Vec3, n: Vec3) -> Vec3;
}

/// The global map shown directly: radiance at the first diffuse vertex seen from the eye
/// (through mirrors and glass) is `rho / pi * E_global`, no final gathering. Layers
/// `emitted` and `global`; deterministic for any thread count, like [`crate::render`].
pub fn render_global_direct(
    scene: &Scene,
    opts: &RenderOptions,
    maps: &dyn Irradiance,
    progress: &(dyn Fn(u64) + Sync),
) -> Film {
    let ctx = Ctx { scene, maps };
    render_layers(scene, opts, ["emitted", "global"], progress, &|ray, rng| {
        ctx.with_eye_vertices(ray, rng, |emitted, verts, _| {
            let global: Vec3 = verts
                .iter()
                .map(|v| {
                    v.beta * v.albedo / std::f32::consts::PI
                        * maps.irradiance(MapLookup::Global, v.hit.point.p, v.n)
                })
                .sum();
            [emitted, global]
        })
    })
}

/// The course framework's standard (Jensen 2001 §9.3): direct light by next-event
/// estimation, caustics from the caustic map, indirect light by `rays` final-gather rays per
/// sample that read the global map where they land. Layers `emitted`, `direct`, `caustic`,
/// `indirect`; deterministic for any thread count.
pub fn render_final_gather(
    scene: &Scene,
    opts: &RenderOptions,
    rays: u32,
    maps: &dyn Irradiance,
    progress: &(dyn Fn(u64) + Sync),
) -> Film {
    let ctx = Ctx { scene, maps };
    render_layers(
        scene,
        opts,
        ["emitted", "direct", "caustic", "indirect"],
        progress,
        &|ray, rng| {
            ctx.with_eye_vertices(ray, rng, |emitted, verts, rng| {
                let mut out = [emitted, Vec3::ZERO, Vec3::ZERO, Vec3::ZERO];
                for v in verts {
                    let brdf = v.beta * v.albedo / std::f32::consts::PI;
                    out[1] += direct_at(scene, v, rng) * brdf;
                    out[2] += brdf * maps.irradiance(MapLookup::Caustic, v.hit.point.p, v.n);
                    out[3] += ctx.gather(v, rays, rng) * (v.beta * v.albedo);
                }
                out
            })
        },
    )
}

/// The first diffuse vertex of an eye path.
use crate::vertices::{Found as Vertex, first_diffuse};

/// Dielectric hits at which camera paths of the photon-map passes follow both Fresnel
/// branches (the course framework's two splits; the splat's eye vertices use the same rule).
const SPLITS: u32 = 2;

thread_local! {
    static VERTICES: std::cell::RefCell<Vec<Vertex>> = const { std::cell::RefCell::new(Vec::new()) };
}

struct Ctx<'a> {
    scene: &'a Scene,
    maps: &'a dyn Irradiance,
}

impl Ctx<'_> {
    /// The camera path's first diffuse vertices (Fresnel-split at the first [`SPLITS`]
    /// dielectric hits) and the emission seen on the way, handed to `f`.
    fn with_eye_vertices<const N: usize>(
        &self,
        ray: Ray,
        rng: &mut Rng,
        f: impl FnOnce(Vec3, &[Vertex], &mut Rng) -> [Vec3; N],
    ) -> [Vec3; N] {
        VERTICES.with_borrow_mut(|verts| {
            verts.clear();
            let emitted = first_diffuse(self.scene, ray, SPLITS, rng, true, &mut |v| verts.push(v));
            f(emitted, verts, rng)
        })
    }

    /// Mean radiance arriving at the vertex over `rays` cosine-distributed gather rays, read
    /// from the global map where they land (emission excluded: next-event estimation owns it).
    /// Times `albedo` this is the indirect radiance (the cosine pdf cancels `cos / pi`).
    fn gather(&self, v: &Vertex, rays: u32, rng: &mut Rng) -> Vec3 {
        if rays == 0 {
            return Vec3::ZERO;
        }
        let frame = Frame::from_z(v.n);
        let mut sum = glam::DVec3::ZERO;
        for _ in 0..rays {
            let wi = frame.to_world(warp::sample_cosine_hemisphere(rng.uniform2()));
            if wi.dot(v.hit.point.n) * v.n.dot(v.hit.point.n) <= 0.0 {
                continue;
            }
            let ray = v.hit.point.spawn_ray(wi);
            // One Fresnel-chosen path per gather ray (no splits): its diffuse end, if any.
            let mut end = None;
            // Emission is returned only past a glossy bounce (L G+ X is no caustic and no
            // light sample at the vertex reaches it).
            let emitted = first_diffuse(self.scene, ray, 0, rng, false, &mut |y| end = Some(y));
            sum += emitted.as_dvec3();
            if let Some(y) = end {
                let e = self.maps.irradiance(MapLookup::Global, y.hit.point.p, y.n);
                sum += (y.beta * y.albedo / std::f32::consts::PI * e).as_dvec3();
            }
        }
        (sum / rays as f64).as_vec3()
    }
}

/// Irradiance at the vertex from the lights by one shadow ray (next-event estimation).
pub(crate) fn direct_at(scene: &Scene, v: &Vertex, rng: &mut Rng) -> Vec3 {
    let (u_pick, u) = (rng.uniform(), rng.uniform2());
    let Some(ls) = scene.light_table.sample(v.hit.point.p, u_pick, u) else {
        return Vec3::ZERO;
    };
    let cos = ls.wi.dot(v.n);
    if cos <= 0.0 || ls.wi.dot(v.hit.point.n) * v.n.dot(v.hit.point.n) <= 0.0 {
        return Vec3::ZERO;
    }
    if scene
        .geometry
        .occluded(&v.hit.point.spawn_ray_to_point(&ls.point))
    {
        return Vec3::ZERO;
    }
    ls.le * (cos / ls.pdf)
}
