//! The GGX models: RoughConductor, RoughDielectric, Glossy. Order as in the parent module:
//! construct → eval against Mitsuba 3 → symmetry → samples against eval → energy → chi-square.

use super::{IMP, RAD, albedo, dir, wos};
use crate::microfacet::{MIN_ALPHA, TrowbridgeReitz};
use crate::*;
use glam::Vec3;
use math::chi2::chi2_test_sidak_sub;
use math::{Frame, Rng};

const ALPHAS: [f32; 3] = [0.05, 0.3, 0.8];
const GOLD_ETA: Vec3 = Vec3::new(0.143, 0.374, 1.442);
const GOLD_K: Vec3 = Vec3::new(3.983, 2.385, 1.603);

fn rough_conductor(alpha: f32) -> Bsdf {
    RoughConductor {
        alpha,
        reflectance: Vec3::new(0.9, 0.6, 0.3),
        eta: None,
    }
    .into()
}

fn rough_gold(alpha: f32) -> Bsdf {
    RoughConductor {
        alpha,
        reflectance: Vec3::ONE,
        eta: Some((GOLD_ETA, GOLD_K)),
    }
    .into()
}

fn rough_glass(alpha: f32) -> Bsdf {
    RoughDielectric::clear(1.5, alpha).into()
}

fn glossy(alpha: f32) -> Bsdf {
    Glossy {
        albedo: Vec3::new(0.5, 0.3, 0.1),
        specular: Vec3::new(0.2, 0.3, 0.1),
        alpha,
    }
    .into()
}

/// Every new model at every test roughness.
fn models() -> Vec<(String, Bsdf)> {
    let mut v = Vec::new();
    for a in ALPHAS {
        v.push((format!("rough conductor a={a}"), rough_conductor(a)));
        v.push((format!("rough gold a={a}"), rough_gold(a)));
        v.push((format!("rough glass a={a}"), rough_glass(a)));
        v.push((format!("glossy a={a}"), glossy(a)));
        v.push((format!("rough plastic a={a}"), rough_plastic(a)));
    }
    v
}

fn rough_plastic(alpha: f32) -> Bsdf {
    RoughPlastic::new(
        Vec3::new(0.5, 0.3, 0.1),
        Vec3::new(0.9, 0.6, 0.3),
        1.49,
        alpha,
        false,
    )
    .into()
}

/// `|a - b| <= rel · max(|a|, |b|)`, or both below `abs`.
fn close(a: f32, b: f32, rel: f32, abs: f32) -> bool {
    (a - b).abs() <= rel * a.abs().max(b.abs()) || a.abs().max(b.abs()) <= abs
}

// --- Construction -----------------------------------------------------------------------

#[test]
fn glossy_models_classify_their_lobes() {
    for (name, b) in models() {
        assert!(!b.is_delta() && !b.is_diffuse() && b.is_glossy(), "{name}");
        assert_eq!(
            b.has_transmission(),
            matches!(b, Bsdf::RoughDielectric(_)),
            "{name}"
        );
        assert!(b.roughness().is_some_and(|a| ALPHAS.contains(&a)), "{name}");
    }
    assert_eq!(glossy(0.3).diffuse_albedo(), Some(Vec3::new(0.5, 0.3, 0.1)));
    assert_eq!(rough_glass(0.3).diffuse_albedo(), None);
    let lambert: Bsdf = Lambertian {
        albedo: Vec3::splat(0.4),
    }
    .into();
    assert_eq!(lambert.diffuse_albedo(), Some(Vec3::splat(0.4)));
    assert!(!lambert.is_glossy() && lambert.roughness().is_none());
    assert!(!Bsdf::from(Dielectric::clear(1.5)).is_glossy());
    // Degenerate roughness is clamped, as Mitsuba 3 does, and stays finite.
    assert_eq!(rough_glass(0.0).roughness(), Some(MIN_ALPHA));
    assert_eq!(TrowbridgeReitz::new(-1.0).alpha_x, MIN_ALPHA);
    let g = Flags::GLOSSY_REFLECTION;
    assert!(g.is_glossy() && g.is_reflection() && !g.is_specular() && !g.is_diffuse());
    assert_eq!(
        Flags::GLOSSY | Flags::TRANSMISSION,
        Flags::GLOSSY_TRANSMISSION
    );
}

