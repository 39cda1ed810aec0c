use super::*;
use crate::index::dist2;
use crate::{Index, KnnHint, MapPhoton, Neighbor, PhotonMap};
use glam::Vec3;
use math::Rng;
use store::Photon;

/// The oracle: sort everything within `r_max` by (d2, index), keep `k`.
fn reference(points: &[[f32; 3]], q: Vec3, k: usize, r_max: f32) -> Vec<Neighbor> {
    let r2 = if r_max >= 0.0 { r_max * r_max } else { 0.0 };
    let mut v: Vec<Neighbor> = points
        .iter()
        .enumerate()
        .map(|(i, &p)| Neighbor {
            index: i as u32,
            d2: dist2(p, q.to_array()),
        })
        .filter(|n| n.d2 <= r2)
        .collect();
    v.sort_by(|a, b| a.d2.total_cmp(&b.d2).then(a.index.cmp(&b.index)));
    v.truncate(k);
    v
}

fn check(
    index: &Index,
    points: &[[f32; 3]],
    q: Vec3,
    k: usize,
    r_max: f32,
    out: &mut Vec<Neighbor>,
) {
    index.knn(q, k, r_max, out);
    let want = reference(points, q, k, r_max);
    assert_eq!(
        *out,
        want,
        "{} n={} q={q} k={k} r_max={r_max}",
        index.kind().name(),
        points.len()
    );
}

/// Points on the integer grid {0..3}^3: many exact ties and duplicates.
fn grid_points(n: usize, rng: &mut Rng) -> Vec<[f32; 3]> {
    (0..n)
        .map(|_| [0, 0, 0].map(|_: i32| rng.below(4) as f32))
        .collect()
}

fn random_points(n: usize, rng: &mut Rng) -> Vec<[f32; 3]> {
    (0..n)
        .map(|_| [rng.uniform(), rng.uniform(), rng.uniform()])
        .collect()
}

each_index!(
    equals_brute_force_for_every_n_up_to_64,
    |kind: IndexKind| {
        let mut out = Vec::new();
        for n in 0..=64usize {
            let mut rng = Rng::for_index(7, n as u64);
            for (points, lo, step, radius) in [
                (grid_points(n, &mut rng), -0.5f32, 1.3f32, 1.5f32),
                (random_points(n, &mut rng), -0.25, 0.5, 0.4),
            ] {
                let index = Index::build(kind, &points);
                for i in 0..64 {
                    let q = Vec3::new(
                        lo + step * (i % 4) as f32,
                        lo + step * (i / 4 % 4) as f32,
                        lo + step * (i / 16) as f32,
                    );
                    for k in [0, 1, 2, 5, n, n + 3] {
                        for r_max in [f32::INFINITY, radius, 0.0] {
                            check(&index, &points, q, k, r_max, &mut out);
                        }
                    }
                }
            }
        }
    }
);

each_index!(equals_brute_force_on_10k_photons, |kind: IndexKind| {
    let mut rng = Rng::new(11);
    let mut points: Vec<[f32; 3]> = (0..10_000)
        .map(|_| crate::bench::point_on_unit_cube(&mut rng))
        .collect();
    // A few exact duplicates and a dense clump.
    points.extend_from_within(0..50);
    points.extend((0..200).map(|i| [0.5, 0.5, 1e-4 * (i % 7) as f32]));
    let index = Index::build(kind, &points);
    let mut out = Vec::new();
    for i in 0..100 {
        let q = if i % 2 == 0 {
            Vec3::from(crate::bench::point_on_unit_cube(&mut rng))
        } else {
            Vec3::new(rng.uniform(), rng.uniform(), rng.uniform()) * 1.2 - 0.1
        };
        for k in [1, 10, 50, 250] {
            for r_max in [f32::INFINITY, 0.05] {
                check(&index, &points, q, k, r_max, &mut out);
            }
        }
    }
    check(
        &index,
        &points,
        Vec3::new(0.5, 0.5, 0.0),
        100,
        f32::INFINITY,
        &mut out,
    );
});

