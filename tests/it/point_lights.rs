//! Point and spot lights (Mitsuba 3's `point` and `spot`, pbrt-v4 §12.1-12.2) end to end,
//! against closed forms: a point light of intensity `I` over a diffuse plane of albedo `ρ`
//! gives radiance `ρ/π · I cos θ / r²` at every point of the plane, in the path tracer and
//! in the photon-map methods; a spot gives the same inside its beam and nothing past its
//! cutoff; and a point light behind glass makes a caustic only photons can find.

use crate::kit::{TempDir, dvec3s, layer, pixel, render, render_uncached, worksheet_with};
use glam::{DVec3, Vec3};
use render::Overrides;
use scene::{LightDesc, Method, Scene};

const RHO: f64 = 0.5;
const I: [f32; 3] = [2.0, 1.0, 0.5];
const LIGHT: [f32; 3] = [0.0, 1.0, 0.0];

/// A 100 x 100 floor of albedo `RHO` at y = 0 lit by `light` only, seen by a narrow camera
/// (`res` x `res`, vfov 8) from `[1.5, 1, 2]` looking at `[0.6, 0, 0.3]`: every pixel sees
/// the floor at angles of 30-50 degrees from the light.
fn plane(dir: &TempDir, light: &str, res: u32, seed: u64) -> Scene {
    let obj = "mtllib p.mtl\nusemtl floor\nv -50 0 -50\nv -50 0 50\nv 50 0 50\nv 50 0 -50\n\
               f 1 2 3 4\n";
    std::fs::write(dir.path().join("p.obj"), obj).unwrap_or_else(|e| panic!("{e}"));
    std::fs::write(
        dir.path().join("p.mtl"),
        format!("newmtl floor\nKd {RHO} {RHO} {RHO}\n"),
    )
    .unwrap_or_else(|e| panic!("{e}"));
    let text = format!(
        "seed = {seed}\n[camera]\neye = [1.5, 1, 2]\nlook_at = [0.6, 0, 0.3]\nvfov = 8\n\
         width = {res}\nheight = {res}\n[[mesh]]\nobj = \"p.obj\"\n[[light]]\n{light}\n"
    );
    Scene::from_toml(&dir.path().join("p.toml"), &text).unwrap_or_else(|e| panic!("{e}"))
}

fn point_light() -> String {
    format!("type = \"point\"\nposition = {LIGHT:?}\nintensity = {I:?}")
}

/// The closed form at the floor point seen through pixel `(x, y)`'s centre, with
/// `falloff` the light's intensity factor towards it.
fn expected(scene: &Scene, x: usize, y: usize, falloff: &dyn Fn(Vec3) -> f64) -> DVec3 {
    let ray = scene.camera.ray(x as f32 + 0.5, y as f32 + 0.5);
    let hit = scene.geometry.intersect(&ray).expect("the floor");
    let to = Vec3::from(LIGHT) - hit.point.p;
    let r2 = to.length_squared() as f64;
    let cos = to.normalize().y as f64;
    let w = falloff(-to.normalize());
    Vec3::from(I).as_dvec3() * (RHO / std::f64::consts::PI * cos * w / r2)
}

/// Largest relative miss of `img` against the closed form over all pixels.
fn worst(scene: &Scene, img: &film::Image, falloff: &dyn Fn(Vec3) -> f64) -> f64 {
    let n = scene.camera.width as usize;
    let mut worst = 0.0f64;
    for y in 0..n {
        for x in 0..n {
            let want = expected(scene, x, y, falloff);
            let got = pixel(img, (x, y));
            let rel = ((got - want).abs() / want).max_element();
            worst = worst.max(rel);
        }
    }
    worst
}

