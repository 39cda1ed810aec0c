//! The scene file: its TOML values and keys checked, and the hashes its parts key.

use super::{GOOD_MTL, GOOD_OBJ, error_of, load, scene_toml, scenes_dir};
use crate::Scene;

#[test]
fn content_hash_changes_with_any_input() {
    let a = load("cornell-spheres/analytic.toml");
    let b = load("cornell-spheres/analytic.toml");
    assert_eq!(a.content_hash, b.content_hash);
    let text = std::fs::read_to_string(scenes_dir().join("cornell-spheres/analytic.toml")).unwrap();
    let edited = text.replace("ior = 1.5", "ior = 1.51");
    let c = Scene::from_toml(&scenes_dir().join("cornell-spheres/analytic.toml"), &edited).unwrap();
    assert_ne!(a.content_hash, c.content_hash);
    assert_ne!(
        a.photon_hash, c.photon_hash,
        "a material change changes the photons"
    );
    // The camera, [render] and [estimate] do not change photons; the camera changes images.
    let d = Scene::from_toml(
        &scenes_dir().join("cornell-spheres/analytic.toml"),
        &(text.replace("vfov = 53.13", "vfov = 50") + "\n[estimate.global]\nk = 20\n"),
    )
    .unwrap();
    assert_ne!(a.content_hash, d.content_hash);
    assert_eq!(a.photon_hash, d.photon_hash);
    assert_ne!(a.image_hash, d.image_hash);
    let e = Scene::from_toml(
        &scenes_dir().join("cornell-spheres/analytic.toml"),
        &(text.clone() + "\n[estimate.global]\nk = 20\n"),
    )
    .unwrap();
    assert_eq!(a.image_hash, e.image_hash);
}

#[test]
fn malformed_toml_values_are_named_with_their_line() {
    let toml = scene_toml("a.obj").replace("vfov = 60", "vfov = \"wide\"");
    error_of(
        "toml",
        &[("s.toml", &toml), ("a.obj", GOOD_OBJ), ("m.mtl", GOOD_MTL)],
        "s.toml",
        "line 4",
    );
    let toml = scene_toml("a.obj") + "spp = 4\n";
    error_of(
        "unknown-key",
        &[("s.toml", &toml), ("a.obj", GOOD_OBJ), ("m.mtl", GOOD_MTL)],
        "s.toml",
        "unknown field `spp`",
    );
    let toml = scene_toml("a.obj") + "[render]\nspp = 0\n";
    error_of(
        "spp0",
        &[("s.toml", &toml), ("a.obj", GOOD_OBJ), ("m.mtl", GOOD_MTL)],
        "s.toml",
        "render.spp = 0",
    );
    let toml = scene_toml("a.obj").replace("look_at = [0, 0, 0]", "look_at = [0, 1, 3]");
    error_of(
        "camera",
        &[("s.toml", &toml), ("a.obj", GOOD_OBJ), ("m.mtl", GOOD_MTL)],
        "s.toml",
        "camera",
    );
}

/// The hashes of a scene of the tree, pinned: a change to the scene file's schema (a new
/// optional key, `obj` made optional beside `ply`) must not move the caches and image
/// metadata of scenes that do not use it. (A changed default does move the image and
/// content hashes of the scenes that leave it to the default: both scenes' moved when the
/// default method became `vcm`; their photon hashes, the caches', did not.)
#[test]
fn hashes_of_existing_scenes_are_pinned() {
    for (rel, want) in [
        (
            "cornell-spheres/analytic.toml",
            [
                0x4a13094c041d42fc,
                0x18e0b8823a34cebe,
                0x0a6652980b9e8d9f,
                0x47d52042c2ac0dfb,
            ],
        ),
        (
            "cornell-glossy/glossy-floor.toml",
            [
                0x0d2a5cb4a6bb47f5,
                0xd647787909482ab3,
                0x98780647dfbce24e,
                0x6110f0336fd4c0ee,
            ],
        ),
    ] {
        let s = load(rel);
        let got = [s.photon_hash, s.image_hash, s.view_hash, s.content_hash];
        assert_eq!(got, want, "{rel}: hashes moved: {got:#018x?}");
    }
}
