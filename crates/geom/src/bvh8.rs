//! The vector path's structure: an 8-wide BVH traversed with AVX2, chosen at run time
//! (`crates/geom/src/isa.rs`). It collapses the same obvhs `Bvh2` as the BVH4
//! (`crates/geom/src/bvh4.rs`) with the same surface-area dynamic programme, widened to eight
//! slots (Wald, Benthin and Boulos 2008, "Getting rid of packets": one wide node test per
//! visit instead of ray packets). Nodes hold eight f32 child boxes in structure-of-arrays
//! layout, so one 8-lane compare per slab tests all children; leaves hold one sphere or up to
//! `LEAF_MAX` triangles in blocks of eight, tested in one pass.
//!
//! Each lane computes exactly what the BVH4's four-lane code computes (same operations in the
//! same order, no fused multiply-adds), so a triangle's `t` is the same bits on both paths;
//! only which of two primitives at an equal `t` wins may differ (the visiting order differs).

use crate::bvh4::{COUNT_SHIFT, EMPTY, LEAF, SPHERE, binary_bvh, visit_ordered};
use crate::float::gamma;
use crate::isa::Avx2;
use crate::ploc::{self, Node2};
use crate::{Prim, Ray, Sphere, TriMesh};
use core::arch::x86_64::*;
use obvhs::BvhBuildParams;
use rayon::prelude::*;
use std::sync::atomic::{AtomicU64, Ordering};

const FIRST_MASK: u32 = (1 << COUNT_SHIFT) - 1;

/// Largest triangle leaf: one block of eight. Two blocks (16), and block costs of 0.5 or 2,
/// measured within noise of this on three scenes in `bench-rays`; leaves of 4 were slower on
/// incoherent rays (docs/benchmarks.md, "vector path (AVX2) against the baseline").
pub(crate) const LEAF_MAX: u32 = 8;

/// Collapse costs per unit of area, as the BVH4's: an 8-wide node test, an 8-triangle block.
pub(crate) const COST_NODE: f64 = 1.0;
pub(crate) const COST_BLOCK: f64 = 1.0;
pub(crate) const COST_SPHERE: f64 = 1.0;

/// Eight children: boxes as `[min_x, max_x, min_y, max_y, min_z, max_z]`, eight lanes each.
/// An empty slot has an inverted (+inf, -inf) box, which no ray enters.
#[derive(Clone, Copy)]
#[repr(C, align(32))]
pub(crate) struct Node8 {
    pub(crate) b: [__m256; 6],
    pub(crate) child: [u32; 8],
}

/// Eight triangles, `v[vertex][axis]` with one lane per triangle. A partly filled block
/// repeats its last triangle, which can only return the same hit again.
#[derive(Clone, Copy)]
#[repr(C, align(32))]
struct Tri8 {
    v: [[__m256; 3]; 3],
}

pub(crate) struct Bvh8 {
    pub(crate) nodes: Vec<Node8>,
    tris: Vec<Tri8>,
    /// Triangle id (in the `TriMesh`) of each lane of `tris`.
    pub(crate) ids: Vec<[u32; 8]>,
    pub(crate) root: u32,
    /// Deepest stack a traversal can need (seven pushes per level below the root).
    stack_need: usize,
    isa: Avx2,
}

fn lanes_mut(v: &mut __m256) -> &mut [f32; 8] {
    bytemuck::cast_mut(v)
}

fn lanes(v: __m256) -> [f32; 8] {
    bytemuck::cast(v)
}

impl Bvh8 {
    /// `None` when there is nothing to index.
    pub(crate) fn build(
        mesh: &TriMesh,
        spheres: &[Sphere],
        params: BvhBuildParams,
        isa: Avx2,
    ) -> Option<Bvh8> {
        let bvh2 = binary_bvh(mesh, spheres, params)?;
        let nodes = ploc::compact(bvh2);
        let mut b = Builder8 {
            choice: (0..nodes.len()).map(|_| AtomicU64::new(0)).collect(),
            bvh2: &nodes,
            n_tri: mesh.len() as u32,
            nodes: Vec::new(),
            ids: Vec::new(),
        };
        b.optimize(0, 0);
        let (root, depth) = b.emit(0);
        let (nodes8, ids) = (b.nodes, b.ids);
        drop(nodes);
        let empty = bytemuck::cast([0f32; 8]);
        let tris = ids
            .par_iter()
            .map(|ids| {
                let mut tri = Tri8 { v: [[empty; 3]; 3] };
                for (l, &id) in ids.iter().enumerate() {
                    for (j, v) in mesh.vertices(id as usize).iter().enumerate() {
                        for a in 0..3 {
                            lanes_mut(&mut tri.v[j][a])[l] = v[a];
                        }
                    }
                }
                tri
            })
            .collect();
        Some(Bvh8 {
            nodes: nodes8,
            tris,
            ids,
            root,
            stack_need: 7 * depth + 1,
            isa,
        })
    }

