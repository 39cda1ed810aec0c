//! Image files: linear float EXR, tone-mapped 8-bit PNG, and atomic replacement on disk.
//!
//! Every writer encodes into a temporary file beside the target (a `temps::Temp`: removed on
//! failure, on a signal, or by a later run once this process is gone) and renames it over the
//! target. A rename within one directory is atomic on POSIX file systems, so readers (and a
//! later run after a crash) see either the old file or the complete new one, never a truncated
//! image. Encoding straight into the file keeps no second copy of the image in memory.

// A decoder of untrusted bytes: no input may reach a panic, so the lints that find the ways
// to one (unwrap, expect, indexing, explicit panics) are errors here; `cargo clippy` is the
// check.
#![cfg_attr(
    not(test),
    deny(
        clippy::unwrap_used,
        clippy::expect_used,
        clippy::indexing_slicing,
        clippy::panic,
        clippy::unreachable
    )
)]

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::Path;

use crate::{FilmError, Image};

/// Display transform for PNG output: `clamp((v · 2^exposure)^(1/gamma), 0, 1) · 255`,
/// rounded. NaN and negative values give 0, +inf gives 255.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ToneMap {
    /// Exposure in stops (`v` is multiplied by `2^exposure`).
    pub exposure: f32,
    /// Display gamma; 1.8 matches the course framework's tone map.
    pub gamma: f32,
}

impl Default for ToneMap {
    fn default() -> Self {
        Self {
            exposure: 0.0,
            gamma: 1.8,
        }
    }
}

impl ToneMap {
    /// One linear channel value to an 8-bit code. Computed in f64.
    pub fn apply(&self, v: f32) -> u8 {
        let x = f64::from(v) * f64::from(self.exposure).exp2();
        if x.is_nan() || x <= 0.0 {
            return 0;
        }
        if x >= 1.0 {
            return 255;
        }
        let y = x.powf(1.0 / f64::from(self.gamma)).clamp(0.0, 1.0);
        // NaN (e.g. from gamma = 0 or NaN) saturates to 0 in the `as` cast.
        (y * 255.0).round() as u8
    }
}

/// Writes `img` as a linear f32 RGB OpenEXR file (lossless ZIP, scan lines), atomically.
pub fn write_exr(path: impl AsRef<Path>, img: &Image) -> Result<(), FilmError> {
    use exr::prelude::{Encoding, SpecificChannels, Vec2, WritableImage};
    let path = path.as_ref();
    img.check("write_exr")?;
    let w = img.width;
    let channels = SpecificChannels::rgb(|Vec2(x, y): Vec2<usize>| {
        let [r, g, b] = img.data.get(y * w + x).copied().unwrap_or_default();
        (r, g, b)
    });
    let image = exr::prelude::Image::from_encoded_channels(
        (img.width, img.height),
        Encoding::SMALL_LOSSLESS,
        channels,
    );
    write_atomic_with(path, |file| {
        image
            .write()
            .to_buffered(file)
            .map_err(|source| FilmError::Exr {
                path: path.to_owned(),
                source,
            })
    })
}

/// Reads the first RGB(A) layer of an OpenEXR file as linear f32 RGB (alpha is dropped).
pub fn read_exr(path: impl AsRef<Path>) -> Result<Image, FilmError> {
    let path = path.as_ref();
    let exr_err = |source| FilmError::Exr {
        path: path.to_owned(),
        source,
    };
    // The image is allocated from the header's size: check that size against what the file
    // could hold first. Deflate, EXR's strongest lossless stage, expands at most 1032:1
    // (RFC 1951: a 258-byte match per 2 bits), so a pixel of three f32 channels needs over
    // 1/100 byte; 128 pixels per byte, plus a million pixels, is room for any real file.
    let len = std::fs::metadata(path)
        .map_err(|source| FilmError::Io {
            path: path.to_owned(),
            what: "read",
            source,
        })?
        .len();
    let meta = exr::meta::MetaData::read_from_file(path, false).map_err(exr_err)?;
    for h in &meta.headers {
        let pixels = (h.layer_size.width() as u64).saturating_mul(h.layer_size.height() as u64);
        if pixels > len.saturating_mul(128).saturating_add(1 << 20) {
            return Err(exr_err(exr::error::Error::Invalid(
                std::borrow::Cow::Owned(format!(
                    "a {}x{} layer cannot fit in a {len}-byte file",
                    h.layer_size.width(),
                    h.layer_size.height()
                )),
            )));
        }
    }
    let read = exr::prelude::read_first_rgba_layer_from_file(
        path,
        |size, _| Image::new(size.width(), size.height()),
        |img: &mut Image, pos, (r, g, b, _a): (f32, f32, f32, f32)| {
            let i = pos.y() * img.width + pos.x();
            if let Some(p) = img.data.get_mut(i) {
                *p = [r, g, b];
            }
        },
    )
    .map_err(|source| FilmError::Exr {
        path: path.to_owned(),
        source,
    })?;
    Ok(read.layer_data.channel_data.pixels)
}

/// Writes `img` as an 8-bit RGB PNG encoded by `tone` (a pure power curve, not sRGB), atomically.
pub fn write_png(path: impl AsRef<Path>, img: &Image, tone: &ToneMap) -> Result<(), FilmError> {
    use image::ImageEncoder;
    let path = path.as_ref();
    img.check("write_png")?;
    let png_err = |source| FilmError::Png {
        path: path.to_owned(),
        source,
    };
    let too_big = || {
        png_err(image::ImageError::Limits(
            image::error::LimitError::from_kind(image::error::LimitErrorKind::DimensionError),
        ))
    };
    let w = u32::try_from(img.width).map_err(|_| too_big())?;
    let h = u32::try_from(img.height).map_err(|_| too_big())?;
    write_atomic_with(path, |file| {
        let pixels: Vec<u8> = img.data.iter().flatten().map(|&v| tone.apply(v)).collect();
        image::codecs::png::PngEncoder::new(file)
            .write_image(&pixels, w, h, image::ExtendedColorType::Rgb8)
            .map_err(png_err)
    })
}

/// Writes `bytes` to `path` via a temporary file in the same directory plus a rename.
/// On failure the temporary file is removed and `path` is untouched.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<(), FilmError> {
    write_atomic_with(path, |file| {
        file.write_all(bytes)
            .map_err(|e| io_error(path, "write temporary file", e))
    })
}

fn io_error(path: &Path, what: &'static str, source: std::io::Error) -> FilmError {
    FilmError::Io {
        path: path.to_owned(),
        what,
        source,
    }
}

/// [`write_atomic`] of what `write` writes into the (buffered) temporary file.
fn write_atomic_with(
    path: &Path,
    write: impl FnOnce(&mut BufWriter<File>) -> Result<(), FilmError>,
) -> Result<(), FilmError> {
    let (tmp, file) =
        temps::Temp::file(path).map_err(|e| io_error(path, "create temporary file", e))?;
    let mut buffered = BufWriter::new(file);
    write(&mut buffered)?;
    let file = buffered
        .into_inner()
        .map_err(|e| io_error(path, "write temporary file", e.into_error()))?;
    // Data on disk before the name: after a crash the renamed file is complete.
    file.sync_all()
        .map_err(|e| io_error(path, "write temporary file", e))?;
    drop(file);
    tmp.publish(path)
        .map_err(|e| io_error(path, "rename temporary file into place", e))
}
