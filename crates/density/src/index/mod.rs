//! Nearest-neighbour search over point positions, three interchangeable back-ends in a
//! closed enum dispatched by `match` (the set is fixed, so no trait object): our own
//! kd-tree (`kdtree.rs`), kiddo's immutable tree (`kiddo.rs`), and brute force, the
//! reference (`brute.rs`). Two queries:
//!
//! - k-NN under a maximum radius: the `k` points with the smallest key `(d2, index)` among
//!   those with `d2 <= r_max^2`, sorted by that key;
//! - fixed radius (`within`): every point with `d2 <= r^2`, sorted by the same key.
//!
//! Ties at equal distance are therefore broken by the smaller index, identically
//! everywhere, so the tests can demand exact equality with brute force.

mod brute;
mod kdtree;
mod kiddo;

pub use brute::Brute;
pub use kdtree::KdTree;
pub use kiddo::Kiddo;

use glam::Vec3;
use serde::{Deserialize, Serialize};

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

/// `r^2`; infinity means "no limit". A NaN or negative radius is taken as 0, which finds
/// only points exactly at the query.
#[inline]
fn radius2(r: f32) -> f32 {
    if r >= 0.0 { r * r } else { 0.0 }
}

/// Point positions as three coordinate arrays (SoA), the one copy of the positions a
/// [`crate::PhotonMap`] keeps. A leaf's distances are then one vectorised loop over three
/// cache lines (the layout of Wald et al. 2001, "Interactive Rendering with Coherent Ray
/// Tracing", §3; measured faster than `[f32; 3]` rows for the kd-tree).
#[derive(Clone, Debug, Default)]
pub(crate) struct Points {
    xyz: [Vec<f32>; 3],
}

impl Points {
    pub(crate) fn new(points: &[[f32; 3]]) -> Points {
        Points {
            xyz: [0, 1, 2].map(|a| points.iter().map(|p| p[a]).collect()),
        }
    }

    pub(crate) fn len(&self) -> usize {
        self.xyz[0].len()
    }

    #[inline]
    pub(crate) fn get(&self, i: usize) -> [f32; 3] {
        [self.xyz[0][i], self.xyz[1][i], self.xyz[2][i]]
    }
}

/// The k smallest `(d2, index)` so far, kept in the caller's `Vec` (no allocation per
/// query once the scratch vector has grown). Not a heap: candidates are appended to a buffer
/// of up to 2k and, when it fills, `select_nth_unstable` keeps the k smallest (amortised
/// O(1) per candidate against a heap's O(log k); the "buffered k-selection" used by GPU
/// k-NN, e.g. Johnson, Douze, Jégou 2019, "Billion-scale similarity search with GPUs").
/// `bound` is the squared distance a point must not exceed to be offered: `r_max^2` until
/// k points are seen, then the k-th smallest distance, so the search radius shrinks.
struct Best<'a> {
    /// `out[..len]` are the candidates; entries beyond are room to write into.
    out: &'a mut Vec<Neighbor>,
    len: usize,
    k: usize,
    cap: usize,
    bound: f32,
}