/// The path tracer: NEE to the point light alone lights the plane (nothing else reflects, the
/// jittered pixel position is the only noise), so every pixel matches `ρ/π I cos θ / r²` at
/// its centre to the curvature across a pixel. Measured: worst pixel 0.05% off (16 x 16,
/// 16 spp), against a 0.5% bound.
#[test]
fn point_light_over_a_plane_path_tracer() {
    let dir = TempDir::new("point-plane");
    let scene = plane(&dir, &point_light(), 16, 1);
    let o = Overrides {
        method: Some(Method::Path),
        spp: Some(16),
        ..Overrides::default()
    };
    let r = render_uncached(&scene, &o, None);
    let direct = layer(&r, "direct");
    let worst = worst(&scene, direct, &|_| 1.0);
    eprintln!("point light over a plane, path tracer: worst relative miss {worst:.5}");
    assert!(worst < 5e-3, "worst relative miss {worst}");
    for l in ["indirect", "caustic", "emitted"] {
        if let Some(img) = r.layers.iter().find(|x| x.name == l) {
            let s: DVec3 = dvec3s(&img.image).iter().sum();
            assert_eq!(s, DVec3::ZERO, "{l} must be zero");
        }
    }
}

/// SPPM's whole image against the same closed form, averaged over the image (its bias at a
/// smooth, nearly linear irradiance is second order in the radius; its noise is the photon
/// count's). Measured: image mean 0.4% off after 8 passes of 20000 photons.
#[test]
fn point_light_over_a_plane_sppm() {
    let dir = TempDir::new("point-plane-sppm");
    let scene = plane(&dir, &point_light(), 16, 1);
    let o = Overrides {
        method: Some(Method::Sppm),
        passes: Some(8),
        photons: Some(20_000),
        ..Overrides::default()
    };
    let r = render(&scene, &o, &dir.path().join("cache"), None);
    let img = crate::kit::sum_layers(&r, |_| true);
    let n = scene.camera.width as usize;
    let (mut got, mut want) = (DVec3::ZERO, DVec3::ZERO);
    for y in 0..n {
        for x in 0..n {
            got += pixel(&img, (x, y));
            want += expected(&scene, x, y, &|_| 1.0);
        }
    }
    let rel = ((got - want).abs() / want).max_element();
    eprintln!("point light over a plane, sppm: image mean {got} against {want}: {rel:.4}");
    assert!(rel < 0.03, "sppm mean misses by {rel}");
}

/// Light tracing: light paths from the point light joined to the camera where they meet the
/// plane, against the same closed form over the image (each pixel averages the footprint it
/// sees; the noise is the count of paths landing in the view, about 9,000 here, a standard
/// error near 1.1%). Measured: image mean 1.2% off (8 passes of 100,000 paths), against a 4%
/// bound; after 400 passes the image mean is within 0.01% of the path tracer's. The same
/// bits on one thread and two.
#[test]
fn point_light_over_a_plane_light_tracer() {
    let dir = TempDir::new("point-plane-light");
    let scene = plane(&dir, &point_light(), 16, 1);
    let o = Overrides {
        method: Some(Method::Light),
        passes: Some(8),
        photons: Some(100_000),
        ..Overrides::default()
    };
    let r = render_uncached(&scene, &o, Some(2));
    let img = crate::kit::sum_layers(&r, |_| true);
    let n = scene.camera.width as usize;
    let (mut got, mut want) = (DVec3::ZERO, DVec3::ZERO);
    for y in 0..n {
        for x in 0..n {
            got += pixel(&img, (x, y));
            want += expected(&scene, x, y, &|_| 1.0);
        }
    }
    let rel = ((got - want).abs() / want).max_element();
    eprintln!("point light over a plane, light tracer: image mean {got} against {want}: {rel:.4}");
    assert!(rel < 0.04, "the light tracer's mean misses by {rel}");
    let direct = layer(&r, "direct");
    assert_eq!(dvec3s(direct), dvec3s(&img), "all of it is direct light");
    let one = render_uncached(&scene, &o, Some(1));
    for (a, b) in r.layers.iter().zip(&one.layers) {
        assert_eq!(a.image.data, b.image.data, "{} differs on 1 thread", a.name);
    }
}

