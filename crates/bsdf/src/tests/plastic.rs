//! The coated models and the thin slab: Plastic, RoughPlastic, ThinDielectric. Order as in the
//! parent module: eval against Mitsuba 3 → optics → samples against eval → energy → chi-square.

use super::{IMP, RAD, albedo, dir, wos};
use crate::*;
use glam::Vec3;
use math::Rng;
use math::chi2::chi2_test_sidak;

const ALPHAS: [f32; 3] = [0.05, 0.3, 0.8];

fn plastic() -> Plastic {
    Plastic::new(
        Vec3::new(0.5, 0.3, 0.1),
        Vec3::new(0.9, 0.8, 1.0),
        1.49,
        false,
    )
}

fn rough_plastic(alpha: f32) -> RoughPlastic {
    RoughPlastic::new(
        Vec3::new(0.8, 0.5, 0.2),
        Vec3::new(0.9, 0.6, 0.3),
        1.5,
        alpha,
        true,
    )
}

/// `2 ∫ g(μ) μ dμ` over [0, 1], composite Simpson in f64.
fn cosine_mean(g: impl Fn(f32) -> f64) -> f64 {
    let n = 20_000;
    let h = 1.0 / n as f64;
    let mut sum = 0.0;
    for i in 0..=n {
        let mu = i as f64 * h;
        let w = if i == 0 || i == n {
            1.0
        } else if i % 2 == 1 {
            4.0
        } else {
            2.0
        };
        sum += w * g(mu as f32) * mu;
    }
    2.0 * sum * h / 3.0
}

// --- Evaluation against Mitsuba 3 -------------------------------------------------------

/// Compares `f` and `pdf` with Mitsuba 3.9.1's `plastic` and `roughplastic` (GGX) at 24 direction
/// pairs per model: four coatings (index 1.33 to 2, linear and `nonlinear`, coloured bases and
/// specular factors) smooth and at roughness 0.05, 0.3, 0.8 (`mitsuba_plastic.py` wrote the
/// file; its header has the command). The rough model's transmittance table and internal
/// reflectance are Mitsuba's quadratures redone here, so they agree to rounding too.
#[test]
fn plastics_match_mitsuba() {
    // Measured worst relative differences over values above 1e-6 are printed below: f 4.5e-7,
    // pdf 2.4e-7 (smooth); f 1.1e-6, pdf 5.7e-7 (rough).
    const MAX_REL: f32 = 1e-5;
    let text = include_str!("mitsuba_plastic.csv");
    let (mut rows, mut nonzero) = (0, 0);
    // Worst relative and absolute differences of f and pdf, smooth and rough.
    let mut worst = [[0.0f32; 4]; 2];
    for line in text.lines().filter(|l| !l.starts_with('#')).skip(1) {
        let c: Vec<&str> = line.split(',').collect();
        let num = |i: usize| c[i].parse::<f32>().unwrap();
        let v3 = |i: usize| Vec3::new(num(i), num(i + 1), num(i + 2));
        let (ior, nonlinear) = (num(2), c[3] == "true");
        let (d, s) = (v3(4), v3(7));
        let (b, k): (Bsdf, usize) = match c[0] {
            "plastic" => (Plastic::new(d, s, ior, nonlinear).into(), 0),
            "roughplastic" => (RoughPlastic::new(d, s, ior, num(1), nonlinear).into(), 1),
            m => panic!("unknown model {m}"),
        };
        let (wo, wi) = (v3(10), v3(13));
        let (want_f, want_pdf) = (v3(16), num(19));
        let (f, pdf) = (b.f(wo, wi, RAD), b.pdf(wo, wi));
        let rel = |a: f32, b: f32| (a - b).abs() / a.abs().max(b.abs()).max(1e-30);
        for j in 0..3 {
            let (r, a) = (rel(f[j], want_f[j]), (f[j] - want_f[j]).abs());
            assert!(
                r <= MAX_REL || a <= 1e-7,
                "{line}: f {f} vs Mitsuba {want_f}"
            );
            if want_f[j] > 1e-6 {
                worst[k][0] = worst[k][0].max(r);
            }
            worst[k][1] = worst[k][1].max(a);
        }
        let (r, a) = (rel(pdf, want_pdf), (pdf - want_pdf).abs());
        assert!(
            r <= MAX_REL || a <= 1e-7,
            "{line}: pdf {pdf} vs Mitsuba {want_pdf}"
        );
        if want_pdf > 1e-6 {
            worst[k][2] = worst[k][2].max(r);
            nonzero += 1;
        }
        worst[k][3] = worst[k][3].max(a);
        rows += 1;
    }
    assert_eq!(rows, 384, "every row of the file was read");
    assert!(nonzero > 300, "most pairs carry energy: {nonzero}");
    eprintln!(
        "worst difference to Mitsuba, [f rel, f abs, pdf rel, pdf abs]: plastic {:?}, \
         roughplastic {:?}",
        worst[0], worst[1]
    );
}

