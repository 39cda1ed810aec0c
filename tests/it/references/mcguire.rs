//! Morgan McGuire's Cornell boxes (`scenes/mcguire/`), their OBJ and MTL files as published,
//! against Mitsuba surface by surface: the Original (a 2% brighter light must fail), the
//! Sphere (a mirror and a glass ball and the glass's caustic: the MTL's `Tf` read as the
//! spec's fraction transmitted must fail), the Water box (its surface and what is seen
//! through it: the spec's reading of `Tf` must fail), the Mirror box (what the tall mirror
//! block reflects: a 5% darker mirror must fail) and the Glossy box (the highlights: a
//! rougher lobe must fail).

use super::{
    Measured, RES, RegionRef, image_by, misfits, misfits_of_runs, region_refs, table_seed,
};
use crate::kit::{PIXEL_POINTS, scene_at};
use glam::Vec3;
use scene::{MaterialDesc, Method, Scene, SceneFile, TfReading};

/// `scenes/mcguire/original.toml` at 128 x 128.
fn mcguire_original(seed: u64, edit: impl FnOnce(&mut SceneFile)) -> Scene {
    scene_at("mcguire/original.toml", RES, seed, edit)
}

/// The McGuire box's regions: the whole image, then the pixels all of whose
/// [`PIXEL_POINTS`] see one MTL material. The light quad seen directly (80 pixels at 128 x
/// 128, its `Ke` plus 0.8% reflected) is left out: both methods read it within 0.01% of
/// Mitsuba's, with too little noise over the seeds for a table to bound.
const MCGUIRE_GROUPS: [(&str, &[&str]); 8] = [
    ("image", &[]),
    ("floor", &["floor"]),
    ("ceiling", &["ceiling"]),
    ("back wall", &["backWall"]),
    ("left wall", &["leftWall"]),
    ("right wall", &["rightWall"]),
    ("short box", &["shortBox"]),
    ("tall box", &["tallBox"]),
];

fn mcguire_regions(scene: &Scene) -> Vec<RegionRef> {
    box_regions(scene, "mcguire-original", &MCGUIRE_GROUPS, |_, _, _| None)
}

/// What the camera ray through a point sees in a McGuire box, told by `refine` (the ray and
/// its first hit), else by the hit's MTL material name; `background` where it leaves.
type Refine = fn(&Scene, &geom::Ray, &geom::Hit) -> Option<&'static str>;

