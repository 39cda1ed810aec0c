//! SPPM's per-pixel statistics against their closed forms.
//!
//! Write T = τ / (π R²). The update gives T' = (τ + β E π R²) / (π R²) = T + β E whatever
//! α and M (M > 0), so after J passes `photon_radiance` = (1/J) Σ β_i E_i over the passes
//! with photons: the mean of the per-pass estimates. The radius alone carries α: with M > 0
//! photons every pass from N = 0, N_i = α M i and R_{i+1}² = R_i² α (i + 1) / (α i + 1),
//! so R_J² = R_0² Π_{i<J} α (i + 1) / (1 + α i), whatever M.
//!
//! Rounding: R is stored in f32 after τ was rescaled with the f64 R', so each pass
//! multiplies T by (1 + δ)^-2 with |δ| <= 2^-24, and R² by (1 + δ)²: relative errors of at
//! most 2^-23 per pass (the f64 arithmetic adds ~1e-16 per pass), plus 2^-24 for the final
//! f32 result.

use crate::sppm::PixelStats;
use glam::{DVec3, Vec3};
use math::Rng;
use std::f64::consts::PI;

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}

/// T = τ / (π R²) per channel, from the stored (f32) radius.
fn t_of(s: &PixelStats) -> DVec3 {
    s.tau / (PI * (s.r as f64).powi(2))
}

#[test]
fn one_update_shrinks_the_radius_and_adds_the_pass_estimate_to_tau_per_area() {
    let (n, r, alpha, m) = (10.0, 0.5f32, 0.7, 7usize);
    let mut s = PixelStats {
        n,
        tau: DVec3::new(0.1, 0.2, 0.3),
        r,
        light: DVec3::ZERO,
    };
    let t0 = t_of(&s);
    let (e, w) = (Vec3::new(2.0, 3.0, 5.0), Vec3::new(0.25, 0.5, 0.125));
    s.update(m, e, w, alpha);
    let m = m as f64;
    assert!(rel(s.n, n + alpha * m) < 1e-15, "{}", s.n);
    let want_r = r as f64 * ((n + alpha * m) / (n + m)).sqrt();
    assert!(
        rel(s.r as f64, want_r) <= 2f64.powi(-24) + 1e-15,
        "{} vs {want_r}",
        s.r
    );
    let want_t = t0 + (w * e).as_dvec3();
    for c in 0..3 {
        assert!(
            rel(t_of(&s)[c], want_t[c]) <= 2f64.powi(-23) + 1e-15,
            "{}",
            t_of(&s)
        );
    }
}

#[test]
fn a_pass_without_photons_changes_nothing() {
    // Fresh (N = 0: the update would divide 0 by 0) and after some passes; the irradiance of
    // an empty search is not read (NaN here would poison τ).
    let mut used = PixelStats::new(0.3);
    used.update(5, Vec3::ONE, Vec3::ONE, 0.7);
    for s0 in [PixelStats::new(0.3), used] {
        let mut s = s0;
        s.update(0, Vec3::NAN, Vec3::ONE, 0.7);
        assert_eq!(s, s0);
    }
}

#[test]
fn under_constant_irradiance_the_radius_follows_its_product_and_the_radiance_is_exact() {
    // M photons per pass always estimating E: R_J² = R_0² Π α (i + 1) / (1 + α i) and the
    // photon radiance is β E after every pass.
    let (r0, alpha, m) = (0.2f32, 2.0 / 3.0, 40usize);
    let (e, w) = (Vec3::new(3.0, 1.5, 0.75), Vec3::new(0.3, 0.2, 0.1));
    let want = (w * e).as_dvec3();
    let mut s = PixelStats::new(r0);
    let mut r2 = (r0 as f64).powi(2);
    for j in 1..=1000u32 {
        let i = (j - 1) as f64;
        r2 *= alpha * (i + 1.0) / (1.0 + alpha * i);
        s.update(m, e, w, alpha);
        let tol = j as f64 * 2f64.powi(-23);
        assert!(rel((s.r as f64).powi(2), r2) <= tol, "pass {j}: R {}", s.r);
        let got = s.photon_radiance(j).as_dvec3();
        for c in 0..3 {
            assert!(
                rel(got[c], want[c]) <= tol + 2f64.powi(-24),
                "pass {j}: {got}"
            );
        }
    }
    // α = 2/3 shrinks R² like J^(α − 1): by ~10 over 1000 passes.
    assert!(s.r < 0.5 * r0, "{}", s.r);
}

