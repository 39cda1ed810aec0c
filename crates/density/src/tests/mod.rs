//! Unit tests of `density`, one module per concern:
//! - `knn`: every index equals brute force, exhaustively for small inputs;
//! - `kernel`: each kernel integrates to 1 over the unit disc; Jensen's Gaussian to 0.531;
//! - `estimate`: bias on a uniform plane, the corner leak, robustness.

use crate::IndexKind;

/// Runs one case under every index back-end (anchor B1.6, ripgrep's `rgtest!`):
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

/// Mean and standard error of independent samples.
fn mean_se(xs: &[f64]) -> (f64, f64) {
    let n = xs.len() as f64;
    let mean = xs.iter().sum::<f64>() / n;
    let var = xs.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0);
    (mean, (var / n).sqrt())
}

#[test]
fn index_kinds_are_all_listed() {
    assert_eq!(IndexKind::ALL.len(), 3);
}
