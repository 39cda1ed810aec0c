//! Stochastic progressive photon mapping end to end, through
//! `render::methods::render`: on scenes with a closed-form answer the estimate converges to
//! it at the rate its radius schedule predicts, its snapshots are the images a shorter run
//! makes, and its images are the same bit for bit on 1 and 2 threads.

use crate::kit::{bits, layer_in, pixel, rect, render_uncached, scene_at};
use glam::DVec3;
use math::analytic::polygon_irradiance;
use render::rendered::CountKind;
use render::{Overrides, Rendered};
use scene::{Method, Scene};

/// `rel` from `scenes/` with seed `seed` and `[estimate.sppm]` (and anything else) from
/// `extra`, a TOML table body applied over the file's.
fn scene_with(rel: &str, seed: u64, res: u32, sppm: &str) -> Scene {
    let table: toml::Table = sppm.parse().unwrap_or_else(|e| panic!("{e}"));
    scene_at(rel, res, seed, |f| {
        f.estimate.insert("sppm".into(), toml::Value::Table(table));
    })
}

fn render(scene: &Scene, passes: u32, threads: Option<usize>) -> Rendered {
    render_method(scene, Method::Sppm, passes, threads)
}

/// `method` with `passes` passes (for `path+splat`, as many path-traced samples per pixel as
/// splatting passes).
fn render_method(scene: &Scene, method: Method, passes: u32, threads: Option<usize>) -> Rendered {
    let o = Overrides {
        method: Some(method),
        passes: Some(passes),
        spp: (method == Method::PathSplat).then_some(passes),
        splat_photons: Some(20_000),
        ..Overrides::default()
    };
    // These methods read no photon cache.
    render_uncached(scene, &o, threads)
}

/// The layers of a snapshot (or of the run, `passes = None`).
fn layers_at(r: &Rendered, passes: Option<u32>) -> &[render::Layer] {
    match passes {
        None => &r.layers,
        Some(p) => {
            &r.snapshots
                .iter()
                .find(|s| s.passes == p)
                .unwrap_or_else(|| panic!("no snapshot at {p} passes"))
                .layers
        }
    }
}

/// The image of a snapshot (or of the run): the sum of its layers.
fn image(r: &Rendered, passes: Option<u32>) -> film::Image {
    let parts: Vec<(&film::Image, f32)> = layers_at(r, passes)
        .iter()
        .map(|l| (&l.image, 1.0))
        .collect();
    film::composite(&parts).unwrap_or_else(|e| panic!("{e}"))
}

/// Grey scenes: the mean of the pixel's channels.
fn grey(img: &film::Image, p: (usize, usize)) -> f64 {
    let v = pixel(img, p);
    (v.x + v.y + v.z) / 3.0
}

/// One layer of a snapshot (or of the run).
fn layer<'a>(r: &'a Rendered, passes: Option<u32>, name: &str) -> &'a film::Image {
    layer_in(layers_at(r, passes), name)
}

/// What [`convergence`] measures.
struct Convergence {
    /// Root-mean-square relative error of the photon layer over pixels and runs, after
    /// `FROM` and after `TO` passes.
    rms_from: f64,
    rms_to: f64,
    /// Standard error of `rms_from / rms_to`: the spread of the runs' own ratios over
    /// sqrt(runs) (a run's pixels share photons, so pixels are not independent samples).
    ratio_se: f64,
    /// The final image's (all layers) mean relative error and its standard error, from the
    /// spread of the runs' pixel means.
    bias: f64,
    se: f64,
}

const FROM: u32 = 4;
const TO: u32 = 64;

