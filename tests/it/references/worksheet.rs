//! The worksheet scene against Mitsuba: every method region by region with its known bias,
//! the negative controls, and how path+splat's and SPPM's errors fall with their passes.

use super::{Measured, RES, RegionRef, misfits, reference_half, region_refs};
use crate::kit::*;
use film::Image;
use render::{Overrides, Rendered};
use scene::{MaterialDesc, Method, Scene, SceneFile};
use std::path::Path;

/// The worksheet scene's references.
const WORKSHEET_REF: &str = "cornell-spheres-analytic";

fn regions(scene: &Scene) -> Vec<RegionRef> {
    // The caustic's core too (within 0.8 sphere radii), where a fixed-k estimate's blur of
    // the focus shows most.
    let core = ("caustic core", lab::regions::caustic_region(scene, 0.8));
    let masks = lab::regions::regions(scene).into_iter().chain([core]);
    region_refs(WORKSHEET_REF, masks.collect())
}

/// The worksheet scene at 128 x 128 with `edit` applied (the negative controls).
fn scene(seed: u64, edit: impl FnOnce(&mut SceneFile)) -> Scene {
    worksheet_with(RES, seed, edit)
}

fn path_image(scene: &Scene, spp: u32) -> Image {
    let o = Overrides {
        method: Some(Method::Path),
        spp: Some(spp),
        ..Overrides::default()
    };
    sum_layers(&render_uncached(scene, &o, None), |_| true)
}

