//! How the report writes a number and names a rung, in its tables and its file names.

use crate::evidence::{RungResult, slug, techniques};

pub(super) fn f(v: f64) -> String {
    if v == 0.0 {
        "0".into()
    } else if v.abs() >= 0.01 && v.abs() < 1000.0 {
        format!("{v:.4}")
    } else {
        format!("{v:.3e}")
    }
}

pub(super) fn label(r: &RungResult) -> String {
    format!("{} {}", r.amount, r.budget.name())
}

pub(super) fn is_layer(r: &RungResult) -> bool {
    techniques(false)
        .iter()
        .any(|t| t.name == r.technique && t.layer.is_some())
}

pub(super) fn slug_of(r: &RungResult) -> String {
    slug(&format!("{}-{}", r.technique, r.amount))
}