    /// Closest hit with `0 < t < ray.t_max`.
    #[inline]
    pub(crate) fn intersect(&self, ray: &Ray, spheres: &[Sphere]) -> Option<(f32, Prim)> {
        if self.stack_need <= INLINE_STACK {
            STACK.with_borrow_mut(|stack| self.isa.closest(self, ray, spheres, stack))
        } else {
            let mut stack = vec![(0, 0.0); self.stack_need];
            self.isa.closest(self, ray, spheres, &mut stack)
        }
    }

    /// True if anything is hit with `0 < t < ray.t_max`; stops at the first hit.
    #[inline]
    pub(crate) fn occluded(&self, ray: &Ray, spheres: &[Sphere]) -> bool {
        if self.stack_need <= INLINE_STACK {
            ANY_STACK.with_borrow_mut(|stack| self.isa.any(self, ray, spheres, stack))
        } else {
            self.isa
                .any(self, ray, spheres, &mut vec![0; self.stack_need])
        }
    }

    /// Every primitive tested with traversal's tests: the reference for it.
    pub(crate) fn brute_force(&self, ray: &Ray, spheres: &[Sphere]) -> Option<(f32, Prim)> {
        self.isa.brute_force(self, ray, spheres)
    }
}

/// Traversal stack entry: child reference and the distance at which the ray enters it.
pub(crate) type Entry = (u32, f32);

/// Per-thread stack entries: enough for trees 36 nodes deep (`stack_need` is 7 per level);
/// deeper ones (degenerate input) use a heap stack. Never zeroed per ray, so its size costs
/// nothing.
const INLINE_STACK: usize = 256;

thread_local! {
    static STACK: std::cell::RefCell<[Entry; INLINE_STACK]> =
        const { std::cell::RefCell::new([(0, 0.0); INLINE_STACK]) };
    static ANY_STACK: std::cell::RefCell<[u32; INLINE_STACK]> =
        const { std::cell::RefCell::new([0; INLINE_STACK]) };
}

/// The AVX2 code. Every function here has `#[target_feature(enable = "avx2")]` and is called
/// only through `Avx2` (`crates/geom/src/isa.rs`), which exists once the processor is known
/// to have AVX2; inside them the value intrinsics are safe.
pub(crate) mod avx2 {
    use super::*;

    /// Ray constants splat over eight lanes: the same values as the BVH4's `RayData`
    /// (Williams et al. 2005 for the box test, Woop et al. 2013 §3 for the shear).
    struct RayData {
        o: [__m256; 3],
        inv: [__m256; 3],
        near: [usize; 3],
        far: [usize; 3],
        k: [usize; 3],
        s: [__m256; 3],
    }

    #[target_feature(enable = "avx2")]
    #[inline]
    fn ray_data(ray: &Ray) -> RayData {
        let d = ray.d.to_array();
        let o = ray.o.to_array();
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
        let inv = [1.0 / d[0], 1.0 / d[1], 1.0 / d[2]];
        RayData {
            o: o.map(|x| _mm256_set1_ps(x)),
            inv: inv.map(|x| _mm256_set1_ps(x)),
            near: [neg[0], 2 + neg[1], 4 + neg[2]],
            far: [1 - neg[0], 3 - neg[1], 5 - neg[2]],
            k: [kx, ky, kz],
            s: [-d[kx] / d[kz], -d[ky] / d[kz], inv[kz]].map(|x| _mm256_set1_ps(x)),
        }
    }

