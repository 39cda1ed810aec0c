//! A photon's anisotropic footprint for splatting (Frisvad et al. 2014, "Photon differential
//! splatting for rendering caustics", CGF 33(6)): the ellipse `{x + α a + β b : α² + β² ≤ 1}`
//! spanned by the photon's positional differentials `a`, `b` in the tangent plane, and the
//! irradiance it deposits at a point y, `E_p(y) = Φ_p K(|M (y - x)|) |det M|` with `M` the
//! map from the plane to the unit disc and `K` Silverman's kernel, so that each photon's
//! splat integrates to its flux over the plane.
//!
//! The ellipse is kept in its principal form: the semi-axes are the singular values of
//! `[a b]` (eigenvalues of `[a b][a b]ᵀ`) along orthonormal directions. That is what makes
//! the clamps of the paper's stability discussion well defined: each principal semi-axis is
//! clamped to `[min_len, max_len]` (a focus makes one of them vanish; a long chain of
//! internal reflections makes them huge), and `|det M| = 1 / (σ₁ σ₂)` is recomputed from the
//! clamped axes, so every photon still deposits exactly its flux. A degenerate footprint
//! (parallel or zero axes, non-finite values) becomes a disc of radius `min_len`.
//!
//! [`splat`] deposits photons ([`SplatPhoton`]) at [`Receivers`] (eye vertices, indexed by
//! spacing level), each level reading a photon through a footprint no thinner than its
//! spacing, and only receivers on the photon's surface and side.

use crate::{Index, IndexKind, Kernel, Neighbor};
use glam::{DVec3, Vec3};
use std::collections::BTreeMap;

/// A photon's footprint on its surface, ready to weigh points.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Footprint {
    pub center: Vec3,
    /// Unit normal of the surface plane.
    pub normal: Vec3,
    /// Principal directions (unit, in the plane) divided by their clamped semi-axes: the rows
    /// of `M`.
    rows: [Vec3; 2],
    /// Clamped principal semi-axes, largest first.
    pub axes: [f32; 2],
}

impl Footprint {
    /// The footprint of semi-axes `a`, `b` (any two vectors; their components along `normal`
    /// are ignored) about `center`, principal semi-axes clamped to `[min_len, max_len]`.
    /// `None` only for a normal that is not a direction or bounds that are not
    /// `0 < min_len <= max_len`, all finite.
    pub fn new(
        center: Vec3,
        normal: Vec3,
        a: Vec3,
        b: Vec3,
        min_len: f32,
        max_len: f32,
    ) -> Option<Footprint> {
        let n = normal.normalize_or_zero();
        if n == Vec3::ZERO
            || !center.is_finite()
            || !(min_len > 0.0 && min_len <= max_len && max_len.is_finite())
        {
            return None;
        }
        let frame = math::Frame::from_z(n);
        let (t1, t2) = (frame.s, frame.t);
        let finite = |v: Vec3| if v.is_finite() { v } else { Vec3::ZERO };
        let (a, b) = (finite(a), finite(b));
        // [a b] in the tangent basis, and S = A Aᵀ (in f64: squares of tiny or huge axes).
        let (a1, a2, b1, b2) = (
            a.dot(t1) as f64,
            a.dot(t2) as f64,
            b.dot(t1) as f64,
            b.dot(t2) as f64,
        );
        let (p, q, r) = (a1 * a1 + b1 * b1, a1 * a2 + b1 * b2, a2 * a2 + b2 * b2);
        let mean = 0.5 * (p + r);
        let dev = (0.25 * (p - r) * (p - r) + q * q).sqrt();
        let (l1, l2) = (mean + dev, (mean - dev).max(0.0));
        // Eigenvector of the larger eigenvalue; any direction when S is a multiple of I.
        let (e1x, e1y) = if dev <= 1e-12 * mean.max(f64::MIN_POSITIVE) {
            (1.0, 0.0)
        } else if p >= r {
            (l1 - r, q)
        } else {
            (q, l1 - p)
        };
        let len = (e1x * e1x + e1y * e1y).sqrt();
        let (e1x, e1y) = if len > 0.0 && len.is_finite() {
            (e1x / len, e1y / len)
        } else {
            (1.0, 0.0)
        };
        let e1 = (e1x as f32) * t1 + (e1y as f32) * t2;
        let e2 = n.cross(e1);
        let clamp = |l: f64| {
            let s = l.sqrt() as f32;
            if s.is_finite() {
                s.clamp(min_len, max_len)
            } else {
                max_len
            }
        };
        let (s1, s2) = (clamp(l1), clamp(l2));
        Some(Footprint {
            center,
            normal: n,
            rows: [e1 / s1, e2 / s2],
            axes: [s1.max(s2), s1.min(s2)],
        })
    }