/// `seeds` independent runs of [`TO`] passes: the photon layer's error against
/// `exact_photons` per pixel, and the whole image's against `exact`.
fn convergence(
    make: impl Fn(u64) -> Scene,
    seeds: u64,
    pixels: &[(usize, usize)],
    exact_photons: &[f64],
    exact: &[f64],
) -> Convergence {
    let (mut sq_from, mut sq_to, mut n) = (0.0, 0.0, 0.0);
    let mut run_means = Vec::new();
    let mut run_ratios = Vec::new();
    for seed in 1..=seeds {
        let (sq_from_0, sq_to_0) = (sq_from, sq_to);
        let r = render(&make(seed), TO, None);
        let (early, late) = (layer(&r, Some(FROM), "photons"), layer(&r, None, "photons"));
        let all = image(&r, None);
        let mut run_mean = 0.0;
        for ((&p, &ep), &e) in pixels.iter().zip(exact_photons).zip(exact) {
            sq_from += (grey(early, p) / ep - 1.0).powi(2);
            sq_to += (grey(late, p) / ep - 1.0).powi(2);
            n += 1.0;
            run_mean += (grey(&all, p) / e - 1.0) / pixels.len() as f64;
        }
        run_means.push(run_mean);
        run_ratios.push(((sq_from - sq_from_0) / (sq_to - sq_to_0)).sqrt());
    }
    let k = run_means.len() as f64;
    let bias = run_means.iter().sum::<f64>() / k;
    let var = run_means.iter().map(|m| (m - bias).powi(2)).sum::<f64>() / (k - 1.0);
    let ratio_mean = run_ratios.iter().sum::<f64>() / k;
    let ratio_var = run_ratios
        .iter()
        .map(|r| (r - ratio_mean).powi(2))
        .sum::<f64>()
        / (k - 1.0);
    Convergence {
        rms_from: (sq_from / n).sqrt(),
        rms_to: (sq_to / n).sqrt(),
        ratio_se: (ratio_var / k).sqrt(),
        bias,
        se: (var / k).sqrt(),
    }
}

/// The error ratio SPPM's radius schedule predicts from [`FROM`] to [`TO`] passes where the
/// error is photon noise (no kernel bias), for pixels whose start disc holds `m0` photons
/// of one pass on average. The estimate after J passes is the mean over passes of each
/// pass's density estimate in its own disc (τ telescopes: `τ_J / (J π R_J²) =
/// (1/J) Σ_j Φ_j / (π R_j²)`), so its relative variance is `(1/J²) Σ_j 1/M_j` with Poisson
/// counts `M_j`; the expected schedule is `M_j = m0 R_j²/R_0²`, `N' = N + α M`,
/// `R'² = R² (N + α M)/(N + M)`. Asymptotically this is Knaus and Zwicker's (2011) J^(-α/2).
fn predicted_ratio(m0: &[f64], alpha: f64) -> f64 {
    let variance = |passes: u32| -> f64 {
        m0.iter()
            .map(|&m0| {
                let (mut n, mut r2, mut inv) = (0.0, 1.0, 0.0);
                for _ in 0..passes {
                    let m = m0 * r2;
                    inv += 1.0 / m;
                    let n_new = n + alpha * m;
                    r2 *= n_new / (n + m);
                    n = n_new;
                }
                inv / (passes as f64).powi(2)
            })
            .sum::<f64>()
            / m0.len() as f64
    };
    (variance(FROM) / variance(TO)).sqrt()
}

/// Standard errors a measured error ratio may lie from its prediction.
const RATIO_Z: f64 = 4.0;

/// Whether the error ratio lies within [`RATIO_Z`] standard errors of `predicted`.
fn ratio_fits(name: &str, c: &Convergence, predicted: f64) -> bool {
    let ratio = c.rms_from / c.rms_to;
    let z = (ratio - predicted) / c.ratio_se;
    eprintln!(
        "{name}: photon layer rms relative error {:.4} after {FROM} passes, {:.4} after {TO} \
         (ratio {ratio:.3} ± {:.3}, predicted {predicted:.3}, z {z:+.2}); image mean relative \
         error {:+.5} ± {:.5}",
        c.rms_from, c.rms_to, c.ratio_se, c.bias, c.se
    );
    z.abs() < RATIO_Z
}

fn check(name: &str, c: &Convergence, predicted: f64) {
    assert!(
        ratio_fits(name, c, predicted),
        "{name}: error ratio {} ± {} against the predicted {predicted}",
        c.rms_from / c.rms_to,
        c.ratio_se
    );
    assert!(c.bias.abs() < 4.0 * c.se, "{name}: {} ± {}", c.bias, c.se);
}

const RADIUS: f64 = 0.1;
const PHOTONS: f64 = 20_000.0;