// Large k over points on a coarse grid of the cube's faces: every distance is shared by
// many points, so each compaction of the k-NN buffer and each leaf cut at the bound
// lands in a tie that only the index settles. Sizes straddle a change of tree depth
// (leaves of 32 and of 16-17 points).
each_index!(large_k_with_ties_equals_brute_force, |kind: IndexKind| {
    let mut out = Vec::new();
    for n in [4095usize, 4097] {
        let mut rng = Rng::new(n as u64);
        let points: Vec<[f32; 3]> = (0..n)
            .map(|_| crate::bench::point_on_unit_cube(&mut rng).map(|c| (c * 16.0).round() / 16.0))
            .collect();
        let index = Index::build(kind, &points);
        for _ in 0..12 {
            let q = Vec3::from(
                crate::bench::point_on_unit_cube(&mut rng).map(|c| (c * 8.0).round() / 8.0),
            );
            for k in [31, 100, 1000] {
                for r_max in [f32::INFINITY, 0.25] {
                    check(&index, &points, q, k, r_max, &mut out);
                }
            }
        }
    }
});

each_index!(duplicates_all_at_one_point, |kind: IndexKind| {
    let points = vec![[0.25f32, -1.0, 3.0]; 1000];
    let index = Index::build(kind, &points);
    let mut out = Vec::new();
    for q in [Vec3::new(0.25, -1.0, 3.0), Vec3::ZERO, Vec3::splat(1e6)] {
        for k in [1, 10, 999, 1000, 1500] {
            for r_max in [f32::INFINITY, 0.5, 0.0] {
                check(&index, &points, q, k, r_max, &mut out);
            }
        }
    }
});

each_index!(
    photon_map_indices_point_at_its_photons,
    |kind: IndexKind| {
        let mut rng = Rng::new(3);
        let photons: Vec<Photon> = (0..2000)
            .map(|i| {
                let p = Vec3::from(crate::bench::point_on_unit_cube(&mut rng));
                let dir = Vec3::new(rng.uniform(), rng.uniform(), rng.uniform()) - 0.5;
                Photon::new(p, Vec3::splat(i as f32), dir, i)
            })
            .collect();
        let map = PhotonMap::build(photons.clone(), kind);
        assert_eq!(map.len(), photons.len());
        // As given, each field from its own slot: the surface id names the photon given.
        let given = |i: usize| {
            let p = &photons[map.surface(i) as usize];
            MapPhoton {
                position: p.position(),
                direction: p.direction(),
                power: p.power(),
                surface: p.surface,
            }
        };
        let mut out = Vec::new();
        for (q, r) in [
            (Vec3::new(0.3, 0.0, 0.6), 0.2),
            (Vec3::new(1.0, 0.5, 0.5), 0.2),
        ] {
            map.knn(q, 20, f32::INFINITY, &mut out);
            assert_eq!(out.len(), 20);
            let mut found = out.clone();
            map.within(q, r, &mut out);
            assert!(out.len() > 20, "{}", out.len());
            found.extend_from_slice(&out);
            for nb in &found {
                let i = nb.index as usize;
                assert_eq!(dist2(map.position(i).to_array(), q.to_array()), nb.d2);
                assert_eq!(map.photon(i), given(i));
            }
        }
        // The iterator walks map order and holds every photon once.
        assert_eq!(map.iter().len(), map.len());
        let mut surfaces = Vec::new();
        for (i, p) in map.iter().enumerate() {
            assert_eq!(p, map.photon(i));
            assert_eq!(p, given(i));
            surfaces.push(p.surface);
        }
        surfaces.sort_unstable();
        assert!(surfaces.iter().copied().eq(0..photons.len() as u32));
    }
);

/// [`Index::within`] returns exactly the oracle's points in `(d2, index)` order, and the
/// estimate's index-order variant the same set by index.
fn check_within(index: &Index, points: &[[f32; 3]], q: Vec3, r: f32, out: &mut Vec<Neighbor>) {
    let what = format!("{} n={} q={q} r={r}", index.kind().name(), points.len());
    let want = reference(points, q, usize::MAX, r);
    index.within(q, r, out);
    assert_eq!(*out, want, "{what}");
    index.within_in_index_order(q, r, out);
    let mut by_index = want;
    by_index.sort_by_key(|n| n.index);
    assert_eq!(*out, by_index, "{what} (index order)");
}

