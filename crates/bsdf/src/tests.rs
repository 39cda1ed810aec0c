//! Order (Mitsuba 3 / pbrt-v4 habit): construct → eval/pdf against closed forms → optics →
//! energy → chi-square of the sampling.

use crate::optics::fresnel_dielectric_polarized;
use crate::*;
use glam::{DVec3, Vec3};
use math::Rng;
use math::chi2::chi2_test_sidak;
use std::f32::consts::{FRAC_1_PI, PI};

mod microfacet;
mod plastic;

const RAD: TransportMode = TransportMode::Radiance;
const IMP: TransportMode = TransportMode::Importance;

/// Local direction from polar and azimuth angles in degrees.
fn dir(theta_deg: f32, phi_deg: f32) -> Vec3 {
    let (t, p) = (theta_deg.to_radians(), phi_deg.to_radians());
    Vec3::new(t.sin() * p.cos(), t.sin() * p.sin(), t.cos())
}

/// Outgoing directions from both sides, normal to near-grazing.
fn wos() -> Vec<Vec3> {
    let mut v = Vec::new();
    for (i, th) in [0.5f32, 10.0, 30.0, 45.0, 60.0, 75.0, 85.0, 89.0]
        .into_iter()
        .enumerate()
    {
        let phi = 37.0 * i as f32;
        v.push(dir(th, phi));
        v.push(dir(180.0 - th, phi + 90.0));
    }
    v
}

fn glass() -> Bsdf {
    Dielectric::clear(1.5).into()
}

fn all_models() -> Vec<(&'static str, Bsdf)> {
    vec![
        (
            "lambertian",
            Lambertian {
                albedo: Vec3::new(0.8, 0.5, 0.2),
            }
            .into(),
        ),
        (
            "mirror",
            Mirror {
                reflectance: Vec3::new(0.9, 0.9, 0.7),
            }
            .into(),
        ),
        (
            "metal",
            Metal {
                reflectance: Vec3::new(0.6, 0.7, 0.8),
            }
            .into(),
        ),
        ("conductor", gold()),
        ("dielectric", glass()),
        (
            "tinted conductor",
            Conductor {
                reflectance: Vec3::new(0.9, 0.5, 0.7),
                ..gold_conductor()
            }
            .into(),
        ),
        ("thin dielectric", ThinDielectric::clear(1.5).into()),
        (
            "tinted thin dielectric",
            ThinDielectric {
                eta: 1.33,
                reflectance: Vec3::new(0.9, 0.8, 0.7),
                transmittance: Vec3::new(0.2, 0.5, 0.9),
            }
            .into(),
        ),
    ]
}

/// A commonly quoted RGB fit of gold's complex index; any absorbing metal would do here.
fn gold() -> Bsdf {
    gold_conductor().into()
}

fn gold_conductor() -> Conductor {
    Conductor {
        eta: Vec3::new(0.143, 0.374, 1.442),
        k: Vec3::new(3.983, 2.385, 1.603),
        reflectance: Vec3::ONE,
    }
}

// --- Construction -----------------------------------------------------------------------

#[test]
fn constructors_classify_their_lobes() {
    let kinds: Vec<(bool, bool, bool)> = all_models()
        .iter()
        .map(|(_, b)| (b.is_delta(), b.is_diffuse(), b.has_transmission()))
        .collect();
    assert_eq!(
        kinds,
        [
            (false, true, false),
            (true, false, false),
            (true, false, false),
            (true, false, false),
            (true, false, true),
            (true, false, false),
            (true, false, true),
            (true, false, true),
        ]
    );
    let f = Flags::REFLECTION | Flags::SPECULAR;
    assert_eq!(f, Flags::SPECULAR_REFLECTION);
    assert!(f.is_specular() && f.is_reflection() && !f.is_transmission() && !f.is_diffuse());
    assert!(Flags::DIFFUSE_REFLECTION.is_diffuse());
    assert!(Flags::SPECULAR_TRANSMISSION.is_transmission());
}

// --- Evaluation against closed forms ----------------------------------------------------

