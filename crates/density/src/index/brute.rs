//! Brute force: every point tested. The reference the other back-ends are checked against,
//! and the fastest choice for a few hundred points.

use super::{Best, KnnHint, Neighbor, Points, dist2, in_index_order, radius2};
use glam::Vec3;

#[derive(Clone, Debug)]
pub struct Brute {
    pts: Points,
}

impl Brute {
    pub fn build(points: &[[f32; 3]]) -> Brute {
        assert!(points.len() <= u32::MAX as usize, "at most 2^32 - 1 points");
        Brute {
            pts: Points::new(points),
        }
    }

    pub(crate) fn points(&self) -> &Points {
        &self.pts
    }

    pub fn knn(&self, q: Vec3, k: usize, r_max: f32, out: &mut Vec<Neighbor>) {
        if k == 0 {
            out.clear();
            return;
        }
        let mut best = Best::new(out, k, radius2(r_max));
        let q = q.to_array();
        for i in 0..self.pts.len() {
            let d2 = dist2(self.pts.get(i), q);
            if d2 <= best.bound {
                best.offer(Neighbor {
                    index: i as u32,
                    d2,
                });
            }
        }
        best.finish();
    }

    /// [`Brute::knn`] in index order; see [`super::KdTree::knn_hinted`].
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
        self.within_in_index_order(q, r, out);
        out.sort_unstable_by_key(|n| n.key());
    }

    /// [`Brute::within`]'s set in index order, the order of the scan.
    pub(crate) fn within_in_index_order(&self, q: Vec3, r: f32, out: &mut Vec<Neighbor>) {
        out.clear();
        let (q, r2) = (q.to_array(), radius2(r));
        for i in 0..self.pts.len() {
            let d2 = dist2(self.pts.get(i), q);
            if d2 <= r2 {
                out.push(Neighbor {
                    index: i as u32,
                    d2,
                });
            }
        }
    }
}