/// Radii for `within`: zero (exact hits only), tiny, the scale of the points, grid
/// distances (exact ties), one whose square overflows, infinite, and invalid ones.
const RADII: [f32; 11] = [
    0.0,
    1e-3,
    0.2,
    0.45,
    1.0,
    std::f32::consts::SQRT_2,
    1e30,
    f32::MAX,
    f32::INFINITY,
    -1.0,
    f32::NAN,
];

each_index!(
    within_equals_brute_force_for_every_n_up_to_64,
    |kind: IndexKind| {
        let mut out = Vec::new();
        for n in 0..=64usize {
            let mut rng = Rng::for_index(27, n as u64);
            for (points, lo, step) in [
                (grid_points(n, &mut rng), -0.5f32, 1.3f32),
                (random_points(n, &mut rng), -0.25, 0.5),
            ] {
                let index = Index::build(kind, &points);
                for i in 0..64 {
                    let q = Vec3::new(
                        lo + step * (i % 4) as f32,
                        lo + step * (i / 4 % 4) as f32,
                        lo + step * (i / 16) as f32,
                    );
                    for r in RADII
                        .into_iter()
                        .chain([rng.uniform(), 3.0 * rng.uniform()])
                    {
                        check_within(&index, &points, q, r, &mut out);
                    }
                }
                // On the points themselves: exact hits, and grid neighbours at exactly r.
                for &p in points.iter().take(8) {
                    for r in [0.0, 1.0, rng.uniform()] {
                        check_within(&index, &points, Vec3::from(p), r, &mut out);
                    }
                }
                check_within(&index, &points, Vec3::NAN, f32::INFINITY, &mut out);
            }
        }
    }
);

each_index!(
    within_equals_brute_force_on_10k_photons,
    |kind: IndexKind| {
        let mut rng = Rng::new(13);
        let mut points: Vec<[f32; 3]> = (0..10_000)
            .map(|_| crate::bench::point_on_unit_cube(&mut rng))
            .collect();
        // Exact duplicates and a dense clump.
        points.extend_from_within(0..50);
        points.extend((0..200).map(|i| [0.5, 0.5, 1e-4 * (i % 7) as f32]));
        let index = Index::build(kind, &points);
        let mut out = Vec::new();
        for i in 0..100 {
            let q = match i % 4 {
                0 => Vec3::new(0.5, 0.5, 0.0),
                1 => Vec3::from(points[rng.below(points.len() as u32) as usize]),
                2 => Vec3::new(rng.uniform(), rng.uniform(), rng.uniform()) * 1.2 - 0.1,
                _ => Vec3::from(crate::bench::point_on_unit_cube(&mut rng)),
            };
            for r in [0.0, 0.2 * rng.uniform(), 0.02 * rng.uniform(), 1e-4] {
                check_within(&index, &points, q, r, &mut out);
            }
        }
        // Everything, once.
        check_within(&index, &points, Vec3::splat(0.5), 2.0, &mut out);
        assert_eq!(out.len(), points.len());
    }
);

each_index!(within_an_empty_index_finds_nothing, |kind: IndexKind| {
    let index = Index::build(kind, &[]);
    assert!(index.is_empty());
    // A stale result must not survive the call.
    let mut out = vec![Neighbor { index: 7, d2: 1.0 }; 3];
    for r in RADII {
        for q in [Vec3::ZERO, Vec3::NAN] {
            index.within(q, r, &mut out);
            assert!(out.is_empty(), "r={r} q={q}");
            out.push(Neighbor { index: 7, d2: 1.0 });
        }
    }
});

/// Radius guesses for `knn_hinted`: none, useless, too small, about right, too large.
fn hints(at: Vec3, r: f32) -> [KnnHint; 10] {
    [
        KnnHint::NONE,
        KnnHint::new(at, 0.0),
        KnnHint::new(at, f32::NAN),
        KnnHint::new(at, f32::INFINITY),
        KnnHint::new(at, -1.0),
        KnnHint::new(at, 1e-30),
        KnnHint::new(at, r * 0.5),
        KnnHint::new(at, r),
        KnnHint::new(at, r * 30.0),
        KnnHint::new(Vec3::NAN, r),
    ]
}

