//! photonflow against an independent renderer: region means of its images of the worksheet
//! scene at 128 x 128 against Mitsuba 3's (`tests/references/`, two halves with independent
//! seeds, made by `tests/references/make.sh`). Regions come from the scene's geometry
//! (`lab::regions`): the whole image, the caustic under the glass sphere, the inner edges and
//! corners, the outer rim, the glass sphere, the open walls.
//!
//! Every method is compared: the path tracer, the global map shown directly with each
//! kernel, final gathering, the splatted caustic layers (alone, added to the path tracer
//! without its caustics, and as `path+splat`) and SPPM. A region's tolerance is `Z`
//! combined standard errors: the reference's, from its halves (`(A - B)/2` per pixel), and
//! photonflow's, measured over independent seeds (the figures are in each method's table),
//! around the method's known bias where it has one (fixed-k estimates, fixed splat discs).
//! Negative controls change the scene a little (a light's power or one albedo by 2%) or
//! leave a layer out, and must fail.
//!
//! A glass sphere's refraction barely moves a region mean of the worksheet's wide view: the
//! light's image in the sphere and the caustic's focus are a few pixels there. The close-up
//! (`scenes/cornell-spheres/closeup.toml`, its own Mitsuba halves) resolves them, and a glass
//! of index 1.45 instead of 1.5 must fail it.

use crate::kit::*;
use film::Image;
use render::Overrides;
use render::Rendered;
use scene::{MaterialDesc, Method, Scene, SceneFile};
use std::path::Path;

const RES: u32 = 128;
/// Combined standard errors a region mean may lie from the reference's.
const Z: f64 = 4.0;

/// The worksheet scene's references.
const WORKSHEET_REF: &str = "cornell-spheres-analytic";

