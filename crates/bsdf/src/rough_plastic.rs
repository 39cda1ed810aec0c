//! Rough plastic: a diffuse base under a GGX dielectric coating, Mitsuba 3's `roughplastic`
//! with `distribution = "ggx"` (its default is Beckmann, which this renderer does not have).

use crate::microfacet::TrowbridgeReitz;
use crate::optics::{fresnel_dielectric, reflect, refract};
use crate::plastic::{coating_probability, internal_albedo, specular_weight, upper};
use crate::{BsdfSample, DiffuseLobe, Flags, same_hemisphere};
use glam::Vec3;
use math::warp::sample_cosine_hemisphere;
use std::f32::consts::FRAC_1_PI;
use std::sync::{Mutex, OnceLock};

/// Entries of the transmittance table over `cos θ` (Mitsuba's `MI_ROUGH_TRANSMITTANCE_RES`).
pub const COATING_RES: usize = 64;

/// What the coating lets through, precomputed per (`alpha`, `eta`) exactly as Mitsuba 3's
/// `roughplastic` does in `parameters_changed`, so values agree with it to rounding.
#[derive(Clone, Debug, PartialEq)]
pub struct CoatingTable {
    /// Fraction of light arriving from outside at `cos θ = i / 63` (the first entry at
    /// `1e-6`) that the rough interface transmits, single-scattering: `E[G1(wt) (1 - F)]` over
    /// visible normals, `wt` the refracted direction (zero unless it points inside).
    pub transmittance: [f32; COATING_RES],
    /// Fraction of diffuse light from inside the coating reflected back in: twice the mean of
    /// `R(μ) μ` over the table's cosines, `R` the rough interface's reflectance from inside.
    pub internal_reflectance: f32,
    /// Cosine-weighted mean of [`CoatingTable::transmittance`], `2 ∫ t(μ) μ dμ` (what photon
    /// estimates put in place of the incident light's own transmittance).
    pub diffuse_transmittance: f32,
}

/// Gauss-Legendre nodes and weights on [-1, 1] (Newton on the Legendre polynomial from
/// Chebyshev guesses, in f64: Mitsuba 3's `quad::gauss_legendre`; Press et al., *Numerical
/// Recipes* 3rd ed., §4.6).
fn gauss_legendre(n: usize) -> (Vec<f64>, Vec<f64>) {
    let legendre = |x: f64| {
        // P_n(x) and P_n'(x) by the three-term recurrence.
        let (mut p0, mut p1) = (1.0, x);
        for k in 2..=n {
            let p2 = ((2 * k - 1) as f64 * x * p1 - (k - 1) as f64 * p0) / k as f64;
            (p0, p1) = (p1, p2);
        }
        (p1, n as f64 * (x * p1 - p0) / (x * x - 1.0))
    };
    let (mut nodes, mut weights) = (vec![0.0; n], vec![0.0; n]);
    for i in 0..n.div_ceil(2) {
        let mut x = -((2 * i + 1) as f64 / (2 * n) as f64 * std::f64::consts::PI).cos();
        for _ in 0..100 {
            let (p, dp) = legendre(x);
            let step = p / dp;
            x -= step;
            if step.abs() <= 4.0 * x.abs() * f64::EPSILON {
                break;
            }
        }
        let (_, dp) = legendre(x);
        let w = 2.0 / ((1.0 - x * x) * dp * dp);
        (nodes[i], nodes[n - 1 - i]) = (x, -x);
        (weights[i], weights[n - 1 - i]) = (w, w);
    }
    (nodes, weights)
}

