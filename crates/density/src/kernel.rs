//! 2-D density-estimation kernels on the unit disc, t = |x - x_p| / r.
//!
//! Each kernel is a *shape* (unnormalised profile, zero for t > 1) times a *norm* making
//! `∫_disc K = 1`; the estimator evaluates the norm once per query and the shape per photon.
//! Constants (Silverman 1986, "Density Estimation", table 3.1, in 2-D; Jensen 2001 §7.2 for
//! the cone and Gaussian filters):
//!
//! | kernel | K(t), t <= 1 |
//! |---|---|
//! | uniform | 1/π |
//! | cone, slope k >= 1 (Jensen 2001 §7.2) | (1 − t/k) / ((1 − 2/(3k)) π) |
//! | Gaussian, Jensen's, renormalised | w(t) / (π I), I = 0.5311 |
//! | Gaussian, Jensen's original | w(t) / π (integrates to I: underestimates by 46.9%) |
//! | Epanechnikov | (2/π)(1 − t²) |
//! | Silverman 2nd order / biweight ("Simpson's") | (3/π)(1 − t²)² |
//! | triweight | (4/π)(1 − t²)³ |
//!
//! with Jensen's Gaussian weight (after Pavicic 1990) w(t) = α [1 − (1 − e^(−β t²/2)) /
//! (1 − e^(−β))], α = 0.918, β = 1.953. Garcia et al. 2014 ("Overestimation and
//! underestimation biases in photon mapping with non-constant kernels", IEEE TVCG 20(10))
//! show the original underestimates by 46.9%; we renormalise with the exact integral
//! I = α [1 − (1 − (2/β)(1 − e^(−β/2))) / (1 − e^(−β))] (substitute u = t²).
//!
//! The support is closed (t = 1 included): the k-th photon of a k-NN estimate lies on the
//! boundary and the classic uniform estimate counts it. Kernels that do not vanish at t = 1
//! (uniform, Gaussian, cone with k > 1) then overestimate by π K(1) / (k − 1) (Garcia et
//! al. 2012; derivation in `tests/estimate.rs`); `drop_kth` removes that.

use serde::{Deserialize, Serialize};
use std::f64::consts::PI;
use std::fmt;
use std::str::FromStr;

/// Jensen's Gaussian constants (Jensen 2001, §7.2, after Pavicic 1990).
pub const JENSEN_ALPHA: f64 = 0.918;
pub const JENSEN_BETA: f64 = 1.953;

#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Kernel {
    /// Box: every photon counts equally (the framework's `irradiance_estimate`).
    Uniform,
    /// Jensen's cone filter with slope `k` (clamped to >= 1); consistent only for k = 1
    /// (Garcia et al. 2014) unless the k-th photon is dropped.
    Cone {
        k: f32,
    },
    /// Jensen's Gaussian, renormalised to integrate to 1.
    Gaussian,
    /// Jensen's Gaussian exactly as published (integrates to 0.531): for the bias tests.
    GaussianJensen,
    Epanechnikov,
    /// Silverman's second-order kernel, (3/π)(1 − t²)² (worksheet 7).
    Silverman,
    Triweight,
}

impl Kernel {
    pub const ALL: [Kernel; 7] = [
        Kernel::Uniform,
        Kernel::Cone { k: 1.0 },
        Kernel::Gaussian,
        Kernel::GaussianJensen,
        Kernel::Epanechnikov,
        Kernel::Silverman,
        Kernel::Triweight,
    ];

    /// Unnormalised profile, zero beyond t = 1.
    #[inline]
    pub fn shape(self, t: f64) -> f64 {
        if t > 1.0 {
            return 0.0;
        }
        let s = 1.0 - t * t;
        match self {
            Kernel::Uniform => 1.0,
            Kernel::Cone { k } => 1.0 - t / cone_slope(k),
            Kernel::Gaussian | Kernel::GaussianJensen => {
                JENSEN_ALPHA
                    * (1.0
                        - (1.0 - (-JENSEN_BETA * t * t * 0.5).exp()) / (1.0 - (-JENSEN_BETA).exp()))
            }
            Kernel::Epanechnikov => s,
            Kernel::Silverman => s * s,
            Kernel::Triweight => s * s * s,
        }
    }

    /// The factor making `shape` integrate to 1 over the unit disc.
    pub fn norm(self) -> f64 {
        match self {
            Kernel::Uniform => 1.0 / PI,
            Kernel::Cone { k } => 1.0 / ((1.0 - 2.0 / (3.0 * cone_slope(k))) * PI),
            Kernel::Gaussian => 1.0 / (PI * jensen_gaussian_mass()),
            Kernel::GaussianJensen => 1.0 / PI,
            Kernel::Epanechnikov => 2.0 / PI,
            Kernel::Silverman => 3.0 / PI,
            Kernel::Triweight => 4.0 / PI,
        }
    }

    /// K(t): the normalised kernel (for one-off use; estimators hoist `norm`).
    pub fn weight(self, t: f64) -> f64 {
        self.shape(t) * self.norm()
    }
}

/// The serde `kind` tag (what scene and parameter files spell), and `cone:K` for a cone of
/// slope K != 1: one spelling for files and command lines. [`FromStr`] reads it back.
impl fmt::Display for Kernel {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match *self {
            Kernel::Uniform => "uniform",
            Kernel::Cone { k } if k != 1.0 => return write!(f, "cone:{k}"),
            Kernel::Cone { .. } => "cone",
            Kernel::Gaussian => "gaussian",
            Kernel::GaussianJensen => "gaussian_jensen",
            Kernel::Epanechnikov => "epanechnikov",
            Kernel::Silverman => "silverman",
            Kernel::Triweight => "triweight",
        })
    }
}

/// What [`Kernel`]'s `Display` writes, plus the input-only aliases `box` (uniform) and
/// `simpson` (silverman); `cone:K` needs a finite K >= 1.
impl FromStr for Kernel {
    type Err = String;

    fn from_str(s: &str) -> Result<Kernel, String> {
        let name = match s {
            "box" => "uniform",
            "simpson" => "silverman",
            s => s,
        };
        // The names come from `Display` alone, so they are spelled once.
        if let Some(k) = Kernel::ALL.into_iter().find(|k| k.to_string() == name) {
            return Ok(k);
        }
        match name.strip_prefix("cone:").map(str::parse::<f32>) {
            Some(Ok(k)) if k >= 1.0 && k.is_finite() => Ok(Kernel::Cone { k }),
            _ => {
                let names: Vec<String> = Kernel::ALL.iter().map(Kernel::to_string).collect();
                Err(format!(
                    "unknown kernel `{s}` ({}, cone:K with K >= 1; aliases box, simpson)",
                    names.join(", ")
                ))
            }
        }
    }
}

fn cone_slope(k: f32) -> f64 {
    (k as f64).max(1.0)
}

/// ∫_disc w(t)/π dA for Jensen's Gaussian: 0.53113 (so the original underestimates by 46.9%).
pub fn jensen_gaussian_mass() -> f64 {
    let (a, b) = (JENSEN_ALPHA, JENSEN_BETA);
    a * (1.0 - (1.0 - (2.0 / b) * (1.0 - (-b / 2.0).exp())) / (1.0 - (-b).exp()))
}
