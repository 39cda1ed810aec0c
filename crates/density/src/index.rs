//! k-nearest search under a maximum radius, three interchangeable back-ends (a closed enum,
//! style anchor A1.1): our own kd-tree, kiddo's immutable tree, and brute force (the reference).
//!
//! Every back-end returns the same answer: the `k` points with the smallest key
//! `(d2, index)` among those with `d2 <= r_max^2`, sorted by that key. Ties at the k-th
//! distance are therefore broken by the smaller index, identically everywhere, so the tests
//! can demand exact equality with brute force.

use glam::Vec3;
use kiddo::SquaredEuclidean;
use kiddo::immutable::float::kdtree::ImmutableKdTree;
use serde::{Deserialize, Serialize};
use std::num::NonZero;

/// One search result: a point's index (into the slice the index was built from) and its
/// squared distance to the query, in f32, summed x + y + z by every back-end.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Neighbor {
    pub index: u32,
    pub d2: f32,
}

impl Neighbor {
    /// `(d2, index)` as one integer: for non-negative floats the IEEE bit pattern is ordered
    /// like the value, so one u64 comparison orders by distance, then by index.
    #[inline]
    pub(crate) fn key(self) -> u64 {
        ((self.d2.to_bits() as u64) << 32) | self.index as u64
    }
}

/// Squared distance in f32, summed in a fixed order (x, y, z) by every back-end, so that
/// results compare bit for bit.
#[inline]
pub(crate) fn dist2(a: [f32; 3], b: [f32; 3]) -> f32 {
    let (dx, dy, dz) = (a[0] - b[0], a[1] - b[1], a[2] - b[2]);
    dx * dx + dy * dy + dz * dz
}

/// `r_max^2`; infinity means "no maximum". NaN or negative radii find nothing.
#[inline]
fn radius2(r_max: f32) -> f32 {
    if r_max >= 0.0 { r_max * r_max } else { 0.0 }
}

/// The k smallest `(d2, index)` so far, kept in the caller's `Vec` (no allocation per
/// query once the scratch vector has grown). Not a heap: candidates are appended to a buffer
/// of up to 2k and, when it fills, `select_nth_unstable` keeps the k smallest (amortised
/// O(1) per candidate against a heap's O(log k); the "buffered k-selection" used by GPU
/// k-NN, e.g. Johnson, Douze, Jégou 2019, "Billion-scale similarity search with GPUs").
/// `bound` is the squared distance a point must not exceed to be offered: `r_max^2` until
/// k points are seen, then the k-th smallest distance, so the search radius shrinks.
struct Best<'a> {
    out: &'a mut Vec<Neighbor>,
    k: usize,
    cap: usize,
    bound: f32,
}

