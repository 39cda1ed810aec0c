use crate::Rng;

// The warp, frame and chi-square tests live in tests/ (one file per module).
mod chi2;
mod frame;
mod sampler;
mod warp;

#[test]
fn streams_are_pure_functions_of_seed_and_index() {
    let a: Vec<u32> = {
        let mut r = Rng::for_index(7, 12345);
        (0..16).map(|_| r.next_u32()).collect()
    };
    // Touch other streams in between: must not matter.
    let _ = Rng::for_index(7, 1).next_u32();
    let b: Vec<u32> = {
        let mut r = Rng::for_index(7, 12345);
        (0..16).map(|_| r.next_u32()).collect()
    };
    assert_eq!(a, b);
    let mut c = Rng::for_index(7, 12346);
    assert_ne!(
        a[0..4],
        (0..4).map(|_| c.next_u32()).collect::<Vec<_>>()[..]
    );
}

#[test]
fn uniform_has_the_right_mean_and_variance() {
    // Mean 1/2, variance 1/12; with n = 1e6 the standard error of the mean is 2.9e-4.
    let mut r = Rng::new(1);
    let n = 1_000_000;
    let (mut s, mut s2) = (0.0f64, 0.0f64);
    for _ in 0..n {
        let u = r.uniform() as f64;
        assert!((0.0..1.0).contains(&u));
        s += u;
        s2 += u * u;
    }
    let mean = s / n as f64;
    let var = s2 / n as f64 - mean * mean;
    assert!((mean - 0.5).abs() < 5.0 * 2.9e-4, "mean {mean}");
    assert!((var - 1.0 / 12.0).abs() < 1e-3, "var {var}");
}

#[test]
fn neighbouring_streams_are_uncorrelated() {
    // Correlation of the first draw across consecutive indices: |rho| < 5 / sqrt(n).
    let n = 200_000u64;
    let xs: Vec<f64> = (0..n)
        .map(|i| Rng::for_index(3, i).uniform() as f64 - 0.5)
        .collect();
    let cov: f64 = xs.windows(2).map(|w| w[0] * w[1]).sum::<f64>() / (n - 1) as f64;
    let rho = cov * 12.0;
    assert!(rho.abs() < 5.0 / (n as f64).sqrt(), "rho {rho}");
}

#[test]
fn below_covers_its_range_evenly() {
    let mut r = Rng::new(9);
    let mut counts = [0u32; 7];
    for _ in 0..70_000 {
        counts[r.below(7) as usize] += 1;
    }
    // Expected 10000 each, sd ~ 92.6: allow 5 sd.
    for c in counts {
        assert!((c as i64 - 10_000).abs() < 463, "{counts:?}");
    }
}
