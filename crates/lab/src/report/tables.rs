//! The tables of every number: `evidence.md` (every rung and sweep point per region) and
//! `evidence.json`.

use super::cells::{f, label};
use crate::evidence::Evidence;
use std::fmt::Write as _;
use std::path::Path;

/// `evidence.md` (every rung and sweep point per region) and `evidence.json`.
pub(super) fn write_tables(out: &Path, ev: &Evidence) -> Result<(), String> {
    let mut md = format!(
        "# Evidence tables: {}\n\n{} runs per rung against {}; see report.md for the \
         conventions.\n\n| technique | budget | time (s) | region | relMSE | relMSE pbrt | RMSE | \
         mean / ref | FLIP | bias^2 | variance |\n|---|---|---|---|---|---|---|---|---|---|---|\n",
        ev.scene.display(),
        ev.seeds,
        ev.reference
    );
    let mut json = Vec::new();
    for (sweep, r) in ev
        .rungs
        .iter()
        .map(|r| (None, r))
        .chain(ev.sweep.iter().map(|s| (Some(s), &s.rung)))
    {
        let technique = sweep.map_or(r.technique.to_string(), |s| {
            format!("global map, {}, k {}", s.variant, s.k)
        });
        for x in &r.regions {
            let e = x.errors;
            let _ = writeln!(
                md,
                "| {technique} | {} | {:.2} | {} | {} | {} | {} | {:.4} | {} | {} | {} |",
                label(r),
                r.seconds,
                x.region,
                f(e.relmse),
                f(e.relmse_pbrt),
                f(e.rmse),
                e.mean_ratio,
                f(e.flip),
                f(x.sums.bias2),
                f(x.sums.variance)
            );
            json.push(serde_json::json!({
                "technique": r.technique, "sweep": sweep.map(|s| s.variant.clone()),
                "k": sweep.map(|s| s.k), "budget": r.budget.name(), "amount": r.amount,
                "seconds": r.seconds, "region": x.region, "pixels": x.sums.pixels,
                "relmse": e.relmse, "relmse_corrected": e.relmse_corrected,
                "relmse_pbrt": e.relmse_pbrt, "rmse": e.rmse,
                "mean_ratio": e.mean_ratio, "flip": e.flip, "bias2": x.sums.bias2,
                "variance": x.sums.variance, "mse": x.sums.mse,
            }));
        }
    }
    film::write_atomic(&out.join("evidence.md"), md.as_bytes()).map_err(|e| e.to_string())?;
    let text = serde_json::to_string_pretty(&json).map_err(|e| e.to_string())? + "\n";
    film::write_atomic(&out.join("evidence.json"), text.as_bytes()).map_err(|e| e.to_string())?;
    Ok(())
}
