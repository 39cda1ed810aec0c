//! The BVH4 collapse against every possible collapse of the same binary BVH (SAH cost).

use crate::bvh4::{
    Bvh4, COST_BLOCK, COST_NODE, COST_SPHERE, COUNT_SHIFT, EMPTY, LEAF, LEAF_MAX, SPHERE,
    binary_bvh, prim_boxes,
};
use crate::{Sphere, TriMesh};
use glam::Vec3;
use math::Rng;
use obvhs::{BvhBuildParams, bvh2::Bvh2};

/// Random triangles of sizes spread over two decades, and `n_sph` spheres.
fn scene(n_tri: usize, n_sph: usize, seed: u64) -> (TriMesh, Vec<Sphere>) {
    let mut rng = Rng::new(seed);
    let mut v = |s: f32| Vec3::new(rng.uniform(), rng.uniform(), rng.uniform()) * s;
    let mut mesh = TriMesh::default();
    for i in 0..n_tri {
        let size = if i % 5 == 0 {
            1.0
        } else {
            0.01 + 0.1 * (i % 3) as f32
        };
        let c = v(10.0);
        let p = [c, c + v(size), c + v(size)];
        let base = mesh.positions.len() as u32;
        mesh.positions.extend(p);
        mesh.indices.push([base, base + 1, base + 2]);
        mesh.materials.push(0);
    }
    let spheres = (0..n_sph)
        .map(|i| Sphere {
            center: v(10.0),
            radius: 0.2 + i as f32,
            material: 0,
        })
        .collect();
    (mesh, spheres)
}

fn half_area(lo: [f32; 3], hi: [f32; 3]) -> f64 {
    let d = [0, 1, 2].map(|a| (hi[a] - lo[a]) as f64);
    d[0] * d[1] + d[1] * d[2] + d[2] * d[0]
}

/// SAH cost of the emitted BVH4, read off its nodes alone.
fn emitted_cost(b: &Bvh4) -> f64 {
    fn node(b: &Bvh4, i: u32) -> f64 {
        let n = &b.nodes[i as usize];
        let (mut lo, mut hi) = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);
        let mut cost = 0.0;
        for s in (0..4).filter(|&s| n.child[s] != EMPTY) {
            let (clo, chi) = ([0, 2, 4].map(|r| n.b[r][s]), [1, 3, 5].map(|r| n.b[r][s]));
            for a in 0..3 {
                lo[a] = lo[a].min(clo[a]);
                hi[a] = hi[a].max(chi[a]);
            }
            let c = n.child[s];
            cost += if c & LEAF == 0 {
                node(b, c)
            } else if c & SPHERE != 0 {
                half_area(clo, chi) * COST_SPHERE
            } else {
                let blocks = (c & !LEAF) >> COUNT_SHIFT;
                half_area(clo, chi) * COST_BLOCK * blocks as f64
            };
        }
        cost + half_area(lo, hi) * COST_NODE
    }
    node(b, b.root)
}

struct Tree<'a> {
    bvh2: &'a Bvh2,
    n_tri: u32,
}

impl Tree<'_> {
    fn kids(&self, ni: usize) -> Option<(usize, usize)> {
        let n = &self.bvh2.nodes[ni];
        (n.prim_count == 0).then(|| (n.first_index as usize, n.first_index as usize + 1))
    }
    fn area(&self, ni: usize) -> f64 {
        let b = self.bvh2.nodes[ni].aabb();
        half_area(b.min.to_array(), b.max.to_array())
    }
    /// (triangles, spheres) under `ni`.
    fn count(&self, ni: usize) -> (u32, u32) {
        match self.kids(ni) {
            Some((l, r)) => {
                let (a, b) = (self.count(l), self.count(r));
                (a.0 + b.0, a.1 + b.1)
            }
            None => {
                let p = self.bvh2.primitive_indices[self.bvh2.nodes[ni].first_index as usize];
                if p >= self.n_tri { (0, 1) } else { (1, 0) }
            }
        }
    }
    fn leaf_cost(&self, ni: usize) -> Option<f64> {
        match self.count(ni) {
            (0, 1) => Some(self.area(ni) * COST_SPHERE),
            (t, 0) if t <= LEAF_MAX => Some(self.area(ni) * COST_BLOCK * t.div_ceil(4) as f64),
            _ => None,
        }
    }
    /// Every cost the subtree can have as one slot: by enumeration, no minimum taken
    /// before the end.
    fn all_one(&self, ni: usize) -> Vec<f64> {
        let mut out: Vec<f64> = self.leaf_cost(ni).into_iter().collect();
        if let Some((l, r)) = self.kids(ni) {
            for k in 1..4 {
                for a in self.all_forests(l, k) {
                    for b in self.all_forests(r, 4 - k) {
                        out.push(self.area(ni) * COST_NODE + a + b);
                    }
                }
            }
        }
        out
    }
    /// Every cost of the subtree as a forest of at most `i` slots.
    fn all_forests(&self, ni: usize, i: usize) -> Vec<f64> {
        let mut out = self.all_one(ni);
        if let (Some((l, r)), true) = (self.kids(ni), i >= 2) {
            for k in 1..i {
                for a in self.all_forests(l, k) {
                    for b in self.all_forests(r, i - k) {
                        out.push(a + b);
                    }
                }
            }
        }
        out
    }
    /// The greedy collapse this BVH used before: a leaf whenever allowed, else open the
    /// largest child until four.
    fn greedy(&self, ni: usize) -> f64 {
        if let Some(c) = self.leaf_cost(ni) {
            return c;
        }
        let (l, r) = self.kids(ni).expect("not a leaf");
        let mut kids = vec![l, r];
        while kids.len() < 4 {
            let open = (0..kids.len())
                .filter(|&i| self.leaf_cost(kids[i]).is_none())
                .max_by(|&a, &b| self.area(kids[a]).total_cmp(&self.area(kids[b])));
            let Some(i) = open else { break };
            let (a, b) = self.kids(kids[i]).expect("not a leaf");
            kids[i] = a;
            kids.push(b);
        }
        self.area(ni) * COST_NODE + kids.iter().map(|&k| self.greedy(k)).sum::<f64>()
    }
}