#[test]
fn glossy_from_mtl_matches_the_python_mapping() {
    // Expected values computed independently in Python with the same mapping.
    let cases = [
        (
            [0.8, 0.5, 0.2],
            [0.5, 0.3, 0.1],
            100.0,
            [0.615_384_6, 0.5, 0.2],
            [0.384_615_4, 0.3, 0.1],
            0.140_028_01,
            true,
        ),
        (
            [0.3; 3],
            [0.2; 3],
            10.0,
            [0.3; 3],
            [0.2; 3],
            0.408_248_3,
            false,
        ),
        (
            [0.9, 0.1, 0.0],
            [0.4, 0.95, 1.0],
            0.0,
            [0.692_307_7, 0.095_238_1, 0.0],
            [0.307_692_3, 0.904_761_9, 1.0],
            1.0,
            true,
        ),
    ];
    for (kd, ks, ns, want_kd, want_ks, want_alpha, want_scaled) in cases {
        let (g, scaled) = Glossy::from_mtl(Vec3::from(kd), Vec3::from(ks), ns);
        assert!(g.albedo.distance(Vec3::from(want_kd)) < 1e-6, "{g:?}");
        assert!(g.specular.distance(Vec3::from(want_ks)) < 1e-6, "{g:?}");
        assert!((g.alpha - want_alpha).abs() < 1e-6, "{g:?}");
        assert_eq!(scaled, want_scaled, "{g:?}");
        assert!((g.albedo + g.specular).max_element() <= 1.0 + 1e-6);
    }
}

// --- Evaluation against Mitsuba 3 -------------------------------------------------------

/// Compares `f` and `pdf` with Mitsuba 3.9.1's `roughconductor` (material none with
/// `specular_reflectance`; and gold's `eta`/`k`), `roughdielectric` (index 1.5 in air, both
/// transport modes) and `diffuse` + `roughconductor` summed as [`Glossy`] defines, at 30
/// direction pairs per model and roughness 0.05, 0.3, 0.8 (`mitsuba_values.py` wrote the file;
/// its header has the command). The pdfs compare too: both sides sample visible normals and, for
/// the dielectric, pick the lobe by the microfacet's Fresnel term, and Glossy's lobe weights are
/// the same.
#[test]
fn ggx_models_match_mitsuba() {
    // Measured worst relative differences over values above 1e-6: f 1.4e-6 and pdf 1.2e-6 for
    // rough glass, below 8e-7 for the others (f32 rounding on both sides).
    const MAX_REL: f32 = 1e-4;
    let text = include_str!("mitsuba_values.csv");
    let mut rows = 0;
    let mut nonzero = 0;
    // Worst relative difference of f and of pdf per model, over values above 1e-6.
    let mut worst: Vec<(String, f32, f32)> = Vec::new();
    for line in text.lines().filter(|l| !l.starts_with('#')).skip(1) {
        let c: Vec<&str> = line.split(',').collect();
        let num = |i: usize| c[i].parse::<f32>().unwrap();
        let alpha = num(1);
        let b = match c[0] {
            "rc_none" => rough_conductor(alpha),
            "rc_gold" => rough_gold(alpha),
            "rd" => rough_glass(alpha),
            "glossy" => glossy(alpha),
            m => panic!("unknown model {m}"),
        };
        let mode = if c[2] == "radiance" { RAD } else { IMP };
        let wo = Vec3::new(num(3), num(4), num(5));
        let wi = Vec3::new(num(6), num(7), num(8));
        let want_f = Vec3::new(num(9), num(10), num(11));
        let want_pdf = num(12);
        let (f, pdf) = (b.f(wo, wi, mode), b.pdf(wo, wi));
        let w = match worst.iter().position(|(m, _, _)| m == c[0]) {
            Some(i) => i,
            None => {
                worst.push((c[0].to_string(), 0.0, 0.0));
                worst.len() - 1
            }
        };
        for k in 0..3 {
            // Values below 1e-6 are f32 noise of products that vanish analytically.
            assert!(
                close(f[k], want_f[k], MAX_REL, 1e-6),
                "{line}: f {f} vs Mitsuba {want_f}"
            );
            if want_f[k] > 1e-6 {
                worst[w].1 = worst[w].1.max((f[k] - want_f[k]).abs() / want_f[k]);
            }
        }
        assert!(
            close(pdf, want_pdf, MAX_REL, 1e-6),
            "{line}: pdf {pdf} vs Mitsuba {want_pdf}"
        );
        if want_pdf > 1e-6 {
            worst[w].2 = worst[w].2.max((pdf - want_pdf).abs() / want_pdf);
            nonzero += 1;
        }
        rows += 1;
    }
    assert_eq!(rows, 450, "every row of the file was read");
    assert!(nonzero > 300, "most pairs carry energy: {nonzero}");
    eprintln!("worst relative difference to Mitsuba (model, f, pdf): {worst:?}");
}

