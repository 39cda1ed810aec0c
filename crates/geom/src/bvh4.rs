//! The default acceleration structure: a 4-wide BVH with full-precision f32 child boxes in
//! structure-of-arrays layout (one SSE compare tests all four children), collapsed from an
//! obvhs `Bvh2` (PLOC + reinsertion) by the collapse that minimises the surface area
//! heuristic (dynamic programming, `Builder::optimize`). Triangles *and* spheres are its
//! primitives, so a ray pays for a sphere only when it enters the sphere's box.
//!
//! Leaves hold up to `LEAF_MAX` triangles in blocks of four, tested together with the
//! watertight test of Woop, Benthin and Wald (JCGT 2013), or one sphere.
//!
//! Why not obvhs' `CwBvh` traversal: it decodes 8-bit quantised child boxes on every visit
//! (its own comments name that the most expensive step), clamps entry distances to
//! `t >= 1e-4`, and calls the primitive test through a closure one triangle at a time.

use crate::float::{gamma, next_down, next_up};
use crate::ploc::{self, Work};
use crate::simd::{F4, Lanes};
use crate::{Prim, Ray, Sphere, TriMesh};
use obvhs::bvh2::Bvh2;
use obvhs::ploc::PlocSearchDistance;
use obvhs::{BvhBuildParams, aabb::Aabb};
use rayon::prelude::*;
use std::ops::{Add, Div, Mul, Sub};
use std::sync::atomic::{AtomicU16, AtomicU64, Ordering};

/// Child reference: an inner node's index, or a leaf tagged by `LEAF`.
pub(crate) const LEAF: u32 = 1 << 31;
/// A leaf holding one sphere (index in the low bits).
pub(crate) const SPHERE: u32 = 1 << 30;
/// Triangle leaves: block count in bits 26..30, first block in bits 0..26.
pub(crate) const COUNT_SHIFT: u32 = 26;
const FIRST_MASK: u32 = (1 << COUNT_SHIFT) - 1;
pub(crate) const EMPTY: u32 = u32::MAX;

/// Largest triangle leaf: one block of four. On the tessellated Cornell scene (`bench-rays`,
/// one run, medians of 3) 2 and 8 were 10-15% slower on both ray sets with the greedy
/// collapse; with the optimal one 8 measured the same as 4.
pub(crate) const LEAF_MAX: u32 = 4;

/// Ize, "Robust BVH Ray Traversal" (JCGT 2013): scaling the exit distance by
/// `1 + 2 gamma(3)` makes the slab test conservative for `(b - o) * (1 / d)`.
fn robust() -> f32 {
    1.0 + 2.0 * gamma(3)
}

/// Four children: boxes as `[min_x, max_x, min_y, max_y, min_z, max_z]` per lane. An empty
/// slot has an inverted (+inf, -inf) box, which no ray enters.
#[derive(Clone, Copy)]
#[repr(C, align(64))]
pub(crate) struct Node4 {
    pub(crate) b: [[f32; 4]; 6],
    pub(crate) child: [u32; 4],
}

/// Four triangles, structure of arrays: `v[vertex][axis][lane]`. A partly filled block
/// repeats its last triangle, which can only return the same hit again.
#[derive(Clone, Copy)]
#[repr(C, align(16))]
struct Tri4 {
    v: [[[f32; 4]; 3]; 3],
}

pub(crate) struct Bvh4 {
    pub(crate) nodes: Vec<Node4>,
    tris: Vec<Tri4>,
    /// Triangle id (in the `TriMesh`) of each lane of `tris`.
    ids: Vec<[u32; 4]>,
    pub(crate) root: u32,
    /// Deepest stack a traversal can need (three pushes per level below the root).
    stack_need: usize,
}

/// Per-ray constants of the box test (Williams et al. 2005: reciprocal direction and the
/// near/far planes picked by its signs) and of the watertight triangle test (Woop et al.
/// 2013 §3: the axis of largest `|d|` becomes z, and the shear that maps `d` onto it).
struct RayData {
    o: [F4; 3],
    inv: [F4; 3],
    near: [usize; 3],
    far: [usize; 3],
    k: [usize; 3],
    s: [F4; 3],
}

