//! Textures: decoding to linear RGB, bilinear lookup, `map_Kd` and its errors.

use super::{GOOD_MTL, GOOD_OBJ, Scratch, close, encoded, scene_toml};
use crate::{Material, Scene};
use glam::Vec3;
use std::path::Path;

/// A `w` x `h` 8-bit RGB image with texel `(x, y)` (row 0 at the top) `f(x, y)`.
fn rgb8(w: u32, h: u32, f: impl Fn(u32, u32) -> [u8; 3]) -> image::DynamicImage {
    image::DynamicImage::ImageRgb8(image::RgbImage::from_fn(w, h, |x, y| image::Rgb(f(x, y))))
}

/// sRGB's decoding (IEC 61966-2-1) in f64, written out apart from the renderer's.
fn srgb8(v: u8) -> f32 {
    let c = v as f64 / 255.0;
    (if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }) as f32
}

#[test]
fn textures_decode_to_linear_and_filter_bilinearly() {
    use crate::Texture;
    use glam::Vec2;
    // 8-bit sRGB → linear, per texel, row 0 at the top.
    let px = |x: u32, y: u32| [[188, 20, 0], [255, 128, 3]][((x + y) % 2) as usize];
    let png = encoded(rgb8(2, 2, px), image::ImageFormat::Png);
    let t = Texture::decode(&png, Path::new("t.png")).unwrap();
    assert_eq!((t.width, t.height), (2, 2));
    for (i, c) in t.texels.iter().enumerate() {
        let want = px(i as u32 % 2, i as u32 / 2).map(srgb8);
        assert!(
            close(*c, Vec3::from(want), 1e-6),
            "texel {i}: {c} != {want:?}"
        );
    }
    // Bilinear with texel centres at half-integers, v up the image: the centre of texel
    // (x, y) is uv ((x + 0.5) / w, 1 - (y + 0.5) / h) and reads it exactly.
    let at = |x: usize, y: usize| t.texels[y * 2 + x];
    for (x, y) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
        let uv = Vec2::new((x as f32 + 0.5) / 2.0, 1.0 - (y as f32 + 0.5) / 2.0);
        assert!(close(t.eval(uv), at(x, y), 1e-6), "centre of ({x}, {y})");
    }
    // Midway between all four: their mean. Repeat: whole periods away reads the same.
    let mean = (at(0, 0) + at(1, 0) + at(0, 1) + at(1, 1)) / 4.0;
    assert!(close(t.eval(Vec2::splat(0.5)), mean, 1e-6));
    let uv = Vec2::new(0.3, 0.8);
    assert!(close(t.eval(uv + Vec2::new(3.0, -2.0)), t.eval(uv), 1e-5));
    // Across the edge u = 0 the left column blends with the right one (wrap, not clamp).
    let edge = t.eval(Vec2::new(0.0, 0.75));
    assert!(close(edge, (at(0, 0) + at(1, 0)) / 2.0, 1e-6), "{edge}");
    // Float images are linear already; grey ones read as equal channels.
    let exr = image::DynamicImage::ImageRgb32F(image::Rgb32FImage::from_fn(1, 1, |_, _| {
        image::Rgb([0.3, 0.6, 0.9])
    }));
    let t = Texture::decode(
        &encoded(exr, image::ImageFormat::OpenExr),
        Path::new("t.exr"),
    )
    .unwrap();
    assert!(close(t.texels[0], Vec3::new(0.3, 0.6, 0.9), 1e-6));
    let grey =
        image::DynamicImage::ImageLuma8(image::GrayImage::from_fn(1, 1, |_, _| image::Luma([100])));
    let t = Texture::decode(&encoded(grey, image::ImageFormat::Png), Path::new("t.png")).unwrap();
    assert!(close(t.texels[0], Vec3::splat(srgb8(100)), 1e-6));
    // TGA exactly, JPEG (lossy) within two levels of a flat colour.
    let flat = rgb8(8, 8, |_, _| [200, 120, 40]);
    let t = Texture::decode(
        &encoded(flat.clone(), image::ImageFormat::Tga),
        Path::new("t.tga"),
    )
    .unwrap();
    assert!(close(
        t.texels[0],
        Vec3::from([200, 120, 40].map(srgb8)),
        1e-6
    ));
    let t = Texture::decode(&encoded(flat, image::ImageFormat::Jpeg), Path::new("t.jpg")).unwrap();
    let tol = srgb8(202) - srgb8(200);
    assert!(close(
        t.texels[27],
        Vec3::from([200, 120, 40].map(srgb8)),
        tol
    ));
    // Not an image, or an empty one: one line saying so.
    let e = Texture::decode(b"P3 this is not an image", Path::new("t.png")).unwrap_err();
    assert!(
        e.contains("not a PNG, JPEG, TGA, EXR or Radiance HDR"),
        "{e}"
    );
}