/// A spot aimed straight down with cutoff 30 and beam 20 degrees: the path tracer's pixels
/// inside the beam match `I cos θ / r²` (times `ρ/π`), those past the cutoff are black, and
/// the ramp between follows Mitsuba's linear falloff in angle.
#[test]
fn spot_light_cone_edge() {
    let dir = TempDir::new("spot-plane");
    // The camera's pixels see the floor 25-55 degrees off the light's vertical.
    let spot = format!(
        "type = \"spot\"\nposition = {LIGHT:?}\nlook_at = [0, 0, 0]\nintensity = {I:?}\n\
         cutoff_angle = 40\nbeam_width = 35"
    );
    let scene = plane(&dir, &spot, 16, 1);
    let o = Overrides {
        method: Some(Method::Path),
        spp: Some(16),
        ..Overrides::default()
    };
    let r = render_uncached(&scene, &o, None);
    let direct = layer(&r, "direct");
    let n = scene.camera.width as usize;
    let (mut inside, mut outside, mut ramp) = (0, 0, 0);
    let (c, b) = (40f64.to_radians(), 35f64.to_radians());
    // Pixels whose whole footprint is on one side of an edge (a pixel spans about 0.8
    // degrees seen from the light): the centre a degree away.
    let margin = 1.0f64.to_radians();
    for y in 0..n {
        for x in 0..n {
            let ray = scene.camera.ray(x as f32 + 0.5, y as f32 + 0.5);
            let p = scene.geometry.intersect(&ray).expect("the floor").point.p;
            let theta = ((Vec3::from(LIGHT) - p).normalize().y as f64).acos();
            let got = pixel(direct, (x, y));
            if theta < b - margin {
                let want = expected(&scene, x, y, &|_| 1.0);
                let rel = ((got - want).abs() / want).max_element();
                assert!(
                    rel < 5e-3,
                    "inside the beam ({x}, {y}): {got} against {want}"
                );
                inside += 1;
            } else if theta > c + margin {
                assert_eq!(got, DVec3::ZERO, "past the cutoff ({x}, {y})");
                outside += 1;
            } else if theta > b + margin && theta < c - margin {
                let want = expected(&scene, x, y, &|_| (c - theta) / (c - b));
                let rel = ((got - want).abs() / want).max_element();
                assert!(rel < 0.03, "on the ramp ({x}, {y}): {got} against {want}");
                ramp += 1;
            }
        }
    }
    eprintln!(
        "spot cone edge: {inside} pixels inside the beam, {ramp} on the ramp, {outside} past the cutoff"
    );
    assert!(
        inside > 10 && outside > 10 && ramp > 5,
        "{inside} {ramp} {outside}"
    );
}

/// The worksheet scene with a point light inside the glass sphere as its only light is
/// wholly caustic (paths L S+ D): the path tracer, whose NEE the glass blocks and whose rays
/// never hit a point light, shows nothing; path+splat's and SPPM's caustic do.
#[test]
fn point_light_in_glass_only_photons_find_the_caustic() {
    let dir = TempDir::new("point-glass");
    let scene = worksheet_with(32, 1, |f| {
        // The glass sphere's centre: the light inside it.
        let c = glass_centre(f);
        f.lights.push(LightDesc::Point {
            position: c,
            intensity: [1.0, 1.0, 1.0],
        });
        // The ceiling lamp goes dark (its MTL keeps emission in Ka, read only on request):
        // the point light is the only light.
        for m in &mut f.meshes {
            m.emission = scene::EmissionSource::Ke;
        }
    });
    assert!(scene.lights.is_empty(), "the area light is still on");
    let path = render_uncached(
        &scene,
        &Overrides {
            method: Some(Method::Path),
            spp: Some(4),
            ..Overrides::default()
        },
        None,
    );
    let all: DVec3 = dvec3s(&crate::kit::sum_layers(&path, |_| true))
        .iter()
        .sum();
    eprintln!("point light in glass: path tracer total {all}");
    assert_eq!(
        all,
        DVec3::ZERO,
        "the path tracer found a path through the glass"
    );
    let splat = render(
        &scene,
        &Overrides {
            method: Some(Method::PathSplat),
            spp: Some(1),
            passes: Some(1),
            splat_photons: Some(20_000),
            ..Overrides::default()
        },
        &dir.path().join("cache"),
        None,
    );
    let caustic: DVec3 = dvec3s(layer(&splat, "caustic")).iter().sum();
    eprintln!("point light in glass: path+splat caustic total {caustic}");
    assert!(caustic.min_element() > 0.0);
    let sppm = render(
        &scene,
        &Overrides {
            method: Some(Method::Sppm),
            passes: Some(1),
            photons: Some(20_000),
            ..Overrides::default()
        },
        &dir.path().join("cache"),
        None,
    );
    let s: DVec3 = dvec3s(&crate::kit::sum_layers(&sppm, |_| true))
        .iter()
        .sum();
    eprintln!("point light in glass: sppm total {s}");
    assert!(s.min_element() > 0.0);
}