impl<'a> Best<'a> {
    fn new(out: &'a mut Vec<Neighbor>, k: usize, r2: f32) -> Best<'a> {
        out.clear();
        Best {
            out,
            k,
            // First compaction as soon as k points are in, to start shrinking the radius.
            cap: k,
            bound: r2,
        }
    }

    /// Offer a point whose `d2 <= self.bound` (checked by the caller, on the hot path).
    #[inline]
    fn offer(&mut self, n: Neighbor) {
        self.out.push(n);
        if self.out.len() >= self.cap {
            self.compact();
        }
    }

    /// Keep the k smallest keys; the k-th becomes the bound (points tied with it in d2 may
    /// still win on index, so the caller keeps `d2 <= bound`).
    #[cold]
    fn compact(&mut self) {
        let k = self.k;
        self.out.select_nth_unstable_by_key(k - 1, |n| n.key());
        self.out.truncate(k);
        self.bound = self.out[k - 1].d2;
        self.cap = k.saturating_mul(2).max(k + 16);
    }

    /// Keep the k smallest, unsorted.
    fn select(&mut self) {
        if self.out.len() > self.k {
            self.out.select_nth_unstable_by_key(self.k - 1, |n| n.key());
            self.out.truncate(self.k);
        }
    }

    fn finish(mut self) {
        self.select();
        self.out.sort_unstable_by_key(|n| n.key());
    }
}

/// Our kd-tree, built in place (Jensen 2001, §6.3 "balanced kd-tree"; Tungsten's in-place
/// layout, anchor A3.4): the positions are permuted so that every index range `[lo, hi)`
/// longer than a leaf is split at its median `mid = (lo + hi) / 2` along the axis of largest
/// extent; `[lo, mid)` lies at or below `pos[mid][axis]`, `[mid + 1, hi)` at or above, and
/// `pos[mid]` is the node's own point. No node structs, no child pointers: a node *is* an
/// index range, and its split axis is one byte stored at `axis[mid]`.
///
/// Hot/cold split (anchor A4.1): the query reads `pos` (and `axis`) only; `ids` (the
/// original index of each slot) is read when a point enters the result buffer.
#[derive(Clone, Debug)]
pub struct KdTree {
    /// Positions by slot as three arrays (SoA), so a leaf's 16 distances are one vectorised
    /// loop over three cache lines (the layout of Wald et al. 2001, "Interactive Rendering
    /// with Coherent Ray Tracing", §3; measured faster than `[f32; 3]` rows here).
    xyz: [Vec<f32>; 3],
    ids: Vec<u32>,
    axis: Vec<u8>,
    /// `ids[i] == i` for every slot (after [`KdTree::relabel_by_slot`]): results need no
    /// relabelling.
    identity: bool,
}

/// Ranges of at most this many points are scanned linearly. 16 beat 8 and 32 at 1M
/// photons for k = 50..1000 (`bench::bench_knn`, release, one thread).
const LEAF: usize = 16;

impl KdTree {
    /// Build over `points`; results index into `points`. O(n log n): one bounding box and
    /// one `select_nth_unstable` (introselect, O(n)) per level.
    pub fn build(points: &[[f32; 3]]) -> KdTree {
        assert!(points.len() <= u32::MAX as usize, "at most 2^32 - 1 points");
        let mut items: Vec<([f32; 3], u32)> = points
            .iter()
            .enumerate()
            .map(|(i, &p)| (p, i as u32))
            .collect();
        let mut axis = vec![0u8; points.len()];
        let mut stack = vec![(0usize, points.len())];
        while let Some((lo, hi)) = stack.pop() {
            if hi - lo <= LEAF {
                continue;
            }
            let (mut min, mut max) = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);
            for (p, _) in &items[lo..hi] {
                for a in 0..3 {
                    min[a] = min[a].min(p[a]);
                    max[a] = max[a].max(p[a]);
                }
            }
            let ext = [max[0] - min[0], max[1] - min[1], max[2] - min[2]];
            let a = if ext[0] >= ext[1] && ext[0] >= ext[2] {
                0
            } else if ext[1] >= ext[2] {
                1
            } else {
                2
            };
            let mid = lo + (hi - lo) / 2;
            items[lo..hi].select_nth_unstable_by(mid - lo, |x, y| x.0[a].total_cmp(&y.0[a]));
            axis[mid] = a as u8;
            // The median stays put as the node's own point; the children exclude it, so
            // their partitions never move it and `pos[mid]` keeps the split value.
            stack.push((lo, mid));
            stack.push((mid + 1, hi));
        }
        let xyz = [0, 1, 2].map(|a| items.iter().map(|(p, _)| p[a]).collect());
        let ids = items.into_iter().map(|(_, i)| i).collect();
        KdTree {
            xyz,
            ids,
            axis,
            identity: false,
        }
    }

    pub fn len(&self) -> usize {
        self.ids.len()
    }

    pub fn is_empty(&self) -> bool {
        self.ids.is_empty()
    }

    #[inline]
    fn pos(&self, i: usize) -> [f32; 3] {
        [self.xyz[0][i], self.xyz[1][i], self.xyz[2][i]]
    }

    /// Original index of each tree slot: `order()[slot]`. A caller that reorders its own
    /// records by this (for memory locality) then calls [`KdTree::relabel_by_slot`].
    pub fn order(&self) -> &[u32] {
        &self.ids
    }

    /// Make results index tree slots instead of the original points (after the caller has
    /// permuted its records by [`KdTree::order`]).
    pub fn relabel_by_slot(&mut self) {
        for (i, id) in self.ids.iter_mut().enumerate() {
            *id = i as u32;
        }
        self.identity = true;
    }