impl RayData {
    #[inline(always)]
    fn new(ray: &Ray) -> RayData {
        let d = ray.d.to_array();
        let o = ray.o.to_array();
        // The sign bit, not `d < 0`: 1 / -0.0 = -inf must take the far plane as its near one.
        let neg = d.map(|x| x.is_sign_negative() as usize);
        let a = ray.d.abs();
        let kz = if a.x > a.y {
            if a.x > a.z { 0 } else { 2 }
        } else if a.y > a.z {
            1
        } else {
            2
        };
        let kx = (kz + 1) % 3;
        let ky = (kx + 1) % 3;
        // The six divisions in one vector division (each lane rounds like the scalar
        // quotient): 1/dx, 1/dy, 1/dz, and the shear's -dkx/dkz, -dky/dkz; 1/dkz is one of
        // the first three.
        let q = F4::new(1.0, 1.0, 1.0, -d[kx]).div(F4::new(d[0], d[1], d[2], d[kz]));
        let sy = -d[ky] / d[kz];
        let q = q.to_array();
        RayData {
            o: o.map(F4::splat),
            inv: [q[0], q[1], q[2]].map(F4::splat),
            near: [neg[0], 2 + neg[1], 4 + neg[2]],
            far: [1 - neg[0], 3 - neg[1], 5 - neg[2]],
            k: [kx, ky, kz],
            s: [F4::splat(q[3]), F4::splat(sy), F4::splat(q[kz])],
        }
    }

    /// Mask of the children whose box the segment `[0, t_max]` enters, and their entry
    /// distances. A NaN slab distance (origin on a plane of a box the ray runs parallel to)
    /// leaves the interval as it was, so that case counts as inside.
    #[inline(always)]
    fn node(&self, n: &Node4, t_max: f32) -> (u32, F4) {
        let slab = |i: usize, a: usize| F4::from_array(n.b[i]).sub(self.o[a]).mul(self.inv[a]);
        let tn = slab(self.near[2], 2).max_into(
            slab(self.near[1], 1).max_into(slab(self.near[0], 0).max_into(F4::splat(0.0))),
        );
        let tf = slab(self.far[2], 2).min_into(
            slab(self.far[1], 1).min_into(slab(self.far[0], 0).min_into(F4::splat(t_max))),
        );
        (tn.le(tf.mul(F4::splat(robust()))), tn)
    }

    /// Woop, Benthin and Wald 2013 on four triangles, in pbrt-v4's form (§6.5.3) with its
    /// conservative `t > 0` bound (§6.8.7): a ray spawned from a triangle's surface never
    /// re-hits it at `t ~ 0`. Edge functions are evaluated on the sheared vertices, which
    /// depend only on the ray and the vertex, so two triangles sharing an edge see the same
    /// values with opposite signs and no ray passes between them. Returns the mask of lanes
    /// hit with `0 < t < t_max`, and their `t`.
    #[inline(always)]
    fn tri4(&self, tri: &Tri4, t_max: f32) -> (u32, [f32; 4]) {
        let [kx, ky, kz] = self.k;
        let [sx, sy, sz] = self.s;
        let vert = |j: usize| {
            let z = F4::from_array(tri.v[j][kz]).sub(self.o[kz]);
            let x = F4::from_array(tri.v[j][kx]).sub(self.o[kx]).add(sx.mul(z));
            let y = F4::from_array(tri.v[j][ky]).sub(self.o[ky]).add(sy.mul(z));
            (x, y, z)
        };
        let (x0, y0, z0) = vert(0);
        let (x1, y1, z1) = vert(1);
        let (x2, y2, z2) = vert(2);
        let mut e0 = x1.mul(y2).sub(y1.mul(x2));
        let mut e1 = x2.mul(y0).sub(y2.mul(x0));
        let mut e2 = x0.mul(y1).sub(y0.mul(x1));
        let zero = F4::splat(0.0);
        let on_edge = e0.eq(zero) | e1.eq(zero) | e2.eq(zero);
        if on_edge != 0 {
            // An edge function rounded to zero: redo it in f64, where the products of two
            // f32 are exact (Woop et al. 2013 §4.1).
            [e0, e1, e2] = edges_f64(on_edge, [x0, x1, x2], [y0, y1, y2], [e0, e1, e2]);
        }
        let neg = e0.lt(zero) | e1.lt(zero) | e2.lt(zero);
        let pos = zero.lt(e0) | zero.lt(e1) | zero.lt(e2);
        let det = e0.add(e1).add(e2);
        let mut mask = !(neg & pos) & !det.eq(zero) & 0xf;
        if mask == 0 {
            return (0, [0.0; 4]);
        }
        let (z0, z1, z2) = (z0.mul(sz), z1.mul(sz), z2.mul(sz));
        let ts = e0.mul(z0).add(e1.mul(z1)).add(e2.mul(z2));
        let tmd = F4::splat(t_max).mul(det);
        let dneg = det.lt(zero);
        mask &= (dneg & ts.lt(zero) & tmd.le(ts)) | (!dneg & zero.lt(ts) & ts.le(tmd));
        if mask == 0 {
            return (0, [0.0; 4]);
        }
        // pbrt-v4's conservative bound on the error of t (§6.8.7), multiplied through by |det|
        // so that the test `dt < t` waits for no division, and with its terms gathered
        // (the bound's dependency chain was 13% of an incoherent ray in `bench-rays`):
        // dz = g3 max_z, dx = g5 (max_x + max_z), dy = g5 (max_y + max_z),
        // de = 2 (g2 max_x max_y + dy max_x + dx max_y)
        //    = 2 ((g2 + 2 g5) max_x max_y + g5 max_z (max_x + max_y)),
        // dt |det| = 3 (g3 max_e max_z + de max_z + dz max_e) = 3 max_z (2 g3 max_e + de).
        let max3 = |a: F4, b: F4, c: F4| a.abs().max_into(b.abs().max_into(c.abs()));
        let max_z = max3(z0, z1, z2);
        let max_x = max3(x0, x1, x2);
        let max_y = max3(y0, y1, y2);
        let max_e = max3(e0, e1, e2);
        let g = |n: i32| F4::splat(gamma(n));
        let de_half = g(2)
            .add(F4::splat(2.0).mul(g(5)))
            .mul(max_x.mul(max_y))
            .add(g(5).mul(max_z).mul(max_x.add(max_y)));
        let dt_det = F4::splat(6.0).mul(max_z).mul(g(3).mul(max_e).add(de_half));
        // ts carries the sign of det in every lane still in the mask.
        mask &= dt_det.lt(ts.abs());
        if mask == 0 {
            return (0, [0.0; 4]);
        }
        let t = ts.div(det);
        mask &= t.lt(F4::splat(t_max));
        (mask, t.to_array())
    }
}