    /// Radius of the smallest disc about the centre holding the ellipse.
    pub fn radius(&self) -> f32 {
        self.axes[0]
    }

    /// `|det M|`: one over the clamped ellipse's parameter area `σ₁ σ₂`.
    pub fn det(&self) -> f32 {
        1.0 / (self.axes[0] * self.axes[1])
    }

    /// `t = |M (y - x)|` for a point `y` (its offset along the normal is ignored: callers
    /// decide which points lie on the surface).
    pub fn t(&self, y: Vec3) -> f32 {
        let d = y - self.center;
        let (u, v) = (self.rows[0].dot(d), self.rows[1].dot(d));
        (u * u + v * v).sqrt()
    }

    /// The irradiance per unit flux this footprint deposits at `y`:
    /// `K(|M (y - x)|) |det M|` with Silverman's kernel (zero outside the ellipse).
    pub fn weight(&self, y: Vec3) -> f64 {
        let t = self.t(y);
        if t >= 1.0 {
            return 0.0;
        }
        Kernel::Silverman.weight(t as f64) * self.det() as f64
    }
}

/// A point that reads splats (an eye vertex: `eye::EyeVertex` field for field, without its
/// surface id).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Receiver {
    /// Pixel index the radiance goes to.
    pub pixel: u32,
    pub p: Vec3,
    /// Unit geometric normal, on the side the eye arrived from.
    pub ng: Vec3,
    /// Radiance sent to the pixel per unit irradiance at `p`.
    pub weight: Vec3,
    /// Distance between neighbouring receivers here: splats are made at least this wide.
    pub spacing: f32,
}

/// A photon with positional differentials (`emit::CausticPhoton` field for field, without
/// its surface, path index and diffuse count).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SplatPhoton {
    pub position: Vec3,
    /// Unit geometric normal, on the side the photon arrived from.
    pub normal: Vec3,
    /// Flux, already divided by the number of paths emitted.
    pub flux: Vec3,
    /// Footprint semi-axes in the tangent plane ([`Footprint::new`]'s `a`, `b`).
    pub a: Vec3,
    pub b: Vec3,
}

/// How far off a photon's tangent plane a receiver may lie, as the sine of its elevation
/// seen from the photon (about 5.7°): keeps a splat on its own surface, as the k-NN
/// estimates' topological test does (`EstimateParams::topo`, off by default there).
pub const DEFAULT_TOPO_EPS: f32 = 0.1;
/// Smallest cosine between a receiver's normal and the photon's (about 26°): same surface,
/// same side. The k-NN estimates test the photon's direction instead; comparing normals
/// also keeps a splat off a surface meeting the photon's at a crease.
pub const DEFAULT_SAME_SIDE_COS: f32 = 0.9;

/// How [`splat`] reads photons.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SplatParams {
    /// Largest principal semi-axis of a footprint (the upper clamp of Frisvad et al. 2014).
    pub max_radius: f32,
    /// When positive, every footprint is a disc of this radius instead (the fixed-radius
    /// splatting that differentials improve on).
    pub isotropic: f32,
    /// A receiver is skipped when `ng · n` is below this ([`DEFAULT_SAME_SIDE_COS`]).
    pub same_side_cos: f32,
    /// A receiver at offset d from the photon is skipped when
    /// `|d · n| > topo_eps |d| + 1e-4 σ₂` ([`DEFAULT_TOPO_EPS`]; σ₂ the footprint's minor
    /// semi-axis, a slack for positions rounded to f32 next to the photon).
    pub topo_eps: f32,
}

impl SplatParams {
    /// The given radii with the default same-side and topological tests.
    pub fn new(max_radius: f32, isotropic: f32) -> SplatParams {
        SplatParams {
            max_radius,
            isotropic,
            same_side_cos: DEFAULT_SAME_SIDE_COS,
            topo_eps: DEFAULT_TOPO_EPS,
        }
    }
}

