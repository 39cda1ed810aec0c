//! A glass ball on a floor under a point light (`scenes/point-caustic/glass-sphere.toml`)
//! against Mitsuba's light tracer; the path tracer, which finds no caustic, must fail.

use super::{
    DIRECT_GROUPS, Measured, RES, RegionRef, Toward, light_run, light_scene_regions, misfits,
    misfits_of_runs,
};
use crate::kit::*;
use render::Overrides;
use scene::{Method, Scene, SceneFile};

/// `scenes/point-caustic/glass-sphere.toml`: a glass ball on a floor under a point light.
fn point_caustic(seed: u64, edit: impl FnOnce(&mut SceneFile)) -> Scene {
    scene_at("point-caustic/glass-sphere.toml", RES, seed, edit)
}

fn point_caustic_regions(scene: &Scene) -> Vec<RegionRef> {
    let l = glam::Vec3::new(-4.0, 3.5, -1.0);
    light_scene_regions(
        scene,
        "point-caustic",
        Toward::Point(l),
        &DIRECT_GROUPS[..4],
    )
}

/// The point light's tables, `m / ref - 1` in percent, mean ± one run's standard deviation
/// over seeds 1-6, regions in [`point_caustic_regions`]' order (diffuse seen, lit, glass
/// shadow, caustic core):
///
/// | run | diffuse seen | lit | glass shadow | core |
/// |---|---|---|---|---|
/// | path, 256 spp | -9.12 ± 0.01 | -0.73 ± 0.01 | -84.28 ± 0.04 | -98.90 ± 0.01 |
/// | path+splat, 256 spp | -0.19 ± 0.58 | +0.04 ± 0.06 | -2.23 ± 5.47 | -3.79 ± 7.38 |
/// | sppm, 16 passes | +0.16 ± 0.29 | +0.04 ± 0.07 | +1.19 ± 2.80 | +1.54 ± 4.37 |
///
/// No bias is resolved. The path tracer's row is the negative control: it cannot find light
/// from a point light through the sphere (its caustic layers are zero), so it misses the
/// glass's shadow and, through the light the caustic passes on, everything else.
const POINT_PATH_SPLAT_256: Measured<4> = Measured {
    bias: [0.0; 4],
    sd: [0.0058, 0.0006, 0.0547, 0.0738],
};

const POINT_SPPM_16: Measured<4> = Measured {
    bias: [0.0; 4],
    sd: [0.0029, 0.0007, 0.0280, 0.0437],
};

/// The path tracer's control table for the point light: no bias allowed, its sd.
const POINT_PATH_256: Measured<4> = Measured {
    bias: [0.0; 4],
    sd: [0.0001, 0.0001, 0.0004, 0.0001],
};

/// A glass ball under a point light against Mitsuba's light tracer (`ptracer`): path+splat
/// and SPPM match in every region, the caustic in the ball's shadow included. The path
/// tracer finds no caustic at all (its caustic layers are exactly zero: no ray hits a point
/// light and glass blocks every shadow ray), so it fails the shadow by -84%.
#[test]
fn a_point_light_caustic_matches_mitsubas_light_tracer() {
    let s = point_caustic(1, |_| {});
    let regs = point_caustic_regions(&s);
    let runs = [
        (Method::PathSplat, 256, &POINT_PATH_SPLAT_256),
        (Method::Sppm, 16, &POINT_SPPM_16),
    ];
    let bad = misfits_of_runs(&s, &regs, &runs);
    assert!(bad.is_empty(), "{bad:#?}");
    let o = Overrides {
        method: Some(Method::Path),
        spp: Some(64),
        ..Overrides::default()
    };
    let path = render_uncached(&s, &o, None);
    let caustic = sum_layers(&path, |n| n.starts_with("caustic"));
    assert!(
        caustic.data.iter().all(|p| *p == [0.0; 3]),
        "the path tracer found a point light's caustic"
    );
    eprintln!("path, 64:");
    let bad = misfits(&sum_layers(&path, |_| true), &regs, &POINT_PATH_256);
    assert!(
        bad.iter().any(|m| m.starts_with("glass shadow:")),
        "the caustic is not resolved: {bad:#?}"
    );
}

/// Light tracing, 4 passes of 250,000 paths: `m / ref - 1` in percent, mean ± one run's
/// standard deviation over seeds 1-6, regions as above:
///
/// | run | diffuse seen | lit | glass shadow | core |
/// |---|---|---|---|---|
/// | light, 4 x 250k | +0.00 ± 0.42 | -0.03 ± 0.42 | +0.22 ± 0.74 | -0.23 ± 1.12 |
///
/// No bias is resolved (|z| < 0.8 over the six seeds): both renderers trace light paths to
/// the camera, and the core is as sharp in both. (SPPM's and path+splat's sd above is
/// 4-7 times larger at the core.)
const POINT_LIGHT_4: Measured<4> = Measured {
    bias: [0.0; 4],
    sd: [0.0042, 0.0042, 0.0074, 0.0112],
};

/// The glass ball under a point light by light tracing against Mitsuba's light tracer: every
/// region matches, the caustic's core and its shadow included (no density estimate blurs
/// them). Its caustic layers carry the shadow's light: without them it fails by -84%, as the
/// path tracer does.
#[test]
fn light_tracing_matches_mitsubas_light_tracer_at_the_caustic() {
    let s = point_caustic(1, |_| {});
    let regs = point_caustic_regions(&s);
    eprintln!("light, 4 x 250k:");
    let r = light_run(&s, 4, 250_000);
    let bad = misfits(&sum_layers(&r, |_| true), &regs, &POINT_LIGHT_4);
    assert!(bad.is_empty(), "{bad:#?}");
    let without = sum_layers(&r, |n| !n.starts_with("caustic"));
    let bad = misfits(&without, &regs, &POINT_LIGHT_4);
    assert!(
        bad.iter().any(|m| m.starts_with("caustic core:")),
        "the caustic layers carry no caustic: {bad:#?}"
    );
}

/// Vertex connection and merging, 16 passes, over seeds 1-6, regions as above:
///
/// | run | diffuse seen | lit | glass shadow | core |
/// |---|---|---|---|---|
/// | vcm, 16 | -0.03 ± 0.25 | -0.02 ± 0.15 | -0.17 ± 1.62 | +0.18 ± 2.04 |
///
/// No bias is resolved (|z| < 0.3).
const POINT_VCM_16: Measured<4> = Measured {
    bias: [0.0; 4],
    sd: [0.0025, 0.0015, 0.0162, 0.0204],
};

/// The glass ball under a point light by vertex connection and merging against Mitsuba's
/// light tracer: every region matches, the core included (light tracing carries the sharp
/// focus seen directly, its MIS weight there far above merging's).
#[test]
fn vcm_matches_mitsubas_light_tracer_at_the_caustic() {
    let s = point_caustic(super::table_seed(), |_| {});
    let regs = point_caustic_regions(&s);
    eprintln!("vcm, 16:");
    let bad = misfits(&super::image_by(&s, Method::Vcm, 16), &regs, &POINT_VCM_16);
    assert!(bad.is_empty(), "{bad:#?}");
}
