use std::path::PathBuf;

use crate::*;

/// A fresh directory under the system temp dir, unique per process and test.
fn scratch(test: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("film-test-{}-{test}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn constant(w: usize, h: usize, v: f32) -> Image {
    Image::from_fn(w, h, |_, _| [v; 3])
}

fn close(a: f64, b: f64) -> bool {
    (a - b).abs() <= 1e-12 * b.abs().max(1.0)
}

// ---------------------------------------------------------------- metrics

#[test]
fn metrics_of_constant_images_match_hand_values() {
    let m = metrics(&constant(4, 3, 1.0), &constant(4, 3, 0.5), None).unwrap();
    assert!(close(m.rmse, 0.5), "{m}");
    assert!(close(m.mae, 0.5), "{m}");
    // (1 - 0.5)² / (0.5² + 0.01) = 0.25 / 0.26
    assert!(close(m.relmse, 0.25 / 0.26), "{m}");
    // pbrt's convention: 0.25 / (0.5 + 0.01)²
    assert!(close(m.relmse_pbrt, 0.25 / (0.51 * 0.51)), "{m}");
    assert!(close(m.mean_a, 1.0) && close(m.mean_b, 0.5), "{m}");
    assert_eq!(m.pixels, 12);
    let line = m.to_string();
    assert!(
        line.starts_with("rmse=") && line.ends_with("pixels=12"),
        "{line}"
    );
    assert!(!line.contains('\n'));
}

#[test]
fn metrics_average_over_channels_and_use_the_documented_epsilon() {
    // One channel of one of two pixels is off by 1 against a black reference:
    // 6 channel values, squared error sum 1, relative term 1 / (0 + 0.01) = 100.
    let a = Image {
        width: 2,
        height: 1,
        data: vec![[1.0, 0.0, 0.0], [0.0; 3]],
    };
    let b = Image::new(2, 1);
    let m = metrics(&a, &b, None).unwrap();
    assert!(close(m.rmse, (1.0f64 / 6.0).sqrt()), "{m}");
    assert!(close(m.mae, 1.0 / 6.0), "{m}");
    assert!(close(m.relmse, 1.0 / RELMSE_EPSILON / 6.0), "{m}");
    assert!(close(m.mean_a, 1.0 / 6.0) && m.mean_b == 0.0, "{m}");
    assert_eq!(m.pixels, 2);
}

#[test]
fn mask_restricts_metrics_to_the_selected_pixels() {
    // a equals b inside [2,5) x [1,3) and is off by 2 elsewhere.
    let (w, h) = (6, 4);
    let inside = |x: usize, y: usize| (2..5).contains(&x) && (1..3).contains(&y);
    let b = constant(w, h, 0.25);
    let a = Image::from_fn(
        w,
        h,
        |x, y| if inside(x, y) { [0.25; 3] } else { [2.25; 3] },
    );
    let mask = Mask::rect(w, h, 2, 1, 5, 3);
    assert_eq!(mask.count(), 6);
    let m = metrics(&a, &b, Some(&mask)).unwrap();
    assert_eq!((m.rmse, m.mae, m.relmse, m.pixels), (0.0, 0.0, 0.0, 6));
    assert_eq!(m.mean_a, 0.25);

    // The complement sees only the error of 2.
    let outside = Mask::from_fn(w, h, |x, y| !inside(x, y));
    let m = metrics(&a, &b, Some(&outside)).unwrap();
    assert_eq!(m.pixels, w * h - 6);
    assert!(close(m.rmse, 2.0) && close(m.mae, 2.0), "{m}");
    assert!(close(m.relmse, 4.0 / (0.0625 + 0.01)), "{m}");

    // Whole image: 18 of 24 pixels off by 2.
    let m = metrics(&a, &b, Some(&Mask::all(w, h))).unwrap();
    assert!(close(m.mae, 2.0 * 18.0 / 24.0), "{m}");

    // A rectangle reaching past the image is clipped.
    assert_eq!(Mask::rect(w, h, 4, 3, 100, 100).count(), 2);
}

#[test]
fn metrics_report_size_problems_as_errors() {
    let a = constant(2, 2, 1.0);
    let err = metrics(&a, &constant(2, 3, 1.0), None).unwrap_err();
    assert!(
        matches!(
            err,
            FilmError::SizeMismatch {
                a: (2, 2),
                b: (2, 3),
                ..
            }
        ),
        "{err}"
    );
    assert!(err.to_string().contains("2x2 vs 2x3"), "{err}");

    let err = metrics(&a, &a, Some(&Mask::all(3, 2))).unwrap_err();
    assert!(matches!(err, FilmError::SizeMismatch { .. }), "{err}");

    let broken = Image {
        width: 2,
        height: 2,
        data: vec![[0.0; 3]; 3],
    };
    let err = metrics(&broken, &a, None).unwrap_err();
    assert!(matches!(err, FilmError::BadBuffer { len: 3, .. }), "{err}");

    let nothing = Mask::from_fn(2, 2, |_, _| false);
    let err = metrics(&a, &a, Some(&nothing)).unwrap_err();
    assert!(matches!(err, FilmError::EmptyRegion), "{err}");
}

// ---------------------------------------------------------------- IO

#[test]
fn exr_round_trip_is_bit_exact() {
    let dir = scratch("exr-round-trip");
    let path = dir.join("img.exr");
    let specials = [
        0.0f32,
        -0.0,
        1.0 / 3.0,
        -2.5e-3,
        1.0e-40, // subnormal
        f32::MIN_POSITIVE,
        3.0e38,
        f32::INFINITY,
        65504.0 * 1000.0, // far beyond f16
    ];
    let img = Image::from_fn(7, 5, |x, y| {
        let i = y * 7 + x;
        [
            specials[i % specials.len()],
            (i as f32).sqrt() * std::f32::consts::PI,
            1.0 / (1.0 + i as f32),
        ]
    });
    write_exr(&path, &img).unwrap();
    let back = read_exr(&path).unwrap();
    assert_eq!((back.width, back.height), (7, 5));
    for (p, q) in img.data.iter().zip(&back.data) {
        for c in 0..3 {
            assert_eq!(p[c].to_bits(), q[c].to_bits(), "{p:?} vs {q:?}");
        }
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn tone_map_values() {
    let t = ToneMap::default();
    assert_eq!((t.exposure, t.gamma), (0.0, 1.8));
    assert_eq!(t.apply(0.0), 0);
    assert_eq!(t.apply(1.0), 255);
    // 255 · 0.5^(1/1.8) = 173.5007…
    assert_eq!(
        f64::from(t.apply(0.5)),
        (255.0 * 0.5f64.powf(1.0 / 1.8)).round()
    );
    assert_eq!(t.apply(0.5), 174);
    // 255 · 0.18^(1/1.8) = 98.356…
    assert_eq!(t.apply(0.18), 98);
    assert_eq!(t.apply(7.0), 255);
    assert_eq!(t.apply(-1.0), 0);
    assert_eq!(t.apply(f32::NAN), 0);
    assert_eq!(t.apply(f32::INFINITY), 255);
    assert_eq!(t.apply(f32::NEG_INFINITY), 0);
    // One stop up: 0.25 displays like 0.5.
    let up = ToneMap { exposure: 1.0, ..t };
    assert_eq!(up.apply(0.25), 174);
    // Gamma 1 is linear: 0.5 · 255 = 127.5 rounds away from zero.
    let linear = ToneMap {
        exposure: 0.0,
        gamma: 1.0,
    };
    assert_eq!(linear.apply(0.5), 128);
    assert_eq!(linear.apply(0.2), 51);
}

#[test]
fn png_holds_tone_mapped_values_and_survives_nan() {
    let dir = scratch("png");
    let path = dir.join("img.png");
    let img = Image {
        width: 3,
        height: 2,
        data: vec![
            [0.0, 0.5, 1.0],
            [f32::NAN, f32::INFINITY, f32::NEG_INFINITY],
            [-3.0, 0.18, 1e30],
            [0.5, 0.5, 0.5],
            [0.0; 3],
            [1.0; 3],
        ],
    };
    write_png(&path, &img, &ToneMap::default()).unwrap();
    let back = image::open(&path).unwrap().to_rgb8();
    assert_eq!(back.dimensions(), (3, 2));
    // Row 0 is the top row in both.
    assert_eq!(back.get_pixel(0, 0).0, [0, 174, 255]);
    assert_eq!(back.get_pixel(1, 0).0, [0, 255, 0]);
    assert_eq!(back.get_pixel(2, 0).0, [0, 98, 255]);
    assert_eq!(back.get_pixel(0, 1).0, [174; 3]);
    assert_eq!(back.get_pixel(2, 1).0, [255; 3]);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn writing_into_a_missing_directory_is_an_error_naming_the_path() {
    let dir = scratch("missing-dir");
    let img = constant(2, 2, 0.5);
    for path in [dir.join("nope/a.exr"), dir.join("nope/a.png")] {
        let err = if path.extension().unwrap() == "exr" {
            write_exr(&path, &img)
        } else {
            write_png(&path, &img, &ToneMap::default())
        }
        .unwrap_err();
        assert!(matches!(err, FilmError::Io { .. }), "{err}");
        let msg = err.to_string();
        assert!(msg.contains(&path.display().to_string()), "{msg}");
        assert!(std::error::Error::source(&err).is_some());
    }
    assert!(!dir.join("nope").exists());
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn reading_a_missing_or_bad_exr_is_an_error_naming_the_path() {
    let dir = scratch("read-errors");
    let missing = dir.join("missing.exr");
    let err = read_exr(&missing).unwrap_err();
    assert!(
        err.to_string().contains(&missing.display().to_string()),
        "{err}"
    );

    let garbage = dir.join("garbage.exr");
    std::fs::write(&garbage, b"not an exr file").unwrap();
    let err = read_exr(&garbage).unwrap_err();
    assert!(matches!(err, FilmError::Exr { .. }), "{err}");
    assert!(
        err.to_string().contains(&garbage.display().to_string()),
        "{err}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn writes_replace_the_target_and_leave_no_temporary_files() {
    let dir = scratch("atomic");
    let path = dir.join("out.exr");
    write_exr(&path, &constant(3, 3, 1.0)).unwrap();
    write_exr(&path, &constant(3, 3, 2.0)).unwrap();
    write_png(
        dir.join("out.png"),
        &constant(3, 3, 2.0),
        &ToneMap::default(),
    )
    .unwrap();
    assert_eq!(read_exr(&path).unwrap(), constant(3, 3, 2.0));
    let mut names: Vec<String> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    assert_eq!(names, ["out.exr", "out.png"]);

    // A path without a file name fails cleanly.
    let err = write_atomic(std::path::Path::new("/"), b"x").unwrap_err();
    assert!(matches!(err, FilmError::Io { .. }), "{err}");
    std::fs::remove_dir_all(&dir).unwrap();
}

// ---------------------------------------------------------------- film, layers, tiles

#[test]
fn tiles_partition_the_image_in_row_major_order() {
    let (w, h) = (37, 23);
    let ts = tiles(w, h, 8);
    assert_eq!(ts.len(), 5 * 3);
    assert_eq!(ts[0], Rect::new(0, 0, 8, 8));
    assert_eq!(ts[1], Rect::new(8, 0, 16, 8));
    assert_eq!(ts[4], Rect::new(32, 0, 37, 8));
    assert_eq!(ts[5], Rect::new(0, 8, 8, 16));
    assert_eq!(ts[14], Rect::new(32, 16, 37, 23));
    let mut cover = vec![0u32; w * h];
    for t in &ts {
        for y in t.y0..t.y1 {
            for x in t.x0..t.x1 {
                cover[y * w + x] += 1;
            }
        }
    }
    assert!(cover.iter().all(|&c| c == 1));
    assert_eq!(ts.iter().map(Rect::area).sum::<usize>(), w * h);
    assert!(tiles(0, 5, 4).is_empty());
}

/// Deterministic, awkward sample values (not exactly representable sums).
fn sample(pass: usize, x: usize, y: usize, s: usize) -> [f32; 3] {
    let k = (pass * 7919 + y * 104_729 + x * 1_299_709 + s * 15_485_863) % 1_000_003;
    let v = k as f32 / 1_000_003.0;
    [v * 0.1, v * v * 3.7, 1.0 / (1.0 + 1e3 * v)]
}

fn render_pass(film: &Film, pass: usize, rect: Rect) -> TileBuffer {
    let mut t = film.tile_buffer(rect);
    for y in rect.y0..rect.y1 {
        for x in rect.x0..rect.x1 {
            for s in 0..5 {
                t.layer_mut("global").add(x, y, sample(pass, x, y, s));
                t.layer_mut("global").add_weight(x, y, 1.0);
                if (x + y + s) % 3 == 0 {
                    t.layer_mut("caustic")
                        .add(x, y, sample(pass + 100, x, y, s));
                }
            }
        }
    }
    t
}

fn film_bits(film: &Film) -> Vec<u64> {
    let mut bits = Vec::new();
    for name in film.layer_names() {
        let l = film.layer(name).unwrap();
        for y in 0..film.height() {
            for x in 0..film.width() {
                bits.extend(l.sum(x, y).map(f64::to_bits));
                bits.push(l.weight(x, y).to_bits());
            }
        }
    }
    bits
}

#[test]
fn tile_merge_order_does_not_change_a_single_bit() {
    let (w, h) = (37, 23);
    let rects = tiles(w, h, 8);
    let run = |order: &dyn Fn(usize) -> usize| {
        let mut film = Film::new(w, h);
        film.layer_mut("global");
        film.layer_mut("caustic");
        for pass in 0..3 {
            let bufs: Vec<TileBuffer> =
                rects.iter().map(|&r| render_pass(&film, pass, r)).collect();
            for i in 0..bufs.len() {
                film.merge_tile(&bufs[order(i)]);
            }
        }
        film
    };
    let n = rects.len();
    let forward = run(&|i| i);
    let reverse = run(&|i| n - 1 - i);
    let strided = run(&|i| (i * 7) % n); // 7 is coprime with 15
    assert_eq!(film_bits(&forward), film_bits(&reverse));
    assert_eq!(film_bits(&forward), film_bits(&strided));
    assert_eq!(forward.layer_names(), ["global", "caustic"]);
    assert_eq!(forward.layer("global").unwrap().weight(36, 22), 15.0);
    assert!(forward.layer("caustic").unwrap().sum(0, 0)[0] > 0.0);
}

#[test]
fn one_pass_of_tiles_equals_direct_accumulation() {
    let (w, h) = (13, 9);
    let mut direct = Film::new(w, h);
    direct.layer_mut("global");
    direct.layer_mut("caustic");
    let mut tiled = direct.clone();
    // Single-threaded: samples straight into the film's layers, same per-pixel order.
    for y in 0..h {
        for x in 0..w {
            for s in 0..5 {
                direct.layer_mut("global").add(x, y, sample(0, x, y, s));
                direct.layer_mut("global").add_weight(x, y, 1.0);
                if (x + y + s) % 3 == 0 {
                    direct.layer_mut("caustic").add(x, y, sample(100, x, y, s));
                }
            }
        }
    }
    for r in tiles(w, h, 4) {
        let t = render_pass(&tiled, 0, r);
        tiled.merge_tile(&t);
    }
    assert_eq!(film_bits(&direct), film_bits(&tiled));
}

#[test]
fn layers_are_named_created_on_demand_and_kept_in_insertion_order() {
    let mut film = Film::new(4, 2);
    assert!(film.layer("direct").is_none());
    film.layer_mut("indirect").add(1, 1, [1.0, 2.0, 3.0]);
    film.layer_mut("direct");
    film.layer_mut("emission");
    film.layer_mut("indirect").add(1, 1, [1.0, 2.0, 3.0]);
    assert_eq!(film.layer_names(), ["indirect", "direct", "emission"]);
    assert_eq!(film.layer("indirect").unwrap().sum(1, 1), [2.0, 4.0, 6.0]);
    assert_eq!(film.layer("direct").unwrap().rect(), Rect::full(4, 2));

    let tile = film.tile_buffer(Rect::new(2, 0, 4, 2));
    assert!(tile.layer("emission").is_some());
    assert_eq!(
        tile.layer("emission").unwrap().rect(),
        Rect::new(2, 0, 4, 2)
    );
    // A layer new in the tile is appended to the film on merge.
    let mut tile = tile;
    tile.layer_mut("caustic").add(3, 1, [0.5; 3]);
    film.merge_tile(&tile);
    assert_eq!(
        film.layer_names(),
        ["indirect", "direct", "emission", "caustic"]
    );
    assert_eq!(film.layer("caustic").unwrap().sum(3, 1), [0.5; 3]);
    assert_eq!(film.layer("caustic").unwrap().sum(2, 1), [0.0; 3]);
}

#[test]
fn tile_layers_reject_pixels_they_do_not_own() {
    // Writing outside a tile is a caller bug (a panic, like slice indexing), never a silent
    // write into a neighbour's pixels.
    let film = Film::new(8, 8);
    let mut tile = film.tile_buffer(Rect::new(0, 0, 4, 4));
    let r = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        tile.layer_mut("global").add(4, 0, [1.0; 3]);
    }));
    let msg = r.expect_err("a write outside the tile must panic");
    let msg = msg.downcast_ref::<String>().cloned().unwrap_or_default();
    assert!(msg.contains("outside layer rect"), "{msg}");
}

#[test]
fn resolve_divides_by_weight_or_by_a_constant() {
    let mut film = Film::new(2, 1);
    let l = film.layer_mut("global");
    l.add(0, 0, [1.0, 2.0, 4.0]);
    l.add(0, 0, [2.0, 2.0, 2.0]);
    l.add_weight(0, 0, 2.0);
    l.add(1, 0, [9.0; 3]); // weight stays 0
    let by_weight = l.resolve(Normalize::Weight);
    assert_eq!((by_weight.width, by_weight.height), (2, 1));
    assert_eq!(by_weight.data, [[1.5, 2.0, 3.0], [0.0; 3]]);
    let by_spp = l.resolve(Normalize::Constant(4.0));
    assert_eq!(by_spp.data, [[0.75, 1.0, 1.5], [2.25; 3]]);
    // A tile resolves to an image of its own size.
    let tile = film.tile_buffer(Rect::new(1, 0, 2, 1));
    assert_eq!(
        tile.layer("global")
            .unwrap()
            .resolve(Normalize::Weight)
            .data
            .len(),
        1
    );
}

#[test]
fn f64_sums_keep_contributions_an_f32_sum_would_drop() {
    // Above 2^24 an f32 sum no longer changes when 1.0 is added.
    let mut film = Film::new(1, 1);
    let l = film.layer_mut("global");
    let mut f32_sum = 16_777_216.0f32;
    l.add(0, 0, [f32_sum; 3]);
    for _ in 0..1000 {
        l.add(0, 0, [1.0; 3]);
        f32_sum += 1.0;
    }
    assert_eq!(f32_sum, 16_777_216.0);
    assert_eq!(
        l.resolve(Normalize::Constant(1.0)).data[0],
        [16_778_216.0; 3]
    );
}

#[test]
fn image_add_scale_and_composite() {
    let mut a = constant(3, 2, 1.0);
    let b = Image::from_fn(3, 2, |x, y| [x as f32, y as f32, 0.5]);
    a.add(&b).unwrap();
    assert_eq!(a.get(2, 1), [3.0, 2.0, 1.5]);
    a.scale(2.0);
    assert_eq!(a.get(2, 1), [6.0, 4.0, 3.0]);
    a.set(0, 0, [7.0; 3]);
    assert_eq!(a.data[0], [7.0; 3]);

    let direct = constant(3, 2, 0.25);
    let caustic = constant(3, 2, 1.0);
    let c = composite(&[(&direct, 1.0), (&caustic, 0.5), (&b, 2.0)]).unwrap();
    assert_eq!(c.get(2, 1), [0.25 + 0.5 + 4.0, 0.75 + 2.0, 0.75 + 1.0]);
    assert_eq!(composite(&[]).unwrap(), Image::new(0, 0));

    let small = constant(2, 2, 1.0);
    assert!(matches!(
        composite(&[(&direct, 1.0), (&small, 1.0)]),
        Err(FilmError::SizeMismatch { .. })
    ));
    assert!(matches!(a.add(&small), Err(FilmError::SizeMismatch { .. })));
}

#[test]
fn box_downsampling_averages_blocks() {
    let img = Image::from_fn(5, 4, |x, y| [x as f32, y as f32, (x + 10 * y) as f32]);
    let d = img.box_downsample(2);
    assert_eq!((d.width, d.height), (2, 2));
    // Block (1, 1) covers x in 2..4, y in 2..4: means 2.5, 2.5, 27.5.
    assert_eq!(d.get(1, 1), [2.5, 2.5, 27.5]);
    assert_eq!(d.get(0, 0), [0.5, 0.5, 5.5]);
    assert_eq!(img.box_downsample(1).data, img.data);
}

/// Synthetic runs: a grey reference of 0.5; the left half of every run biased by `B`, every
/// pixel of every run with independent uniform noise of standard deviation `SIGMA`
/// (splitmix64: `film` has no random numbers of its own). The decomposition recovers both.
#[test]
fn bias_and_variance_are_recovered_from_injected_ones() {
    const B: f64 = 0.05;
    const SIGMA: f64 = 0.1;
    const K: usize = 32;
    let (w, h) = (16, 16);
    let mut state = 7u64;
    let mut uniform = || {
        state = state.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = state;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    };
    let reference = constant(w, h, 0.5);
    let runs: Vec<Image> = (0..K)
        .map(|_| {
            Image::from_fn(w, h, |x, _| {
                let bias = if x < w / 2 { B } else { 0.0 };
                // Uniform on [-a, a] has variance a^2 / 3.
                let a = SIGMA * 3f64.sqrt();
                [0, 1, 2].map(|_| (0.5 + bias + a * (2.0 * uniform() - 1.0)) as f32)
            })
        })
        .collect();
    let refs: Vec<&Image> = runs.iter().collect();
    let bv = BiasVariance::new(&refs, &reference, false).unwrap();
    let left = Mask::from_fn(w, h, |x, _| x < w / 2);
    let right = Mask::from_fn(w, h, |x, _| x >= w / 2);
    let (l, r) = (
        bv.region(Some(&left)).unwrap(),
        bv.region(Some(&right)).unwrap(),
    );
    eprintln!("left {l:?}\nright {r:?}");
    // bias^2: the mean error's square has standard deviation sqrt(4 B^2 s^2/K + 2 s^4/K^2)
    // per pixel and channel, 1.8e-3 here, so 1.0e-4 over 384 values: 4 of those.
    assert!((l.bias2 - B * B).abs() < 4e-4, "left bias^2 {}", l.bias2);
    // Unbiased pixels: the clamp at zero leaves a small positive mean (about 0.4 s^2 / K).
    assert!(r.bias2 < 0.1 * B * B, "right bias^2 {}", r.bias2);
    // s^2 has relative standard deviation sqrt(2 / (K - 1)) = 0.25 per value, 1.3% over 384.
    for s in [&l, &r] {
        assert!((s.variance / (SIGMA * SIGMA) - 1.0).abs() < 0.06, "{s:?}");
        // One run's squared error is bias^2 + s^2 exactly wherever the clamp did not act.
        assert!(s.mse <= s.bias2 + s.variance + 1e-12);
        assert!((s.mse - s.bias2 - s.variance).abs() < 0.05 * s.mse, "{s:?}");
    }
    // The relative weighting divides by ref^2 + 0.01 = 0.26 here.
    let rel = BiasVariance::new(&refs, &reference, true).unwrap();
    let rl = rel.region(Some(&left)).unwrap();
    assert!((rl.bias2 * 0.26 / l.bias2 - 1.0).abs() < 1e-6);
    // One run is not enough.
    assert!(matches!(
        BiasVariance::new(&refs[..1], &reference, false),
        Err(FilmError::TooFewRuns { runs: 1 })
    ));
}

#[test]
fn flip_is_zero_for_equal_images_and_grows_with_the_difference() {
    // A smooth gradient, and the same with a bright square over its left half's centre.
    let (w, h) = (64, 32);
    let base = Image::from_fn(w, h, |x, _| [x as f32 / w as f32 * 0.8; 3]);
    let with_square = |v: f32| {
        let mut img = base.clone();
        for y in 12..20 {
            for x in 12..20 {
                img.set(x, y, [v; 3]);
            }
        }
        img
    };
    let same = flip(&base, &base, 1.0).unwrap();
    assert_eq!(same.mean(None).unwrap(), Some(0.0));
    let small = flip(&with_square(0.3), &base, 1.0).unwrap();
    let large = flip(&with_square(1.0), &base, 1.0).unwrap();
    let square = Mask::rect(w, h, 12, 12, 20, 20);
    let (s, l) = (
        small.mean(Some(&square)).unwrap().unwrap(),
        large.mean(Some(&square)).unwrap().unwrap(),
    );
    assert!(s > 0.05 && l > s + 0.1, "FLIP in the square: {s} then {l}");
    // FLIP's filters reach a few pixels at 67 pixels per degree, not across the image.
    let far = Mask::rect(w, h, 40, 0, 64, 32);
    assert!(large.mean(Some(&far)).unwrap().unwrap() < 1e-3);
    // Exposure tone-maps both images alike: scaling both leaves equal images equal.
    assert_eq!(
        flip(&base, &base, 4.0).unwrap().mean(None).unwrap(),
        Some(0.0)
    );
}

#[test]
fn flip_reports_size_problems_as_errors() {
    let err = flip(&Image::new(4, 4), &Image::new(4, 5), 1.0).unwrap_err();
    assert!(matches!(err, FilmError::SizeMismatch { .. }), "{err}");
    let map = flip(&Image::new(4, 4), &Image::new(4, 4), 1.0).unwrap();
    assert!(map.mean(Some(&Mask::all(5, 4))).is_err());
    assert_eq!(map.mean(Some(&Mask::rect(4, 4, 0, 0, 0, 0))).unwrap(), None);
    assert!(flip(&Image::new(0, 0), &Image::new(0, 0), 1.0).is_err());
}

#[test]
fn sums_files_round_trip_exactly_and_refuse_damage() {
    let dir = scratch("sums");
    let p = dir.join("a.f64");
    let s = Sums {
        width: 3,
        height: 2,
        planes: vec![
            (0..6).map(|i| [i as f64 * 0.1, -0.0, 1e-300]).collect(),
            (0..6).map(|i| [f64::MAX, i as f64 / 3.0, 7.0]).collect(),
        ],
    };
    write_sums(&p, &s).unwrap();
    let back = read_sums(&p).unwrap();
    let bits = |s: &Sums| -> Vec<u64> {
        s.planes
            .iter()
            .flatten()
            .flatten()
            .map(|v| v.to_bits())
            .collect()
    };
    assert_eq!((back.width, back.height), (3, 2));
    assert_eq!(bits(&back), bits(&s));
    let good = std::fs::read(&p).unwrap();
    for (i, what) in [(30, "checksum"), (0, "magic"), (8, "version")] {
        let mut b = good.clone();
        b[i] ^= 1;
        std::fs::write(&p, &b).unwrap();
        let e = read_sums(&p).unwrap_err().to_string();
        assert!(e.contains("a.f64") && e.contains(what), "{e}");
    }
    std::fs::write(&p, &good[..good.len() - 1]).unwrap();
    let e = read_sums(&p).unwrap_err().to_string();
    assert!(e.contains("bytes"), "{e}");
}

// ---------------------------------------------------------------- class

#[test]
fn class_names_round_trip_through_from_name_from_str_and_display() {
    let names: Vec<&str> = Class::ALL.iter().map(|c| c.name()).collect();
    assert_eq!(
        names,
        [
            "emitted",
            "direct",
            "indirect",
            "caustic",
            "caustic_indirect"
        ]
    );
    for c in Class::ALL {
        assert_eq!(Class::from_name(c.name()), Some(c));
        assert_eq!(c.name().parse::<Class>(), Ok(c));
        assert_eq!(c.to_string(), c.name());
        assert_eq!(c.to_string().parse::<Class>(), Ok(c));
    }
}

#[test]
fn unknown_class_names_are_refused_naming_the_name_and_the_valid_ones() {
    for bad in ["caustics", "", "Emitted", "caustic-indirect", " direct"] {
        assert_eq!(Class::from_name(bad), None, "{bad:?}");
        let e = bad.parse::<Class>().unwrap_err();
        assert!(e.contains(&format!("\"{bad}\"")), "{e}");
        for c in Class::ALL {
            assert!(e.contains(c.name()), "{e}");
        }
        assert!(!e.contains('\n'), "{e}");
    }
}

#[test]
fn class_all_is_sorted_and_lists_each_class_once() {
    assert!(Class::ALL.is_sorted_by(|a, b| a < b), "{:?}", Class::ALL);
    let mut sorted = Class::ALL;
    sorted.reverse();
    sorted.sort();
    assert_eq!(sorted, Class::ALL);
    for (i, c) in Class::ALL.into_iter().enumerate() {
        assert_eq!(c as usize, i, "{c:?}");
    }
    let caustic: Vec<Class> = Class::ALL.into_iter().filter(|c| c.is_caustic()).collect();
    assert_eq!(caustic, [Class::Caustic, Class::CausticIndirect]);
}

// ---- a reference as two halves

/// Gaussian noise from a fixed stream (Box-Muller over splitmix64), for synthetic images.
fn gaussian_stream(seed: u64) -> impl FnMut() -> f64 {
    let mut s = seed;
    let mut uniform = move || {
        s = s.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = s;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        (((z ^ (z >> 31)) >> 11) as f64 + 0.5) / (1u64 << 53) as f64
    };
    move || (-2.0 * uniform().ln()).sqrt() * (std::f64::consts::TAU * uniform()).cos()
}

/// Synthetic images with known noise: truth T = 1, halves of standard deviation 0.03, an image
/// of standard deviation 0.05 (and a bias of 0.03 on its left half). Against the halves' mean
/// its plain MSE carries the reference's variance 0.03²/2 = 0.00045 (15% of its own); with
/// the halves' variance taken out it is its error against the truth.
#[test]
fn halves_take_the_references_noise_out_of_the_errors() {
    let (w, h) = (256, 256);
    let (sigma_ref, sigma, bias) = (0.03, 0.05, 0.03);
    let mut g = gaussian_stream(7);
    let mut noisy = |s: f64, b: &dyn Fn(usize) -> f64| {
        Image::from_fn(w, h, |x, _| {
            [0, 1, 2].map(|_| (1.0 + b(x) + s * g()) as f32)
        })
    };
    let a = noisy(sigma_ref, &|_| 0.0);
    let b = noisy(sigma_ref, &|_| 0.0);
    let img = noisy(sigma, &|x| if x < w / 2 { bias } else { 0.0 });
    let truth = constant(w, h, 1.0);
    let halves = Halves::new(&a, &b).unwrap();
    // One image given as both halves estimates no noise: refused.
    assert!(matches!(
        Halves::new(&a, &a.clone()),
        Err(FilmError::IdenticalHalves)
    ));
    let against_truth = metrics(&img, &truth, None).unwrap();
    let m = metrics_halves(&img, &halves, None).unwrap();
    // Against the truth: MSE = sigma² + bias²/2 = 0.0025 + 0.00045 = 0.00295.
    let mse_truth = sigma * sigma + bias * bias / 2.0;
    assert!((against_truth.rmse.powi(2) / mse_truth - 1.0).abs() < 0.02);
    // The plain MSE against the halves' mean adds their variance, 0.00045.
    let plain = m.plain.rmse.powi(2);
    let with_ref = mse_truth + sigma_ref * sigma_ref / 2.0;
    assert!((plain / with_ref - 1.0).abs() < 0.02, "plain {plain}");
    // Taken out: the MSE against the truth. Per element, d² - v has standard deviation about
    // 0.0048, so 1.1e-5 over 196608 values: 5e-5 is 4.5 of those.
    let corrected = m.rmse.powi(2);
    assert!(
        (corrected - mse_truth).abs() < 5e-5,
        "corrected {corrected}, truth {mse_truth}"
    );
    // The relative MSE likewise. Its weights 1/(R² + 0.01) share R's noise with the error,
    // which adds about 3 Var(R) MSE + 4 bias Var(R) (Taylor in R's noise): 1% here.
    assert!(
        (m.relmse / against_truth.relmse - 1.0).abs() < 0.025,
        "{} vs {}",
        m.relmse,
        against_truth.relmse
    );
    assert!(m.plain.relmse > 1.1 * against_truth.relmse);
    assert!((m.plain.relmse - m.relmse - m.reference_relmse).abs() < 1e-12);
    assert!((m.reference_relmse / (0.00045 / 1.01) - 1.0).abs() < 0.02);
}

/// Bias² maps against halves: the reference's noise no longer reads as bias where there is
/// none, and a real bias is still measured.
#[test]
fn bias_maps_against_halves_count_the_references_noise_out() {
    let (w, h, k) = (64, 64, 8);
    let (sigma_ref, sigma, bias) = (0.1, 0.05, 0.1);
    let mut g = gaussian_stream(11);
    let mut noisy =
        |s: f64, b: f64| Image::from_fn(w, h, |_, _| [0, 1, 2].map(|_| (1.0 + b + s * g()) as f32));
    let a = noisy(sigma_ref, 0.0);
    let b = noisy(sigma_ref, 0.0);
    let unbiased: Vec<Image> = (0..k).map(|_| noisy(sigma, 0.0)).collect();
    let biased: Vec<Image> = (0..k).map(|_| noisy(sigma, bias)).collect();
    let halves = Halves::new(&a, &b).unwrap();
    let region = |runs: &[Image], corrected: bool| {
        let refs: Vec<&Image> = runs.iter().collect();
        let bv = if corrected {
            BiasVariance::against_halves(&refs, &halves, false).unwrap()
        } else {
            BiasVariance::new(&refs, &halves.mean, false).unwrap()
        };
        bv.region(None).unwrap().bias2
    };
    // Plain: the reference's variance 0.005 reads as bias² (minus the clamp's share).
    let plain = region(&unbiased, false);
    assert!(plain > 0.003, "plain bias² of unbiased runs {plain}");
    // Corrected: zero within its standard error. Per pixel and channel, (m - R)² - s²/K - v
    // has standard deviation about 0.008 here, so 1.4e-4 over 4096 pixels' 3 channels.
    let corrected = region(&unbiased, true);
    assert!(
        corrected.abs() < 5e-4,
        "corrected {corrected}, plain {plain}"
    );
    // A real bias of 0.1 (bias² 0.01) is still there.
    let real = region(&biased, true);
    assert!((real / (bias * bias) - 1.0).abs() < 0.15, "{real}");
}