/// Regions of the reference `reference`: per `(name, labels)` of `groups`, the pixels all of
/// whose [`PIXEL_POINTS`] see one of `labels` (every pixel where `labels` is empty). Each
/// region's pixel count is printed.
fn box_regions(
    scene: &Scene,
    reference: &str,
    groups: &[(&'static str, &[&str])],
    refine: Refine,
) -> Vec<RegionRef> {
    let (w, h) = (RES as usize, RES as usize);
    let label = |x: f32, y: f32| -> String {
        let ray = scene.camera.ray(x, y);
        match scene.geometry.intersect(&ray) {
            None => "background".into(),
            Some(hit) => refine(scene, &ray, &hit)
                .map(String::from)
                .unwrap_or_else(|| scene.material_names[hit.material as usize].clone()),
        }
    };
    let labels: Vec<[String; 5]> = (0..w * h)
        .map(|i| {
            let (x, y) = ((i % w) as f32, (i / w) as f32);
            PIXEL_POINTS.map(|(u, v)| label(x + u, y + v))
        })
        .collect();
    let masks: Vec<(&'static str, film::Mask)> = groups
        .iter()
        .map(|&(name, group)| {
            let pixels: Vec<bool> = labels
                .iter()
                .map(|l| group.is_empty() || l.iter().all(|m| group.contains(&m.as_str())))
                .collect();
            let mask = film::Mask {
                width: w,
                height: h,
                pixels,
            };
            (name, mask)
        })
        .collect();
    let counts: Vec<String> = masks
        .iter()
        .map(|(n, m)| format!("{n} {}", m.count()))
        .collect();
    eprintln!("{reference} regions (pixels): {}", counts.join(", "));
    region_refs(reference, masks)
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

// ---------------------------------------------------------------------------------------------
// The Sphere, Water, Mirror and Glossy boxes.

/// McGuire's box `name` (its scene file in `scenes/mcguire/`) at 128 x 128.
fn mcguire(name: &str, seed: u64, edit: impl FnOnce(&mut SceneFile)) -> Scene {
    scene_at(&format!("mcguire/{name}.toml"), RES, seed, edit)
}

/// The centre of the light quad of the Sphere, Water and Glossy boxes (1 cm under their
/// ceiling at 1.59).
const LIGHT_LOW: Vec3 = Vec3::new(-0.005, 1.58, -0.03);

/// The camera ray's direction mirrored about the hit's shading normal.
fn reflected(ray: &geom::Ray, hit: &geom::Hit) -> Vec3 {
    let d = ray.d.normalize();
    let n = if hit.ns.dot(d) < 0.0 { hit.ns } else { -hit.ns };
    d - 2.0 * d.dot(n) * n
}

/// The floor in the glass ball's shadow from the light's centre (`caustic`): where the light
/// the ball refracts lands, brightest under and in front of it.
fn glass_shadow(s: &Scene, _: &geom::Ray, hit: &geom::Hit) -> Option<&'static str> {
    if s.material_names[hit.material as usize] != "floor" {
        return None;
    }
    let blocker = s.geometry.intersect(&hit.point.spawn_ray_to(LIGHT_LOW))?;
    (s.material_names[blocker.material as usize] == "rightSphere").then_some("caustic")
}

/// The water's wavy top (`water surface`) and its front face (`water front`), through which
/// the floor, its caustics and the balls' lower halves are seen.
fn water_faces(s: &Scene, _: &geom::Ray, hit: &geom::Hit) -> Option<&'static str> {
    if s.material_names[hit.material as usize] != "water" {
        return None;
    }
    Some(if hit.ns.y > 0.5 {
        "water surface"
    } else {
        "water front"
    })
}

/// The tall mirror block where its reflection meets the box (`mirror`), not the open front
/// (black in both renderers).
fn mirror_sees_box(s: &Scene, ray: &geom::Ray, hit: &geom::Hit) -> Option<&'static str> {
    if s.material_names[hit.material as usize] != "tallBox" {
        return None;
    }
    let r = reflected(ray, hit);
    Some(match s.geometry.intersect(&hit.point.spawn_ray(r)) {
        Some(_) => "mirror",
        None => "mirror, open front",
    })
}

/// The glossy sphere where the camera ray's mirror direction lies within 25 degrees of the
/// light's centre (its highlight, the lobe of alpha 0.071 around the light's mirror image),
/// and the glossy block's top (its lobe of alpha 0.22 towards the ceiling and the light).
fn highlights(s: &Scene, ray: &geom::Ray, hit: &geom::Hit) -> Option<&'static str> {
    match s.material_names[hit.material as usize].as_str() {
        "sphere" => {
            let to_light = (LIGHT_LOW - hit.point.p).normalize();
            (reflected(ray, hit).dot(to_light) >= 25f32.to_radians().cos())
                .then_some("sphere highlight")
        }
        "shortBox" if hit.ns.y > 0.5 => Some("box top"),
        _ => None,
    }
}

const SPHERE_GROUPS: [(&str, &[&str]); 9] = [
    ("image", &[]),
    ("glass ball", &["rightSphere"]),
    ("caustic", &["caustic"]),
    ("mirror ball", &["leftSphere"]),
    ("floor", &["floor"]),
    ("ceiling", &["ceiling"]),
    ("back wall", &["backWall"]),
    ("left wall", &["leftWall"]),
    ("right wall", &["rightWall"]),
];

const WATER_GROUPS: [(&str, &[&str]); 9] = [
    ("image", &[]),
    ("water surface", &["water surface"]),
    ("water front", &["water front"]),
    ("glass ball", &["rightSphere"]),
    ("mirror ball", &["leftSphere"]),
    ("ceiling", &["ceiling"]),
    ("back wall", &["backWall"]),
    ("left wall", &["leftWall"]),
    ("right wall", &["rightWall"]),
];

