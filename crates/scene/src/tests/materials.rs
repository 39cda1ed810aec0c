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

/// Mitsuba 3's coated and thin models and the smooth conductor from the scene file: keys,
/// Mitsuba's defaults, named conductors, and the BSDFs they become.
#[test]
fn plastic_thin_and_conductor_keys() {
    let path = scenes_dir().join("cornell-spheres/analytic.toml");
    let text = std::fs::read_to_string(&path).unwrap();
    let with = |silver: &str, glass: &str| {
        let t = text
            .replace("type = \"metal\"\nreflectance = [0.96, 0.98, 0.96]", silver)
            .replace("type = \"dielectric\"\nior = 1.5", glass);
        Scene::from_toml(&path, &t).unwrap_or_else(|e| panic!("{e}"))
    };
    let s = with(
        "type = \"plastic\"\ndiffuse = [0.5, 0.4, 0.3]",
        "type = \"rough_plastic\"\ndiffuse = [0.2, 0.3, 0.4]\nnonlinear = true",
    );
    let (silver, glass) = (
        s.material_of("silver").unwrap(),
        s.material_of("glass").unwrap(),
    );
    // Mitsuba's defaults: polypropylene in air, specular 1, linear, alpha 0.1.
    let ior = 1.49 / 1.000_277;
    assert_eq!(
        s.materials[silver as usize],
        Material::Plastic {
            diffuse: Vec3::new(0.5, 0.4, 0.3),
            specular: Vec3::ONE,
            ior,
            nonlinear: false,
        }
    );
    assert_eq!(
        s.materials[glass as usize],
        Material::RoughPlastic {
            diffuse: Vec3::new(0.2, 0.3, 0.4),
            specular: Vec3::ONE,
            ior,
            alpha: 0.1,
            nonlinear: true,
        }
    );
    assert!(matches!(s.bsdf(silver), Some(bsdf::Bsdf::Plastic(p)) if p.eta == ior));
    assert!(matches!(s.bsdf(glass), Some(bsdf::Bsdf::RoughPlastic(p)) if p.alpha == 0.1));
    // Photons are stored on both (their base is diffuse); neither is a caustic caster.
    assert!(s.is_diffuse(silver) && s.is_diffuse(glass));
    assert!(!s.materials[silver as usize].is_specular());

    let s = with(
        "type = \"conductor\"\nmaterial = \"Au\"\nreflectance = [0.9, 0.9, 0.9]",
        "type = \"thin_dielectric\"",
    );
    let (silver, glass) = (
        s.material_of("silver").unwrap(),
        s.material_of("glass").unwrap(),
    );
    let (eta, k) = crate::mitsuba_conductor("Au").unwrap();
    let Some(bsdf::Bsdf::Conductor(c)) = s.bsdf(silver) else {
        panic!("not a conductor")
    };
    assert_eq!(
        (c.eta, c.k, c.reflectance),
        (eta.into(), k.into(), Vec3::splat(0.9))
    );
    let Some(bsdf::Bsdf::ThinDielectric(t)) = s.bsdf(glass) else {
        panic!("not a thin dielectric")
    };
    assert_eq!(t.eta, 1.5046 / 1.000_277);
    assert!(
        s.materials[silver as usize].is_specular() && s.materials[glass as usize].is_specular()
    );
    // No index: Mitsuba's `none`, which reflects everything.
    let s = with(
        "type = \"conductor\"",
        "type = \"thin_dielectric\"\nior = 1.33",
    );
    let Some(b @ bsdf::Bsdf::Conductor(_)) = s.bsdf(silver) else {
        panic!("not a conductor")
    };
    let r = b
        .sample(
            Vec3::new(0.6, 0.0, 0.8),
            0.5,
            [0.5; 2],
            bsdf::TransportMode::Radiance,
        )
        .unwrap();
    assert!((r.weight() - Vec3::ONE).abs().max_element() < 1e-6, "{r:?}");
    // rough_conductor takes a name too, and a name written out hashes like the values.
    let named = with(
        "type = \"rough_conductor\"\nalpha = 0.2\nmaterial = \"Cu\"",
        "type = \"thin_dielectric\"",
    );
    let (eta, k) = crate::mitsuba_conductor("Cu").unwrap();
    assert_eq!(
        named.materials[silver as usize],
        Material::RoughConductor {
            reflectance: Vec3::ONE,
            alpha: 0.2,
            eta: Some((eta.into(), k.into())),
        }
    );
}

#[test]
fn mitsuba_tables_hold_its_names() {
    use crate::{mitsuba_conductor, mitsuba_ior};
    // Values as Mitsuba 3.9.1 reports them in scalar_rgb (also in mitsuba_tables.rs).
    let (eta, k) = mitsuba_conductor("Au").unwrap();
    assert!((eta[0] - 0.143_036).abs() < 1e-5 && (k[2] - 1.603_359).abs() < 1e-5);
    assert_eq!(mitsuba_conductor("none"), Some(([0.0; 3], [1.0; 3])));
    for name in ["Ag", "Al", "Cu", "Cr", "W", "Cu_palik", "a-C"] {
        let (eta, k) = mitsuba_conductor(name).unwrap_or_else(|| panic!("{name}"));
        assert!(
            eta.iter().chain(&k).all(|v| v.is_finite() && *v >= 0.0),
            "{name}"
        );
    }
    assert_eq!(
        mitsuba_conductor("au"),
        None,
        "case-sensitive, as Mitsuba's file names"
    );
    assert_eq!(mitsuba_conductor("gold"), None);
    let want = [
        ("vacuum", 1.0),
        ("helium", 1.000036),
        ("hydrogen", 1.000132),
        ("air", 1.000277),
        ("carbon dioxide", 1.00045),
        ("water", 1.333),
        ("acetone", 1.36),
        ("ethanol", 1.361),
        ("carbon tetrachloride", 1.461),
        ("glycerol", 1.4729),
        ("benzene", 1.501),
        ("silicone oil", 1.52045),
        ("bromine", 1.661),
        ("water ice", 1.31),
        ("fused quartz", 1.458),
        ("pyrex", 1.47),
        ("acrylic glass", 1.49),
        ("polypropylene", 1.49),
        ("bk7", 1.5046),
        ("sodium chloride", 1.544),
        ("amber", 1.55),
        ("pet", 1.575),
        ("diamond", 2.419),
    ];
    for (name, v) in want {
        assert_eq!(mitsuba_ior(name), Some(v), "{name}");
    }
    assert_eq!(
        mitsuba_ior("BK7"),
        Some(1.5046),
        "case is ignored, as Mitsuba ignores it"
    );
    assert_eq!(mitsuba_ior("glass"), None);
}