// --- Symmetry ---------------------------------------------------------------------------

#[test]
fn reflection_is_reciprocal_and_two_sided() {
    for (name, b) in models() {
        for wo in wos() {
            for wi in wos() {
                if wo.z * wi.z <= 0.0 {
                    continue;
                }
                let (a, c) = (b.f(wo, wi, RAD), b.f(wi, wo, RAD));
                for k in 0..3 {
                    assert!(
                        close(a[k], c[k], 1e-4, 1e-30),
                        "{name} {wo} {wi}: {a} vs {c}"
                    );
                }
                // Reflection ignores the transport mode.
                assert_eq!(a, b.f(wo, wi, IMP), "{name}");
                // The opaque models reflect alike from below (Mitsuba's are one-sided; a mesh
                // here may be seen from either side).
                if !b.has_transmission() {
                    let flip = |w: Vec3| Vec3::new(w.x, w.y, -w.z);
                    assert_eq!(a, b.f(flip(wo), flip(wi), RAD), "{name}");
                    assert_eq!(b.pdf(wo, wi), b.pdf(flip(wo), flip(wi)), "{name}");
                }
            }
        }
    }
}

/// Transmission through the rough interface. With `n_o`, `n_i` the indices on `wo`'s and `wi`'s
/// sides, the radiance BTDF obeys the generalized reciprocity `f(wo, wi) / n_o² = f(wi, wo) / n_i²`
/// (Veach 1997, eq. 5.14: `f` scales with the index of the side radiance leaves to), i.e.
/// `f(wo, wi) · n_i² = f(wi, wo) · n_o²`; and the Importance-mode BTDF is its adjoint,
/// `f_imp(wo, wi) = f_rad(wi, wo)` (Veach §3.7.6), so neither mode is plainly symmetric.
#[test]
fn transmission_obeys_generalized_reciprocity() {
    let mut checked = 0;
    for a in ALPHAS {
        let b = rough_glass(a);
        for wo in wos() {
            for wi in wos() {
                if wo.z * wi.z >= 0.0 {
                    continue;
                }
                let index = |w: Vec3| if w.z > 0.0 { 1.0f32 } else { 1.5 };
                let (n_o, n_i) = (index(wo), index(wi));
                let (fwd, back) = (b.f(wo, wi, RAD).x, b.f(wi, wo, RAD).x);
                assert!(
                    close(fwd * n_i * n_i, back * n_o * n_o, 1e-4, 1e-30),
                    "a={a} {wo} {wi}: {fwd} vs {back}"
                );
                assert!(
                    close(b.f(wo, wi, IMP).x, back, 1e-4, 1e-30),
                    "a={a} {wo} {wi}"
                );
                checked += (fwd > 0.0) as usize;
            }
        }
    }
    assert!(checked > 50, "{checked}");
}

#[test]
fn transmission_modes_differ_by_eta_squared() {
    let mut rng = Rng::new(601);
    for a in ALPHAS {
        let b = rough_glass(a);
        for wo in wos() {
            for _ in 0..200 {
                let (uc, u) = (rng.uniform(), rng.uniform2());
                let (Some(r), Some(i)) = (b.sample(wo, uc, u, RAD), b.sample(wo, uc, u, IMP))
                else {
                    continue;
                };
                assert_eq!((r.wi, r.pdf, r.flags, r.eta), (i.wi, i.pdf, i.flags, i.eta));
                let scale = if r.is_transmission() {
                    1.0 / (r.eta * r.eta)
                } else {
                    1.0
                };
                assert!(close(r.f.x, i.f.x * scale, 1e-6, 0.0), "a={a} {wo}");
            }
        }
    }
}