// --- Optics -----------------------------------------------------------------------------

#[test]
fn diffuse_fresnel_fits_follow_the_integral() {
    // Mitsuba's fits against `2 ∫ F(μ) μ dμ`: within 0.6% (its own bound) for indices from
    // 1/2 to 2, from either side.
    for eta in [
        1.1f32,
        1.33,
        1.5,
        2.0,
        1.0 / 1.1,
        1.0 / 1.33,
        1.0 / 1.5,
        0.5,
    ] {
        let exact = cosine_mean(|mu| fresnel_dielectric(mu, eta) as f64);
        let fit = fresnel_diffuse_reflectance(eta) as f64;
        assert!(
            (fit - exact).abs() <= 6e-3 * exact,
            "eta {eta}: fit {fit} vs {exact}"
        );
    }
}

#[test]
fn thin_slab_sums_its_internal_reflections() {
    // R' by the series R + T² R + T² R³ + ... summed term by term.
    for eta in [1.33f32, 1.5, 2.4] {
        for i in 0..=20 {
            let cos = i as f32 / 20.0;
            let r = fresnel_dielectric(cos, eta) as f64;
            let t = 1.0 - r;
            let mut series = r;
            let mut term = t * t * r;
            for _ in 0..2000 {
                series += term;
                term *= r * r;
            }
            let slab = ThinDielectric::clear(eta);
            assert!(
                (slab.reflectance_at(cos) as f64 - series).abs() < 1e-6,
                "eta {eta} cos {cos}"
            );
            assert_eq!(slab.reflectance_at(cos), slab.reflectance_at(-cos));
        }
    }
}

#[test]
fn thin_slab_transmits_straight_through_from_either_side() {
    let b: Bsdf = ThinDielectric::clear(1.5).into();
    for wo in wos() {
        let r = ThinDielectric::clear(1.5).reflectance_at(wo.z);
        for mode in [RAD, IMP] {
            let t = b.sample(wo, 0.999_999, [0.5; 2], mode).unwrap();
            assert_eq!(
                (t.wi, t.flags, t.eta),
                (-wo, Flags::SPECULAR_TRANSMISSION, 1.0)
            );
            assert!((t.pdf - (1.0 - r)).abs() < 1e-6 && (t.weight().x - 1.0).abs() < 1e-5);
            let s = b.sample(wo, 0.0, [0.5; 2], mode).unwrap();
            assert_eq!(s.flags, Flags::SPECULAR_REFLECTION, "{wo}");
            assert!(s.wi.distance(reflect(wo, Vec3::Z)) < 1e-6);
            assert!((s.pdf - r).abs() < 1e-6);
        }
        assert_eq!(b.f(wo, -wo, RAD), Vec3::ZERO);
        assert_eq!(b.pdf(wo, -wo), 0.0);
    }
    // Index-matched: nothing reflects, and transmission is still chosen at uc = 0.
    let clear: Bsdf = ThinDielectric::clear(1.0).into();
    let s = clear.sample(dir(30.0, 0.0), 0.0, [0.5; 2], RAD).unwrap();
    assert!(s.is_transmission());
    assert_eq!(
        Bsdf::from(ThinDielectric::clear(1.5)).glass_eta(),
        Some(1.0)
    );
}

