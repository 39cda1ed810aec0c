//! Lights: missing or absurd ones refused, point, spot and infinite lights' power and photons.

use super::{GOOD_MTL, GOOD_OBJ, Scratch, close, encoded, error_of, scene_toml};
use crate::{Light, Scene};
use glam::Vec3;

#[test]
fn a_scene_without_light_is_refused_with_a_hint() {
    let mtl = GOOD_MTL.replace("Ke 4 4 4", "Ka 4 4 4");
    error_of(
        "nolight",
        &[
            ("s.toml", &scene_toml("a.obj")),
            ("a.obj", GOOD_OBJ),
            ("m.mtl", &mtl),
        ],
        "s.toml",
        "no light",
    );
    error_of(
        "nolight2",
        &[
            ("s.toml", &scene_toml("a.obj")),
            ("a.obj", GOOD_OBJ),
            ("m.mtl", &mtl),
        ],
        "s.toml",
        "emission = \"ka\"",
    );
}

#[test]
fn zero_area_light_is_refused() {
    let obj = GOOD_OBJ
        .replace("v 0.1 1 0.1", "v -0.1 1 -0.1")
        .replace("v 0.1 1 -0.1", "v -0.1 1 -0.1");
    error_of(
        "zeroarea",
        &[
            ("s.toml", &scene_toml("a.obj")),
            ("a.obj", &obj),
            ("m.mtl", GOOD_MTL),
        ],
        "s.toml",
        "zero-area light",
    );
}

#[test]
fn absurd_light_power_or_size_is_refused_not_overflowed() {
    // Finite emission times area can overflow f32 power, which used to panic downstream.
    let mtl = GOOD_MTL.replace("Ke 4 4 4", "Ke 3e38 3e38 3e38");
    let toml = scene_toml("a.obj").replace("obj = \"a.obj\"", "obj = \"a.obj\"\nscale = 4");
    error_of(
        "power",
        &[("s.toml", &toml), ("a.obj", GOOD_OBJ), ("m.mtl", &mtl)],
        "s.toml",
        "overflows f32",
    );
    let mtl = GOOD_MTL.replace("Ke 4 4 4", "Ke 3e38 0 0");
    let toml = scene_toml("a.obj").replace("obj = \"a.obj\"", "obj = \"a.obj\"\nscale = 40");
    error_of(
        "power1",
        &[("s.toml", &toml), ("a.obj", GOOD_OBJ), ("m.mtl", &mtl)],
        "s.toml",
        "overflows f32",
    );
    let toml = scene_toml("a.obj").replace("obj = \"a.obj\"", "obj = \"a.obj\"\nscale = 1e25");
    error_of(
        "huge",
        &[("s.toml", &toml), ("a.obj", GOOD_OBJ), ("m.mtl", GOOD_MTL)],
        "a.obj",
        "check the scale",
    );
}

/// The good scene with its lamp dark and `lights` (TOML `[[light]]` tables) added.
fn delta_scene(name: &str, lights: &str) -> (Scratch, Scene) {
    let mtl = GOOD_MTL.replace("Ke 4 4 4", "Ke 0 0 0");
    let toml = scene_toml("a.obj") + lights;
    let dir = Scratch::new(
        name,
        &[("s.toml", &toml), ("a.obj", GOOD_OBJ), ("m.mtl", &mtl)],
    );
    let s = Scene::load(dir.path("s.toml")).unwrap_or_else(|e| panic!("{e}"));
    (dir, s)
}

/// Summed flux of `n x n` stratified photons (centres of a grid over `u_dir`), f64.
fn emitted_power(s: &Scene, n: u32) -> glam::DVec3 {
    let total = (n * n) as u64;
    let mut sum = glam::DVec3::ZERO;
    for i in 0..n {
        for j in 0..n {
            let u = [(i as f32 + 0.5) / n as f32, (j as f32 + 0.5) / n as f32];
            let e = s.light_table.emit(0.5, [0.5, 0.5], u, total);
            assert!(e.ray.d.is_normalized(), "{:?}", e.ray.d);
            sum += e.flux;
        }
    }
    sum
}

