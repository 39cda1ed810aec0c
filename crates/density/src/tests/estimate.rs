use super::*;
use crate::{EstimateParams, Kernel, KnnHint, PhotonMap, radiance_lambertian};
use glam::Vec3;
use math::Rng;
use std::f64::consts::PI;
use store::Photon;

/// `n` photons of flux 1, uniform on [x0, x0 + sx] × [z0, z0 + sz] on the floor y = 0,
/// travelling straight down.
fn floor_photons(n: usize, x0: f32, sx: f32, z0: f32, sz: f32, rng: &mut Rng) -> Vec<Photon> {
    (0..n)
        .map(|_| {
            let p = Vec3::new(x0 + sx * rng.uniform(), 0.0, z0 + sz * rng.uniform());
            Photon::new(p, Vec3::ONE, -Vec3::Y, 0)
        })
        .collect()
}

/// Uniform density on a plane, away from its edges.
///
/// Why the biases are what they are (Garcia et al. 2012, 2014): with N photons uniform on
/// area A, λ = N/A, the disc to the k-th photon covers a fraction p ~ Beta(k, N − k + 1)
/// of A, so E[1/(π r²)] = λ / (k − 1); given r, the k − 1 nearer photons are uniform in the
/// disc, so E[Σ_{i<k} K(t_i)] = (k − 1) ∫K / π. Hence
///   E[estimate] / E0 = ∫K + π K(1) / (k − 1)  (the k-th photon on the boundary),
///   E[estimate] / E0 = ∫K                       (dropping it).
/// Uniform: 1 + 1/(k − 1) = k/(k − 1) (+2.04% at k = 50); kernels vanishing at t = 1 are
/// unbiased either way; the renormalised Gaussian has K(1) = 0.150: +0.96%.
#[test]
fn each_estimator_matches_uniform_irradiance_or_its_predicted_bias() {
    const K: usize = 50;
    let (n, reps, queries) = (160_000, 16, 4000);
    // E0 = flux / area = n photons of flux 1 on the unit square.
    let e0 = n as f64;
    let kernels = Kernel::ALL;
    // per (kernel, drop_kth): the mean of E / E0 over each replicate.
    let mut means = vec![Vec::new(); kernels.len() * 2];
    let mut scratch = Vec::new();
    for rep in 0..reps {
        let mut rng = Rng::for_index(2012, rep);
        let map = PhotonMap::build(
            floor_photons(n, 0.0, 1.0, 0.0, 1.0, &mut rng),
            IndexKind::KdTree,
        );
        let mut sums = vec![0.0f64; means.len()];
        for _ in 0..queries {
            // r ≈ 0.01: a 0.1 margin keeps every disc on the plane.
            let x = Vec3::new(0.1 + 0.8 * rng.uniform(), 0.0, 0.1 + 0.8 * rng.uniform());
            map.knn(x, K, f32::INFINITY, &mut scratch);
            for (i, &kernel) in kernels.iter().enumerate() {
                for drop_kth in [false, true] {
                    let p = EstimateParams {
                        k: K,
                        kernel,
                        drop_kth,
                        ..Default::default()
                    };
                    let e = map.irradiance_from_neighbors(x, Vec3::Y, &p, &scratch);
                    sums[2 * i + drop_kth as usize] += e.x as f64 / e0;
                }
            }
        }
        for (m, s) in means.iter_mut().zip(sums) {
            m.push(s / queries as f64);
        }
    }
    let mut report = String::new();
    for (i, &kernel) in kernels.iter().enumerate() {
        let mass = if kernel == Kernel::GaussianJensen {
            crate::jensen_gaussian_mass()
        } else {
            1.0
        };
        for drop_kth in [false, true] {
            let (mean, se) = mean_se(&means[2 * i + drop_kth as usize]);
            let boundary = if drop_kth {
                0.0
            } else {
                PI * kernel.weight(1.0) / (K - 1) as f64
            };
            let predicted = mass + boundary;
            report += &format!(
                "{kernel:?} drop={drop_kth}: {mean:.5} ± {se:.5} (predicted {predicted:.5})\n"
            );
            assert!(se < 0.0015, "standard error too large:\n{report}");
            assert!((mean - predicted).abs() < 0.004, "{report}");
            // The consistent estimators are within 1% of the true irradiance.
            if kernel != Kernel::GaussianJensen && (drop_kth || boundary == 0.0) {
                assert!((mean - 1.0).abs() < 0.01, "{report}");
            }
        }
    }
    // The classic k-NN overestimate, measured: k/(k − 1) − 1 = 2.04% at k = 50.
    let (plain, _) = mean_se(&means[0]);
    let (dropped, _) = mean_se(&means[1]);
    assert!(
        (plain - 1.0 - 1.0 / (K - 1) as f64).abs() < 0.004 && plain - 1.0 > 0.012,
        "{report}"
    );
    assert!((dropped - 1.0).abs() < 0.004, "{report}");
    eprintln!("{report}");
}