    /// The `k` nearest points with `d2 <= r_max^2`, sorted by `(d2, index)`, into `out`.
    pub fn knn(&self, q: Vec3, k: usize, r_max: f32, out: &mut Vec<Neighbor>) {
        let mut best = Best::new(out, k, radius2(r_max));
        self.search(q.to_array(), &mut best);
        best.finish();
    }

    /// Depth-first k-NN into `best` (near child first, shrinking bound).
    fn search(&self, q: [f32; 3], best: &mut Best) {
        if best.k == 0 || self.is_empty() {
            return;
        }
        // (lo, hi, per-axis distance from q to the range's cell, lower bound on d2).
        // Depth <= 32, at most two entries per level.
        let mut stack = [(0u32, 0u32, [0f32; 3], 0f32); 72];
        stack[0] = (0, self.len() as u32, [0.0; 3], 0.0);
        let mut sp = 1;
        while sp > 0 {
            sp -= 1;
            let (lo, hi, off, dmin) = stack[sp];
            // Strictly greater: a point at exactly the k-th distance with a smaller index
            // still wins its tie.
            if dmin > best.bound {
                continue;
            }
            let (lo, hi) = (lo as usize, hi as usize);
            if hi - lo <= LEAF {
                for i in lo..hi {
                    let d2 = dist2(self.pos(i), q);
                    if d2 <= best.bound {
                        best.offer(Neighbor {
                            index: self.ids[i],
                            d2,
                        });
                    }
                }
                continue;
            }
            let mid = lo + (hi - lo) / 2;
            let split = self.pos(mid);
            let d2 = dist2(split, q);
            if d2 <= best.bound {
                best.offer(Neighbor {
                    index: self.ids[mid],
                    d2,
                });
            }
            let a = self.axis[mid] as usize;
            let diff = q[a] - split[a];
            // The far cell's distance from q (Arya & Mount 1993, "Algorithms for fast
            // vector quantization": incremental distance to the cell, tighter than the
            // plane alone). Summed like `dist2` from per-axis offsets that never exceed
            // |q - p| for a point p in the cell, and f32 rounding is monotone, so the
            // bound never prunes a true neighbour.
            let mut far_off = off;
            far_off[a] = diff.abs().max(off[a]);
            let dfar = dist2(far_off, [0.0; 3]);
            let (near, far) = if diff < 0.0 {
                ((lo, mid), (mid + 1, hi))
            } else {
                ((mid + 1, hi), (lo, mid))
            };
            stack[sp] = (far.0 as u32, far.1 as u32, far_off, dfar);
            stack[sp + 1] = (near.0 as u32, near.1 as u32, off, dmin);
            sp += 2;
        }
    }

