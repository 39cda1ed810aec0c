//! Pearson's chi-square goodness-of-fit test for samplers: the one harness every crate's tests
//! reuse (after pbrt-v3's `chi2test` and Mitsuba 3's `ChiSquareTest`). A sampler is drawn many
//! times with a fixed seed, the directions are binned, and the counts are compared with the
//! counts its claimed pdf predicts. Mean-value checks miss a wrong pdf shape; this does not.
//!
//! Public rather than test-only because it is small, dependency-free, and `bsdf`/`light`
//! tests need it across crate boundaries.

use crate::Rng;
use glam::Vec3;
use std::f64::consts::{PI, TAU};

/// Significance level of one test. Families of tests use [`sidak_alpha`].
pub const ALPHA: f64 = 0.01;

/// Cells expecting fewer samples than this are pooled: Pearson's statistic is only close to
/// chi-square distributed when every expected count is at least ~5 (Cochran 1952).
pub const MIN_EXPECTED: f64 = 5.0;

/// Per-test level keeping the family-wise false-rejection rate at [`ALPHA`] over
/// `test_count` independent tests (Šidák 1967): `1 - (1 - α)^(1/n)`.
pub fn sidak_alpha(test_count: u32) -> f64 {
    if test_count <= 1 {
        return ALPHA;
    }
    1.0 - (1.0 - ALPHA).powf(1.0 / test_count as f64)
}

/// Result of [`pearson`].
#[derive(Clone, Copy, Debug)]
pub struct Pearson {
    pub chi2: f64,
    pub dof: usize,
    /// Probability of a statistic at least this large if the counts follow `expected`.
    pub p: f64,
}

/// Pearson's statistic of observed against expected counts, pooling low-expectation cells
/// (smallest first, until the pool reaches [`MIN_EXPECTED`]). Errs on a sample in a cell of
/// expected count exactly 0: that is a support bug, not noise.
pub fn pearson(observed: &[f64], expected: &[f64]) -> Result<Pearson, String> {
    assert_eq!(
        observed.len(),
        expected.len(),
        "one expected count per cell"
    );
    if let Some(i) = (0..observed.len()).find(|&i| expected[i] <= 0.0 && observed[i] > 0.0) {
        return Err(format!(
            "{} samples in cell {i}, where the pdf integrates to 0",
            observed[i]
        ));
    }
    let mut cells: Vec<(f64, f64)> = expected
        .iter()
        .copied()
        .zip(observed.iter().copied())
        .filter(|&(e, _)| e > 0.0)
        .collect();
    cells.sort_by(|a, b| a.0.total_cmp(&b.0));
    let (mut chi2, mut dof) = (0.0, 0usize);
    let (mut pool_e, mut pool_o, mut pooled) = (0.0, 0.0, 0usize);
    for (e, o) in cells {
        if e < MIN_EXPECTED || (pooled > 0 && pool_e < MIN_EXPECTED) {
            pool_e += e;
            pool_o += o;
            pooled += 1;
        } else {
            chi2 += (o - e) * (o - e) / e;
            dof += 1;
        }
    }
    if pooled > 0 {
        chi2 += (pool_o - pool_e) * (pool_o - pool_e) / pool_e;
        dof += 1;
    }
    if dof < 2 {
        return Err(format!("only {dof} usable cells: raise the sample count"));
    }
    // The total count is fixed by the sample count: one constraint.
    let dof = dof - 1;
    let p = gamma_q(dof as f64 / 2.0, chi2 / 2.0);
    Ok(Pearson { chi2, dof, p })
}

/// [`chi2_test_sidak`] for a single test at level [`ALPHA`].
pub fn chi2_test(
    theta_res: usize,
    phi_res: usize,
    sample_count: usize,
    seed: u64,
    sample: impl FnMut(&mut Rng) -> Option<Vec3>,
    pdf: impl Fn(Vec3) -> f64,
) -> Result<(), String> {
    chi2_test_sidak(1, theta_res, phi_res, sample_count, seed, sample, pdf)
}