// --- Samples against eval ---------------------------------------------------------------

#[test]
fn samples_agree_with_f_and_pdf() {
    let mut rng = Rng::new(602);
    for (name, b) in models() {
        let mut kinds = [0usize; 4];
        for wo in wos() {
            for _ in 0..500 {
                let mode = if rng.uniform() < 0.5 { RAD } else { IMP };
                let Some(s) = b.sample(wo, rng.uniform(), rng.uniform2(), mode) else {
                    continue;
                };
                assert!((s.wi.length() - 1.0).abs() < 1e-4, "{name} {wo}: {s:?}");
                assert!(s.pdf > 0.0 && s.f.is_finite() && s.f.min_element() >= 0.0);
                let (f, pdf) = (b.f(wo, s.wi, mode), b.pdf(wo, s.wi));
                for k in 0..3 {
                    assert!(
                        close(s.f[k], f[k], 1e-4, 0.0),
                        "{name} {wo}: {s:?} vs f {f}"
                    );
                }
                assert!(
                    close(s.pdf, pdf, 1e-4, 0.0),
                    "{name} {wo}: {s:?} vs pdf {pdf}"
                );
                let reflected = s.wi.z * wo.z > 0.0;
                assert_eq!(s.is_reflection(), reflected, "{name}");
                assert_eq!(s.is_transmission(), !reflected, "{name}");
                let want_eta = match (reflected, wo.z > 0.0) {
                    (true, _) => 1.0,
                    (false, true) => 1.5,
                    (false, false) => 1.0 / 1.5,
                };
                assert_eq!(s.eta, want_eta, "{name}");
                let k = match s.flags {
                    Flags::GLOSSY_REFLECTION => 0,
                    Flags::GLOSSY_TRANSMISSION => 1,
                    Flags::DIFFUSE_REFLECTION => 2,
                    other => panic!("{name}: flags {other:?}"),
                };
                kinds[k] += 1;
            }
        }
        let want: &[usize] = match b {
            Bsdf::RoughDielectric(_) => &[0, 1],
            Bsdf::Glossy(_) | Bsdf::RoughPlastic(_) => &[0, 2],
            _ => &[0],
        };
        for k in 0..4 {
            assert_eq!(kinds[k] > 0, want.contains(&k), "{name}: {kinds:?}");
        }
    }
}

#[test]
fn glossy_picks_its_lobes_by_mean_reflectance() {
    // pd = mean(albedo) / (mean(albedo) + mean(specular)) = 0.3 / 0.5; the diffuse count is
    // Binomial(n, pd): 5 standard deviations.
    let b = glossy(0.3);
    let Bsdf::Glossy(g) = b else { unreachable!() };
    assert!((g.diffuse_probability() - 0.6).abs() < 1e-6);
    let black = Glossy {
        albedo: Vec3::ZERO,
        specular: Vec3::ZERO,
        alpha: 0.3,
    };
    assert_eq!(black.diffuse_probability(), 0.5);
    let n = 20_000;
    let mut rng = Rng::new(603);
    let wo = dir(30.0, 10.0);
    let diffuse = (0..n)
        .filter_map(|_| b.sample(wo, rng.uniform(), rng.uniform2(), RAD))
        .filter(|s| s.flags == Flags::DIFFUSE_REFLECTION)
        .count();
    let sd = (n as f64 * 0.6 * 0.4).sqrt();
    assert!(
        (diffuse as f64 - 0.6 * n as f64).abs() < 5.0 * sd,
        "{diffuse} / {n}"
    );
}