    #[target_feature(enable = "avx2")]
    #[inline]
    fn mask(v: __m256) -> u32 {
        _mm256_movemask_ps(v) as u32
    }

    #[target_feature(enable = "avx2")]
    #[inline]
    fn lt(a: __m256, b: __m256) -> u32 {
        mask(_mm256_cmp_ps::<_CMP_LT_OQ>(a, b))
    }

    #[target_feature(enable = "avx2")]
    #[inline]
    fn le(a: __m256, b: __m256) -> u32 {
        mask(_mm256_cmp_ps::<_CMP_LE_OQ>(a, b))
    }

    #[target_feature(enable = "avx2")]
    #[inline]
    fn eq(a: __m256, b: __m256) -> u32 {
        mask(_mm256_cmp_ps::<_CMP_EQ_OQ>(a, b))
    }

    #[target_feature(enable = "avx2")]
    #[inline]
    fn abs(a: __m256) -> __m256 {
        _mm256_andnot_ps(_mm256_set1_ps(-0.0), a)
    }

    /// `max(a, b)` per lane, `b` where `a` is NaN (`vmaxps` returns its second operand on
    /// NaN), as the BVH4's `max_into`.
    #[target_feature(enable = "avx2")]
    #[inline]
    fn max_into(a: __m256, acc: __m256) -> __m256 {
        _mm256_max_ps(a, acc)
    }

    #[target_feature(enable = "avx2")]
    #[inline]
    fn min_into(a: __m256, acc: __m256) -> __m256 {
        _mm256_min_ps(a, acc)
    }

    /// Mask of the children whose box the segment `[0, t_max]` enters, and their entry
    /// distances; Ize 2013's `1 + 2 gamma(3)` makes the far distance conservative. A macro:
    /// LLVM left a function call here, and `#[inline(always)]` cannot go with
    /// `#[target_feature]` on stable Rust.
    macro_rules! node {
        ($r:expr, $n:expr, $t_max:expr) => {{
            let (r, n): (&RayData, &Node8) = ($r, $n);
            let slab = |i: usize, a: usize| _mm256_mul_ps(_mm256_sub_ps(n.b[i], r.o[a]), r.inv[a]);
            let tn = max_into(
                slab(r.near[2], 2),
                max_into(
                    slab(r.near[1], 1),
                    max_into(slab(r.near[0], 0), _mm256_setzero_ps()),
                ),
            );
            let tf = min_into(
                slab(r.far[2], 2),
                min_into(
                    slab(r.far[1], 1),
                    min_into(slab(r.far[0], 0), _mm256_set1_ps($t_max)),
                ),
            );
            let robust = _mm256_set1_ps(1.0 + 2.0 * gamma(3));
            (le(tn, _mm256_mul_ps(tf, robust)), tn)
        }};
    }