/// The fixed-radius estimate on a uniform plane: with r fixed, the photons in the disc are
/// a Poisson-like sample of it and none sits on the boundary by construction, so
/// E[(1/r²) Σ Φ K(d/r)] = λ Φ ∫K exactly (no k-NN boundary term): E0 for every kernel
/// normalised to 1, and 0.531 E0 for Jensen's original Gaussian. Replicates (independent
/// photon sets) give the standard error.
#[test]
fn fixed_radius_irradiance_of_a_uniform_plane_is_unbiased() {
    let (n, reps, queries, r) = (20_000, 48, 200, 0.05f32);
    // Every photon carries 1/n of a total flux of 1 on the unit square: E0 = 1.
    let photon_flux = 1.0 / n as f32;
    let kernels = Kernel::ALL;
    let mut means = vec![Vec::new(); kernels.len()];
    let mut scratch = Vec::new();
    for rep in 0..reps {
        let mut rng = Rng::for_index(1999, rep);
        let photons = floor_photons(n, 0.0, 1.0, 0.0, 1.0, &mut rng)
            .into_iter()
            .map(|p| Photon::new(p.position(), Vec3::splat(photon_flux), p.direction(), 0))
            .collect();
        let map = PhotonMap::build(photons, IndexKind::KdTree);
        let mut sums = vec![0.0f64; kernels.len()];
        for _ in 0..queries {
            // A margin of 2r keeps every disc on the plane.
            let x = Vec3::new(0.1 + 0.8 * rng.uniform(), 0.0, 0.1 + 0.8 * rng.uniform());
            for (sum, &kernel) in sums.iter_mut().zip(&kernels) {
                let p = EstimateParams {
                    kernel,
                    ..Default::default()
                };
                *sum += map.irradiance_within(x, Vec3::Y, r, &p, &mut scratch).x as f64;
            }
        }
        for (m, s) in means.iter_mut().zip(sums) {
            m.push(s / queries as f64);
        }
    }
    let mut report = String::new();
    for (m, &kernel) in means.iter().zip(&kernels) {
        let want = if kernel == Kernel::GaussianJensen {
            crate::jensen_gaussian_mass()
        } else {
            1.0
        };
        let (mean, se) = mean_se(m);
        report += &format!("{kernel:?}: {mean:.5} ± {se:.5} (expected {want:.5})\n");
        assert!(se < 0.005, "standard error too large:\n{report}");
        assert!((mean - want).abs() < 4.0 * se, "{report}");
    }
    eprintln!("{report}");
}

/// Area of the unit-radius... of the disc (radius r, centre at distance d from a line)
/// on the centre's side of the line.
fn disc_area_on_near_side(r: f64, d: f64) -> f64 {
    PI * r * r - (r * r * (d / r).acos() - d * (r * r - d * d).sqrt())
}