/// A point light's power is `4π I`; its photons, summed, carry exactly that (each carries
/// `Φ / N`). Broken to `2π I` (a hemisphere) the sum misses by 50%.
#[test]
fn point_light_power_and_photons() {
    let (_d, s) = delta_scene(
        "point",
        "[[light]]\ntype = \"point\"\nposition = [0, 0.5, 0]\nintensity = [1, 2, 3]\n",
    );
    assert!(s.lights.is_empty());
    assert_eq!(s.light_table.len(), 1);
    let want = 4.0 * std::f64::consts::PI * glam::DVec3::new(1.0, 2.0, 3.0);
    let got = s.light_table.total_power();
    assert!(((got - want) / want).abs().max_element() < 1e-6, "{got}");
    let sum = emitted_power(&s, 100);
    let rel = ((sum - want) / want).abs().max_element();
    eprintln!("point light: photon power {sum} against 4 pi I = {want}: {rel:.2e}");
    assert!(rel < 1e-3, "{rel}");
    // NEE: `I / r²` towards a point 2 below it, chosen with probability 1.
    let ls = s
        .light_table
        .sample(Vec3::new(0.0, -1.5, 0.0), 0.3, [0.2, 0.7])
        .unwrap();
    assert!(ls.delta && ls.pdf == 1.0 && ls.dist == 2.0);
    assert!(close(ls.le, Vec3::new(0.25, 0.5, 0.75), 1e-6), "{}", ls.le);
}

/// A spot's power `2π I ∫ falloff sin θ dθ` in closed form against a midpoint quadrature of
/// Mitsuba's falloff, and its photons' summed flux against it (stratified in `cos θ`, so the
/// falloff's kinks cost a little). Measured: closed form against quadrature 3.2e-9
/// relative, photons 1.3e-6 (a point light's photons: 1.3e-13).
#[test]
fn spot_light_power_and_photons() {
    let (_d, s) = delta_scene(
        "spot",
        "[[light]]\ntype = \"spot\"\nposition = [0, 0.5, 0]\nlook_at = [0.3, 0, 0]\n\
         intensity = [1, 2, 3]\ncutoff_angle = 40\nbeam_width = 15\n",
    );
    let Some(Light::Spot(spot)) = s.light_table.light(0).cloned() else {
        panic!("not a spot light")
    };
    // Midpoint rule over θ in f64, with Mitsuba's falloff written out.
    let (c, b) = (40f64.to_radians(), 15f64.to_radians());
    let n = 200_000;
    let quad: f64 = (0..n)
        .map(|k| {
            let t = (k as f64 + 0.5) / n as f64 * c;
            let f = if t <= b { 1.0 } else { (c - t) / (c - b) };
            f * t.sin() * c / n as f64
        })
        .sum();
    let closed = spot.solid_angle_fraction();
    eprintln!("spot: closed form {closed}, quadrature {quad}");
    assert!((closed - quad).abs() / quad < 1e-6);
    let want = std::f64::consts::TAU * quad * glam::DVec3::new(1.0, 2.0, 3.0);
    let got = s.light_table.total_power();
    assert!(
        ((got - want) / want).abs().max_element() < 1e-6,
        "{got} {want}"
    );
    let sum = emitted_power(&s, 300);
    let rel = ((sum - want) / want).abs().max_element();
    eprintln!("spot: photon power {sum} against {want}: {rel:.2e}");
    assert!(rel < 1e-3, "{rel}");
    // Every photon leaves inside the cutoff cone.
    let axis = spot.frame.n;
    for i in 0..64 {
        let e = s
            .light_table
            .emit(0.5, [0.5; 2], [i as f32 / 64.0, 0.3], 64);
        assert!(e.ray.d.dot(axis) >= c.cos() as f32 - 1e-6);
    }
    // The falloff: 1 inside the beam, half way down the ramp at its middle, 0 past the cutoff.
    assert_eq!(spot.falloff(10f32.to_radians().cos()), 1.0);
    assert!((spot.falloff(27.5f32.to_radians().cos()) - 0.5).abs() < 1e-4);
    assert_eq!(spot.falloff(41f32.to_radians().cos()), 0.0);
}

