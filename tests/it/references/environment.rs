//! A floor, a glass and a clay sphere lit by a rotated sky map alone
//! (`scenes/environment/env-only.toml`) against Mitsuba; the map turned must fail.

use super::{
    Measured, RES, RegionRef, Toward, image_by, light_run, light_scene_regions, misfits,
    misfits_of_runs,
};
use crate::kit::scene_at;
use scene::{Method, Scene, SceneFile};

/// `scenes/environment/env-only.toml`: a floor, a glass and a clay sphere under a sky map.
fn environment(seed: u64, edit: impl FnOnce(&mut SceneFile)) -> Scene {
    scene_at("environment/env-only.toml", RES, seed, edit)
}

/// The sky map's sun: 45 degrees up at the map's `u = 0.25` (local `(cos 45°, sin 45°, 0)`
/// in Mitsuba's `envmap` frame), turned by the scene's `rotate = [-10, 60, 0]`.
fn sun_direction() -> glam::Vec3 {
    let local = glam::Vec3::new(1.0, 1.0, 0.0).normalize();
    glam::Mat3::from_rotation_y(60f32.to_radians())
        * glam::Mat3::from_rotation_x((-10f32).to_radians())
        * local
}

fn environment_regions(scene: &Scene) -> Vec<RegionRef> {
    let groups: [(&str, &[&str]); 7] = [
        ("image", &[]),
        ("background", &["background"]),
        ("floor", &["lit"]),
        ("glass shadow", &["shadow", "core"]),
        ("caustic core", &["core"]),
        ("glass", &["glass"]),
        ("clay", &["clay"]),
    ];
    light_scene_regions(
        scene,
        "environment",
        Toward::Direction(sun_direction()),
        &groups,
    )
}

/// The environment's tables, `m / ref - 1` in percent, mean ± one run's standard deviation
/// over seeds 1-6, regions in [`environment_regions`]' order (image, background, floor,
/// glass shadow, caustic core, glass, clay):
///
/// | run | image | background | floor | glass shadow | core | glass | clay |
/// |---|---|---|---|---|---|---|---|
/// | path, 256 spp | -0.00 ± 0.06 | +0.00 ± 0.00 | -0.01 ± 0.02 | +0.05 ± 0.50 | +0.33 ± 0.92 | +0.04 ± 0.29 | -0.07 ± 0.16 |
/// | path+splat, 256 spp | +0.03 ± 0.18 | +0.00 ± 0.00 | +0.05 ± 0.21 | +0.92 ± 1.35 | +1.07 ± 3.07 | -0.17 ± 0.23 | -0.44 ± 0.79 |
/// | sppm, 16 passes | +0.00 ± 0.19 | +0.00 ± 0.00 | -0.01 ± 0.20 | +0.04 ± 0.43 | -0.14 ± 0.83 | +0.21 ± 0.67 | +0.02 ± 0.58 |
///
/// No bias is resolved.
const ENV_PATH_256: Measured<7> = Measured {
    bias: [0.0; 7],
    sd: [0.0006, 0.0001, 0.0002, 0.0050, 0.0092, 0.0029, 0.0016],
};

const ENV_PATH_SPLAT_256: Measured<7> = Measured {
    bias: [0.0; 7],
    sd: [0.0018, 0.0001, 0.0021, 0.0135, 0.0307, 0.0023, 0.0079],
};

const ENV_SPPM_16: Measured<7> = Measured {
    bias: [0.0; 7],
    sd: [0.0019, 0.0001, 0.0020, 0.0043, 0.0083, 0.0067, 0.0058],
};

