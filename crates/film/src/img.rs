//! The resolved image: linear RGB f32, and compositing.

use crate::FilmError;

/// A resolved image: linear RGB, one `[f32; 3]` per pixel, row-major, row 0 at the top.
/// Invariant expected by every function taking an `Image`: `data.len() == width * height`
/// (checked, reported as [`FilmError::BadBuffer`]).
#[derive(Clone, Debug, PartialEq)]
pub struct Image {
    pub width: usize,
    pub height: usize,
    pub data: Vec<[f32; 3]>,
}

impl Image {
    /// A black image.
    pub fn new(width: usize, height: usize) -> Self {
        Self {
            width,
            height,
            data: vec![[0.0; 3]; width * height],
        }
    }

    /// An image whose pixel `(x, y)` is `f(x, y)`.
    pub fn from_fn(
        width: usize,
        height: usize,
        mut f: impl FnMut(usize, usize) -> [f32; 3],
    ) -> Self {
        let mut data = Vec::with_capacity(width * height);
        for y in 0..height {
            for x in 0..width {
                data.push(f(x, y));
            }
        }
        Self {
            width,
            height,
            data,
        }
    }

    /// Pixel `(x, y)`. Panics when out of range, like slice indexing.
    pub fn get(&self, x: usize, y: usize) -> [f32; 3] {
        assert!(
            x < self.width && y < self.height,
            "pixel ({x}, {y}) out of range"
        );
        self.data[y * self.width + x]
    }

    /// Sets pixel `(x, y)`. Panics when out of range, like slice indexing.
    pub fn set(&mut self, x: usize, y: usize, rgb: [f32; 3]) {
        assert!(
            x < self.width && y < self.height,
            "pixel ({x}, {y}) out of range"
        );
        self.data[y * self.width + x] = rgb;
    }

    pub(crate) fn check(&self, what: &'static str) -> Result<(), FilmError> {
        if self.width.checked_mul(self.height) == Some(self.data.len()) {
            Ok(())
        } else {
            Err(FilmError::BadBuffer {
                what,
                width: self.width,
                height: self.height,
                len: self.data.len(),
            })
        }
    }

    pub(crate) fn check_same_size(
        &self,
        other: &Image,
        what: &'static str,
    ) -> Result<(), FilmError> {
        self.check(what)?;
        other.check(what)?;
        if (self.width, self.height) == (other.width, other.height) {
            Ok(())
        } else {
            Err(FilmError::SizeMismatch {
                what,
                a: (self.width, self.height),
                b: (other.width, other.height),
            })
        }
    }

    /// `self += other`, per element.
    pub fn add(&mut self, other: &Image) -> Result<(), FilmError> {
        self.check_same_size(other, "Image::add")?;
        for (a, b) in self.data.iter_mut().zip(&other.data) {
            for c in 0..3 {
                a[c] += b[c];
            }
        }
        Ok(())
    }

    /// `self *= s`, per element.
    pub fn scale(&mut self, s: f32) {
        for p in &mut self.data {
            for v in p {
                *v *= s;
            }
        }
    }

    /// Box-filters `factor` x `factor` blocks into one pixel (f64 sums); a partial block at
    /// the right or bottom edge is dropped. Comparing downsampled images against a reference
    /// multiplies the reference's samples per compared pixel by `factor^2`, which lowers its
    /// own noise floor in the metrics.
    pub fn box_downsample(&self, factor: usize) -> Image {
        let f = factor.max(1);
        let (w, h) = (self.width / f, self.height / f);
        Image::from_fn(w, h, |x, y| {
            let mut s = [0.0f64; 3];
            for yy in y * f..(y + 1) * f {
                for xx in x * f..(x + 1) * f {
                    let p = self.data[yy * self.width + xx];
                    for c in 0..3 {
                        s[c] += p[c] as f64;
                    }
                }
            }
            let n = (f * f) as f64;
            [(s[0] / n) as f32, (s[1] / n) as f32, (s[2] / n) as f32]
        })
    }
}

/// `Σ weight_k · image_k`, summed in f64 per element and rounded to f32 once. All images
/// must have the same size; an empty list gives a 0x0 image.
pub fn composite(parts: &[(&Image, f32)]) -> Result<Image, FilmError> {
    let Some(&(first, _)) = parts.first() else {
        return Ok(Image::new(0, 0));
    };
    for &(img, _) in parts {
        first.check_same_size(img, "composite")?;
    }
    let mut acc = vec![[0.0f64; 3]; first.data.len()];
    for &(img, w) in parts {
        let w = f64::from(w);
        for (a, p) in acc.iter_mut().zip(&img.data) {
            for c in 0..3 {
                a[c] += w * f64::from(p[c]);
            }
        }
    }
    Ok(Image {
        width: first.width,
        height: first.height,
        data: acc
            .into_iter()
            .map(|a| [a[0] as f32, a[1] as f32, a[2] as f32])
            .collect(),
    })
}
