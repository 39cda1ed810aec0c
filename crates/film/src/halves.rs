//! A reference given as two independent halves: images of one scene by one renderer and budget
//! with different seeds. Their mean `R = (A + B) / 2` is the reference, and `(A - B)² / 4`
//! estimates its variance per element without bias: halves of variance σ² give
//! `E[(A - B)²] = 2σ²`, and their mean has variance σ²/2. An image's squared error against `R`
//! is its error against the truth plus that variance (the two are independent), so subtracting
//! it takes the reference's own noise out of every error (the plain figure stays beside it).

use crate::{FilmError, Image, Mask, Metrics, RELMSE_EPSILON, metrics};

/// The mean of two halves and the variance of each of its elements.
#[derive(Clone, Debug)]
pub struct Halves {
    pub mean: Image,
    /// `(A - B)² / 4` per pixel and channel.
    pub variance: Vec<[f64; 3]>,
}

impl Halves {
    /// The halves `a` and `b` (same size, independent seeds). Two equal images are refused:
    /// one file given twice would estimate no noise and take nothing out.
    pub fn new(a: &Image, b: &Image) -> Result<Halves, FilmError> {
        a.check_same_size(b, "reference halves")?;
        if a.data == b.data {
            return Err(FilmError::IdenticalHalves);
        }
        let mut variance = Vec::with_capacity(a.data.len());
        let mean = Image::from_fn(a.width, a.height, |x, y| {
            let (pa, pb) = (a.get(x, y), b.get(x, y));
            let mut m = [0.0f32; 3];
            let mut v = [0.0f64; 3];
            for c in 0..3 {
                let (u, w) = (f64::from(pa[c]), f64::from(pb[c]));
                m[c] = (0.5 * (u + w)) as f32;
                v[c] = 0.25 * (u - w) * (u - w);
            }
            variance.push(v);
            m
        });
        Ok(Halves { mean, variance })
    }
}

/// Errors of an image against [`Halves`]: the plain metrics against their mean, and the
/// squared errors with the reference's variance subtracted.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HalvesMetrics {
    pub plain: Metrics,
    /// `mean(((a - R)² - Var R) / (R² + RELMSE_EPSILON))`: an unbiased estimate of the
    /// relative MSE against the truth (weighted by the reference's own `R²`); it can come out
    /// slightly negative for an image much better than the reference.
    pub relmse: f64,
    /// pbrt's convention, corrected the same way.
    pub relmse_pbrt: f64,
    /// `sqrt(max(0, mean((a - R)² - Var R)))`.
    pub rmse: f64,
    /// The part of the plain relative MSE that is the reference's noise.
    pub reference_relmse: f64,
}

impl std::fmt::Display for HalvesMetrics {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{} | reference noise taken out: relmse={:.6e} relmse_pbrt={:.6e} rmse={:.6e} \
             (the reference's own relmse {:.6e})",
            self.plain, self.relmse, self.relmse_pbrt, self.rmse, self.reference_relmse
        )
    }
}

/// Metrics of `a` against the halves' mean inside `mask` if given, plain and with the
/// reference's variance taken out. Sums in f64.
pub fn metrics_halves(
    a: &Image,
    r: &Halves,
    mask: Option<&Mask>,
) -> Result<HalvesMetrics, FilmError> {
    let plain = metrics(a, &r.mean, mask)?;
    let (mut var, mut rel, mut pbrt) = (0.0f64, 0.0f64, 0.0f64);
    for (i, (pr, v)) in r.mean.data.iter().zip(&r.variance).enumerate() {
        if mask.is_some_and(|m| !m.pixels[i]) {
            continue;
        }
        for c in 0..3 {
            let y = f64::from(pr[c]);
            var += v[c];
            rel += v[c] / (y * y + RELMSE_EPSILON);
            pbrt += v[c] / ((y + 0.01) * (y + 0.01));
        }
    }
    let n = (3 * plain.pixels) as f64;
    let (var, rel, pbrt) = (var / n, rel / n, pbrt / n);
    Ok(HalvesMetrics {
        plain,
        relmse: plain.relmse - rel,
        relmse_pbrt: plain.relmse_pbrt - pbrt,
        rmse: (plain.rmse * plain.rmse - var).max(0.0).sqrt(),
        reference_relmse: rel,
    })
}