#[test]
fn conductor_reflectance_scales_fresnel() {
    let eta = Vec3::new(0.2, 0.9, 1.1);
    let k = Vec3::new(3.9, 2.4, 2.1);
    let tint = Vec3::new(0.5, 0.8, 1.0);
    let b: Bsdf = Conductor {
        eta,
        k,
        reflectance: tint,
    }
    .into();
    for wo in wos() {
        let s = b.sample(wo, 0.5, [0.5; 2], RAD).unwrap();
        let want = tint * fresnel_conductor(wo.z, eta, k);
        assert!(s.weight().distance(want) < 1e-5, "{wo}: {}", s.weight());
    }
}

// --- Samples against eval ---------------------------------------------------------------

#[test]
fn plastic_samples_agree_with_f_and_pdf() {
    let p = plastic();
    let b: Bsdf = p.into();
    let mut rng = Rng::new(1301);
    let (mut spec, mut diff) = (0, 0);
    for wo in wos() {
        for _ in 0..400 {
            let s = b
                .sample(wo, rng.uniform(), rng.uniform2(), RAD)
                .expect("plastic always scatters");
            assert!(s.wi.z * wo.z > 0.0 && s.eta == 1.0, "{wo}: {s:?}");
            if s.is_specular() {
                spec += 1;
                let fo = fresnel_dielectric(wo.z.abs(), 1.49);
                assert!(s.wi.distance(reflect(wo, Vec3::Z)) < 1e-6);
                assert!((s.pdf - p.specular_probability(wo)).abs() < 1e-6);
                assert!(s.weight().distance(p.specular * fo / s.pdf) < 1e-4 * s.weight().length());
            } else {
                diff += 1;
                assert_eq!(s.flags, Flags::DIFFUSE_REFLECTION);
                assert!(s.f.distance(b.f(wo, s.wi, RAD)) < 1e-6);
                assert!((s.pdf - b.pdf(wo, s.wi)).abs() < 1e-6 * s.pdf.max(1.0));
                let (l, diffuse, pdf_all) = b.sample_lobe(wo, 0.9999, [0.3, 0.6], RAD).unwrap();
                assert!(diffuse && l.pdf == pdf_all);
            }
        }
    }
    assert!(spec > 100 && diff > 1000, "{spec} specular, {diff} diffuse");
}

#[test]
fn rough_plastic_lobes_sum_to_the_model() {
    // `sample_lobe` weighs one lobe alone: its f and pdf, plus the other lobe's at the same
    // direction, are the whole model's.
    let mut rng = Rng::new(1302);
    for a in ALPHAS {
        let p = rough_plastic(a);
        let b: Bsdf = p.into();
        let (mut seen_d, mut seen_g) = (0, 0);
        for wo in wos() {
            for _ in 0..100 {
                let (uc, u) = (rng.uniform(), rng.uniform2());
                let Some((s, diffuse, pdf_all)) = b.sample_lobe(wo, uc, u, RAD) else {
                    continue;
                };
                let full = b.sample(wo, uc, u, RAD).unwrap();
                assert_eq!(full.wi, s.wi);
                assert!((full.pdf - pdf_all).abs() <= 1e-5 * pdf_all, "a={a} {wo}");
                let other = if diffuse {
                    p.coating().f(wo, s.wi)
                } else {
                    RoughPlastic {
                        specular: Vec3::ZERO,
                        ..p
                    }
                    .f(wo, s.wi)
                };
                assert!(
                    (s.f + other).distance(full.f) <= 1e-5 * full.f.length(),
                    "a={a} {wo}"
                );
                assert!(s.pdf <= pdf_all * (1.0 + 1e-6));
                assert_eq!(s.flags.is_diffuse(), diffuse);
                seen_d += diffuse as u32;
                seen_g += !diffuse as u32;
            }
        }
        assert!(seen_d > 100 && seen_g > 100, "a={a}: {seen_d} {seen_g}");
    }
}

