//! The environment light's radiance, sampling density and power: a lat-long (equirectangular)
//! image or a constant colour at infinity, with Mitsuba 3's `envmap` conventions so its
//! images are exact references (Mitsuba 3 plugin docs, "Environment emitter"; pbrt-v4
//! §12.5.2, `ImageInfiniteLight`).
//!
//! Conventions, in the emitter's local frame (world = `to_world` × local):
//! - the direction of azimuth `φ` and polar angle `θ` (from +Y) is
//!   `d = (sin φ sin θ, cos θ, -cos φ sin θ)`; conversely `u = atan2(d.x, -d.z) / 2π`
//!   (wrapped to `[0, 1)`) and `v = acos(d.y) / π`;
//! - texel column `i` of a `W`-wide image is centred on `u = (i + ½) / W` (a half-texel
//!   shift, wrapping from the last column to the first) and row `j` of an `H`-high image sits
//!   on `v = j / (H - 1)`: row 0 (the top of the file) is the +Y pole, the last row the -Y
//!   pole, so -Z (`φ = 0`, the image's left edge) is half a texel left of column 0;
//! - between those nodes radiance is bilinear in `(u, v)`.
//!
//! [`EnvMap::eval`] is the radiance carried along a ray that escapes the scene in direction
//! `d` (the environment seen looking along `d`), Mitsuba's `eval` for an escaped ray.

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

use glam::{DVec3, Mat3, Vec2, Vec3};
use math::Distribution2D;
use math::warp::sample_uniform_sphere;
use std::f64::consts::PI;

/// Rec. 709 luminance weights, those of Mitsuba 3's `luminance()`: the sampling weight.
const LUMINANCE: [f64; 3] = [0.212671, 0.715160, 0.072169];

/// How far `to_worldᵀ to_world` may stray from the identity before it is not a rotation.
const ORTHONORMAL_TOL: f32 = 1e-4;

/// An environment light: radiance at infinity by direction, importance sampled.
#[derive(Clone, Debug)]
pub struct EnvMap {
    source: Source,
    scale: f32,
    to_world: Mat3,
    /// The transpose of `to_world`, its inverse for a rotation.
    to_local: Mat3,
    /// `∫ L dω` over the sphere before `scale`, in `f64` sums.
    integral: [f64; 3],
}

#[derive(Clone, Debug)]
enum Source {
    Constant(Vec3),
    Image(Image),
}

#[derive(Clone, Debug)]
struct Image {
    width: usize,
    height: usize,
    /// Row-major, row 0 at the +Y pole.
    texels: Vec<Vec3>,
    /// Over the `width x (height - 1)` bilinear patches: patch `(i, j)` spans columns `i`,
    /// `i + 1` (wrapping) and rows `j`, `j + 1`, in the half-texel-shifted `u`.
    distribution: Distribution2D,
    /// `cos θ_j` of each row, `θ_j = π j / (height - 1)`.
    row_cos: Vec<f64>,
}

impl EnvMap {
    /// A lat-long map of linear RGB radiance, `texels[row * width + column]`, row 0 at the
    /// top (the +Y pole). `Err` is one line saying what is wrong. At least 2 x 3 texels, as
    /// Mitsuba 3 requires, so every map loaded here has a Mitsuba reference.
    pub fn from_image(
        width: usize,
        height: usize,
        texels: Vec<Vec3>,
        scale: f32,
        to_world: Mat3,
    ) -> Result<EnvMap, String> {
        if width < 2 || height < 3 {
            return Err(format!(
                "a {width}x{height} environment map is smaller than 2x3 texels"
            ));
        }
        if texels.len() != width * height {
            return Err(format!(
                "a {width}x{height} environment map needs {} texels, not {}",
                width * height,
                texels.len()
            ));
        }
        if let Some(i) = texels
            .iter()
            .position(|t| !t.is_finite() || t.min_element() < 0.0)
        {
            return Err(format!(
                "texel ({}, {}) of the environment map is {}: radiance must be finite and non-negative",
                i % width,
                i / width,
                texels.get(i).copied().unwrap_or_default()
            ));
        }
        if texels.iter().all(|t| *t == Vec3::ZERO) {
            return Err("the environment map is black everywhere".to_string());
        }
        let (to_world, to_local) = check_frame(scale, to_world)?;
        let row_cos: Vec<f64> = (0..height)
            .map(|j| (PI * j as f64 / (height - 1) as f64).cos())
            .collect();
        let (weights, integral) = patch_integrals(width, height, &texels);
        let distribution = Distribution2D::new(&weights, width, height - 1)
            .ok_or_else(|| "the environment map's luminance is 0 everywhere".to_string())?;
        Ok(EnvMap {
            source: Source::Image(Image {
                width,
                height,
                texels,
                distribution,
                row_cos,
            }),
            scale,
            to_world,
            to_local,
            integral,
        })
    }

