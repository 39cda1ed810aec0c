//! Rough spheres: a GGX metal and GGX glass over the glossy floor against Mitsuba; the same
//! spheres smooth must fail.

use super::{Measured, RES, image_by, misfits, misfits_of_runs, region_refs};
use crate::kit::scene_at;
use scene::{MaterialDesc, Method, Scene, SceneFile};

/// `scenes/cornell-glossy/rough-spheres.toml`: the glossy-floor scene with a rough metal
/// sphere (alpha 0.2) and a rough glass sphere (alpha 0.1, index 1.5), Mitsuba's
/// `roughconductor` and `roughdielectric` in its references.
fn rough(seed: u64, edit: impl FnOnce(&mut SceneFile)) -> Scene {
    scene_at("cornell-glossy/rough-spheres.toml", RES, seed, edit)
}

/// The rough scene's tables, regions as [`super::glossy::glossy_regions`]' (the caustic now
/// under rough glass), seeds 1-6, percent, mean ± one run's standard deviation:
///
/// | run | image | caustic | edges, corners | outer rim | glass | open walls | core |
/// |---|---|---|---|---|---|---|---|
/// | path, 256 spp | +0.02 ± 0.07 | +0.36 ± 0.63 | -0.05 ± 0.32 | +0.06 ± 0.35 | +0.02 ± 0.73 | -0.01 ± 0.08 | +0.99 ± 2.35 |
/// | sppm, 16 passes | -0.04 ± 0.42 | -1.54 ± 2.24 | +1.44 ± 0.12 | +0.73 ± 3.21 | +1.00 ± 2.43 | -0.15 ± 0.26 | -0.84 ± 7.73 |
///
/// No caustic here is a photon map's or a splat's (light through rough glass has made a
/// glossy bounce): the path tracer and the global photons carry it, and `path+splat` is the
/// path tracer. SPPM's only resolved bias is its boundary correction's overshoot into the
/// corners (+1.4%). Final gathering (10^6 paths) matches too but its gather rays through
/// the rough spheres leave it 12% noisy per run in the caustic and the glass.
const ROUGH_PATH_256: Measured = Measured {
    bias: [0.0; 7],
    sd: [0.0007, 0.0063, 0.0032, 0.0035, 0.0073, 0.0008, 0.0235],
};

/// SPPM at 16 passes on the rough scene (the table above).
const ROUGH_SPPM_16: Measured = Measured {
    bias: [0.0, 0.0, 0.0144, 0.0, 0.0, 0.0, 0.0],
    sd: [0.0042, 0.0224, 0.0012, 0.0321, 0.0243, 0.0026, 0.0773],
};

/// Rough metal and rough glass (GGX) as Mitsuba renders them, by the path tracer and SPPM.
/// The same spheres smooth (a mirror metal, clear glass) fail: the rough lobes are resolved.
#[test]
fn rough_spheres_match_mitsuba() {
    let s = rough(1, |_| {});
    let core = ("caustic core", lab::regions::caustic_region(&s, 0.8));
    let masks = lab::regions::regions(&s).into_iter().chain([core]);
    let regs = region_refs("cornell-rough", masks.collect());
    let runs = [
        (Method::Path, 256, &ROUGH_PATH_256),
        (Method::Sppm, 16, &ROUGH_SPPM_16),
    ];
    let bad = misfits_of_runs(&s, &regs, &runs);
    assert!(bad.is_empty(), "{bad:#?}");
    let smooth = rough(1, |f| {
        f.materials.insert(
            "silver".into(),
            MaterialDesc::Metal {
                reflectance: [0.96, 0.98, 0.96],
            },
        );
        f.materials.insert(
            "glass".into(),
            MaterialDesc::Dielectric {
                ior: 1.5,
                transmittance: [1.0; 3],
                absorption: [0.0; 3],
            },
        );
    });
    eprintln!("path, 256, smooth spheres:");
    let bad = misfits(
        &image_by(&smooth, Method::Path, 256),
        &regs,
        &ROUGH_PATH_256,
    );
    assert!(
        bad.iter().any(|m| m.starts_with("caustic")),
        "the rough glass is not resolved: {bad:#?}"
    );
}

/// Vertex connection and merging, 16 passes, seeds 1-6, `m / ref - 1` in percent:
///
/// | image | caustic | edges, corners | outer rim | spheres | open walls | core |
/// |---|---|---|---|---|---|---|
/// | +0.00 ± 0.39 | +0.52 ± 0.65 | +0.51 ± 0.62 | -0.74 ± 0.40 | +0.41 ± 0.72 | +0.12 ± 0.19 | +2.05 ± 1.71 |
///
/// The outer rim's -0.7% is resolved (z -4.5): merging's disc off the open front, as on the
/// worksheet; no other (|z| < 3).
const ROUGH_VCM_16: Measured = Measured {
    bias: [0.0, 0.0, 0.0, -0.0074, 0.0, 0.0, 0.0],
    sd: [0.0039, 0.0065, 0.0062, 0.0040, 0.0072, 0.0019, 0.0171],
};

/// The rough spheres by vertex connection and merging against Mitsuba: connections and
/// merging weigh the GGX lobes' densities in both directions, and every region matches.
#[test]
fn vcm_matches_mitsuba_on_rough_spheres() {
    let s = rough(super::table_seed(), |_| {});
    let core = ("caustic core", lab::regions::caustic_region(&s, 0.8));
    let masks = lab::regions::regions(&s).into_iter().chain([core]);
    let regs = region_refs("cornell-rough", masks.collect());
    eprintln!("vcm, 16:");
    let bad = misfits(&image_by(&s, Method::Vcm, 16), &regs, &ROUGH_VCM_16);
    assert!(bad.is_empty(), "{bad:#?}");
}