#[cold]
#[inline(never)]
fn edges_f64(lanes: u32, x: [F4; 3], y: [F4; 3], e: [F4; 3]) -> [F4; 3] {
    let x = x.map(|v| v.to_array());
    let y = y.map(|v| v.to_array());
    let mut e = e.map(|v| v.to_array());
    for l in (0..4).filter(|l| lanes & (1 << l) != 0) {
        let f = |a: usize, b: usize| {
            let (xa, ya, xb, yb) = (
                x[a][l] as f64,
                y[a][l] as f64,
                x[b][l] as f64,
                y[b][l] as f64,
            );
            (xa * yb - ya * xb) as f32
        };
        e[0][l] = f(1, 2);
        e[1][l] = f(2, 0);
        e[2][l] = f(0, 1);
    }
    e.map(F4::from_array)
}

/// Traversal stack entry: child reference and the distance at which the ray enters it.
type Entry = (u32, f32);

/// Ordered traversal's step at an inner node (Wald et al. 2008, "Getting rid of packets"):
/// of the children in `mask` (at least one), entered at distances `tn`, returns the nearest
/// to visit next and pushes the others onto `stack` far to near, ties to the later child.
/// Shared by the BVH4 and the BVH8 (`crates/geom/src/bvh8.rs`), so both visit in one order.
#[inline(always)]
pub(crate) fn visit_ordered(
    mask: u32,
    tn: &[f32],
    child: &[u32],
    stack: &mut [Entry],
    sp: &mut usize,
) -> u32 {
    if mask & (mask - 1) == 0 {
        return child[mask.trailing_zeros() as usize];
    }
    let rest = mask & (mask - 1);
    if rest & (rest - 1) == 0 {
        // Two children, the common case: one comparison.
        let (i, j) = (
            mask.trailing_zeros() as usize,
            rest.trailing_zeros() as usize,
        );
        let (near, far) = if tn[i] < tn[j] { (i, j) } else { (j, i) };
        stack[*sp] = (child[far], tn[far]);
        *sp += 1;
        return child[near];
    }
    let mut c = [(0u32, 0f32); 8];
    let mut k = 0;
    let mut m = mask;
    while m != 0 {
        let i = m.trailing_zeros() as usize;
        m &= m - 1;
        let e = (child[i], tn[i]);
        // Insertion sort, farthest first.
        let mut j = k;
        while j > 0 && c[j - 1].1 < e.1 {
            c[j] = c[j - 1];
            j -= 1;
        }
        c[j] = e;
        k += 1;
    }
    stack[*sp..*sp + k - 1].copy_from_slice(&c[..k - 1]);
    *sp += k - 1;
    c[k - 1].0
}

/// Stack size that covers every BVH whose traversal needs at most this many entries;
/// deeper ones (degenerate input) use a heap stack.
const INLINE_STACK: usize = 40;

thread_local! {
    static STACK: std::cell::RefCell<[Entry; INLINE_STACK]> =
        const { std::cell::RefCell::new([(0, 0.0); INLINE_STACK]) };
    static ANY_STACK: std::cell::RefCell<[u32; INLINE_STACK]> =
        const { std::cell::RefCell::new([0; INLINE_STACK]) };
}