/// A point light above the glass sphere (the area light off): the path tracer's caustic
/// layers are exactly zero (no ray hits a point light, and NEE through glass is blocked),
/// and path+splat's path layers (emitted, direct, indirect) are the path tracer's to the
/// bit, so nothing the splats add is counted twice; the splatted caustic layers are what
/// path+splat adds, and they are not empty. (Whether the splatted caustic is right in
/// amount is checked against Mitsuba's light tracer in
/// `references::point_caustic::a_point_light_caustic_matches_mitsubas_light_tracer`.)
#[test]
fn point_light_over_glass_partition() {
    let dir = TempDir::new("point-glass-partition");
    let scene = worksheet_with(32, 1, |f| {
        let c = glass_centre(f);
        f.lights.push(LightDesc::Point {
            position: [c[0], c[1] + 6.0, c[2]],
            intensity: [30.0, 30.0, 30.0],
        });
        for m in &mut f.meshes {
            m.emission = scene::EmissionSource::Ke;
        }
    });
    assert!(scene.lights.is_empty(), "the area light is still on");
    let cache = dir.path().join("cache");
    let path = render(
        &scene,
        &Overrides {
            method: Some(Method::Path),
            spp: Some(16),
            ..Overrides::default()
        },
        &cache,
        None,
    );
    for l in ["caustic", "caustic_indirect"] {
        if let Some(img) = path.layers.iter().find(|x| x.name == l) {
            let s: DVec3 = dvec3s(&img.image).iter().sum();
            eprintln!("point light over glass: path tracer's {l} total {s}");
            assert_eq!(s, DVec3::ZERO, "the path tracer's {l} layer");
        }
    }
    let splat_o = |m| Overrides {
        method: Some(m),
        spp: Some(16),
        passes: Some(2),
        splat_photons: Some(100_000),
        ..Overrides::default()
    };
    let ps = render(&scene, &splat_o(Method::PathSplat), &cache, None);
    let cs = render(&scene, &splat_o(Method::CausticSplat), &cache, None);
    let names =
        |r: &render::Rendered| -> Vec<String> { r.layers.iter().map(|l| l.name.clone()).collect() };
    eprintln!(
        "layers: path {:?}, path+splat {:?}, caustic-splat {:?}",
        names(&path),
        names(&ps),
        names(&cs)
    );
    // Layer by layer over the image: path+splat's path layers against the path tracer's,
    // its caustic layers against caustic-splat's.
    let sum = |img: &film::Image| -> DVec3 { dvec3s(img).iter().sum() };
    for l in [
        "emitted",
        "direct",
        "indirect",
        "caustic",
        "caustic_indirect",
    ] {
        let want = if l.starts_with("caustic") {
            sum(layer(&cs, l))
        } else {
            sum(layer(&path, l))
        };
        let got = sum(layer(&ps, l));
        eprintln!("point light over glass: {l}: path+splat {got}, alone {want}");
        if l.starts_with("caustic") {
            assert!(got.min_element() > 0.0, "{l}: path+splat splatted nothing");
        } else {
            assert_eq!(
                got, want,
                "{l}: path+splat's path part is not the path tracer"
            );
        }
    }
}

/// The centre of the worksheet scene's glass sphere.
fn glass_centre(f: &scene::SceneFile) -> [f32; 3] {
    f.spheres
        .iter()
        .find(|s| s.material == "glass")
        .expect("the glass sphere")
        .center
}