    /// Fixed-radius search: every point with `d2 <= r2` as `(slot, d2)`, in slot order (an
    /// in-order walk: left range, node point, right range), so the output order depends on
    /// the set alone. Gives up (returns false, `out` partial) once more than `cap` are in.
    /// `out`'s old entries are overwritten, not cleared first: its length is room to write
    /// into without zero-filling it again (a resize writes every new entry).
    fn gather(&self, q: [f32; 3], r2: f32, cap: usize, out: &mut Vec<Neighbor>) -> bool {
        if self.is_empty() {
            out.clear();
            return true;
        }
        let mut len = 0;
        // (lo, hi, per-axis distance from q to the range's cell). Each level leaves at most
        // two entries (node point, right range) behind; depth <= 32.
        let mut stack = [(0u32, 0u32, [0f32; 3]); 100];
        stack[0] = (0, self.len() as u32, [0.0; 3]);
        let mut sp = 1;
        while sp > 0 {
            sp -= 1;
            let (lo, hi, off) = stack[sp];
            let (lo, hi) = (lo as usize, hi as usize);
            if hi - lo <= LEAF {
                // Distances first (a loop over the SoA rows that vectorises), then a
                // branch-free stream compaction: every point is written, and kept by advancing
                // `len` only if inside (no mispredicted branch per point; the usual SIMD
                // "left-pack" idiom, e.g. Lemire's blog, "Quickly pruning elements in SIMD
                // vectors", 2017).
                let m = hi - lo;
                let mut d2s = [0f32; LEAF];
                let (xs, ys, zs) = (
                    &self.xyz[0][lo..hi],
                    &self.xyz[1][lo..hi],
                    &self.xyz[2][lo..hi],
                );
                for (j, d2) in d2s[..m].iter_mut().enumerate() {
                    *d2 = dist2([xs[j], ys[j], zs[j]], q);
                }
                if out.len() < len + LEAF {
                    out.resize(2 * out.len() + LEAF, Neighbor { index: 0, d2: 0.0 });
                }
                // `kept <= j < LEAF`, so the mask never changes it; it lets the compiler drop
                // the bounds check.
                let dst = &mut out[len..len + LEAF];
                let mut kept = 0;
                for (j, &d2) in d2s[..m].iter().enumerate() {
                    dst[kept & (LEAF - 1)] = Neighbor {
                        index: (lo + j) as u32,
                        d2,
                    };
                    kept += (d2 <= r2) as usize;
                }
                len += kept;
                if len > cap {
                    out.truncate(len);
                    return false;
                }
                continue;
            }
            let mid = lo + (hi - lo) / 2;
            let a = self.axis[mid] as usize;
            let diff = q[a] - self.xyz[a][mid];
            // As in `search` (Arya & Mount): the far side's cell distance.
            let mut far_off = off;
            far_off[a] = diff.abs().max(off[a]);
            let far_in = dist2(far_off, [0.0; 3]) <= r2;
            let (left, right) = if diff < 0.0 {
                (Some(off), far_in.then_some(far_off))
            } else {
                (far_in.then_some(far_off), Some(off))
            };
            if let Some(o) = right {
                stack[sp] = ((mid + 1) as u32, hi as u32, o);
                sp += 1;
            }
            stack[sp] = (mid as u32, (mid + 1) as u32, off);
            sp += 1;
            if let Some(o) = left {
                stack[sp] = (lo as u32, mid as u32, o);
                sp += 1;
            }
        }
        out.truncate(len);
        true
    }

    /// The same neighbours as [`KdTree::knn`], but in slot order (a fixed permutation of
    /// the index order, the identity after [`KdTree::relabel_by_slot`]), found radius-first:
    /// a range search at a radius guessed from `hint`, then a linear-time selection of the
    /// k smallest `(d2, index)`. Exact whatever the guess: if at least k points lie within
    /// the guessed radius R, the true k nearest (all within the k-th distance <= R) are
    /// among them. Fewer than k: grow R and retry; no usable guess, or far too many points
    /// inside it: an exact k-NN finds the k-th distance and the range search runs at it.
    /// `hint` becomes this query's point and k-th distance.
    pub fn knn_hinted(
        &self,
        q: Vec3,
        k: usize,
        r_max: f32,
        hint: &mut KnnHint,
        out: &mut Vec<Neighbor>,
    ) {
        if k == 0 || self.is_empty() {
            out.clear();
            return;
        }
        let qa = q.to_array();
        let rmax2 = radius2(r_max);
        // A range search finding more than this is abandoned for the exact k-NN.
        let cap = k.saturating_mul(4).max(k.saturating_add(1024));
        let mut r2 = hint.guess2(q);
        let mut done = false;
        for _ in 0..4 {
            // NaN, zero, or negative: no usable guess.
            if r2.is_nan() || r2 <= 0.0 || !self.gather(qa, r2.min(rmax2), cap, out) {
                break;
            }
            if out.len() >= k || r2 >= rmax2 {
                done = true;
                break;
            }
            r2 *= grow2(k, out.len());
        }
        if !done {
            let mut best = Best::new(out, k, rmax2);
            self.search(qa, &mut best);
            best.select();
            // The k-th distance, or r_max when fewer than k lie within it.
            let r2 = if out.len() == k {
                out.iter().fold(0f32, |m, n| m.max(n.d2))
            } else {
                rmax2
            };
            self.gather(qa, r2, usize::MAX, out);
        }
        // Slots to indices before selecting: ties break by index.
        if !self.identity {
            for n in out.iter_mut() {
                n.index = self.ids[n.index as usize];
            }
        }
        keep_k_smallest(out, k);
        hint.update(q, k, r_max, out);
    }
}

