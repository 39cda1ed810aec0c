//! Eye vertices: where camera paths first meet a diffuse surface after any number of specular
//! or glossy bounces (E (S|G)* D), the points at which photon splatting (and SPPM's visible points)
//! estimate radiance. Through glass both reflection and refraction are followed, weighted by
//! Fresnel, for the first few dielectric hits (the course framework's two splits), then one
//! of them is chosen with Fresnel probability (Russian roulette), so 1-spp images through the
//! glass sphere are not speckled.

use bsdf::TransportMode;
use geom::{Hit, Ray};
use glam::Vec3;
use math::{Frame, Rng, mix64};
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
    /// Which pass of a progressive method: each pass draws new pixel samples.
    pub pass: u64,
}

/// The random stream seed of pass `pass`'s eye vertices: pass 0 uses the scene's seed, as
/// every eye pass does (its vertices are the photon-map passes' first vertices), later passes
/// a SplitMix64 mix of the pass number (Steele et al. 2014).
pub fn pass_seed(seed: u64, pass: u64) -> u64 {
    if pass == 0 {
        seed
    } else {
        seed ^ mix64(pass ^ 0x7061_7373_6579_6573)
    }
}

/// The eye vertices of every pixel sample, in pixel order, then sample order, then branch
/// order (reflection before refraction). Pixel sample `s` of pixel `p` draws from
/// `Rng::for_index(pass_seed(seed, pass), s * pixels + p)` after two numbers for its jitter,
/// like every eye pass, so the list is the same for any thread count.
pub fn eye_vertices(scene: &Scene, opts: &VertexOptions) -> Vec<EyeVertex> {
    let (w, h) = (scene.camera.width as usize, scene.camera.height as usize);
    let spp = opts.spp.max(1);
    // Angle one pixel subtends at the image centre.
    let pixel_angle = 2.0 * (scene.camera.vfov_deg.to_radians() * 0.5).tan() / h as f32;
    let per_sample = pixel_angle / (spp as f32).sqrt();
    let seed = pass_seed(scene.seed(), opts.pass);
    let row = |y: usize| -> Vec<EyeVertex> {
        let mut out = Vec::new();
        let mut found = Vec::new();
        for x in 0..w {
            let pixel = (y * w + x) as u64;
            for s in 0..spp as u64 {
                let mut rng = Rng::for_index(seed, s * (w * h) as u64 + pixel);
                let [jx, jy] = rng.uniform2();
                let ray = scene.camera.ray(x as f32 + jx, y as f32 + jy);
                found.clear();
                first_diffuse(scene, ray, opts.splits, &mut rng, false, &mut |f| {
                    found.push(f)
                });
                for f in &found {
                    let ng = f.hit.point.n;
                    let facing = if f.wo.dot(ng) >= 0.0 { ng } else { -ng };
                    out.push(EyeVertex {
                        pixel: pixel as u32,
                        p: f.hit.point.p,
                        ng: facing,
                        surface: surface_id(f.hit.prim),
                        weight: f.beta * f.albedo / (std::f32::consts::PI * spp as f32),
                        // A grazing view stretches the pixel's footprint (bounded at 1/0.1).
                        spacing: f.length * per_sample / f.wo.dot(facing).max(0.1),
                    });
                }
            }
        }
        out
    };
    let work = || -> Vec<EyeVertex> { (0..h).into_par_iter().flat_map_iter(row).collect() };
    crate::render::on_threads(opts.threads, work)
}

/// A first diffuse vertex as the eye passes use it.
pub(crate) struct Found {
    pub hit: Hit,
    /// Shading normal turned towards the incoming ray.
    pub n: Vec3,
    pub albedo: Vec3,
    /// Throughput of the specular chain that led here (Fresnel weights of split branches
    /// included).
    pub beta: Vec3,
    /// Path length from the start of the chain.
    pub length: f32,
    /// Unit direction back along the ray that arrived.
    pub wo: Vec3,
    /// Which split branches led here, as a heap index: 1 for the walk that has not split,
    /// and at a split `2 b` for reflection, `2 b + 1` for refraction. The same chain of
    /// choices gives the same number on every pass, so a pixel's points are told apart.
    pub branch: u32,
}