/// Chi-square test of a sampler of unit directions against its claimed solid-angle `pdf`, one
/// of `test_count` tests in a family (level [`sidak_alpha`]). The sphere is cut into
/// `theta_res` bands of equal height in `cos θ` (equal area, so the integrand needs no
/// `sin θ`) times `phi_res` wedges. Use odd `theta_res` (e.g. 51 × 101): the equator then runs
/// through the middle of a band, so samples that rounding puts at `z = ±0` land in a cell the
/// pdf covers. A sampler may return `None` (absorbed); then the pdf integrates to less than 1.
/// The error message names the seed, to replay a failure.
pub fn chi2_test_sidak(
    test_count: u32,
    theta_res: usize,
    phi_res: usize,
    sample_count: usize,
    seed: u64,
    sample: impl FnMut(&mut Rng) -> Option<Vec3>,
    pdf: impl Fn(Vec3) -> f64,
) -> Result<(), String> {
    chi2_test_sidak_sub(
        test_count,
        theta_res,
        phi_res,
        SUB,
        sample_count,
        seed,
        sample,
        pdf,
    )
}

/// Sub-cells per cell side in the expected-count quadrature of [`chi2_test_sidak`].
pub const SUB: usize = 4;

/// [`chi2_test_sidak`] with `sub × sub` quadrature sub-cells per cell instead of [`SUB`]. For a
/// pdf that jumps along a curve crossing cells (not only at the equator), e.g. a rough
/// refraction lobe where the generalized half vector meets the horizon: quadrature error
/// there shrinks with the sub-cell size, and a sliver of support is less likely to be missed
/// by every node.
#[allow(clippy::too_many_arguments)]
pub fn chi2_test_sidak_sub(
    test_count: u32,
    theta_res: usize,
    phi_res: usize,
    sub: usize,
    sample_count: usize,
    seed: u64,
    mut sample: impl FnMut(&mut Rng) -> Option<Vec3>,
    pdf: impl Fn(Vec3) -> f64,
) -> Result<(), String> {
    assert!(theta_res > 0 && phi_res > 0 && sub > 0 && sample_count > 0);
    let mut observed = vec![0.0; theta_res * phi_res];
    let mut rng = Rng::new(seed);
    for i in 0..sample_count {
        let Some(w) = sample(&mut rng) else { continue };
        if !w.is_finite() || (w.length() - 1.0).abs() > 1e-3 {
            return Err(format!(
                "seed {seed}: sample {i} = {w} is not a unit vector"
            ));
        }
        observed[cell_of(w, theta_res, phi_res)] += 1.0;
    }
    let expected = expected_counts(theta_res, phi_res, sub, sample_count, &pdf);
    let mass = expected.iter().sum::<f64>() / sample_count as f64;
    if mass > 1.0 + 1e-3 {
        return Err(format!("seed {seed}: the pdf integrates to {mass} > 1"));
    }
    let r = pearson(&observed, &expected).map_err(|e| format!("seed {seed}: {e}"))?;
    let alpha = sidak_alpha(test_count);
    if r.p < alpha {
        return Err(format!(
            "seed {seed}: chi-square rejects the sampler: p = {:.3e} < alpha = {alpha:.3e} \
             (chi2 = {:.1}, dof = {})",
            r.p, r.chi2, r.dof
        ));
    }
    Ok(())
}

fn cell_of(w: Vec3, theta_res: usize, phi_res: usize) -> usize {
    let z = (w.z as f64).clamp(-1.0, 1.0);
    let row = (((1.0 - z) * 0.5 * theta_res as f64) as usize).min(theta_res - 1);
    let mut phi = (w.y as f64).atan2(w.x as f64);
    if phi < 0.0 {
        phi += TAU;
    }
    let col = ((phi / TAU * phi_res as f64) as usize).min(phi_res - 1);
    row * phi_res + col
}

/// Expected counts: the pdf integrated over each cell by 2-point Gauss–Legendre on a `sub × sub`
/// grid of sub-cells (exact for cubics per sub-cell; Numerical Recipes §4.6). The nodes never
/// sit on a sub-cell edge, and with odd `theta_res` the equator is such an edge, so a
/// hemisphere pdf's jump is integrated exactly rather than smeared.
fn expected_counts(
    theta_res: usize,
    phi_res: usize,
    sub: usize,
    sample_count: usize,
    pdf: &impl Fn(Vec3) -> f64,
) -> Vec<f64> {
    let g = 0.5 / 3f64.sqrt();
    let nodes = [0.5 - g, 0.5 + g];
    let dz = 2.0 / theta_res as f64;
    let dphi = TAU / phi_res as f64;
    let sub_area = (dz / sub as f64) * (dphi / sub as f64);
    let mut out = Vec::with_capacity(theta_res * phi_res);
    for row in 0..theta_res {
        for col in 0..phi_res {
            let mut sum = 0.0;
            for sz in 0..sub {
                for nz in nodes {
                    let z = 1.0 - (row as f64 + (sz as f64 + nz) / sub as f64) * dz;
                    let r = (1.0 - z * z).max(0.0).sqrt();
                    for sp in 0..sub {
                        for np in nodes {
                            let phi = (col as f64 + (sp as f64 + np) / sub as f64) * dphi;
                            let w =
                                Vec3::new((r * phi.cos()) as f32, (r * phi.sin()) as f32, z as f32);
                            sum += pdf(w);
                        }
                    }
                }
            }
            // Each node weighs a quarter of its sub-cell.
            out.push(sum * 0.25 * sub_area * sample_count as f64);
        }
    }
    out
}

