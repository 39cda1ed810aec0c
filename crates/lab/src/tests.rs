//! Unit tests of the lab's helpers: region masks, distances, the peers' output parsed, bench
//! accuracy's cases, peers and tables.

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

// --- bench accuracy ------------------------------------------------------------------------

mod accuracy {
    use crate::accuracy::*;

    fn rung(seconds: f64, relmse: f64) -> Rung {
        Rung { seconds, relmse }
    }

    #[test]
    fn time_to_interpolates_log_log_between_budgets() {
        let rungs = [rung(2.0, 0.08), rung(8.0, 0.02), rung(32.0, 0.005)];
        // Error falling as 1/t: 0.04 is reached at 4 s exactly.
        assert!((time_to(0.04, &rungs).unwrap() - 4.0).abs() < 1e-9);
        // Already reached at the first budget, and exactly at a rung.
        assert_eq!(time_to(0.5, &rungs), Some(2.0));
        assert!((time_to(0.02, &rungs).unwrap() - 8.0).abs() < 1e-9);
        // Not reached at the largest budget.
        assert_eq!(time_to(0.001, &rungs), None);
        // A corrected error at or below zero is taken as reached at that rung.
        assert_eq!(
            time_to(0.01, &[rung(1.0, 0.1), rung(2.0, -0.001)]),
            Some(2.0)
        );
    }

    #[test]
    fn cases_and_peers_parse_and_bad_ones_say_what_is_expected() {
        let c = Case::parse("s.toml,a.exr,b.exr").unwrap();
        assert_eq!(
            (
                c.scene.to_str(),
                c.reference_a.to_str(),
                c.reference_b.to_str()
            ),
            (Some("s.toml"), Some("a.exr"), Some("b.exr"))
        );
        for bad in ["s.toml", "s.toml,a.exr", "s.toml,,b.exr", "a,b,c,d"] {
            assert!(
                Case::parse(bad)
                    .unwrap_err()
                    .contains("SCENE.toml,REF_A.exr,REF_B.exr")
            );
        }
        let p = Peer::parse("mine=render --out $OUT").unwrap();
        assert_eq!(
            (p.name.as_str(), p.command.as_str()),
            ("mine", "render --out $OUT")
        );
        let p = Peer::parse("smallvcm-vcm").unwrap();
        assert!(p.command.contains("peer.sh") && p.command.contains(" smallvcm-vcm \"$SCENE\""));
        assert!(Peer::parse("povray").unwrap_err().contains("mitsuba"));
        assert!(Peer::parse("=x").is_err());
    }

    #[test]
    fn the_suite_resolves_scenes_beside_it_and_references_under_refs() {
        let d = std::env::temp_dir().join(format!("pf-suite-{}", std::process::id()));
        std::fs::create_dir_all(&d).unwrap();
        let f = d.join("suite.toml");
        std::fs::write(
            &f,
            "[[case]]\nscene = \"x/s.toml\"\nreference_a = \"a.exr\"\nreference_b = \"b.exr\"\n",
        )
        .unwrap();
        let cases = read_suite(&f, Some(std::path::Path::new("/refs"))).unwrap();
        assert_eq!(cases.len(), 1);
        assert_eq!(cases[0].scene, d.join("x/s.toml"));
        assert_eq!(cases[0].reference_b, std::path::Path::new("/refs/b.exr"));
        assert_eq!(
            read_suite(&f, None).unwrap()[0].reference_a,
            d.join("a.exr")
        );
        std::fs::write(&f, "[[case]]\nscene = \"s.toml\"\n").unwrap();
        assert!(read_suite(&f, None).unwrap_err().contains("suite.toml"));
        // The committed suite parses.
        let committed = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../../scenes/bench-accuracy.toml");
        for c in read_suite(&committed, None).unwrap() {
            assert!(c.scene.is_file(), "{}", c.scene.display());
        }
    }

    #[test]
    fn the_tables_give_the_best_of_each_side_and_the_time_ratio() {
        let col = |name: &str, cells: Vec<Result<Rung, String>>| Column {
            name: name.into(),
            cells,
        };
        let ours = [
            col("sppm", vec![Ok(rung(2.0, 0.08)), Ok(rung(8.0, 0.02))]),
            col("path", vec![Ok(rung(2.0, 0.1)), Ok(rung(8.0, 0.03))]),
        ];
        let peers = [
            col("fast", vec![Ok(rung(2.5, 0.04)), Ok(rung(8.5, 0.01))]),
            col(
                "gone",
                vec![Err("no such scene".into()), Err("no such scene".into())],
            ),
        ];
        let t = tables(&[2.0, 8.0], &ours, &peers);
        let lines: Vec<&str> = t.lines().collect();
        assert_eq!(lines[0], "| budget | sppm | path | fast | gone |");
        assert_eq!(
            lines[2],
            "| 2 s | 0.08000 (2.0 s) | 0.10000 (2.0 s) | 0.04000 (2.5 s) | – |"
        );
        // sppm reaches the peer's 0.04 at 4 s, the peer took 2.5 s.
        assert_eq!(
            lines[7],
            "| 2 s | sppm 0.08000 | fast 0.04000 | 0.50 | 1.60 (4.0 s / 2.5 s) |"
        );
        assert_eq!(
            lines[8],
            "| 8 s | sppm 0.02000 | fast 0.01000 | 0.50 | > 0.94 (not reached in 8.0 s) |"
        );
        // Without a peer that ran, the comparison is blank.
        let t = tables(&[2.0], &ours[..1], &peers[1..]);
        assert!(t.ends_with("| 2 s | sppm 0.08000 | – | – | – |\n"), "{t}");
    }
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