/// Grow factor for a squared radius that caught `found < k` points: on a surface the count
/// grows like r², so aim for 1.3 k, at least doubling (a 3-D cluster grows faster, and a
/// retry costs more than a few extra candidates), at most 16x.
fn grow2(k: usize, found: usize) -> f32 {
    (1.3 * k as f32 / found.max(1) as f32).clamp(2.0, 16.0)
}

/// Keep the k smallest `(d2, index)` of `out`, in their order. Selection by bucketing:
/// d2 ↦ round(256 d2 / max d2) is monotone, so counting per bucket finds the bucket holding
/// the k-th key in one pass; only that bucket (a few points, as d2 is near uniform on a
/// surface) is selected exactly, in `out`'s spare tail. A radix select (Alabi et al. 2012,
/// "Fast k-selection algorithms for graphics processing units", bucket select): one
/// counting pass instead of introselect's repeated partitions of all candidates.
///
/// The bucket is computed without a float-to-integer conversion: for 0 <= v <= 2^22,
/// v + 2^23 has exponent 23, so its low mantissa bits are v rounded to an integer (the
/// usual "magic number" trick). Rounding is monotone like the floor, which is all the
/// selection needs. Two histograms, alternating, so runs of equal buckets (neighbouring
/// points in slot order) do not serialise on one counter.
fn keep_k_smallest(out: &mut Vec<Neighbor>, k: usize) {
    const B: usize = 256;
    const MAGIC: f32 = 8_388_608.0; // 2^23
    let m = out.len();
    if m <= k {
        return;
    }
    let hi = out.iter().fold(0f32, |a, n| a.max(n.d2));
    let scale = B as f32 / hi;
    // In 0..=B (d2 * scale <= B up to rounding, which rounds to B at most): B + 1 buckets.
    let bucket =
        |d2: f32| ((d2 * scale + MAGIC).to_bits().wrapping_sub(MAGIC.to_bits()) as usize) & 511;
    let below = if scale.is_finite() && scale > 0.0 {
        let mut counts = [[0u32; 512]; 2];
        let mut pairs = out.chunks_exact(2);
        for pair in &mut pairs {
            counts[0][bucket(pair[0].d2)] += 1;
            counts[1][bucket(pair[1].d2)] += 1;
        }
        for n in pairs.remainder() {
            counts[0][bucket(n.d2)] += 1;
        }
        let (mut b, mut below) = (0, 0);
        while below + ((counts[0][b] + counts[1][b]) as usize) < k {
            below += (counts[0][b] + counts[1][b]) as usize;
            b += 1;
        }
        for i in 0..m {
            if bucket(out[i].d2) == b {
                out.push(out[i]);
            }
        }
        below
    } else {
        // Every d2 zero, subnormal or infinite: select among all.
        out.extend_from_within(..);
        0
    };
    let tail = &mut out[m..];
    let (_, kth, _) = tail.select_nth_unstable_by_key(k - below - 1, |n| n.key());
    let kth = kth.key();
    // Branch-free compaction (as in `KdTree::gather`): every entry is written, and kept
    // by advancing `len`.
    let mut len = 0;
    for i in 0..m {
        let n = out[i];
        out[len] = n;
        len += (n.key() <= kth) as usize;
    }
    out.truncate(len);
}

/// A radius guess for `knn_hinted`: the previous query's point and its k-th distance
/// (`r_max` if it found fewer than k). [`KnnHint::NONE`] (or a NaN, zero or negative `r`)
/// means no guess. Keep one per thread and per map, and query in a coherent order (pixel
/// by pixel along a row, say) so consecutive queries are close.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct KnnHint {
    pub at: Vec3,
    pub r: f32,
}

impl Default for KnnHint {
    fn default() -> KnnHint {
        KnnHint::NONE
    }
}

impl KnnHint {
    pub const NONE: KnnHint = KnnHint {
        at: Vec3::NAN,
        r: f32::NAN,
    };

    /// Relative margin on the previous radius. On a surface the count inside r grows like
    /// r², so 5% more radius is ~10% more candidates, ample for the few-% jitter of the
    /// k-th distance between neighbouring pixels at k >= 50 (`bench_coherent`).
    const MARGIN: f32 = 0.05;