/// Mitsuba 3's `eval_transmittance` (`reflect` false) or `eval_reflectance` (true): the mean
/// over visible normals of `wi` of `G1(wo) (1 - F)` or `G1(wo) F`, `wo` refracted or reflected
/// there, by a tensor Gauss-Legendre rule on the sample square (32 points per side for
/// `eta > 1`, 128 otherwise, as Mitsuba). Normals come from [`TrowbridgeReitz::sample_visible`],
/// Mitsuba's map mirrored across the plane of incidence; Gauss-Legendre nodes are symmetric,
/// so the sums hold the same terms.
fn coating_integral(mf: &TrowbridgeReitz, wi: Vec3, eta: f32, reflect_in: bool) -> f32 {
    let res = if eta > 1.0 { 32 } else { 128 };
    let (nodes, weights) = gauss_legendre(res);
    let (nodes, weights): (Vec<f32>, Vec<f32>) = (
        nodes.iter().map(|&x| x as f32).collect(),
        weights.iter().map(|&w| w as f32).collect(),
    );
    // In f32 and in Mitsuba's order (x fastest), so the sum rounds as Mitsuba's does: the
    // node mirrored in x stands in for Mitsuba's (see above), hence x runs backwards.
    let mut sum = 0.0f32;
    for (y, wy) in nodes.iter().zip(&weights) {
        for (x, wx) in nodes.iter().zip(&weights).rev() {
            let u = [-x * 0.5 + 0.5, y * 0.5 + 0.5];
            let m = mf.sample_visible(wi, u);
            let f = fresnel_dielectric(wi.dot(m), eta);
            let term = if reflect_in {
                let wo = reflect(wi, m);
                if wo.z <= 0.0 || wi.z <= 0.0 {
                    0.0
                } else {
                    mf.g1(wo, m) * f
                }
            } else {
                match refract(wi, m, eta) {
                    Some((wo, _)) if wo.z * wi.z < 0.0 => mf.g1(wo, m) * (1.0 - f),
                    _ => 0.0,
                }
            };
            sum += term * (wx * wy) * 0.25;
        }
    }
    sum
}

impl CoatingTable {
    /// The table of a GGX coating of roughness `alpha` (clamped as everywhere) and relative
    /// index `eta`.
    pub fn compute(alpha: f32, eta: f32) -> CoatingTable {
        let mf = TrowbridgeReitz::new(alpha);
        let mu = |i: usize| (i as f32 * (1.0 / (COATING_RES - 1) as f32)).max(1e-6);
        let dir = |mu: f32| Vec3::new((1.0 - mu * mu).sqrt(), 0.0, mu);
        let mut transmittance = [0.0; COATING_RES];
        let mut reflectance = 0.0f64;
        for (i, t) in transmittance.iter_mut().enumerate() {
            let wi = dir(mu(i));
            *t = coating_integral(&mf, wi, eta, false);
            reflectance += (coating_integral(&mf, wi, 1.0 / eta, true) * mu(i)) as f64;
        }
        let internal_reflectance = (2.0 * reflectance / COATING_RES as f64) as f32;
        let mut table = CoatingTable {
            transmittance,
            internal_reflectance,
            diffuse_transmittance: 0.0,
        };
        // 2 ∫ t(μ) μ dμ of the interpolated table, by the midpoint rule on a fine grid.
        let n = 4096;
        let s: f64 = (0..n)
            .map(|k| {
                let mu = (k as f32 + 0.5) / n as f32;
                (table.at(mu) * mu) as f64
            })
            .sum();
        table.diffuse_transmittance = (2.0 * s / n as f64) as f32;
        table
    }

    /// The transmittance at `cos θ`, linearly interpolated as Mitsuba's `lerp_gather` does
    /// (treating the table as evenly spaced from 0 to 1).
    #[inline]
    pub fn at(&self, cos_theta: f32) -> f32 {
        let x = cos_theta * (COATING_RES - 1) as f32;
        let i = (x.max(0.0) as usize).min(COATING_RES - 2);
        let (v0, v1) = (self.transmittance[i], self.transmittance[i + 1]);
        v0 + (v1 - v0) * (x - i as f32)
    }

    /// The table of (`alpha`, `eta`), computed on first use and kept for the process: a scene
    /// has a handful of rough plastics, and a [`crate::Bsdf`] stays `Copy` by holding a
    /// reference.
    pub fn shared(alpha: f32, eta: f32) -> &'static CoatingTable {
        type Tables = Vec<((u32, u32), &'static CoatingTable)>;
        static TABLES: OnceLock<Mutex<Tables>> = OnceLock::new();
        let key = (alpha.to_bits(), eta.to_bits());
        let tables = TABLES.get_or_init(|| Mutex::new(Vec::new()));
        if let Some(&(_, t)) = tables
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .iter()
            .find(|(k, _)| *k == key)
        {
            return t;
        }
        // Computed outside the lock; two threads racing keep one and leak the other's copy.
        let table: &'static CoatingTable = Box::leak(Box::new(CoatingTable::compute(alpha, eta)));
        let mut tables = tables.lock().unwrap_or_else(|e| e.into_inner());
        if let Some(&(_, t)) = tables.iter().find(|(k, _)| *k == key) {
            return t;
        }
        tables.push((key, table));
        table
    }
}