    /// The BVH4's `tri4` on eight lanes: Woop, Benthin and Wald (JCGT 2013) in pbrt-v4's form
    /// with its conservative `t > 0` bound (§6.8.7). Mask of lanes hit with `0 < t < t_max`.
    #[target_feature(enable = "avx2")]
    #[inline]
    fn tri8(r: &RayData, tri: &Tri8, t_max: f32) -> (u32, __m256) {
        let [kx, ky, kz] = r.k;
        let [sx, sy, sz] = r.s;
        let vert = |j: usize| {
            let z = _mm256_sub_ps(tri.v[j][kz], r.o[kz]);
            let x = _mm256_add_ps(_mm256_sub_ps(tri.v[j][kx], r.o[kx]), _mm256_mul_ps(sx, z));
            let y = _mm256_add_ps(_mm256_sub_ps(tri.v[j][ky], r.o[ky]), _mm256_mul_ps(sy, z));
            (x, y, z)
        };
        let (x0, y0, z0) = vert(0);
        let (x1, y1, z1) = vert(1);
        let (x2, y2, z2) = vert(2);
        let cross = |xa, ya, xb, yb| _mm256_sub_ps(_mm256_mul_ps(xa, yb), _mm256_mul_ps(ya, xb));
        let mut e0 = cross(x1, y1, x2, y2);
        let mut e1 = cross(x2, y2, x0, y0);
        let mut e2 = cross(x0, y0, x1, y1);
        let zero = _mm256_setzero_ps();
        let on_edge = eq(e0, zero) | eq(e1, zero) | eq(e2, zero);
        if on_edge != 0 {
            [e0, e1, e2] = edges_f64(on_edge, [x0, x1, x2], [y0, y1, y2], [e0, e1, e2]);
        }
        let neg = lt(e0, zero) | lt(e1, zero) | lt(e2, zero);
        let pos = lt(zero, e0) | lt(zero, e1) | lt(zero, e2);
        let det = _mm256_add_ps(_mm256_add_ps(e0, e1), e2);
        let mut m = !(neg & pos) & !eq(det, zero) & 0xff;
        if m == 0 {
            return (0, zero);
        }
        let (z0, z1, z2) = (
            _mm256_mul_ps(z0, sz),
            _mm256_mul_ps(z1, sz),
            _mm256_mul_ps(z2, sz),
        );
        let ts = _mm256_add_ps(
            _mm256_add_ps(_mm256_mul_ps(e0, z0), _mm256_mul_ps(e1, z1)),
            _mm256_mul_ps(e2, z2),
        );
        let tmax = _mm256_set1_ps(t_max);
        let tmd = _mm256_mul_ps(tmax, det);
        let dneg = lt(det, zero);
        m &= (dneg & lt(ts, zero) & le(tmd, ts)) | (!dneg & lt(zero, ts) & le(ts, tmd));
        if m == 0 {
            return (0, zero);
        }
        // The BVH4's gathered form of pbrt-v4's bound on the error of t, times |det|.
        let max3 = |a, b, c| max_into(abs(a), max_into(abs(b), abs(c)));
        let max_z = max3(z0, z1, z2);
        let max_x = max3(x0, x1, x2);
        let max_y = max3(y0, y1, y2);
        let max_e = max3(e0, e1, e2);
        let g = |n: i32| _mm256_set1_ps(gamma(n));
        let de_half = _mm256_add_ps(
            _mm256_mul_ps(
                _mm256_add_ps(g(2), _mm256_mul_ps(_mm256_set1_ps(2.0), g(5))),
                _mm256_mul_ps(max_x, max_y),
            ),
            _mm256_mul_ps(_mm256_mul_ps(g(5), max_z), _mm256_add_ps(max_x, max_y)),
        );
        let dt_det = _mm256_mul_ps(
            _mm256_mul_ps(_mm256_set1_ps(6.0), max_z),
            _mm256_add_ps(_mm256_mul_ps(g(3), max_e), de_half),
        );
        m &= lt(dt_det, abs(ts));
        if m == 0 {
            return (0, zero);
        }
        let t = _mm256_div_ps(ts, det);
        m &= lt(t, tmax);
        (m, t)
    }

    /// Edge functions that rounded to zero, redone in f64 where the products of two f32 are
    /// exact (Woop et al. 2013 §4.1).
    #[cold]
    #[inline(never)]
    fn edges_f64(lanes_hit: u32, x: [__m256; 3], y: [__m256; 3], e: [__m256; 3]) -> [__m256; 3] {
        let x = x.map(lanes);
        let y = y.map(lanes);
        let mut e = e.map(lanes);
        for l in (0..8).filter(|l| lanes_hit & (1 << l) != 0) {
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
        e.map(bytemuck::cast)
    }

    #[target_feature(enable = "avx2")]
    #[inline]
    fn leaf_block(b: &Bvh8, r: &RayData, i: usize, best: &mut f32, hit: &mut Option<Prim>) {
        let (mut m, t) = tri8(r, &b.tris[i], *best);
        if m == 0 {
            return;
        }
        let t = lanes(t);
        while m != 0 {
            let l = m.trailing_zeros() as usize;
            m &= m - 1;
            if t[l] < *best {
                *best = t[l];
                *hit = Some(Prim::Triangle(b.ids[i][l]));
            }
        }
    }

    #[target_feature(enable = "avx2")]
    #[inline]
    fn leaf(
        b: &Bvh8,
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
            for i in first..first + n {
                leaf_block(b, r, i, best, hit);
            }
        }
    }