#[test]
fn sppm_under_a_square_light_converges_to_the_polygon_irradiance() {
    // The plane (albedo 1/2) under the square light (Le = 10), direct light by photons (no
    // next-event estimation: every photon here is direct light), 64 x 64 pixels of 0.11
    // scene units seen from 6 units above, beside the light. Each pixel's exact value is
    // rho/pi times the irradiance averaged over the part of the plane the pixel sees (visible
    // points are jittered over it): 16 x 16 camera rays per pixel, Lambert's closed form at
    // each hit.
    const SPPM: &str = "photons = 20000\nradius = 0.1\ndirect = false\n";
    let make = |seed| scene_with("plane-light/plane-light.toml", seed, 64, SPPM);
    let scene = make(1);
    let light = [
        [-0.25, 2.0, -0.25],
        [0.25, 2.0, -0.25],
        [0.25, 2.0, 0.25],
        [-0.25, 2.0, 0.25],
    ]
    .map(DVec3::from_array);
    let pixels = rect([16, 28, 24, 36]);
    let exact: Vec<f64> = pixels
        .iter()
        .map(|&(x, y)| {
            let mut sum = 0.0;
            for i in 0..16 {
                for j in 0..16 {
                    let ray = scene.camera.ray(
                        x as f32 + (i as f32 + 0.5) / 16.0,
                        y as f32 + (j as f32 + 0.5) / 16.0,
                    );
                    let hit = scene.geometry.intersect(&ray).expect("the plane");
                    assert!(
                        hit.point.p.y.abs() < 1e-4,
                        "pixel ({x}, {y}) sees the light"
                    );
                    sum += polygon_irradiance(hit.point.p.as_dvec3(), DVec3::Y, &light, 10.0);
                }
            }
            0.5 / std::f64::consts::PI * sum / 256.0
        })
        .collect();
    // Photons in a start disc: irradiance over one photon's flux (the light's power
    // pi Le A over the paths), times the disc's area.
    let flux = std::f64::consts::PI * 10.0 * 0.25 / PHOTONS;
    let m0: Vec<f64> = exact
        .iter()
        .map(|&l| l * std::f64::consts::PI / 0.5 / flux * std::f64::consts::PI * RADIUS * RADIUS)
        .collect();
    let c = convergence(make, 16, &pixels, &exact, &exact);
    check("plane", &c, predicted_ratio(&m0, 2.0 / 3.0));
}

/// SPPM in the furnace with `[estimate.sppm]` body `sppm`, 16 runs: walls emitting Le = 1
/// with albedo 1/2, radiance 2 everywhere. Emission seen directly and next-event estimation
/// give 1.5, photons after a bounce the other 0.5: a uniform density (indirect irradiance pi
/// over a photon's unchanged flux pi Le A / paths: paths / A photons per unit area), so no
/// kernel bias at all, only noise. Interior pixels. With the photons expected in a start
/// disc.
fn furnace_convergence(sppm: &str) -> (Convergence, Vec<f64>) {
    let make = |seed| scene_with("furnace/furnace.toml", seed, 16, sppm);
    let scene = make(1);
    let mesh = scene.geometry.mesh();
    let area: f64 = (0..mesh.len()).map(|t| mesh.area(t) as f64).sum();
    let pixels = rect([5, 5, 11, 11]);
    let m0 = vec![PHOTONS / area * std::f64::consts::PI * RADIUS * RADIUS; pixels.len()];
    let c = convergence(
        make,
        16,
        &pixels,
        &vec![0.5; pixels.len()],
        &vec![2.0; pixels.len()],
    );
    (c, m0)
}

#[test]
fn sppm_in_the_furnace_converges_to_le_over_one_minus_rho() {
    let (c, m0) = furnace_convergence("photons = 20000\nradius = 0.1\n");
    check("furnace", &c, predicted_ratio(&m0, 2.0 / 3.0));
}

