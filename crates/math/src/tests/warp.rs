use crate::chi2::{ALPHA, chi2_test, pearson};
use crate::warp::*;
use crate::{Distribution1D, Distribution2D, Rng, power_heuristic};
use glam::{Vec2, Vec3};

/// Distance between two points of the unit square, treating `u[1]` as periodic when the
/// warp maps it to an azimuth (0 and 1 are the same direction).
fn square_dist(a: [f32; 2], b: [f32; 2], periodic_v: bool) -> f32 {
    let du = (a[0] - b[0]).abs();
    let mut dv = (a[1] - b[1]).abs();
    if periodic_v {
        dv = dv.min(1.0 - dv);
    }
    du.max(dv)
}

/// `invert(sample(u)) == u` over many random `u`, plus the square's corners and centre.
fn round_trip<T: std::fmt::Debug>(
    name: &str,
    sample: impl Fn([f32; 2]) -> T,
    invert: impl Fn(T) -> [f32; 2],
    periodic_v: bool,
    tol: f32,
) {
    let mut rng = Rng::new(21);
    let mut us: Vec<[f32; 2]> = (0..100_000).map(|_| rng.uniform2()).collect();
    us.extend([
        [0.0, 0.0],
        [0.5, 0.5],
        [0.25, 0.75],
        [0.999, 0.001],
        [0.3, 0.3],
    ]);
    for u in us {
        let back = invert(sample(u));
        assert!(
            square_dist(u, back, periodic_v) < tol,
            "{name}: u = {u:?} -> {back:?}"
        );
    }
}

#[test]
fn disk_concentric_round_trips_and_stays_in_the_disk() {
    round_trip(
        "disk",
        sample_uniform_disk_concentric,
        invert_uniform_disk_concentric,
        false,
        1e-5,
    );
    let mut rng = Rng::new(22);
    for _ in 0..10_000 {
        let p = sample_uniform_disk_concentric(rng.uniform2());
        assert!(p.length() <= 1.0 + 1e-6);
        assert_eq!(uniform_disk_concentric_pdf(p), std::f32::consts::FRAC_1_PI);
    }
    assert_eq!(uniform_disk_concentric_pdf(Vec2::new(1.0, 0.1)), 0.0);
}

#[test]
fn hemisphere_and_sphere_warps_round_trip() {
    // Away from the poles (u0 near 0 for the sphere), azimuth is well conditioned; the
    // tolerance covers atan2's f32 error at the smallest radii drawn here.
    round_trip(
        "cosine hemisphere",
        sample_cosine_hemisphere,
        invert_cosine_hemisphere,
        false,
        1e-4,
    );
    round_trip(
        "uniform hemisphere",
        sample_uniform_hemisphere,
        invert_uniform_hemisphere,
        true,
        1e-4,
    );
    round_trip(
        "uniform sphere",
        sample_uniform_sphere,
        invert_uniform_sphere,
        true,
        1e-3,
    );
}

#[test]
fn triangle_round_trips() {
    round_trip(
        "triangle",
        sample_uniform_triangle,
        invert_uniform_triangle,
        false,
        1e-6,
    );
}

#[test]
fn warps_produce_unit_directions_with_consistent_pdfs() {
    let mut rng = Rng::new(23);
    for _ in 0..10_000 {
        let u = rng.uniform2();
        let c = sample_cosine_hemisphere(u);
        let h = sample_uniform_hemisphere(u);
        let s = sample_uniform_sphere(u);
        for w in [c, h, s] {
            assert!((w.length() - 1.0).abs() < 1e-5, "{w}");
        }
        assert!(c.z >= 0.0 && h.z >= 0.0);
        assert!((cosine_hemisphere_pdf(c) - c.z / std::f32::consts::PI).abs() < 1e-7);
        assert_eq!(uniform_hemisphere_pdf(h), 0.5 / std::f32::consts::PI);
    }
    assert_eq!(cosine_hemisphere_pdf(-Vec3::Z), 0.0);
    assert_eq!(uniform_hemisphere_pdf(-Vec3::Z), 0.0);
}

