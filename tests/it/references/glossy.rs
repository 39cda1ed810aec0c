//! A glossy receiver: the worksheet scene with a glossy floor (MTL `illum 2`) against
//! Mitsuba; the floor without its GGX lobe must fail.

use super::{Measured, RES, RegionRef, image_by, misfits, misfits_of_runs, region_refs};
use crate::kit::scene_at;
use scene::{MaterialDesc, Method, Scene, SceneFile};

/// The glossy floor's references: `scenes/cornell-glossy/glossy-floor.toml`, the worksheet
/// scene whose floor is MTL `illum 2` (Lambertian `Kd` 0.5 plus a GGX lobe of `Ks` 0.4,
/// `Ns` 100), rendered by Mitsuba with the same mapping.
const GLOSSY_REF: &str = "cornell-glossy";

/// The glossy-floor scene at 128 x 128, `edit` applied.
fn glossy(seed: u64, edit: impl FnOnce(&mut SceneFile)) -> Scene {
    scene_at("cornell-glossy/glossy-floor.toml", RES, seed, edit)
}

/// The glossy scene's regions: those of the worksheet (the caustic now on the glossy floor),
/// and the caustic's core.
fn glossy_regions(scene: &Scene) -> Vec<RegionRef> {
    let core = ("caustic core", lab::regions::caustic_region(scene, 0.8));
    let masks = lab::regions::regions(scene).into_iter().chain([core]);
    region_refs(GLOSSY_REF, masks.collect())
}

/// The glossy floor's tables, regions in [`glossy_regions`]' order (image, caustic, edges and
/// corners, outer rim, glass sphere, open walls, caustic core), seeds 1-6, `m / ref - 1` in
/// percent, mean ± one run's standard deviation:
///
/// | run | image | caustic | edges, corners | outer rim | glass | open walls | core |
/// |---|---|---|---|---|---|---|---|
/// | path, 256 spp | +0.03 ± 0.12 | +0.14 ± 0.95 | -0.01 ± 0.75 | +0.25 ± 0.30 | -0.08 ± 0.69 | +0.02 ± 0.17 | -0.43 ± 2.02 |
/// | path+splat, 256 spp | +0.02 ± 0.09 | +1.41 ± 2.39 | -0.90 ± 0.40 | -0.24 ± 0.41 | +1.08 ± 0.87 | -0.05 ± 0.13 | +4.47 ± 7.18 |
/// | sppm, 16 passes | -0.02 ± 0.50 | -1.65 ± 1.82 | +1.43 ± 0.17 | +0.05 ± 3.19 | +1.02 ± 3.09 | -0.12 ± 0.29 | -1.24 ± 5.40 |
///
/// The known biases are the worksheet's: `path+splat`'s fixed indirect discs at the edges
/// (-0.9%) and a small excess in the glass sphere (+1.1% ± 0.35%; the worksheet's +0.58% ±
/// 0.28%), SPPM's boundary correction overshooting into the corners (+1.4%). On the glossy
/// floor the splatted caustic is noisier than on the worksheet's (2.4% per run against 1.0%):
/// an eye vertex takes the floor's diffuse lobe with probability 0.56 only (its GGX lobe is
/// followed as a path), so fewer vertices read the caustic, each with more weight.
const GLOSSY_PATH_256: Measured = Measured {
    bias: [0.0; 7],
    sd: [0.0012, 0.0095, 0.0075, 0.0030, 0.0069, 0.0017, 0.0202],
};

/// `path+splat` at 256 spp on the glossy floor (the table above).
const GLOSSY_PATH_SPLAT_256: Measured = Measured {
    bias: [0.0, 0.0, -0.0090, 0.0, 0.0108, 0.0, 0.0],
    sd: [0.0009, 0.0239, 0.0040, 0.0041, 0.0087, 0.0013, 0.0718],
};

/// SPPM at 16 passes on the glossy floor (the table above).
const GLOSSY_SPPM_16: Measured = Measured {
    bias: [0.0, 0.0, 0.0143, 0.0, 0.0, 0.0, 0.0],
    sd: [0.0050, 0.0182, 0.0017, 0.0319, 0.0309, 0.0029, 0.0540],
};

/// A glossy receiver under the glass sphere (MTL `illum 2`: Lambertian plus GGX): the path
/// tracer, the path tracer with splatted caustics and SPPM each match Mitsuba in every
/// region, the caustic on the glossy floor included. Drawn without its GGX lobe (what
/// photonflow did with `illum 2` before), the floor fails.
#[test]
fn a_glossy_receiver_matches_mitsuba() {
    let s = glossy(1, |_| {});
    let regs = glossy_regions(&s);
    let runs = [
        (Method::Path, 256, &GLOSSY_PATH_256),
        (Method::PathSplat, 256, &GLOSSY_PATH_SPLAT_256),
        (Method::Sppm, 16, &GLOSSY_SPPM_16),
    ];
    let bad = misfits_of_runs(&s, &regs, &runs);
    assert!(bad.is_empty(), "{bad:#?}");
    let lambertian = glossy(1, |f| {
        f.materials.insert(
            "floor".into(),
            MaterialDesc::Lambertian {
                albedo: [0.5; 3],
                emission: [0.0; 3],
                texture: None,
            },
        );
    });
    eprintln!("path, 256, the floor without its GGX lobe:");
    let bad = misfits(
        &image_by(&lambertian, Method::Path, 256),
        &regs,
        &GLOSSY_PATH_256,
    );
    assert!(!bad.is_empty(), "the floor's glossy lobe is not resolved");
}

/// Vertex connection and merging, 16 passes, over seeds 1-6 (`m / ref - 1` in percent):
///
/// | image | caustic | edges, corners | outer rim | glass | open walls | core |
/// |---|---|---|---|---|---|---|
/// | -0.11 ± 0.31 | -0.13 ± 0.45 | +0.47 ± 0.78 | -0.69 ± 0.58 | -0.73 ± 2.28 | -0.00 ± 0.17 | -0.19 ± 1.24 |
///
/// No bias is resolved (|z| < 3; the outer rim's -0.7%, z -2.9, is merging's disc running
/// off the open front, resolved on the worksheet).
const GLOSSY_VCM_16: Measured = Measured {
    bias: [0.0; 7],
    sd: [0.0031, 0.0045, 0.0078, 0.0058, 0.0228, 0.0017, 0.0124],
};

/// The glossy floor by vertex connection and merging against Mitsuba: every region, the
/// caustic on the glossy floor included (its GGX lobe weighs connections and merging there).
#[test]
fn vcm_matches_mitsuba_on_a_glossy_receiver() {
    let s = glossy(super::table_seed(), |_| {});
    let regs = glossy_regions(&s);
    eprintln!("vcm, 16:");
    let bad = misfits(&image_by(&s, Method::Vcm, 16), &regs, &GLOSSY_VCM_16);
    assert!(bad.is_empty(), "{bad:#?}");
}