#[test]
fn lambertian_f_and_pdf_match_closed_forms() {
    let albedo = Vec3::new(0.8, 0.5, 0.2);
    let b: Bsdf = Lambertian { albedo }.into();
    for wo in wos() {
        for wi in wos() {
            let same = wo.z * wi.z > 0.0;
            let (f, pdf) = (b.f(wo, wi, RAD), b.pdf(wo, wi));
            if same {
                assert!(f.distance(albedo * FRAC_1_PI) < 1e-7, "{wo} {wi}");
                assert!((pdf - wi.z.abs() / PI).abs() < 1e-7, "{wo} {wi}");
            } else {
                assert_eq!((f, pdf), (Vec3::ZERO, 0.0), "{wo} {wi}: transmits");
            }
            assert_eq!(f, b.f(wo, wi, IMP), "diffuse reflection ignores the mode");
        }
    }
    // Grazing wo: no hemisphere, nothing scatters.
    assert_eq!(b.f(Vec3::X, Vec3::Z, RAD), Vec3::ZERO);
    assert!(b.sample(Vec3::X, 0.5, [0.3, 0.3], RAD).is_none());
}

#[test]
fn lambertian_is_reciprocal() {
    let b: Bsdf = Lambertian {
        albedo: Vec3::splat(0.7),
    }
    .into();
    for wo in wos() {
        for wi in wos() {
            assert_eq!(b.f(wo, wi, RAD), b.f(wi, wo, RAD), "{wo} {wi}");
        }
    }
}

#[test]
fn lambertian_samples_agree_with_f_and_pdf() {
    let b: Bsdf = Lambertian {
        albedo: Vec3::new(0.8, 0.5, 0.2),
    }
    .into();
    let mut rng = Rng::new(31);
    for wo in wos() {
        for _ in 0..1000 {
            let s = b.sample(wo, rng.uniform(), rng.uniform2(), RAD).unwrap();
            assert!(s.wi.z * wo.z > 0.0 && (s.wi.length() - 1.0).abs() < 1e-5);
            assert!(s.f.distance(b.f(wo, s.wi, RAD)) < 1e-7);
            assert!((s.pdf - b.pdf(wo, s.wi)).abs() < 1e-6);
            assert_eq!((s.flags, s.eta), (Flags::DIFFUSE_REFLECTION, 1.0));
        }
    }
}

#[test]
fn delta_bsdfs_evaluate_to_zero_even_in_the_mirror_direction() {
    for (name, b) in all_models().into_iter().filter(|(_, b)| b.is_delta()) {
        for wo in wos() {
            let mirror = Vec3::new(-wo.x, -wo.y, wo.z);
            assert_eq!(b.f(wo, mirror, RAD), Vec3::ZERO, "{name}");
            assert_eq!(b.pdf(wo, mirror), 0.0, "{name}");
        }
    }
}

#[test]
fn specular_reflectors_reflect_about_the_normal_with_pdf_one() {
    for (name, b) in all_models() {
        if b.is_diffuse() || b.has_transmission() {
            continue;
        }
        for wo in wos() {
            let s = b.sample(wo, 0.5, [0.5, 0.5], RAD).unwrap();
            assert!(s.wi.distance(reflect(wo, Vec3::Z)) < 1e-6, "{name}");
            assert_eq!(
                (s.pdf, s.flags, s.eta),
                (1.0, Flags::SPECULAR_REFLECTION, 1.0)
            );
            assert!(s.is_specular() && s.is_reflection());
        }
    }
}

// --- Optics -----------------------------------------------------------------------------

/// Transmittances `(T_s, T_p)` from the Fresnel *transmission* amplitudes (Hecht, Optics
/// §4.6.2): `T = (η cos θt / cos θi) t²`. Independent of the reflection formulas, so
/// `R + T = 1` is a real check of energy conservation, not a tautology.
fn transmittance(cos_i: f32, eta: f32) -> (f32, f32) {
    let (ci, eta) = if cos_i < 0.0 {
        (-cos_i, 1.0 / eta)
    } else {
        (cos_i, eta)
    };
    let sin2_t = (1.0 - ci * ci) / (eta * eta);
    if sin2_t >= 1.0 {
        return (0.0, 0.0);
    }
    let ct = (1.0 - sin2_t).sqrt();
    let ts = 2.0 * ci / (ci + eta * ct);
    let tp = 2.0 * ci / (eta * ci + ct);
    let k = eta * ct / ci;
    (k * ts * ts, k * tp * tp)
}