#[test]
fn bad_delta_lights_are_named() {
    let cases = [
        (
            "type = \"point\"\nposition = [0, 1, 0]\nintensity = [1, nan, 1]",
            "light 0 (point): intensity must be finite and >= 0",
        ),
        (
            "type = \"spot\"\nposition = [0, 1, 0]\nlook_at = [0, 0, 0]\nintensity = [1, 1, 1]\ncutoff_angle = 95",
            "light 0 (spot): cutoff_angle = 95 must be in (0, 90] degrees",
        ),
        (
            "type = \"spot\"\nposition = [0, 1, 0]\nlook_at = [0, 0, 0]\nintensity = [1, 1, 1]\nbeam_width = 30",
            "light 0 (spot): beam_width = 30 must be in [0, cutoff_angle = 20] degrees",
        ),
    ];
    for (i, (light, problem)) in cases.iter().enumerate() {
        let toml = scene_toml("a.obj") + "[[light]]\n" + light + "\n";
        error_of(
            &format!("bad-delta-{i}"),
            &[("s.toml", &toml), ("a.obj", GOOD_OBJ), ("m.mtl", GOOD_MTL)],
            "s.toml",
            problem,
        );
    }
}

/// An EXR file to write beside a scene: name, width, height and texel function.
type ExrFile<'a> = (&'a str, u32, u32, &'a dyn Fn(u32, u32) -> [f32; 3]);

/// The good scene with its lamp dark, `lights` added and `exr` (name, width, height, texel
/// function) written beside it as a float EXR.
fn infinite_scene(name: &str, lights: &str, exr: Option<ExrFile>) -> (Scratch, Scene) {
    let mtl = GOOD_MTL.replace("Ke 4 4 4", "Ke 0 0 0");
    let toml = scene_toml("a.obj") + lights;
    let dir = Scratch::new(
        name,
        &[("s.toml", &toml), ("a.obj", GOOD_OBJ), ("m.mtl", &mtl)],
    );
    if let Some((file, w, h, f)) = exr {
        let img = image::DynamicImage::ImageRgb32F(image::Rgb32FImage::from_fn(w, h, |x, y| {
            image::Rgb(f(x, y))
        }));
        std::fs::write(dir.path(file), encoded(img, image::ImageFormat::OpenExr)).unwrap();
    }
    let s = Scene::load(dir.path("s.toml")).unwrap_or_else(|e| panic!("{e}"));
    (dir, s)
}

/// `∫ L dω` over the sphere of light `i` at infinity, by the midpoint rule in `(cos θ, φ)`
/// (uniform in solid angle), f64.
fn radiance_quadrature(s: &Scene, i: usize, n: usize) -> glam::DVec3 {
    let l = s.light_table.light(i).unwrap();
    let mut sum = glam::DVec3::ZERO;
    for a in 0..n {
        let z = 1.0 - 2.0 * (a as f64 + 0.5) / n as f64;
        let r = (1.0 - z * z).sqrt();
        for b in 0..2 * n {
            let phi = std::f64::consts::PI * (b as f64 + 0.5) / n as f64;
            let d = glam::DVec3::new(r * phi.cos(), z, r * phi.sin()).as_vec3();
            sum += l.le(d).as_dvec3();
        }
    }
    sum * (4.0 * std::f64::consts::PI / (2 * n * n) as f64)
}