/// A Lambertian base of reflectance `diffuse` under a GGX coating of roughness `alpha` and
/// relative index `eta` (Mitsuba 3's `roughplastic`):
///
/// - glossy: `F(wo·wm) D G / (4 cos θo cos θi) · specular`, the rough dielectric's reflection
///   ([`crate::RoughDielectric`]);
/// - diffuse: `t(cos θo) t(cos θi) ρ' / (π η²)`, `t` the coating's transmittance from
///   [`CoatingTable`] and `ρ'` the base's albedo with the internal bounces summed against the
///   table's internal reflectance, as [`crate::Plastic`] does with `F_dr`.
///
/// Sampling picks the glossy lobe with probability `(1 - t) w / ((1 - t) w + t (1 - w))` at
/// `wo`, `w` the specular sampling weight, and draws visible normals there; the pdf is the
/// mixture. Two-sided like [`crate::Plastic`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RoughPlastic {
    pub diffuse: Vec3,
    pub specular: Vec3,
    pub eta: f32,
    pub alpha: f32,
    pub nonlinear: bool,
    pub specular_weight: f32,
    pub table: &'static CoatingTable,
}

impl RoughPlastic {
    pub fn new(
        diffuse: Vec3,
        specular: Vec3,
        eta: f32,
        alpha: f32,
        nonlinear: bool,
    ) -> RoughPlastic {
        let alpha = TrowbridgeReitz::new(alpha).alpha_x;
        RoughPlastic {
            diffuse,
            specular,
            eta,
            alpha,
            nonlinear,
            specular_weight: specular_weight(diffuse, specular),
            table: CoatingTable::shared(alpha, eta),
        }
    }

    #[inline]
    pub(crate) fn distribution(&self) -> TrowbridgeReitz {
        TrowbridgeReitz::new(self.alpha)
    }

    /// Probability that [`RoughPlastic::sample`] draws from the glossy lobe at `wo`.
    #[inline]
    pub fn specular_probability(&self, wo: Vec3) -> f32 {
        coating_probability(1.0 - self.table.at(wo.z.abs()), self.specular_weight)
    }

    /// The two lobes' values for directions on the upper side.
    fn lobes(&self, wo: Vec3, wi: Vec3) -> (Vec3, Vec3) {
        let mf = self.distribution();
        let spec = match (wo + wi).try_normalize() {
            Some(h) => {
                let f = fresnel_dielectric(wo.dot(h), self.eta);
                self.specular * (f * mf.d(h) * mf.g(wo, wi, h) / (4.0 * wo.z * wi.z))
            }
            None => Vec3::ZERO,
        };
        let t = self.table.at(wo.z) * self.table.at(wi.z);
        let diff = internal_albedo(
            self.diffuse,
            self.table.internal_reflectance,
            self.nonlinear,
        ) * (t * FRAC_1_PI / (self.eta * self.eta));
        (spec, diff)
    }

    /// The two lobes' densities, each times its probability.
    fn lobe_pdfs(&self, wo: Vec3, wi: Vec3) -> (f32, f32) {
        let ps = self.specular_probability(wo);
        let spec = match (wo + wi).try_normalize() {
            Some(h) => {
                let mf = self.distribution();
                mf.d(h) * mf.g1(wo, h) / (4.0 * wo.z)
            }
            None => 0.0,
        };
        (ps * spec, (1.0 - ps) * wi.z * FRAC_1_PI)
    }

    pub fn f(&self, wo: Vec3, wi: Vec3) -> Vec3 {
        if !same_hemisphere(wo, wi) {
            return Vec3::ZERO;
        }
        let (s, d) = self.lobes(upper(wo), upper(wi));
        s + d
    }

