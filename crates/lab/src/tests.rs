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

// --- The benchmarks' ray files -------------------------------------------------------------

mod ray_files {
    use crate::bench::*;

    fn tmp(name: &str) -> std::path::PathBuf {
        let d = std::env::temp_dir().join(format!("pf-rayfile-{}", std::process::id()));
        std::fs::create_dir_all(&d).unwrap();
        d.join(name)
    }

    #[test]
    fn ray_file_round_trips_and_bad_lengths_name_the_file() {
        let rows = [
            [1.0f32, -2.5, 3.0, 0.0, -1.0, 0.0],
            [0.1, 0.2, 0.3, 0.6, 0.0, 0.8],
        ];
        let bytes: Vec<u8> = rows
            .iter()
            .flatten()
            .flat_map(|v| v.to_le_bytes())
            .collect();
        let p = tmp("ok_rays.f32");
        std::fs::write(&p, &bytes).unwrap();
        let rays = read_ray_file(&p).unwrap();
        assert_eq!(rays.len(), 2);
        for (r, w) in rays.iter().zip(&rows) {
            assert_eq!(r.o.to_array(), [w[0], w[1], w[2]]);
            assert_eq!(r.d.to_array(), [w[3], w[4], w[5]]);
            assert_eq!(r.t_max, f32::INFINITY);
        }
        let short = tmp("short_rays.f32");
        std::fs::write(&short, &bytes[..bytes.len() - 1]).unwrap();
        let e = read_ray_file(&short).unwrap_err();
        assert!(
            e.contains("short_rays.f32") && e.contains("47 bytes"),
            "{e}"
        );
        std::fs::write(&short, []).unwrap();
        assert!(read_ray_file(&short).is_err());
        assert!(
            read_ray_file(&tmp("missing.f32"))
                .unwrap_err()
                .contains("missing.f32")
        );
    }

    fn npy(descr: &str, shape: &str, data: &[f32]) -> Vec<u8> {
        let mut h = format!("{{'descr': '{descr}', 'fortran_order': False, 'shape': {shape}, }}");
        while (10 + h.len() + 1) % 64 != 0 {
            h.push(' ');
        }
        h.push('\n');
        let mut b = b"\x93NUMPY\x01\x00".to_vec();
        b.extend((h.len() as u16).to_le_bytes());
        b.extend(h.bytes());
        b.extend(data.iter().flat_map(|v| v.to_le_bytes()));
        b
    }

    #[test]
    fn npy_reader_reads_f32_vectors_and_rejects_others() {
        let data = [1.5f32, f32::INFINITY, 0.25];
        let p = tmp("t.npy");
        std::fs::write(&p, npy("<f4", "(3,)", &data)).unwrap();
        assert_eq!(read_npy_f32(&p).unwrap(), data);
        for (descr, shape, n) in [("<i4", "(3,)", 3), ("<f4", "(4,)", 3), ("<f4", "(3, 1)", 3)] {
            std::fs::write(&p, npy(descr, shape, &data[..n])).unwrap();
            let e = read_npy_f32(&p).unwrap_err();
            assert!(e.contains("t.npy"), "{e}");
        }
        std::fs::write(&p, b"not numpy").unwrap();
        assert!(read_npy_f32(&p).is_err());
    }
}
