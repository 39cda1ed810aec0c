//! Colour textures (MTL `map_Kd`): decoded once at load into linear RGB, looked up bilinearly
//! with repeat wrapping, the defaults of Mitsuba 3's `bitmap` texture, so its images are
//! references for textured scenes.

// A decoder of untrusted bytes (image files a scene names): no input may reach a panic, so
// the lints that find the ways to one are errors here, as in every loader; `cargo clippy` is
// the check.
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

use glam::{Vec2, Vec3};
use std::path::Path;

/// Largest texture photonflow loads, in texels: 2^26 (8192 x 8192) is 768 MiB of f32 RGB,
/// beyond any albedo map a scene needs; a larger header is taken for a damaged file.
const MAX_TEXELS: u64 = 1 << 26;

/// A linear-RGB image, row 0 at the top (as files store them), or a checkerboard (whose
/// two colours are then its texels).
#[derive(Clone, Debug, PartialEq)]
pub struct Texture {
    pub width: usize,
    pub height: usize,
    pub texels: Vec<Vec3>,
    pub checker: Option<Checkerboard>,
}

/// Mitsuba 3's `checkerboard` texture: `color0` where the fractional parts of `to_uv` times
/// the texture coordinate are both below or both above 1/2, `color1` elsewhere.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Checkerboard {
    pub color0: Vec3,
    pub color1: Vec3,
    /// Rows of the affine map, on Mitsuba's coordinates (`v = 0` at an image's top).
    pub to_uv: [[f32; 3]; 2],
}

/// The sRGB transfer function's inverse (IEC 61966-2-1), per channel.
pub fn srgb_to_linear(c: f32) -> f32 {
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

impl Texture {
    /// Decodes a PNG, JPEG, TGA, EXR or Radiance HDR file's bytes. Integer images are sRGB-encoded (what image files hold
    /// unless they say otherwise, and what Mitsuba 3 assumes of them) and decoded to linear;
    /// float images (EXR, HDR) are linear already. Grey images are read as equal channels; alpha
    /// is not read (`map_Kd` is a colour, and MTL's `map_d` is the transparency). `Err` is one
    /// line saying what is wrong, without the path (the caller names the file).
    /// `name` is the file's name: TGA files carry no signature, so their extension tells.
    pub fn decode(bytes: &[u8], name: &Path) -> Result<Texture, String> {
        let reader = || {
            let mut r = image::ImageReader::new(std::io::Cursor::new(bytes))
                .with_guessed_format()
                .map_err(|e| format!("cannot read it: {e}"))?;
            if r.format().is_none()
                && let Ok(f) = image::ImageFormat::from_path(name)
            {
                r.set_format(f);
            }
            Ok::<_, String>(r)
        };
        let (w, h) = reader()?.into_dimensions().map_err(|e| {
            format!("not a PNG, JPEG, TGA, EXR or Radiance HDR image photonflow can read: {e}")
        })?;
        if w == 0 || h == 0 {
            return Err(format!("the image is empty ({w}x{h})"));
        }
        if w as u64 * h as u64 > MAX_TEXELS {
            return Err(format!(
                "a {w}x{h} image is larger than the {MAX_TEXELS} texels photonflow loads"
            ));
        }
        let img = reader()?
            .decode()
            .map_err(|e| format!("cannot decode it: {e}"))?;
        let linear = matches!(
            img.color(),
            image::ColorType::Rgb32F | image::ColorType::Rgba32F
        );
        let rgb = img.into_rgb32f();
        let texels: Vec<Vec3> = rgb
            .pixels()
            .map(|p| {
                let c = Vec3::from(p.0);
                if linear {
                    c
                } else {
                    Vec3::new(
                        srgb_to_linear(c.x),
                        srgb_to_linear(c.y),
                        srgb_to_linear(c.z),
                    )
                }
            })
            .collect();
        if let Some(bad) = texels
            .iter()
            .find(|c| !(c.is_finite() && c.min_element() >= 0.0))
        {
            return Err(format!(
                "texel {:?} is negative or not finite: an albedo lies in [0, 1]",
                bad.to_array()
            ));
        }
        Ok(Texture {
            width: rgb.width() as usize,
            height: rgb.height() as usize,
            texels,
            checker: None,
        })
    }

    /// A checkerboard of two colours.
    pub fn checkerboard(c: Checkerboard) -> Texture {
        Texture {
            width: 2,
            height: 1,
            texels: vec![c.color0, c.color1],
            checker: Some(c),
        }
    }

    /// The largest value of each channel over the texture.
    pub fn max(&self) -> Vec3 {
        self.texels.iter().fold(Vec3::ZERO, |m, &c| m.max(c))
    }

    /// Bilinear lookup at texture coordinate `uv`, repeated outside [0, 1)^2. `v` runs up the
    /// image (OBJ's convention: `v = 0` is the bottom row); texel centres lie at half-integer
    /// coordinates (Mitsuba 3's `bitmap`: `filter_type = bilinear`, `wrap_mode = repeat`).
    pub fn eval(&self, uv: Vec2) -> Vec3 {
        if let Some(c) = &self.checker {
            // Mitsuba's v runs down the image: photonflow's, as OBJ's `vt`, up.
            let (u, v) = (uv.x, 1.0 - uv.y);
            let [a, b] = c.to_uv;
            let s = a[0] * u + a[1] * v + a[2];
            let t = b[0] * u + b[1] * v + b[2];
            let upper = |x: f32| x - x.floor() > 0.5;
            return if upper(s) == upper(t) {
                c.color0
            } else {
                c.color1
            };
        }
        let x = uv.x * self.width as f32 - 0.5;
        let y = (1.0 - uv.y) * self.height as f32 - 0.5;
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = (x - x0, y - y0);
        let wrap = |i: f32, n: usize| -> usize {
            // rem_euclid of a finite float lands in [0, n); a NaN coordinate reads texel 0.
            let r = (i as i64).rem_euclid(n as i64) as usize;
            r.min(n - 1)
        };
        let (xa, xb) = (wrap(x0, self.width), wrap(x0 + 1.0, self.width));
        let (ya, yb) = (wrap(y0, self.height), wrap(y0 + 1.0, self.height));
        let at = |x: usize, y: usize| {
            self.texels
                .get(y * self.width + x)
                .copied()
                .unwrap_or(Vec3::ZERO)
        };
        // `a + (b - a) t`: exact where neighbours are equal, so a constant texture reads its
        // value to the bit.
        let lerp = |a: Vec3, b: Vec3, t: f32| a + (b - a) * t;
        let top = lerp(at(xa, ya), at(xb, ya), fx);
        let bottom = lerp(at(xa, yb), at(xb, yb), fx);
        let c = lerp(top, bottom, fy);
        if c.is_finite() { c } else { at(0, 0) }
    }
}
