//! A hashed uniform grid over one pass's light vertices for merging's range queries (the
//! structure SmallVCM and Hachisuka and Jensen 2009 §4.3 use): cells of twice the radius, so
//! the 2 x 2 x 2 cells nearest a point hold every vertex within the radius of it. Built by a
//! counting sort, so each bucket lists its vertices in their index order and a query visits
//! them in an order fixed by the vertices alone. Each bucket also holds its points' positions
//! in the same order, so a query rejects the candidates beyond the radius (most of them: the
//! eight cells cover 16 r² of a surface, the disc π r²) without loading their vertices from
//! a pass's array of many megabytes; on McGuire's Glossy box that load was a cache miss per
//! candidate and a quarter of the method's cycles (`perf`).

use glam::Vec3;

pub struct Grid {
    origin: Vec3,
    inv_cell: f32,
    mask: usize,
    /// Bucket `b` holds `items[starts[b]..starts[b + 1]]`.
    starts: Vec<u32>,
    items: Vec<u32>,
    /// `points[k]` is the position of point `items[k]`.
    points: Vec<Vec3>,
    r2: f32,
}

impl Grid {
    /// The grid of `points` for queries of `radius`.
    pub fn build(points: impl ExactSizeIterator<Item = Vec3> + Clone, radius: f32) -> Grid {
        let n = points.len();
        let buckets = n.max(1).next_power_of_two();
        let origin = points
            .clone()
            .fold(Vec3::splat(f32::INFINITY), |m, p| m.min(p));
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
            items: vec![0; n],
            points: vec![Vec3::ZERO; n],
            r2: radius * radius,
        };
        let cells: Vec<usize> = points
            .clone()
            .map(|p| grid.bucket_of(grid.cell(p)))
            .collect();
        for &b in &cells {
            grid.starts[b + 1] += 1;
        }
        for b in 0..buckets {
            grid.starts[b + 1] += grid.starts[b];
        }
        let mut fill = grid.starts.clone();
        for (i, (&b, p)) in cells.iter().zip(points).enumerate() {
            grid.items[fill[b] as usize] = i as u32;
            grid.points[fill[b] as usize] = p;
            fill[b] += 1;
        }
        grid
    }

    fn cell(&self, p: Vec3) -> [i32; 3] {
        let c = ((p - self.origin) * self.inv_cell).floor();
        [c.x as i32, c.y as i32, c.z as i32]
    }

    fn bucket_of(&self, c: [i32; 3]) -> usize {
        // Teschner et al. 2003's spatial hash.
        let h = (c[0] as u32).wrapping_mul(73_856_093)
            ^ (c[1] as u32).wrapping_mul(19_349_663)
            ^ (c[2] as u32).wrapping_mul(83_492_791);
        h as usize & self.mask
    }

    /// Calls `f` with the index of every point within the radius of `p`, each once, in an
    /// order fixed by the points (a hash collision brings other cells' points into a
    /// bucket, but only those within the radius pass).
    ///
    /// The eight buckets are random places in arrays of megabytes: their bounds, then their
    /// points and items, are each prefetched for all eight before any is read, so the misses
    /// overlap (`math::prefetch`; results are the same without).
    pub fn query(&self, p: Vec3, mut f: impl FnMut(usize)) {
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
            // Two of the eight cells in one bucket would visit its points twice.
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
            math::prefetch(&self.items[r.clone()]);
        }
        for r in &ranges[..n] {
            for (&i, &q) in self.items[r.clone()].iter().zip(&self.points[r.clone()]) {
                if self.within(p, q) {
                    f(i as usize);
                }
            }
        }
    }

    /// Whether `q` lies within the radius of `p`.
    #[inline]
    fn within(&self, p: Vec3, q: Vec3) -> bool {
        (p - q).length_squared() <= self.r2
    }
}