const MIRROR_GROUPS: [(&str, &[&str]); 8] = [
    ("image", &[]),
    ("mirror", &["mirror"]),
    ("short box", &["shortBox"]),
    ("floor", &["floor"]),
    ("ceiling", &["ceiling"]),
    ("back wall", &["backWall"]),
    ("left wall", &["leftWall"]),
    ("right wall", &["rightWall"]),
];

const GLOSSY_GROUPS: [(&str, &[&str]); 10] = [
    ("image", &[]),
    ("sphere", &["sphere", "sphere highlight"]),
    ("sphere highlight", &["sphere highlight"]),
    ("short box", &["shortBox", "box top"]),
    ("box top", &["box top"]),
    ("floor", &["floor"]),
    ("ceiling", &["ceiling"]),
    ("back wall", &["backWall"]),
    ("left wall", &["leftWall"]),
    ("right wall", &["rightWall"]),
];

/// The Sphere box's tables, `m / ref - 1` in percent, mean ± one run's standard deviation
/// over seeds 1-6 (`PHOTONFLOW_TABLE_SEED`), regions in [`SPHERE_GROUPS`]' order (reference
/// standard errors 0.021%, 0.083%, 0.279%, 0.089%, 0.038%, 0.125%, 0.029%, 0.039%, 0.047%):
///
/// | run | image | glass ball | caustic | mirror ball | floor | ceiling | back wall | left wall | right wall |
/// |---|---|---|---|---|---|---|---|---|---|
/// | path, 256 spp | -0.04 ± 0.09 | -0.40 ± 0.52 | +0.64 ± 0.60 | +0.16 ± 0.31 | -0.14 ± 0.42 | +0.04 ± 1.15 | -0.08 ± 0.26 | -0.01 ± 0.37 | +0.10 ± 0.55 |
/// | sppm, 16 passes | -0.05 ± 0.23 | -0.15 ± 0.18 | +0.37 ± 0.97 | -3.85 ± 5.33 | +0.07 ± 0.14 | -0.11 ± 0.12 | +0.05 ± 0.12 | +0.08 ± 0.12 | +0.04 ± 0.06 |
///
/// No offset lies 3 standard errors of its mean from zero (the largest: the path tracer's
/// caustic, +0.64% at 2.6). SPPM's mirror ball is noisy (5.3% a run): most of its mean is the
/// light's small image in the ball, which one eye sample per pixel and pass hits or misses.
const SPHERE_PATH_256: Measured<9> = Measured {
    bias: [0.0; 9],
    sd: [
        0.0009, 0.0052, 0.0060, 0.0031, 0.0042, 0.0115, 0.0026, 0.0037, 0.0055,
    ],
};

/// SPPM at 16 passes on the Sphere box (the table above).
const SPHERE_SPPM_16: Measured<9> = Measured {
    bias: [0.0; 9],
    sd: [
        0.0023, 0.0018, 0.0097, 0.0533, 0.0014, 0.0012, 0.0012, 0.0012, 0.0006,
    ],
};