#[test]
fn fresnel_conserves_energy_from_both_sides() {
    for eta in [1.33f32, 1.5, 2.4, 1.0 / 1.5] {
        let critical = if eta < 1.0 {
            eta.asin()
        } else {
            (1.0 / eta).asin()
        };
        for i in 1..1000 {
            let cos = i as f32 / 1000.0;
            for c in [cos, -cos] {
                let (rs, rp) = fresnel_dielectric_polarized(c, eta);
                let (ts, tp) = transmittance(c, eta);
                assert!(
                    (rs + ts - 1.0).abs() < 1e-5,
                    "eta {eta}, cos {c}: s {rs} + {ts}"
                );
                assert!(
                    (rp + tp - 1.0).abs() < 1e-5,
                    "eta {eta}, cos {c}: p {rp} + {tp}"
                );
                // From the dense side beyond the critical angle: total internal reflection.
                let inside_dense = (c > 0.0) == (eta < 1.0);
                if inside_dense && cos.acos() > critical + 1e-4 {
                    assert_eq!(fresnel_dielectric(c, eta), 1.0, "eta {eta}, cos {c}");
                }
            }
        }
    }
}

#[test]
fn fresnel_at_normal_incidence_is_four_percent_for_glass() {
    // ((1 - 1.5) / (1 + 1.5))^2 = 0.04, the same from either side.
    assert!((fresnel_dielectric(1.0, 1.5) - 0.04).abs() < 1e-7);
    assert!((fresnel_dielectric(-1.0, 1.5) - 0.04).abs() < 1e-7);
    assert!(
        fresnel_dielectric(0.7, 1.0).abs() < 1e-7,
        "index-matched: no reflection"
    );
    assert_eq!(
        fresnel_dielectric(0.0, 1.5),
        1.0,
        "grazing: total reflection"
    );
}

#[test]
fn fresnel_polarised_terms_match_brewster_and_45_degrees() {
    // Brewster: tan θB = n2/n1 makes R_p vanish, from outside (1.5) and inside (1/1.5).
    for (cos_b, eta) in [
        (1.5f32.atan().cos(), 1.5),
        (-(1.0f32 / 1.5).atan().cos(), 1.5),
    ] {
        let (rs, rp) = fresnel_dielectric_polarized(cos_b, eta);
        assert!(rp < 1e-9 && rs > 0.01, "Brewster: {rs} {rp}");
    }
    // 45° onto glass, by hand: sin θt = 0.7071/1.5, cos θt = 0.881917; R_s = 0.0920134,
    // R_p = 0.0084665, and R_p = R_s^2 at 45° exactly (Abelès 1950).
    let (rs, rp) = fresnel_dielectric_polarized(std::f32::consts::FRAC_1_SQRT_2, 1.5);
    assert!((rs - 0.092_013_36).abs() < 1e-6, "{rs}");
    assert!((rp - 0.008_466_459).abs() < 1e-6, "{rp}");
    assert!((rp - rs * rs).abs() < 1e-6);
    let r = fresnel_dielectric(std::f32::consts::FRAC_1_SQRT_2, 1.5);
    assert!((r - 0.050_239_91).abs() < 1e-6, "{r}");
}

#[test]
fn fresnel_is_the_same_both_ways_through_the_interface() {
    // Stokes relations: the reflectance seen from the refracted side, at the refracted
    // angle, is the same (Hecht §4.10).
    for i in 1..100 {
        let cos_i = i as f32 / 100.0;
        let sin_t = (1.0 - cos_i as f64 * cos_i as f64).sqrt() / 1.5;
        let cos_t = (1.0 - sin_t * sin_t).sqrt() as f32;
        let (a, b) = (
            fresnel_dielectric(cos_i, 1.5),
            fresnel_dielectric(-cos_t, 1.5),
        );
        // Near grazing, cos θt sits near the critical angle where R's slope is unbounded:
        // rounding cos θt to f32 alone moves R by ~1e-4 there.
        let tol = if cos_i < 0.1 { 2e-4 } else { 1e-5 };
        assert!((a - b).abs() < tol, "cos {cos_i}: {a} vs {b}");
    }
}