impl Bvh4 {
    /// `None` when there is nothing to index.
    pub(crate) fn build(
        mesh: &TriMesh,
        spheres: &[Sphere],
        params: BvhBuildParams,
    ) -> Option<Bvh4> {
        let n_tri = mesh.len();
        let bvh2 = binary_bvh(mesh, spheres, params)?;
        let nodes = ploc::compact(bvh2);
        let b = Builder {
            choice: (0..nodes.len()).map(|_| AtomicU16::new(0)).collect(),
            size: (0..nodes.len()).map(|_| AtomicU64::new(0)).collect(),
            bvh2: &nodes,
            n_tri: n_tri as u32,
        };
        let mut out = b.collapse();
        drop(nodes);
        // Each block's vertices from the mesh, in parallel: blocks are independent, so the
        // result does not depend on the thread count.
        out.tris = out
            .ids
            .par_iter()
            .map(|ids| {
                let mut tri = Tri4 {
                    v: [[[0.0; 4]; 3]; 3],
                };
                for (l, &id) in ids.iter().enumerate() {
                    for (j, v) in mesh.vertices(id as usize).iter().enumerate() {
                        for a in 0..3 {
                            tri.v[j][a][l] = v[a];
                        }
                    }
                }
                tri
            })
            .collect();
        Some(out)
    }

    /// Closest hit with `0 < t < ray.t_max`.
    #[inline]
    pub(crate) fn intersect(&self, ray: &Ray, spheres: &[Sphere]) -> Option<(f32, Prim)> {
        if self.stack_need <= INLINE_STACK {
            // A per-thread stack: a fresh one would be zeroed on every ray (a 320-byte
            // memset, ~5% of an incoherent ray's time in `bench-rays`).
            STACK.with_borrow_mut(|stack| self.closest(ray, spheres, stack))
        } else {
            self.closest(ray, spheres, &mut vec![(0, 0.0); self.stack_need])
        }
    }

    /// True if anything is hit with `0 < t < ray.t_max`; stops at the first hit.
    #[inline]
    pub(crate) fn occluded(&self, ray: &Ray, spheres: &[Sphere]) -> bool {
        if self.stack_need <= INLINE_STACK {
            ANY_STACK.with_borrow_mut(|stack| self.any(ray, spheres, stack))
        } else {
            self.any(ray, spheres, &mut vec![0; self.stack_need])
        }
    }

    /// Every primitive tested with the same tests as traversal: the reference for it.
    pub(crate) fn brute_force(&self, ray: &Ray, spheres: &[Sphere]) -> Option<(f32, Prim)> {
        let r = RayData::new(ray);
        let mut best = ray.t_max;
        let mut hit = None;
        for (i, s) in spheres.iter().enumerate() {
            if let Some(t) = s.intersect(&Ray {
                t_max: best,
                ..*ray
            }) {
                best = t;
                hit = Some(Prim::Sphere(i as u32));
            }
        }
        for b in 0..self.tris.len() {
            self.leaf_block(&r, b, &mut best, &mut hit);
        }
        hit.map(|p| (best, p))
    }

    #[inline(always)]
    fn leaf_block(&self, r: &RayData, b: usize, best: &mut f32, hit: &mut Option<Prim>) {
        let (mut m, t) = r.tri4(&self.tris[b], *best);
        while m != 0 {
            let l = m.trailing_zeros() as usize;
            m &= m - 1;
            if t[l] < *best {
                *best = t[l];
                *hit = Some(Prim::Triangle(self.ids[b][l]));
            }
        }
    }

    #[inline(always)]
    fn leaf(
        &self,
        r: &RayData,
        ray: &Ray,
        spheres: &[Sphere],
        c: u32,
        best: &mut f32,
        hit: &mut Option<Prim>,
    ) {
        if c & SPHERE != 0 {
            let i = c & !(LEAF | SPHERE);
            if let Some(t) = spheres[i as usize].intersect(&Ray {
                t_max: *best,
                ..*ray
            }) {
                *best = t;
                *hit = Some(Prim::Sphere(i));
            }
        } else {
            let first = (c & FIRST_MASK) as usize;
            let n = ((c & !LEAF) >> COUNT_SHIFT) as usize;
            for b in first..first + n {
                self.leaf_block(r, b, best, hit);
            }
        }
    }

    #[inline(always)]
    fn closest(&self, ray: &Ray, spheres: &[Sphere], stack: &mut [Entry]) -> Option<(f32, Prim)> {
        let r = RayData::new(ray);
        let mut best = ray.t_max;
        let mut hit = None;
        let mut sp = 0;
        let mut cur = self.root;
        loop {
            if cur & LEAF == 0 {
                let n = &self.nodes[cur as usize];
                let (mask, tn) = r.node(n, best);
                if mask != 0 {
                    cur = visit_ordered(mask, &tn.to_array(), &n.child, stack, &mut sp);
                    continue;
                }
            } else {
                self.leaf(&r, ray, spheres, cur, &mut best, &mut hit);
            }
            // Pop the next entry the ray still reaches before its closest hit so far.
            let limit = best * robust();
            loop {
                if sp == 0 {
                    return hit.map(|p| (best, p));
                }
                sp -= 1;
                if stack[sp].1 <= limit {
                    cur = stack[sp].0;
                    break;
                }
            }
        }
    }