    #[target_feature(enable = "avx2")]
    pub(crate) fn closest(
        b: &Bvh8,
        ray: &Ray,
        spheres: &[Sphere],
        stack: &mut [Entry],
    ) -> Option<(f32, Prim)> {
        let r = ray_data(ray);
        let mut best = ray.t_max;
        let mut hit = None;
        let mut sp = 0;
        let mut cur = b.root;
        let robust = 1.0 + 2.0 * gamma(3);
        loop {
            if cur & LEAF == 0 {
                let n = &b.nodes[cur as usize];
                let (mask, tn) = node!(&r, n, best);
                if mask != 0 {
                    cur = visit_ordered(mask, &lanes(tn), &n.child, stack, &mut sp);
                    continue;
                }
            } else {
                leaf(b, &r, ray, spheres, cur, &mut best, &mut hit);
            }
            let limit = best * robust;
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

    #[target_feature(enable = "avx2")]
    pub(crate) fn any(b: &Bvh8, ray: &Ray, spheres: &[Sphere], stack: &mut [u32]) -> bool {
        let r = ray_data(ray);
        let mut sp = 0;
        let mut cur = b.root;
        loop {
            if cur & LEAF == 0 {
                let n = &b.nodes[cur as usize];
                let (mut mask, _) = node!(&r, n, ray.t_max);
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
                leaf(b, &r, ray, spheres, cur, &mut best, &mut hit);
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

    #[target_feature(enable = "avx2")]
    pub(crate) fn brute_force(b: &Bvh8, ray: &Ray, spheres: &[Sphere]) -> Option<(f32, Prim)> {
        let r = ray_data(ray);
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
        for i in 0..b.tris.len() {
            leaf_block(b, &r, i, &mut best, &mut hit);
        }
        hit.map(|p| (best, p))
    }
}

/// The BVH4's collapse (`crates/geom/src/bvh4.rs`, `Builder`) with eight slots: per Bvh2 node
/// and slot count, the choice of least SAH cost (Ylitie, Karras and Laine 2017 §4.1).
struct Builder8<'a> {
    bvh2: &'a [Node2],
    n_tri: u32,
    /// Per Bvh2 node, eight choices of eight bits (see `pack`); atomic so that subtrees are
    /// optimised on several threads (each node is written by one).
    choice: Vec<AtomicU64>,
    nodes: Vec<Node8>,
    ids: Vec<[u32; 8]>,
}

/// Bvh2 depth above which `optimize` splits its work between threads.
const PAR_DEPTH: usize = 12;

#[derive(Clone, Copy)]
enum Choice {
    Leaf,
    /// One slot: an 8-wide node with `left` in `k` slots and `right` in `8 - k`.
    Node(u8),
    /// `left` in `k` of the slots, `right` in the rest.
    Split(u8),
    /// No better than one slot fewer.
    Fewer,
}

fn pack(c: [Choice; 8]) -> u64 {
    c.iter().enumerate().fold(0, |acc, (i, c)| {
        let bits = match *c {
            Choice::Leaf => 0,
            Choice::Node(k) => 1 | (k << 2),
            Choice::Split(k) => 2 | (k << 2),
            Choice::Fewer => 3,
        };
        acc | (bits as u64) << (8 * i)
    })
}

fn unpack(p: u64, i: usize) -> Choice {
    let bits = (p >> (8 * (i - 1))) as u8;
    match bits & 3 {
        0 => Choice::Leaf,
        1 => Choice::Node(bits >> 2),
        2 => Choice::Split(bits >> 2),
        _ => Choice::Fewer,
    }
}

impl Builder8<'_> {
    /// Primitive count, whether a sphere is under `ni`, and the least cost in 1 to 8 slots.
    /// Subtrees above depth `PAR_DEPTH` run on every core: the choices do not depend on it.
    fn optimize(&self, ni: usize, depth: usize) -> (u32, bool, [f64; 8]) {
        let node = self.bvh2[ni];
        let area = node.aabb().half_area() as f64;
        let Some((l, r)) = node.children() else {
            let is_sphere = node.prim >= self.n_tri;
            let c = area * if is_sphere { COST_SPHERE } else { COST_BLOCK };
            self.choice[ni].store(pack([Choice::Leaf; 8]), Ordering::Relaxed);
            return (1, is_sphere, [c; 8]);
        };
        let ((nl, sl, cl), (nr, sr, cr)) = if depth < PAR_DEPTH {
            rayon::join(
                || self.optimize(l, depth + 1),
                || self.optimize(r, depth + 1),
            )
        } else {
            (self.optimize(l, depth + 1), self.optimize(r, depth + 1))
        };
        let (count, sphere) = (nl + nr, sl || sr);
        let split = |i: usize| {
            (1..i)
                .map(|k| (cl[k - 1] + cr[i - k - 1], k as u8))
                .min_by(|a, b| a.0.total_cmp(&b.0))
                .expect("i >= 2")
        };
        let (inner, k) = split(8);
        let mut best = (area * COST_NODE + inner, Choice::Node(k));
        if !sphere && count <= LEAF_MAX {
            let leaf = area * COST_BLOCK * count.div_ceil(8) as f64;
            if leaf <= best.0 {
                best = (leaf, Choice::Leaf);
            }
        }
        let mut cost = [best.0; 8];
        let mut choice = [best.1; 8];
        for i in 2..=8 {
            let (c, k) = split(i);
            (cost[i - 1], choice[i - 1]) = if c < cost[i - 2] {
                (c, Choice::Split(k))
            } else {
                (cost[i - 2], Choice::Fewer)
            };
        }
        self.choice[ni].store(pack(choice), Ordering::Relaxed);
        (count, sphere, cost)
    }

    fn forest(&self, ni: usize, i: usize, out: &mut Vec<usize>) {
        match unpack(self.choice[ni].load(Ordering::Relaxed), i) {
            Choice::Leaf | Choice::Node(_) => out.push(ni),
            Choice::Fewer => self.forest(ni, i - 1, out),
            Choice::Split(k) => {
                let (l, r) = self.bvh2[ni].children().expect("a split node has children");
                self.forest(l, k as usize, out);
                self.forest(r, i - k as usize, out);
            }
        }
    }

    fn prims(&self, ni: usize, out: &mut Vec<u32>) {
        match self.bvh2[ni].children() {
            None => out.push(self.bvh2[ni].prim),
            Some((l, r)) => {
                self.prims(l, out);
                self.prims(r, out);
            }
        }
    }

    /// Emits subtree `ni` as its one-slot choice; its reference and depth in nodes.
    fn emit(&mut self, ni: usize) -> (u32, usize) {
        let Choice::Node(k) = unpack(self.choice[ni].load(Ordering::Relaxed), 1) else {
            let mut prims = Vec::new();
            self.prims(ni, &mut prims);
            if prims[0] >= self.n_tri {
                return (LEAF | SPHERE | (prims[0] - self.n_tri), 0);
            }
            let first = self.ids.len() as u32;
            for group in prims.chunks(8) {
                self.ids
                    .push(std::array::from_fn(|l| group[l.min(group.len() - 1)]));
            }
            let blocks = self.ids.len() as u32 - first;
            assert!(
                first <= FIRST_MASK,
                "too many triangles for the BVH8 leaf encoding"
            );
            return (LEAF | (blocks << COUNT_SHIFT) | first, 0);
        };
        let (l, r) = self.bvh2[ni]
            .children()
            .expect("an inner node has children");
        let mut kids = Vec::with_capacity(8);
        self.forest(l, k as usize, &mut kids);
        self.forest(r, 8 - k as usize, &mut kids);
        let idx = self.nodes.len();
        let (inf, ninf) = (
            bytemuck::cast([f32::INFINITY; 8]),
            bytemuck::cast([f32::NEG_INFINITY; 8]),
        );
        self.nodes.push(Node8 {
            b: [inf, ninf, inf, ninf, inf, ninf],
            child: [EMPTY; 8],
        });
        let mut depth = 0;
        for (slot, &k) in kids.iter().enumerate() {
            let (c, d) = self.emit(k);
            depth = depth.max(d);
            let bb = self.bvh2[k].aabb();
            let n = &mut self.nodes[idx];
            for a in 0..3 {
                lanes_mut(&mut n.b[2 * a])[slot] = bb.min[a];
                lanes_mut(&mut n.b[2 * a + 1])[slot] = bb.max[a];
            }
            n.child[slot] = c;
        }
        (idx as u32, depth + 1)
    }
}