#[test]
fn conductor_fresnel_matches_closed_forms() {
    let (eta, k) = (Vec3::new(0.2, 1.1, 2.5), Vec3::new(3.0, 2.0, 0.5));
    // Normal incidence: R = ((n - 1)^2 + k^2) / ((n + 1)^2 + k^2).
    let want = ((eta - 1.0).powf(2.0) + k * k) / ((eta + 1.0).powf(2.0) + k * k);
    assert!(fresnel_conductor(1.0, eta, k).distance(want) < 1e-6);
    // Grazing incidence reflects everything.
    assert!(fresnel_conductor(0.0, eta, k).distance(Vec3::ONE) < 1e-6);
    // k = 0 is a dielectric seen from outside.
    for i in 1..=20 {
        let c = i as f32 / 20.0;
        let r = fresnel_conductor(c, Vec3::splat(1.5), Vec3::ZERO);
        assert!((r.x - fresnel_dielectric(c, 1.5)).abs() < 1e-6, "cos {c}");
    }
    // Bounded by [0, 1] at all angles.
    for i in 0..=100 {
        let r = fresnel_conductor(i as f32 / 100.0, eta, k);
        assert!(
            r.min_element() >= 0.0 && r.max_element() <= 1.0 + 1e-6,
            "{r}"
        );
    }
}

#[test]
fn refract_obeys_snell_about_any_normal() {
    let n = Vec3::new(1.0, 2.0, 3.0).normalize();
    let mut rng = Rng::new(32);
    let mut tir = 0;
    for _ in 0..10_000 {
        let wi = math::warp::sample_uniform_sphere(rng.uniform2());
        let eta = 1.5;
        match refract(wi, n, eta) {
            Some((wt, etap)) => {
                // Snell in vector form: wi × n = -η' (wt × n); wt on the far side, unit.
                let e = wi.cross(n) + etap * wt.cross(n);
                assert!(e.length() < 1e-5, "{wi} -> {wt}: {e}");
                assert!(wi.dot(n) * wt.dot(n) < 0.0 && (wt.length() - 1.0).abs() < 1e-5);
                assert_eq!(etap, if wi.dot(n) > 0.0 { eta } else { 1.0 / eta });
            }
            None => {
                tir += 1;
                assert_eq!(fresnel_dielectric(wi.dot(n), eta), 1.0, "{wi}");
            }
        }
        let r = reflect(wi, n);
        assert!((r.dot(n) - wi.dot(n)).abs() < 1e-6 && (r + wi).cross(n).length() < 1e-6);
    }
    assert!(
        tir > 0,
        "some inside directions lie beyond the critical angle"
    );
}

#[test]
fn dielectric_transmission_obeys_snell() {
    let b = glass();
    for wo in wos() {
        // uc close to 1 picks transmission whenever T > 0.
        let Some(s) = b.sample(wo, 0.999_999, [0.5, 0.5], RAD) else {
            panic!("{wo}: no sample");
        };
        if !s.is_transmission() {
            assert_eq!(
                fresnel_dielectric(wo.z, 1.5),
                1.0,
                "{wo}: reflected with T > 0"
            );
            continue;
        }
        let sin = |w: Vec3| (w.x * w.x + w.y * w.y).sqrt();
        assert!(
            (sin(wo) - s.eta * sin(s.wi)).abs() < 1e-5,
            "{wo} -> {}",
            s.wi
        );
        assert!(wo.z * s.wi.z < 0.0, "crosses the surface");
        // Azimuth turns by 180°: the plane of incidence is kept.
        assert!(wo.truncate().perp_dot(s.wi.truncate()).abs() < 1e-5);
        assert!(wo.truncate().dot(s.wi.truncate()) <= 1e-6);
        assert_eq!(s.eta, if wo.z > 0.0 { 1.5 } else { 1.0 / 1.5 });
    }
}

#[test]
fn transport_modes_differ_only_by_radiance_compression() {
    let b = glass();
    for wo in wos() {
        let (r, i) = (
            b.sample(wo, 0.999_999, [0.0; 2], RAD).unwrap(),
            b.sample(wo, 0.999_999, [0.0; 2], IMP).unwrap(),
        );
        assert_eq!((r.wi, r.pdf, r.flags), (i.wi, i.pdf, i.flags));
        let scale = if r.is_transmission() {
            1.0 / (r.eta * r.eta)
        } else {
            1.0
        };
        assert!(r.f.distance(i.f * scale) < 1e-6 * i.f.length(), "{wo}");
    }
}

// --- Energy -----------------------------------------------------------------------------