// --- Energy -----------------------------------------------------------------------------

/// The smooth plastic's albedo in closed form: `F(wo) s + (1 - F(wo)) ρ' / η² · 2 ∫ (1 - F(μ))
/// μ dμ`, with `ρ'` the base's albedo with its internal bounces, computed here from the fit.
fn plastic_albedo(p: &Plastic, wo: Vec3) -> Vec3 {
    let fo = fresnel_dielectric(wo.z.abs(), p.eta);
    let fdr_int = fresnel_diffuse_reflectance(1.0 / p.eta);
    let rho = if p.nonlinear {
        p.diffuse / (Vec3::ONE - p.diffuse * fdr_int)
    } else {
        p.diffuse / (1.0 - fdr_int)
    };
    let t = cosine_mean(|mu| 1.0 - fresnel_dielectric(mu, p.eta) as f64) as f32;
    p.specular * fo + rho * ((1.0 - fo) * t / (p.eta * p.eta))
}

#[test]
fn plastic_albedo_matches_its_closed_form_and_white_conserves() {
    // A white linear plastic reflects everything but what the F_dr fits lose: the coating's
    // reflection plus its diffuse transmission, (1 - F_dr(η)) / (η² (1 - F_dr(1/η))) = 1 for
    // the exact integrals. Without the internal bounces (ρ' = ρ) the diffuse part would be
    // 2.5 times smaller at index 1.5.
    let n = 40_000;
    let models = [
        plastic(),
        Plastic::new(Vec3::ONE, Vec3::ONE, 1.5, false),
        Plastic::new(Vec3::new(0.9, 0.5, 0.1), Vec3::ONE, 1.33, true),
        Plastic::new(Vec3::splat(0.7), Vec3::splat(0.2), 2.0, true),
    ];
    for (i, p) in models.into_iter().enumerate() {
        let b: Bsdf = p.into();
        for (k, wo) in wos().into_iter().enumerate() {
            let seed = 1400 + (16 * i + k) as u64;
            for mode in [RAD, IMP] {
                let (e, se) = albedo(&b, wo, mode, n, seed);
                let want = plastic_albedo(&p, wo);
                let tol = 5.0 * se.max_element() + 1e-4;
                assert!(
                    e.distance(want) <= tol,
                    "{p:?} wo {wo} seed {seed}: {e} vs {want}"
                );
            }
            if p.diffuse == Vec3::ONE && p.specular == Vec3::ONE {
                let want = plastic_albedo(&p, wo);
                assert!((want.x - 1.0).abs() < 5e-3, "white: {want}");
            }
        }
    }
}

#[test]
fn diffuse_lobe_albedo_is_the_base_lit_uniformly() {
    // What photon estimates multiply irradiance by: ∫ f_diffuse(wo, wi) |cos θi| dwi (the
    // directional albedo of the diffuse lobe alone), up to the smooth model's F_dr fit; and
    // the coating (the rest) carries the rest of the model.
    for (name, b, tol) in [
        ("plastic", Bsdf::from(plastic()), 4e-3),
        ("rough plastic a=0.3", rough_plastic(0.3).into(), 1e-4),
        ("rough plastic a=0.05", rough_plastic(0.05).into(), 1e-4),
    ] {
        for wo in wos() {
            let lobe = b.diffuse_lobe(wo).unwrap();
            let rest = lobe.rest.expect("the coating");
            assert_eq!(rest.diffuse_albedo(), Some(Vec3::ZERO));
            let spec = |wi: Vec3| rest.f(wo, wi, RAD);
            // Quadrature over the hemisphere of wo: f is smooth in wi but for the GGX peak,
            // which the coating holds.
            let n = 400;
            let mut sum = Vec3::ZERO.as_dvec3();
            for i in 0..n {
                for j in 0..n {
                    let (u, v) = ((i as f32 + 0.5) / n as f32, (j as f32 + 0.5) / n as f32);
                    // cosine-weighted directions: f cos / pdf = π f
                    let mut wi = math::warp::sample_cosine_hemisphere([u, v]);
                    if wo.z < 0.0 {
                        wi.z = -wi.z;
                    }
                    let fd = b.f(wo, wi, RAD) - spec(wi);
                    sum += (fd * std::f32::consts::PI).as_dvec3();
                }
            }
            let directional = (sum / (n * n) as f64).as_vec3();
            assert!(
                directional.distance(lobe.albedo) <= tol * directional.length().max(0.1),
                "{name} wo {wo}: {directional} vs {}",
                lobe.albedo
            );
            assert!((0.0..=1.0).contains(&lobe.probability), "{name}");
        }
    }
}