/// Area of the wall's half-disc (y >= 0, y² + z² <= w²) whose points v = (−d, y, z) seen
/// from the query point satisfy the topological test y < eps |v|, i.e.
/// y < eps sqrt((d² + z²) / (1 − eps²)). Composite Simpson in z.
fn wall_sliver_area(w: f64, d: f64, eps: f64) -> f64 {
    let m = 20_000;
    let h = 2.0 * w / m as f64;
    (0..=m)
        .map(|i| {
            let z = -w + i as f64 * h;
            let c = if i == 0 || i == m {
                1.0
            } else if i % 2 == 1 {
                4.0
            } else {
                2.0
            };
            let half = (w * w - z * z).max(0.0).sqrt();
            let topo = eps * ((d * d + z * z) / (1.0 - eps * eps)).sqrt();
            c * half.min(topo)
        })
        .sum::<f64>()
        * h
        / 3.0
}

/// Corner: the floor y = 0 (x ∈ [0, 0.5]) meets the wall x = 0 (y ∈ [0, 0.5]), z ∈ [0, 2].
/// Both carry λ = 10⁴ photons of flux 1 per unit area. Wall photons travel along
/// (−1, −1, 0)/√2: they hit the wall from the room and *also* pass the floor's same-side
/// test, so only the topological test can reject them. Estimates on the floor at distance
/// d = 0.05 from the edge, fixed radius R = 0.1 (k above any count, r = r_max: no k-NN
/// bias), uniform kernel. Expected, in units of λ:
///   floor only: A_floor / (π R²), the disc part on the floor (boundary bias, analytic);
///   plain:      + π (R² − d²) / 2 / (π R²), the wall's half-disc inside the sphere (leak);
///   topo eps:   + the sliver of that half-disc within asin(eps) of the floor plane.
#[test]
fn topological_test_removes_the_corner_leak() {
    let (lambda, r, d, eps) = (1.0e4, 0.1f64, 0.05f64, 0.1f32);
    let per_face = (lambda * 0.5 * 2.0) as usize;
    let norm = lambda / (PI * r * r);
    let floor = norm * disc_area_on_near_side(r, d);
    let w = (r * r - d * d).sqrt();
    let plain_expected = floor + norm * PI * w * w / 2.0;
    let topo_expected = floor + norm * wall_sliver_area(w, d, eps as f64);
    let wall_dir = Vec3::new(-1.0, -1.0, 0.0).normalize();
    let plain = EstimateParams {
        k: usize::MAX,
        r_max: r as f32,
        ..Default::default()
    };
    let topo = EstimateParams {
        topo: Some(eps),
        ..plain
    };
    let (mut plain_means, mut topo_means) = (Vec::new(), Vec::new());
    let mut scratch = Vec::new();
    for rep in 0..64 {
        let mut rng = Rng::for_index(2014, rep);
        let mut photons = floor_photons(per_face, 0.0, 0.5, 0.0, 2.0, &mut rng);
        photons.extend((0..per_face).map(|_| {
            let p = Vec3::new(0.0, 0.5 * rng.uniform(), 2.0 * rng.uniform());
            Photon::new(p, Vec3::ONE, wall_dir, 1)
        }));
        let map = PhotonMap::build(photons, IndexKind::KdTree);
        let (mut sp, mut st) = (0.0, 0.0);
        let zs: Vec<f32> = (0..171).map(|i| 0.15 + 0.01 * i as f32).collect();
        for &z in &zs {
            let x = Vec3::new(d as f32, 0.0, z);
            let (ep, et) = (
                map.irradiance(x, Vec3::Y, &plain, &mut scratch),
                map.irradiance(x, Vec3::Y, &topo, &mut scratch),
            );
            // The fixed-radius estimate applies the same tests.
            for (e, p) in [(ep, &plain), (et, &topo)] {
                let w = map.irradiance_within(x, Vec3::Y, r as f32, p, &mut scratch);
                assert_eq!(w, e, "{p:?}");
            }
            sp += ep.x as f64;
            st += et.x as f64;
        }
        plain_means.push(sp / zs.len() as f64);
        topo_means.push(st / zs.len() as f64);
    }
    let (pm, pse) = mean_se(&plain_means);
    let (tm, tse) = mean_se(&topo_means);
    let report = format!(
        "floor-only {floor:.1}; plain {pm:.1} ± {pse:.1} (expected {plain_expected:.1}); \
         topo {tm:.1} ± {tse:.1} (expected {topo_expected:.1})"
    );
    assert!(pse < 0.004 * floor && tse < 0.004 * floor, "{report}");
    assert!((pm - plain_expected).abs() < 0.015 * floor, "{report}");
    assert!((tm - topo_expected).abs() < 0.015 * floor, "{report}");
    // The leak: +47% without the test, under 6% with eps = 0.1 (the residual is the
    // sliver of wall within 5.7 degrees of the floor plane, 4.8% predicted).
    let (leak_plain, leak_topo) = (pm / floor - 1.0, tm / floor - 1.0);
    assert!(leak_plain > 0.40, "{report}");
    assert!(leak_topo < 0.06, "{report}");
    eprintln!("{report}; leak {leak_plain:.3} -> {leak_topo:.3}");
}