// --- Incomplete gamma (Numerical Recipes 3rd ed. §6.2) -----------------------------------

/// `ln Γ(x)` for `x > 0`: shift up by the recurrence until `x ≥ 10`, then Stirling's series
/// to `x^-7` (Abramowitz & Stegun 6.1.41), absolute error below 1e-12.
pub fn ln_gamma(x: f64) -> f64 {
    assert!(x > 0.0, "ln_gamma needs x > 0");
    let (mut x, mut shift) = (x, 0.0);
    while x < 10.0 {
        shift += x.ln();
        x += 1.0;
    }
    let x2 = x * x;
    let series = 1.0 / (12.0 * x) - 1.0 / (360.0 * x * x2) + 1.0 / (1260.0 * x * x2 * x2)
        - 1.0 / (1680.0 * x * x2 * x2 * x2);
    (x - 0.5) * x.ln() - x + 0.5 * (2.0 * PI).ln() + series - shift
}

/// Regularized lower incomplete gamma `P(a, x)`.
pub fn gamma_p(a: f64, x: f64) -> f64 {
    assert!(a > 0.0 && x >= 0.0, "gamma_p needs a > 0, x >= 0");
    if x == 0.0 {
        0.0
    } else if x < a + 1.0 {
        gamma_series(a, x)
    } else {
        1.0 - gamma_continued_fraction(a, x)
    }
}

/// Regularized upper incomplete gamma `Q(a, x) = 1 - P(a, x)`; the chi-square p-value of
/// statistic `c` with `k` degrees of freedom is `Q(k/2, c/2)`. Series below `x = a + 1`,
/// continued fraction above, where each converges fast (NR §6.2).
pub fn gamma_q(a: f64, x: f64) -> f64 {
    assert!(a > 0.0 && x >= 0.0, "gamma_q needs a > 0, x >= 0");
    if x == 0.0 {
        1.0
    } else if x < a + 1.0 {
        1.0 - gamma_series(a, x)
    } else {
        gamma_continued_fraction(a, x)
    }
}

const EPS: f64 = 1e-15;
const MAX_ITER: usize = 100_000;

/// `x^a e^-x / Γ(a)`, the factor both expansions share.
fn gamma_prefactor(a: f64, x: f64) -> f64 {
    (a * x.ln() - x - ln_gamma(a)).exp()
}

/// `P(a, x)` by its power series (NR eq. 6.2.5). Terms shrink like `x/(a+n)`, so large `a`
/// needs O(sqrt(a)) terms: hence the generous iteration cap, unlike NR's 100.
fn gamma_series(a: f64, x: f64) -> f64 {
    let (mut ap, mut del) = (a, 1.0 / a);
    let mut sum = del;
    for _ in 0..MAX_ITER {
        ap += 1.0;
        del *= x / ap;
        sum += del;
        if del.abs() < sum.abs() * EPS {
            break;
        }
    }
    sum * gamma_prefactor(a, x)
}

/// `Q(a, x)` by its continued fraction (NR eq. 6.2.7), evaluated with the modified Lentz
/// method (NR §5.2).
fn gamma_continued_fraction(a: f64, x: f64) -> f64 {
    const TINY: f64 = 1e-300;
    let mut b = x + 1.0 - a;
    let mut c = 1.0 / TINY;
    let mut d = 1.0 / b;
    let mut h = d;
    for i in 1..MAX_ITER {
        let an = -(i as f64) * (i as f64 - a);
        b += 2.0;
        d = an * d + b;
        if d.abs() < TINY {
            d = TINY;
        }
        c = b + an / c;
        if c.abs() < TINY {
            c = TINY;
        }
        d = 1.0 / d;
        let del = d * c;
        h *= del;
        if (del - 1.0).abs() < EPS {
            break;
        }
    }
    gamma_prefactor(a, x) * h
}