    pub fn new(at: Vec3, r: f32) -> KnnHint {
        KnnHint { at, r }
    }

    /// The squared radius to try at `q`: the ball of radius r + |q − at| around q contains
    /// the previous ball, hence its k points (triangle inequality; slack 1e-5 for f32
    /// rounding), and is the tighter guess for a close query; r (1 + MARGIN) is the
    /// tighter one for a distant query in a region of similar density. NaN: no guess.
    fn guess2(&self, q: Vec3) -> f32 {
        if self.r.is_nan() || self.r <= 0.0 {
            return f32::NAN;
        }
        let step = q.distance(self.at);
        let reach = (self.r + step) * (1.0 + 1e-5);
        let r = if reach <= self.r * (1.0 + Self::MARGIN) {
            reach
        } else {
            self.r * (1.0 + Self::MARGIN)
        };
        r * r
    }

    fn update(&mut self, q: Vec3, k: usize, r_max: f32, found: &[Neighbor]) {
        if !q.is_finite() || found.is_empty() {
            return;
        }
        self.at = q;
        self.r = if found.len() == k {
            found.iter().fold(0f32, |m, n| m.max(n.d2)).sqrt()
        } else {
            r_max
        };
    }
}

/// Brute force: every point tested. The reference the others are checked against, and the
/// fastest choice for a few hundred points.
#[derive(Clone, Debug)]
pub struct Brute {
    pos: Vec<[f32; 3]>,
}

impl Brute {
    pub fn build(points: &[[f32; 3]]) -> Brute {
        assert!(points.len() <= u32::MAX as usize, "at most 2^32 - 1 points");
        Brute {
            pos: points.to_vec(),
        }
    }

    pub fn knn(&self, q: Vec3, k: usize, r_max: f32, out: &mut Vec<Neighbor>) {
        let mut best = Best::new(out, k, radius2(r_max));
        if k == 0 {
            return;
        }
        let q = q.to_array();
        for (i, &p) in self.pos.iter().enumerate() {
            let d2 = dist2(p, q);
            if d2 <= best.bound {
                best.offer(Neighbor {
                    index: i as u32,
                    d2,
                });
            }
        }
        best.finish();
    }

    /// [`Brute::knn`] in index order; see [`KdTree::knn_hinted`].
    pub fn knn_hinted(
        &self,
        q: Vec3,
        k: usize,
        r_max: f32,
        hint: &mut KnnHint,
        out: &mut Vec<Neighbor>,
    ) {
        self.knn(q, k, r_max, out);
        in_index_order(q, k, r_max, hint, out);
    }
}

/// The hinted answer of a back-end without a radius-first search: its exact k-NN, put in
/// index order (the order `knn_hinted` promises), with the hint updated.
fn in_index_order(q: Vec3, k: usize, r_max: f32, hint: &mut KnnHint, out: &mut [Neighbor]) {
    out.sort_unstable_by_key(|n| n.index);
    hint.update(q, k, r_max, out);
}

/// kiddo 5's `ImmutableKdTree` (bucket 32, u32 items). kiddo orders results by distance
/// only, so ties at the k-th distance come back in arbitrary order. We ask for `k + 1`: if
/// the (k+1)-th is strictly farther than the k-th, the k nearest are unique; otherwise (a
/// tie, rare except for duplicate points) a second `within` query collects every point at or
/// inside the k-th distance and we keep the first `k` by `(d2, index)`.
pub struct Kiddo {
    pos: Vec<[f32; 3]>,
    tree: Option<ImmutableKdTree<f32, u32, 3, 32>>,
}

impl Kiddo {
    pub fn build(points: &[[f32; 3]]) -> Kiddo {
        assert!(points.len() <= u32::MAX as usize, "at most 2^32 - 1 points");
        let tree = (!points.is_empty()).then(|| ImmutableKdTree::new_from_slice(points));
        Kiddo {
            pos: points.to_vec(),
            tree,
        }
    }