fn finite(e: Vec3) -> bool {
    e.is_finite() && e.cmpge(Vec3::ZERO).all()
}

each_index!(
    more_k_than_photons_uses_r_max_or_the_farthest,
    |kind: IndexKind| {
        let mut rng = Rng::new(5);
        // Ten photons traced from 4 emitted paths: each stores 1/4 of its path's flux 1.
        let photons = floor_photons(10, -0.5, 1.0, -0.5, 1.0, &mut rng)
            .into_iter()
            .map(|p| Photon::new(p.position(), p.power() / 4.0, p.direction(), 0))
            .collect();
        let map = PhotonMap::build(photons, kind);
        let mut s = Vec::new();
        let p = EstimateParams {
            k: 50,
            r_max: 2.0,
            ..Default::default()
        };
        // All 10 within r_max = 2: E = 10 Φ / (π 2²), Φ = 1/4.
        let e = map.irradiance(Vec3::ZERO, Vec3::Y, &p, &mut s);
        assert_eq!(s.len(), 10);
        assert!((e.x as f64 - 10.0 / (PI * 4.0) / 4.0).abs() < 1e-6, "{e}");
        let p = EstimateParams {
            r_max: f32::INFINITY,
            ..p
        };
        let e = map.irradiance(Vec3::ZERO, Vec3::Y, &p, &mut s);
        // `irradiance` leaves them in index order: the farthest is the largest d2.
        let r2 = s.iter().fold(0f32, |m, n| m.max(n.d2)) as f64;
        assert!(
            (e.x as f64 - 10.0 / (PI * r2) / 4.0).abs() < 1e-5 * e.x as f64,
            "{e}"
        );
        let e = map.irradiance(
            Vec3::ZERO,
            Vec3::Y,
            &EstimateParams {
                drop_kth: true,
                ..p
            },
            &mut s,
        );
        assert!(
            (e.x as f64 - 9.0 / (PI * r2) / 4.0).abs() < 1e-5 * e.x as f64,
            "{e}"
        );
    }
);

