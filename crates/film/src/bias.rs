//! Bias and variance apart: from K independent renders of one image (other seeds) and a
//! reference, per pixel the mean, the sample variance s² and the squared bias
//! `max(0, (mean - ref)² - s²/K)` (the squared error of the mean, less what its own noise
//! contributes: an unbiased estimate of bias² clamped at zero). Over a region, the mean of
//! bias² + s² is the expected squared error of one render, so `bias² + variance = MSE` can be
//! read off per region. Every quantity comes in two weightings: absolute, and relative to
//! `ref² + RELMSE_EPSILON` (per channel, as [`crate::metrics`]'s relative MSE).

use crate::{FilmError, Image, Mask, RELMSE_EPSILON};

/// Per-pixel maps (the mean of the three channels, in the chosen weighting).
#[derive(Clone, Debug, PartialEq)]
pub struct BiasVariance {
    pub width: usize,
    pub height: usize,
    /// Runs the maps come from.
    pub runs: usize,
    /// The mean render (RGB).
    pub mean: Image,
    /// Squared bias per pixel.
    pub bias2: Vec<f64>,
    /// Sample variance of one render per pixel (K - 1 in the denominator).
    pub variance: Vec<f64>,
    /// Mean over the runs of one render's squared error per pixel.
    pub mse: Vec<f64>,
}

/// One region's averages of the maps.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RegionSums {
    pub pixels: usize,
    pub bias2: f64,
    pub variance: f64,
    pub mse: f64,
}

impl BiasVariance {
    /// `runs` (at least 2, all the reference's size) against `reference`; `relative` divides
    /// each channel's squares by `ref² + RELMSE_EPSILON`. Sums in f64.
    pub fn new(
        runs: &[&Image],
        reference: &Image,
        relative: bool,
    ) -> Result<BiasVariance, FilmError> {
        BiasVariance::with_reference_variance(runs, reference, None, relative)
    }

    /// As [`BiasVariance::new`] against the mean of two halves (`crate::Halves`): the
    /// reference's variance is taken out of each bias² as the runs' own variance of the mean
    /// is, so the reference's noise no longer reads as bias. Pixels' bias² may then be
    /// negative (unbiased estimates of a small bias²); maps show them as zero.
    pub fn against_halves(
        runs: &[&Image],
        halves: &crate::Halves,
        relative: bool,
    ) -> Result<BiasVariance, FilmError> {
        BiasVariance::with_reference_variance(runs, &halves.mean, Some(&halves.variance), relative)
    }

    fn with_reference_variance(
        runs: &[&Image],
        reference: &Image,
        reference_variance: Option<&[[f64; 3]]>,
        relative: bool,
    ) -> Result<BiasVariance, FilmError> {
        let (w, h) = (reference.width, reference.height);
        for r in runs {
            if (r.width, r.height) != (w, h) {
                return Err(FilmError::SizeMismatch {
                    what: "run and reference",
                    a: (r.width, r.height),
                    b: (w, h),
                });
            }
        }
        let k = runs.len();
        if k < 2 {
            return Err(FilmError::TooFewRuns { runs: k });
        }
        let kf = k as f64;
        let mut mean = Image::new(w, h);
        let (mut bias2, mut variance, mut mse) =
            (vec![0.0; w * h], vec![0.0; w * h], vec![0.0; w * h]);
        for y in 0..h {
            for x in 0..w {
                let r = reference.get(x, y);
                let (mut m_rgb, mut b, mut v, mut e) = ([0.0f32; 3], 0.0, 0.0, 0.0);
                for c in 0..3 {
                    let rc = r[c] as f64;
                    let weight = if relative {
                        1.0 / (rc * rc + RELMSE_EPSILON)
                    } else {
                        1.0
                    };
                    let vals = runs.iter().map(|img| img.get(x, y)[c] as f64);
                    let m = vals.clone().sum::<f64>() / kf;
                    let s2 = vals.clone().map(|a| (a - m) * (a - m)).sum::<f64>() / (kf - 1.0);
                    let sq = vals.map(|a| (a - rc) * (a - rc)).sum::<f64>() / kf;
                    m_rgb[c] = m as f32;
                    // E[(m - ref)²] = bias² + Var(m) + Var(ref): both variances out.
                    let var_ref = reference_variance.map_or(0.0, |v| v[y * w + x][c]);
                    let b2 = (m - rc).powi(2) - s2 / kf - var_ref;
                    // Against halves the per-pixel estimate is left unclamped: the halves'
                    // variance estimate is too noisy per pixel (one degree of freedom) for
                    // a clamp at zero not to read as bias, and region means stay unbiased.
                    b += if reference_variance.is_some() {
                        b2
                    } else {
                        b2.max(0.0)
                    } * weight;
                    v += s2 * weight;
                    e += sq * weight;
                }
                mean.set(x, y, m_rgb);
                let i = y * w + x;
                (bias2[i], variance[i], mse[i]) = (b / 3.0, v / 3.0, e / 3.0);
            }
        }
        Ok(BiasVariance {
            width: w,
            height: h,
            runs: k,
            mean,
            bias2,
            variance,
            mse,
        })
    }

    /// The maps' means over the pixels `mask` selects (all pixels without one).
    pub fn region(&self, mask: Option<&Mask>) -> Result<RegionSums, FilmError> {
        if let Some(m) = mask
            && (m.width, m.height) != (self.width, self.height)
        {
            return Err(FilmError::SizeMismatch {
                what: "mask and maps",
                a: (m.width, m.height),
                b: (self.width, self.height),
            });
        }
        let (mut n, mut b, mut v, mut e) = (0usize, 0.0, 0.0, 0.0);
        for i in 0..self.width * self.height {
            if mask.is_some_and(|m| !m.pixels[i]) {
                continue;
            }
            n += 1;
            b += self.bias2[i];
            v += self.variance[i];
            e += self.mse[i];
        }
        let d = n.max(1) as f64;
        Ok(RegionSums {
            pixels: n,
            bias2: b / d,
            variance: v / d,
            mse: e / d,
        })
    }

    /// A map as a grey image (for EXR).
    pub fn image(&self, map: &[f64]) -> Image {
        Image::from_fn(self.width, self.height, |x, y| {
            [map[y * self.width + x] as f32; 3]
        })
    }

    /// A map in false colour for PNG: black through red and yellow to white over
    /// `0..=max` on a square-root scale (most of a map is small, a few pixels large).
    pub fn false_colour(&self, map: &[f64], max: f64) -> Image {
        Image::from_fn(self.width, self.height, |x, y| {
            let t = (map[y * self.width + x] / max.max(f64::MIN_POSITIVE))
                .clamp(0.0, 1.0)
                .sqrt() as f32;
            [
                (3.0 * t).min(1.0),
                (3.0 * t - 1.0).clamp(0.0, 1.0),
                (3.0 * t - 2.0).clamp(0.0, 1.0),
            ]
        })
    }
}