#[test]
fn triangle_sampling_is_uniform_chi2() {
    // Cut the parameter triangle into n^2 congruent sub-triangles (each grid square's lower
    // half, and the upper half where it is inside): equal expected counts.
    let n = 20usize;
    let samples = 200_000;
    let index = |b: Vec3| -> usize {
        let (x, y) = (b.x * n as f32, b.y * n as f32);
        let (i, j) = ((x as usize).min(n - 1), (y as usize).min(n - 1));
        let upper = (x - i as f32) + (y - j as f32) >= 1.0;
        (i * n + j) * 2 + upper as usize
    };
    let mut observed = vec![0.0; n * n * 2];
    let mut expected = vec![0.0; n * n * 2];
    for i in 0..n {
        for j in 0..n {
            let e = samples as f64 / (n * n) as f64;
            if i + j < n {
                expected[(i * n + j) * 2] = e;
            }
            if i + j + 1 < n {
                expected[(i * n + j) * 2 + 1] = e;
            }
        }
    }
    let mut rng = Rng::new(24);
    for _ in 0..samples {
        let b = sample_uniform_triangle(rng.uniform2());
        assert!(uniform_triangle_pdf(b) == 2.0 && (b.x + b.y + b.z - 1.0).abs() < 1e-6);
        observed[index(b)] += 1.0;
    }
    let r = pearson(&observed, &expected).unwrap_or_else(|e| panic!("seed 24: {e}"));
    assert!(r.p >= ALPHA, "seed 24: {r:?}");
}

#[test]
fn distribution1d_samples_in_proportion_chi2() {
    let weights = [1.0, 0.0, 3.0, 0.5, 7.0, 0.0, 2.5, 1e-3];
    let d = Distribution1D::new(&weights);
    let total: f64 = weights.iter().sum();
    assert_eq!(d.total(), total);
    assert_eq!(d.len(), weights.len());
    for (i, w) in weights.iter().enumerate() {
        assert!((d.pmf(i) as f64 - w / total).abs() < 1e-7, "pmf({i})");
    }
    let samples = 200_000;
    let mut observed = vec![0.0; weights.len()];
    let mut rng = Rng::new(25);
    for _ in 0..samples {
        let (i, pmf, u2) = d.sample(rng.uniform());
        assert_eq!(pmf, d.pmf(i));
        assert!((0.0..1.0).contains(&u2));
        observed[i] += 1.0;
    }
    let expected: Vec<f64> = weights.iter().map(|w| w / total * samples as f64).collect();
    // Zero-weight entries expect 0: pearson errs if one was ever drawn.
    let r = pearson(&observed, &expected).unwrap_or_else(|e| panic!("seed 25: {e}"));
    assert!(r.p >= ALPHA, "seed 25: {r:?}");
}

#[test]
fn distribution1d_round_trips_and_handles_edges() {
    let d = Distribution1D::new(&[0.0, 2.0, 0.0, 1.0, 1.0, 0.0]);
    let mut rng = Rng::new(26);
    for u in (0..10_000)
        .map(|_| rng.uniform())
        .chain([0.0, 0.5, ONE_MINUS_EPSILON])
    {
        let (i, _, u2) = d.sample(u);
        assert!(d.pmf(i) > 0.0, "u = {u} chose empty bucket {i}");
        assert!((d.invert(i, u2) - u).abs() < 1e-6, "u = {u}");
    }
    // Bucket edges: u = 0.5 is where bucket 1 ends and bucket 3 begins.
    assert_eq!(d.sample(0.0).0, 1);
    assert_eq!(d.sample(0.5).0, 3);
    assert_eq!(d.sample(ONE_MINUS_EPSILON).0, 4);
    // All-zero weights fall back to uniform.
    let z = Distribution1D::new(&[0.0; 4]);
    assert_eq!(z.total(), 0.0);
    assert_eq!(z.pmf(2), 0.25);
    assert_eq!(z.sample(0.6).0, 2);
}

#[test]
fn power_heuristic_matches_veach() {
    // w = f^2 / (f^2 + g^2); weights of the two strategies sum to 1.
    assert!((power_heuristic(1, 2.0, 1, 1.0) - 0.8).abs() < 1e-7);
    assert!((power_heuristic(1, 2.0, 1, 1.0) + power_heuristic(1, 1.0, 1, 2.0) - 1.0).abs() < 1e-7);
    assert!((power_heuristic(2, 1.0, 1, 1.0) - 0.8).abs() < 1e-7);
    assert_eq!(power_heuristic(1, f32::INFINITY, 1, 1.0), 1.0);
    assert_eq!(power_heuristic(1, 0.0, 1, 0.0), 0.0);
}

/// A 5 x 6 grid with an empty row, an empty column (in one row) and a 1000:1 range.
const GRID_NU: usize = 5;
const GRID_NV: usize = 6;
#[rustfmt::skip]
const GRID: [f64; GRID_NU * GRID_NV] = [
    1.0, 2.0, 0.0, 4.0, 0.5,
    0.0, 0.0, 0.0, 0.0, 0.0,
    3.0, 1.0, 7.0, 0.2, 1.0,
    0.1, 0.1, 1e-3, 0.1, 0.1,
    9.0, 0.0, 0.0, 2.0, 5.0,
    1.0, 1.0, 1.0, 1.0, 1.0,
];