/// The albedo of `scene` seen straight down at `(x, z)` of the y = 0 floor.
fn floor_albedo(scene: &Scene, x: f32, z: f32) -> Vec3 {
    let ray = geom::Ray::new(Vec3::new(x, 0.5, z), Vec3::NEG_Y);
    let hit = scene.geometry.intersect(&ray).expect("the floor");
    scene
        .bsdf_at(&hit)
        .and_then(|b| b.diffuse_albedo())
        .unwrap()
}

#[test]
fn map_kd_multiplies_kd_at_the_obj_texture_coordinates() {
    // The floor of GOOD_OBJ spans x, z in [-1, 1]; vt u = (x + 1) / 2, v = (1 - z) / 2 ... as
    // given per corner below, so the texture's left column lies at x < 0, its top row at z < 0.
    let obj = GOOD_OBJ.replace(
        "v 1 0 -1\nf 1 2 3\nf 1 3 4\n",
        "v 1 0 -1\nvt 0 1\nvt 0 0\nvt 1 0\nvt 1 1\nf 1/1 2/2 3/3\nf 1/1 3/3 4/4\n",
    );
    let px = |x: u32, y: u32| {
        [
            [[250, 10, 10], [10, 250, 10]],
            [[10, 10, 250], [128, 128, 128]],
        ][y as usize][x as usize]
    };
    let png = encoded(rgb8(2, 2, px), image::ImageFormat::Png);
    // Each scene in a directory of its own: a test's scratch directories share a name.
    let n = std::cell::Cell::new(0);
    let setup = |mtl: &str, obj: &str, toml: &str| {
        n.set(n.get() + 1);
        let dir = Scratch::new(
            &format!("map-kd-{}", n.get()),
            &[("s.toml", toml), ("a.obj", obj), ("m.mtl", mtl)],
        );
        std::fs::write(dir.path("t.png"), &png).unwrap();
        dir
    };
    let mtl = GOOD_MTL.replace("Kd 0.5 0.5 0.5", "Kd 0.5 0.5 0.5\nmap_Kd t.png");
    let dir = setup(&mtl, &obj, &scene_toml("a.obj"));
    let s = Scene::load(dir.path("s.toml")).unwrap_or_else(|e| panic!("{e}"));
    assert!(s.warnings.is_empty(), "{:?}", s.warnings);
    // Texel centres at x, z = +-0.5: Kd times the decoded texel.
    for (x, z, tx, ty) in [
        (-0.5, -0.5, 0, 0),
        (0.5, -0.5, 1, 0),
        (-0.5, 0.5, 0, 1),
        (0.5, 0.5, 1, 1),
    ] {
        let want = 0.5 * Vec3::from(px(tx, ty).map(srgb8));
        let got = floor_albedo(&s, x, z);
        assert!(close(got, want, 1e-5), "({x}, {z}): {got} != {want}");
    }
    // The image's bytes key the caches: another texture, another photon set.
    let other = encoded(rgb8(2, 2, |_, _| [1, 2, 3]), image::ImageFormat::Png);
    let dir2 = setup(&mtl, &obj, &scene_toml("a.obj"));
    std::fs::write(dir2.path("t.png"), &other).unwrap();
    let s2 = Scene::load(dir2.path("s.toml")).unwrap();
    assert_ne!(s.photon_hash, s2.photon_hash);
    assert_ne!(s.content_hash, s2.content_hash);
    // No `Kd`: the texture as it is.
    let s = Scene::load(
        setup(
            &GOOD_MTL.replace("Kd 0.5 0.5 0.5", "map_Kd t.png"),
            &obj,
            &scene_toml("a.obj"),
        )
        .path("s.toml"),
    )
    .unwrap();
    assert!(close(
        floor_albedo(&s, 0.5, 0.5),
        Vec3::splat(srgb8(128)),
        1e-5
    ));
    // The scene file's `texture` key does the same for its own materials.
    let toml = format!(
        "{}[material.white]\ntype = \"lambertian\"\nalbedo = [0.5, 0.5, 0.5]\ntexture = \"t.png\"\n",
        scene_toml("a.obj")
    );
    let s = Scene::load(setup(GOOD_MTL, &obj, &toml).path("s.toml")).unwrap();
    assert!(close(
        floor_albedo(&s, -0.5, 0.5),
        0.5 * Vec3::from(px(0, 1).map(srgb8)),
        1e-5
    ));
    // Glossy: `Kd` x the brightest texel + `Ks` above 1 (an EXR texel of 2) scales both
    // there, with a warning.
    let bright = image::DynamicImage::ImageRgb32F(image::Rgb32FImage::from_fn(1, 1, |_, _| {
        image::Rgb([2.0, 0.5, 0.5])
    }));
    let glossy = GOOD_MTL.replace(
        "Kd 0.5 0.5 0.5",
        "Kd 0.5 0.5 0.5\nKs 0.4 0.4 0.4\nNs 100\nillum 2\nmap_Kd t.exr",
    );
    let dir = setup(&glossy, &obj, &scene_toml("a.obj"));
    std::fs::write(
        dir.path("t.exr"),
        encoded(bright, image::ImageFormat::OpenExr),
    )
    .unwrap();
    let s = Scene::load(dir.path("s.toml")).unwrap();
    assert!(
        s.warnings.iter().any(|w| w.contains("brightest texel")),
        "{:?}",
        s.warnings
    );
    let id = s.material_of("white").unwrap() as usize;
    let Material::Glossy { specular, .. } = s.materials[id] else {
        panic!("not glossy")
    };
    // Red: 0.5 x 2 + 0.4 = 1.4 → Ks 0.4 / 1.4 and albedo 1 / 1.4; green and blue untouched.
    assert!(
        close(specular, Vec3::new(0.4 / 1.4, 0.4, 0.4), 1e-6),
        "{specular}"
    );
    let a = floor_albedo(&s, 0.5, 0.5);
    assert!(close(a, Vec3::new(1.0 / 1.4, 0.25, 0.25), 1e-6), "{a}");
    // Warned: a texture on a mirror, a mesh without `vt`.
    let mirror = GOOD_MTL.replace("Kd 0.5 0.5 0.5", "Ks 1 1 1\nillum 3\nmap_Kd t.png");
    let s = Scene::load(setup(&mirror, &obj, &scene_toml("a.obj")).path("s.toml")).unwrap();
    assert!(
        s.warnings
            .iter()
            .any(|w| w.contains("only diffuse and glossy")),
        "{:?}",
        s.warnings
    );
    let s = Scene::load(setup(&mtl, GOOD_OBJ, &scene_toml("a.obj")).path("s.toml")).unwrap();
    assert!(
        s.warnings
            .iter()
            .any(|w| w.contains("no texture coordinates")),
        "{:?}",
        s.warnings
    );
}