fn build(mesh: &TriMesh, spheres: &[Sphere]) -> (Bvh4, Bvh2) {
    let params = BvhBuildParams::medium_build();
    let b = Bvh4::build(mesh, spheres, params).expect("non-empty");
    // The same deterministic Bvh2 the collapse started from.
    (b, binary_bvh(mesh, spheres, params).expect("non-empty"))
}

#[test]
fn the_collapse_is_the_cheapest_of_all_collapses() {
    for seed in 1..=4 {
        let (mesh, spheres) = scene(9, 2, seed);
        let (b, bvh2) = build(&mesh, &spheres);
        let t = Tree {
            bvh2: &bvh2,
            n_tri: mesh.len() as u32,
        };
        let all = t.all_one(0);
        let best = all.iter().copied().fold(f64::INFINITY, f64::min);
        let worst = all.iter().copied().fold(0.0, f64::max);
        let got = emitted_cost(&b);
        assert!(
            all.len() > 50 && worst > 1.5 * best,
            "{} collapses, {best}..{worst}",
            all.len()
        );
        assert!(
            (got - best).abs() <= 1e-5 * best,
            "seed {seed}: emitted {got}, optimum {best}"
        );
    }
}

#[test]
fn the_collapse_beats_the_greedy_one_on_a_larger_scene() {
    // Measured: 6.2% below the greedy collapse; the bound leaves 2% of it.
    let (mesh, spheres) = scene(400, 3, 7);
    let (b, bvh2) = build(&mesh, &spheres);
    let t = Tree {
        bvh2: &bvh2,
        n_tri: mesh.len() as u32,
    };
    let (got, greedy) = (emitted_cost(&b), t.greedy(0));
    assert!(got < 0.96 * greedy, "optimal {got}, greedy {greedy}");
}

/// `binary_bvh` writes PLOC's leaves from the mesh itself instead of a list of boxes: the
/// `Bvh2` must be the one obvhs' `build_bvh2` makes from those boxes, node for node, on one
/// thread and on several (sizes past PLOC's and the sort's parallel and radix thresholds and
/// past one chunk of the parallel passes, and the build presets' other search distances and
/// sort precisions).
#[test]
fn the_lean_binary_build_is_obvhs_build() {
    use obvhs::bvh2::builder::build_bvh2;
    let presets = [
        BvhBuildParams::medium_build(),
        BvhBuildParams::fast_build(),
        BvhBuildParams::very_fast_build(),
    ];
    for (n_tri, n_sph) in [(1, 0), (0, 2), (37, 3), (5000, 4), (300_000, 0)] {
        let (mesh, spheres) = scene(n_tri, n_sph, 7 + n_tri as u64);
        for params in presets {
            let params = BvhBuildParams {
                max_prims_per_leaf: 1,
                ..params
            };
            let boxes: Vec<_> = prim_boxes(&mesh, &spheres).collect();
            let full = build_bvh2(&boxes, params, &mut Default::default());
            // The parallel passes on one thread and on several: the same tree.
            for threads in [1, 3] {
                let pool = rayon::ThreadPoolBuilder::new()
                    .num_threads(threads)
                    .build()
                    .unwrap();
                let lean = pool.install(|| binary_bvh(&mesh, &spheres, params).unwrap());
                assert_eq!(lean.primitive_indices, full.primitive_indices);
                assert_eq!(lean.nodes.len(), full.nodes.len());
                for (a, b) in lean.nodes.iter().zip(&full.nodes) {
                    assert_eq!(
                        (a.aabb().min, a.aabb().max, a.prim_count, a.first_index),
                        (b.aabb().min, b.aabb().max, b.prim_count, b.first_index)
                    );
                }
            }
            if n_tri == 300_000 {
                break;
            }
        }
    }
}

/// The collapse and the emission run subtrees on several threads: the 4-wide BVH (nodes,
/// their order, blocks) must be the same on one thread and on several, on a tree deeper than
/// the depths where tasks split.
#[test]
fn the_bvh4_is_the_same_on_any_thread_count() {
    let (mesh, spheres) = scene(60_000, 5, 3);
    let on = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| Bvh4::build(&mesh, &spheres, BvhBuildParams::medium_build()).unwrap())
    };
    let one = on(1);
    let (root, stack_need, blocks) = one.built();
    assert!(stack_need > 3 * 8, "depth {}", stack_need / 3);
    for threads in [2, 3] {
        let b = on(threads);
        assert_eq!(b.nodes.len(), one.nodes.len());
        for (x, y) in b.nodes.iter().zip(&one.nodes) {
            assert_eq!((x.b, x.child), (y.b, y.child));
        }
        assert_eq!(b.built(), (root, stack_need, blocks.clone()));
    }
}
