//! The scene file's glass keys: transmittance and absorption, their hashes and ranges.

use super::{GOOD_MTL, GOOD_OBJ, Scratch, error_of, scene_toml, scenes_dir};
use crate::{Material, Scene};
use glam::Vec3;

/// The scene file's coloured and absorbing glass: keys, defaults, the hash of clear glass
/// unchanged by writing the defaults out, and Beer-Lambert read at the surface a segment
/// ends on, from the inside only.
#[test]
fn glass_transmittance_and_absorption_keys() {
    let path = scenes_dir().join("cornell-spheres/analytic.toml");
    let text = std::fs::read_to_string(&path).unwrap();
    let a = Scene::from_toml(&path, &text).unwrap();
    let glass = a.material_of("glass").unwrap();
    assert_eq!(a.materials[glass as usize], Material::glass(1.5));
    assert_eq!(a.absorption[glass as usize], Vec3::ZERO);
    let defaults = text.replace(
        "ior = 1.5",
        "ior = 1.5\ntransmittance = [1, 1, 1]\nabsorption = [0, 0, 0]",
    );
    let b = Scene::from_toml(&path, &defaults).unwrap();
    assert_eq!(
        (a.photon_hash, a.image_hash, a.view_hash),
        (b.photon_hash, b.image_hash, b.view_hash),
        "clear glass written out in full hashes as before"
    );
    let coloured = text.replace(
        "ior = 1.5",
        "ior = 1.5\ntransmittance = [0.9, 0.6, 0.3]\nabsorption = [0.5, 0.25, 0]",
    );
    let c = Scene::from_toml(&path, &coloured).unwrap();
    assert_eq!(
        c.materials[glass as usize],
        Material::Dielectric {
            ior: 1.5,
            transmittance: Vec3::new(0.9, 0.6, 0.3),
            absorption: Vec3::new(0.5, 0.25, 0.0),
        }
    );
    assert_ne!(a.photon_hash, c.photon_hash);
    let Some(bsdf::Bsdf::Dielectric(d)) = c.bsdf(glass) else {
        panic!("not a dielectric")
    };
    assert_eq!(d.transmittance, Vec3::new(0.9, 0.6, 0.3));

    // The glass sphere (centre (-3.272, 2.29, -6.2395), radius 2.25): a chord through its
    // centre from inside is attenuated by exp(-σ 2r); the same segment arriving from outside,
    // or ending on the (non-absorbing) wall, is not.
    let centre = Vec3::new(-3.272, 2.29, -6.2395);
    let from_inside = geom::Ray::new(centre - Vec3::new(0.0, 0.0, 2.2), Vec3::new(0.0, 0.0, 2.0));
    let hit = c.geometry.intersect(&from_inside).unwrap();
    assert_eq!(hit.material, glass);
    let t = hit.t * 2.0;
    assert!((t - 4.45).abs() < 1e-4, "{t}");
    let want = (-Vec3::new(0.5, 0.25, 0.0) * t).exp();
    let got = c.transmittance_to(&hit, &from_inside);
    assert!((got - want).abs().max_element() < 1e-6, "{got} vs {want}");
    let from_outside = geom::Ray::new(centre + Vec3::new(0.0, 0.0, 4.0), Vec3::NEG_Z);
    let hit = c.geometry.intersect(&from_outside).unwrap();
    assert_eq!(hit.material, glass);
    assert_eq!(c.transmittance_to(&hit, &from_outside), Vec3::ONE);
    // Rough glass takes the same keys.
    let rough = text.replace(
        "type = \"dielectric\"\nior = 1.5",
        "type = \"rough_dielectric\"\nior = 1.5\nalpha = 0.1\nabsorption = [1, 2, 3]",
    );
    let r = Scene::from_toml(&path, &rough).unwrap();
    assert_eq!(r.absorption[glass as usize], Vec3::new(1.0, 2.0, 3.0));
}

#[test]
fn glass_keys_out_of_range_name_the_file_and_material() {
    for (key, problem) in [
        ("absorption = [-0.5, 0, 0]", "absorption"),
        ("absorption = [nan, 0, 0]", "absorption"),
        ("absorption = [inf, 0, 0]", "absorption"),
        ("transmittance = [1.5, 1, 1]", "transmittance"),
        ("transmittance = [-0.1, 1, 1]", "transmittance"),
    ] {
        let toml = format!(
            "{}[material.tinted]\ntype = \"dielectric\"\nior = 1.5\n{key}\n",
            scene_toml("a.obj")
        );
        error_of(
            "glass-keys",
            &[("s.toml", &toml), ("a.obj", GOOD_OBJ), ("m.mtl", GOOD_MTL)],
            "s.toml",
            "material `tinted`",
        );
        let dir = Scratch::new(
            "glass-keys-2",
            &[("s.toml", &toml), ("a.obj", GOOD_OBJ), ("m.mtl", GOOD_MTL)],
        );
        let e = Scene::load(dir.path("s.toml")).err().unwrap().to_string();
        assert!(e.contains(problem) && !e.contains('\n'), "{key}: {e}");
    }
}
