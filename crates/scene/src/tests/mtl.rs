//! The MTL table: each key and illum code drawn, warned or refused as the table says.

use super::{GOOD_MTL, GOOD_OBJ, Scratch, error_of, scene_toml};
use crate::{Material, Scene};
use glam::Vec3;

#[test]
fn unknown_illum_code_is_named() {
    let mtl = GOOD_MTL.replace("Kd 0.5 0.5 0.5", "Kd 0.5 0.5 0.5\nillum 42");
    error_of(
        "illum",
        &[
            ("s.toml", &scene_toml("a.obj")),
            ("a.obj", GOOD_OBJ),
            ("m.mtl", &mtl),
        ],
        "m.mtl",
        "unknown illum code 42",
    );
}

/// `Kd 0.5` is grey (a real MTL variant; tobj alone panics on it); two numbers are an error.
#[test]
fn one_number_mtl_colour_is_grey() {
    let dir = Scratch::new(
        "grey",
        &[
            ("s.toml", &scene_toml("a.obj")),
            ("a.obj", GOOD_OBJ),
            ("m.mtl", &GOOD_MTL.replace("Kd 0.5 0.5 0.5", "Kd 0.25")),
        ],
    );
    let s = Scene::load(dir.path("s.toml")).unwrap();
    let white = s.material_of("white").unwrap() as usize;
    assert_eq!(
        s.materials[white],
        Material::Lambertian {
            albedo: Vec3::splat(0.25)
        }
    );
    error_of(
        "grey2",
        &[
            ("s.toml", &scene_toml("a.obj")),
            ("a.obj", GOOD_OBJ),
            ("m.mtl", &GOOD_MTL.replace("Kd 0.5 0.5 0.5", "Kd 0.5 0.5")),
        ],
        "m.mtl",
        "line 2: `Kd` needs one number (grey) or three (RGB), got 2",
    );
}

/// The floor's material `white` of [`GOOD_MTL`] given `lines` instead, loaded with emission
/// from `emission` (`ke`, `ka`): the material, and the warnings.
fn white_as(lines: &str, emission: &str) -> Result<(Material, Vec<String>), String> {
    white_with(lines, emission, "")
}

/// [`white_as`] with `mesh` (TOML lines) added to the scene file's `[[mesh]]` table.
fn white_with(lines: &str, emission: &str, mesh: &str) -> Result<(Material, Vec<String>), String> {
    let mtl = GOOD_MTL.replace("Kd 0.5 0.5 0.5", lines);
    let mtl = if emission == "ka" {
        mtl.replace("Ke 4 4 4", "Ka 4 4 4")
    } else {
        mtl
    };
    let toml = format!("{}emission = \"{emission}\"\n{mesh}", scene_toml("a.obj"));
    let dir = Scratch::new(
        "mtl-conventions",
        &[("s.toml", &toml), ("a.obj", GOOD_OBJ), ("m.mtl", &mtl)],
    );
    match Scene::load(dir.path("s.toml")) {
        Ok(s) => {
            let id = s.material_names.iter().position(|n| n == "white").unwrap();
            Ok((s.materials[id].clone(), s.warnings.clone()))
        }
        Err(e) => {
            assert!(e.file.ends_with("m.mtl"), "{e}: names {:?}", e.file);
            assert!(e.to_string().contains("material `white`"), "{e}");
            Err(e.to_string())
        }
    }
}

