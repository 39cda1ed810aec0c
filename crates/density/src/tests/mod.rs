//! Unit tests of `density`, one module per concern:
//! - `knn`: every index equals brute force (k-NN and fixed radius), exhaustively for small
//!   inputs;
//! - `kernel`: each kernel integrates to 1 over the unit disc; Jensen's Gaussian to 0.531;
//!   kernel names round-trip and are the serde tags;
//! - `estimate`: bias on a uniform plane (k-NN and fixed radius), the corner leak,
//!   robustness;
//! - `splat`: footprints integrate to their flux; splats onto receivers do at every spacing
//!   level, and stay on the photon's surface and side;
//! - `sppm`: the per-pixel statistics against their closed forms.

use crate::IndexKind;

/// Runs one case under every index back-end (as ripgrep's `rgtest!` runs each case under
/// every regex engine):
/// `each_index!(name, |kind: IndexKind| { ... });` makes `name::{kd_tree, kiddo, brute}`.
macro_rules! each_index {
    ($name:ident, $case:expr) => {
        mod $name {
            use super::*;
            #[test]
            fn kd_tree() {
                ($case)(IndexKind::KdTree)
            }
            #[test]
            fn kiddo() {
                ($case)(IndexKind::Kiddo)
            }
            #[test]
            fn brute() {
                ($case)(IndexKind::Brute)
            }
        }
    };
}

mod estimate;
mod kernel;
mod knn;
mod splat;
mod sppm;

/// Mean and standard error of independent samples.
fn mean_se(xs: &[f64]) -> (f64, f64) {
    let n = xs.len() as f64;
    let mean = xs.iter().sum::<f64>() / n;
    let var = xs.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0);
    (mean, (var / n).sqrt())
}

/// `IndexKind::ALL` is what the tests and benchmarks iterate: each entry must build its own
/// back-end, and its name must be distinct and be what parameter files spell (serde).
#[test]
fn each_index_kind_builds_itself_under_its_own_name() {
    #[derive(serde::Deserialize)]
    struct File {
        index: IndexKind,
    }
    let mut names = Vec::new();
    for kind in IndexKind::ALL {
        let index = crate::Index::build(kind, &[[0.0, 1.0, 2.0]]);
        assert_eq!(index.kind(), kind);
        assert_eq!(index.len(), 1, "{kind:?}");
        let file: File = toml::from_str(&format!("index = \"{}\"", kind.name())).unwrap();
        assert_eq!(file.index, kind, "{kind:?} is not spelled {}", kind.name());
        assert!(!names.contains(&kind.name()), "{} twice", kind.name());
        names.push(kind.name());
    }
}