    /// The same radiance from every direction (Mitsuba 3's `constant` emitter); sampled
    /// uniformly over the sphere. `to_world` is checked but changes nothing.
    pub fn constant(radiance: Vec3, scale: f32, to_world: Mat3) -> Result<EnvMap, String> {
        if !radiance.is_finite() || radiance.min_element() < 0.0 {
            return Err(format!(
                "the environment radiance {radiance} must be finite and non-negative"
            ));
        }
        if radiance == Vec3::ZERO {
            return Err("the environment radiance is black".to_string());
        }
        let (to_world, to_local) = check_frame(scale, to_world)?;
        let integral = radiance.to_array().map(|c| 4.0 * PI * c as f64);
        Ok(EnvMap {
            source: Source::Constant(radiance),
            scale,
            to_world,
            to_local,
            integral,
        })
    }

    pub fn scale(&self) -> f32 {
        self.scale
    }

    pub fn to_world(&self) -> Mat3 {
        self.to_world
    }

    /// Radiance carried along a ray escaping the scene in world direction `dir` (unit).
    #[inline]
    pub fn eval(&self, dir: Vec3) -> Vec3 {
        self.scale
            * match &self.source {
                Source::Constant(c) => *c,
                Source::Image(img) => img.lookup(self.to_local * dir),
            }
    }

    /// A world direction drawn with density proportional to luminance over solid angle,
    /// piecewise constant over the bilinear patches between texels (pbrt-v4 §12.5.2), its
    /// radiance ([`EnvMap::eval`]) and its solid-angle density ([`EnvMap::pdf`]).
    ///
    /// Each patch weighs `∫ luminance dω` over it, the `sin θ` of `dω` integrated exactly
    /// rather than taken at the patch centre, and within a patch `cos θ` (not `θ`) is uniform:
    /// so the density is constant over every patch, and exactly `1/(4π)` for a uniform map
    /// (pbrt-v3's lat-long light and Mitsuba 3's `envmap` take `sin θ` at a point and so keep
    /// a `1/sin θ` factor in the density). Mitsuba's warp is bilinear (`Hierarchical2D`), this
    /// one piecewise constant: the densities differ, the estimates converge to the same image.
    #[inline]
    pub fn sample(&self, u: [f32; 2]) -> (Vec3, Vec3, f32) {
        match &self.source {
            Source::Constant(c) => {
                let d = self.to_world * sample_uniform_sphere(u);
                (d, *c * self.scale, UNIFORM_SPHERE_PDF)
            }
            Source::Image(img) => {
                let (p, pdf_square) = img.distribution.sample(u);
                let rows = img.height - 1;
                let j = cell_of(p.y, rows);
                let t = (p.y as f64 * rows as f64 - j as f64).clamp(0.0, 1.0);
                let (z0, z1) = (img.cos_row(j), img.cos_row(j + 1));
                let z = z0 + t * (z1 - z0);
                let phi = std::f64::consts::TAU * (p.x as f64 + 0.5 / img.width as f64);
                let r = (1.0 - z * z).max(0.0).sqrt();
                let local = Vec3::new((phi.sin() * r) as f32, z as f32, (-phi.cos() * r) as f32);
                let pdf = pdf_square * img.solid_angle_factor(j);
                (self.to_world * local, img.lookup(local) * self.scale, pdf)
            }
        }
    }

    /// Solid-angle density with which [`EnvMap::sample`] draws world direction `dir` (unit).
    #[inline]
    pub fn pdf(&self, dir: Vec3) -> f32 {
        match &self.source {
            Source::Constant(_) => UNIFORM_SPHERE_PDF,
            Source::Image(img) => {
                let local = self.to_local * dir;
                let (u, v) = img.patch_uv(local);
                let j = cell_of(v, img.height - 1);
                let centre = Vec2::new(u, (j as f32 + 0.5) / (img.height - 1) as f32);
                img.distribution.pdf(centre) * img.solid_angle_factor(j)
            }
        }
    }

    /// `∫ L dω` over the sphere, `scale` included, per channel in f64.
    pub fn radiance_integral(&self) -> glam::DVec3 {
        glam::DVec3::from_array(self.integral) * self.scale as f64
    }

    /// Power entering a sphere of radius `scene_radius` around the scene:
    /// `Φ = π r² ∫ L(ω) dω` (pbrt-v4 §12.5.2, `ImageInfiniteLight::Phi`): from each
    /// direction, radiance crosses the sphere's projected disk of area `π r²`. The integral is
    /// of the bilinear lookup itself, in closed form per patch, not a sum of texels.
    pub fn power(&self, scene_radius: f32) -> Vec3 {
        let k = PI * (scene_radius as f64).powi(2) * self.scale as f64;
        Vec3::from_array(self.integral.map(|c| (k * c) as f32))
    }
}

const UNIFORM_SPHERE_PDF: f32 = 0.25 * std::f32::consts::FRAC_1_PI;