#[derive(Clone, Copy)]
struct Branch {
    ray: Ray,
    beta: Vec3,
    length: f32,
    depth: u32,
    splits: u32,
    /// A glossy bounce was made on the way: emission met past it is counted whatever
    /// `count_emission` says, since neither next-event estimation at the vertex the walk
    /// started from nor a caustic map (specular chains only) holds it.
    glossy: bool,
    /// [`Found::branch`] of the vertices this branch reaches.
    branch: u32,
}

/// Most dielectric splits one walk follows: the branches waiting on the stack are never more
/// than the splits made plus the one being followed, so a fixed array holds them (the walk
/// runs per pixel sample and per gather ray; it allocates nothing).
pub(crate) const MAX_SPLITS: u32 = 16;

/// Follows `ray` through specular surfaces to its first diffuse vertices, depth first
/// (reflection before refraction), handing them to `found`; at the first `splits` (at most
/// [`MAX_SPLITS`]) dielectric
/// hits both Fresnel branches are followed with weights R and T/η², later ones choose one
/// with Fresnel probability. Every hit draws three numbers from `rng` whether it uses them or
/// not (the layout every eye pass shares), so without a split the walk is the single path
/// the photon-map passes have always followed. Returns the emission met on the way, each
/// light hit weighted by its branch's throughput, when `count_emission` or past a glossy
/// bounce.
pub(crate) fn first_diffuse(
    scene: &Scene,
    ray: Ray,
    splits: u32,
    rng: &mut Rng,
    count_emission: bool,
    found: &mut dyn FnMut(Found),
) -> Vec3 {
    let max_depth = scene.render().max_depth;
    let splits = splits.min(MAX_SPLITS);
    let lights = &scene.light_table;
    let mut emitted = Vec3::ZERO;
    let mut stack = [None::<Branch>; MAX_SPLITS as usize + 2];
    stack[0] = Some(Branch {
        ray,
        beta: Vec3::ONE,
        length: 0.0,
        depth: 0,
        splits: 0,
        glossy: false,
        branch: 1,
    });
    let mut len = 1;
    while len > 0 {
        len -= 1;
        let Some(b) = stack[len].take() else {
            continue;
        };
        if b.depth > max_depth {
            continue;
        }
        let Some(hit) = scene.geometry.intersect(&b.ray) else {
            // Leaving the scene: the lights at infinity it sees, on the same terms as an
            // emissive triangle's hit below.
            if count_emission || b.glossy {
                emitted += b.beta * lights.escaped(b.ray.d.normalize());
            }
            continue;
        };
        // Beer-Lambert along the segment just traced, when it ran inside absorbing glass.
        let b = Branch {
            beta: b.beta * scene.transmittance_to(&hit, &b.ray),
            ..b
        };
        if (count_emission || b.glossy)
            && let Some(light) = lights.light_of(hit.prim)
        {
            emitted += b.beta * lights.le(light, b.ray.d);
        }
        let wo = -b.ray.d.normalize();
        let (u_lobe, u_dir) = (rng.uniform(), rng.uniform2());
        // Black surfaces absorb.
        let Some(bsdf) = scene.bsdf_at(&hit) else {
            continue;
        };
        let length = b.length + hit.t * b.ray.d.length();
        // Shading normals face the geometric one (geom), so this turns both to the side the
        // ray came from.
        let facing = || {
            if wo.dot(hit.point.n) >= 0.0 {
                hit.ns
            } else {
                -hit.ns
            }
        };
        // Photon estimates read diffuse lobes only. The Glossy model's two lobes are chosen
        // between with its sampling probability: its Lambertian part is a vertex, its GGX
        // part is followed as a specular bounce is (pbrt-v4's SPPM follows glossy lobes too).
        // A plastic's base seen through its coating is a vertex the same way, the coating's
        // reflection the rest.
        let frame = Frame::from_z(hit.ns);
        let wo_l = frame.to_local(wo);
        let (bsdf, lobe) = match bsdf.diffuse_lobe(wo_l) {
            Some(d) => {
                // A Lambertian model is its diffuse lobe (probability 1: `beta` unchanged).
                if d.rest.is_none() || u_lobe < d.probability {
                    found(Found {
                        hit,
                        n: facing(),
                        albedo: d.albedo,
                        beta: b.beta / d.probability,
                        length,
                        wo,
                        branch: b.branch,
                    });
                    continue;
                }
                match d.rest {
                    Some(rest) => (rest, 1.0 / (1.0 - d.probability)),
                    None => continue,
                }
            }
            None => (bsdf, 1.0),
        };
        // Light from a point, spot or directional light reflected by this glossy lobe: no
        // bounce the walk samples can reach a delta light, and neither next-event estimation
        // at a diffuse vertex nor a photon map holds `L G` seen from here, so it is counted
        // here, each delta light with its one sample (no random numbers: the walk's layout
        // stays), on the same terms as emission past a glossy bounce.
        if lights.has_delta() && !bsdf.is_delta() {
            for ls in lights.delta_samples(hit.point.p) {
                let wi_l = frame.to_local(ls.wi);
                let f = bsdf.f(wo_l, wi_l, TransportMode::Radiance);
                if f == Vec3::ZERO
                    || !sides_agree(wo, ls.wi, hit.point.n, wo_l, wi_l)
                    || scene
                        .geometry
                        .occluded(&hit.point.spawn_ray_to_point(&ls.point))
                {
                    continue;
                }
                emitted += b.beta * lobe * f * wi_l.z.abs() * ls.le / ls.pdf;
            }
        }
        let split = bsdf.glass_eta().is_some() && b.splits < splits;
        let samples = if split {
            // Both branches, weighted by what each carries (f |cos|, no pdf); the stack is
            // LIFO, so refraction goes in first and reflection is followed first.
            let r = bsdf.sample(wo_l, 0.0, u_dir, TransportMode::Radiance);
            let t = bsdf.sample(wo_l, 1.0, u_dir, TransportMode::Radiance);
            [
                t.filter(|t| t.is_transmission())
                    .map(|t| (t, t.f * t.wi.z.abs())),
                r.filter(|r| r.is_reflection())
                    .map(|r| (r, r.f * r.wi.z.abs())),
            ]
        } else {
            [
                bsdf.sample(wo_l, u_lobe, u_dir, TransportMode::Radiance)
                    .map(|s| (s, s.weight())),
                None,
            ]
        };
        // Split children are numbered as a heap: refraction (first in `samples`) 2 b + 1,
        // reflection 2 b.
        for (i, sample) in samples.into_iter().enumerate() {
            let Some((s, weight)) = sample else {
                continue;
            };
            let branch = match (split, i) {
                (false, _) => b.branch,
                (true, 0) => 2 * b.branch + 1,
                (true, _) => 2 * b.branch,
            };
            let wi = frame.to_world(s.wi);
            // As in the path tracer: end the path where shading and geometric normals
            // disagree on reflection vs transmission (pbrt-v4 §10.1.1).
            if !sides_agree(wo, wi, hit.point.n, wo_l, s.wi) {
                continue;
            }
            let beta = b.beta * weight * lobe;
            if beta == Vec3::ZERO || !beta.is_finite() {
                continue;
            }
            stack[len] = Some(Branch {
                ray: hit.point.spawn_ray(wi),
                beta,
                length,
                depth: b.depth + 1,
                splits: b.splits + split as u32,
                glossy: b.glossy || !s.is_specular(),
                branch,
            });
            len += 1;
        }
    }
    emitted
}
