//! Unit tests of the lab's helpers: region masks, distances, the peers' output parsed.

use std::path::Path;

fn cornell() -> scene::Scene {
    let p =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/cornell-spheres/analytic.toml");
    scene::Scene::load(p).unwrap()
}

#[test]
fn point_triangle_distance_matches_a_dense_search() {
    use crate::regions::distance_for_test;
    use glam::Vec3;
    let mut rng = math::Rng::new(5);
    let mut v = || Vec3::new(rng.uniform(), rng.uniform(), rng.uniform()) * 4.0 - 2.0;
    for _ in 0..200 {
        let t = [v(), v(), v()];
        let p = v();
        // Brute force over a 200 x 200 barycentric grid: an upper bound within the grid's
        // spacing of the true distance.
        let n = 200;
        let mut best = f32::INFINITY;
        for i in 0..=n {
            for j in 0..=n - i {
                let (b1, b2) = (i as f32 / n as f32, j as f32 / n as f32);
                let q = t[0] + (t[1] - t[0]) * b1 + (t[2] - t[0]) * b2;
                best = best.min((p - q).length());
            }
        }
        let d = distance_for_test(p, t);
        let spacing = ((t[1] - t[0]).length() + (t[2] - t[0]).length()) / n as f32;
        assert!(d <= best + 1e-5 && d >= best - spacing, "{d} vs {best}");
    }
}

#[test]
fn the_edge_mask_marks_the_inner_edges_only() {
    let s = cornell();
    let m = crate::regions::edge_mask(&s, 0.4);
    let share = m.count() as f64 / m.pixels.len() as f64;
    // A band of 0.4 along the box's inner edges covers a modest share of the image.
    assert!(share > 0.03 && share < 0.3, "{share}");
    // The centre of the back wall is far from every edge.
    let (w, h) = (m.width, m.height);
    assert!(!m.pixels[(h / 2 - 40) * w + w / 2]);
}

#[test]
fn the_rim_mask_marks_the_open_front_only() {
    let s = cornell();
    let b = s.geometry.bounds();
    let band = 0.02 * (b.max - b.min).length();
    let m = crate::regions::rim_mask(&s, band);
    let (w, h) = (m.width, m.height);
    assert!(m.count() > 500, "{} rim pixels", m.count());
    // The box's open side faces the camera (at +z): every rim pixel sees a point within the
    // band of that plane, and the inner edges at the back are not rim.
    for y in 0..h {
        for x in 0..w {
            if m.pixels[y * w + x] {
                let hit = s
                    .geometry
                    .intersect(&s.camera.ray(x as f32 + 0.5, y as f32 + 0.5))
                    .unwrap();
                assert!(
                    b.max.z - hit.point.p.z < band,
                    "({x}, {y}) at {}",
                    hit.point.p
                );
            }
        }
    }
}

/// `bench-rays --peer` reads the peer's rates from lines like the Embree script's.
#[test]
fn peer_ray_rates_are_read_from_their_lines() {
    let out = "embreex 4.4  triangles 16140  pinned to CPU 0\n\
        coherent primary (camera grid)     rays 1,048,576  hits 1,013,507 ( 96.7%)  wall 0.303 s  cpu 0.149 s    3.46 Mrays/s\n\
        incoherent (random o, random d)    rays 1,048,576  hits   882,790 ( 84.2%)  wall 0.495 s  cpu 0.245 s    2.12 Mrays/s\n";
    assert_eq!(crate::bench::peer_rate(out, "coherent"), Some(3.46));
    assert_eq!(crate::bench::peer_rate(out, "incoherent"), Some(2.12));
    assert_eq!(
        crate::bench::peer_rate("  coherent: 7.5 M rays/s\n", "coherent"),
        Some(7.5)
    );
    assert_eq!(
        crate::bench::peer_rate("coherent rays only\n", "coherent"),
        None
    );
}