/// A floor, a glass and a clay sphere lit by a rotated sky map alone against Mitsuba's path
/// tracer: the path tracer, path+splat and SPPM match in every region, the background seen
/// directly, the sun's caustic and the glass included. The map turned the other way about y
/// (the sun moved) fails on the floor (+8.7%) and the caustic's core (-71%).
#[test]
fn an_environment_lit_scene_matches_mitsuba() {
    let s = environment(1, |_| {});
    let regs = environment_regions(&s);
    let runs = [
        (Method::Path, 256, &ENV_PATH_256),
        (Method::PathSplat, 256, &ENV_PATH_SPLAT_256),
        (Method::Sppm, 16, &ENV_SPPM_16),
    ];
    let bad = misfits_of_runs(&s, &regs, &runs);
    assert!(bad.is_empty(), "{bad:#?}");
    let turned = environment(1, |f| {
        for l in &mut f.lights {
            if let scene::LightDesc::Environment { rotate, .. } = l {
                rotate[1] = -rotate[1];
            }
        }
    });
    eprintln!("path, 64, the map turned by -60 degrees about y:");
    let bad = misfits(&image_by(&turned, Method::Path, 64), &regs, &ENV_PATH_256);
    assert!(
        bad.iter().any(|m| m.starts_with("floor:"))
            && bad.iter().any(|m| m.starts_with("caustic core:")),
        "the map's orientation is not resolved: {bad:#?}"
    );
}

/// Light tracing, 4 passes of 250,000 paths from the sky map (photons from a disc covering
/// the scene, importance-sampled by luminance), over seeds 1-6, on the diffuse regions it
/// draws (the glass and the sky seen directly it cannot):
///
/// | run | floor | glass shadow | core | clay |
/// |---|---|---|---|---|
/// | light, 4 x 250k | -0.05 ± 0.47 | +0.98 ± 1.54 | +1.17 ± 2.64 | +0.27 ± 2.22 |
///
/// No bias is resolved (|z| < 1.6).
const ENV_LIGHT_4: Measured<4> = Measured {
    bias: [0.0; 4],
    sd: [0.0047, 0.0154, 0.0264, 0.0222],
};

/// The sky-lit floor and spheres by light tracing against Mitsuba's path tracer, over the
/// diffuse regions: a light at infinity's photons reach the camera as a point light's do.
#[test]
fn light_tracing_matches_mitsuba_under_the_sky() {
    let s = environment(1, |_| {});
    let regs: Vec<RegionRef> = environment_regions(&s)
        .into_iter()
        .filter(|r| ["floor", "glass shadow", "caustic core", "clay"].contains(&r.name))
        .collect();
    eprintln!("light, 4 x 250k:");
    let img = crate::kit::sum_layers(&light_run(&s, 4, 250_000), |_| true);
    let bad = misfits(&img, &regs, &ENV_LIGHT_4);
    assert!(bad.is_empty(), "{bad:#?}");
}

/// Vertex connection and merging, 16 passes, over seeds 1-6, every region (`m / ref - 1` in
/// percent, mean ± one run's standard deviation):
///
/// | image | background | floor | glass shadow | core | glass | clay |
/// |---|---|---|---|---|---|---|
/// | +0.10 ± 0.27 | +0.00 ± 0.00 | +0.11 ± 0.24 | +0.12 ± 1.65 | -0.55 ± 3.34 | +0.42 ± 1.81 | +0.07 ± 0.23 |
///
/// No bias is resolved (|z| < 1.3). The background's sd is below 0.005%: it is the map
/// itself, seen by the camera (weight 1).
const ENV_VCM_16: Measured<7> = Measured {
    bias: [0.0; 7],
    sd: [0.0027, 0.0001, 0.0024, 0.0165, 0.0334, 0.0181, 0.0023],
};

/// The sky-lit scene by vertex connection and merging against Mitsuba's path tracer: every
/// region, the sky and the glass seen directly and the sun's caustic included (a light at
/// infinity's emission and NEE densities weigh its paths).
#[test]
fn vcm_matches_mitsuba_under_the_sky() {
    let s = environment(super::table_seed(), |_| {});
    let regs = environment_regions(&s);
    eprintln!("vcm, 16:");
    let bad = misfits(&image_by(&s, Method::Vcm, 16), &regs, &ENV_VCM_16);
    assert!(bad.is_empty(), "{bad:#?}");
}