each_index!(degenerate_inputs_give_zero_not_nan, |kind: IndexKind| {
    let mut rng = Rng::new(6);
    let map = PhotonMap::build(floor_photons(100, 0.0, 1.0, 0.0, 1.0, &mut rng), kind);
    let empty = PhotonMap::build(Vec::new(), kind);
    let mut s = Vec::new();
    let p = EstimateParams::default();
    let x = Vec3::new(0.5, 0.0, 0.5);
    // No photon within r_max.
    let far = EstimateParams { r_max: 0.1, ..p };
    assert_eq!(
        map.irradiance(Vec3::new(5.0, 0.0, 5.0), Vec3::Y, &far, &mut s),
        Vec3::ZERO
    );
    assert_eq!(empty.irradiance(x, Vec3::Y, &p, &mut s), Vec3::ZERO);
    assert_eq!(
        map.irradiance(x, Vec3::Y, &EstimateParams { k: 0, ..p }, &mut s),
        Vec3::ZERO
    );
    assert_eq!(
        map.irradiance(
            x,
            Vec3::Y,
            &EstimateParams {
                r_max: f32::NAN,
                ..p
            },
            &mut s
        ),
        Vec3::ZERO
    );
    // Photons arrive from above: seen from below (or with no normal) nothing passes.
    assert_eq!(map.irradiance(x, -Vec3::Y, &p, &mut s), Vec3::ZERO);
    assert_eq!(map.irradiance(x, Vec3::ZERO, &p, &mut s), Vec3::ZERO);
    // A NaN query point finds nothing.
    assert_eq!(map.irradiance(Vec3::NAN, Vec3::Y, &p, &mut s), Vec3::ZERO);
    assert!(map.irradiance(x, Vec3::Y, &p, &mut s).x > 0.0);
    // Fixed radius: no bandwidth, an infinite or invalid one, nothing inside, no photons.
    for r in [0.0, -0.5, f32::NAN, f32::INFINITY] {
        assert_eq!(map.irradiance_within(x, Vec3::Y, r, &p, &mut s), Vec3::ZERO);
        assert!(s.is_empty(), "r={r}");
    }
    let within =
        |m: &PhotonMap, x: Vec3, n: Vec3, s: &mut Vec<_>| m.irradiance_within(x, n, 0.1, &p, s);
    assert_eq!(
        within(&map, Vec3::new(5.0, 0.0, 5.0), Vec3::Y, &mut s),
        Vec3::ZERO
    );
    assert_eq!(within(&empty, x, Vec3::Y, &mut s), Vec3::ZERO);
    assert_eq!(within(&map, Vec3::NAN, Vec3::Y, &mut s), Vec3::ZERO);
    assert_eq!(within(&map, x, -Vec3::Y, &mut s), Vec3::ZERO);
    assert!(within(&map, x, Vec3::Y, &mut s).x > 0.0);
});

each_index!(all_photons_at_one_point, |kind: IndexKind| {
    let at = Vec3::new(1.0, 0.0, 1.0);
    let photons = vec![Photon::new(at, Vec3::ONE, -Vec3::Y, 0); 500];
    let map = PhotonMap::build(photons, kind);
    let mut s = Vec::new();
    for kernel in Kernel::ALL {
        for drop_kth in [false, true] {
            for topo in [None, Some(0.1)] {
                let p = EstimateParams {
                    kernel,
                    drop_kth,
                    topo,
                    ..Default::default()
                };
                // At the point: r = 0, the density is undefined: zero by contract.
                assert_eq!(map.irradiance(at, Vec3::Y, &p, &mut s), Vec3::ZERO);
                // Beside it: r = distance to the clump, every photon on the boundary.
                let e = map.irradiance(at + Vec3::new(0.01, 0.0, 0.0), Vec3::Y, &p, &mut s);
                assert!(finite(e), "{kernel:?} {e}");
                let p = EstimateParams {
                    r_max: 0.02,
                    k: 1000,
                    ..p
                };
                let e = map.irradiance(at + Vec3::new(0.01, 0.0, 0.0), Vec3::Y, &p, &mut s);
                assert!(finite(e) && e.x > 0.0, "{kernel:?} {e}");
            }
        }
    }
    // Uniform, beside it: 50 photons / (π 0.01²).
    let e = map.irradiance(
        at + Vec3::new(0.01, 0.0, 0.0),
        Vec3::Y,
        &EstimateParams::default(),
        &mut s,
    );
    assert!(
        (e.x as f64 / (50.0 / (PI * 1e-4)) - 1.0).abs() < 1e-4,
        "{e}"
    );
});

