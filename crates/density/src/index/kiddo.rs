//! kiddo 5's `ImmutableKdTree` behind our contract (exact ties, our own distances).

use super::{KnnHint, Neighbor, Points, dist2, in_index_order, radius2};
use glam::Vec3;
use kiddo::SquaredEuclidean;
use kiddo::immutable::float::kdtree::ImmutableKdTree;
use std::num::NonZero;

/// kiddo 5's `ImmutableKdTree` (bucket 32, u32 items). kiddo orders results by distance
/// only, so ties at the k-th distance come back in arbitrary order. We ask for `k + 1`: if
/// the (k+1)-th is strictly farther than the k-th, the k nearest are unique; otherwise (a
/// tie, rare except for duplicate points) a second `within` query collects every point at or
/// inside the k-th distance and we keep the first `k` by `(d2, index)`.
pub struct Kiddo {
    /// Our copy of the positions, by index: distances are ours, not kiddo's (kiddo keeps
    /// its own copy in its leaves).
    pts: Points,
    tree: Option<ImmutableKdTree<f32, u32, 3, 32>>,
}

impl Kiddo {
    pub fn build(points: &[[f32; 3]]) -> Kiddo {
        assert!(points.len() <= u32::MAX as usize, "at most 2^32 - 1 points");
        let tree = (!points.is_empty()).then(|| ImmutableKdTree::new_from_slice(points));
        Kiddo {
            pts: Points::new(points),
            tree,
        }
    }

    pub(crate) fn points(&self) -> &Points {
        &self.pts
    }

    /// Append `item` to `out` if our own d2 (same summation order as kiddo's, but do not
    /// depend on it) is within `r2`.
    #[inline]
    fn push(&self, out: &mut Vec<Neighbor>, q: [f32; 3], r2: f32, item: u32) {
        let d2 = dist2(self.pts.get(item as usize), q);
        if d2 <= r2 {
            out.push(Neighbor { index: item, d2 });
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
        for n in tree.nearest_n_within::<SquaredEuclidean>(&q, r2, k1, true) {
            self.push(out, q, r2, n.item);
        }
        out.sort_unstable_by_key(|n| n.key());
        if out.len() > k && out[k].d2 == out[k - 1].d2 {
            let dk = out[k - 1].d2;
            out.clear();
            for n in tree.within_unsorted::<SquaredEuclidean>(&q, dk) {
                self.push(out, q, r2, n.item);
            }
            out.sort_unstable_by_key(|n| n.key());
        }
        out.truncate(k);
    }

    /// kiddo's own k-NN as its documentation recommends (`nearest_n`, squared Euclidean,
    /// sorted by distance), without our tie rule or distances: the honest baseline for
    /// `bench::bench_knn`. Returns the number found.
    pub fn nearest_n_raw(&self, q: Vec3, k: usize) -> usize {
        match (&self.tree, NonZero::new(k)) {
            (Some(tree), Some(k)) => tree.nearest_n::<SquaredEuclidean>(&q.to_array(), k).len(),
            _ => 0,
        }
    }

    /// [`Kiddo::knn`] in index order; see [`super::KdTree::knn_hinted`].
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

    /// Every point with `d2 <= r^2`, sorted by `(d2, index)` (see [`super::Index::within`]).
    pub fn within(&self, q: Vec3, r: f32, out: &mut Vec<Neighbor>) {
        self.within_unordered(q, r, out);
        out.sort_unstable_by_key(|n| n.key());
    }

    /// [`Kiddo::within`]'s set in index order.
    pub(crate) fn within_in_index_order(&self, q: Vec3, r: f32, out: &mut Vec<Neighbor>) {
        self.within_unordered(q, r, out);
        out.sort_unstable_by_key(|n| n.index);
    }

    /// The set, in kiddo's order. kiddo is asked for a slightly larger radius (relative
    /// 1e-6, plus the smallest normal float for subnormal distances) and we keep our own
    /// `d2 <= r^2`, so a last-bit difference in its distances or pruning cannot drop a point.
    fn within_unordered(&self, q: Vec3, r: f32, out: &mut Vec<Neighbor>) {
        out.clear();
        let Some(tree) = &self.tree else {
            return;
        };
        let (q, r2) = (q.to_array(), radius2(r));
        let wide = r2 * (1.0 + 1e-6) + f32::MIN_POSITIVE;
        for n in tree.within_unsorted::<SquaredEuclidean>(&q, wide) {
            self.push(out, q, r2, n.item);
        }
    }
}