/// Receivers under kd-trees, one per spacing level: the receivers whose spacing lies in
/// `(2^(l-1), 2^l]` share level `l`, which records the largest spacing among them.
///
/// Levels, not one tree, because a splat must be at least as wide as the spacing of the
/// receivers that read it, and receivers of very different spacing share a surface (a floor
/// seen directly and through a glass ball). A footprint clamped to one spacing falls between
/// the coarser receivers; each level instead reads a photon through its own footprint,
/// clamped to the level's spacing, so each set of receivers integrates every photon to its
/// flux: the lower clamp of Frisvad et al. 2014's stability discussion, taken per sampling
/// density. Cost: one range search per level per photon.
pub struct Receivers {
    levels: Vec<Level>,
    receivers: Vec<Receiver>,
}

/// The receivers of one spacing level.
struct Level {
    /// Largest spacing of the level's receivers (infinite for receivers without a finite
    /// positive spacing, which the clamp then widens to the largest footprint).
    spacing: f32,
    index: Index,
    /// Receiver ids (into `Receivers::receivers`) by the level index's point order.
    ids: Vec<u32>,
}

impl Receivers {
    pub fn new(receivers: Vec<Receiver>) -> Receivers {
        let mut by_level: BTreeMap<i32, (f32, Vec<u32>)> = BTreeMap::new();
        for (i, v) in receivers.iter().enumerate() {
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
                    .map(|&i| receivers[i as usize].p.to_array())
                    .collect();
                Level {
                    spacing,
                    index: Index::build(IndexKind::KdTree, &points),
                    ids,
                }
            })
            .collect();
        Receivers { levels, receivers }
    }

    pub fn len(&self) -> usize {
        self.receivers.len()
    }

    pub fn is_empty(&self) -> bool {
        self.receivers.is_empty()
    }

    pub fn receivers(&self) -> &[Receiver] {
        &self.receivers
    }
}

/// Scratch space of one worker.
#[derive(Default)]
pub struct Scratch {
    near: Vec<Neighbor>,
}

/// The footprint of `p` as the receivers of spacing `spacing` read it: its differentials,
/// each principal semi-axis no thinner than `spacing` (else the splat falls between those
/// receivers) and no wider than `max_radius`.
pub fn footprint(p: &SplatPhoton, spacing: f32, max_radius: f32) -> Option<Footprint> {
    let min_len = spacing.clamp(max_radius * 1e-6, max_radius);
    Footprint::new(p.position, p.normal, p.a, p.b, min_len, max_radius)
}

/// Adds what `photons` deposit at the receivers to `out`, as `(pixel, weight × flux × K |det
/// M|)` pairs in photon order, then by spacing level and receiver (f64, so a caller's sums
/// are the same for any chunking that keeps this order). Each level reads a photon through
/// its own footprint ([`footprint`] with the level's spacing; see [`Receivers`]); photons
/// of non-finite flux are skipped.
pub fn splat(
    receivers: &Receivers,
    photons: impl IntoIterator<Item = SplatPhoton>,
    params: &SplatParams,
    scratch: &mut Scratch,
    out: &mut Vec<(u32, DVec3)>,
) {
    let (max_radius, isotropic) = (params.max_radius, params.isotropic);
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
        for level in &receivers.levels {
            let f = if isotropic > 0.0 {
                disc
            } else {
                let free = *shared.get_or_insert_with(|| {
                    let f = footprint(&p, 0.0, max_radius);
                    (f.map_or(f32::INFINITY, |f| f.axes[1]), f)
                });
                if level.spacing <= free.0 {
                    free.1
                } else {
                    footprint(&p, level.spacing, max_radius)
                }
            };
            let Some(f) = f else {
                continue;
            };
            level
                .index
                .within(p.position, f.radius(), &mut scratch.near);
            for nb in &scratch.near {
                let v = &receivers.receivers[level.ids[nb.index as usize] as usize];
                let d = v.p - p.position;
                if v.ng.dot(f.normal) < params.same_side_cos
                    || d.dot(f.normal).abs() > params.topo_eps * d.length() + 1e-4 * f.axes[1]
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