/// Monte-Carlo albedo `E[f |cos θi| / pdf]` for one `wo`, and its standard error.
fn albedo(b: &Bsdf, wo: Vec3, mode: TransportMode, n: usize, seed: u64) -> (Vec3, Vec3) {
    // f64 sums: 2e4 f32 additions drift by ~1e-4, more than a delta lobe's exact answer allows.
    let mut rng = Rng::new(seed);
    let (mut s, mut s2) = (DVec3::ZERO, DVec3::ZERO);
    for _ in 0..n {
        if let Some(x) = b.sample(wo, rng.uniform(), rng.uniform2(), mode) {
            let w = x.weight().as_dvec3();
            s += w;
            s2 += w * w;
        }
    }
    let mean = s / n as f64;
    let var = (s2 / n as f64 - mean * mean).max(DVec3::ZERO);
    (mean.as_vec3(), (var / n as f64).powf(0.5).as_vec3())
}

#[test]
fn albedos_match_known_values_and_never_exceed_one() {
    let n = 20_000;
    for (name, b) in all_models() {
        for (k, wo) in wos().into_iter().enumerate() {
            let seed = 100 + k as u64;
            let (a, se) = albedo(&b, wo, IMP, n, seed);
            // Photons carry flux: no model may create energy.
            assert!(
                a.max_element() <= 1.0 + 1e-4,
                "{name}, wo {wo}, seed {seed}: {a}"
            );
            let want = match b {
                Bsdf::Lambertian(l) => l.albedo,
                Bsdf::Mirror(m) => m.reflectance,
                Bsdf::Metal(m) => m.reflectance,
                Bsdf::Conductor(c) => c.reflectance * fresnel_conductor(wo.z, c.eta, c.k),
                // Every sample carries exactly 1: R or T cancels against its probability.
                Bsdf::Dielectric(_) => Vec3::ONE,
                // Each lobe carries its factor: R' reflectance + T' transmittance.
                Bsdf::ThinDielectric(t) => {
                    let r = t.reflectance_at(wo.z);
                    r * t.reflectance + (1.0 - r) * t.transmittance
                }
                // The GGX models have their own furnace tests (`microfacet`).
                _ => unreachable!("{name} is not in all_models"),
            };
            let tol = 5.0 * se.max_element() + 1e-5;
            assert!(
                a.distance(want) <= tol,
                "{name}, wo {wo}, seed {seed}: {a} vs {want}"
            );
        }
    }
}

#[test]
fn dielectric_radiance_albedo_includes_the_eta_squared_factor() {
    // Radiance mode: E = R + T / η'^2 (pbrt-v4 §9.5.2); can exceed 1 leaving glass, which is
    // why photons use Importance mode.
    let b = glass();
    for (k, wo) in wos().into_iter().enumerate() {
        let seed = 200 + k as u64;
        let r = fresnel_dielectric(wo.z, 1.5);
        let etap: f32 = if wo.z > 0.0 { 1.5 } else { 1.0 / 1.5 };
        let want = r + (1.0 - r) / (etap * etap);
        let (a, se) = albedo(&b, wo, RAD, 20_000, seed);
        assert!(
            (a.x - want).abs() <= 5.0 * se.x + 1e-5,
            "wo {wo}, seed {seed}: {a} vs {want}"
        );
    }
}

#[test]
fn dielectric_lobe_frequencies_match_fresnel() {
    // Reflection count ~ Binomial(n, R): allow 5 standard deviations (p ≈ 6e-7 per angle).
    let b = glass();
    let n = 20_000;
    for (k, wo) in wos().into_iter().enumerate() {
        let seed = 300 + k as u64;
        let mut rng = Rng::new(seed);
        let r = fresnel_dielectric(wo.z, 1.5) as f64;
        let mut reflected = 0usize;
        for _ in 0..n {
            let s = b.sample(wo, rng.uniform(), rng.uniform2(), IMP).unwrap();
            let want_pdf = if s.is_reflection() { r } else { 1.0 - r };
            assert!((s.pdf as f64 - want_pdf).abs() < 1e-6);
            reflected += s.is_reflection() as usize;
        }
        let sd = (n as f64 * r * (1.0 - r)).sqrt();
        let dev = (reflected as f64 - n as f64 * r).abs();
        assert!(
            dev <= 5.0 * sd + 0.5,
            "wo {wo}, seed {seed}: {reflected} / {n}, R = {r}"
        );
    }
}

// --- Chi-square -------------------------------------------------------------------------