    pub fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        if !same_hemisphere(wo, wi) {
            return 0.0;
        }
        let (s, d) = self.lobe_pdfs(upper(wo), upper(wi));
        s + d
    }

    /// The direction from `uc` (the lobe) and `u`, on the upper side, and whether it came
    /// from the diffuse lobe; `None` when the glossy lobe sends it below the surface.
    fn direction(&self, wo: Vec3, uc: f32, u: [f32; 2]) -> Option<(Vec3, bool)> {
        if uc < self.specular_probability(wo) {
            let m = self.distribution().sample_visible(wo, u);
            let wi = reflect(wo, m);
            (wi.z > 0.0).then_some((wi, false))
        } else {
            Some((sample_cosine_hemisphere(u), true))
        }
    }

    /// `uc` picks the lobe; the sample carries the whole `f` and the mixture pdf (Mitsuba's
    /// `sample`), so its weight is the one-sample MIS estimate over both lobes.
    pub fn sample(&self, wo: Vec3, uc: f32, u: [f32; 2]) -> Option<BsdfSample> {
        let below = wo.z < 0.0;
        let up = upper(wo);
        let (mut wi, diffuse) = self.direction(up, uc, u)?;
        let (s, d) = self.lobes(up, wi);
        let (ps, pd) = self.lobe_pdfs(up, wi);
        let (f, pdf) = (s + d, ps + pd);
        if !(pdf > 0.0 && pdf.is_finite() && f.is_finite()) {
            return None;
        }
        if below {
            wi.z = -wi.z;
        }
        Some(BsdfSample {
            f,
            wi,
            pdf,
            flags: if diffuse {
                Flags::DIFFUSE_REFLECTION
            } else {
                Flags::GLOSSY_REFLECTION
            },
            eta: 1.0,
        })
    }

    /// One lobe, weighted by it alone (as [`crate::Glossy::sample_lobe`]): `f` is the lobe's,
    /// `pdf` its density times the probability of picking it; the flag is true for the
    /// diffuse lobe.
    pub fn sample_lobe(&self, wo: Vec3, uc: f32, u: [f32; 2]) -> Option<(BsdfSample, bool)> {
        let below = wo.z < 0.0;
        let up = upper(wo);
        let (mut wi, diffuse) = self.direction(up, uc, u)?;
        let (s, d) = self.lobes(up, wi);
        let (ps, pd) = self.lobe_pdfs(up, wi);
        let (f, pdf) = if diffuse { (d, pd) } else { (s, ps) };
        if !(pdf > 0.0 && pdf.is_finite() && f.is_finite()) {
            return None;
        }
        if below {
            wi.z = -wi.z;
        }
        let flags = if diffuse {
            Flags::DIFFUSE_REFLECTION
        } else {
            Flags::GLOSSY_REFLECTION
        };
        Some((
            BsdfSample {
                f,
                wi,
                pdf,
                flags,
                eta: 1.0,
            },
            diffuse,
        ))
    }

    /// The diffuse lobe as photon estimates read it: albedo `t(cos θo) t̄ ρ' / η²`, the
    /// incident light's transmittance replaced by its cosine-weighted mean `t̄`
    /// ([`CoatingTable::diffuse_transmittance`]), chosen with the sampling's probability; the
    /// glossy coating (this model with a black base) is the rest.
    pub fn diffuse_lobe(&self, wo: Vec3) -> DiffuseLobe {
        let albedo = internal_albedo(
            self.diffuse,
            self.table.internal_reflectance,
            self.nonlinear,
        ) * (self.table.at(wo.z.abs()) * self.table.diffuse_transmittance
            / (self.eta * self.eta));
        DiffuseLobe {
            albedo,
            probability: 1.0 - self.specular_probability(wo),
            rest: Some(self.coating().into()),
        }
    }

    /// The glossy coating alone: this model with a black base, which always samples it.
    pub fn coating(&self) -> RoughPlastic {
        RoughPlastic {
            diffuse: Vec3::ZERO,
            specular_weight: 1.0,
            ..*self
        }
    }
}