#[test]
fn the_radiance_is_the_mean_of_the_per_pass_estimates_and_light_its_mean() {
    // Random photon counts (zero in some passes), irradiances and weights: the estimator is
    // exactly the mean of the per-pass β E (passes without photons count as zero).
    let mut rng = Rng::new(2009);
    let passes = 2000u32;
    let alpha = 0.7;
    let mut s = PixelStats::new(0.1);
    let (mut sum, mut light) = (DVec3::ZERO, DVec3::ZERO);
    for _ in 0..passes {
        let m = rng.below(20) as usize;
        let e = Vec3::new(rng.uniform(), rng.uniform(), rng.uniform()) * 10.0;
        let w = Vec3::new(rng.uniform(), rng.uniform(), rng.uniform());
        let l = Vec3::new(rng.uniform(), rng.uniform(), rng.uniform());
        s.add_light(l);
        light += l.as_dvec3();
        s.update(m, e, w, alpha);
        if m > 0 {
            sum += (w * e).as_dvec3();
        }
    }
    let j = passes as f64;
    let (got, want) = (s.photon_radiance(passes).as_dvec3(), sum / j);
    let tol = (j + 1.0) * 2f64.powi(-23);
    let got_light = s.light_radiance(passes).as_dvec3();
    for c in 0..3 {
        assert!(rel(got[c], want[c]) <= tol, "{got} vs {want}");
        assert!(
            rel(got_light[c], light[c] / j) <= 2f64.powi(-23),
            "{got_light}"
        );
    }
    assert!(s.r < 0.05, "the radius shrank: {}", s.r);
}

#[test]
fn update_is_the_sppm_methods_arithmetic_bit_for_bit() {
    // The per-pixel update and the layers as the `sppm` method wrote them inline, kept
    // verbatim as the reference its images depend on.
    struct Stats {
        n: f64,
        tau: DVec3,
        r: f32,
    }
    let mut rng = Rng::new(16);
    let alpha = 0.75f32 as f64;
    let mut st = Stats {
        n: 0.0,
        tau: DVec3::ZERO,
        r: 0.37,
    };
    let mut s = PixelStats::new(0.37);
    for pass in 1..=500u32 {
        let m = rng.below(6) as usize;
        let e = Vec3::new(rng.uniform(), rng.uniform(), rng.uniform()) * 7.0;
        let weight = Vec3::new(rng.uniform(), rng.uniform(), rng.uniform());
        s.update(m, e, weight, alpha);
        let m = m as f64;
        if m != 0.0 {
            let n_new = st.n + alpha * m;
            let r_new = st.r as f64 * (n_new / (st.n + m)).sqrt();
            let r2 = (st.r as f64).powi(2);
            let phi = (weight * e).as_dvec3() * (std::f64::consts::PI * r2);
            st.tau = (st.tau + phi) * (r_new * r_new / r2);
            st.n = n_new;
            st.r = r_new as f32;
        }
        assert_eq!(s.n.to_bits(), st.n.to_bits());
        assert_eq!(s.r.to_bits(), st.r.to_bits());
        assert_eq!(
            s.tau.to_array().map(f64::to_bits),
            st.tau.to_array().map(f64::to_bits)
        );
        let j = pass.max(1) as f64;
        let area = std::f64::consts::PI * (st.r as f64).powi(2);
        let v: Vec3 = (st.tau / (j * area)).as_vec3();
        let got = s.photon_radiance(pass);
        assert_eq!(
            got.to_array().map(f32::to_bits),
            v.to_array().map(f32::to_bits)
        );
    }
}