#[test]
fn grazing_and_degenerate_directions_stay_finite() {
    let mut rng = Rng::new(604);
    let mut bsdfs = models();
    for a in [0.0, MIN_ALPHA, 1e-3, 1.0, 2.0] {
        bsdfs.push((format!("conductor a={a}"), rough_gold(a)));
        bsdfs.push((format!("glass a={a}"), rough_glass(a)));
        bsdfs.push((format!("glossy a={a}"), glossy(a)));
        bsdfs.push((format!("rough plastic a={a}"), rough_plastic(a)));
    }
    let edge = [
        Vec3::Z,
        -Vec3::Z,
        Vec3::new(1.0, 0.0, 1e-7).normalize(),
        Vec3::new(0.0, 1.0, -1e-7).normalize(),
        Vec3::new(1.0, 0.0, 1e-3).normalize(),
        Vec3::new(-1.0, 0.0, 1e-3).normalize(),
    ];
    for (name, b) in bsdfs {
        // wo exactly in the tangent plane has no hemisphere.
        assert_eq!(b.f(Vec3::X, Vec3::Z, RAD), Vec3::ZERO, "{name}");
        assert_eq!(b.pdf(Vec3::X, Vec3::Z), 0.0, "{name}");
        assert!(b.sample(Vec3::X, 0.5, [0.3, 0.7], RAD).is_none(), "{name}");
        let mut dirs: Vec<Vec3> = edge.to_vec();
        dirs.extend((0..30).map(|_| math::warp::sample_uniform_sphere(rng.uniform2())));
        for &wo in &dirs {
            for &wi in &dirs {
                let (f, pdf) = (b.f(wo, wi, RAD), b.pdf(wo, wi));
                assert!(
                    f.is_finite() && f.min_element() >= 0.0,
                    "{name} {wo} {wi}: {f}"
                );
                assert!(pdf.is_finite() && pdf >= 0.0, "{name} {wo} {wi}: {pdf}");
            }
            for u in [
                [0.0, 0.0],
                [0.999_999_9, 0.5],
                [0.5, 0.999_999_9],
                [0.5, 0.0],
            ] {
                if let Some(s) = b.sample(wo, 0.5, u, RAD) {
                    assert!(s.f.is_finite() && s.wi.is_finite() && s.pdf > 0.0, "{name}");
                    assert!(s.pdf.is_finite(), "{name} {wo}: {s:?}");
                }
            }
        }
    }
}

// --- Energy -----------------------------------------------------------------------------

/// Single-scattering albedo of a white GGX reflector at normal incidence, by quadrature. There
/// `D_wo(wm) = D(wm) cos θm` and `u = tan²θm` has density `α² / (α² + u)²`; `wi` leaves at
/// `2θm`, inside the hemisphere for `u < 1`, and weighs `G1(wi)` (`tan²2θm = 4u / (1 - u)²`).
/// Composite Simpson in f64.
fn ggx_albedo_at_normal_incidence(alpha: f64) -> f64 {
    let a2 = alpha * alpha;
    let g = |u: f64| {
        let t2 = 4.0 * u / ((1.0 - u) * (1.0 - u));
        let g1 = if t2.is_finite() {
            2.0 / (1.0 + (1.0 + a2 * t2).sqrt())
        } else {
            0.0
        };
        a2 / ((a2 + u) * (a2 + u)) * g1
    };
    let n = 200_000;
    let h = 1.0 / n as f64;
    let mut sum = g(0.0) + g(1.0);
    for i in 1..n {
        sum += g(i as f64 * h) * if i % 2 == 1 { 4.0 } else { 2.0 };
    }
    sum * h / 3.0
}