/// The negative control of the rate: with `alpha` set to 0.5 or 0.8 in the scene file the
/// error falls at that alpha's rate (from 4 to 64 passes by 1.94x and 3.03x here, against
/// 2.50x at 2/3), and the check against 2/3's prediction fails. Measured: 1.916 ± 0.064 at
/// 0.5 (z = -9.1 against 2/3), 3.064 ± 0.110 at 0.8 (z = +5.1), 2.487 ± 0.088 at 2/3; the
/// square light's plane 2.386 ± 0.083 at 2/3 (z = -1.4).
#[test]
fn sppm_error_falls_at_the_rate_of_the_alpha_the_scene_file_sets() {
    for alpha in [0.5, 0.8] {
        let (c, m0) =
            furnace_convergence(&format!("photons = 20000\nradius = 0.1\nalpha = {alpha}\n"));
        let name = format!("furnace, alpha = {alpha}");
        check(&name, &c, predicted_ratio(&m0, alpha));
        assert!(
            !ratio_fits(
                &format!("{name} against 2/3"),
                &c,
                predicted_ratio(&m0, 2.0 / 3.0)
            ),
            "{name}: the rate test cannot tell it from 2/3"
        );
    }
}

#[test]
fn sppm_snapshots_are_shorter_runs_and_threads_change_no_bit() {
    let scene = scene_with("cornell-spheres/analytic.toml", 3, 32, "photons = 20000\n");
    let long = render(&scene, 8, Some(2));
    let short = render(&scene, 4, Some(1));
    let passes: Vec<u32> = long.snapshots.iter().map(|s| s.passes).collect();
    assert_eq!(passes, [1, 2, 4, 8]);
    // The snapshot at 4 passes of an 8-pass run on 2 threads is the 4-pass run on 1 thread.
    assert!(bits(&image(&long, Some(4))) == bits(&image(&short, None)));
    assert!(bits(&image(&long, Some(8))) == bits(&image(&long, None)));
    assert_eq!(long.passes, Some(8));
    // Layers: light (emitted, direct) by the eye pass, the rest by photons; counts for
    // compositing.
    let kinds: Vec<(&str, CountKind, u64)> = long
        .layers
        .iter()
        .map(|l| (l.name.as_str(), l.count_kind, l.count))
        .collect();
    assert_eq!(
        kinds,
        [
            ("light", CountKind::Spp, 8),
            ("photons", CountKind::PhotonPaths, 8 * 20_000)
        ]
    );
    let img = image(&long, None);
    assert!(
        img.data
            .iter()
            .flatten()
            .all(|c| c.is_finite() && *c >= 0.0)
    );
}

#[test]
fn every_progressive_method_snapshots_what_a_shorter_run_makes() {
    // Snapshots at 1, 2, 4 and 8 passes (path: samples per pixel; path+splat: path-traced
    // samples, with as many splatting passes), the one at 4 the image of a 4-pass run on
    // another thread count, bit for bit.
    let scene = scene_with("cornell-spheres/analytic.toml", 5, 24, "photons = 20000\n");
    for method in [Method::Path, Method::CausticSplat, Method::PathSplat] {
        let long = render_method(&scene, method, 8, Some(2));
        let short = render_method(&scene, method, 4, Some(1));
        let passes: Vec<u32> = long.snapshots.iter().map(|s| s.passes).collect();
        assert_eq!(passes, [1, 2, 4, 8], "{method}");
        assert!(
            bits(&image(&long, Some(4))) == bits(&image(&short, None)),
            "{method}: the snapshot at 4 passes is not the 4-pass run"
        );
        assert!(
            bits(&image(&long, Some(8))) == bits(&image(&long, None)),
            "{method}"
        );
    }
}

#[test]
fn a_time_budget_stops_after_the_pass_that_reaches_it() {
    let scene = scene_with("furnace/furnace.toml", 1, 16, "photons = 1000\n");
    let budget = |method, passes| Overrides {
        method: Some(method),
        passes: Some(passes),
        time: Some(1e-9),
        ..Overrides::default()
    };
    // The path tracer: passes of 1, 1, 2, 4, ... samples, so the first pass makes one
    // sample per pixel, recorded as the spp made.
    let r = render_uncached(&scene, &budget(Method::Path, 4096), None);
    assert_eq!(r.samples, Some(1));
    assert!(r.layers.iter().all(|l| l.count == 1));
    // SPPM: exactly one pass is made, and recorded.
    let r = render_uncached(&scene, &budget(Method::Sppm, 1000), None);
    assert_eq!(r.passes, Some(1));
    assert_eq!(r.snapshots.len(), 1);
}