#[test]
fn lambertian_sampling_passes_chi2() {
    let b: Bsdf = Lambertian {
        albedo: Vec3::splat(0.5),
    }
    .into();
    let wo_list = [
        dir(0.0, 0.0),
        dir(40.0, 30.0),
        dir(85.0, 200.0),
        dir(120.0, 10.0),
    ];
    for (k, wo) in wo_list.into_iter().enumerate() {
        let seed = 400 + k as u64;
        chi2_test_sidak(
            wo_list.len() as u32,
            51,
            101,
            200_000,
            seed,
            |rng| {
                b.sample(wo, rng.uniform(), rng.uniform2(), RAD)
                    .map(|s| s.wi)
            },
            |wi| b.pdf(wo, wi) as f64,
        )
        .unwrap_or_else(|e| panic!("wo {wo}: {e}"));
    }
}

#[test]
fn chi2_catches_a_forgotten_hemisphere_flip() {
    // The classic bug: sampling below the surface for wo.z < 0 but evaluating the pdf of the
    // upper hemisphere. The harness must reject it (and name the seed).
    let b: Bsdf = Lambertian {
        albedo: Vec3::splat(0.5),
    }
    .into();
    let wo = dir(120.0, 10.0);
    let err = chi2_test_sidak(
        1,
        51,
        101,
        50_000,
        500,
        |rng| {
            b.sample(wo, rng.uniform(), rng.uniform2(), RAD)
                .map(|s| s.wi)
        },
        |wi| math::warp::cosine_hemisphere_pdf(wi) as f64,
    )
    .unwrap_err();
    assert!(err.contains("seed 500"), "{err}");
}

// --- Coloured glass ---------------------------------------------------------------------

#[test]
fn dielectric_transmittance_scales_the_transmitted_lobe_only() {
    // Mitsuba 3's `specular_transmittance`: the refracted sample's value times τ, the
    // reflected one's and both lobe probabilities unchanged, from either side, in both modes.
    let tau = Vec3::new(0.9, 0.5, 0.1);
    let clear = Dielectric::clear(1.5);
    let tinted = Dielectric {
        eta: 1.5,
        transmittance: tau,
    };
    for wo in wos() {
        for mode in [RAD, IMP] {
            for uc in [0.0, 0.999_999] {
                let (a, b) = (clear.sample(wo, uc, mode), tinted.sample(wo, uc, mode));
                let (Some(a), Some(b)) = (a, b) else {
                    assert_eq!(a, b, "wo {wo}, uc {uc}");
                    continue;
                };
                assert_eq!((a.wi, a.pdf, a.flags, a.eta), (b.wi, b.pdf, b.flags, b.eta));
                let want = if a.is_transmission() { a.f * tau } else { a.f };
                assert_eq!(b.f, want, "wo {wo}, uc {uc}, {mode:?}");
                if a.is_transmission() {
                    // The throughput factor of a refraction is exactly τ (importance) or
                    // τ / η'² (radiance): the Fresnel weight cancels against the pdf.
                    let w = b.weight() * if mode == RAD { b.eta * b.eta } else { 1.0 };
                    assert!((w - tau).abs().max_element() < 1e-6, "wo {wo}: {w}");
                }
            }
        }
    }
}

#[test]
fn rough_dielectric_transmittance_scales_the_transmitted_lobe_only() {
    let tau = Vec3::new(0.9, 0.5, 0.1);
    let clear = RoughDielectric::clear(1.5, 0.3);
    let tinted = RoughDielectric {
        transmittance: tau,
        ..clear
    };
    let mut rng = Rng::new(77);
    let (mut seen_r, mut seen_t) = (0, 0);
    for wo in wos() {
        for _ in 0..64 {
            let (uc, u) = (rng.uniform(), rng.uniform2());
            let (a, b) = (clear.sample(wo, uc, u, RAD), tinted.sample(wo, uc, u, RAD));
            let (Some(a), Some(b)) = (a, b) else {
                assert_eq!(a, b);
                continue;
            };
            assert_eq!((a.wi, a.pdf, a.flags), (b.wi, b.pdf, b.flags));
            let want = if a.is_transmission() { a.f * tau } else { a.f };
            assert_eq!(b.f, want, "wo {wo}");
            assert_eq!(tinted.f(wo, a.wi, RAD), want);
            assert_eq!(tinted.pdf(wo, a.wi), clear.pdf(wo, a.wi));
            seen_r += a.is_reflection() as u32;
            seen_t += a.is_transmission() as u32;
        }
    }
    assert!(
        seen_r > 50 && seen_t > 50,
        "{seen_r} reflections, {seen_t} refractions"
    );
}