#[test]
fn rough_plastic_never_gains_and_approaches_the_smooth_one() {
    // White base and coating: no estimate above 1. At alpha 0.05 the rough model is the smooth
    // one but for GGX's single-scattering loss and Mitsuba's coarser internal reflectance (the
    // mean of `R(μ) μ` over 64 cosines: 0.570 at index 1.5 where the smooth fit has 0.596,
    // which darkens the base by 6%): measured 0.957 against 1.001 at normal incidence; within
    // 5% up to 60 degrees.
    let n = 20_000;
    for a in ALPHAS {
        let p = RoughPlastic::new(Vec3::ONE, Vec3::ONE, 1.5, a, false);
        let smooth = Plastic::new(Vec3::ONE, Vec3::ONE, 1.5, false);
        for (k, wo) in wos().into_iter().enumerate() {
            let seed = 1500 + k as u64;
            let (e, se) = albedo(&p.into(), wo, IMP, n, seed);
            assert!(e.x <= 1.0 + 4.0 * se.x, "a={a} wo {wo}: {e} ± {se}");
            let theta = wo.z.abs().acos().to_degrees();
            if a == 0.05 && theta <= 60.5 {
                let want = plastic_albedo(&smooth, wo).x;
                assert!(
                    (e.x - want).abs() <= 0.05 + 4.0 * se.x,
                    "wo {wo}: {e} vs smooth {want}"
                );
            }
        }
    }
}

#[test]
fn coating_table_is_mitsubas_quadrature() {
    // Normal incidence through a nearly smooth coating transmits 1 - F(1) = 0.96 at index 1.5;
    // grazing, nothing; internal reflectance near the smooth F_dr(1/1.5) = 0.596.
    let t = CoatingTable::shared(1e-3, 1.5);
    assert!(
        (t.transmittance[COATING_RES - 1] - 0.96).abs() < 1e-4,
        "{t:?}"
    );
    assert!(t.transmittance[0] < t.transmittance[COATING_RES / 2]);
    assert!((t.internal_reflectance - 0.596).abs() < 0.02, "{t:?}");
    assert!(
        std::ptr::eq(t, CoatingTable::shared(1e-3, 1.5)),
        "computed once"
    );
    // Monotone in the cosine and below 1 - F at each.
    for (i, w) in t.transmittance.windows(2).enumerate() {
        assert!(w[1] >= w[0] - 1e-6, "{i}: {w:?}");
    }
}

// --- Chi-square -------------------------------------------------------------------------

#[test]
fn plastic_sampling_passes_chi2() {
    // The non-delta samples against `pdf` (the diffuse lobe times its probability); the
    // specular ones are the missing mass, which the test's totals account for.
    let wo_list = [
        dir(0.0, 0.0),
        dir(50.0, 30.0),
        dir(85.0, 200.0),
        dir(120.0, 10.0),
    ];
    let b: Bsdf = plastic().into();
    for (k, wo) in wo_list.into_iter().enumerate() {
        chi2_test_sidak(
            wo_list.len() as u32,
            51,
            100,
            200_000,
            1600 + k as u64,
            |rng| {
                b.sample(wo, rng.uniform(), rng.uniform2(), RAD)
                    .filter(|s| !s.is_specular())
                    .map(|s| s.wi)
            },
            |wi| b.pdf(wo, wi) as f64,
        )
        .unwrap_or_else(|e| panic!("wo {wo}: {e}"));
    }
}
