use crate::kit::load;
use geom::{Prim, Ray};
use glam::Vec3;
use math::Rng;

fn rand_dir(rng: &mut Rng) -> Vec3 {
    let z = 1.0 - 2.0 * rng.uniform();
    let r = (1.0 - z * z).max(0.0).sqrt();
    let phi = std::f32::consts::TAU * rng.uniform();
    Vec3::new(r * phi.cos(), r * phi.sin(), z)
}

#[test]
fn bvh_equals_brute_force_on_both_cornell_variants() {
    for rel in [
        "cornell-spheres/tessellated.toml",
        "cornell-spheres/analytic.toml",
    ] {
        let s = load(rel);
        let b = s.geometry.bounds();
        let mut rng = Rng::new(21);
        for _ in 0..3_000 {
            let o = b.lerp(Vec3::new(rng.uniform(), rng.uniform(), rng.uniform()));
            let ray = Ray::new(o, rand_dir(&mut rng));
            let a = s.geometry.intersect(&ray);
            let c = s.geometry.intersect_brute_force(&ray);
            assert_eq!(a.map(|h| h.t), c.map(|h| h.t), "{rel}: {ray:?}");
        }
    }
}

#[test]
fn the_light_is_lit_from_the_floor_and_sealed_by_the_ceiling() {
    let s = load("cornell-spheres/tessellated.toml");
    let g = &s.geometry;
    let white = s.material_of("white").unwrap();
    let light = s.material_of("light").unwrap();
    let mut rng = Rng::new(4);
    let (mut clear, mut tried) = (0, 0);
    for _ in 0..2_000 {
        // A floor point, found by a ray straight down from mid-height.
        let p = Vec3::new(
            -13.5 + 13.0 * rng.uniform(),
            5.0,
            -13.5 + 13.0 * rng.uniform(),
        );
        let floor = g.intersect(&Ray::new(p, Vec3::NEG_Y)).unwrap();
        if floor.material != white || floor.point.p.y > 1e-3 {
            continue; // a sphere was in the way
        }
        // A point on the light, found by a ray from the floor point.
        let lp = Vec3::new(
            -8.575 + 3.25 * rng.uniform(),
            13.7175,
            -8.3 + 2.625 * rng.uniform(),
        );
        let Some(up) = g.intersect(&floor.point.spawn_ray(lp - floor.point.p)) else {
            panic!("a ray from the floor to the light escaped the box")
        };
        tried += 1;
        if up.material == light {
            clear += 1;
            assert!(!g.occluded(&floor.point.spawn_ray_to_point(&up.point)));
            // Behind the light: the ceiling, 0.0025 above, never open sky.
            let back = g
                .intersect(&up.point.spawn_ray(Vec3::Y))
                .expect("leak through the ceiling");
            assert!(back.material == white && (back.t - 0.0025).abs() < 1e-4);
        } else {
            // Only the spheres may block the view of the light from the floor.
            assert!(
                g.mesh().materials[match up.prim {
                    Prim::Triangle(t) => t as usize,
                    Prim::Sphere(_) => unreachable!(),
                }] != white
                    || up.point.p.y < 13.0
            );
        }
    }
    assert!(
        tried > 1_000 && clear > tried / 2,
        "{clear} of {tried} floor points see the light"
    );
}

#[test]
fn camera_rays_enter_the_box_and_see_the_spheres() {
    let s = load("cornell-spheres/analytic.toml");
    let c = &s.camera;
    let (mut spheres, mut n) = (0, 0);
    for y in (0..c.height).step_by(8) {
        for x in (0..c.width).step_by(8) {
            let r = c.ray(x as f32 + 0.5, y as f32 + 0.5);
            assert!((r.d.length() - 1.0).abs() < 1e-5);
            if let Some(h) = s.geometry.intersect(&r) {
                n += 1;
                spheres += matches!(h.prim, Prim::Sphere(_)) as u32;
            }
        }
    }
    // Both spheres fill roughly a tenth of the image between them.
    assert!(
        n > 3_500 && spheres > 200 && spheres < 1_000,
        "{n} hits, {spheres} on spheres"
    );
}