#[test]
fn missing_or_broken_textures_are_named() {
    let with = |line: &str, image: Option<&[u8]>| {
        let mtl = GOOD_MTL.replace("Kd 0.5 0.5 0.5", line);
        let dir = Scratch::new(
            "bad-texture",
            &[
                ("s.toml", &scene_toml("a.obj")),
                ("a.obj", GOOD_OBJ),
                ("m.mtl", &mtl),
            ],
        );
        if let Some(b) = image {
            std::fs::write(dir.path("t.png"), b).unwrap();
        }
        match Scene::load(dir.path("s.toml")) {
            Ok(_) => panic!("{line}: loaded"),
            Err(e) => {
                assert!(e.file.ends_with("m.mtl"), "{e}");
                e.to_string()
            }
        }
    };
    let e = with("map_Kd gone.png", None);
    assert!(
        e.contains("material `white`")
            && e.contains("map_Kd gone.png")
            && e.contains("gone.png: cannot read it"),
        "{e}"
    );
    let e = with("map_Kd t.png", Some(b"not an image at all"));
    assert!(
        e.contains("t.png") && e.contains("not a PNG, JPEG, TGA, EXR or Radiance HDR"),
        "{e}"
    );
    let e = with("map_Kd -s 2 2 1 t.png", None);
    assert!(e.contains("texture options"), "{e}");
    let e = with(
        "Kd 0.5 0.5 0.5\nmap_Ks t.png\nKs 0.5 0.5 0.5\nillum 2",
        None,
    );
    assert!(e.contains("only `map_Kd`"), "{e}");
    // The scene file's key names the scene file.
    let toml = format!(
        "{}[material.white]\ntype = \"lambertian\"\nalbedo = [0.5, 0.5, 0.5]\ntexture = \"gone.png\"\n",
        scene_toml("a.obj")
    );
    let dir = Scratch::new(
        "bad-texture-toml",
        &[("s.toml", &toml), ("a.obj", GOOD_OBJ), ("m.mtl", GOOD_MTL)],
    );
    let e = Scene::load(dir.path("s.toml")).err().unwrap();
    assert!(
        e.file.ends_with("s.toml") && e.problem.contains("texture `gone.png`"),
        "{e}"
    );
}