/// The Water box's tables (as the Sphere's; reference standard errors 0.034%, 0.191%, 0.285%,
/// 0.270%, 0.145%, 0.212%, 0.052%, 0.073%, 0.105%), regions in [`WATER_GROUPS`]' order:
///
/// | run | image | water surface | water front | glass ball | mirror ball | ceiling | back wall | left wall | right wall |
/// |---|---|---|---|---|---|---|---|---|---|
/// | path, 256 spp | -0.65 ± 0.11 | -3.04 ± 1.38 | -1.15 ± 1.24 | -3.07 ± 2.30 | -0.42 ± 0.70 | -1.81 ± 1.23 | -0.15 ± 0.27 | -0.23 ± 0.48 | -0.26 ± 0.56 |
/// | sppm, 16 passes | -0.59 ± 0.30 | -3.05 ± 0.45 | -0.79 ± 0.29 | -3.58 ± 0.87 | -4.84 ± 6.43 | -0.50 ± 0.13 | -0.18 ± 0.09 | -0.19 ± 0.08 | -0.48 ± 0.11 |
///
/// Both methods read the water box darker than Mitsuba where light has crossed the wavy
/// water: the surface and the glass ball by about 3%, the image by 0.6% (the offsets more than
/// 3 standard errors of their mean from zero are the tables' known biases). They agree with
/// each other, and the Sphere box, the same glass without water, has no such offset: the
/// difference is in refraction through the water's interpolated vertex normals, which the
/// two renderers handle differently (Mitsuba's own image of the water box with flat normals
/// is 4.2% brighter than with the file's). Left as measured; reading `Tf` the other way
/// moves these regions by far more (below).
const WATER_PATH_256: Measured<9> = Measured {
    bias: [-0.0065, -0.0304, 0.0, -0.0307, 0.0, -0.0181, 0.0, 0.0, 0.0],
    sd: [
        0.0011, 0.0138, 0.0124, 0.0230, 0.0070, 0.0123, 0.0027, 0.0048, 0.0056,
    ],
};

/// SPPM at 16 passes on the Water box (the table above).
const WATER_SPPM_16: Measured<9> = Measured {
    bias: [
        -0.0059, -0.0305, -0.0079, -0.0358, 0.0, -0.0050, -0.0018, -0.0019, -0.0048,
    ],
    sd: [
        0.0030, 0.0045, 0.0029, 0.0087, 0.0643, 0.0013, 0.0009, 0.0008, 0.0011,
    ],
};

/// The Mirror box's tables (as the Sphere's; reference standard errors 0.016%, 0.113%,
/// 0.082%, 0.065%, 0.111%, 0.036%, 0.047%, 0.034%), regions in [`MIRROR_GROUPS`]' order:
///
/// | run | image | mirror | short box | floor | ceiling | back wall | left wall | right wall |
/// |---|---|---|---|---|---|---|---|---|
/// | path, 256 spp | -0.07 ± 0.08 | +0.19 ± 0.48 | -0.38 ± 0.55 | +0.05 ± 0.38 | -0.29 ± 0.60 | -0.13 ± 0.22 | -0.32 ± 0.33 | -0.02 ± 0.23 |
/// | sppm, 16 passes | +0.00 ± 0.32 | +0.01 ± 0.30 | +0.17 ± 0.26 | +0.05 ± 0.12 | -0.12 ± 0.07 | +0.04 ± 0.14 | -0.03 ± 0.07 | +0.07 ± 0.12 |
///
/// One offset lies more than 3 standard errors of its mean from zero: SPPM's ceiling, -0.12%
/// (4.2), as on the Original (-0.13%); it is allowed as SPPM's known bias.
const MIRROR_PATH_256: Measured<8> = Measured {
    bias: [0.0; 8],
    sd: [
        0.0008, 0.0048, 0.0055, 0.0038, 0.0060, 0.0022, 0.0033, 0.0023,
    ],
};

/// SPPM at 16 passes on the Mirror box (the table above).
const MIRROR_SPPM_16: Measured<8> = Measured {
    bias: [0.0, 0.0, 0.0, 0.0, -0.0012, 0.0, 0.0, 0.0],
    sd: [
        0.0032, 0.0030, 0.0026, 0.0012, 0.0007, 0.0014, 0.0007, 0.0012,
    ],
};

