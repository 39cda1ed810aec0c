//! Our kd-tree: in place over SoA f32 positions with u32 ids, k-NN radius-first (from the
//! leaf's density or a hint; depth-first with buffered selection as the fallback), and a
//! fixed-radius range search.

use super::{Best, KnnHint, Neighbor, Points, dist2, keep_k_smallest, radius2, sort_neighbors};
use glam::Vec3;

/// Our kd-tree, a bucket tree built in place (Friedman, Bentley, Finkel 1977, "An
/// Algorithm for Finding Best Matches in Logarithmic Expected Time": points only in
/// buckets; median splits as in Jensen 2001, §6.3): the positions are permuted so that
/// every node is an index range `[lo, hi)`, split at `mid = lo + (hi - lo) / 2` along the
/// axis of largest extent into `[lo, mid)`, at or below `split`, and `[mid, hi)`, at or
/// above it, down to a depth where every range has at most `LEAF` points. All leaves are at
/// that one depth, so the nodes form a complete binary tree numbered in heap order (node
/// `i`'s children are `2i + 1`, `2i + 2`), and a node is its split value and axis, two
/// small arrays that stay in cache (at 1M points, 32k nodes, 160 kB), while the points are
/// read a leaf at a time, contiguously.
///
/// Hot/cold split: the search reads the splits and positions; `ids` (the original index
/// of each slot) is read when a leaf's points are offered to the result buffer.
#[derive(Clone, Debug)]
pub struct KdTree {
    /// Positions by slot.
    pts: Points,
    ids: Vec<u32>,
    /// Per internal node, in heap order.
    split: Vec<f32>,
    axis: Vec<u8>,
    /// Per leaf, in order: squared distance per neighbour, 1 / (pi * density), from the
    /// leaf's points (see [`leaf_spacing2`]); a k-NN query's first radius guess is k times
    /// the value at its leaf. NaN: no guess.
    spacing2: Vec<f32>,
    /// `ids[i] == i` for every slot (after [`KdTree::relabel_by_slot`]): results need no
    /// relabelling.
    identity: bool,
}

/// Most points per leaf: 32, kiddo's bucket size too (not yet tuned for this tree; the
/// in-place tree it replaced had measured 16 best).
const LEAF: usize = 32;

/// Leaves a range search finds (and prefetches) before it reads them.
const BATCH: usize = 16;

/// The depth at which every leaf holds at most `LEAF` of `n` points (sizes at one depth
/// differ by at most one, the largest being ceil(n / 2^depth)).
fn depth_for(n: usize) -> u32 {
    let mut d = 0;
    while n.div_ceil(1 << d) > LEAF {
        d += 1;
    }
    d
}

