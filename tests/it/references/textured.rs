//! A textured receiver: the worksheet scene with a checker floor (MTL `map_Kd`) against
//! Mitsuba, tile colour by tile colour; the floor at the texture's mean colour must fail.

use super::{Measured, RES, RegionRef, image_by, misfits, misfits_of_runs, region_refs};
use crate::kit::{PIXEL_POINTS, scene_at};
use scene::{MaterialDesc, Method, Scene, SceneFile};

/// `scenes/cornell-textured/textured-floor.toml`: the worksheet scene whose floor is MTL
/// `map_Kd checker.png` (8-bit sRGB) at the OBJ's `vt`, Mitsuba's `bitmap` texture in its
/// references.
fn textured(seed: u64, edit: impl FnOnce(&mut SceneFile)) -> Scene {
    scene_at("cornell-textured/textured-floor.toml", RES, seed, edit)
}

/// The checker's three colours (its 8-bit sRGB texels): warm, cool and the red corner tile
/// (too few pixels for a region of its own: 8 at 128 x 128).
const CHECKER: [(&str, [u8; 3]); 3] = [
    ("warm tiles", [230, 200, 120]),
    ("cool tiles", [60, 110, 200]),
    ("red tiles", [200, 40, 40]),
];

/// The textured scene's regions: the worksheet's (the caustic now on the checker), the
/// caustic's core, and the floor's pixels whose every [`PIXEL_POINTS`] sees one tile colour
/// (told by the texture's value at the hit, nearest of [`CHECKER`]): a texture read at the
/// wrong place, flipped or not decoded from sRGB moves their means apart from Mitsuba's.
fn textured_regions(scene: &Scene) -> Vec<RegionRef> {
    let (w, h) = (RES as usize, RES as usize);
    let tile = |x: f32, y: f32| -> Option<usize> {
        let hit = scene.geometry.intersect(&scene.camera.ray(x, y))?;
        if scene.material_names[hit.material as usize] != "floor" {
            return None;
        }
        let a = scene.bsdf_at(&hit)?.diffuse_albedo()?;
        let d = |c: [u8; 3]| {
            (a - glam::Vec3::from(c.map(|v| scene::srgb_to_linear(v as f32 / 255.0)))).length()
        };
        (0..CHECKER.len()).min_by(|&i, &j| d(CHECKER[i].1).total_cmp(&d(CHECKER[j].1)))
    };
    let mut tiles: Vec<(&'static str, film::Mask)> = CHECKER
        .iter()
        .map(|(name, _)| {
            let mask = film::Mask {
                width: w,
                height: h,
                pixels: vec![false; w * h],
            };
            (*name, mask)
        })
        .collect();
    for y in 0..h {
        for x in 0..w {
            let seen: Vec<Option<usize>> = PIXEL_POINTS
                .iter()
                .map(|(u, v)| tile(x as f32 + u, y as f32 + v))
                .collect();
            if let Some(&Some(t)) = seen.first()
                && seen.iter().all(|s| *s == Some(t))
            {
                tiles[t].1.pixels[y * w + x] = true;
            }
        }
    }
    tiles.truncate(2);
    let core = ("caustic core", lab::regions::caustic_region(scene, 0.8));
    let masks = lab::regions::regions(scene)
        .into_iter()
        .chain([core])
        .chain(tiles);
    region_refs("cornell-textured", masks.collect())
}

/// The textured floor's tables, regions in [`textured_regions`]' order (image, caustic, edges
/// and corners, outer rim, glass sphere, open walls, caustic core, warm tiles, cool tiles),
/// `m / ref - 1` in percent, mean ± one run's standard deviation, seeds 1-6 (path: 1-12):
///
/// | run | image | caustic | edges, corners | outer rim | glass | open walls | core | warm | cool |
/// |---|---|---|---|---|---|---|---|---|---|
/// | path, 256 spp | +0.02 ± 0.06 | +0.43 ± 0.98 | +0.07 ± 0.64 | -0.16 ± 0.49 | +0.08 ± 0.53 | +0.00 ± 0.13 | +0.33 ± 1.89 | +0.11 ± 0.41 | +0.43 ± 0.40 |
/// | path+splat, 256 spp | -0.03 ± 0.05 | -1.07 ± 1.09 | -0.78 ± 0.35 | -0.61 ± 0.22 | +0.49 ± 0.85 | +0.01 ± 0.10 | -3.03 ± 2.63 | -0.46 ± 0.51 | -1.32 ± 0.90 |
/// | sppm, 16 passes | +0.07 ± 0.47 | -0.03 ± 1.15 | +1.27 ± 0.14 | +0.35 ± 0.54 | +1.20 ± 3.49 | -0.04 ± 0.11 | -0.92 ± 2.53 | -0.30 ± 0.19 | -0.12 ± 0.23 |
///
/// Known biases, each more than 3 standard errors from 0: path+splat's fixed indirect discs at
/// the edges and the rim (as on the worksheet), SPPM's boundary correction in the corners
/// (+1.3%), and three small offsets on the tiles not explained yet: the path tracer's cool
/// tiles +0.43% ± 0.12% (12 seeds; its warm tiles and whole image agree), path+splat's cool
/// tiles -1.3% ± 0.37%, SPPM's warm tiles -0.30% ± 0.08%. A texture read wrongly moves the
/// tiles by far more: drawn at its mean colour, the floor fails (below).
const TEXTURED_PATH_256: Measured<9> = Measured {
    bias: [0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0043],
    sd: [
        0.0006, 0.0098, 0.0064, 0.0049, 0.0053, 0.0013, 0.0189, 0.0041, 0.0040,
    ],
};

/// `path+splat` at 256 spp on the textured floor (the table above).
const TEXTURED_PATH_SPLAT_256: Measured<9> = Measured {
    bias: [0.0, 0.0, -0.0078, -0.0061, 0.0, 0.0, 0.0, 0.0, -0.0132],
    sd: [
        0.0005, 0.0109, 0.0035, 0.0022, 0.0085, 0.0010, 0.0263, 0.0051, 0.0090,
    ],
};

/// SPPM at 16 passes on the textured floor (the table above).
const TEXTURED_SPPM_16: Measured<9> = Measured {
    bias: [0.0, 0.0, 0.0127, 0.0, 0.0, 0.0, 0.0, -0.0030, 0.0],
    sd: [
        0.0047, 0.0115, 0.0014, 0.0054, 0.0349, 0.0011, 0.0253, 0.0019, 0.0023,
    ],
};

/// A textured receiver under the glass sphere (MTL `map_Kd` at the OBJ's `vt`): the path
/// tracer, the path tracer with splatted caustics and SPPM each match Mitsuba's `bitmap`
/// texture in every region, the caustic on the checker and each tile colour included. The
/// floor drawn at the texture's mean colour instead fails on the tiles.
#[test]
fn a_textured_receiver_matches_mitsuba() {
    let s = textured(1, |_| {});
    let regs = textured_regions(&s);
    let runs = [
        (Method::Path, 256, &TEXTURED_PATH_256),
        (Method::PathSplat, 256, &TEXTURED_PATH_SPLAT_256),
        (Method::Sppm, 16, &TEXTURED_SPPM_16),
    ];
    let bad = misfits_of_runs(&s, &regs, &runs);
    assert!(bad.is_empty(), "{bad:#?}");
    // The mean of the decoded checker: 32 x 32 texels of which 16 red, the rest half warm,
    // half cool.
    let lin = |c: [u8; 3]| glam::Vec3::from(c.map(|v| scene::srgb_to_linear(v as f32 / 255.0)));
    let mean =
        (lin(CHECKER[0].1) * 504.0 + lin(CHECKER[1].1) * 504.0 + lin(CHECKER[2].1) * 16.0) / 1024.0;
    let flat = textured(1, |f| {
        f.materials.insert(
            "floor".into(),
            MaterialDesc::Lambertian {
                albedo: mean.to_array(),
                emission: [0.0; 3],
                texture: None,
            },
        );
    });
    eprintln!("path, 256, the floor at the texture's mean colour:");
    let bad = misfits(
        &image_by(&flat, Method::Path, 256),
        &regs,
        &TEXTURED_PATH_256,
    );
    assert!(
        bad.iter().any(|m| m.starts_with("warm tiles:"))
            && bad.iter().any(|m| m.starts_with("cool tiles:")),
        "the checker is not resolved: {bad:#?}"
    );
}

/// Vertex connection and merging, 16 passes, seeds 1-6, `m / ref - 1` in percent, regions as
/// above: -0.12 ± 0.35, -0.09 ± 0.67, +0.44 ± 0.47, -0.59 ± 0.49, -1.14 ± 3.69, -0.02 ± 0.08,
/// -0.60 ± 1.86, -0.04 ± 0.24 (warm tiles), -0.02 ± 0.42 (cool tiles). No bias is resolved
/// (|z| < 3; the outer rim's -0.6%, z -2.95, is merging's disc off the open front).
const TEXTURED_VCM_16: Measured<9> = Measured {
    bias: [0.0; 9],
    sd: [
        0.0035, 0.0067, 0.0047, 0.0049, 0.0369, 0.0008, 0.0186, 0.0024, 0.0042,
    ],
};

/// The textured floor by vertex connection and merging against Mitsuba: both subpaths read
/// the texel at their vertex, so every checker square matches.
#[test]
fn vcm_matches_mitsuba_on_a_textured_receiver() {
    let s = textured(super::table_seed(), |_| {});
    let regs = textured_regions(&s);
    eprintln!("vcm, 16:");
    let bad = misfits(&image_by(&s, Method::Vcm, 16), &regs, &TEXTURED_VCM_16);
    assert!(bad.is_empty(), "{bad:#?}");
}
