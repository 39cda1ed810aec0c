//! Photon differential splatting onto eye vertices (Frisvad et al. 2014): a pass's eye
//! vertices (E S* D) are indexed once; caustic photons with differentials (L S+ D, `emit`)
//! are traced in chunks on the pipeline's workers, and each photon adds to every eye vertex
//! inside its footprint `Φ_p K(|M (y - x_p)|) |det M|` (`density::splat`), accepting only
//! vertices on the same surface and side. With `indirect` on, each caustic path goes on past
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
use density::splat::Footprint;
use density::{Index, IndexKind, Neighbor};
use emit::{CausticPhoton, EmitParams};
use eye::{EyeVertex, VertexOptions};
use flow::{PipelineOptions, Stats};
use glam::{DVec3, Vec3};
use scene::Scene;

/// How far off the photon's tangent plane a vertex may lie, relative to its distance: the
/// topological test of the k-NN estimates (keeps a splat on its own surface).
const TOPO_EPS: f32 = 0.1;
/// Smallest cosine between a vertex's normal and the photon's: same surface, same side.
const SAME_SIDE_COS: f32 = 0.9;

/// Eye vertices under kd-trees, one per spacing level: the vertices whose spacing lies in
/// `(2^(l-1), 2^l]` share level `l`, which records the largest spacing among them.
///
/// Levels, not one tree, because a splat must be at least as wide as the spacing of the
/// vertices that read it, and vertices of very different spacing share a surface: the floor
/// under a glass ball is seen both directly (coarse at a low camera) and through the ball
/// (fine). A footprint clamped to the nearest vertex's spacing, as splats were first made,
/// is then often the fine set's and falls between the coarse set's vertices: on the caustic
/// focus of `tests/it/hard_cases.rs` the directly seen floor kept 80% of the focused flux
/// (34% of the photons whose nearest vertex was seen through the ball). Each level now reads
/// a photon through its own footprint, clamped to the level's spacing, so each set of
/// vertices integrates every photon to its flux: the lower clamp of Frisvad et al. 2014's
/// stability discussion, taken per sampling density since the eye's sampling of a surface
/// varies with the eye path that reached it. Cost: one range search per level (a few) per
/// photon; a 128 x 128 worksheet caustic-splat run took 1.03 s against 0.78 s.
pub struct EyeIndex {
    levels: Vec<Level>,
    vertices: Vec<EyeVertex>,
}

/// The vertices of one spacing level.
struct Level {
    /// Largest spacing of the level's vertices (infinite for vertices without a finite
    /// positive spacing, which the clamp then widens to the largest footprint).
    spacing: f32,
    index: Index,
    /// Vertex ids (into `EyeIndex::vertices`) by the level index's point order.
    ids: Vec<u32>,
}

impl EyeIndex {
    pub fn new(vertices: Vec<EyeVertex>) -> EyeIndex {
        let mut by_level: std::collections::BTreeMap<i32, (f32, Vec<u32>)> =
            std::collections::BTreeMap::new();
        for (i, v) in vertices.iter().enumerate() {
            let (key, spacing) = if v.spacing.is_finite() && v.spacing > 0.0 {
                (v.spacing.log2().ceil() as i32, v.spacing)
            } else {
                (i32::MAX, f32::INFINITY)
            };
            let e = by_level.entry(key).or_insert((0.0, Vec::new()));
            e.0 = e.0.max(spacing);
            e.1.push(i as u32);
        }
        let levels = by_level
            .into_values()
            .map(|(spacing, ids)| {
                let points: Vec<[f32; 3]> = ids
                    .iter()
                    .map(|&i| vertices[i as usize].p.to_array())
                    .collect();
                Level {
                    spacing,
                    index: Index::build(IndexKind::KdTree, &points),
                    ids,
                }
            })
            .collect();
        EyeIndex { levels, vertices }
    }

    pub fn len(&self) -> usize {
        self.vertices.len()
    }

    pub fn is_empty(&self) -> bool {
        self.vertices.is_empty()
    }

    pub fn vertices(&self) -> &[EyeVertex] {
        &self.vertices
    }
}