fn reference_half(name: &str, half: &str) -> Image {
    let p = scenes_dir()
        .join("../tests/references")
        .join(format!("{name}-{RES}x{RES}-{half}.exr"));
    film::read_exr(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

/// The grey value of a pixel: its channels' mean.
fn grey(img: &Image, i: usize) -> f64 {
    img.data[i].iter().map(|&c| c as f64).sum::<f64>() / 3.0
}

/// Per region: the reference's mean (of the halves' mean) and its standard error.
struct RegionRef {
    name: &'static str,
    mask: film::Mask,
    mean: f64,
    se: f64,
}

fn regions(scene: &Scene) -> Vec<RegionRef> {
    // The caustic's core too (within 0.8 sphere radii), where a fixed-k estimate's blur of
    // the focus shows most.
    let core = ("caustic core", lab::regions::caustic_region(scene, 0.8));
    let masks = lab::regions::regions(scene).into_iter().chain([core]);
    region_refs(WORKSHEET_REF, masks.collect())
}

/// The reference `name`'s mean and standard error over each of `masks`' non-empty regions.
fn region_refs(name: &str, masks: Vec<(&'static str, film::Mask)>) -> Vec<RegionRef> {
    let (a, b) = (reference_half(name, "a"), reference_half(name, "b"));
    region_refs_of(&a, &b, masks)
}

/// [`region_refs`] of the halves `a` and `b`.
fn region_refs_of(a: &Image, b: &Image, masks: Vec<(&'static str, film::Mask)>) -> Vec<RegionRef> {
    masks
        .into_iter()
        .filter(|(_, m)| m.count() > 0)
        .map(|(name, mask)| {
            let (mut sum, mut var, mut n) = (0.0, 0.0, 0.0);
            for i in (0..mask.pixels.len()).filter(|&i| mask.pixels[i]) {
                let (ga, gb) = (grey(a, i), grey(b, i));
                sum += 0.5 * (ga + gb);
                // The mean of two halves has variance (A - B)²/4 per pixel (unbiased).
                var += 0.25 * (ga - gb) * (ga - gb);
                n += 1.0;
            }
            RegionRef {
                name,
                mask,
                mean: sum / n,
                se: var.sqrt() / n,
            }
        })
        .collect()
}

/// The region means of `img` over `regions`.
fn means(img: &Image, regions: &[RegionRef]) -> Vec<f64> {
    regions
        .iter()
        .map(|r| {
            let idx: Vec<usize> = (0..r.mask.pixels.len())
                .filter(|&i| r.mask.pixels[i])
                .collect();
            idx.iter().map(|&i| grey(img, i)).sum::<f64>() / idx.len() as f64
        })
        .collect()
}

/// A method's region means against the reference's, `m / ref - 1`, measured over seeds 1-6,
/// per region in the order of `lab::regions::regions` (image, caustic, edges and corners,
/// outer rim, glass sphere, open walls) and the caustic's core: `bias` is the mean over the seeds where it lies
/// more than 3 of its standard errors from zero (the method's known bias), else 0; `sd` is
/// one run's standard deviation.
struct Measured<const N: usize = 7> {
    bias: [f64; N],
    sd: [f64; N],
}

/// Seeds behind every [`Measured`] table.
const SEEDS: f64 = 6.0;

/// Regions where `img` lies more than `Z` combined standard errors from the reference moved
/// by the method's known bias: the reference's standard error, one run's, and, where a bias
/// is allowed, the standard error of its measured value.
fn misfits<const N: usize>(img: &Image, regions: &[RegionRef], m: &Measured<N>) -> Vec<String> {
    assert_eq!(regions.len(), N, "the regions of the tables");
    let got = means(img, regions);
    let mut out = Vec::new();
    for (i, (r, g)) in regions.iter().zip(got).enumerate() {
        let (bias, sd) = (m.bias[i], m.sd[i]);
        let bias_se = if bias != 0.0 { sd / SEEDS.sqrt() } else { 0.0 };
        let rel_se = ((r.se / r.mean).powi(2) + sd * sd + bias_se * bias_se).sqrt();
        let rel = g / r.mean - 1.0;
        let z = (rel - bias) / rel_se;
        eprintln!(
            "  {:<18} photonflow {g:.6} reference {:.6} ({:+.3}%, known bias {:+.3}%, z {z:+.2}; \
             ref se {:.3}%)",
            r.name,
            r.mean,
            100.0 * rel,
            100.0 * bias,
            100.0 * r.se / r.mean
        );
        if z.abs() > Z {
            out.push(format!(
                "{}: {g:.6} against {:.6} ({:+.2}%, known bias {:+.2}%, z {z:+.1})",
                r.name,
                r.mean,
                100.0 * rel,
                100.0 * bias
            ));
        }
    }
    out
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
// The glass sphere close up: its refraction.

/// The close-up's references: `scenes/cornell-spheres/closeup.toml`, the worksheet scene
/// through a 20-degree lens on the glass sphere and its caustic.
const CLOSEUP_REF: &str = "cornell-spheres-closeup";

/// The close-up of the glass sphere at 128 x 128, `edit` applied.
fn closeup(seed: u64, edit: impl FnOnce(&mut SceneFile)) -> Scene {
    scene_at("cornell-spheres/closeup.toml", RES, seed, edit)
}

/// The close-up's regions: the whole image, the glass sphere, the caustic, the open walls,
/// and where the refraction shows most: the glass sphere's pixels and the caustic's that the
/// reference shows at more than twice their region's mean (the light seen through the
/// sphere, and the caustic's focus). Seen through the worksheet's wide lens the light's
/// image in the sphere covers a few pixels, partly, and the focus blurs into its
/// neighbours; here each is tens of pixels, so a change of the glass's index moves them
/// whole pixels (1.5 to 1.45 shifts the light's image by about 3).
fn closeup_regions(scene: &Scene) -> Vec<RegionRef> {
    let (a, b) = (
        reference_half(CLOSEUP_REF, "a"),
        reference_half(CLOSEUP_REF, "b"),
    );
    let r = |i: usize| 0.5 * (grey(&a, i) + grey(&b, i));
    let named = lab::regions::regions(scene);
    let get = |name: &str| {
        let (_, m) = named.iter().find(|(n, _)| *n == name).unwrap();
        m.clone()
    };
    let bright = |m: &film::Mask| {
        let idx: Vec<usize> = (0..m.pixels.len()).filter(|&i| m.pixels[i]).collect();
        let mean = idx.iter().map(|&i| r(i)).sum::<f64>() / idx.len() as f64;
        let mut out = m.clone();
        for &i in &idx {
            out.pixels[i] = r(i) > 2.0 * mean;
        }
        out
    };
    let (glass, caustic) = (get("glass sphere"), get("caustic"));
    let masks = vec![
        ("image", get("image")),
        ("glass sphere", glass.clone()),
        ("caustic", caustic.clone()),
        ("open walls", get("open walls")),
        ("light through glass", bright(&glass)),
        ("caustic focus", bright(&caustic)),
    ];
    region_refs(CLOSEUP_REF, masks)
}

/// The close-up's tables, regions in [`closeup_regions`]' order (image, glass sphere,
/// caustic, open walls, light through glass, caustic focus), seeds 1-6, `m / ref - 1` in
/// percent, mean ± one run's standard deviation:
///
/// | run | image | glass | caustic | walls | light through glass | caustic focus |
/// |---|---|---|---|---|---|---|
/// | path, 256 spp | +0.10 ± 0.09 | +0.17 ± 0.13 | +0.06 ± 0.20 | +0.05 ± 0.13 | +1.46 ± 1.67 | +0.13 ± 0.75 |
/// | path+splat, 64 spp | -0.01 ± 0.24 | -0.04 ± 0.56 | +0.21 ± 0.28 | -0.04 ± 0.24 | +1.30 ± 1.88 | -1.93 ± 0.83 |
/// | sppm, 16 passes | +0.02 ± 0.32 | +0.03 ± 0.92 | +0.05 ± 0.09 | -0.02 ± 0.15 | -2.80 ± 10.5 | -1.89 ± 0.29 |
///
/// The splatted and SPPM focus reads 1.9% dark (fixed splat discs and SPPM's radii blur the
/// focus into its rim); nothing else is resolved. SPPM follows one Fresnel branch per pass,
/// so after 16 passes the light seen through the sphere is still speckled (10% per run).
/// With the glass's index at 1.45 (seeds 7, 8) the light through the glass reads -19.5%
/// (path), -16.0% (path+splat) and -25.2% (SPPM), the focus -6.0%, -9.4% and -7.6%.
const CLOSEUP_PATH_256: Measured<6> = Measured {
    bias: [0.0; 6],
    sd: [0.0009, 0.0013, 0.0020, 0.0013, 0.0167, 0.0075],
};

/// `path+splat` at 64 spp on the close-up (the table above).
const CLOSEUP_PATH_SPLAT_64: Measured<6> = Measured {
    bias: [0.0, 0.0, 0.0, 0.0, 0.0, -0.0193],
    sd: [0.0024, 0.0056, 0.0028, 0.0024, 0.0188, 0.0083],
};

/// SPPM at 16 passes on the close-up (the table above).
const CLOSEUP_SPPM_16: Measured<6> = Measured {
    bias: [0.0, 0.0, 0.0, 0.0, 0.0, -0.0189],
    sd: [0.0032, 0.0092, 0.0009, 0.0015, 0.1053, 0.0029],
};

/// One image of `s` by `method` at `count` samples per pixel (path, path+splat) or passes
/// (SPPM).
fn image_by(s: &Scene, method: Method, count: u32) -> Image {
    let o = Overrides {
        method: Some(method),
        spp: (method != Method::Sppm).then_some(count),
        passes: (method == Method::Sppm).then_some(count),
        ..Overrides::default()
    };
    sum_layers(&render_uncached(s, &o, None), |_| true)
}

/// The misfits of each run's image of `s` (method, count, its table) against `regs`.
fn misfits_of_runs<const N: usize>(
    s: &Scene,
    regs: &[RegionRef],
    runs: &[(Method, u32, &Measured<N>)],
) -> Vec<String> {
    let mut bad = Vec::new();
    for &(method, count, table) in runs {
        eprintln!("{method:?}, {count}:");
        bad.extend(misfits(&image_by(s, method, count), regs, table));
    }
    bad
}

/// The refraction of the glass sphere as Mitsuba renders it: the light seen through it and
/// the caustic's focus, by the path tracer, the path tracer with splatted caustics, and SPPM.
#[test]
fn the_glass_sphere_close_up_matches_mitsuba() {
    let s = closeup(1, |_| {});
    let regs = closeup_regions(&s);
    let runs = [
        (Method::Path, 256, &CLOSEUP_PATH_256),
        (Method::PathSplat, 64, &CLOSEUP_PATH_SPLAT_64),
        (Method::Sppm, 16, &CLOSEUP_SPPM_16),
    ];
    let bad = misfits_of_runs(&s, &regs, &runs);
    assert!(bad.is_empty(), "{bad:#?}");
}

/// The negative control of the glass: its index of refraction 1.45 instead of 1.5 moves the
/// light's image in the sphere and the caustic's focus, and the close-up's comparison fails
/// for the path tracer and for `path+splat`. (SPPM's speckled glass after 16 passes hides
/// it: -25% against a 10% standard deviation.)
#[test]
fn the_close_up_catches_a_glass_of_index_1_45() {
    let regs = closeup_regions(&closeup(1, |_| {}));
    let s = closeup(2, |f| {
        f.materials.insert(
            "glass".into(),
            MaterialDesc::Dielectric {
                ior: 1.45,
                transmittance: [1.0; 3],
                absorption: [0.0; 3],
            },
        );
    });
    for (method, count, table) in [
        (Method::Path, 256, &CLOSEUP_PATH_256),
        (Method::PathSplat, 64, &CLOSEUP_PATH_SPLAT_64),
    ] {
        eprintln!("{method:?}, {count}, index 1.45:");
        let bad = misfits(&image_by(&s, method, count), &regs, table);
        assert!(
            bad.iter().any(|m| m.starts_with("light through glass:")),
            "{method:?}: a glass of index 1.45 passed: {bad:#?}"
        );
    }
}

// ---------------------------------------------------------------------------------------------
// A glossy receiver: the worksheet scene with a glossy floor.

/// The glossy floor's references: `scenes/cornell-glossy/glossy-floor.toml`, the worksheet
/// scene whose floor is MTL `illum 2` (Lambertian `Kd` 0.5 plus a GGX lobe of `Ks` 0.4,
/// `Ns` 100), rendered by Mitsuba with the same mapping.
const GLOSSY_REF: &str = "cornell-glossy";

/// The glossy-floor scene at 128 x 128, `edit` applied.
fn glossy(seed: u64, edit: impl FnOnce(&mut SceneFile)) -> Scene {
    scene_at("cornell-glossy/glossy-floor.toml", RES, seed, edit)
}

/// The glossy scene's regions: those of the worksheet (the caustic now on the glossy floor),
/// and the caustic's core.
fn glossy_regions(scene: &Scene) -> Vec<RegionRef> {
    let core = ("caustic core", lab::regions::caustic_region(scene, 0.8));
    let masks = lab::regions::regions(scene).into_iter().chain([core]);
    region_refs(GLOSSY_REF, masks.collect())
}

/// The glossy floor's tables, regions in [`glossy_regions`]' order (image, caustic, edges and
/// corners, outer rim, glass sphere, open walls, caustic core), seeds 1-6, `m / ref - 1` in
/// percent, mean ± one run's standard deviation:
///
/// | run | image | caustic | edges, corners | outer rim | glass | open walls | core |
/// |---|---|---|---|---|---|---|---|
/// | path, 256 spp | +0.03 ± 0.12 | +0.14 ± 0.95 | -0.01 ± 0.75 | +0.25 ± 0.30 | -0.08 ± 0.69 | +0.02 ± 0.17 | -0.43 ± 2.02 |
/// | path+splat, 256 spp | +0.02 ± 0.09 | +1.41 ± 2.39 | -0.90 ± 0.40 | -0.24 ± 0.41 | +1.08 ± 0.87 | -0.05 ± 0.13 | +4.47 ± 7.18 |
/// | sppm, 16 passes | -0.02 ± 0.50 | -1.65 ± 1.82 | +1.43 ± 0.17 | +0.05 ± 3.19 | +1.02 ± 3.09 | -0.12 ± 0.29 | -1.24 ± 5.40 |
///
/// The known biases are the worksheet's: `path+splat`'s fixed indirect discs at the edges
/// (-0.9%) and a small excess in the glass sphere (+1.1% ± 0.35%; the worksheet's +0.58% ±
/// 0.28%), SPPM's boundary correction overshooting into the corners (+1.4%). On the glossy
/// floor the splatted caustic is noisier than on the worksheet's (2.4% per run against 1.0%):
/// an eye vertex takes the floor's diffuse lobe with probability 0.56 only (its GGX lobe is
/// followed as a path), so fewer vertices read the caustic, each with more weight.
const GLOSSY_PATH_256: Measured = Measured {
    bias: [0.0; 7],
    sd: [0.0012, 0.0095, 0.0075, 0.0030, 0.0069, 0.0017, 0.0202],
};

/// `path+splat` at 256 spp on the glossy floor (the table above).
const GLOSSY_PATH_SPLAT_256: Measured = Measured {
    bias: [0.0, 0.0, -0.0090, 0.0, 0.0108, 0.0, 0.0],
    sd: [0.0009, 0.0239, 0.0040, 0.0041, 0.0087, 0.0013, 0.0718],
};

/// SPPM at 16 passes on the glossy floor (the table above).
const GLOSSY_SPPM_16: Measured = Measured {
    bias: [0.0, 0.0, 0.0143, 0.0, 0.0, 0.0, 0.0],
    sd: [0.0050, 0.0182, 0.0017, 0.0319, 0.0309, 0.0029, 0.0540],
};

/// A glossy receiver under the glass sphere (MTL `illum 2`: Lambertian plus GGX): the path
/// tracer, the path tracer with splatted caustics and SPPM each match Mitsuba in every
/// region, the caustic on the glossy floor included. Drawn without its GGX lobe (what
/// photonflow did with `illum 2` before), the floor fails.
#[test]
fn a_glossy_receiver_matches_mitsuba() {
    let s = glossy(1, |_| {});
    let regs = glossy_regions(&s);
    let runs = [
        (Method::Path, 256, &GLOSSY_PATH_256),
        (Method::PathSplat, 256, &GLOSSY_PATH_SPLAT_256),
        (Method::Sppm, 16, &GLOSSY_SPPM_16),
    ];
    let bad = misfits_of_runs(&s, &regs, &runs);
    assert!(bad.is_empty(), "{bad:#?}");
    let lambertian = glossy(1, |f| {
        f.materials.insert(
            "floor".into(),
            MaterialDesc::Lambertian {
                albedo: [0.5; 3],
                emission: [0.0; 3],
                texture: None,
            },
        );
    });
    eprintln!("path, 256, the floor without its GGX lobe:");
    let bad = misfits(
        &image_by(&lambertian, Method::Path, 256),
        &regs,
        &GLOSSY_PATH_256,
    );
    assert!(!bad.is_empty(), "the floor's glossy lobe is not resolved");
}

// ---------------------------------------------------------------------------------------------
// Rough spheres: a GGX metal and GGX glass over the glossy floor.

/// `scenes/cornell-glossy/rough-spheres.toml`: the glossy-floor scene with a rough metal
/// sphere (alpha 0.2) and a rough glass sphere (alpha 0.1, index 1.5), Mitsuba's
/// `roughconductor` and `roughdielectric` in its references.
fn rough(seed: u64, edit: impl FnOnce(&mut SceneFile)) -> Scene {
    scene_at("cornell-glossy/rough-spheres.toml", RES, seed, edit)
}

/// The rough scene's tables, regions as [`glossy_regions`]' (the caustic now under rough
/// glass), seeds 1-6, percent, mean ± one run's standard deviation:
///
/// | run | image | caustic | edges, corners | outer rim | glass | open walls | core |
/// |---|---|---|---|---|---|---|---|
/// | path, 256 spp | +0.02 ± 0.07 | +0.36 ± 0.63 | -0.05 ± 0.32 | +0.06 ± 0.35 | +0.02 ± 0.73 | -0.01 ± 0.08 | +0.99 ± 2.35 |
/// | sppm, 16 passes | -0.04 ± 0.42 | -1.54 ± 2.24 | +1.44 ± 0.12 | +0.73 ± 3.21 | +1.00 ± 2.43 | -0.15 ± 0.26 | -0.84 ± 7.73 |
///
/// No caustic here is a photon map's or a splat's (light through rough glass has made a
/// glossy bounce): the path tracer and the global photons carry it, and `path+splat` is the
/// path tracer. SPPM's only resolved bias is its boundary correction's overshoot into the
/// corners (+1.4%). Final gathering (10^6 paths) matches too but its gather rays through
/// the rough spheres leave it 12% noisy per run in the caustic and the glass.
const ROUGH_PATH_256: Measured = Measured {
    bias: [0.0; 7],
    sd: [0.0007, 0.0063, 0.0032, 0.0035, 0.0073, 0.0008, 0.0235],
};

/// SPPM at 16 passes on the rough scene (the table above).
const ROUGH_SPPM_16: Measured = Measured {
    bias: [0.0, 0.0, 0.0144, 0.0, 0.0, 0.0, 0.0],
    sd: [0.0042, 0.0224, 0.0012, 0.0321, 0.0243, 0.0026, 0.0773],
};

/// Rough metal and rough glass (GGX) as Mitsuba renders them, by the path tracer and SPPM.
/// The same spheres smooth (a mirror metal, clear glass) fail: the rough lobes are resolved.
#[test]
fn rough_spheres_match_mitsuba() {
    let s = rough(1, |_| {});
    let core = ("caustic core", lab::regions::caustic_region(&s, 0.8));
    let masks = lab::regions::regions(&s).into_iter().chain([core]);
    let regs = region_refs("cornell-rough", masks.collect());
    let runs = [
        (Method::Path, 256, &ROUGH_PATH_256),
        (Method::Sppm, 16, &ROUGH_SPPM_16),
    ];
    let bad = misfits_of_runs(&s, &regs, &runs);
    assert!(bad.is_empty(), "{bad:#?}");
    let smooth = rough(1, |f| {
        f.materials.insert(
            "silver".into(),
            MaterialDesc::Metal {
                reflectance: [0.96, 0.98, 0.96],
            },
        );
        f.materials.insert(
            "glass".into(),
            MaterialDesc::Dielectric {
                ior: 1.5,
                transmittance: [1.0; 3],
                absorption: [0.0; 3],
            },
        );
    });
    eprintln!("path, 256, smooth spheres:");
    let bad = misfits(
        &image_by(&smooth, Method::Path, 256),
        &regs,
        &ROUGH_PATH_256,
    );
    assert!(
        bad.iter().any(|m| m.starts_with("caustic")),
        "the rough glass is not resolved: {bad:#?}"
    );
}

// ---------------------------------------------------------------------------------------------
// Coloured glass: the worksheet's glass sphere transmitting (0.9, 0.6, 0.3) per crossing.

/// `scenes/cornell-spheres/coloured-glass.toml`'s references: Mitsuba's `dielectric` with
/// `specular_transmittance` (the peers' mapping of MTL `Tf`).
const COLOURED_REF: &str = "cornell-coloured-glass";

fn coloured(seed: u64, edit: impl FnOnce(&mut SceneFile)) -> Scene {
    scene_at("cornell-spheres/coloured-glass.toml", RES, seed, edit)
}

/// Channel `c` of `img` in all three channels: the region helpers, which read a pixel's
/// channel mean, then read that channel.
fn channel(img: &Image, c: usize) -> Image {
    Image {
        width: img.width,
        height: img.height,
        data: img.data.iter().map(|p| [p[c]; 3]).collect(),
    }
}

const CHANNELS: [&str; 3] = ["red", "green", "blue"];

/// The coloured glass's tables, per channel, regions as [`regions`]' with the caustic's
/// core, seeds 1-6, `m / ref - 1` in percent, mean ± one run's standard deviation (`*`: more
/// than 3 standard errors from zero):
///
/// | run | channel | image | caustic | edges, corners | outer rim | glass | open walls | core |
/// |---|---|---|---|---|---|---|---|---|
/// | path, 256 spp | red | +0.03 ± 0.08 | +0.44 ± 0.95 | -0.31 ± 0.38 | -0.11 ± 0.17 | +0.32 ± 0.81 | +0.03 ± 0.12 | +0.69 ± 1.21 |
/// | | green | +0.04 ± 0.02* | +0.54 ± 0.51 | -0.05 ± 0.32 | -0.08 ± 0.40 | +0.39 ± 0.32 | +0.06 ± 0.04* | +0.06 ± 0.91 |
/// | | blue | +0.01 ± 0.06 | +0.55 ± 0.95 | -0.45 ± 0.36* | -0.15 ± 0.57 | +0.61 ± 1.59 | +0.02 ± 0.14 | +0.51 ± 2.97 |
/// | sppm, 16 passes | red | +0.06 ± 0.39 | -0.21 ± 0.61 | +1.24 ± 0.16* | +0.27 ± 0.55 | +1.26 ± 2.63 | -0.05 ± 0.10 | -0.71 ± 1.27 |
/// | | green | +0.08 ± 0.35 | -0.07 ± 0.39 | +1.33 ± 0.33* | +0.02 ± 0.59 | +1.55 ± 2.34 | -0.01 ± 0.08 | -0.77 ± 0.89 |
/// | | blue | +0.06 ± 0.49 | +0.05 ± 0.50 | +0.96 ± 0.44* | -0.28 ± 0.78 | +6.13 ± 9.07 | -0.05 ± 0.08 | -1.00 ± 1.08 |
///
/// The path tracer is held to no bias, as on the worksheet ([`PATH_256`]: its small
/// offsets there are of the same size). SPPM's one resolved bias is its boundary
/// correction's overshoot into the corners, as on the other scenes. The reference's blue
/// caustic is 0.1065 against 0.3721 green and 0.4813 red: light through the glass keeps
/// `τ²` = (0.81, 0.36, 0.09) of its colour.
const COLOURED_PATH_256: [Measured; 3] = [
    Measured {
        bias: [0.0; 7],
        sd: [0.0008, 0.0095, 0.0038, 0.0017, 0.0081, 0.0012, 0.0121],
    },
    Measured {
        bias: [0.0; 7],
        sd: [0.0002, 0.0051, 0.0032, 0.0040, 0.0032, 0.0004, 0.0091],
    },
    Measured {
        bias: [0.0; 7],
        sd: [0.0006, 0.0095, 0.0036, 0.0057, 0.0159, 0.0014, 0.0297],
    },
];

/// SPPM at 16 passes on the coloured glass (the table above).
const COLOURED_SPPM_16: [Measured; 3] = [
    Measured {
        bias: [0.0, 0.0, 0.0124, 0.0, 0.0, 0.0, 0.0],
        sd: [0.0039, 0.0061, 0.0016, 0.0055, 0.0263, 0.0010, 0.0127],
    },
    Measured {
        bias: [0.0, 0.0, 0.0133, 0.0, 0.0, 0.0, 0.0],
        sd: [0.0035, 0.0039, 0.0033, 0.0059, 0.0234, 0.0008, 0.0089],
    },
    Measured {
        bias: [0.0, 0.0, 0.0096, 0.0, 0.0, 0.0, 0.0],
        sd: [0.0049, 0.0050, 0.0044, 0.0078, 0.0907, 0.0008, 0.0108],
    },
];

/// Coloured glass as Mitsuba renders it, channel by channel, by the path tracer and SPPM:
/// the caustic and the sphere take the glass's colour (`τ²` for light through it). The same
/// sphere clear fails in the caustic.
#[test]
fn coloured_glass_matches_mitsuba_channel_by_channel() {
    let s = coloured(1, |_| {});
    let core = ("caustic core", lab::regions::caustic_region(&s, 0.8));
    let masks: Vec<_> = lab::regions::regions(&s)
        .into_iter()
        .chain([core])
        .collect();
    let (a, b) = (
        reference_half(COLOURED_REF, "a"),
        reference_half(COLOURED_REF, "b"),
    );
    let regs: Vec<Vec<RegionRef>> = (0..3)
        .map(|c| region_refs_of(&channel(&a, c), &channel(&b, c), masks.clone()))
        .collect();
    let misfits_rgb = |img: &Image, tables: &[Measured; 3]| -> Vec<String> {
        (0..3)
            .flat_map(|c| {
                eprintln!("  {} channel:", CHANNELS[c]);
                misfits(&channel(img, c), &regs[c], &tables[c])
                    .into_iter()
                    .map(move |m| format!("{} {m}", CHANNELS[c]))
            })
            .collect()
    };
    let mut bad = Vec::new();
    for (method, count, tables) in [
        (Method::Path, 256, &COLOURED_PATH_256),
        (Method::Sppm, 16, &COLOURED_SPPM_16),
    ] {
        eprintln!("{method:?}, {count}:");
        bad.extend(misfits_rgb(&image_by(&s, method, count), tables));
    }
    assert!(bad.is_empty(), "{bad:#?}");
    let clear = coloured(1, |f| {
        f.materials.insert(
            "glass".into(),
            MaterialDesc::Dielectric {
                ior: 1.5,
                transmittance: [1.0; 3],
                absorption: [0.0; 3],
            },
        );
    });
    eprintln!("path, 256, clear glass:");
    let bad = misfits_rgb(&image_by(&clear, Method::Path, 256), &COLOURED_PATH_256);
    assert!(
        bad.iter().any(|m| m.contains(" caustic")),
        "the glass's colour is not resolved: {bad:#?}"
    );
}
// A textured receiver: the worksheet scene with a checker floor.

/// `scenes/cornell-textured/textured-floor.toml`: the worksheet scene whose floor is MTL
/// `map_Kd checker.png` (8-bit sRGB) at the OBJ's `vt`, Mitsuba's `bitmap` texture in its
/// references.
fn textured(seed: u64, edit: impl FnOnce(&mut SceneFile)) -> Scene {
    scene_at("cornell-textured/textured-floor.toml", RES, seed, edit)
}

/// The checker's three colours (its 8-bit sRGB texels): warm, cool and the red corner tile
/// (too few pixels for a region of its own: 8 at 128 x 128).
const CHECKER: [(&str, [u8; 3]); 3] = [
    ("warm tiles", [230, 200, 120]),
    ("cool tiles", [60, 110, 200]),
    ("red tiles", [200, 40, 40]),
];

/// The textured scene's regions: the worksheet's (the caustic now on the checker), the
/// caustic's core, and the floor's pixels whose every [`PIXEL_POINTS`] sees one tile colour
/// (told by the texture's value at the hit, nearest of [`CHECKER`]): a texture read at the
/// wrong place, flipped or not decoded from sRGB moves their means apart from Mitsuba's.
fn textured_regions(scene: &Scene) -> Vec<RegionRef> {
    let (w, h) = (RES as usize, RES as usize);
    let tile = |x: f32, y: f32| -> Option<usize> {
        let hit = scene.geometry.intersect(&scene.camera.ray(x, y))?;
        if scene.material_names[hit.material as usize] != "floor" {
            return None;
        }
        let a = scene.bsdf_at(&hit)?.diffuse_albedo()?;
        let d = |c: [u8; 3]| {
            (a - glam::Vec3::from(c.map(|v| scene::srgb_to_linear(v as f32 / 255.0)))).length()
        };
        (0..CHECKER.len()).min_by(|&i, &j| d(CHECKER[i].1).total_cmp(&d(CHECKER[j].1)))
    };
    let mut tiles: Vec<(&'static str, film::Mask)> = CHECKER
        .iter()
        .map(|(name, _)| {
            let mask = film::Mask {
                width: w,
                height: h,
                pixels: vec![false; w * h],
            };
            (*name, mask)
        })
        .collect();
    for y in 0..h {
        for x in 0..w {
            let seen: Vec<Option<usize>> = PIXEL_POINTS
                .iter()
                .map(|(u, v)| tile(x as f32 + u, y as f32 + v))
                .collect();
            if let Some(&Some(t)) = seen.first()
                && seen.iter().all(|s| *s == Some(t))
            {
                tiles[t].1.pixels[y * w + x] = true;
            }
        }
    }
    tiles.truncate(2);
    let core = ("caustic core", lab::regions::caustic_region(scene, 0.8));
    let masks = lab::regions::regions(scene)
        .into_iter()
        .chain([core])
        .chain(tiles);
    region_refs("cornell-textured", masks.collect())
}

/// The textured floor's tables, regions in [`textured_regions`]' order (image, caustic, edges
/// and corners, outer rim, glass sphere, open walls, caustic core, warm tiles, cool tiles),
/// `m / ref - 1` in percent, mean ± one run's standard deviation, seeds 1-6 (path: 1-12):
///
/// | run | image | caustic | edges, corners | outer rim | glass | open walls | core | warm | cool |
/// |---|---|---|---|---|---|---|---|---|---|
/// | path, 256 spp | +0.02 ± 0.06 | +0.43 ± 0.98 | +0.07 ± 0.64 | -0.16 ± 0.49 | +0.08 ± 0.53 | +0.00 ± 0.13 | +0.33 ± 1.89 | +0.11 ± 0.41 | +0.43 ± 0.40 |
/// | path+splat, 256 spp | -0.03 ± 0.05 | -1.07 ± 1.09 | -0.78 ± 0.35 | -0.61 ± 0.22 | +0.49 ± 0.85 | +0.01 ± 0.10 | -3.03 ± 2.63 | -0.46 ± 0.51 | -1.32 ± 0.90 |
/// | sppm, 16 passes | +0.07 ± 0.47 | -0.03 ± 1.15 | +1.27 ± 0.14 | +0.35 ± 0.54 | +1.20 ± 3.49 | -0.04 ± 0.11 | -0.92 ± 2.53 | -0.30 ± 0.19 | -0.12 ± 0.23 |
///
/// Known biases, each more than 3 standard errors from 0: path+splat's fixed indirect discs at
/// the edges and the rim (as on the worksheet), SPPM's boundary correction in the corners
/// (+1.3%), and three small offsets on the tiles not explained yet: the path tracer's cool
/// tiles +0.43% ± 0.12% (12 seeds; its warm tiles and whole image agree), path+splat's cool
/// tiles -1.3% ± 0.37%, SPPM's warm tiles -0.30% ± 0.08%. A texture read wrongly moves the
/// tiles by far more: drawn at its mean colour, the floor fails (below).
const TEXTURED_PATH_256: Measured<9> = Measured {
    bias: [0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0043],
    sd: [
        0.0006, 0.0098, 0.0064, 0.0049, 0.0053, 0.0013, 0.0189, 0.0041, 0.0040,
    ],
};

/// `path+splat` at 256 spp on the textured floor (the table above).
const TEXTURED_PATH_SPLAT_256: Measured<9> = Measured {
    bias: [0.0, 0.0, -0.0078, -0.0061, 0.0, 0.0, 0.0, 0.0, -0.0132],
    sd: [
        0.0005, 0.0109, 0.0035, 0.0022, 0.0085, 0.0010, 0.0263, 0.0051, 0.0090,
    ],
};

/// SPPM at 16 passes on the textured floor (the table above).
const TEXTURED_SPPM_16: Measured<9> = Measured {
    bias: [0.0, 0.0, 0.0127, 0.0, 0.0, 0.0, 0.0, -0.0030, 0.0],
    sd: [
        0.0047, 0.0115, 0.0014, 0.0054, 0.0349, 0.0011, 0.0253, 0.0019, 0.0023,
    ],
};

/// A textured receiver under the glass sphere (MTL `map_Kd` at the OBJ's `vt`): the path
/// tracer, the path tracer with splatted caustics and SPPM each match Mitsuba's `bitmap`
/// texture in every region, the caustic on the checker and each tile colour included. The
/// floor drawn at the texture's mean colour instead fails on the tiles.
#[test]
fn a_textured_receiver_matches_mitsuba() {
    let s = textured(1, |_| {});
    let regs = textured_regions(&s);
    let runs = [
        (Method::Path, 256, &TEXTURED_PATH_256),
        (Method::PathSplat, 256, &TEXTURED_PATH_SPLAT_256),
        (Method::Sppm, 16, &TEXTURED_SPPM_16),
    ];
    let bad = misfits_of_runs(&s, &regs, &runs);
    assert!(bad.is_empty(), "{bad:#?}");
    // The mean of the decoded checker: 32 x 32 texels of which 16 red, the rest half warm,
    // half cool.
    let lin = |c: [u8; 3]| glam::Vec3::from(c.map(|v| scene::srgb_to_linear(v as f32 / 255.0)));
    let mean =
        (lin(CHECKER[0].1) * 504.0 + lin(CHECKER[1].1) * 504.0 + lin(CHECKER[2].1) * 16.0) / 1024.0;
    let flat = textured(1, |f| {
        f.materials.insert(
            "floor".into(),
            MaterialDesc::Lambertian {
                albedo: mean.to_array(),
                emission: [0.0; 3],
                texture: None,
            },
        );
    });
    eprintln!("path, 256, the floor at the texture's mean colour:");
    let bad = misfits(
        &image_by(&flat, Method::Path, 256),
        &regs,
        &TEXTURED_PATH_256,
    );
    assert!(
        bad.iter().any(|m| m.starts_with("warm tiles:"))
            && bad.iter().any(|m| m.starts_with("cool tiles:")),
        "the checker is not resolved: {bad:#?}"
    );
}

// Scenes lit by a point light, a spot light and an environment map alone.

/// Where the light of a light-scene region comes from: a point or spot light's position, or
/// the direction towards the environment map's sun.
#[derive(Clone, Copy)]
enum Toward {
    Point(glam::Vec3),
    Direction(glam::Vec3),
}

/// What the camera sees through `(x, y)` in a light scene: `background`; a sphere by its
/// material's name; or a mesh surface: `core` (in the glass sphere's shadow within 0.4 of its
/// radius of the axis from the light through the sphere's centre, where its caustic
/// focuses), `shadow` (elsewhere in that shadow, the rest of the caustic), `ceiling` (a
/// surface facing down at the camera) or `lit`.
fn light_scene_label(scene: &Scene, toward: Toward, x: f32, y: f32) -> &'static str {
    let glass = scene
        .geometry
        .spheres()
        .iter()
        .find(|s| scene.material_names[s.material as usize] == "glass")
        .expect("a glass sphere");
    let names = |m: u32| -> &'static str {
        match scene.material_names[m as usize].as_str() {
            "glass" => "glass",
            "silver" => "silver",
            "clay" => "clay",
            _ => "other sphere",
        }
    };
    let ray = scene.camera.ray(x, y);
    let Some(hit) = scene.geometry.intersect(&ray) else {
        return "background";
    };
    if matches!(hit.prim, geom::Prim::Sphere(_)) {
        return names(hit.material);
    }
    let p = hit.point.p;
    let (to_light, axis_from) = match toward {
        Toward::Point(l) => ((l - p).normalize(), l),
        Toward::Direction(d) => (d, glass.center + d * 100.0),
    };
    let shadowed = scene
        .geometry
        .intersect(&hit.point.spawn_ray(to_light))
        .is_some_and(|h| matches!(h.prim, geom::Prim::Sphere(_)) && names(h.material) == "glass");
    if shadowed {
        // The axis meets the receiver where a ray from just past the sphere, away from the
        // light, lands.
        let axis = (glass.center - axis_from).normalize();
        let from = glass.center + axis * (glass.radius * 1.001);
        let c = scene
            .geometry
            .intersect(&geom::Ray::new(from, axis))
            .map(|h| h.point.p);
        return match c {
            Some(c) if (p - c).length() < 0.4 * glass.radius => "core",
            _ => "shadow",
        };
    }
    let ng = hit.point.n;
    let facing = if ng.dot(-ray.d) >= 0.0 { ng } else { -ng };
    if facing.y < -0.9 { "ceiling" } else { "lit" }
}

/// Regions of a light scene: pixels whose every [`PIXEL_POINTS`] carries a label of `group`
/// (see [`light_scene_label`]), for each `(name, group)`.
fn light_scene_regions(
    scene: &Scene,
    reference: &str,
    toward: Toward,
    groups: &[(&'static str, &[&str])],
) -> Vec<RegionRef> {
    let (w, h) = (RES as usize, RES as usize);
    let labels: Vec<[&str; 5]> = (0..w * h)
        .map(|i| {
            let (x, y) = ((i % w) as f32, (i / w) as f32);
            PIXEL_POINTS.map(|(u, v)| light_scene_label(scene, toward, x + u, y + v))
        })
        .collect();
    let masks = groups
        .iter()
        .map(|(name, group)| {
            let pixels = labels
                .iter()
                .map(|l| group.is_empty() || l.iter().all(|s| group.contains(s)))
                .collect();
            (
                *name,
                film::Mask {
                    width: w,
                    height: h,
                    pixels,
                },
            )
        })
        .collect();
    region_refs(reference, masks)
}

/// Regions of the light-traced references (Mitsuba's `ptracer` draws no specular surface
/// the camera sees): the diffuse surfaces seen directly, those lit directly, the glass
/// sphere's shadow with its caustic, the caustic's core, and (in the box) the ceiling.
const DIRECT_GROUPS: [(&str, &[&str]); 5] = [
    ("diffuse seen", &["lit", "shadow", "core", "ceiling"]),
    ("lit", &["lit"]),
    ("glass shadow", &["shadow", "core"]),
    ("caustic core", &["core"]),
    ("ceiling", &["ceiling"]),
];

/// `scenes/point-caustic/glass-sphere.toml`: a glass ball on a floor under a point light.
fn point_caustic(seed: u64, edit: impl FnOnce(&mut SceneFile)) -> Scene {
    scene_at("point-caustic/glass-sphere.toml", RES, seed, edit)
}

fn point_caustic_regions(scene: &Scene) -> Vec<RegionRef> {
    let l = glam::Vec3::new(-4.0, 3.5, -1.0);
    light_scene_regions(
        scene,
        "point-caustic",
        Toward::Point(l),
        &DIRECT_GROUPS[..4],
    )
}

/// `scenes/cornell-spot/spot.toml`: the worksheet box and spheres under a spot light.
fn cornell_spot(seed: u64, edit: impl FnOnce(&mut SceneFile)) -> Scene {
    scene_at("cornell-spot/spot.toml", RES, seed, edit)
}

fn cornell_spot_regions(scene: &Scene) -> Vec<RegionRef> {
    let l = glam::Vec3::new(-6.95, 13.5, -6.99);
    light_scene_regions(scene, "cornell-spot", Toward::Point(l), &DIRECT_GROUPS)
}

/// `scenes/environment/env-only.toml`: a floor, a glass and a clay sphere under a sky map.
fn environment(seed: u64, edit: impl FnOnce(&mut SceneFile)) -> Scene {
    scene_at("environment/env-only.toml", RES, seed, edit)
}

/// The sky map's sun: 45 degrees up at the map's `u = 0.25` (local `(cos 45°, sin 45°, 0)`
/// in Mitsuba's `envmap` frame), turned by the scene's `rotate = [-10, 60, 0]`.
fn sun_direction() -> glam::Vec3 {
    let local = glam::Vec3::new(1.0, 1.0, 0.0).normalize();
    glam::Mat3::from_rotation_y(60f32.to_radians())
        * glam::Mat3::from_rotation_x((-10f32).to_radians())
        * local
}

fn environment_regions(scene: &Scene) -> Vec<RegionRef> {
    let groups: [(&str, &[&str]); 7] = [
        ("image", &[]),
        ("background", &["background"]),
        ("floor", &["lit"]),
        ("glass shadow", &["shadow", "core"]),
        ("caustic core", &["core"]),
        ("glass", &["glass"]),
        ("clay", &["clay"]),
    ];
    light_scene_regions(
        scene,
        "environment",
        Toward::Direction(sun_direction()),
        &groups,
    )
}

/// The light scenes' tables, `m / ref - 1` in percent, mean ± one run's standard deviation
/// over seeds 1-6, regions in each `*_regions` function's order.
///
/// Point light (diffuse seen, lit, glass shadow, caustic core):
///
/// | run | diffuse seen | lit | glass shadow | core |
/// |---|---|---|---|---|
/// | path, 256 spp | -9.12 ± 0.01 | -0.73 ± 0.01 | -84.28 ± 0.04 | -98.90 ± 0.01 |
/// | path+splat, 256 spp | -0.19 ± 0.58 | +0.04 ± 0.06 | -2.23 ± 5.47 | -3.79 ± 7.38 |
/// | sppm, 16 passes | +0.16 ± 0.29 | +0.04 ± 0.07 | +1.19 ± 2.80 | +1.54 ± 4.37 |
///
/// Spot light in the box (diffuse seen, lit, glass shadow, caustic core, ceiling):
///
/// | run | diffuse seen | lit | glass shadow | core | ceiling |
/// |---|---|---|---|---|---|
/// | path, 256 spp | -12.33 ± 0.04 | -8.32 ± 0.05 | -71.17 ± 0.12 | -96.84 ± 0.05 | -22.77 ± 0.08 |
/// | path+splat, 256 spp | -0.16 ± 0.08 | -0.10 ± 0.07 | -0.78 ± 3.23 | -17.08 ± 3.67 | -0.21 ± 0.26 |
/// | sppm, 16 passes | +0.05 ± 0.07 | +0.04 ± 0.07 | +0.13 ± 0.60 | -6.83 ± 1.60 | -0.10 ± 0.14 |
///
/// Environment (image, background, floor, glass shadow, caustic core, glass, clay):
///
/// | run | image | background | floor | glass shadow | core | glass | clay |
/// |---|---|---|---|---|---|---|---|
/// | path, 256 spp | -0.00 ± 0.06 | +0.00 ± 0.00 | -0.01 ± 0.02 | +0.05 ± 0.50 | +0.33 ± 0.92 | +0.04 ± 0.29 | -0.07 ± 0.16 |
/// | path+splat, 256 spp | +0.03 ± 0.18 | +0.00 ± 0.00 | +0.05 ± 0.21 | +0.92 ± 1.35 | +1.07 ± 3.07 | -0.17 ± 0.23 | -0.44 ± 0.79 |
/// | sppm, 16 passes | +0.00 ± 0.19 | +0.00 ± 0.00 | -0.01 ± 0.20 | +0.04 ± 0.43 | -0.14 ± 0.83 | +0.21 ± 0.67 | +0.02 ± 0.58 |
///
/// Known biases, each more than 3 standard errors from 0: the spot's caustic core (12 pixels
/// of a sharp focus) is blurred out of its pixels by path+splat's discs (-17%) and SPPM's
/// radii after 16 passes (-7%), and path+splat's fixed indirect discs take 0.1% off the box
/// (as on the worksheet). The path tracer's rows are the negative control: it cannot find
/// light from a point or spot light through the spheres (its caustic layers are zero), so it
/// misses the glass's shadow and, through the light those caustics and the silver sphere's
/// reflections pass on, everything else.
const POINT_PATH_SPLAT_256: Measured<4> = Measured {
    bias: [0.0; 4],
    sd: [0.0058, 0.0006, 0.0547, 0.0738],
};

const POINT_SPPM_16: Measured<4> = Measured {
    bias: [0.0; 4],
    sd: [0.0029, 0.0007, 0.0280, 0.0437],
};

/// The path tracer's control table for the point light: no bias allowed, its sd.
const POINT_PATH_256: Measured<4> = Measured {
    bias: [0.0; 4],
    sd: [0.0001, 0.0001, 0.0004, 0.0001],
};

const SPOT_PATH_SPLAT_256: Measured<5> = Measured {
    bias: [-0.0016, -0.0010, 0.0, -0.1708, 0.0],
    sd: [0.0008, 0.0007, 0.0323, 0.0367, 0.0026],
};

const SPOT_SPPM_16: Measured<5> = Measured {
    bias: [0.0, 0.0, 0.0, -0.0683, 0.0],
    sd: [0.0007, 0.0007, 0.0060, 0.0160, 0.0014],
};

const ENV_PATH_256: Measured<7> = Measured {
    bias: [0.0; 7],
    sd: [0.0006, 0.0001, 0.0002, 0.0050, 0.0092, 0.0029, 0.0016],
};

const ENV_PATH_SPLAT_256: Measured<7> = Measured {
    bias: [0.0; 7],
    sd: [0.0018, 0.0001, 0.0021, 0.0135, 0.0307, 0.0023, 0.0079],
};

const ENV_SPPM_16: Measured<7> = Measured {
    bias: [0.0; 7],
    sd: [0.0019, 0.0001, 0.0020, 0.0043, 0.0083, 0.0067, 0.0058],
};

/// A glass ball under a point light against Mitsuba's light tracer (`ptracer`): path+splat
/// and SPPM match in every region, the caustic in the ball's shadow included. The path
/// tracer finds no caustic at all (its caustic layers are exactly zero: no ray hits a point
/// light and glass blocks every shadow ray), so it fails the shadow by -84%.
#[test]
fn a_point_light_caustic_matches_mitsubas_light_tracer() {
    let s = point_caustic(1, |_| {});
    let regs = point_caustic_regions(&s);
    let runs = [
        (Method::PathSplat, 256, &POINT_PATH_SPLAT_256),
        (Method::Sppm, 16, &POINT_SPPM_16),
    ];
    let bad = misfits_of_runs(&s, &regs, &runs);
    assert!(bad.is_empty(), "{bad:#?}");
    let o = Overrides {
        method: Some(Method::Path),
        spp: Some(64),
        ..Overrides::default()
    };
    let path = render_uncached(&s, &o, None);
    let caustic = sum_layers(&path, |n| n.starts_with("caustic"));
    assert!(
        caustic.data.iter().all(|p| *p == [0.0; 3]),
        "the path tracer found a point light's caustic"
    );
    eprintln!("path, 64:");
    let bad = misfits(&sum_layers(&path, |_| true), &regs, &POINT_PATH_256);
    assert!(
        bad.iter().any(|m| m.starts_with("glass shadow:")),
        "the caustic is not resolved: {bad:#?}"
    );
}

/// The worksheet box and spheres under a spot light instead of the area light, against
/// Mitsuba's light tracer: path+splat and SPPM match everywhere a diffuse surface is seen
/// directly, the glass ball's caustic and the ceiling it lights from below included.
#[test]
fn a_spot_lit_box_matches_mitsubas_light_tracer() {
    let s = cornell_spot(1, |_| {});
    let regs = cornell_spot_regions(&s);
    let runs = [
        (Method::PathSplat, 256, &SPOT_PATH_SPLAT_256),
        (Method::Sppm, 16, &SPOT_SPPM_16),
    ];
    let bad = misfits_of_runs(&s, &regs, &runs);
    assert!(bad.is_empty(), "{bad:#?}");
}

/// A floor, a glass and a clay sphere lit by a rotated sky map alone against Mitsuba's path
/// tracer: the path tracer, path+splat and SPPM match in every region, the background seen
/// directly, the sun's caustic and the glass included. The map turned the other way about y
/// (the sun moved) fails on the floor (+8.7%) and the caustic's core (-71%).
#[test]
fn an_environment_lit_scene_matches_mitsuba() {
    let s = environment(1, |_| {});
    let regs = environment_regions(&s);
    let runs = [
        (Method::Path, 256, &ENV_PATH_256),
        (Method::PathSplat, 256, &ENV_PATH_SPLAT_256),
        (Method::Sppm, 16, &ENV_SPPM_16),
    ];
    let bad = misfits_of_runs(&s, &regs, &runs);
    assert!(bad.is_empty(), "{bad:#?}");
    let turned = environment(1, |f| {
        for l in &mut f.lights {
            if let scene::LightDesc::Environment { rotate, .. } = l {
                rotate[1] = -rotate[1];
            }
        }
    });
    eprintln!("path, 64, the map turned by -60 degrees about y:");
    let bad = misfits(&image_by(&turned, Method::Path, 64), &regs, &ENV_PATH_256);
    assert!(
        bad.iter().any(|m| m.starts_with("floor:"))
            && bad.iter().any(|m| m.starts_with("caustic core:")),
        "the map's orientation is not resolved: {bad:#?}"
    );
}

// ---------------------------------------------------------------------------------------------
// Morgan McGuire's CornellBox-Original (`scenes/mcguire/`), its OBJ and MTL as published.

/// `scenes/mcguire/original.toml` at 128 x 128.
fn mcguire_original(seed: u64, edit: impl FnOnce(&mut SceneFile)) -> Scene {
    scene_at("mcguire/original.toml", RES, seed, edit)
}

/// The McGuire box's regions: the whole image, then the pixels all of whose
/// [`PIXEL_POINTS`] see one MTL material. The light quad seen directly (80 pixels at 128 x
/// 128, its `Ke` plus 0.8% reflected) is left out: both methods read it within 0.01% of
/// Mitsuba's, with too little noise over the seeds for a table to bound.
const MCGUIRE_GROUPS: [(&str, &str); 8] = [
    ("image", ""),
    ("floor", "floor"),
    ("ceiling", "ceiling"),
    ("back wall", "backWall"),
    ("left wall", "leftWall"),
    ("right wall", "rightWall"),
    ("short box", "shortBox"),
    ("tall box", "tallBox"),
];

fn mcguire_regions(scene: &Scene) -> Vec<RegionRef> {
    let (w, h) = (RES as usize, RES as usize);
    let material = |x: f32, y: f32| -> Option<&str> {
        let hit = scene.geometry.intersect(&scene.camera.ray(x, y))?;
        Some(scene.material_names[hit.material as usize].as_str())
    };
    let labels: Vec<[Option<&str>; 5]> = (0..w * h)
        .map(|i| {
            let (x, y) = ((i % w) as f32, (i / w) as f32);
            PIXEL_POINTS.map(|(u, v)| material(x + u, y + v))
        })
        .collect();
    let masks = MCGUIRE_GROUPS
        .iter()
        .map(|&(name, mtl)| {
            let pixels = labels
                .iter()
                .map(|l| mtl.is_empty() || l.iter().all(|m| *m == Some(mtl)))
                .collect();
            (
                name,
                film::Mask {
                    width: w,
                    height: h,
                    pixels,
                },
            )
        })
        .collect();
    region_refs("mcguire-original", masks)
}

/// The McGuire box's tables, `m / ref - 1` in percent, mean ± one run's standard deviation
/// over seeds 1-6, regions in [`MCGUIRE_GROUPS`]' order (reference standard errors 0.010%,
/// 0.012%, 0.026%, 0.009%, 0.011%, 0.009%, 0.030%, 0.022%):
///
/// | run | image | floor | ceiling | back wall | left wall | right wall | short box | tall box |
/// |---|---|---|---|---|---|---|---|---|
/// | path, 256 spp | -0.01 ± 0.02 | +0.02 ± 0.07 | -0.01 ± 0.08 | -0.03 ± 0.04 | -0.03 ± 0.04 | +0.07 ± 0.05 | +0.14 ± 0.14 | -0.02 ± 0.17 |
/// | path, 64 spp | -0.01 ± 0.05 | -0.05 ± 0.16 | +0.03 ± 0.22 | +0.02 ± 0.08 | +0.04 ± 0.16 | +0.21 ± 0.17 | +0.01 ± 0.28 | +0.07 ± 0.29 |
/// | sppm, 16 passes | +0.02 ± 0.31 | +0.03 ± 0.15 | -0.13 ± 0.14 | +0.00 ± 0.16 | +0.04 ± 0.05 | +0.04 ± 0.13 | +0.23 ± 0.13 | +0.24 ± 0.32 |
///
/// Two offsets lie more than 3 standard errors of their mean from zero: the path tracer's
/// right wall, +0.07% (3.4), and SPPM's short box, +0.23% (4.3; SPPM's radii reach from the
/// small box's faces onto the brighter floor and walls beside them, as at the worksheet's
/// edges and corners). SPPM's is allowed as its known bias; the path tracer is held to no
/// bias, and its offset passes only while it stays within the noise. SPPM's whole-image
/// noise (0.31%, more than any surface's) is the light's outline, which one eye sample per
/// pixel and pass hits or misses.
const MCGUIRE_PATH_256: Measured<8> = Measured {
    bias: [0.0; 8],
    sd: [
        0.0002, 0.0007, 0.0008, 0.0004, 0.0004, 0.0005, 0.0014, 0.0017,
    ],
};

/// The path tracer at 64 spp on the McGuire box (the table above; the negative control).
const MCGUIRE_PATH_64: Measured<8> = Measured {
    bias: [0.0; 8],
    sd: [
        0.0005, 0.0016, 0.0022, 0.0008, 0.0016, 0.0017, 0.0028, 0.0029,
    ],
};

/// SPPM at 16 passes on the McGuire box (the table above).
const MCGUIRE_SPPM_16: Measured<8> = Measured {
    bias: [0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0023, 0.0],
    sd: [
        0.0031, 0.0015, 0.0014, 0.0016, 0.0005, 0.0013, 0.0013, 0.0032,
    ],
};

/// McGuire's CornellBox-Original, its OBJ and MTL as published (emission from `Ke`), against
/// Mitsuba's path tracer: the path tracer and SPPM match in the whole image and on every
/// surface seen. The negative control: the light's `Ke` 2% brighter (a scene-file material
/// over the MTL's) fails the path tracer's comparison at 64 spp.
#[test]
fn mcguire_original_matches_mitsuba() {
    let s = mcguire_original(1, |_| {});
    let regs = mcguire_regions(&s);
    let runs = [
        (Method::Path, 256, &MCGUIRE_PATH_256),
        (Method::Sppm, 16, &MCGUIRE_SPPM_16),
    ];
    let bad = misfits_of_runs(&s, &regs, &runs);
    assert!(bad.is_empty(), "{bad:#?}");
    let brighter = mcguire_original(2, |f| {
        let light = MaterialDesc::Lambertian {
            albedo: [0.78; 3],
            emission: [17.0 * 1.02, 12.0 * 1.02, 4.0 * 1.02],
            texture: None,
        };
        f.materials.insert("light".into(), light);
    });
    eprintln!("path, 64, the light's Ke +2%:");
    let bad = misfits(
        &image_by(&brighter, Method::Path, 64),
        &regs,
        &MCGUIRE_PATH_64,
    );
    assert!(
        bad.iter().any(|m| m.starts_with("image:")),
        "a 2% brighter light passed: {bad:#?}"
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