    #[inline(always)]
    fn any(&self, ray: &Ray, spheres: &[Sphere], stack: &mut [u32]) -> bool {
        let r = RayData::new(ray);
        let mut sp = 0;
        let mut cur = self.root;
        loop {
            if cur & LEAF == 0 {
                let n = &self.nodes[cur as usize];
                let (mut mask, _) = r.node(n, ray.t_max);
                if mask != 0 {
                    cur = n.child[mask.trailing_zeros() as usize];
                    mask &= mask - 1;
                    while mask != 0 {
                        stack[sp] = n.child[mask.trailing_zeros() as usize];
                        sp += 1;
                        mask &= mask - 1;
                    }
                    continue;
                }
            } else {
                let mut best = ray.t_max;
                let mut hit = None;
                self.leaf(&r, ray, spheres, cur, &mut best, &mut hit);
                if hit.is_some() {
                    return true;
                }
            }
            if sp == 0 {
                return false;
            }
            sp -= 1;
            cur = stack[sp];
        }
    }
}

/// Relative costs of the collapse's surface area heuristic, per unit of area: visiting a node
/// (one 4-wide box test), testing a leaf block (four triangles) or a sphere. A block costing
/// 1, 2 or 3 node visits measured the same in `bench-rays` (pinned, 5 alternating rounds).
pub(crate) const COST_NODE: f64 = 1.0;
pub(crate) const COST_BLOCK: f64 = 1.0;
pub(crate) const COST_SPHERE: f64 = 1.0;

/// What the collapse decided for one Bvh2 node and a number of slots.
#[derive(Clone, Copy, Default)]
enum Choice {
    /// One slot: the subtree becomes one leaf.
    #[default]
    Leaf,
    /// One slot: the subtree becomes one 4-wide node whose children are the forests of
    /// `left` in `k` slots and `right` in `4 - k`.
    Node(u8),
    /// `i` slots: `left` fills `k` of them and `right` the rest.
    Split(u8),
    /// `i` slots: no better than `i - 1` slots.
    Fewer,
}

/// Primitives above which the second reinsertion searches as many candidates as the first,
/// not twice as many (obvhs' `medium_build`): on `bench-load`'s 4M-triangle mesh that is 38%
/// less search time for a collapsed BVH of 0.13% higher SAH cost, its path-traced render time
/// within noise. Smaller scenes, whose build is short anyway, keep obvhs' steps.
const LARGE: usize = 1 << 21;

/// The obvhs `Bvh2` the collapse starts from: triangles, then spheres, one primitive per
/// leaf (the collapse forms the leaves, and keeps spheres out of triangle blocks). `None`
/// when there is nothing to index.
///
/// The steps of obvhs' `build_bvh2` (obvhs 0.4, its `bvh2` builder: PLOC, reinsertion,
/// collapse, reinsertion) with PLOC's leaves written straight from the mesh, not from a list
/// of boxes the builder copies, PLOC itself run over lean buffers and both PLOC and the
/// reinsertions' searches on every core (`crates/geom/src/ploc.rs`): the same `Bvh2` for any
/// thread count, which `crates/geom/src/tests/bvh4.rs` checks against `build_bvh2`, up to
/// `LARGE` primitives.
pub(crate) fn binary_bvh(
    mesh: &TriMesh,
    spheres: &[Sphere],
    params: BvhBuildParams,
) -> Option<Bvh2> {
    let n = mesh.len() + spheres.len();
    if n == 0 {
        return None;
    }
    let mut bvh = Bvh2::zeroed(n);
    bvh.reset_for_reuse(n, Some((0..n as u32).collect()));
    let leaves: Vec<Work> = (0..n)
        .into_par_iter()
        .map(|i| Work::leaf(prim_box(mesh, spheres, i), i as u32))
        .collect();
    // Minima and maxima, exact in any order.
    let total = leaves
        .par_iter()
        .map(Work::aabb)
        .reduce(Aabb::empty, |a, b| a.union(&b));
    let (precision, depth) = (params.sort_precision, params.search_depth_threshold);
    let b = &mut bvh;
    match params.ploc_search_distance {
        PlocSearchDistance::Minimum => ploc::build::<1>(b, leaves, total, precision, depth),
        PlocSearchDistance::VeryLow => ploc::build::<2>(b, leaves, total, precision, depth),
        PlocSearchDistance::Low => ploc::build::<6>(b, leaves, total, precision, depth),
        PlocSearchDistance::Medium => ploc::build::<14>(b, leaves, total, precision, depth),
        PlocSearchDistance::High => ploc::build::<24>(b, leaves, total, precision, depth),
        PlocSearchDistance::VeryHigh => ploc::build::<32>(b, leaves, total, precision, depth),
    }
    ploc::reinsert(&mut bvh, params.reinsertion_batch_ratio);
    // One primitive per leaf: the collapse forms the leaves, and obvhs' leaf collapse between
    // the two reinsertions leaves such a tree as it is.
    let second = if n > LARGE {
        params.reinsertion_batch_ratio
    } else {
        params.reinsertion_batch_ratio * params.post_collapse_reinsertion_batch_ratio_multiplier
    };
    ploc::reinsert(&mut bvh, second);
    Some(bvh)
}