#[test]
fn textured_spheres_read_their_texture_at_phi_and_theta() {
    // A checkerboard sphere beside a plain one. The textured sphere's uv is
    // `(phi / 2pi, theta / pi)` of its normal (phi from +x towards +z in [0, 2pi), theta from
    // +y); the checkerboard is `color0` where the fractional parts of u and 1 - v (Mitsuba's
    // v runs down) are both below one half or both above it. The plain sphere's hits skip
    // the uv (an atan2 and an acos per hit).
    let toml = format!(
        "{}[[sphere]]\ncenter = [0.0, 5.0, 0.0]\nradius = 1.0\nmaterial = \"checks\"\n\
         [[sphere]]\ncenter = [4.0, 5.0, 0.0]\nradius = 1.0\nmaterial = \"plain\"\n\
         [material.checks]\ntype = \"lambertian\"\nalbedo = [1.0, 1.0, 1.0]\n\
         texture = {{ type = \"checkerboard\", color0 = [0.1, 0.2, 0.3], color1 = [0.7, 0.8, 0.9] }}\n\
         [material.plain]\ntype = \"lambertian\"\nalbedo = [0.5, 0.5, 0.5]\n",
        scene_toml("a.obj")
    );
    let dir = Scratch::new(
        "sphere-uv",
        &[("s.toml", &toml), ("a.obj", GOOD_OBJ), ("m.mtl", GOOD_MTL)],
    );
    let s = Scene::load(dir.path("s.toml")).unwrap_or_else(|e| panic!("{e}"));
    let centre = Vec3::new(0.0, 5.0, 0.0);
    let (c0, c1) = (Vec3::new(0.1, 0.2, 0.3), Vec3::new(0.7, 0.8, 0.9));
    // Normals and their (u, v), worked out by hand: (0.046, 0.358), (0.546, 0.358), (0.046,
    // 0.642), (0.546, 0.642).
    for (n, want) in [
        (Vec3::new(1.0, 0.5, 0.3), c1),
        (Vec3::new(-1.0, 0.5, -0.3), c0),
        (Vec3::new(1.0, -0.5, 0.3), c0),
        (Vec3::new(-1.0, -0.5, -0.3), c1),
    ] {
        let n = n.normalize();
        let ray = geom::Ray::new(centre + 3.0 * n, -n);
        let hit = s.geometry.intersect(&ray).expect("the textured sphere");
        let phi = (n.z as f64)
            .atan2(n.x as f64)
            .rem_euclid(std::f64::consts::TAU);
        let theta = (n.y as f64).acos();
        let uv = [phi / std::f64::consts::TAU, theta / std::f64::consts::PI];
        assert!(
            (hit.uv[0] as f64 - uv[0]).abs() < 1e-5 && (hit.uv[1] as f64 - uv[1]).abs() < 1e-5,
            "{n}: uv {:?} != {uv:?}",
            hit.uv
        );
        let albedo = s.bsdf_at(&hit).and_then(|b| b.diffuse_albedo()).unwrap();
        assert!(close(albedo, want, 1e-6), "{n}: {albedo} != {want}");
    }
    let plain = geom::Ray::new(Vec3::new(4.0, 8.0, 0.0), Vec3::NEG_Y);
    let hit = s.geometry.intersect(&plain).expect("the plain sphere");
    assert_eq!(hit.uv, [0.0, 0.0]);
    assert!(close(
        s.bsdf_at(&hit).and_then(|b| b.diffuse_albedo()).unwrap(),
        Vec3::splat(0.5),
        1e-6
    ));
}