/// `knn_hinted` finds exactly `knn`'s set, in the same order whatever the hint, and
/// leaves the k-th distance (or r_max) in the hint.
fn check_hinted(
    index: &Index,
    q: Vec3,
    k: usize,
    r_max: f32,
    carried: &mut KnnHint,
    out: &mut Vec<Neighbor>,
) {
    let mut want = Vec::new();
    index.knn(q, k, r_max, &mut want);
    let r = want.last().map_or(0.1, |n| n.d2.sqrt());
    let mut first: Option<Vec<Neighbor>> = None;
    for (i, mut hint) in hints(q + Vec3::splat(0.01), r)
        .into_iter()
        .chain([*carried])
        .enumerate()
    {
        index.knn_hinted(q, k, r_max, &mut hint, out);
        let what = format!(
            "{} q={q} k={k} r_max={r_max} hint #{i}",
            index.kind().name()
        );
        let mut sorted = out.clone();
        sorted.sort_by_key(|n| (n.d2.to_bits(), n.index));
        assert_eq!(sorted, want, "{what}");
        match &first {
            None => first = Some(out.clone()),
            Some(f) => assert_eq!(out, f, "{what}: order depends on the hint"),
        }
        if !want.is_empty() && q.is_finite() {
            let expect = if want.len() == k { r } else { r_max };
            assert_eq!(hint.r.to_bits(), expect.to_bits(), "{what}");
        }
    }
    index.knn_hinted(q, k, r_max, carried, out);
}

each_index!(
    hinted_equals_plain_for_every_n_up_to_64,
    |kind: IndexKind| {
        let mut out = Vec::new();
        for n in 0..=64usize {
            let mut rng = Rng::for_index(17, n as u64);
            for (points, lo, step, radius) in [
                (grid_points(n, &mut rng), -0.5f32, 1.3f32, 1.5f32),
                (random_points(n, &mut rng), -0.25, 0.5, 0.4),
            ] {
                let index = Index::build(kind, &points);
                let mut carried = KnnHint::NONE;
                for i in 0..64 {
                    let q = Vec3::new(
                        lo + step * (i % 4) as f32,
                        lo + step * (i / 4 % 4) as f32,
                        lo + step * (i / 16) as f32,
                    );
                    for k in [0, 1, 2, 5, n, n + 3] {
                        for r_max in [f32::INFINITY, radius, 0.0] {
                            check_hinted(&index, q, k, r_max, &mut carried, &mut out);
                        }
                    }
                }
            }
        }
    }
);

each_index!(hinted_equals_plain_on_10k_photons, |kind: IndexKind| {
    let mut rng = Rng::new(12);
    let mut points: Vec<[f32; 3]> = (0..10_000)
        .map(|_| crate::bench::point_on_unit_cube(&mut rng))
        .collect();
    points.extend_from_within(0..50);
    points.extend((0..300).map(|i| [0.5, 0.5, 1e-4 * (i % 7) as f32]));
    let index = Index::build(kind, &points);
    let mut out = Vec::new();
    let mut carried = KnnHint::NONE;
    // A walk of small steps (the coherent case the hint is for), jumps, and the clump.
    let mut q = Vec3::new(0.3, 0.0, 0.3);
    for i in 0..150 {
        q = match i % 10 {
            0 => Vec3::from(crate::bench::point_on_unit_cube(&mut rng)),
            1 => Vec3::new(0.5, 0.5, 0.0),
            2 => Vec3::NAN,
            3 => Vec3::new(rng.uniform(), rng.uniform(), rng.uniform()) * 1.2 - 0.1,
            _ => q + Vec3::new(rng.uniform(), 0.0, rng.uniform()) * 0.01,
        };
        for k in [1, 10, 250, 1000] {
            for r_max in [f32::INFINITY, 0.05] {
                check_hinted(&index, q, k, r_max, &mut carried, &mut out);
            }
        }
    }
});

each_index!(hinted_duplicates_all_at_one_point, |kind: IndexKind| {
    let points = vec![[0.25f32, -1.0, 3.0]; 1000];
    let index = Index::build(kind, &points);
    let mut out = Vec::new();
    let mut carried = KnnHint::NONE;
    for q in [Vec3::new(0.25, -1.0, 3.0), Vec3::ZERO, Vec3::splat(1e6)] {
        for k in [1, 10, 999, 1000, 1500] {
            for r_max in [f32::INFINITY, 0.5, 0.0] {
                check_hinted(&index, q, k, r_max, &mut carried, &mut out);
            }
        }
    }
});