/// Each primitive's box: triangles, then spheres (the boxes obvhs' own build is given in the
/// tests).
#[cfg(test)]
pub(crate) fn prim_boxes<'a>(
    mesh: &'a TriMesh,
    spheres: &'a [Sphere],
) -> impl Iterator<Item = Aabb> + 'a {
    (0..mesh.len() + spheres.len()).map(|i| prim_box(mesh, spheres, i))
}

/// Primitive `i`'s box: triangle `i`, or sphere `i - mesh.len()` (its f32 box widened by an
/// ulp so it contains the exact sphere).
fn prim_box(mesh: &TriMesh, spheres: &[Sphere], i: usize) -> Aabb {
    match i.checked_sub(mesh.len()) {
        None => {
            let [a, b, c] = mesh.vertices(i);
            Aabb::new(a.min(b).min(c).into(), a.max(b).max(c).into())
        }
        Some(s) => {
            let s = &spheres[s];
            let lo = (s.center - s.radius).to_array().map(next_down);
            let hi = (s.center + s.radius).to_array().map(next_up);
            Aabb::new(glam::Vec3A::from_array(lo), glam::Vec3A::from_array(hi))
        }
    }
}

/// Four choices in four bits each: the variant in two, `k` (at most 3) in the other two.
fn pack(c: [Choice; 4]) -> u16 {
    c.iter().enumerate().fold(0, |acc, (i, c)| {
        let bits = match *c {
            Choice::Leaf => 0,
            Choice::Node(k) => 1 | (k << 2),
            Choice::Split(k) => 2 | (k << 2),
            Choice::Fewer => 3,
        };
        acc | (bits as u16) << (4 * i)
    })
}

/// The choice for `i` slots (1 to 4) out of `pack`'s four.
fn unpack(p: u16, i: usize) -> Choice {
    let bits = (p >> (4 * (i - 1))) as u8 & 0xf;
    match bits & 3 {
        0 => Choice::Leaf,
        1 => Choice::Node(bits >> 2),
        2 => Choice::Split(bits >> 2),
        _ => Choice::Fewer,
    }
}

struct Builder<'a> {
    /// The `Bvh2`'s nodes, 32 bytes each.
    bvh2: &'a [ploc::Node2],
    /// Primitives `0..n_tri` are triangles, the rest spheres.
    n_tri: u32,
    /// Per Bvh2 node and slot count `i` (index `i - 1`): the choice that reaches the least
    /// SAH cost of the subtree as a forest of at most `i` subtrees. The costs themselves
    /// travel up the recursion: a node's are read by its parent only. Packed by `pack`.
    /// Atomic only so that subtrees fill it on several threads (each its own entries).
    choice: Vec<AtomicU16>,
    /// Per Bvh2 node: the nodes and leaf blocks its one-slot choice emits, so that subtrees
    /// are emitted on several threads each into its own part of the output.
    size: Vec<AtomicU64>,
}

/// Depths (of the Bvh2 in `optimize`, of the 4-wide BVH in `emit`) above which subtrees go
/// to other threads: thousands of tasks, each of them a subtree large enough to be worth one.
const PAR_DEPTH_BVH2: usize = 12;
const PAR_DEPTH_BVH4: usize = 6;

/// Nodes and leaf blocks a subtree emits.
#[derive(Clone, Copy, Default)]
struct Size {
    nodes: u32,
    blocks: u32,
}

impl Add for Size {
    type Output = Size;
    fn add(self, o: Size) -> Size {
        Size {
            nodes: self.nodes + o.nodes,
            blocks: self.blocks + o.blocks,
        }
    }
}

/// What `optimize` hands up: the subtree's primitive count, whether it holds a sphere, and
/// per slot count its least cost and the size of the forest that reaches it.
struct Optimum {
    count: u32,
    sphere: bool,
    cost: [f64; 4],
    size: [Size; 4],
}