/// The Glossy box's tables (as the Sphere's; reference standard errors 0.017%, 0.057%,
/// 0.175%, 0.043%, 0.079%, 0.020%, 0.056%, 0.020%, 0.023%, 0.027%), regions in
/// [`GLOSSY_GROUPS`]' order (the sphere's highlight is 21 pixels, the block's top 39):
///
/// | run | image | sphere | highlight | short box | box top | floor | ceiling | back wall | left wall | right wall |
/// |---|---|---|---|---|---|---|---|---|---|---|
/// | path, 256 spp | +0.04 ± 0.06 | +0.14 ± 0.40 | +0.28 ± 1.54 | -0.12 ± 0.39 | +0.09 ± 0.55 | -0.05 ± 0.15 | -0.17 ± 0.33 | +0.10 ± 0.10 | -0.12 ± 0.18 | +0.07 ± 0.18 |
/// | sppm, 16 passes | -0.12 ± 0.58 | -2.47 ± 2.96 | -7.2 ± 11.7 | -0.82 ± 2.11 | -0.7 ± 11.3 | -0.09 ± 0.10 | +0.06 ± 0.22 | +0.06 ± 0.10 | +0.09 ± 0.04 | +0.09 ± 0.04 |
///
/// SPPM gathers photons on the glossy surfaces, whose lobes (alpha 0.071 and 0.22) are far
/// narrower than its radii: their regions are noisy (11% a run on the highlights). Two
/// offsets lie more than 3 standard errors from zero, SPPM's side walls (+0.09%, 4.9 and
/// 6.2), allowed as its known bias.
const GLOSSY_PATH_256: Measured<10> = Measured {
    bias: [0.0; 10],
    sd: [
        0.0006, 0.0040, 0.0154, 0.0039, 0.0055, 0.0015, 0.0033, 0.0010, 0.0018, 0.0018,
    ],
};

/// SPPM at 16 passes on the Glossy box (the table above).
const GLOSSY_SPPM_16: Measured<10> = Measured {
    bias: [0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0009, 0.0009],
    sd: [
        0.0058, 0.0296, 0.1168, 0.0211, 0.1125, 0.0010, 0.0022, 0.0010, 0.0004, 0.0004,
    ],
};

/// The `[[mesh]]` table's `tf` set to the spec's reading (`Tf` the fraction transmitted).
fn spec_tf(f: &mut SceneFile) {
    f.meshes[0].tf = TfReading::Transmitted;
}

/// McGuire's CornellBox-Sphere (its MTL's `Tf` read as G3D reads it, `tf = "absorbed"`)
/// against Mitsuba's path tracer: the path tracer and SPPM match on the glass ball, its
/// caustic on the floor, the mirror ball and every wall. The negative control: `Tf` read as
/// the spec's fraction transmitted (the glass keeps 10% a crossing) fails the glass ball and
/// the caustic (path tracer, 64 spp, against the 256-spp table).
#[test]
fn mcguire_sphere_matches_mitsuba() {
    let s = mcguire("sphere", table_seed(), |_| {});
    let regs = box_regions(&s, "mcguire-sphere", &SPHERE_GROUPS, glass_shadow);
    let runs = [
        (Method::Path, 256, &SPHERE_PATH_256),
        (Method::Sppm, 16, &SPHERE_SPPM_16),
    ];
    let bad = misfits_of_runs(&s, &regs, &runs);
    assert!(bad.is_empty(), "{bad:#?}");
    eprintln!("path, 64, Tf read as the fraction transmitted:");
    let spec = mcguire("sphere", 2, spec_tf);
    let bad = misfits(&image_by(&spec, Method::Path, 64), &regs, &SPHERE_PATH_256);
    for region in ["glass ball:", "caustic:"] {
        assert!(
            bad.iter().any(|m| m.starts_with(region)),
            "the spec's Tf passed {region} {bad:#?}"
        );
    }
}

/// McGuire's CornellBox-Water (`tf = "absorbed"`) against Mitsuba: the path tracer and SPPM
/// match on the water's surface and front, the balls and the walls, within the water's
/// measured offsets (see the tables). The negative control: `Tf` read as the spec's fraction
/// transmitted (the water keeps (0.1, 0.1, 0) a crossing) fails the water's surface and front.
#[test]
fn mcguire_water_matches_mitsuba() {
    let s = mcguire("water", table_seed(), |_| {});
    let regs = box_regions(&s, "mcguire-water", &WATER_GROUPS, water_faces);
    let runs = [
        (Method::Path, 256, &WATER_PATH_256),
        (Method::Sppm, 16, &WATER_SPPM_16),
    ];
    let bad = misfits_of_runs(&s, &regs, &runs);
    assert!(bad.is_empty(), "{bad:#?}");
    eprintln!("path, 64, Tf read as the fraction transmitted:");
    let spec = mcguire("water", 2, spec_tf);
    let bad = misfits(&image_by(&spec, Method::Path, 64), &regs, &WATER_PATH_256);
    for region in ["water surface:", "water front:"] {
        assert!(
            bad.iter().any(|m| m.starts_with(region)),
            "the spec's Tf passed {region} {bad:#?}"
        );
    }
}