/// Lights at infinity: the photons' summed flux equals `LightTable::power`, and that power
/// equals the closed form `π R² ∫ L dω` with `R` the half-diagonal of the scene's bounds (the
/// good scene spans [-1, 1] x [0, 1] x [-1, 1]: `R = 1.5`): `π R² E` for a directional light,
/// `π R² 2E/(1 + cos α)` for a sun disc, `π R² 4π L` for a constant environment (given as a
/// colour or as a constant image), and for a non-constant image the quadrature of its
/// radiance over the sphere. Point and spot lights: `point_light_power_and_photons` and
/// `spot_light_power_and_photons` above. Measured: powers against the closed forms 0 to
/// 3.4e-8 relative (the sun 5.7e-6: its `cos α` in f32); photon sums over a 1000 x 1000
/// grid of `u_dir` 4e-12 to 6e-9 (environments 4e-8), the non-constant image 2.8e-4 (1.0e-3
/// on a 300 x 300 grid: the grid's error at the patch edges, falling as 1/n), the
/// quadrature of the non-constant image 3.4e-8. Tried: the photons' disc area `R²` in
/// place of `π R²` (`emit_infinite`) fails the first case, the directional light's photon
/// sum, by 68%.
#[test]
fn infinite_light_power_and_photons() {
    use glam::DVec3;
    use std::f64::consts::PI;
    let e = DVec3::new(1.0, 2.0, 3.0);
    let l = DVec3::new(0.25, 0.5, 1.0);
    let alpha = 5f64.to_radians();
    let grad = |x: u32, y: u32| [1.0 + x as f32, 0.5 + 2.0 * y as f32, 3.0 + (x * y) as f32];
    let cases: [(&str, String, Option<ExrFile>, DVec3); 5] = [
        (
            "directional",
            "type = \"directional\"\ndirection = [1, -2, 0.5]\nirradiance = [1, 2, 3]\n".into(),
            None,
            e,
        ),
        (
            "sun",
            "type = \"directional\"\ndirection = [1, -2, 0.5]\nirradiance = [1, 2, 3]\n\
             angular_radius = 5\n"
                .into(),
            None,
            2.0 * e / (1.0 + alpha.cos()),
        ),
        (
            "constant environment",
            "type = \"environment\"\nradiance = [0.25, 0.5, 1]\n".into(),
            None,
            4.0 * PI * l,
        ),
        (
            "constant image environment",
            "type = \"environment\"\nfilename = \"env.exr\"\nscale = 0.5\nrotate = [10, 20, 30]\n"
                .into(),
            Some(("env.exr", 8, 5, &|_, _| [0.5, 1.0, 2.0])),
            4.0 * PI * l,
        ),
        (
            "image environment",
            "type = \"environment\"\nfilename = \"env.exr\"\nscale = 2\n".into(),
            Some(("env.exr", 6, 4, &grad)),
            DVec3::ZERO, // the quadrature below
        ),
    ];
    for (k, (what, light, exr, integral)) in cases.into_iter().enumerate() {
        let (_d, s) = infinite_scene(
            &format!("infinite-power-{k}"),
            &format!("[[light]]\n{light}"),
            exr,
        );
        assert!(s.lights.is_empty() && s.light_table.len() == 1, "{what}");
        let b = s.geometry.bounds();
        let half_diag = (0.5 * (b.max - b.min)).length();
        let r = s.light_table.scene_radius();
        assert!(
            (r - 1.5).abs() < 1e-6 && (r - half_diag).abs() < 1e-6,
            "{what}: R = {r}"
        );
        let integral = if integral == DVec3::ZERO {
            let q = radiance_quadrature(&s, 0, 1000);
            let int = s.light_table.light(0).unwrap().integral();
            let rel = ((q - int) / int).abs().max_element();
            eprintln!("{what}: ∫ L dω {int}, quadrature {q}: {rel:.1e}");
            assert!(rel < 1e-4, "{what}: {int} against quadrature {q}");
            q
        } else {
            integral
        };
        let want = PI * 1.5f64.powi(2) * integral;
        let got = s.light_table.power(0);
        let rel_power = ((got - want) / want).abs().max_element();
        let sum = emitted_power(&s, 1000);
        let rel_sum = ((sum - got) / got).abs().max_element();
        eprintln!(
            "{what}: power {got} against {want}: {rel_power:.1e}; photons {sum}: {rel_sum:.1e}"
        );
        assert!(rel_power < 1e-4, "{what}: power {got} against {want}");
        assert!(rel_sum < 1e-3, "{what}: photons {sum} against {got}");
        assert_eq!(s.light_table.total_power(), got, "{what}");
    }
}
