//! The report's pictures: the crops it shows, and each rung's first image, bias² and
//! variance maps written under `maps/`.

use crate::evidence::{RungResult, slug};
use film::{Image, Mask, ToneMap};
use scene::Scene;
use std::path::Path;

/// A crop of the image: its name and pixel rectangle `(x0, y0, x1, y1)`, half open.
pub(super) type Crop = (&'static str, (usize, usize, usize, usize));

pub(super) fn png(path: &Path, img: &Image, tone: &ToneMap) -> Result<(), String> {
    film::write_png(path, img, tone).map_err(|e| e.to_string())
}

/// `img` cut to `[x0, x1) x [y0, y1)` and enlarged `zoom` times (nearest pixel: the noise
/// stays visible as noise).
pub(super) fn crop(
    img: &Image,
    (x0, y0, x1, y1): (usize, usize, usize, usize),
    zoom: usize,
) -> Image {
    Image::from_fn((x1 - x0) * zoom, (y1 - y0) * zoom, |x, y| {
        img.get(x0 + x / zoom, y0 + y / zoom)
    })
}

/// The crops the report shows: the caustic under the glass sphere and two corners of the box,
/// from the scene's geometry (squares around the caustic region and around the pixels seeing
/// the box's back corners).
pub(super) fn crops(scene: &Scene, regions: &[(&'static str, Mask)]) -> Vec<Crop> {
    let (w, h) = (scene.camera.width as usize, scene.camera.height as usize);
    let side = (w.min(h) / 5).max(4);
    let square = |cx: usize, cy: usize| {
        let x0 = cx.saturating_sub(side / 2).min(w - side.min(w));
        let y0 = cy.saturating_sub(side / 2).min(h - side.min(h));
        (x0, y0, x0 + side.min(w), y0 + side.min(h))
    };
    let mut out = Vec::new();
    if let Some((_, m)) = regions.iter().find(|(n, _)| *n == "caustic")
        && m.count() > 0
    {
        let (mut sx, mut sy, mut n) = (0usize, 0usize, 0usize);
        for (i, &p) in m.pixels.iter().enumerate() {
            if p {
                sx += i % w;
                sy += i / w;
                n += 1;
            }
        }
        out.push(("caustic", square(sx / n, sy / n)));
    }
    // The pixel whose visible point is nearest each back corner (floor and ceiling, left).
    let b = scene.geometry.bounds();
    let back = if (scene.camera.eye.z - b.min.z).abs() > (scene.camera.eye.z - b.max.z).abs() {
        b.min.z
    } else {
        b.max.z
    };
    for (name, corner) in [
        ("floor corner", glam::Vec3::new(b.min.x, b.min.y, back)),
        ("ceiling corner", glam::Vec3::new(b.min.x, b.max.y, back)),
    ] {
        let mut best = (f32::INFINITY, 0, 0);
        for y in 0..h {
            for x in 0..w {
                if let Some(hit) = scene
                    .geometry
                    .intersect(&scene.camera.ray(x as f32 + 0.5, y as f32 + 0.5))
                {
                    let d = (hit.point.p - corner).length();
                    if d < best.0 {
                        best = (d, x, y);
                    }
                }
            }
        }
        if best.0.is_finite() {
            out.push((name, square(best.1, best.2)));
        }
    }
    out
}

/// A rung's files under `maps/<name>/`: bias² and variance (EXR if `exr`, and false colour
/// on a square-root scale up to the 99th percentile of their sum), the mean (EXR if `exr`),
/// the first run's image and its crops (PNG).
pub(super) fn rung_files(
    out: &Path,
    r: &RungResult,
    tone: &ToneMap,
    crops: &[Crop],
    name: &str,
    exr: bool,
) -> Result<(), String> {
    let dir = out.join("maps").join(name);
    std::fs::create_dir_all(&dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    let mut both: Vec<f64> = r
        .maps
        .bias2
        .iter()
        .zip(&r.maps.variance)
        .map(|(b, v)| b + v)
        .collect();
    both.sort_by(f64::total_cmp);
    let top = both.get(both.len() * 99 / 100).copied().unwrap_or(1.0);
    let linear = ToneMap {
        gamma: 1.0,
        exposure: 0.0,
    };
    for (name, map) in [("bias2", &r.maps.bias2), ("variance", &r.maps.variance)] {
        if exr {
            film::write_exr(dir.join(format!("{name}.exr")), &r.maps.image(map))
                .map_err(|e| e.to_string())?;
        }
        png(
            &dir.join(format!("{name}.png")),
            &r.maps.false_colour(map, top),
            &linear,
        )?;
    }
    if exr {
        film::write_exr(dir.join("mean.exr"), &r.maps.mean).map_err(|e| e.to_string())?;
    }
    png(&dir.join("image.png"), &r.first, tone)?;
    for (name, rect) in crops {
        png(
            &dir.join(format!("{}.png", slug(name))),
            &crop(&r.first, *rect, 2),
            tone,
        )?;
    }
    Ok(())
}
