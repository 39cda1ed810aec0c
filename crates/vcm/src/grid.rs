//! A hashed uniform grid over one pass's light vertices for merging's range queries (the
//! structure SmallVCM and Hachisuka and Jensen 2009 §4.3 use): cells of twice the radius, so
//! the 2 x 2 x 2 cells nearest a point hold every vertex within the radius of it. Built by a
//! counting sort, so each bucket lists its vertices in their index order and a query visits
//! them in an order fixed by the vertices alone.
//!
//! Each bucket holds copies of what a query reads, positions and a payload (for merging, the
//! few fields of a light vertex it needs), side by side in bucket order: a pass's vertices in
//! path order span tens of megabytes, and loading each candidate from there was a cache miss
//! apiece and, on McGuire's Glossy box, a quarter of the method's cycles (`perf`).

use glam::Vec3;

pub struct Grid<T> {
    origin: Vec3,
    inv_cell: f32,
    mask: usize,
    /// Bucket `b` holds `points[starts[b]..starts[b + 1]]` and the same range of `data`.
    starts: Vec<u32>,
    points: Vec<Vec3>,
    data: Vec<T>,
    r2: f32,
}

impl<T: Copy + Default> Grid<T> {
    /// The grid of `items` (a position and its payload each) for queries of `radius`.
    pub fn build(items: impl ExactSizeIterator<Item = (Vec3, T)> + Clone, radius: f32) -> Grid<T> {
        let n = items.len();
        let buckets = n.max(1).next_power_of_two();
        let origin = items
            .clone()
            .fold(Vec3::splat(f32::INFINITY), |m, (p, _)| m.min(p));
        let origin = if origin.is_finite() {
            origin
        } else {
            Vec3::ZERO
        };
        let mut grid = Grid {
            origin,
            inv_cell: 0.5 / radius,
            mask: buckets - 1,
            starts: vec![0; buckets + 1],
            points: Vec::new(),
            data: Vec::new(),
            r2: radius * radius,
        };
        let cells: Vec<usize> = items
            .clone()
            .map(|(p, _)| grid.bucket_of(grid.cell(p)))
            .collect();
        for &b in &cells {
            grid.starts[b + 1] += 1;
        }
        for b in 0..buckets {
            grid.starts[b + 1] += grid.starts[b];
        }
        // Items in bucket order, each bucket in index order.
        let mut slot: Vec<u32> = grid.starts[..buckets].to_vec();
        grid.points = vec![Vec3::ZERO; n];
        grid.data = vec![T::default(); n];
        for ((p, t), &b) in items.zip(&cells) {
            let k = slot[b] as usize;
            grid.points[k] = p;
            grid.data[k] = t;
            slot[b] += 1;
        }
        grid
    }

    /// The cell of an item: `p - origin` is never negative (the origin is the items' least
    /// corner), so truncation is the floor, without a call to `floorf` (x86-64's baseline has
    /// no rounding instruction) per coordinate.
    fn cell(&self, p: Vec3) -> [i32; 3] {
        let c = (p - self.origin) * self.inv_cell;
        [c.x as i32, c.y as i32, c.z as i32]
    }

    fn bucket_of(&self, c: [i32; 3]) -> usize {
        // Teschner et al. 2003's spatial hash.
        let h = (c[0] as u32).wrapping_mul(73_856_093)
            ^ (c[1] as u32).wrapping_mul(19_349_663)
            ^ (c[2] as u32).wrapping_mul(83_492_791);
        h as usize & self.mask
    }

    /// Calls `f` with the payload of every item within the radius of `p`, each once, in an
    /// order fixed by the items (a hash collision brings other cells' items into a bucket,
    /// but only those within the radius pass).
    ///
    /// The eight buckets are random places in arrays of megabytes: their bounds, then their
    /// points and payloads, are each prefetched for all eight before any is read, so the
    /// misses overlap (`math::prefetch`; results are the same without).
    pub fn query(&self, p: Vec3, mut f: impl FnMut(&T)) {
        let c = (p - self.origin) * self.inv_cell - Vec3::splat(0.5);
        let base = c.floor();
        let base = [base.x as i32, base.y as i32, base.z as i32];
        let mut buckets = [0usize; 8];
        let mut n = 0;
        for k in 0..8 {
            let cell = [
                base[0] + (k & 1),
                base[1] + ((k >> 1) & 1),
                base[2] + ((k >> 2) & 1),
            ];
            let b = self.bucket_of(cell);
            // Two of the eight cells in one bucket would visit its items twice.
            if !buckets[..n].contains(&b) {
                buckets[n] = b;
                n += 1;
                math::prefetch(&self.starts[b..b + 2]);
            }
        }
        let ranges: [std::ops::Range<usize>; 8] =
            std::array::from_fn(|k| match buckets[..n].get(k) {
                Some(&b) => self.starts[b] as usize..self.starts[b + 1] as usize,
                None => 0..0,
            });
        for r in &ranges[..n] {
            math::prefetch(&self.points[r.clone()]);
            math::prefetch(&self.data[r.clone()]);
        }
        for r in &ranges[..n] {
            for (q, t) in self.points[r.clone()].iter().zip(&self.data[r.clone()]) {
                if (p - *q).length_squared() <= self.r2 {
                    f(t);
                }
            }
        }
    }
}
