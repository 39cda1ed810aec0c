//! Light tracing (`--method light`) where no reference renderer is needed: the worksheet's
//! area light seen directly comes out at its radiance, the one value the camera can see of
//! it, through the connection from the light's own point (`L E`).

use crate::kit::{layer, render_uncached, worksheet_with};
use glam::Vec3;
use render::Overrides;
use scene::{Light, Method};

/// Pixels whose every sample point sees the worksheet's light directly read its radiance
/// `Le` in the `emitted` layer: the light's photons land on its image uniformly, each
/// weighted by the camera's importance, so the mean over those pixels is `Le` up to the
/// count of paths there (800,000 paths over about 80 pixels of the light's image at
/// 128 x 128). Measured: mean over the 76 pixels 0.02% from `Le`, against a 1% bound; without
/// the pinhole's `cos θ_e` in the geometry term, or without the connection from the light's
/// own point, it fails (tried).
#[test]
fn the_area_light_seen_directly_is_its_radiance() {
    let s = worksheet_with(128, 1, |_| {});
    let le = match s.light_table.light(0) {
        Some(Light::Area(t)) => t.le,
        _ => panic!("the worksheet's light is a triangle"),
    };
    let o = Overrides {
        method: Some(Method::Light),
        passes: Some(4),
        photons: Some(200_000),
        ..Overrides::default()
    };
    let r = render_uncached(&s, &o, None);
    let emitted = layer(&r, "emitted");
    let w = s.camera.width as usize;
    let sees_light = |x: usize, y: usize| {
        [(0.1, 0.1), (0.9, 0.1), (0.5, 0.5), (0.1, 0.9), (0.9, 0.9)]
            .iter()
            .all(|(u, v)| {
                let ray = s.camera.ray(x as f32 + u, y as f32 + v);
                s.geometry
                    .intersect(&ray)
                    .and_then(|h| s.light_table.light_of(h.prim))
                    .is_some()
            })
    };
    let pixels: Vec<usize> = (0..w * w).filter(|&i| sees_light(i % w, i / w)).collect();
    assert!(pixels.len() >= 20, "{} pixels see the light", pixels.len());
    let mean = pixels
        .iter()
        .map(|&i| Vec3::from(emitted.data[i]).as_dvec3())
        .sum::<glam::DVec3>()
        / pixels.len() as f64;
    let rel = ((mean - le.as_dvec3()) / le.as_dvec3()).abs().max_element();
    eprintln!(
        "the light seen directly, {} pixels: mean {mean} against Le {le}: {rel:.4}",
        pixels.len()
    );
    assert!(rel < 0.01, "the light's image misses Le by {rel}");
}

/// A pass's light paths are one scrambled Sobol sequence (2-D strata per pair of
/// dimensions), not independent draws: the worksheet's direct light, whose noise comes from
/// where the first bounce lands, is several times smoother over areas of the image. Measured
/// at 32 x 32, one pass of 2^16 paths, 8 seeds: relative variance of 8 x 8-pixel block means
/// 0.00016 (independent paths, as before: 0.00054, tried); bound 0.0003.
#[test]
fn light_paths_of_a_pass_are_stratified() {
    let images: Vec<_> = (1..=8)
        .map(|seed| {
            let s = worksheet_with(32, seed, |_| {});
            let o = Overrides {
                method: Some(Method::Light),
                passes: Some(1),
                photons: Some(1 << 16),
                ..Overrides::default()
            };
            layer(&render_uncached(&s, &o, None), "direct").clone()
        })
        .collect();
    let v = crate::kit::relative_variance(&images, 8);
    eprintln!("light tracing's direct light: relative variance per block {v:.5}");
    assert!(v < 0.0003, "relative variance per block {v}");
}