each_index!(scene_scale_does_not_change_irradiance, |kind: IndexKind| {
    // Scale positions by s and flux by s²: flux per area, so E, is unchanged.
    let mut rng = Rng::new(8);
    let base = floor_photons(5000, 0.0, 1.0, 0.0, 1.0, &mut rng);
    let queries: Vec<Vec3> = (0..50)
        .map(|_| Vec3::new(0.2 + 0.6 * rng.uniform(), 0.0, 0.2 + 0.6 * rng.uniform()))
        .collect();
    let offset = Vec3::new(3.0, -2.0, 7.0);
    let scaled = |s: f32| {
        let photons = base
            .iter()
            .map(|p| {
                Photon::new(
                    (p.position() + offset) * s,
                    p.power() * s * s,
                    p.direction(),
                    0,
                )
            })
            .collect();
        PhotonMap::build(photons, kind)
    };
    let reference = scaled(1.0);
    let mut s = Vec::new();
    for scale in [1e-3f32, 1e4] {
        let map = scaled(scale);
        for kernel in Kernel::ALL {
            for topo in [None, Some(0.1)] {
                let p = EstimateParams {
                    kernel,
                    topo,
                    r_max: 0.05,
                    ..Default::default()
                };
                let ps = EstimateParams {
                    r_max: 0.05 * scale,
                    ..p
                };
                for &q in &queries {
                    let e1 = reference.irradiance(q + offset, Vec3::Y, &p, &mut s);
                    let es = map.irradiance((q + offset) * scale, Vec3::Y, &ps, &mut s);
                    assert!(finite(es), "{scale} {kernel:?}: {es}");
                    assert!(
                        (es.x / e1.x - 1.0).abs() < 1e-3,
                        "{scale} {kernel:?}: {es} vs {e1}"
                    );
                }
            }
        }
    }
    // Far beyond the scales above: still finite.
    for scale in [1e-19f32, 1e18] {
        let map = scaled(scale);
        let e = map.irradiance(
            (queries[0] + offset) * scale,
            Vec3::Y,
            &EstimateParams::default(),
            &mut s,
        );
        assert!(finite(e), "{scale}: {e}");
    }
});

#[test]
fn lambertian_radiance_is_albedo_over_pi_times_irradiance() {
    let e = Vec3::new(2.0, 4.0, 8.0);
    let l = radiance_lambertian(e, Vec3::new(0.9, 0.5, 0.0));
    let want = Vec3::new(1.8, 2.0, 0.0) / std::f32::consts::PI;
    assert!((l - want).abs().max_element() < 1e-6, "{l}");
}

// `irradiance_hinted` is `irradiance` bit for bit, whatever the hint, for every estimator
// option: photons on a cube's faces (edges, corners) with a dense clump, queries walking
// in small steps with jumps, each under hints carried, absent, useless, small and large.
each_index!(hinted_irradiance_is_bit_identical, |kind: IndexKind| {
    let mut rng = Rng::new(21);
    let mut photons: Vec<Photon> = (0..8000)
        .map(|i| {
            let p = Vec3::from(crate::bench::point_on_unit_cube(&mut rng));
            let dir = Vec3::new(rng.uniform(), rng.uniform(), rng.uniform()) - 0.5;
            Photon::new(p, Vec3::new(1.0, 0.5, 0.25) * (1.0 + rng.uniform()), dir, i)
        })
        .collect();
    photons.extend((0..200).map(|i| {
        let p = Vec3::new(0.5, 1e-4 * (i % 5) as f32, 0.5);
        Photon::new(p, Vec3::ONE, -Vec3::Y, 0)
    }));
    let map = PhotonMap::build(photons, kind);
    let mut s = Vec::new();
    let mut plain = Vec::new();
    let params: Vec<EstimateParams> = [1, 50, 250]
        .into_iter()
        .flat_map(|k| {
            [
                (f32::INFINITY, Kernel::Uniform, false, None, true),
                (f32::INFINITY, Kernel::Silverman, true, None, true),
                (0.06, Kernel::Uniform, true, Some(0.1), true),
                (0.06, Kernel::Cone { k: 1.0 }, false, Some(0.1), false),
                (f32::INFINITY, Kernel::Gaussian, true, Some(0.2), false),
            ]
            .map(
                |(r_max, kernel, drop_kth, topo, same_side)| EstimateParams {
                    k,
                    r_max,
                    kernel,
                    drop_kth,
                    topo,
                    same_side,
                },
            )
        })
        .collect();
    let mut carried = vec![KnnHint::NONE; params.len()];
    let mut x = Vec3::new(0.2, 0.0, 0.2);
    for i in 0..120 {
        x = match i % 12 {
            0 => Vec3::from(crate::bench::point_on_unit_cube(&mut rng)),
            1 => Vec3::new(0.5, 0.0, 0.5),
            2 => Vec3::new(0.0, 0.0, 0.3),
            _ => (x + Vec3::new(rng.uniform(), 0.0, rng.uniform()) * 0.004).min(Vec3::ONE),
        };
        for (p, carried) in params.iter().zip(&mut carried) {
            let want = map.irradiance(x, Vec3::Y, p, &mut plain);
            let mut hints = [
                *carried,
                KnnHint::NONE,
                KnnHint::new(x, 0.0),
                KnnHint::new(x, f32::NAN),
                KnnHint::new(x, f32::INFINITY),
                KnnHint::new(x, 1e-3),
                KnnHint::new(x, 0.5),
            ];
            for (j, hint) in hints.iter_mut().enumerate() {
                let e = map.irradiance_hinted(x, Vec3::Y, p, hint, &mut s);
                let what = format!("{} x={x} {p:?} hint #{j}", kind.name());
                assert_eq!(s, plain, "{what}");
                assert_eq!(
                    e.to_array().map(f32::to_bits),
                    want.to_array().map(f32::to_bits),
                    "{what}"
                );
            }
            *carried = hints[0];
            assert!(want.is_finite());
        }
    }
});