/// One leaf's squared distances, a loop over the SoA rows that vectorises.
#[inline(always)]
fn leaf_d2(pts: &Points, lo: usize, hi: usize, q: [f32; 3]) -> [f32; LEAF] {
    let mut d2s = [f32::INFINITY; LEAF];
    let (xs, ys, zs) = (
        &pts.xyz[0][lo..hi],
        &pts.xyz[1][lo..hi],
        &pts.xyz[2][lo..hi],
    );
    for (j, d2) in d2s[..hi - lo].iter_mut().enumerate() {
        *d2 = dist2([xs[j], ys[j], zs[j]], q);
    }
    d2s
}

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
        let depth = depth_for(points.len());
        let nodes = (1usize << depth) - 1;
        let mut split = vec![0f32; nodes];
        let mut axis = vec![0u8; nodes];
        let mut leaves = vec![(0, 0); nodes + 1];
        let mut stack = vec![(0usize, 0usize, points.len())];
        while let Some((node, lo, hi)) = stack.pop() {
            if node >= nodes {
                leaves[node - nodes] = (lo, hi);
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
            if mid < hi {
                items[lo..hi].select_nth_unstable_by(mid - lo, |x, y| x.0[a].total_cmp(&y.0[a]));
            }
            // The right half's smallest coordinate: the left half lies at or below it.
            split[node] = items.get(mid).map_or(0.0, |it| it.0[a]);
            axis[node] = a as u8;
            stack.push((2 * node + 1, lo, mid));
            stack.push((2 * node + 2, mid, hi));
        }
        let pts = Points {
            xyz: [0, 1, 2].map(|a| items.iter().map(|(p, _)| p[a]).collect()),
        };
        let ids = items.into_iter().map(|(_, i)| i).collect();
        let mut tree = KdTree {
            pts,
            ids,
            split,
            axis,
            spacing2: Vec::new(),
            identity: false,
        };
        let mut scratch = Vec::new();
        tree.spacing2 = leaves
            .iter()
            .map(|&(lo, hi)| tree.leaf_spacing2(lo, hi, &mut scratch))
            .collect();
        tree
    }

    /// A leaf's squared distance per neighbour, 1 / (pi rho) for points on a surface of
    /// density rho: the leaf's point nearest its centroid, and the d2 of its
    /// `SPACING_K`-th neighbour over `SPACING_K` (on a surface the j-th neighbour's
    /// expected d2 is j / (pi rho)). From the whole tree, not the leaf's own points: a
    /// median split through a wall of equal coordinates spreads the wall's points over
    /// both children, and a leaf's own box can then be hundreds of times too large.
    /// NaN for an empty leaf or a zero distance (duplicates): no guess.
    fn leaf_spacing2(&self, lo: usize, hi: usize, scratch: &mut Vec<Neighbor>) -> f32 {
        const SPACING_K: usize = 64;
        if hi <= lo {
            return f32::NAN;
        }
        let m = (hi - lo) as f32;
        let c = (lo..hi).fold([0f32; 3], |c, i| {
            let p = self.pts.get(i);
            [c[0] + p[0] / m, c[1] + p[1] / m, c[2] + p[2] / m]
        });
        let rep = (lo..hi)
            .min_by(|&i, &j| dist2(self.pts.get(i), c).total_cmp(&dist2(self.pts.get(j), c)))
            .map_or(c, |i| self.pts.get(i));
        // The point itself is the first of the SPACING_K + 1 nearest.
        let mut best = Best::new(scratch, SPACING_K + 1, f32::INFINITY);
        self.search(rep, &mut best);
        best.select();
        let d2 = scratch.iter().fold(0f32, |m, n| m.max(n.d2));
        if scratch.len() == SPACING_K + 1 && d2 > 0.0 && d2.is_finite() {
            d2 / SPACING_K as f32
        } else {
            f32::NAN
        }
    }

    pub fn len(&self) -> usize {
        self.ids.len()
    }

    pub fn is_empty(&self) -> bool {
        self.ids.is_empty()
    }

    /// Positions by slot.
    pub(crate) fn points(&self) -> &Points {
        &self.pts
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

    /// The `k` nearest points with `d2 <= r_max^2`, sorted by `(d2, index)`, into `out`:
    /// radius-first from the density at the query's leaf (see [`KdTree::knn_hinted`]),
    /// then a bucket sort.
    pub fn knn(&self, q: Vec3, k: usize, r_max: f32, out: &mut Vec<Neighbor>) {
        if k == 0 || self.is_empty() {
            out.clear();
            return;
        }
        let qa = q.to_array();
        let guess = self.leaf_guess2(qa, k);
        self.radius_first(qa, k, radius2(r_max), guess, out);
        // Sorting every candidate (about 1.3 k, see `leaf_guess2`) and keeping the first k costs less than
        // selecting k first and sorting those.
        sort_neighbors(out, k);
    }

    /// The exact k-NN by the depth-first search alone (the radius-first search's
    /// fallback), sorted like [`KdTree::knn`]: the tests hold it to brute force too.
    #[cfg(test)]
    pub(crate) fn knn_depth_first(&self, q: Vec3, k: usize, r_max: f32, out: &mut Vec<Neighbor>) {
        let mut best = Best::new(out, k, radius2(r_max));
        self.search(q.to_array(), &mut best);
        best.finish();
    }

    /// A first squared radius for k neighbours of `q`: on a surface of density rho the k
    /// nearest lie within r^2 = k / (pi rho), rho taken at the leaf `q` falls in, with a
    /// margin: 30% more area. Measured on `bench knn`'s 1M photons: 1.3 k candidates per
    /// query, and 2% of queries find fewer than k and search again (1.5: 1.5 k and 0.2%,
    /// slower at every k; 1.1: 15% search again).
    fn leaf_guess2(&self, q: [f32; 3], k: usize) -> f32 {
        const MARGIN: f32 = 1.3;
        let nodes = self.split.len();
        let mut node = 0;
        while node < nodes {
            let right = q[self.axis[node] as usize] >= self.split[node];
            node = 2 * node + 1 + right as usize;
        }
        self.spacing2[node - nodes] * k as f32 * MARGIN
    }

    /// Depth-first k-NN into `best` (near child first, shrinking bound).
    fn search(&self, q: [f32; 3], best: &mut Best) {
        if best.k == 0 || self.is_empty() {
            return;
        }
        let nodes = self.split.len();
        // (node, lo, hi, per-axis distance from q to the node's cell, lower bound on d2).
        // Depth <= 32, one entry left behind per level.
        let mut stack = [(0u32, 0u32, 0u32, [0f32; 3], 0f32); 40];
        stack[0] = (0, 0, self.len() as u32, [0.0; 3], 0.0);
        let mut sp = 1;
        while sp > 0 {
            sp -= 1;
            let (mut node, lo, hi, off, dmin) = stack[sp];
            // Strictly greater: a point at exactly the k-th distance with a smaller index
            // still wins its tie.
            if dmin > best.bound {
                continue;
            }
            let (mut lo, mut hi) = (lo as usize, hi as usize);
            // Down to the near leaf, leaving the far children behind.
            while (node as usize) < nodes {
                let mid = lo + (hi - lo) / 2;
                let a = self.axis[node as usize] as usize;
                let diff = q[a] - self.split[node as usize];
                // The far cell's distance from q (Arya & Mount 1993, "Algorithms for fast
                // vector quantization": incremental distance to the cell, tighter than the
                // plane alone). Summed like `dist2` from per-axis offsets that never exceed
                // |q - p| for a point p in the cell, and f32 rounding is monotone, so the
                // bound never prunes a true neighbour.
                let mut far_off = off;
                far_off[a] = diff.abs().max(off[a]);
                let dfar = dist2(far_off, [0.0; 3]);
                let (near, far) = if diff < 0.0 {
                    ((2 * node + 1, lo, mid), (2 * node + 2, mid, hi))
                } else {
                    ((2 * node + 2, mid, hi), (2 * node + 1, lo, mid))
                };
                if dfar <= best.bound {
                    stack[sp] = (far.0, far.1 as u32, far.2 as u32, far_off, dfar);
                    sp += 1;
                }
                (node, lo, hi) = near;
            }
            // The leaf: distances, then a branch-free left-pack of those within the bound
            // into the buffer (every point is written, kept by advancing the length; the
            // SIMD "left-pack" idiom, e.g. Lemire's blog, "Quickly pruning elements in SIMD
            // vectors", 2017).
            let d2s = leaf_d2(&self.pts, lo, hi, q);
            best.offer_leaf(&d2s[..hi - lo], &self.ids[lo..hi]);
        }
    }

    /// Fixed-radius search: every point with `d2 <= r2` as `(index, d2)`, in slot order (an
    /// in-order walk of the leaves), so the output order depends on the set alone. Gives up
    /// (returns false, `out` partial) once more than `cap` are in. `out`'s old entries are
    /// overwritten, not cleared first: its length is room to write into without
    /// zero-filling it again (a resize writes every new entry).
    fn gather(&self, q: [f32; 3], r2: f32, cap: usize, out: &mut Vec<Neighbor>) -> bool {
        if self.is_empty() {
            out.clear();
            return true;
        }
        let nodes = self.split.len();
        let mut len = 0;
        // Leaves in reach, found ahead of reading them (see `prefetch_leaf`).
        let mut pending = [(0u32, 0u32); BATCH];
        let mut np = 0;
        // (node, lo, hi, per-axis distance from q to the node's cell). Depth <= 32, one
        // entry left behind per level.
        let mut stack = [(0u32, 0u32, 0u32, [0f32; 3]); 40];
        stack[0] = (0, 0, self.len() as u32, [0.0; 3]);
        let mut sp = 1;
        while sp > 0 {
            sp -= 1;
            let (mut node, lo, hi, mut off) = stack[sp];
            let (mut lo, mut hi) = (lo as usize, hi as usize);
            // Down the left-most child in reach, leaving the right children behind, so
            // leaves come out in slot order.
            while (node as usize) < nodes {
                let mid = lo + (hi - lo) / 2;
                let a = self.axis[node as usize] as usize;
                let diff = q[a] - self.split[node as usize];
                // As in `search` (Arya & Mount): the far side's cell distance.
                let mut far_off = off;
                far_off[a] = diff.abs().max(off[a]);
                let far_in = dist2(far_off, [0.0; 3]) <= r2;
                let (left, right) = if diff < 0.0 {
                    (Some(off), far_in.then_some(far_off))
                } else {
                    (far_in.then_some(far_off), Some(off))
                };
                // The near side is always in reach.
                match (left, right) {
                    (Some(lo_off), Some(ro)) => {
                        stack[sp] = (2 * node + 2, mid as u32, hi as u32, ro);
                        sp += 1;
                        (node, hi, off) = (2 * node + 1, mid, lo_off);
                    }
                    (Some(lo_off), None) => (node, hi, off) = (2 * node + 1, mid, lo_off),
                    (None, r) => (node, lo, off) = (2 * node + 2, mid, r.unwrap_or(off)),
                }
            }
            self.prefetch_leaf(lo, hi);
            pending[np] = (lo as u32, hi as u32);
            np += 1;
            if np < BATCH && sp > 0 {
                continue;
            }
            for &(lo, hi) in &pending[..np] {
                len = self.pack_leaf(lo as usize, hi as usize, q, r2, len, out);
                if len > cap {
                    out.truncate(len);
                    return false;
                }
            }
            np = 0;
        }
        out.truncate(len);
        true
    }

    /// Append the points of leaf `[lo, hi)` with `d2 <= r2` to `out[..len]` as `(index, d2)`
    /// in slot order; returns the new length. `out` only grows: entries past the returned
    /// length are scratch.
    #[inline(always)]
    fn pack_leaf(
        &self,
        lo: usize,
        hi: usize,
        q: [f32; 3],
        r2: f32,
        len: usize,
        out: &mut Vec<Neighbor>,
    ) -> usize {
        let d2s = leaf_d2(&self.pts, lo, hi, q);
        let d2s = &d2s[..hi - lo];
        if out.len() < len + LEAF {
            out.resize(2 * out.len() + LEAF, Neighbor { index: 0, d2: 0.0 });
        }
        // Branch-free left-pack (as in `search`). `kept <= j < LEAF`, so the mask never
        // changes it; it lets the compiler drop the bounds check.
        let dst = &mut out[len..len + LEAF];
        let mut kept = 0;
        if self.identity {
            for (j, &d2) in d2s.iter().enumerate() {
                dst[kept & (LEAF - 1)] = Neighbor {
                    index: (lo + j) as u32,
                    d2,
                };
                kept += (d2 <= r2) as usize;
            }
        } else {
            // Ids read here, beside the leaf's positions, so their cache misses overlap
            // those rather than wait in a later pass.
            for (&index, &d2) in self.ids[lo..hi].iter().zip(d2s) {
                dst[kept & (LEAF - 1)] = Neighbor { index, d2 };
                kept += (d2 <= r2) as usize;
            }
        }
        len + kept
    }

    /// Ask for a leaf's positions (and ids) ahead of reading them: a range search finds its
    /// leaves from the splits alone (in cache), so the leaves' misses, each at a random spot
    /// in megabytes of points, are in flight together instead of one leaf after another
    /// (the batched prefetching of Chen, Gibbons and Mowry 2001, "Improving Index
    /// Performance through Prefetching", for B+-tree range scans). Measured at k = 50 on
    /// 1M photons: +8-10% queries/s.
    #[inline(always)]
    fn prefetch_leaf(&self, lo: usize, hi: usize) {
        for row in &self.pts.xyz {
            math::prefetch(&row[lo..hi]);
        }
        if !self.identity {
            math::prefetch(&self.ids[lo..hi]);
        }
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
        let mut r2 = hint.guess2(q);
        // NaN, zero, or negative: no usable hint; the leaf's density instead.
        if r2.is_nan() || r2 <= 0.0 {
            r2 = self.leaf_guess2(qa, k);
        }
        self.radius_first(qa, k, radius2(r_max), r2, out);
        keep_k_smallest(out, k);
        hint.update(q, k, r_max, out);
    }

    /// Candidates for the k nearest of `q` within `rmax2`, found radius-first from the
    /// squared radius `r2` (see [`KdTree::knn_hinted`]): every point within some radius
    /// that holds at least k of them (or all within `rmax2`), by index, in slot order.
    fn radius_first(
        &self,
        qa: [f32; 3],
        k: usize,
        rmax2: f32,
        mut r2: f32,
        out: &mut Vec<Neighbor>,
    ) {
        // A range search finding more than this is abandoned for the exact k-NN.
        let cap = k.saturating_mul(4).max(k.saturating_add(1024));
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
    }

    /// Every point with `d2 <= r^2`, sorted by `(d2, index)` (see [`super::Index::within`]).
    pub fn within(&self, q: Vec3, r: f32, out: &mut Vec<Neighbor>) {
        self.within_in_index_order(q, r, out);
        out.sort_unstable_by_key(|n| n.key());
    }

    /// [`KdTree::within`]'s set in index order: the range search's slot order, sorted by
    /// index only if the tree was not relabelled.
    pub(crate) fn within_in_index_order(&self, q: Vec3, r: f32, out: &mut Vec<Neighbor>) {
        self.gather(q.to_array(), radius2(r), usize::MAX, out);
        if !self.identity {
            out.sort_unstable_by_key(|n| n.index);
        }
    }
}

/// Grow factor for a squared radius that caught `found < k` points: on a surface the count
/// grows like r², so aim for 1.3 k, at least doubling (a 3-D cluster grows faster, and a
/// retry costs more than a few extra candidates), at most 16x.
fn grow2(k: usize, found: usize) -> f32 {
    (1.3 * k as f32 / found.max(1) as f32).clamp(2.0, 16.0)
}
