use crate::chi2::{
    chi2_test, chi2_test_sidak_sub, gamma_p, gamma_q, ln_gamma, pearson, sidak_alpha,
};
use crate::warp::{
    cosine_hemisphere_pdf, sample_cosine_hemisphere, sample_uniform_sphere, uniform_hemisphere_pdf,
    uniform_sphere_pdf,
};
use glam::Vec3;

fn close(a: f64, b: f64, tol: f64) -> bool {
    (a - b).abs() <= tol * b.abs().max(1e-300)
}

#[test]
fn ln_gamma_matches_reference_values() {
    // References from mpmath.loggamma (30 digits).
    for (x, want) in [
        (0.5, 0.572_364_942_924_700_1),
        (1.0, 0.0),
        (3.7, 1.428_072_326_665_388),
        (10.0, 12.801_827_480_081_469),
        (1234.5, 7_550.550_901_077_895),
    ] {
        let got = ln_gamma(x);
        assert!(
            (got - want).abs() < 1e-11,
            "ln_gamma({x}) = {got}, want {want}"
        );
    }
}

#[test]
fn incomplete_gamma_matches_closed_forms_and_references() {
    // Integer a: Q(n, x) = e^-x sum_{k<n} x^k / k!  (here 5 e^-2).
    let q = gamma_q(3.0, 2.0);
    assert!(close(q, 5.0 * (-2.0f64).exp(), 1e-11), "{q}");
    // a = 1: Q = e^-x, on both sides of the series / continued-fraction switch at x = a + 1.
    for x in [0.1, 1.9, 2.1, 30.0] {
        assert!(close(gamma_q(1.0, x), (-x).exp(), 1e-11), "x = {x}");
    }
    // mpmath.gammainc(a, x, inf, regularized=True).
    for (a, x, want) in [
        (0.5, 0.3, 0.438_578_026_080_999_9),
        (7.5, 3.0, 0.979_747_746_717_813_4),
        (2500.0, 2600.0, 0.023_818_998_020_740_654),
        (2500.0, 2400.0, 0.978_340_312_134_636_7),
        // The 1% critical value of chi-square with 100 dof is 135.807 (tables).
        (50.0, 135.807 / 2.0, 0.009_999_573_729_248_8),
    ] {
        let q = gamma_q(a, x);
        assert!(close(q, want, 1e-10), "Q({a}, {x}) = {q}, want {want}");
        assert!((gamma_p(a, x) + q - 1.0).abs() < 1e-14);
    }
}

#[test]
fn pearson_pools_sparse_cells_and_rejects_impossible_samples() {
    // 10 cells expecting 0.5 each pool into one cell expecting 5.
    let mut expected = vec![0.5; 10];
    expected.extend([100.0; 4]);
    let observed = expected.clone();
    let r = pearson(&observed, &expected).unwrap();
    assert_eq!(r.dof, 4, "4 full cells + 1 pool - 1 constraint");
    assert!(r.chi2.abs() < 1e-12 && (r.p - 1.0).abs() < 1e-12);
    // A sample where the pdf is zero is a support bug, whatever the p-value.
    let err = pearson(&[1.0, 99.0, 100.0], &[0.0, 100.0, 100.0]).unwrap_err();
    assert!(err.contains("integrates to 0"), "{err}");
}

#[test]
fn sidak_keeps_the_family_level() {
    let a = sidak_alpha(5);
    assert!(((1.0 - a).powi(5) - 0.99).abs() < 1e-12);
    assert_eq!(sidak_alpha(1), 0.01);
}

#[test]
fn chi2_accepts_cosine_hemisphere_sampling() {
    chi2_test(
        51,
        101,
        400_000,
        1,
        |rng| Some(sample_cosine_hemisphere(rng.uniform2())),
        |w| cosine_hemisphere_pdf(w) as f64,
    )
    .unwrap_or_else(|e| panic!("{e}"));
}

#[test]
fn chi2_accepts_uniform_sphere_sampling() {
    chi2_test(
        51,
        101,
        400_000,
        2,
        |rng| Some(sample_uniform_sphere(rng.uniform2())),
        |w| uniform_sphere_pdf(w) as f64,
    )
    .unwrap_or_else(|e| panic!("{e}"));
}

#[test]
fn chi2_accepts_a_sampler_that_sometimes_fails() {
    // Absorb half the samples: the pdf then integrates to 1/2 and the test must still pass.
    chi2_test(
        51,
        101,
        400_000,
        3,
        |rng| (rng.uniform() < 0.5).then(|| sample_uniform_sphere(rng.uniform2())),
        |w| 0.5 * uniform_sphere_pdf(w) as f64,
    )
    .unwrap_or_else(|e| panic!("{e}"));
}

#[test]
fn chi2_rejects_a_wrong_pdf() {
    // Cosine samples claimed to be uniform over the hemisphere: same support, wrong shape.
    let err = chi2_test(
        51,
        101,
        400_000,
        4,
        |rng| Some(sample_cosine_hemisphere(rng.uniform2())),
        |w| uniform_hemisphere_pdf(w) as f64,
    )
    .unwrap_err();
    assert!(err.contains("seed 4") && err.contains("rejects"), "{err}");
}

#[test]
fn chi2_rejects_samples_outside_the_support() {
    // Uniform-sphere samples claimed to stay in the upper hemisphere.
    let err = chi2_test(
        51,
        101,
        100_000,
        5,
        |rng| Some(sample_uniform_sphere(rng.uniform2())),
        |w| uniform_hemisphere_pdf(w) as f64 * 0.5,
    )
    .unwrap_err();
    assert!(err.contains("seed 5"), "{err}");
    // Non-unit vectors are reported, not binned.
    let err = chi2_test(51, 101, 10, 6, |_| Some(Vec3::splat(1.0)), |_| 0.0).unwrap_err();
    assert!(err.contains("not a unit vector"), "{err}");
}

#[test]
fn finer_quadrature_integrates_a_jump_across_cells() {
    // Uniform on a cap about a tilted axis: the pdf's jump (the cap's rim) crosses cells
    // everywhere, not along their edges. 16 x 16 sub-cells per cell resolve it.
    let frame = crate::Frame::from_z(Vec3::new(0.3, -0.5, 0.6).normalize());
    let cos_max = 0.8f32;
    let area = std::f64::consts::TAU * (1.0 - cos_max as f64);
    let axis = frame.n;
    chi2_test_sidak_sub(
        1,
        51,
        100,
        16,
        400_000,
        7,
        |rng| {
            let [u0, u1] = rng.uniform2();
            let z = 1.0 - u0 * (1.0 - cos_max);
            let r = (1.0 - z * z).max(0.0).sqrt();
            let phi = std::f32::consts::TAU * u1;
            Some(frame.to_world(Vec3::new(r * phi.cos(), r * phi.sin(), z)))
        },
        |w| {
            if w.dot(axis) >= cos_max {
                1.0 / area
            } else {
                0.0
            }
        },
    )
    .unwrap_or_else(|e| panic!("{e}"));
}