// The depth-first search, now the radius-first search's fallback (and the leaves' density
// estimate), still equals brute force on its own: surface photons with duplicates and a
// clump, and a coarse grid where every distance is shared by many points.
#[test]
fn kd_tree_depth_first_equals_brute_force() {
    let mut rng = Rng::new(13);
    let mut sets: Vec<Vec<[f32; 3]>> = Vec::new();
    let mut photons: Vec<[f32; 3]> = (0..10_000)
        .map(|_| crate::bench::point_on_unit_cube(&mut rng))
        .collect();
    photons.extend_from_within(0..50);
    photons.extend((0..200).map(|i| [0.5, 0.5, 1e-4 * (i % 7) as f32]));
    sets.push(photons);
    sets.push(
        (0..4097)
            .map(|_| crate::bench::point_on_unit_cube(&mut rng).map(|c| (c * 16.0).round() / 16.0))
            .collect(),
    );
    let mut out = Vec::new();
    for points in &sets {
        let tree = crate::KdTree::build(points);
        for i in 0..60 {
            let q = if i % 2 == 0 {
                Vec3::from(crate::bench::point_on_unit_cube(&mut rng))
            } else {
                Vec3::new(0.5, 0.5, 0.0)
            };
            for k in [1, 31, 250, 1000] {
                for r_max in [f32::INFINITY, 0.05] {
                    tree.knn_depth_first(q, k, r_max, &mut out);
                    assert_eq!(
                        out,
                        reference(points, q, k, r_max),
                        "q={q} k={k} r_max={r_max}"
                    );
                }
            }
        }
    }
}

/// Density that changes a hundredfold within a leaf's reach: a dense patch on a sparse
/// face, queried across its rim, where the radius guessed from the query's leaf is far
/// too small (sparse side of the rim) or far too large (dense side), so the radius-first
/// search must grow its radius or give up for the depth-first one, and still be exact.
#[test]
fn kd_tree_radius_guess_off_by_far_stays_exact() {
    let mut rng = Rng::new(14);
    let mut points: Vec<[f32; 3]> = (0..3000)
        .map(|_| [rng.uniform(), rng.uniform(), 0.0])
        .collect();
    points.extend((0..30_000).map(|_| [0.4 + 0.2 * rng.uniform(), 0.4 + 0.2 * rng.uniform(), 0.0]));
    let index = Index::build(crate::IndexKind::KdTree, &points);
    let mut out = Vec::new();
    for i in 0..200 {
        // Along a line across the patch's rim at x = 0.4 and x = 0.6.
        let q = Vec3::new(
            0.3 + 0.4 * i as f32 / 199.0,
            0.5 + 0.05 * rng.uniform(),
            0.0,
        );
        for k in [1, 10, 50, 250, 1000] {
            check(&index, &points, q, k, f32::INFINITY, &mut out);
        }
    }
}

/// The bucket sort orders by `(d2, index)` exactly like a comparison sort: uniform,
/// clustered and tied distances (a bucket of more than 32 ties falls back), zeros, huge
/// and infinite values, at every size tier.
#[test]
fn bucket_sort_equals_comparison_sort() {
    let mut rng = Rng::new(15);
    for n in [0usize, 1, 2, 31, 33, 100, 256, 257, 1000, 1025, 3000, 5000] {
        for case in 0..6 {
            let v: Vec<Neighbor> = (0..n)
                .map(|i| Neighbor {
                    index: rng.below(1 << 20) ^ i as u32,
                    d2: match case {
                        0 => rng.uniform(),
                        1 => rng.uniform().powi(8),
                        2 => (rng.below(5) as f32) * 0.25,
                        3 => 0.0,
                        4 => [0.0, 1e-30, 3e38, f32::INFINITY][rng.below(4) as usize],
                        _ => 1.0 + (i % 3) as f32 * f32::EPSILON,
                    },
                })
                .collect();
            let mut want = v.clone();
            want.sort_by_key(|n| n.key());
            for k in [n, n / 2, 1] {
                let mut got = v.clone();
                crate::index::sort_neighbors(&mut got, k);
                assert_eq!(got, want[..k.min(n)], "n={n} case={case} k={k}");
            }
        }
    }
}