/// White furnace. With visible-normal sampling each GGX sample weighs `G1(wi) ≤ 1` (Heitz 2014,
/// "Understanding the Masking-Shadowing Function", §5), or 0 when `wi` falls below the surface,
/// so no estimate can exceed 1; the shortfall is what single scattering loses. Measured (2e4
/// samples per `wo`; standard errors 7e-5 to 3.4e-3; glass in Importance mode):
///
/// | alpha | conductor at θo 0.5° / 45° / 75° / 85° / 89° | glass from outside, same θo | glass from inside, 179.5° / 135° / 105° / 95° |
/// |-------|-----------------------------------|------------------------------------|---------------------------------|
/// | 0.05  | 0.9976 / 0.9965 / 0.976 / 0.897 / 0.901 | 0.9999 / 0.9993 / 0.990 / 0.927 / 0.914 | 0.9974 / 0.9924 / 0.974 / 0.891 |
/// | 0.3   | 0.875 / 0.848 / 0.811 / 0.843 / 0.874 | 0.987 / 0.971 / 0.898 / 0.844 / 0.806 | 0.901 / 0.823 / 0.746 / 0.737 |
/// | 0.8   | 0.425 / 0.470 / 0.579 / 0.648 / 0.683 | 0.926 / 0.845 / 0.620 / 0.491 / 0.425 | 0.536 / 0.538 / 0.448 / 0.437 |
///
/// GGX's long tail costs even a smooth surface: at normal incidence microfacets tilted past 45°
/// (probability `α² / (1 + α²)`, 0.25% at alpha 0.05) send `wi` below the surface. At alpha 0.05
/// the albedo is `≥ 0.99` up to 60° (0.9926 at 60°, the lowest); the normal-incidence values
/// match the quadrature of [`ggx_albedo_at_normal_incidence`] (0.99730, 0.87736, 0.42700).
#[test]
fn white_furnace_never_gains_and_loses_little_when_smooth() {
    let n = 20_000;
    for a in ALPHAS {
        let white: Bsdf = RoughConductor {
            alpha: a,
            reflectance: Vec3::ONE,
            eta: None,
        }
        .into();
        for (name, b) in [("conductor", white), ("glass", rough_glass(a))] {
            for (k, wo) in wos().into_iter().enumerate() {
                let seed = 700 + k as u64;
                let (e, se) = albedo(&b, wo, IMP, n, seed);
                let (e, se) = (e.x, se.x);
                assert!(
                    e <= 1.0 + 1e-5,
                    "{name} a={a} wo {wo} seed {seed}: {e} ± {se}"
                );
                let theta = wo.z.abs().acos().to_degrees();
                if a == 0.05 && theta <= 60.5 {
                    assert!(
                        e >= 0.99 - 3.0 * se,
                        "{name} wo {wo} seed {seed}: {e} ± {se}"
                    );
                }
            }
        }
        // Independent check of the conductor's level: quadrature at normal incidence.
        let want = ggx_albedo_at_normal_incidence(a as f64);
        let (e, se) = albedo(&white, Vec3::Z, IMP, 100_000, 750);
        let (e, se) = (e.x as f64, se.x as f64);
        assert!(
            (e - want).abs() <= 4.0 * se + 1e-6,
            "a={a}: {e} ± {se} vs {want}"
        );
    }
}

#[test]
fn rough_gold_albedo_follows_its_fresnel_term() {
    // At alpha 0.05 microfacets stay within a few degrees of the normal, so the albedo is the
    // white reflector's times F(cos θo), up to F's change over that spread. Same seeds for
    // both (common random numbers), so noise nearly cancels. Measured worst difference 5e-4
    // (blue, 45°); allowed 3e-3. Without F the difference is 0.04 to 0.68.
    for (k, th) in [0.0f32, 30.0, 45.0, 60.0].into_iter().enumerate() {
        let wo = dir(th, 20.0);
        let white: Bsdf = RoughConductor {
            alpha: 0.05,
            reflectance: Vec3::ONE,
            eta: None,
        }
        .into();
        let seed = 760 + k as u64;
        let (eg, _) = albedo(&rough_gold(0.05), wo, IMP, 20_000, seed);
        let (ew, _) = albedo(&white, wo, IMP, 20_000, seed);
        let want = fresnel_conductor(wo.z, GOLD_ETA, GOLD_K) * ew;
        assert!(eg.distance(want) < 3e-3, "theta {th}: {eg} vs {want}");
    }
}

#[test]
fn glossy_albedo_is_the_sum_of_its_lobes() {
    // A white Lambertian plus GGX of specular 0.3: `albedo + 0.3 · E_ggx(wo)`, where E_ggx is
    // the white rough conductor's albedo at the same wo. Both measured by sampling with
    // different seeds: 5 combined standard errors.
    let n = 40_000;
    for a in ALPHAS {
        let g: Bsdf = Glossy {
            albedo: Vec3::splat(0.6),
            specular: Vec3::splat(0.3),
            alpha: a,
        }
        .into();
        let spec: Bsdf = RoughConductor {
            alpha: a,
            reflectance: Vec3::ONE,
            eta: None,
        }
        .into();
        for (k, wo) in wos().into_iter().enumerate() {
            let (e, se) = albedo(&g, wo, IMP, n, 800 + k as u64);
            let (es, ses) = albedo(&spec, wo, IMP, n, 900 + k as u64);
            let want = 0.6 + 0.3 * es.x;
            let tol = 5.0 * (se.x * se.x + 0.09 * ses.x * ses.x).sqrt() + 1e-5;
            assert!(
                (e.x - want).abs() <= tol,
                "a={a} wo {wo}: {e} vs {want} ± {tol}"
            );
            assert!(e.x <= 0.9 + tol, "a={a} wo {wo}: {e}");
        }
    }
}