/// The unit square onto the sphere by the area-preserving uniform-sphere warp (area 4π),
/// so the crate's direction harness tests a square's density: with `theta_res` a multiple of
/// `nu` and `phi_res` of `nv`, the harness's cells tile the grid's cells exactly.
fn chi2_of_distribution2d(d: &Distribution2D, pdf_of: impl Fn(Vec2) -> f32) -> Result<(), String> {
    chi2_test(
        9 * GRID_NU,
        10 * GRID_NV,
        400_000,
        27,
        |rng| {
            let (p, pdf) = d.sample(rng.uniform2());
            assert_eq!(pdf, d.pdf(p), "sample's pdf against pdf() at {p}");
            Some(sample_uniform_sphere([p.x, p.y]))
        },
        |w| {
            let u = invert_uniform_sphere(w);
            pdf_of(Vec2::new(u[0], u[1])) as f64 / (4.0 * std::f64::consts::PI)
        },
    )
}

#[test]
fn distribution2d_samples_in_proportion_chi2() {
    let d = Distribution2D::new(&GRID, GRID_NU, GRID_NV).unwrap();
    assert_eq!(d.resolution(), (GRID_NU, GRID_NV));
    chi2_of_distribution2d(&d, |p| d.pdf(p)).unwrap();
    // The harness notices a wrong density: the same grid transposed row for row.
    let mut flipped = GRID;
    flipped.reverse();
    let wrong = Distribution2D::new(&flipped, GRID_NU, GRID_NV).unwrap();
    assert!(chi2_of_distribution2d(&d, |p| wrong.pdf(p)).is_err());
}

#[test]
fn distribution2d_pdf_is_the_normalised_weight_and_integrates_to_one() {
    let d = Distribution2D::new(&GRID, GRID_NU, GRID_NV).unwrap();
    let total: f64 = GRID.iter().sum();
    assert!((d.total() - total).abs() < 1e-12 * total);
    for (i, w) in GRID.iter().enumerate() {
        let (col, row) = (i % GRID_NU, i / GRID_NU);
        let centre = Vec2::new(
            (col as f32 + 0.5) / GRID_NU as f32,
            (row as f32 + 0.5) / GRID_NV as f32,
        );
        let want = w / total * (GRID_NU * GRID_NV) as f64;
        assert!(
            (d.pdf(centre) as f64 - want).abs() < 1e-6 * want.max(1.0),
            "cell ({col}, {row})"
        );
    }
    // Midpoint rule on a grid 20 times finer: exact for a piecewise-constant density.
    let (n, m) = (20 * GRID_NU, 20 * GRID_NV);
    let mut sum = 0.0f64;
    for j in 0..m {
        for i in 0..n {
            let p = Vec2::new((i as f32 + 0.5) / n as f32, (j as f32 + 0.5) / m as f32);
            sum += d.pdf(p) as f64;
        }
    }
    let integral = sum / (n * m) as f64;
    assert!((integral - 1.0).abs() < 1e-5, "integral {integral}");
    assert_eq!(d.pdf(Vec2::new(1.2, 0.5)), 0.0);
    assert_eq!(d.pdf(Vec2::new(0.5, -0.1)), 0.0);
}

#[test]
fn distribution2d_round_trips_and_never_lands_on_an_empty_cell() {
    let d = Distribution2D::new(&GRID, GRID_NU, GRID_NV).unwrap();
    let mut rng = Rng::new(28);
    for u in (0..100_000).map(|_| rng.uniform2()).chain([
        [0.0, 0.0],
        [ONE_MINUS_EPSILON; 2],
        [0.5, 0.5],
        [0.0, ONE_MINUS_EPSILON],
    ]) {
        let (p, pdf) = d.sample(u);
        assert!(pdf > 0.0 && (0.0..1.0).contains(&p.x) && (0.0..1.0).contains(&p.y));
        let back = d.invert(p);
        assert!(
            square_dist(u, back, false) < 1e-5,
            "u = {u:?} -> {p} -> {back:?}"
        );
    }
    // One lit cell: every sample lands in it, with density nu * nv.
    let mut one = [0.0; 12];
    one[7] = 0.25;
    let d = Distribution2D::new(&one, 4, 3).unwrap();
    for _ in 0..1000 {
        let (p, pdf) = d.sample(rng.uniform2());
        assert_eq!(pdf, 12.0);
        assert!(
            (0.75..1.0).contains(&p.x) && (1.0 / 3.0..2.0 / 3.0).contains(&p.y),
            "{p}"
        );
    }
}

#[test]
fn distribution2d_refuses_all_zero_weights() {
    assert!(Distribution2D::new(&[0.0; 6], 3, 2).is_none());
    assert!(Distribution2D::new(&[0.0, 0.0, 1e-300], 3, 1).is_some());
}