impl Builder<'_> {
    /// The collapsed BVH: its nodes and its blocks' triangle ids, the blocks' vertices not yet
    /// written. The choices are freed with the builder.
    fn collapse(self) -> Bvh4 {
        let size = self.optimize(0, 0).size[0];
        let mut nodes = vec![
            Node4 {
                b: [
                    [f32::INFINITY; 4],
                    [f32::NEG_INFINITY; 4],
                    [f32::INFINITY; 4],
                    [f32::NEG_INFINITY; 4],
                    [f32::INFINITY; 4],
                    [f32::NEG_INFINITY; 4],
                ],
                child: [EMPTY; 4],
            };
            size.nodes as usize
        ];
        let mut ids = vec![[0; 4]; size.blocks as usize];
        assert!(
            size.blocks <= FIRST_MASK + 1,
            "too many triangles for the BVH4 leaf encoding"
        );
        let (root, depth) = self.emit(0, &mut nodes, 0, &mut ids, 0, 0);
        Bvh4 {
            nodes,
            tris: Vec::new(),
            ids,
            root,
            stack_need: 3 * depth + 1,
        }
    }

    fn children(&self, ni: usize) -> Option<(usize, usize)> {
        self.bvh2[ni].children()
    }

    fn choice(&self, ni: usize, i: usize) -> Choice {
        unpack(self.choice[ni].load(Ordering::Relaxed), i)
    }

    fn size(&self, ni: usize) -> Size {
        let s = self.size[ni].load(Ordering::Relaxed);
        Size {
            nodes: s as u32,
            blocks: (s >> 32) as u32,
        }
    }

    /// The optimal collapse of a binary BVH into a wide one by dynamic programming over
    /// (node, slots), Ylitie, Karras and Laine, "Efficient Incoherent Ray Traversal on GPUs
    /// Through Compressed Wide BVHs" (HPG 2017) §4.1, with our leaf rule: one sphere, or up
    /// to `LEAF_MAX` triangles. `depth` is `ni`'s in the Bvh2. Subtrees are independent, so
    /// the choices do not depend on the thread count.
    fn optimize(&self, ni: usize, depth: usize) -> Optimum {
        let node = self.bvh2[ni];
        let area = node.aabb().half_area() as f64;
        let Some((l, r)) = self.children(ni) else {
            let p = node.prim;
            let is_sphere = p >= self.n_tri;
            let c = area * if is_sphere { COST_SPHERE } else { COST_BLOCK };
            let size = Size {
                nodes: 0,
                blocks: !is_sphere as u32,
            };
            self.set(ni, [Choice::Leaf; 4], size);
            return Optimum {
                count: 1,
                sphere: is_sphere,
                cost: [c; 4],
                size: [size; 4],
            };
        };
        let (a, b) = if depth < PAR_DEPTH_BVH2 {
            rayon::join(
                || self.optimize(l, depth + 1),
                || self.optimize(r, depth + 1),
            )
        } else {
            (self.optimize(l, depth + 1), self.optimize(r, depth + 1))
        };
        let (count, sphere) = (a.count + b.count, a.sphere || b.sphere);
        // Best split of `i` slots between the two children.
        let split = |i: usize| {
            (1..i)
                .map(|k| (a.cost[k - 1] + b.cost[i - k - 1], k as u8))
                .min_by(|a, b| a.0.total_cmp(&b.0))
                .expect("i >= 2")
        };
        let parts = |k: u8, i: usize| a.size[k as usize - 1] + b.size[i - k as usize - 1];
        let (inner, k) = split(4);
        let one = Size {
            nodes: 1,
            blocks: 0,
        };
        let mut best = (area * COST_NODE + inner, Choice::Node(k), one + parts(k, 4));
        if !sphere && count <= LEAF_MAX {
            let blocks = count.div_ceil(4);
            let leaf = area * COST_BLOCK * blocks as f64;
            if leaf <= best.0 {
                best = (leaf, Choice::Leaf, Size { nodes: 0, blocks });
            }
        }
        let mut cost = [best.0; 4];
        let mut choice = [best.1; 4];
        let mut size = [best.2; 4];
        for i in 2..=4 {
            let (c, k) = split(i);
            (cost[i - 1], choice[i - 1], size[i - 1]) = if c < cost[i - 2] {
                (c, Choice::Split(k), parts(k, i))
            } else {
                (cost[i - 2], Choice::Fewer, size[i - 2])
            };
        }
        self.set(ni, choice, size[0]);
        Optimum {
            count,
            sphere,
            cost,
            size,
        }
    }

    fn set(&self, ni: usize, choice: [Choice; 4], size: Size) {
        self.choice[ni].store(pack(choice), Ordering::Relaxed);
        let s = size.nodes as u64 | (size.blocks as u64) << 32;
        self.size[ni].store(s, Ordering::Relaxed);
    }

    /// The roots of the forest that stands for subtree `ni` in `i` slots, appended to
    /// `out[..*len]`.
    fn forest(&self, ni: usize, i: usize, out: &mut [usize; 4], len: &mut usize) {
        match self.choice(ni, i) {
            Choice::Leaf | Choice::Node(_) => {
                out[*len] = ni;
                *len += 1;
            }
            Choice::Fewer => self.forest(ni, i - 1, out, len),
            Choice::Split(k) => {
                let (l, r) = self.children(ni).expect("a split node has children");
                self.forest(l, k as usize, out, len);
                self.forest(r, i - k as usize, out, len);
            }
        }
    }

    /// The primitives under `ni`, appended to `out[..*len]` (a leaf holds at most
    /// `LEAF_MAX`).
    fn prims(&self, ni: usize, out: &mut [u32; LEAF_MAX as usize], len: &mut usize) {
        match self.children(ni) {
            None => {
                out[*len] = self.bvh2[ni].prim;
                *len += 1;
            }
            Some((l, r)) => {
                self.prims(l, out, len);
                self.prims(r, out, len);
            }
        }
    }

    /// Emits the subtree under Bvh2 node `ni` as its one-slot choice into `nodes` and `ids`,
    /// exactly its size (`size`), whose first entries are numbers `node_base` and
    /// `block_base` of the output; returns its reference and depth in nodes. The layout is
    /// depth first, a node before its children's subtrees in slot order, whatever the
    /// thread count: each subtree's part follows from the sizes.
    fn emit(
        &self,
        ni: usize,
        nodes: &mut [Node4],
        node_base: u32,
        ids: &mut [[u32; 4]],
        block_base: u32,
        depth: usize,
    ) -> (u32, usize) {
        let Choice::Node(k) = self.choice(ni, 1) else {
            let mut prims = [0; LEAF_MAX as usize];
            let mut len = 0;
            self.prims(ni, &mut prims, &mut len);
            if prims[0] >= self.n_tri {
                return (LEAF | SPHERE | (prims[0] - self.n_tri), 0);
            }
            // The blocks' triangles only: their vertices are written once the `Bvh2` is gone.
            let group = &prims[..len];
            for (block, group) in ids.iter_mut().zip(group.chunks(4)) {
                *block = std::array::from_fn(|l| group[l.min(group.len() - 1)]);
            }
            return (LEAF | ((ids.len() as u32) << COUNT_SHIFT) | block_base, 0);
        };
        let (l, r) = self.children(ni).expect("an inner node has children");
        let mut kids = [0; 4];
        let mut n = 0;
        self.forest(l, k as usize, &mut kids, &mut n);
        self.forest(r, 4 - k as usize, &mut kids, &mut n);
        let (node, mut rest_nodes) = nodes.split_first_mut().expect("sized by `optimize`");
        let mut rest_ids = ids;
        let (mut nb, mut bb) = (node_base + 1, block_base);
        let mut parts = Vec::with_capacity(n);
        for &kid in &kids[..n] {
            let s = self.size(kid);
            let (a, r) = std::mem::take(&mut rest_nodes).split_at_mut(s.nodes as usize);
            rest_nodes = r;
            let (b, r) = std::mem::take(&mut rest_ids).split_at_mut(s.blocks as usize);
            rest_ids = r;
            parts.push((kid, a, nb, b, bb));
            (nb, bb) = (nb + s.nodes, bb + s.blocks);
        }
        let emit = |(kid, a, nb, b, bb): (usize, &mut [Node4], u32, &mut [[u32; 4]], u32)| {
            self.emit(kid, a, nb, b, bb, depth + 1)
        };
        let refs: Vec<(u32, usize)> = if depth < PAR_DEPTH_BVH4 {
            parts.into_par_iter().map(emit).collect()
        } else {
            parts.into_iter().map(emit).collect()
        };
        let mut sub = 0;
        for (slot, (&kid, &(c, d))) in kids[..n].iter().zip(&refs).enumerate() {
            sub = sub.max(d);
            let bb = self.bvh2[kid].aabb();
            for a in 0..3 {
                node.b[2 * a][slot] = bb.min[a];
                node.b[2 * a + 1][slot] = bb.max[a];
            }
            node.child[slot] = c;
        }
        (node_base, sub + 1)
    }
}

/// A leaf block as the tests compare it: its triangle ids and vertices.
#[cfg(test)]
pub(crate) type Block = ([u32; 4], [[[f32; 4]; 3]; 3]);

#[cfg(test)]
impl Bvh4 {
    /// What the build decided besides the nodes, for the tests: root, stack need, and each
    /// block's triangle ids and vertices.
    pub(crate) fn built(&self) -> (u32, usize, Vec<Block>) {
        let blocks = self.ids.iter().zip(&self.tris).map(|(i, t)| (*i, t.v));
        (self.root, self.stack_need, blocks.collect())
    }
}