// --- Chi-square -------------------------------------------------------------------------

/// A frame whose pole is the normal of `wo`'s plane of incidence, so mirror and refracted lobes
/// both lie on the new equator: there the binning's cells are near square and smallest in solid
/// angle, and the cell quadrature resolves a narrow lobe (at the pole a band of 101 wedges 16°
/// tall would hold an alpha = 0.05 lobe whole). Its x axis is the surface normal, so the
/// horizon, where the pdf jumps, is the meridians φ = 90° and 270°: cell edges when the azimuth
/// count is a multiple of 4. A rotation keeps densities unchanged.
fn incidence_plane_frame(wo: Vec3) -> Frame {
    let n = Vec3::Z.cross(wo).try_normalize().unwrap_or(Vec3::Y);
    Frame {
        s: Vec3::Z,
        t: n.cross(Vec3::Z),
        n,
    }
}

/// Chi-square of sampling against `pdf` for each model, several `wo` (normal, oblique, 85°, and
/// from below), alpha 0.05 / 0.3 / 0.8. One Šidák family per model. The narrow lobes get a finer
/// grid so they span several cells; `sub` is the quadrature's sub-cells per cell side.
fn chi2_family(name: &str, make: fn(f32) -> Bsdf, wo_list: &[Vec3], sub: usize, seed0: u64) {
    let count = (wo_list.len() * ALPHAS.len()) as u32;
    for (ia, &a) in ALPHAS.iter().enumerate() {
        let b = make(a);
        // The finer grid needs fewer sub-cells for a similar quadrature step.
        let (theta_res, phi_res, sub, n) = if a < 0.1 {
            (101, 200, (sub * 3 / 4).max(4), 500_000)
        } else {
            (51, 100, sub, 300_000)
        };
        for (k, &wo) in wo_list.iter().enumerate() {
            let seed = seed0 + (ia * wo_list.len() + k) as u64;
            let frame = incidence_plane_frame(wo);
            chi2_test_sidak_sub(
                count,
                theta_res,
                phi_res,
                sub,
                n,
                seed,
                |rng| {
                    b.sample(wo, rng.uniform(), rng.uniform2(), RAD)
                        .map(|s| frame.to_local(s.wi))
                },
                |v| b.pdf(wo, frame.to_world(v)) as f64,
            )
            .unwrap_or_else(|e| panic!("{name} a={a} wo {wo}: {e}"));
        }
    }
}

fn reflection_wos() -> Vec<Vec3> {
    vec![
        dir(0.0, 0.0),
        dir(40.0, 30.0),
        dir(85.0, 200.0),
        dir(120.0, 10.0),
    ]
}

#[test]
fn rough_conductor_sampling_passes_chi2() {
    chi2_family("rough gold", rough_gold, &reflection_wos(), 4, 1000);
}

#[test]
fn rough_plastic_sampling_passes_chi2() {
    chi2_family("rough plastic", rough_plastic, &reflection_wos(), 4, 1300);
}

#[test]
fn glossy_sampling_passes_chi2() {
    chi2_family("glossy", glossy, &reflection_wos(), 4, 1100);
}

#[test]
fn rough_dielectric_sampling_passes_chi2() {
    // From inside: 130° is 50° off the inner normal, beyond the smooth critical angle (41.8°);
    // 160° is within it.
    let wo_list = [
        dir(0.0, 0.0),
        dir(40.0, 30.0),
        dir(85.0, 200.0),
        dir(160.0, 10.0),
        dir(130.0, 70.0),
    ];
    // Refraction's pdf jumps where the generalized half vector reaches the horizon (D does not
    // vanish there), a curve across cells: a finer quadrature integrates it.
    chi2_family("rough glass", rough_glass, &wo_list, 16, 1200);
}
