//! Morgan McGuire's CornellBox-Original (`scenes/mcguire/`), its OBJ and MTL as published,
//! against Mitsuba surface by surface; a 2% brighter light must fail.

use super::{Measured, RES, RegionRef, image_by, misfits, misfits_of_runs, region_refs};
use crate::kit::{PIXEL_POINTS, scene_at};
use scene::{MaterialDesc, Method, Scene, SceneFile};

/// `scenes/mcguire/original.toml` at 128 x 128.
fn mcguire_original(seed: u64, edit: impl FnOnce(&mut SceneFile)) -> Scene {
    scene_at("mcguire/original.toml", RES, seed, edit)
}

/// The McGuire box's regions: the whole image, then the pixels all of whose
/// [`PIXEL_POINTS`] see one MTL material. The light quad seen directly (80 pixels at 128 x
/// 128, its `Ke` plus 0.8% reflected) is left out: both methods read it within 0.01% of
/// Mitsuba's, with too little noise over the seeds for a table to bound.
const MCGUIRE_GROUPS: [(&str, &str); 8] = [
    ("image", ""),
    ("floor", "floor"),
    ("ceiling", "ceiling"),
    ("back wall", "backWall"),
    ("left wall", "leftWall"),
    ("right wall", "rightWall"),
    ("short box", "shortBox"),
    ("tall box", "tallBox"),
];

fn mcguire_regions(scene: &Scene) -> Vec<RegionRef> {
    let (w, h) = (RES as usize, RES as usize);
    let material = |x: f32, y: f32| -> Option<&str> {
        let hit = scene.geometry.intersect(&scene.camera.ray(x, y))?;
        Some(scene.material_names[hit.material as usize].as_str())
    };
    let labels: Vec<[Option<&str>; 5]> = (0..w * h)
        .map(|i| {
            let (x, y) = ((i % w) as f32, (i / w) as f32);
            PIXEL_POINTS.map(|(u, v)| material(x + u, y + v))
        })
        .collect();
    let masks = MCGUIRE_GROUPS
        .iter()
        .map(|&(name, mtl)| {
            let pixels = labels
                .iter()
                .map(|l| mtl.is_empty() || l.iter().all(|m| *m == Some(mtl)))
                .collect();
            (
                name,
                film::Mask {
                    width: w,
                    height: h,
                    pixels,
                },
            )
        })
        .collect();
    region_refs("mcguire-original", masks)
}

/// The McGuire box's tables, `m / ref - 1` in percent, mean ± one run's standard deviation
/// over seeds 1-6, regions in [`MCGUIRE_GROUPS`]' order (reference standard errors 0.010%,
/// 0.012%, 0.026%, 0.009%, 0.011%, 0.009%, 0.030%, 0.022%):
///
/// | run | image | floor | ceiling | back wall | left wall | right wall | short box | tall box |
/// |---|---|---|---|---|---|---|---|---|
/// | path, 256 spp | -0.01 ± 0.02 | +0.02 ± 0.07 | -0.01 ± 0.08 | -0.03 ± 0.04 | -0.03 ± 0.04 | +0.07 ± 0.05 | +0.14 ± 0.14 | -0.02 ± 0.17 |
/// | path, 64 spp | -0.01 ± 0.05 | -0.05 ± 0.16 | +0.03 ± 0.22 | +0.02 ± 0.08 | +0.04 ± 0.16 | +0.21 ± 0.17 | +0.01 ± 0.28 | +0.07 ± 0.29 |
/// | sppm, 16 passes | +0.02 ± 0.31 | +0.03 ± 0.15 | -0.13 ± 0.14 | +0.00 ± 0.16 | +0.04 ± 0.05 | +0.04 ± 0.13 | +0.23 ± 0.13 | +0.24 ± 0.32 |
///
/// Two offsets lie more than 3 standard errors of their mean from zero: the path tracer's
/// right wall, +0.07% (3.4), and SPPM's short box, +0.23% (4.3; SPPM's radii reach from the
/// small box's faces onto the brighter floor and walls beside them, as at the worksheet's
/// edges and corners). SPPM's is allowed as its known bias; the path tracer is held to no
/// bias, and its offset passes only while it stays within the noise. SPPM's whole-image
/// noise (0.31%, more than any surface's) is the light's outline, which one eye sample per
/// pixel and pass hits or misses.
const MCGUIRE_PATH_256: Measured<8> = Measured {
    bias: [0.0; 8],
    sd: [
        0.0002, 0.0007, 0.0008, 0.0004, 0.0004, 0.0005, 0.0014, 0.0017,
    ],
};

/// The path tracer at 64 spp on the McGuire box (the table above; the negative control).
const MCGUIRE_PATH_64: Measured<8> = Measured {
    bias: [0.0; 8],
    sd: [
        0.0005, 0.0016, 0.0022, 0.0008, 0.0016, 0.0017, 0.0028, 0.0029,
    ],
};

/// SPPM at 16 passes on the McGuire box (the table above).
const MCGUIRE_SPPM_16: Measured<8> = Measured {
    bias: [0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0023, 0.0],
    sd: [
        0.0031, 0.0015, 0.0014, 0.0016, 0.0005, 0.0013, 0.0013, 0.0032,
    ],
};

/// McGuire's CornellBox-Original, its OBJ and MTL as published (emission from `Ke`), against
/// Mitsuba's path tracer: the path tracer and SPPM match in the whole image and on every
/// surface seen. The negative control: the light's `Ke` 2% brighter (a scene-file material
/// over the MTL's) fails the path tracer's comparison at 64 spp.
#[test]
fn mcguire_original_matches_mitsuba() {
    let s = mcguire_original(1, |_| {});
    let regs = mcguire_regions(&s);
    let runs = [
        (Method::Path, 256, &MCGUIRE_PATH_256),
        (Method::Sppm, 16, &MCGUIRE_SPPM_16),
    ];
    let bad = misfits_of_runs(&s, &regs, &runs);
    assert!(bad.is_empty(), "{bad:#?}");
    let brighter = mcguire_original(2, |f| {
        let light = MaterialDesc::Lambertian {
            albedo: [0.78; 3],
            emission: [17.0 * 1.02, 12.0 * 1.02, 4.0 * 1.02],
            texture: None,
        };
        f.materials.insert("light".into(), light);
    });
    eprintln!("path, 64, the light's Ke +2%:");
    let bad = misfits(
        &image_by(&brighter, Method::Path, 64),
        &regs,
        &MCGUIRE_PATH_64,
    );
    assert!(
        bad.iter().any(|m| m.starts_with("image:")),
        "a 2% brighter light passed: {bad:#?}"
    );
}
