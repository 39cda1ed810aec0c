//! The worksheet box and spheres under a spot light (`scenes/cornell-spot/spot.toml`) against
//! Mitsuba's light tracer.

use super::{
    DIRECT_GROUPS, Measured, RES, RegionRef, Toward, light_run, light_scene_regions, misfits,
    misfits_of_runs,
};
use crate::kit::scene_at;
use scene::{Method, Scene, SceneFile};

/// `scenes/cornell-spot/spot.toml`: the worksheet box and spheres under a spot light.
fn cornell_spot(seed: u64, edit: impl FnOnce(&mut SceneFile)) -> Scene {
    scene_at("cornell-spot/spot.toml", RES, seed, edit)
}

fn cornell_spot_regions(scene: &Scene) -> Vec<RegionRef> {
    let l = glam::Vec3::new(-6.95, 13.5, -6.99);
    light_scene_regions(scene, "cornell-spot", Toward::Point(l), &DIRECT_GROUPS)
}

/// The spot light's tables, `m / ref - 1` in percent, mean ± one run's standard deviation
/// over seeds 1-6, regions in [`cornell_spot_regions`]' order (diffuse seen, lit, glass
/// shadow, caustic core, ceiling):
///
/// | run | diffuse seen | lit | glass shadow | core | ceiling |
/// |---|---|---|---|---|---|
/// | path, 256 spp | -12.33 ± 0.04 | -8.32 ± 0.05 | -71.17 ± 0.12 | -96.84 ± 0.05 | -22.77 ± 0.08 |
/// | path+splat, 256 spp | -0.16 ± 0.08 | -0.10 ± 0.07 | -0.78 ± 3.23 | -17.08 ± 3.67 | -0.21 ± 0.26 |
/// | sppm, 16 passes | +0.05 ± 0.07 | +0.04 ± 0.07 | +0.13 ± 0.60 | -6.83 ± 1.60 | -0.10 ± 0.14 |
///
/// Known biases, each more than 3 standard errors from 0: the caustic core (12 pixels of a
/// sharp focus) is blurred out of its pixels by path+splat's discs (-17%) and SPPM's radii
/// after 16 passes (-7%), and path+splat's fixed indirect discs take 0.1% off the box (as on
/// the worksheet). The path tracer's row shows what it misses: it cannot find light from a
/// spot light through the spheres (its caustic layers are zero), so it misses the glass's
/// shadow and, through the light those caustics and the silver sphere's reflections pass on,
/// everything else.
const SPOT_PATH_SPLAT_256: Measured<5> = Measured {
    bias: [-0.0016, -0.0010, 0.0, -0.1708, 0.0],
    sd: [0.0008, 0.0007, 0.0323, 0.0367, 0.0026],
};

const SPOT_SPPM_16: Measured<5> = Measured {
    bias: [0.0, 0.0, 0.0, -0.0683, 0.0],
    sd: [0.0007, 0.0007, 0.0060, 0.0160, 0.0014],
};

/// The worksheet box and spheres under a spot light instead of the area light, against
/// Mitsuba's light tracer: path+splat and SPPM match everywhere a diffuse surface is seen
/// directly, the glass ball's caustic and the ceiling it lights from below included.
#[test]
fn a_spot_lit_box_matches_mitsubas_light_tracer() {
    let s = cornell_spot(1, |_| {});
    let regs = cornell_spot_regions(&s);
    let runs = [
        (Method::PathSplat, 256, &SPOT_PATH_SPLAT_256),
        (Method::Sppm, 16, &SPOT_SPPM_16),
    ];
    let bad = misfits_of_runs(&s, &regs, &runs);
    assert!(bad.is_empty(), "{bad:#?}");
}

/// Light tracing, 4 passes of 250,000 paths, over seeds 1-6 as above:
///
/// | run | diffuse seen | lit | glass shadow | core | ceiling |
/// |---|---|---|---|---|---|
/// | light, 4 x 250k | -0.08 ± 0.12 | -0.08 ± 0.15 | +0.01 ± 0.37 | -0.09 ± 0.78 | -0.19 ± 0.20 |
///
/// No bias is resolved (|z| < 2.4): the 12-pixel focus that SPPM and path+splat blur by -7%
/// and -17% comes out whole.
const SPOT_LIGHT_4: Measured<5> = Measured {
    bias: [0.0; 5],
    sd: [0.0012, 0.0015, 0.0037, 0.0078, 0.0020],
};

/// The spot-lit box by light tracing against Mitsuba's light tracer: every region matches,
/// the sharp caustic core included.
#[test]
fn light_tracing_matches_mitsubas_light_tracer_in_the_spot_box() {
    let s = cornell_spot(1, |_| {});
    let regs = cornell_spot_regions(&s);
    eprintln!("light, 4 x 250k:");
    let img = crate::kit::sum_layers(&light_run(&s, 4, 250_000), |_| true);
    let bad = misfits(&img, &regs, &SPOT_LIGHT_4);
    assert!(bad.is_empty(), "{bad:#?}");
}

/// Vertex connection and merging, 16 passes, over seeds 1-6 as above:
///
/// | run | diffuse seen | lit | glass shadow | core | ceiling |
/// |---|---|---|---|---|---|
/// | vcm, 16 | +0.02 ± 0.18 | +0.05 ± 0.13 | +0.05 ± 1.19 | -1.43 ± 1.16 | -0.17 ± 0.43 |
///
/// The core's -1.4% is resolved (z -3.0): the share of the 12-pixel focus that merging
/// carries is blurred by its disc (a pixel's footprint), as SPPM's -7% and path+splat's -17%
/// are by theirs; light tracing carries the rest sharp.
const SPOT_VCM_16: Measured<5> = Measured {
    bias: [0.0, 0.0, 0.0, -0.0143, 0.0],
    sd: [0.0018, 0.0013, 0.0119, 0.0116, 0.0043],
};

/// The spot-lit box by vertex connection and merging against Mitsuba's light tracer: every
/// region matches, the 12-pixel focus included.
#[test]
fn vcm_matches_mitsubas_light_tracer_in_the_spot_box() {
    let s = cornell_spot(super::table_seed(), |_| {});
    let regs = cornell_spot_regions(&s);
    eprintln!("vcm, 16:");
    let bad = misfits(&super::image_by(&s, Method::Vcm, 16), &regs, &SPOT_VCM_16);
    assert!(bad.is_empty(), "{bad:#?}");
}