impl<'a> Best<'a> {
    fn new(out: &'a mut Vec<Neighbor>, k: usize, r2: f32) -> Best<'a> {
        Best {
            out,
            len: 0,
            k,
            // First compaction as soon as k points are in, to start shrinking the radius.
            cap: k,
            bound: r2,
        }
    }

    /// Offer a point whose `d2 <= self.bound` (checked by the caller, on the hot path).
    #[inline]
    fn offer(&mut self, n: Neighbor) {
        if self.out.len() <= self.len {
            self.out.resize(2 * self.len + 16, n);
        }
        self.out[self.len] = n;
        self.len += 1;
        if self.len >= self.cap {
            self.compact();
        }
    }

    /// Offer a leaf's points (`d2s[j]` for `ids[j]`), those within the bound, by a
    /// branch-free left-pack: every point is written, and kept by advancing the length (no
    /// mispredicted branch per point; the SIMD "left-pack" idiom, e.g. Lemire's blog,
    /// "Quickly pruning elements in SIMD vectors", 2017).
    #[inline]
    fn offer_leaf(&mut self, d2s: &[f32], ids: &[u32]) {
        let m = d2s.len().min(ids.len());
        if self.out.len() < self.len + m {
            self.out
                .resize(2 * self.len + 2 * m, Neighbor { index: 0, d2: 0.0 });
        }
        let bound = self.bound;
        let dst = &mut self.out[self.len..self.len + m];
        let mut kept = 0;
        for j in 0..m {
            // `kept <= j`: in bounds.
            dst[kept.min(m - 1)] = Neighbor {
                index: ids[j],
                d2: d2s[j],
            };
            kept += (d2s[j] <= bound) as usize;
        }
        self.len += kept;
        if self.len >= self.cap {
            self.compact();
        }
    }

    /// Keep the k smallest keys; the k-th becomes the bound (points tied with it in d2 may
    /// still win on index, so the caller keeps `d2 <= bound`).
    #[cold]
    fn compact(&mut self) {
        let k = self.k;
        self.out[..self.len].select_nth_unstable_by_key(k - 1, |n| n.key());
        self.len = k;
        self.bound = self.out[k - 1].d2;
        self.cap = k.saturating_mul(2).max(k + 16);
    }

    /// Keep the k smallest, unsorted, in `out` (truncated to them).
    fn select(&mut self) {
        self.out.truncate(self.len);
        if self.len > self.k {
            self.out.select_nth_unstable_by_key(self.k - 1, |n| n.key());
            self.out.truncate(self.k);
        }
    }

    /// Sorted by key, the k smallest.
    fn finish(self) {
        self.out.truncate(self.len);
        sort_neighbors(self.out, self.k);
    }
}

/// The k smallest by `(d2, index)`, sorted, in expected linear time: a bucket sort on d2 (Knuth, TAOCP vol. 3,
/// §5.2.5, "distribution sorting"). On a surface, the k nearest's d2 is near uniform over
/// [0, r_k²] (the area within r grows like r²), so `n` buckets over [0, max d2] hold about
/// one point each; one counting pass and one scatter put every point in its bucket, and an
/// insertion sort, whose work is the inversions left (within buckets only), finishes.
/// Measured against `sort_unstable` (pattern-defeating quicksort, O(n log n)), which was
/// the largest cost of a k = 250 query. Few points, d2 all zero or not finite, or a bucket
/// with many ties (duplicate photons): `sort_unstable`. Buckets past the one holding the
/// k-th point are not sorted.
pub(crate) fn sort_neighbors(out: &mut Vec<Neighbor>, k: usize) {
    let n = out.len();
    if n <= 32 {
        out.sort_unstable_by_key(|n| n.key());
    } else if n <= 256 {
        sort_bucketed::<512>(out, k);
    } else if n <= 1024 {
        sort_bucketed::<2048>(out, k);
    } else {
        sort_bucketed::<4096>(out, k);
    }
    out.truncate(k);
}

fn sort_bucketed<const B: usize>(out: &mut Vec<Neighbor>, k: usize) {
    let n = out.len();
    // Twice as many buckets as points: fewer share one, fewer inversions to undo.
    let nb = (2 * n).min(B - 1);
    let hi = out.iter().fold(0f32, |m, n| m.max(n.d2));
    let scale = nb as f32 / hi;
    if !(scale.is_finite() && scale > 0.0) {
        out.sort_unstable_by_key(|n| n.key());
        return;
    }
    // d2 * scale is in [0, nb]; clamped below nb.
    let bucket = |d2: f32| round_small(d2 * scale).min(nb - 1);
    let mut start = [0u32; B];
    for e in out.iter() {
        start[bucket(e.d2)] += 1;
    }
    // Bucket starts, and `cut`: the bucket holding the k-th smallest. Later buckets
    // cannot hold any of the first k, so they are not sorted.
    let (mut sum, mut most, mut cut) = (0u32, 0u32, nb - 1);
    for (b, c) in start[..nb].iter_mut().enumerate() {
        most = most.max(*c);
        (*c, sum) = (sum, sum + *c);
        if (*c as usize) < k && sum as usize >= k {
            cut = b;
        }
    }
    if most > 32 {
        out.sort_unstable_by_key(|n| n.key());
        return;
    }
    // Points in buckets up to `cut`, and one slot past them that points beyond `cut` all
    // overwrite (branch-free).
    let kept = if cut + 1 < nb {
        start[cut + 1]
    } else {
        n as u32
    };
    start[cut + 1] = kept;
    // Scatter from a copy in the spare tail.
    out.extend_from_within(..);
    for i in n..2 * n {
        let e = out[i];
        let b = bucket(e.d2);
        let slot = b.min(cut + 1);
        out[start[slot] as usize] = e;
        start[slot] += (b <= cut) as u32;
    }
    out.truncate(kept as usize);
    for i in 1..out.len() {
        let e = out[i];
        let mut j = i;
        while j > 0 && out[j - 1].key() > e.key() {
            out[j] = out[j - 1];
            j -= 1;
        }
        out[j] = e;
    }
}

/// `v` rounded to an integer, for 0 <= v <= 2^22, without a float-to-integer conversion:
/// v + 2^23 has exponent 23, so its low mantissa bits are v rounded (the usual "magic
/// number" trick). Monotone like the floor, which is all bucketing needs.
#[inline(always)]
fn round_small(v: f32) -> usize {
    const MAGIC: f32 = 8_388_608.0; // 2^23
    (v + MAGIC).to_bits().wrapping_sub(MAGIC.to_bits()) as usize
}

/// Keep the k smallest `(d2, index)` of `out`, in their order. Selection by bucketing:
/// d2 ↦ round(256 d2 / max d2) is monotone, so counting per bucket finds the bucket holding
/// the k-th key in one pass; only that bucket (a few points, as d2 is near uniform on a
/// surface) is selected exactly, in `out`'s spare tail. A radix select (Alabi et al. 2012,
/// "Fast k-selection algorithms for graphics processing units", bucket select): one
/// counting pass instead of introselect's repeated partitions of all candidates.
///
/// The bucket is computed by [`round_small`]. Two histograms, alternating, so runs of
/// equal buckets (neighbouring points in slot order) do not serialise on one counter.
fn keep_k_smallest(out: &mut Vec<Neighbor>, k: usize) {
    const B: usize = 256;
    let m = out.len();
    if m <= k {
        return;
    }
    let hi = out.iter().fold(0f32, |a, n| a.max(n.d2));
    let scale = B as f32 / hi;
    // In 0..=B (d2 * scale <= B up to rounding, which rounds to B at most): B + 1 buckets.
    let bucket = |d2: f32| round_small(d2 * scale) & 511;
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

/// The hinted answer of a back-end without a radius-first search: its exact k-NN, put in
/// index order (the order `knn_hinted` promises), with the hint updated.
fn in_index_order(q: Vec3, k: usize, r_max: f32, hint: &mut KnnHint, out: &mut [Neighbor]) {
    out.sort_unstable_by_key(|n| n.index);
    hint.update(q, k, r_max, out);
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

    /// The name parameter files use (the serde spelling).
    pub fn name(self) -> &'static str {
        match self {
            IndexKind::KdTree => "kd_tree",
            IndexKind::Kiddo => "kiddo",
            IndexKind::Brute => "brute",
        }
    }
}

/// A built index: a closed set of back-ends, dispatched by `match`.
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

