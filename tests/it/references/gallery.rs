//! The Mitsuba 3 XML gallery (`scenes/mitsuba/`): each scene read by photonflow from the
//! same file Mitsuba rendered its two reference halves from (`tests/references/make.sh`,
//! `mitsuba_xml.py`), compared surface by surface: the pixels all of whose
//! [`PIXEL_POINTS`] see one BSDF (by its XML `id`), and the whole image.

use super::{
    Measured, RES, RegionRef, image_by, misfits, misfits_of_runs, region_refs, table_seed,
};
use crate::kit::{PIXEL_POINTS, scenes_dir};
use scene::{LightDesc, Method, Scene, SceneFile};

/// `scenes/mitsuba/NAME.xml` at 128 x 128 (its `$width` and `$height`), seed `seed`.
fn gallery(name: &str, seed: u64, edit: impl FnOnce(&mut SceneFile)) -> Scene {
    let size = [("width", RES), ("height", RES)].map(|(k, v)| (k.to_string(), v.to_string()));
    Scene::load_defined(
        scenes_dir().join(format!("mitsuba/{name}.xml")),
        &size,
        |f| {
            f.seed = seed;
            edit(f);
        },
    )
    .unwrap_or_else(|e| panic!("{e}"))
}

/// Regions: for each `(name, materials)`, the pixels all of whose [`PIXEL_POINTS`] see one
/// of `materials` first (none listed: every pixel).
fn by_material(
    scene: &Scene,
    reference: &str,
    groups: &[(&'static str, &[&str])],
) -> Vec<RegionRef> {
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
    let masks = groups
        .iter()
        .map(|&(name, mats)| {
            let pixels = labels
                .iter()
                .map(|l| mats.is_empty() || l.iter().all(|m| m.is_some_and(|m| mats.contains(&m))))
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
    region_refs(reference, masks)
}

const WORKSHEET_GROUPS: [(&str, &[&str]); 6] = [
    ("image", &[]),
    ("white", &["white"]),
    ("red", &["red"]),
    ("green", &["green"]),
    ("silver", &["silver"]),
    ("glass", &["glass"]),
];

/// `worksheet.xml`'s tables, `m / ref - 1` in percent, mean ± one run's standard deviation
/// over seeds 1-6, regions in [`WORKSHEET_GROUPS`]' order:
///
/// | run | image | white | red | green | silver | glass |
/// |---|---|---|---|---|---|---|
/// | path, 256 spp | TBD |
/// | sppm, 16 passes | TBD |
const WORKSHEET_PATH_256: Measured<6> = Measured {
    bias: [0.0; 6],
    sd: [0.01; 6],
};

const WORKSHEET_SPPM_16: Measured<6> = Measured {
    bias: [0.0; 6],
    sd: [0.01; 6],
};

/// The worksheet scene written as Mitsuba XML (OBJ walls in millimetres placed by one
/// transform, a `rectangle` lamp, analytic spheres, BSDFs by `<ref>` from an included file)
/// matches Mitsuba's rendering of the same file, by the path tracer and SPPM. The lamp 2%
/// brighter fails.
#[test]
fn worksheet_xml_matches_mitsuba() {
    let s = gallery("worksheet", table_seed(), |_| {});
    let regs = by_material(&s, "mitsuba-worksheet", &WORKSHEET_GROUPS);
    let runs = [
        (Method::Path, 256, &WORKSHEET_PATH_256),
        (Method::Sppm, 16, &WORKSHEET_SPPM_16),
    ];
    let bad = misfits_of_runs(&s, &regs, &runs);
    assert!(bad.is_empty(), "{bad:#?}");
    let brighter = gallery("worksheet", 2, |f| {
        for m in f.meshes.iter_mut().filter_map(|m| m.radiance.as_mut()) {
            *m = m.map(|c| c * 1.02);
        }
    });
    eprintln!("path, 256, the lamp 2% brighter:");
    let bad = misfits(
        &image_by(&brighter, Method::Path, 256),
        &regs,
        &WORKSHEET_PATH_256,
    );
    assert!(
        bad.iter().any(|m| m.starts_with("image:")),
        "a 2% brighter lamp passed: {bad:#?}"
    );
}

const SHAPES_GROUPS: [(&str, &[&str]); 5] = [
    ("image", &[]),
    ("floor", &["floor"]),
    ("back wall", &["wall"]),
    ("gold cube", &["gold"]),
    ("glass ball", &["glass"]),
];

/// `shapes-and-lights.xml`'s tables (as the worksheet's above):
///
/// | run | image | floor | back wall | gold cube | glass ball |
/// |---|---|---|---|---|---|
/// | path, 256 spp | TBD |
/// | sppm, 16 passes | TBD |
const SHAPES_PATH_256: Measured<5> = Measured {
    bias: [0.0; 5],
    sd: [0.01; 5],
};

const SHAPES_SPPM_16: Measured<5> = Measured {
    bias: [0.0; 5],
    sd: [0.01; 5],
};

/// Generated shapes under every kind of light (`rectangle` with a `bitmap`, `cube` of rough
/// gold by its complex index, a rough glass `sphere` by named indices, a `disk` lamp, a
/// `spot`, a `directional`, a turned `envmap`) match Mitsuba's rendering of the same file.
/// The environment left unturned (its `to_world` dropped) fails.
#[test]
fn shapes_and_lights_xml_matches_mitsuba() {
    let s = gallery("shapes-and-lights", table_seed(), |_| {});
    let regs = by_material(&s, "mitsuba-shapes-and-lights", &SHAPES_GROUPS);
    let runs = [
        (Method::Path, 256, &SHAPES_PATH_256),
        (Method::Sppm, 16, &SHAPES_SPPM_16),
    ];
    let bad = misfits_of_runs(&s, &regs, &runs);
    assert!(bad.is_empty(), "{bad:#?}");
    let unturned = gallery("shapes-and-lights", 2, |f| {
        for l in &mut f.lights {
            if let LightDesc::Environment { rotate, .. } = l {
                *rotate = [0.0; 3];
            }
        }
    });
    eprintln!("path, 256, the sky unturned:");
    let bad = misfits(
        &image_by(&unturned, Method::Path, 256),
        &regs,
        &SHAPES_PATH_256,
    );
    assert!(!bad.is_empty(), "the sky unturned passed");
}