/// The first eye vertices of pass `pass` (`spp` pixel samples each), indexed.
pub fn eye_index(
    scene: &Scene,
    s: &SplatSettings,
    spp: u32,
    pass: u64,
    threads: Option<usize>,
) -> EyeIndex {
    EyeIndex::new(eye::eye_vertices(
        scene,
        &VertexOptions {
            spp,
            splits: s.splits,
            threads,
            pass,
        },
    ))
}

/// Scratch space of one worker.
#[derive(Default)]
pub struct Scratch {
    near: Vec<Neighbor>,
}

/// The footprint of `p` as the vertices of spacing `spacing` read it: its differentials,
/// each principal semi-axis no thinner than `spacing` (else the splat falls between those
/// vertices) and no wider than `max_radius`.
pub fn footprint(p: &CausticPhoton, spacing: f32, max_radius: f32) -> Option<Footprint> {
    let min_len = spacing.clamp(max_radius * 1e-6, max_radius);
    Footprint::new(p.position, p.normal, p.a, p.b, min_len, max_radius)
}

/// Adds what `photons` deposit at the eye vertices to `out`, as `(pixel, radiance)` pairs
/// in photon order, then by spacing level and vertex. Each level reads a photon through its
/// own footprint ([`footprint`] with the level's spacing; see [`EyeIndex`]). `isotropic > 0`
/// replaces every footprint by a disc of that radius (the fixed-radius splatting that
/// differentials improve on).
pub fn splat(
    eyes: &EyeIndex,
    photons: &[CausticPhoton],
    max_radius: f32,
    isotropic: f32,
    scratch: &mut Scratch,
    out: &mut Vec<(u32, DVec3)>,
) {
    for p in photons {
        if !p.flux.is_finite() {
            continue;
        }
        let flux = p.flux.as_dvec3();
        let disc = if isotropic > 0.0 {
            let frame = math::Frame::from_z(p.normal);
            Footprint::new(
                p.position,
                p.normal,
                isotropic * frame.s,
                isotropic * frame.t,
                isotropic,
                isotropic,
            )
        } else {
            None
        };
        // Levels at or below the unclamped footprint's minor axis read it as it is: one
        // footprint for them all.
        let mut shared: Option<(f32, Option<Footprint>)> = None;
        for level in &eyes.levels {
            let f = if isotropic > 0.0 {
                disc
            } else {
                let free = *shared.get_or_insert_with(|| {
                    let f = footprint(p, 0.0, max_radius);
                    (f.map_or(f32::INFINITY, |f| f.axes[1]), f)
                });
                if level.spacing <= free.0 {
                    free.1
                } else {
                    footprint(p, level.spacing, max_radius)
                }
            };
            let Some(f) = f else {
                continue;
            };
            level
                .index
                .within(p.position, f.radius(), &mut scratch.near);
            for nb in &scratch.near {
                let v = &eyes.vertices[level.ids[nb.index as usize] as usize];
                let d = v.p - p.position;
                if v.ng.dot(f.normal) < SAME_SIDE_COS
                    || d.dot(f.normal).abs() > TOPO_EPS * d.length() + 1e-4 * f.axes[1]
                {
                    continue;
                }
                let w = f.weight(v.p);
                if w > 0.0 {
                    let e = flux * w;
                    out.push((v.pixel, v.weight.as_dvec3() * e));
                }
            }
        }
    }
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

/// What a splatting pass needs: the scene, its caustic paths' parameters (`params.photons`
/// per pass, `params.max_depth`), the splat settings and the indexed eye vertices.
pub struct Splatter<'a> {
    pub scene: &'a Scene,
    pub params: &'a EmitParams,
    pub settings: &'a SplatSettings,
    pub eyes: &'a EyeIndex,
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
        let max_r = max_radius(scene, s);
        let indirect_r = indirect_radius(scene, s);
        let work = |range: std::ops::Range<u64>| -> Chunk {
            let n = range.end - range.start;
            let photons = emit::trace_caustics(scene, params, s.scale, pass, range, s.indirect);
            let (first, bounced): (Vec<CausticPhoton>, Vec<CausticPhoton>) =
                photons.into_iter().partition(|p| p.diffuse == 1);
            let mut out = [Vec::new(), Vec::new()];
            let mut scratch = Scratch::default();
            let iso = s.isotropic_radius;
            splat(eyes, &first, max_r, iso, &mut scratch, &mut out[0]);
            splat(
                eyes,
                &bounced,
                indirect_r,
                indirect_r,
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
