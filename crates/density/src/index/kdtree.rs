//! Our kd-tree: in place over SoA f32 positions with u32 ids, k-NN by buffered selection,
//! radius-first k-NN from a hint, and a fixed-radius range search.

use super::{Best, KnnHint, Neighbor, Points, dist2, keep_k_smallest, radius2};
use glam::Vec3;

/// Our kd-tree, built in place (Jensen 2001, §6.3 "balanced kd-tree"; like Tungsten's
/// photon map, without node structs): the positions are permuted so that every index range
/// `[lo, hi)` longer than a leaf is split at its median `mid = (lo + hi) / 2` along the
/// axis of largest extent; `[lo, mid)` lies at or below `pos[mid][axis]`, `[mid + 1, hi)`
/// at or above, and `pos[mid]` is the node's own point. No child pointers: a node *is* an
/// index range, and its split axis is one byte stored at `axis[mid]`.
///
/// Hot/cold split: the query reads the positions (and `axis`) only; `ids` (the original
/// index of each slot) is read when a point enters the result buffer.
#[derive(Clone, Debug)]
pub struct KdTree {
    /// Positions by slot.
    pts: Points,
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
        let pts = Points {
            xyz: [0, 1, 2].map(|a| items.iter().map(|(p, _)| p[a]).collect()),
        };
        let ids = items.into_iter().map(|(_, i)| i).collect();
        KdTree {
            pts,
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

    /// Positions by slot.
    pub(crate) fn points(&self) -> &Points {
        &self.pts
    }

    #[inline]
    fn pos(&self, i: usize) -> [f32; 3] {
        self.pts.get(i)
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
                    &self.pts.xyz[0][lo..hi],
                    &self.pts.xyz[1][lo..hi],
                    &self.pts.xyz[2][lo..hi],
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
            let diff = q[a] - self.pts.xyz[a][mid];
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

    /// Slots in `out` to indices (a no-op after [`KdTree::relabel_by_slot`]).
    fn slots_to_indices(&self, out: &mut [Neighbor]) {
        if !self.identity {
            for n in out.iter_mut() {
                n.index = self.ids[n.index as usize];
            }
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
        self.slots_to_indices(out);
        keep_k_smallest(out, k);
        hint.update(q, k, r_max, out);
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
            self.slots_to_indices(out);
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