/// The MTL table (the module doc of `src/load/mtl.rs`), row by row: what each key draws,
/// which approximations warn (naming the file and material) and what is refused (naming
/// file, material and key).
#[test]
fn mtl_files_follow_the_documented_table() {
    let v = |x: f32| Vec3::splat(x);
    let ok = |lines: &str| white_as(lines, "ke").unwrap_or_else(|e| panic!("{lines}: {e}"));
    let quiet = |lines: &str| {
        let (m, w) = ok(lines);
        assert!(w.is_empty(), "{lines}: {w:?}");
        m
    };
    let warned = |lines: &str, what: &str| {
        let (m, w) = ok(lines);
        assert!(
            w.iter()
                .any(|w| w.contains(what) && w.contains("m.mtl: material `white`")),
            "{lines}: no warning saying `{what}`: {w:?}"
        );
        m
    };
    let refused = |lines: &str, emission: &str, key: &str| match white_as(lines, emission) {
        Ok(m) => panic!("{lines}: accepted as {m:?}"),
        Err(e) => assert!(e.contains(key), "{lines}: `{e}` does not name `{key}`"),
    };
    // Diffuse.
    assert_eq!(
        quiet("Kd 0.5 0.5 0.5\nillum 1"),
        Material::Lambertian { albedo: v(0.5) }
    );
    assert_eq!(
        quiet("Kd 0.5 0.5 0.5\nillum 0"),
        Material::Lambertian { albedo: v(0.5) }
    );
    warned(
        "Kd 0.5 0.5 0.5\nKs 0.3 0.3 0.3\nillum 1",
        "`Ks 0.3 0.3 0.3` is not drawn",
    );
    // Glossy: Walter et al.'s alpha = sqrt(2 / (Ns + 2)).
    assert_eq!(
        quiet("Kd 0.5 0.5 0.5\nKs 0.3 0.3 0.3\nNs 200\nillum 2"),
        Material::Glossy {
            albedo: v(0.5),
            specular: v(0.3),
            alpha: (2.0f32 / 202.0).sqrt()
        }
    );
    // McGuire's glossy box: Kd 0.66 + Ks 0.9 scaled to sum to 1 in each channel.
    let Material::Glossy {
        albedo, specular, ..
    } = warned(
        "Kd 0.66 0.66 0.66\nKs 0.9 0.9 0.9\nNs 40\nillum 2",
        "exceeds 1",
    )
    else {
        panic!("not glossy")
    };
    assert!((albedo.x - 0.66 / 1.56).abs() < 1e-6 && (specular.x - 0.9 / 1.56).abs() < 1e-6);
    // Scaled sums that round a hair above 1 still load; a mirror-like exponent takes the
    // smallest roughness.
    for (kd, ks) in [
        ("0.66 0.33 0.1", "0.9 0.8 0.95"),
        ("0.7 0.61 0.57", "0.31 0.77 0.83"),
    ] {
        warned(&format!("Kd {kd}\nKs {ks}\nNs 10\nillum 2"), "exceeds 1");
    }
    let Material::Glossy { alpha, .. } = quiet("Kd 0.3 0.3 0.3\nKs 0.7 0.7 0.7\nNs 1e12\nillum 2")
    else {
        panic!("not glossy")
    };
    assert_eq!(alpha, 1e-4);
    assert_eq!(
        quiet("Kd 0.5 0.5 0.5\nKs 0 0 0\nillum 2"),
        Material::Lambertian { albedo: v(0.5) }
    );
    // Mirrors.
    assert_eq!(
        quiet("Kd 0 0 0\nKs 0.9 0.8 0.7\nillum 3"),
        Material::Mirror {
            reflectance: Vec3::new(0.9, 0.8, 0.7)
        }
    );
    assert_eq!(
        quiet("Kd 0 0 0\nillum 3"),
        Material::Mirror {
            reflectance: v(1.0)
        }
    );
    warned(
        "Kd 0 0 0\nKs 0.9 0.9 0.9\nillum 5",
        "illum 5 (Fresnel reflection)",
    );
    warned("Kd 0 0 0\nKs 0.9 0.9 0.9\nillum 8", "illum 8");
    warned(
        "Kd 0.5 0.5 0.5\nKs 0.9 0.9 0.9\nillum 3",
        "`Kd 0.5 0.5 0.5` is not used",
    );
    // Glass.
    assert_eq!(quiet("Ni 1.33\nillum 7"), Material::glass(1.33));
    assert_eq!(quiet("Ni 1.5\nillum 4"), Material::glass(1.5));
    assert_eq!(quiet("Kd 0.5 0.5 0.5\nNi 1.4\nd 0.2"), Material::glass(1.4));
    assert_eq!(
        warned("illum 4", "drawn with index 1.5"),
        Material::glass(1.5)
    );
    warned("Ni 1.5\nillum 6", "illum 6");
    warned("Ni 1.5\nillum 9", "illum 9");
    warned(
        "Ni 1.5\nKs 0.5 0.5 0.5\nillum 7",
        "glass reflects by the Fresnel",
    );
    assert_eq!(quiet("Ni 1.5\nTr 0.9\nillum 7"), Material::glass(1.5));
    // `d` and `Tr` both: `d` is used, with a warning where they disagree.
    assert_eq!(
        quiet("Ni 1.5\nd 0.1\nTr 0.9\nillum 7"),
        Material::glass(1.5)
    );
    assert_eq!(
        warned("Kd 0.5 0.5 0.5\nd 1\nTr 0.5", "`d` is used"),
        Material::Lambertian { albedo: v(0.5) }
    );
    // Course metal.
    assert_eq!(
        quiet("Ks 0.96 0.98 0.96\nillum 11"),
        Material::Metal {
            reflectance: Vec3::new(0.96, 0.98, 0.96)
        }
    );
    // Warned and drawn without.
    warned("Kd 0.5 0.5 0.5\nbump n.png", "`bump n.png`");
    warned("Kd 0.5 0.5 0.5\nrefl r.png", "`refl r.png`");
    warned("Kd 0.5 0.5 0.5\nTf 0.5 0.5 0.5", "`Tf 0.5 0.5 0.5`");
    // Refused, naming the key.
    refused("Kd 0.5 0.5 0.5\nillum 10", "ke", "illum 10");
    refused("Kd 0.5 0.5 0.5\nillum 12", "ke", "unknown illum code 12");
    refused(
        "Kd 0.5 0.5 0.5\nmap_Kd wood.png",
        "ke",
        "`map_Kd wood.png`: ",
    ); // missing
    refused(
        "Kd 0.5 0.5 0.5\nKs 0.5 0.5 0.5\nmap_Ks s.png\nillum 2",
        "ke",
        "map_Ks",
    );
    // Coloured glass: `Tf` is the transmittance (grey with one number); out of [0, 1] refused.
    let tinted = |ior: f32, t: Vec3| Material::Dielectric {
        ior,
        transmittance: t,
        absorption: Vec3::ZERO,
    };
    assert_eq!(
        quiet("Ni 1.5\nTf 0.9 0.5 0.5\nillum 7"),
        tinted(1.5, Vec3::new(0.9, 0.5, 0.5))
    );
    // Glass keeping under half the light in every channel is drawn so, with a warning naming
    // the other reading.
    assert_eq!(
        warned("Ni 1.5\nTf 0.25\nillum 4", "tf = \"absorbed\""),
        tinted(1.5, v(0.25))
    );
    assert_eq!(
        quiet("Kd 0.5 0.5 0.5\nNi 1.4\nd 0.2\nTf 0.2 0.4 0.6"),
        tinted(1.4, Vec3::new(0.2, 0.4, 0.6))
    );
    refused("Ni 1.5\nTf 1.2 0.5 0.5\nillum 7", "ke", "`Tf 1.2 0.5 0.5`");
    refused(
        "Ni 1.5\nTf -0.1 0.5 0.5\nillum 9",
        "ke",
        "must lie in [0, 1]",
    );
    refused("Ni 1.5\nTf nan 0.5 0.5\nillum 4", "ke", "`Tf nan 0.5 0.5`");
    // A negative or NaN `Ni` on glass is no exporter's "unset" (`Ni 0` is: warned above).
    refused("Ni nan\nillum 7", "ke", "`Ni NaN`");
    refused("Ni -1.5\nillum 4", "ke", "`Ni -1.5`");
    warned("Ni 0\nillum 7", "`Ni 0`): drawn with index 1.5");
    // `Ks` is checked before the model is chosen, whatever the `illum`.
    refused(
        "Kd 0.5 0.5 0.5\nKs -0.5 -0.5 -0.5\nillum 2",
        "ke",
        "`Ks -0.5 -0.5 -0.5`",
    );
    refused("Kd 0.5 0.5 0.5\nKs nan 0 0\nillum 1", "ke", "`Ks NaN 0 0`");
    refused("Kd 0.5 0.5 0.5\nd 0.5", "ke", "opacity 0.5");
    refused("Kd 0.5 0.5 0.5\nTr 0.5", "ke", "opacity 0.5");
    refused("Kd 0.5 0.5 0.5\nPr 0.5", "ke", "`Pr 0.5`");
    refused(
        "Kd 0.5 0.5 0.5\nNs -1\nKs 0.5 0.5 0.5\nillum 2",
        "ke",
        "`Ns -1`",
    );
    // A lamp with both Ka and Ke, emission read from Ka: Ke would be dropped.
    refused(
        "Kd 0 0 0\nKa 12 12 12\nKe 5 5 5",
        "ka",
        "`Ke 5 5 5` is not read",
    );
}