/// The cell of `x` in `[0, 1]` among `n`, as [`Distribution2D`] finds it.
#[inline]
fn cell_of(x: f32, n: usize) -> usize {
    ((x.max(0.0) as f64 * n as f64) as usize).min(n - 1)
}

fn check_frame(scale: f32, to_world: Mat3) -> Result<(Mat3, Mat3), String> {
    if !scale.is_finite() || scale <= 0.0 {
        return Err(format!(
            "the environment scale {scale} must be positive and finite"
        ));
    }
    let off = (to_world.transpose() * to_world - Mat3::IDENTITY)
        .to_cols_array()
        .iter()
        .fold(0.0f32, |m, e| m.max(e.abs()));
    if !to_world.is_finite() || off > ORTHONORMAL_TOL {
        return Err("the environment's to_world is not a rotation (orthonormal)".to_string());
    }
    Ok((to_world, to_world.transpose()))
}

/// Per patch, `∫ luminance dω`, the sampling weights; and `∫ L dω` over the sphere per
/// channel. The lookup is linear in `φ` and in `θ` across a patch, so with
/// `s = (θ - θ_j) / Δθ` the `θ` integral needs `∫ sin θ dθ = cos θ_j - cos θ_{j+1}` and
/// `∫ s sin θ dθ = (sin θ_{j+1} - sin θ_j) / Δθ - cos θ_{j+1}` (by parts).
fn patch_integrals(width: usize, height: usize, texels: &[Vec3]) -> (Vec<f64>, [f64; 3]) {
    let dphi = 2.0 * PI / width as f64;
    let dtheta = PI / (height - 1) as f64;
    let mut weights = Vec::with_capacity(width * (height - 1));
    let mut integral = DVec3::ZERO;
    let texel = |i: usize, j: usize| -> DVec3 {
        texels
            .get(j * width + i % width)
            .map_or(DVec3::ZERO, |t| t.as_dvec3())
    };
    for j in 0..height - 1 {
        let (t0, t1) = (j as f64 * dtheta, (j + 1) as f64 * dtheta);
        let whole = t0.cos() - t1.cos();
        let lower = (t1.sin() - t0.sin()) / dtheta - t1.cos();
        let upper = whole - lower;
        for i in 0..width {
            let (a, b, c, d) = (
                texel(i, j),
                texel(i + 1, j),
                texel(i, j + 1),
                texel(i + 1, j + 1),
            );
            let patch = 0.5 * dphi * ((a + b) * upper + (c + d) * lower);
            integral += patch;
            // Summed in channel order from zero, as the scalar loop it replaces did.
            let [l0, l1, l2] = LUMINANCE;
            let lum = 0.0 + l0 * patch.x + l1 * patch.y + l2 * patch.z;
            weights.push(lum.max(0.0));
        }
    }
    (weights, integral.to_array())
}

impl Image {
    /// `cos θ` of node row `j` (0 past the last: no caller reaches it).
    #[inline]
    fn cos_row(&self, j: usize) -> f64 {
        self.row_cos.get(j).copied().unwrap_or(0.0)
    }

    /// `(u, v)` of a local direction in the patch grid: `u` shifted by half a texel.
    #[inline]
    fn patch_uv(&self, d: Vec3) -> (f32, f32) {
        let mut u = d.x.atan2(-d.z) * (0.5 * std::f32::consts::FRAC_1_PI) - 0.5 / self.width as f32;
        u -= u.floor();
        let v = d.y.clamp(-1.0, 1.0).acos() * std::f32::consts::FRAC_1_PI;
        (u, v)
    }

    /// Bilinear lookup of local direction `d`, as Mitsuba's `envmap` interpolates.
    #[inline]
    fn lookup(&self, d: Vec3) -> Vec3 {
        let (u, v) = self.patch_uv(d);
        let x = u * self.width as f32;
        let y = v * (self.height - 1) as f32;
        let (i, j) = (
            (x as usize).min(self.width - 1),
            (y as usize).min(self.height - 2),
        );
        let (fx, fy) = (x - i as f32, y - j as f32);
        let i1 = (i + 1) % self.width;
        let at = |i: usize, j: usize| {
            self.texels
                .get(j * self.width + i)
                .copied()
                .unwrap_or(Vec3::ZERO)
        };
        let top = at(i, j) * (1.0 - fx) + at(i1, j) * fx;
        let bottom = at(i, j + 1) * (1.0 - fx) + at(i1, j + 1) * fx;
        top * (1.0 - fy) + bottom * fy
    }

    /// From density over the patch square to density over solid angle in row `j`: the
    /// square's area `1/(W (H-1))` per patch covers `(2π/W) (cos θ_j - cos θ_{j+1})`.
    #[inline]
    fn solid_angle_factor(&self, j: usize) -> f32 {
        let dz = self.cos_row(j) - self.cos_row(j + 1);
        (1.0 / (2.0 * PI * (self.height - 1) as f64 * dz)) as f32
    }
}