/// McGuire's CornellBox-Mirror against Mitsuba: the tall block (MTL illum 5, drawn as a
/// mirror of reflectance `Ks` = 0.95) where it reflects the box, and every other surface,
/// by the path tracer and SPPM. The negative control: the mirror's reflectance 0.9 (a
/// scene-file material over the MTL's) fails the mirror's region at 256 spp.
#[test]
fn mcguire_mirror_matches_mitsuba() {
    let s = mcguire("mirror", table_seed(), |_| {});
    let regs = box_regions(&s, "mcguire-mirror", &MIRROR_GROUPS, mirror_sees_box);
    let runs = [
        (Method::Path, 256, &MIRROR_PATH_256),
        (Method::Sppm, 16, &MIRROR_SPPM_16),
    ];
    let bad = misfits_of_runs(&s, &regs, &runs);
    assert!(bad.is_empty(), "{bad:#?}");
    eprintln!("path, 256, the mirror's reflectance 0.9:");
    let darker = mcguire("mirror", 2, |f| {
        let mirror = MaterialDesc::Mirror {
            reflectance: [0.9; 3],
        };
        f.materials.insert("tallBox".into(), mirror);
    });
    let bad = misfits(
        &image_by(&darker, Method::Path, 256),
        &regs,
        &MIRROR_PATH_256,
    );
    assert!(
        bad.iter().any(|m| m.starts_with("mirror:")),
        "a 5% darker mirror passed: {bad:#?}"
    );
}

/// McGuire's CornellBox-Glossy against Mitsuba (its `--glossy` mapping of MTL illum 2, the
/// same as photonflow's): the glossy sphere, its highlight, the glossy block and its top,
/// and the walls, by the path tracer and SPPM. The negative control: the sphere's lobe twice
/// as rough (alpha 0.14 instead of `Ns 400`'s 0.071; a scene-file material over the MTL's)
/// fails the highlight at 256 spp.
#[test]
fn mcguire_glossy_matches_mitsuba() {
    let s = mcguire("glossy", table_seed(), |_| {});
    let regs = box_regions(&s, "mcguire-glossy", &GLOSSY_GROUPS, highlights);
    let runs = [
        (Method::Path, 256, &GLOSSY_PATH_256),
        (Method::Sppm, 16, &GLOSSY_SPPM_16),
    ];
    let bad = misfits_of_runs(&s, &regs, &runs);
    assert!(bad.is_empty(), "{bad:#?}");
    eprintln!("path, 256, the sphere's lobe twice as rough:");
    let rougher = mcguire("glossy", 2, |f| {
        // The MTL's Kd and Ks, scaled to sum to 1 per channel as the MTL table does.
        let kd = [0.486f32, 0.631, 0.663];
        let sum = kd.map(|d| d + 0.9);
        let sphere = MaterialDesc::Glossy {
            albedo: [0, 1, 2].map(|c| kd[c] / sum[c]),
            specular: sum.map(|t| 0.9 / t),
            alpha: 2.0 * (2.0f32 / 402.0).sqrt(),
            texture: None,
        };
        f.materials.insert("sphere".into(), sphere);
    });
    let bad = misfits(
        &image_by(&rougher, Method::Path, 256),
        &regs,
        &GLOSSY_PATH_256,
    );
    assert!(
        bad.iter().any(|m| m.starts_with("sphere highlight:")),
        "a rougher sphere passed: {bad:#?}"
    );
}