/// `[[mesh]] tf = "absorbed"` (G3D's reading of `Tf`): glass keeps `1 - Tf` at each
/// crossing; an absent `Tf` is clear glass either way; `Tf` on an opaque surface is warned
/// about as under the spec's reading; glass that would keep under half the light is drawn so
/// with a warning naming `tf = "transmitted"`.
#[test]
fn tf_absorbed_reads_tf_as_g3d_does() {
    let absorbed = |lines: &str| {
        white_with(lines, "ke", "tf = \"absorbed\"\n").unwrap_or_else(|e| panic!("{lines}: {e}"))
    };
    let glass = |ior: f32, t: Vec3| Material::Dielectric {
        ior,
        transmittance: t,
        absorption: Vec3::ZERO,
    };
    // McGuire's glass ball and water.
    let (m, w) = absorbed("Kd 0.01 0.01 0.01\nNi 1.5\nTf 0.10 0.10 0.10\nillum 4");
    assert_eq!(m, glass(1.5, Vec3::splat(0.9)));
    assert!(!w.iter().any(|w| w.contains("absorbs most")), "{w:?}");
    let (m, _) = absorbed("Ni 1.33\nTf 0.10 0.10 0.0\nillum 7");
    assert_eq!(m, glass(1.33, Vec3::new(0.9, 0.9, 1.0)));
    let (m, w) = absorbed("Ni 1.5\nillum 7");
    assert_eq!(m, glass(1.5, Vec3::ONE));
    assert!(w.is_empty(), "{w:?}");
    let (m, w) = absorbed("Ni 1.5\nTf 0.9 0.8 0.95\nillum 4");
    assert_eq!(m, glass(1.5, Vec3::ONE - Vec3::new(0.9, 0.8, 0.95)));
    assert!(
        w.iter()
            .any(|w| w.contains("absorbs most") && w.contains("tf = \"transmitted\"")),
        "{w:?}"
    );
    let (m, w) = absorbed("Kd 0.5 0.5 0.5\nTf 0.5 0.5 0.5");
    assert_eq!(
        m,
        Material::Lambertian {
            albedo: Vec3::splat(0.5)
        }
    );
    assert!(w.iter().any(|w| w.contains("`Tf 0.5 0.5 0.5`")), "{w:?}");
    // Out of [0, 1] is refused under either reading.
    let e = white_with(
        "Ni 1.5\nTf 1.2 0.5 0.5\nillum 7",
        "ke",
        "tf = \"absorbed\"\n",
    );
    assert!(e.is_err_and(|e| e.contains("`Tf 1.2 0.5 0.5`")));
}
