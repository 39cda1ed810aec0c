//! FLIP (Andersson et al. 2020, "FLIP: A Difference Evaluator for Alternating Images"), the
//! perceptual error of an image against a reference, by NVIDIA's reference implementation
//! (the C++ of NVlabs/flip through gfx-rs' `nv-flip` bindings): not a hand copy.
//!
//! LDR-FLIP needs display values: both images are tone-mapped the same way, exposure, clamp
//! to [0, 1], gamma 2.2 (the convention of the peers' comparison script, so our numbers and
//! theirs are one metric), then quantised to 8 bits as FLIP's own tools read PNGs.

use crate::{FilmError, Image, Mask};

/// Per-pixel FLIP error in [0, 1] (`map[y * width + x]`).
#[derive(Clone, Debug)]
pub struct FlipMap {
    pub width: usize,
    pub height: usize,
    pub map: Vec<f32>,
}

impl FlipMap {
    /// Mean error over the selected pixels (f64 sum); `None` when none is selected.
    pub fn mean(&self, mask: Option<&Mask>) -> Result<Option<f64>, FilmError> {
        if let Some(m) = mask
            && ((m.width, m.height) != (self.width, self.height)
                || m.pixels.len() != self.map.len())
        {
            return Err(FilmError::SizeMismatch {
                what: "FLIP mask",
                a: (self.width, self.height),
                b: (m.width, m.height),
            });
        }
        let (mut sum, mut n) = (0.0f64, 0usize);
        for (i, &e) in self.map.iter().enumerate() {
            if mask.is_none_or(|m| m.pixels[i]) {
                sum += e as f64;
                n += 1;
            }
        }
        Ok((n > 0).then(|| sum / n as f64))
    }
}

/// The display value of a linear channel: exposure, clamp, gamma 2.2, 8 bits (NaN reads as
/// black, +inf as white, like the peers' script).
fn ldr(v: f32, exposure: f32) -> u8 {
    let v = v * exposure;
    let v = if v.is_nan() { 0.0 } else { v.clamp(0.0, 1.0) };
    (v.powf(1.0 / 2.2) * 255.0).round() as u8
}

/// FLIP of `test` against `reference` at FLIP's default viewing condition (67 pixels per
/// degree: a 0.7 m wide 4K monitor seen from 0.7 m).
pub fn flip(test: &Image, reference: &Image, exposure: f32) -> Result<FlipMap, FilmError> {
    test.check_same_size(reference, "FLIP")?;
    let (w, h) = (test.width, test.height);
    if w == 0 || h == 0 {
        return Err(FilmError::EmptyRegion);
    }
    let bytes = |img: &Image| {
        let data: Vec<u8> = img
            .data
            .iter()
            .flatten()
            .map(|&v| ldr(v, exposure))
            .collect();
        nv_flip::FlipImageRgb8::with_data(w as u32, h as u32, &data)
    };
    let map = nv_flip::flip(
        bytes(reference),
        bytes(test),
        nv_flip::DEFAULT_PIXELS_PER_DEGREE,
    );
    Ok(FlipMap {
        width: w,
        height: h,
        map: map.to_vec(),
    })
}
