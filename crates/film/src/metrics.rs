//! Error metrics of a rendered image against a reference, optionally inside a mask.

use std::fmt;

use crate::{FilmError, Image};

/// Epsilon in the relative MSE denominator `b² + RELMSE_EPSILON` (pbrt/Mitsuba convention):
/// keeps black reference pixels from dominating (or dividing by zero).
pub const RELMSE_EPSILON: f64 = 1e-2;

/// Which pixels a metric looks at: `pixels[y * width + x]`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Mask {
    pub width: usize,
    pub height: usize,
    pub pixels: Vec<bool>,
}

impl Mask {
    /// Every pixel selected.
    pub fn all(width: usize, height: usize) -> Self {
        Self {
            width,
            height,
            pixels: vec![true; width * height],
        }
    }

    /// Pixels with `x0 <= x < x1` and `y0 <= y < y1` (clipped to the image) selected.
    pub fn rect(width: usize, height: usize, x0: usize, y0: usize, x1: usize, y1: usize) -> Self {
        Self::from_fn(width, height, |x, y| {
            (x0..x1).contains(&x) && (y0..y1).contains(&y)
        })
    }

    /// Pixel `(x, y)` selected iff `f(x, y)`.
    pub fn from_fn(width: usize, height: usize, mut f: impl FnMut(usize, usize) -> bool) -> Self {
        let mut pixels = Vec::with_capacity(width * height);
        for y in 0..height {
            for x in 0..width {
                pixels.push(f(x, y));
            }
        }
        Self {
            width,
            height,
            pixels,
        }
    }

    /// Number of selected pixels.
    pub fn count(&self) -> usize {
        self.pixels.iter().filter(|&&p| p).count()
    }
}

/// Error of an image `a` against a reference `b`, over the selected pixels and all three
/// channels. Sums are accumulated in f64. NaN pixels propagate into every field.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Metrics {
    /// `sqrt(mean((a - b)²))`.
    pub rmse: f64,
    /// `mean((a - b)² / (b² + RELMSE_EPSILON))`.
    pub relmse: f64,
    /// pbrt's convention, `mean((a - b)² / (b + 0.01)²)`: the same idea, weighted more
    /// heavily in dark pixels (so the two are named apart).
    pub relmse_pbrt: f64,
    /// `mean(|a - b|)`.
    pub mae: f64,
    /// Mean channel value of `a` (compare with `mean_b` for bias).
    pub mean_a: f64,
    /// Mean channel value of the reference `b`.
    pub mean_b: f64,
    /// Number of pixels the means are over (each contributes 3 channel values).
    pub pixels: usize,
}

impl fmt::Display for Metrics {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "rmse={:.6e} relmse={:.6e} relmse_pbrt={:.6e} mae={:.6e} mean_a={:.6e} mean_b={:.6e} \
             pixels={}",
            self.rmse,
            self.relmse,
            self.relmse_pbrt,
            self.mae,
            self.mean_a,
            self.mean_b,
            self.pixels
        )
    }
}

/// Metrics of `a` against the reference `b` (same size), inside `mask` if given.
///
/// Errors: size mismatch between the images or with the mask, an image whose buffer does
/// not match its size, or no selected pixel.
pub fn metrics(a: &Image, b: &Image, mask: Option<&Mask>) -> Result<Metrics, FilmError> {
    a.check_same_size(b, "metrics")?;
    if let Some(m) = mask {
        if (m.width, m.height) != (a.width, a.height) {
            return Err(FilmError::SizeMismatch {
                what: "metrics mask",
                a: (a.width, a.height),
                b: (m.width, m.height),
            });
        }
        if m.pixels.len() != a.data.len() {
            return Err(FilmError::BadBuffer {
                what: "metrics mask",
                width: m.width,
                height: m.height,
                len: m.pixels.len(),
            });
        }
    }
    let selected = |i: usize| mask.is_none_or(|m| m.pixels[i]);
    let (mut se, mut rel, mut ae, mut sa, mut sb) = (0.0f64, 0.0f64, 0.0f64, 0.0f64, 0.0f64);
    let mut pbrt = 0.0f64;
    let mut pixels = 0usize;
    for (i, (pa, pb)) in a.data.iter().zip(&b.data).enumerate() {
        if !selected(i) {
            continue;
        }
        pixels += 1;
        for c in 0..3 {
            let (x, y) = (f64::from(pa[c]), f64::from(pb[c]));
            let d = x - y;
            se += d * d;
            rel += d * d / (y * y + RELMSE_EPSILON);
            pbrt += d * d / ((y + 0.01) * (y + 0.01));
            ae += d.abs();
            sa += x;
            sb += y;
        }
    }
    if pixels == 0 {
        return Err(FilmError::EmptyRegion);
    }
    let n = (3 * pixels) as f64;
    Ok(Metrics {
        rmse: (se / n).sqrt(),
        relmse: rel / n,
        relmse_pbrt: pbrt / n,
        mae: ae / n,
        mean_a: sa / n,
        mean_b: sb / n,
        pixels,
    })
}