// The fixed-radius estimate is the k-NN estimate whose k is never reached and whose r_max
// is the radius, bit for bit, for every kernel and test: same photons, same index order,
// same sums. Photons on a cube's faces with random directions and a dense clump.
each_index!(
    fixed_radius_irradiance_is_the_knn_estimate_with_k_unbounded,
    |kind: IndexKind| {
        let mut rng = Rng::new(31);
        let mut photons: Vec<Photon> = (0..6000)
            .map(|i| {
                let p = Vec3::from(crate::bench::point_on_unit_cube(&mut rng));
                let dir = Vec3::new(rng.uniform(), rng.uniform(), rng.uniform()) - 0.5;
                Photon::new(p, Vec3::new(1.0, 0.5, 0.25) * (1.0 + rng.uniform()), dir, i)
            })
            .collect();
        photons.extend((0..100).map(|i| {
            let p = Vec3::new(0.5, 1e-4 * (i % 5) as f32, 0.5);
            Photon::new(p, Vec3::ONE, -Vec3::Y, 0)
        }));
        let map = PhotonMap::build(photons, kind);
        let (mut s, mut knn) = (Vec::new(), Vec::new());
        let mut nonzero = 0;
        for i in 0..60 {
            let x = match i % 3 {
                0 => Vec3::from(crate::bench::point_on_unit_cube(&mut rng)),
                1 => Vec3::new(0.5, 0.0, 0.5),
                _ => Vec3::new(rng.uniform(), 0.0, rng.uniform()),
            };
            for kernel in Kernel::ALL {
                for (same_side, topo) in [(true, None), (false, Some(0.2)), (true, Some(0.05))] {
                    for r in [0.01f32, 0.06, 0.3] {
                        let p = EstimateParams {
                            kernel,
                            same_side,
                            topo,
                            ..Default::default()
                        };
                        let e = map.irradiance_within(x, Vec3::Y, r, &p, &mut s);
                        let unbounded = EstimateParams {
                            k: usize::MAX,
                            r_max: r,
                            ..p
                        };
                        let want = map.irradiance(x, Vec3::Y, &unbounded, &mut knn);
                        let what = format!("{} x={x} r={r} {p:?}", kind.name());
                        assert_eq!(s, knn, "{what}");
                        assert_eq!(
                            e.to_array().map(f32::to_bits),
                            want.to_array().map(f32::to_bits),
                            "{what}"
                        );
                        nonzero += (e.x > 0.0) as usize;
                    }
                }
            }
        }
        // Not vacuous: most estimates see photons.
        assert!(nonzero > 60 * 7 * 9 / 2, "{nonzero}");
    }
);