/// The edits of the negative controls: each must move some region out of its tolerance.
/// A named edit of the scene file.
type Control = (&'static str, Box<dyn Fn(&mut SceneFile)>);

fn controls() -> Vec<Control> {
    let lambertian = |albedo: [f32; 3], emission: [f32; 3]| MaterialDesc::Lambertian {
        albedo,
        emission,
        texture: None,
    };
    vec![
        (
            "light power +2%",
            Box::new(move |f: &mut SceneFile| {
                let e = [36.8 * 1.02, 31.2 * 1.02, 16.0 * 1.02];
                f.materials.insert("light".into(), lambertian([0.0; 3], e));
            }),
        ),
        (
            "white albedo -2%",
            Box::new(move |f: &mut SceneFile| {
                f.materials
                    .insert("white".into(), lambertian([0.9 * 0.98; 3], [0.0; 3]));
            }),
        ),
    ]
}

/// The path tracer at 256 spp (the default Sobol sampler), seeds 1-6: means over the seeds
/// +0.08% ± 0.02% (image), +0.54% ± 0.33% (caustic), -0.23% ± 0.10% (edges and corners),
/// -0.19% ± 0.09% (outer rim), +0.11% ± 0.25% (glass sphere), +0.12% ± 0.04% (open walls),
/// +0.75% ± 0.65% (caustic core). The image and the open walls read a little bright, and
/// more so at 64 spp (+0.19% ± 0.06% and +0.35% ± 0.12%), while the independent sampler at
/// 64 spp reads -0.01% ± 0.14% and -0.20% ± 0.16%: most likely a bias of the hash-based
/// Owen scramble that fades with the sample count. It is not allowed for here: the path
/// tracer is held to no bias, and the offset passes only while it stays within the noise.
const PATH_256: Measured = Measured {
    bias: [0.0; 7],
    sd: [0.0005, 0.0081, 0.0024, 0.0021, 0.0062, 0.0010, 0.0158],
};

/// The path tracer at 64 spp, seeds 1-6 (the figures above).
const PATH_64: Measured = Measured {
    bias: [0.0; 7],
    sd: [0.0014, 0.0170, 0.0096, 0.0116, 0.0102, 0.0029, 0.0393],
};

/// The path tracer (next-event estimation and BSDF sampling by MIS, the Sobol sampler):
/// every region's mean lies within 4 combined standard errors of Mitsuba's, with no bias
/// allowed ([`PATH_256`] has the measured offsets).
#[test]
fn the_path_tracer_matches_mitsuba_in_every_region() {
    let s = scene(1, |_| {});
    let regs = regions(&s);
    let bad = misfits(&path_image(&s, 256), &regs, &PATH_256);
    assert!(bad.is_empty(), "{bad:#?}");
}

/// The negative controls: the same comparison at 64 spp fails on each small change of the
/// scene (and passes without one, or the controls would prove nothing).
#[test]
fn the_reference_comparison_catches_a_two_percent_change() {
    let regs = regions(&scene(1, |_| {}));
    let check = |s: &Scene| {
        let img = path_image(s, 64);
        misfits(&img, &regs, &PATH_64)
    };
    let clean = check(&scene(2, |_| {}));
    assert!(clean.is_empty(), "unchanged scene: {clean:#?}");
    for (what, edit) in controls() {
        let bad = check(&scene(2, |f| edit(f)));
        eprintln!("{what}: {bad:#?}");
        assert!(!bad.is_empty(), "{what} passed the reference comparison");
    }
}

// ---------------------------------------------------------------------------------------------
// The photon-map methods.

/// Photon paths of the photon-map methods here. At the scene's 200 000 one run's region
/// means are about 1% noisy (the photons' own Monte Carlo noise: which surfaces a path's
/// bounces reach), too much to see a 2% change of the light; at 10^6, 0.4%.
const MAP_PHOTONS: u64 = 1_000_000;

/// Jensen's Gaussian as published integrates to `∫_0^1 w(t) 2t dt` over the unit disc
/// (Jensen 2001 §7.2: w(t) = α [1 - (1 - e^(-β t²/2)) / (1 - e^(-β))], α = 0.918,
/// β = 1.953): here by Simpson's rule, independently of `density`.
fn jensen_gaussian_integral() -> f64 {
    let (a, b) = (0.918f64, 1.953f64);
    let f = |t: f64| a * (1.0 - (1.0 - (-b * t * t / 2.0).exp()) / (1.0 - (-b).exp())) * 2.0 * t;
    let n = 1000;
    let h = 1.0 / n as f64;
    let inner: f64 = (1..n)
        .map(|i| f(i as f64 * h) * if i % 2 == 1 { 4.0 } else { 2.0 })
        .sum();
    h / 3.0 * (f(0.0) + inner + f(1.0))
}

/// A photon-map method's image of `s` with 10^6 photon paths traced into (or reused from)
/// `cache`, with `kernel` for the global map.
fn photon_map_image(s: &Scene, method: Method, kernel: Option<&str>, cache: &Path) -> Rendered {
    let o = Overrides {
        method: Some(method),
        photons: Some(MAP_PHOTONS),
        kernel: kernel.map(|k| k.parse().unwrap_or_else(|e| panic!("{e}"))),
        ..Overrides::default()
    };
    render(s, &o, cache, None)
}

/// The global map shown directly (k = 1000, 10^6 paths, one sample per pixel), per kernel,
/// seeds 1-6. Its fixed-k estimate has a bias the seeds resolve, and the kernels order it
/// as their shapes predict, flatter kernels blurring more: the outer rim reads 16-23% dark
/// (the disc runs off the box's open front), the inner edges and corners 1-1.5% bright (a
/// disc at a corner reaches the brighter wall beside it), the caustic 1-2% bright and its
/// core 2-5% (the focus, partly hidden under the sphere, spread over the visible floor).
/// The open walls hold no bias to 0.07%. The whole image's noise (0.9%) is the light's
/// outline, which one sample per pixel either hits or misses. Means over the seeds (± their
/// standard errors), in the regions' order:
///
/// | kernel | image | caustic | edges, corners | outer rim | glass | open walls | core |
/// |---|---|---|---|---|---|---|---|
/// | uniform | -0.63 ± 0.38 | +2.35 ± 0.42 | +1.53 ± 0.31 | -23.44 ± 0.47 | +0.61 ± 0.91 | +0.03 ± 0.06 | +5.31 ± 1.18 |
/// | silverman | -0.61 ± 0.38 | +0.88 ± 0.47 | +0.87 ± 0.30 | -17.30 ± 0.51 | +0.29 ± 0.90 | -0.02 ± 0.07 | +2.08 ± 1.41 |
/// | epanechnikov | -0.64 ± 0.38 | +1.33 ± 0.45 | +1.05 ± 0.30 | -19.68 ± 0.50 | +0.36 ± 0.91 | -0.03 ± 0.06 | +3.08 ± 1.30 |
/// | cone | -0.63 ± 0.38 | +1.14 ± 0.46 | +0.98 ± 0.30 | -18.60 ± 0.50 | +0.34 ± 0.90 | -0.03 ± 0.07 | +2.67 ± 1.36 |
/// | gaussian | -0.63 ± 0.38 | +1.73 ± 0.44 | +1.24 ± 0.30 | -21.01 ± 0.49 | +0.46 ± 0.91 | +0.00 ± 0.06 | +3.95 ± 1.26 |
/// | triweight | -0.59 ± 0.38 | +0.62 ± 0.50 | +0.77 ± 0.30 | -15.63 ± 0.52 | +0.26 ± 0.90 | -0.01 ± 0.07 | +1.49 ± 1.49 |
///
/// (percent). Jensen's Gaussian as published reads 45.97% ± 0.23% dark on the caustic, the
/// Gaussian's +1.73% times its integral 0.5311.
const GLOBAL_DIRECT: [(&str, Measured); 6] = [
    (
        "uniform",
        Measured {
            bias: [0.0, 0.0235, 0.0153, -0.2344, 0.0, 0.0, 0.0531],
            sd: [0.0093, 0.0103, 0.0075, 0.0115, 0.0222, 0.0015, 0.0288],
        },
    ),
    (
        "silverman",
        Measured {
            bias: [0.0, 0.0, 0.0, -0.1730, 0.0, 0.0, 0.0],
            sd: [0.0094, 0.0116, 0.0073, 0.0126, 0.0221, 0.0016, 0.0345],
        },
    ),
    (
        "epanechnikov",
        Measured {
            bias: [0.0, 0.0, 0.0105, -0.1968, 0.0, 0.0, 0.0],
            sd: [0.0093, 0.0110, 0.0073, 0.0122, 0.0222, 0.0016, 0.0319],
        },
    ),
    (
        "cone",
        Measured {
            bias: [0.0, 0.0, 0.0098, -0.1860, 0.0, 0.0, 0.0],
            sd: [0.0093, 0.0114, 0.0073, 0.0123, 0.0221, 0.0016, 0.0332],
        },
    ),
    (
        "gaussian",
        Measured {
            bias: [0.0, 0.0173, 0.0124, -0.2101, 0.0, 0.0, 0.0395],
            sd: [0.0093, 0.0108, 0.0074, 0.0119, 0.0222, 0.0016, 0.0308],
        },
    ),
    (
        "triweight",
        Measured {
            bias: [0.0, 0.0, 0.0, -0.1563, 0.0, 0.0, 0.0],
            sd: [0.0094, 0.0122, 0.0074, 0.0127, 0.0221, 0.0017, 0.0366],
        },
    ),
];

#[test]
fn the_global_map_shown_directly_matches_mitsuba_with_each_kernels_known_bias() {
    let s = scene(1, |_| {});
    let regs = regions(&s);
    let dir = TempDir::new("references-global-direct");
    let mut bad = Vec::new();
    for (kernel, measured) in &GLOBAL_DIRECT {
        eprintln!("global-direct, {kernel}:");
        let r = photon_map_image(&s, Method::GlobalDirect, Some(kernel), dir.path());
        bad.extend(
            misfits(&sum_layers(&r, |_| true), &regs, measured)
                .into_iter()
                .map(|m| format!("{kernel}: {m}")),
        );
    }
    // Jensen's Gaussian as published is the renormalised one times its integral: its global
    // layer divided by that closed form meets the Gaussian's figures.
    let i = jensen_gaussian_integral();
    assert!((i - 0.5311).abs() < 1e-3, "{i}");
    eprintln!("global-direct, gaussian_jensen (global layer / {i:.5}):");
    let r = photon_map_image(
        &s,
        Method::GlobalDirect,
        Some("gaussian_jensen"),
        dir.path(),
    );
    let mut img = layer(&r, "emitted").clone();
    let mut global = layer(&r, "global").clone();
    global.scale((1.0 / i) as f32);
    img.add(&global).unwrap_or_else(|e| panic!("{e}"));
    let gaussian = &GLOBAL_DIRECT
        .iter()
        .find(|(k, _)| *k == "gaussian")
        .unwrap()
        .1;
    bad.extend(
        misfits(&img, &regs, gaussian)
            .into_iter()
            .map(|m| format!("gaussian_jensen: {m}")),
    );
    assert!(bad.is_empty(), "{bad:#?}");
}

/// Final gathering (k = 1000 and 250, 16 gather rays through the irradiance cache, 10^6
/// paths, one sample per pixel), seeds 1-6: the caustic map's fixed-k blur is its one
/// resolved bias, +2.84% ± 0.72% over the caustic and +6.06% ± 1.46% in its core; the
/// global map, seen only through gather rays, leaves the rim at -1.90% ± 0.73% and the open
/// walls at -0.07% ± 0.06%.
const FINAL_GATHER: Measured = Measured {
    bias: [0.0, 0.0284, 0.0, 0.0, 0.0, 0.0, 0.0606],
    sd: [0.0095, 0.0177, 0.0088, 0.0179, 0.0186, 0.0015, 0.0358],
};

#[test]
fn final_gathering_matches_mitsuba_and_needs_each_of_its_layers() {
    let s = scene(1, |_| {});
    let regs = regions(&s);
    let dir = TempDir::new("references-final-gather");
    let r = photon_map_image(&s, Method::FinalGather, None, dir.path());
    eprintln!("final gathering:");
    let bad = misfits(&sum_layers(&r, |_| true), &regs, &FINAL_GATHER);
    assert!(bad.is_empty(), "{bad:#?}");
    // Each layer is resolved: without it some region fails.
    for left_out in ["direct", "caustic", "indirect"] {
        eprintln!("final gathering without its {left_out} layer:");
        let bad = misfits(&sum_layers(&r, |l| l != left_out), &regs, &FINAL_GATHER);
        assert!(!bad.is_empty(), "the {left_out} layer is not resolved");
    }
}

// ---------------------------------------------------------------------------------------------
// The splatted caustic layers and SPPM.

/// `path+splat` at 256 spp (the scene's splat settings: one pass of eye vertices and
/// 200 000 caustic paths), seeds 1-6. The caustics splatted onto later eye vertices use
/// discs of a fixed radius (2% of the scene's diagonal), which lose part of their mass past
/// the box's edges: -0.79% ± 0.17% over the edges and corners, -0.84% ± 0.09% over the
/// outer rim. Elsewhere none is resolved: image -0.03% ± 0.03%, caustic -0.49% ± 0.39%,
/// glass sphere +0.58% ± 0.28%, open walls +0.01% ± 0.06%, caustic core -1.38% ± 1.28%.
const PATH_SPLAT: Measured = Measured {
    bias: [0.0, 0.0, -0.0079, -0.0084, 0.0, 0.0, 0.0],
    sd: [0.0008, 0.0096, 0.0042, 0.0023, 0.0069, 0.0013, 0.0314],
};

#[test]
fn the_splatted_caustics_match_mitsuba_alone_and_with_the_path_tracer() {
    let s = scene(1, |_| {});
    let regs = regions(&s);
    let run = |method, spp, caustics| {
        let o = Overrides {
            method: Some(method),
            spp,
            caustics,
            ..Overrides::default()
        };
        render_uncached(&s, &o, None)
    };
    eprintln!("path+splat:");
    let path_splat = sum_layers(&run(Method::PathSplat, Some(256), None), |_| true);
    let mut bad = misfits(&path_splat, &regs, &PATH_SPLAT);
    // caustic-splat's layers are exactly what the path tracer leaves out with `caustics =
    // false`: added to it, the same figures hold; without them the caustic fails.
    let no_caustics = sum_layers(&run(Method::Path, Some(256), Some(false)), |_| true);
    let mut added = no_caustics.clone();
    let splat = run(Method::CausticSplat, None, None);
    assert_eq!(
        splat
            .layers
            .iter()
            .map(|l| l.name.as_str())
            .collect::<Vec<_>>(),
        ["caustic", "caustic_indirect"]
    );
    added
        .add(&sum_layers(&splat, |_| true))
        .unwrap_or_else(|e| panic!("{e}"));
    eprintln!("caustic-splat + path without caustics:");
    bad.extend(misfits(&added, &regs, &PATH_SPLAT));
    assert!(bad.is_empty(), "{bad:#?}");
    eprintln!("path without caustics alone:");
    let without = misfits(&no_caustics, &regs, &PATH_SPLAT);
    assert!(
        without.iter().any(|m| m.starts_with("caustic:")),
        "the splatted layers are not resolved: {without:#?}"
    );
}

/// SPPM after 16 passes of the scene's 200 000 paths (boundary correction on, the
/// default), seeds 1-6. The correction overshoots at the inner edges and corners by +1.30%
/// ± 0.09% (it takes the density on the disc's part on the surface for the density at its
/// centre, and indirect light falls off into a corner; the bias shrinks with the radii).
/// Elsewhere none is resolved: image +0.07% ± 0.16%, caustic -0.17% ± 0.26%, outer rim
/// +0.16% ± 0.23%, glass sphere +0.93% ± 0.84%, open walls -0.03% ± 0.03%, caustic core
/// -0.72% ± 0.49%. Without the correction the outer rim read -5.38% ± 0.21%, and with photon
/// paths cut at 16 hits (the old default) the open walls -0.16% ± 0.04% (64 passes).
const SPPM_16: Measured = Measured {
    bias: [0.0, 0.0, 0.0130, 0.0, 0.0, 0.0, 0.0],
    sd: [0.0039, 0.0063, 0.0022, 0.0056, 0.0207, 0.0008, 0.0119],
};

/// SPPM's image of the scene with `seed`, 16 passes, with or without its boundary
/// correction (`[estimate.sppm] boundary`).
fn sppm_image(seed: u64, boundary: bool) -> Image {
    let s = scene(seed, |f| {
        let mut t = toml::Table::new();
        t.insert("boundary".into(), boundary.into());
        f.estimate.insert("sppm".into(), t.into());
    });
    let o = Overrides {
        method: Some(Method::Sppm),
        passes: Some(16),
        ..Overrides::default()
    };
    sum_layers(&render_uncached(&s, &o, None), |_| true)
}

#[test]
fn sppm_matches_mitsuba_and_its_rim_needs_the_boundary_correction() {
    let regs = regions(&scene(1, |_| {}));
    eprintln!("sppm, 16 passes:");
    let bad = misfits(&sppm_image(1, true), &regs, &SPPM_16);
    assert!(bad.is_empty(), "{bad:#?}");
    eprintln!("sppm, 16 passes, no boundary correction:");
    let bad = misfits(&sppm_image(1, false), &regs, &SPPM_16);
    assert!(
        bad.iter().any(|m| m.starts_with("outer rim:")),
        "the boundary correction is not resolved: {bad:#?}"
    );
}

// ---------------------------------------------------------------------------------------------
// Convergence: path+splat's error falls with its passes, SPPM's glass is smooth after one.

/// The worksheet's reference halves, for noise-corrected errors.
fn worksheet_halves() -> film::Halves {
    let (a, b) = (
        reference_half(WORKSHEET_REF, "a"),
        reference_half(WORKSHEET_REF, "b"),
    );
    film::Halves::new(&a, &b).expect("same size")
}

/// Relative MSE of `img` against the halves' mean with the reference's noise taken out, over
/// `mask` (or the whole image).
fn corrected_relmse(img: &Image, h: &film::Halves, mask: Option<&film::Mask>) -> f64 {
    film::metrics_halves(img, h, mask)
        .expect("same size")
        .relmse
}

/// path+splat's passes with the path tracer's samples in their ratio (`--passes` alone).
fn path_splat_passes(s: &Scene, passes: u32) -> Image {
    let o = Overrides {
        method: Some(Method::PathSplat),
        passes: Some(passes),
        ..Overrides::default()
    };
    sum_layers(&render_uncached(s, &o, None), |_| true)
}

/// An unbiased estimator's error falls fourfold with fourfold work. path+splat's splatted
/// caustics shrink their footprints from pass to pass (`[estimate.splat] alpha`), so their
/// blur fades too. Measured (noise-corrected relative MSE, seed 1; 4 samples per pixel and
/// 50,000 caustic paths per pass): 4, 16, 64, 256 passes read 0.02067, 0.00504, 0.00134,
/// 0.00037 (4.1x, 3.8x, 3.6x); seed 2 reads 0.00496 and 0.00137 at 16 and 64 (3.6x). With
/// fixed footprints (`alpha = 1`) seed 1 falls only 2.8x from 16 to 64 passes (0.00543,
/// 0.00193), and with 16 samples per pass it stalled at 0.0058, 0.0020, 0.0011 for 4, 16, 64
/// passes (2.9x, then 1.9x). Here 16 and 64 passes of seeds 1 and 2 must fall threefold.
#[test]
fn path_splat_error_falls_as_an_unbiased_estimators_does() {
    let h = worksheet_halves();
    for seed in [1, 2] {
        let s = scene(seed, |_| {});
        let e16 = corrected_relmse(&path_splat_passes(&s, 16), &h, None);
        let e64 = corrected_relmse(&path_splat_passes(&s, 64), &h, None);
        eprintln!(
            "seed {seed}: 16 passes {e16:.5}, 64 passes {e64:.5}: {:.2}x",
            e16 / e64
        );
        assert!(e16 / e64 >= 3.0, "seed {seed}: {e16:.5} -> {e64:.5}");
    }
}

/// SPPM's visible points split at the glass sphere (`[estimate.sppm] splits`): each Fresnel
/// branch has its own statistics, so one pass already sees both what the glass reflects and
/// what it refracts. Measured over the glass region after one pass (noise-corrected relative
/// MSE, seed 1, 128 x 128): 0.067 with splits, 0.900 without (the classic one point per
/// pixel, a random branch per pass); after 4 passes 0.018 against 0.404. Seed 2 reads 0.124
/// with splits after one pass.
#[test]
fn sppm_glass_is_smooth_after_one_pass() {
    let h = worksheet_halves();
    let s = scene(1, |_| {});
    let glass = lab::regions::regions(&s)
        .into_iter()
        .find(|(n, _)| *n == "glass sphere")
        .map(|(_, m)| m)
        .expect("a glass region");
    let run = |splits: u32| {
        let s = scene(1, |f| {
            let mut t = toml::Table::new();
            t.insert("splits".into(), i64::from(splits).into());
            f.estimate.insert("sppm".into(), t.into());
        });
        let o = Overrides {
            method: Some(Method::Sppm),
            passes: Some(1),
            ..Overrides::default()
        };
        let img = sum_layers(&render_uncached(&s, &o, None), |_| true);
        corrected_relmse(&img, &h, Some(&glass))
    };
    let (split, single) = (run(2), run(0));
    eprintln!("glass after one pass: splits {split:.4}, none {single:.4}");
    assert!(split < 0.15, "split glass: {split}");
    assert!(split * 3.0 <= single, "{split} against {single}");
}

/// Vertex connection and merging, 16 passes (one light and one eye subpath per pixel each),
/// seeds 1-6, `m / ref - 1` in percent (mean ± one run's standard deviation):
///
/// | image | caustic | edges, corners | outer rim | glass | open walls | core |
/// |---|---|---|---|---|---|---|
/// | -0.11 ± 0.30 | -0.00 ± 0.72 | +0.56 ± 0.46 | -0.66 ± 0.40 | -0.73 ± 1.95 | -0.07 ± 0.15 | -0.17 ± 1.71 |
///
/// The outer rim's -0.7% is resolved (z -4.1 over the seeds): merging's disc runs off the
/// box's open front there, as the global map's does (-16% to -23% at k = 1000), at a radius
/// of one pixel's footprint and with its share of the indirect light. Elsewhere no bias is
/// resolved, the caustic's core included (|z| < 3).
const VCM_16: Measured = Measured {
    bias: [0.0, 0.0, 0.0, -0.0066, 0.0, 0.0, 0.0],
    sd: [0.0030, 0.0072, 0.0046, 0.0040, 0.0195, 0.0015, 0.0171],
};

/// Vertex connection and merging on the worksheet: every region within its tolerance of
/// Mitsuba's, the caustic and its core included (merging carries the caustic seen on the
/// floor, connections and path tracing the rest).
#[test]
fn vcm_matches_mitsuba_in_every_region() {
    let s = scene(super::table_seed(), |_| {});
    let regs = regions(&s);
    eprintln!("vcm, 16:");
    let bad = misfits(&super::image_by(&s, Method::Vcm, 16), &regs, &VCM_16);
    assert!(bad.is_empty(), "{bad:#?}");
}