    pub fn len(&self) -> usize {
        self.points().len()
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The positions, by the index results use (by slot for a [`KdTree`] not relabelled
    /// with [`KdTree::relabel_by_slot`]).
    pub(crate) fn points(&self) -> &Points {
        match self {
            Index::KdTree(t) => t.points(),
            Index::Kiddo(t) => t.points(),
            Index::Brute(t) => t.points(),
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

    /// Every point with `d2 <= r^2` (`r` infinite: all of them; NaN or negative: only
    /// points exactly at `q`), sorted by `(d2, index)` like [`Index::knn`], written to
    /// `out` (cleared first). For splatting and fixed-radius (progressive) estimates. Same
    /// answer from every back-end.
    pub fn within(&self, q: Vec3, r: f32, out: &mut Vec<Neighbor>) {
        match self {
            Index::KdTree(t) => t.within(q, r, out),
            Index::Kiddo(t) => t.within(q, r, out),
            Index::Brute(t) => t.within(q, r, out),
        }
    }

    /// [`Index::within`]'s set in index order (an order that depends on the set alone,
    /// as the estimate's f64 sum needs): no sort for a relabelled kd-tree, whose range
    /// search walks slots in order.
    pub(crate) fn within_in_index_order(&self, q: Vec3, r: f32, out: &mut Vec<Neighbor>) {
        match self {
            Index::KdTree(t) => t.within_in_index_order(q, r, out),
            Index::Kiddo(t) => t.within_in_index_order(q, r, out),
            Index::Brute(t) => t.within_in_index_order(q, r, out),
        }
    }
}