    pub fn knn(&self, q: Vec3, k: usize, r_max: f32, out: &mut Vec<Neighbor>) {
        out.clear();
        let r2 = radius2(r_max);
        let (Some(tree), Some(k1)) = (&self.tree, NonZero::new(k)) else {
            return;
        };
        let q = q.to_array();
        let k1 = k1.saturating_add(1);
        // Our own d2 (same summation order as kiddo's, but do not depend on it).
        let push = |out: &mut Vec<Neighbor>, item: u32| {
            let d2 = dist2(self.pos[item as usize], q);
            if d2 <= r2 {
                out.push(Neighbor { index: item, d2 });
            }
        };
        for n in tree.nearest_n_within::<SquaredEuclidean>(&q, r2, k1, true) {
            push(out, n.item);
        }
        out.sort_unstable_by_key(|n| n.key());
        if out.len() > k && out[k].d2 == out[k - 1].d2 {
            let dk = out[k - 1].d2;
            out.clear();
            for n in tree.within_unsorted::<SquaredEuclidean>(&q, dk) {
                push(out, n.item);
            }
            out.sort_unstable_by_key(|n| n.key());
        }
        out.truncate(k);
    }

    /// [`Kiddo::knn`] in index order; see [`KdTree::knn_hinted`].
    pub fn knn_hinted(
        &self,
        q: Vec3,
        k: usize,
        r_max: f32,
        hint: &mut KnnHint,
        out: &mut Vec<Neighbor>,
    ) {
        self.knn(q, k, r_max, out);
        in_index_order(q, k, r_max, hint, out);
    }
}

/// Which back-end a [`crate::PhotonMap`] uses (parameter files name it in snake_case).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum IndexKind {
    KdTree,
    Kiddo,
    Brute,
}

impl IndexKind {
    pub const ALL: [IndexKind; 3] = [IndexKind::KdTree, IndexKind::Kiddo, IndexKind::Brute];

    pub fn name(self) -> &'static str {
        match self {
            IndexKind::KdTree => "kd_tree",
            IndexKind::Kiddo => "kiddo",
            IndexKind::Brute => "brute",
        }
    }
}

/// A built index: a closed set of back-ends, dispatched by `match` (anchor A1.1).
pub enum Index {
    KdTree(KdTree),
    Kiddo(Kiddo),
    Brute(Brute),
}

impl Index {
    pub fn build(kind: IndexKind, points: &[[f32; 3]]) -> Index {
        match kind {
            IndexKind::KdTree => Index::KdTree(KdTree::build(points)),
            IndexKind::Kiddo => Index::Kiddo(Kiddo::build(points)),
            IndexKind::Brute => Index::Brute(Brute::build(points)),
        }
    }

    pub fn kind(&self) -> IndexKind {
        match self {
            Index::KdTree(_) => IndexKind::KdTree,
            Index::Kiddo(_) => IndexKind::Kiddo,
            Index::Brute(_) => IndexKind::Brute,
        }
    }

    /// The `k` nearest points with `d2 <= r_max^2` (`r_max` infinite: no limit), sorted by
    /// `(d2, index)`, written to `out` (cleared first). Same answer from every back-end.
    pub fn knn(&self, q: Vec3, k: usize, r_max: f32, out: &mut Vec<Neighbor>) {
        match self {
            Index::KdTree(t) => t.knn(q, k, r_max, out),
            Index::Kiddo(t) => t.knn(q, k, r_max, out),
            Index::Brute(t) => t.knn(q, k, r_max, out),
        }
    }

    /// The same neighbours as [`Index::knn`], in an order that depends on the set alone
    /// (index order; slot order for a bare [`KdTree`]), using and updating `hint`. Fast
    /// for large k with the kd-tree when consecutive queries are close: see
    /// [`KdTree::knn_hinted`]. The other back-ends run `knn` and sort by index.
    pub fn knn_hinted(
        &self,
        q: Vec3,
        k: usize,
        r_max: f32,
        hint: &mut KnnHint,
        out: &mut Vec<Neighbor>,
    ) {
        match self {
            Index::KdTree(t) => t.knn_hinted(q, k, r_max, hint, out),
            Index::Kiddo(t) => t.knn_hinted(q, k, r_max, hint, out),
            Index::Brute(t) => t.knn_hinted(q, k, r_max, hint, out),
        }
    }
}
