//! The report's comparisons of the techniques: error against time, the best technique per
//! time budget, and bias² and variance per region.

use super::blocks::Block;
use super::cells::{f, is_layer, label};
use crate::evidence::{Evidence, RungResult};
use crate::plots::{self, Series};
use std::path::Path;

/// Error against time: plots of relMSE and FLIP, a table of every rung and the best per
/// budget. `names` are the techniques in the order of their rungs, `whole` those measured on
/// the whole image.
pub(super) fn error_vs_time(
    out: &Path,
    ev: &Evidence,
    names: &[&str],
    whole: &[&str],
    blocks: &mut Vec<Block>,
) -> Result<(), String> {
    blocks.push(Block::Heading(2, "Error against time".into()));
    let series = |names: &[&str], region: &str, flip: bool| -> Vec<Series> {
        names
            .iter()
            .map(|n| Series {
                name: n.to_string(),
                points: ev
                    .rungs
                    .iter()
                    .filter(|r| r.technique == *n)
                    .filter_map(|r| {
                        let e = r.region(region)?.errors;
                        Some((r.seconds, if flip { e.flip } else { e.relmse }))
                    })
                    .collect(),
            })
            .collect()
    };
    let slopes = [
        (-1.0, "slope -1 (unbiased Monte Carlo)"),
        (-2.0 / 3.0, "slope -2/3 (progressive photon mapping)"),
    ];
    plots::log_log(
        &out.join("plots/error-vs-time.svg"),
        "relMSE against time, whole image",
        "seconds per run",
        "relMSE",
        &series(whole, "image", false),
        &slopes,
    )?;
    plots::log_log(
        &out.join("plots/flip-vs-time.svg"),
        "FLIP against time, whole image",
        "seconds per run",
        "mean LDR-FLIP",
        &series(whole, "image", true),
        &[],
    )?;
    let mut figs = vec![
        (
            "plots/error-vs-time.svg".to_string(),
            "relMSE against seconds, log-log, with reference slopes".to_string(),
        ),
        (
            "plots/flip-vs-time.svg".to_string(),
            "FLIP against seconds".to_string(),
        ),
    ];
    let layered: Vec<&str> = names
        .iter()
        .copied()
        .filter(|n| ev.rungs.iter().any(|r| r.technique == *n && is_layer(r)))
        .collect();
    if !layered.is_empty() {
        plots::log_log(
            &out.join("plots/caustic-vs-time.svg"),
            "caustic layer: relMSE against time, caustic region",
            "seconds per run",
            "relMSE",
            &series(&layered, "caustic", false),
            &slopes[..1],
        )?;
        figs.push((
            "plots/caustic-vs-time.svg".into(),
            "the caustic map against splatting".into(),
        ));
    }
    blocks.push(Block::Figures(figs));
    let rows = ev
        .rungs
        .iter()
        .map(|r| {
            let e = r.regions[0].errors;
            vec![
                r.technique.to_string() + if is_layer(r) { " (caustic layer)" } else { "" },
                label(r),
                format!("{:.2}", r.seconds),
                f(e.relmse),
                f(e.flip),
            ]
        })
        .collect();
    blocks.push(Block::Table(
        ["technique", "budget", "time (s)", "relMSE", "FLIP"]
            .map(String::from)
            .to_vec(),
        rows,
    ));
    blocks.push(Block::Para(
        "Best at each time budget (the least relMSE over the whole image among the runs that \
         took no longer):"
            .into(),
    ));
    blocks.push(best_per_budget(ev));
    Ok(())
}

/// Bias² and variance per region at each technique's largest budget: bars and a table.
pub(super) fn regions(
    out: &Path,
    ev: &Evidence,
    whole: &[&str],
    region_names: &[&str],
    blocks: &mut Vec<Block>,
) -> Result<(), String> {
    blocks.push(Block::Heading(2, "Bias and variance per region".into()));
    let tops: Vec<&RungResult> = whole
        .iter()
        .filter_map(|n| ev.rungs.iter().rfind(|r| r.technique == *n))
        .collect();
    let bars: Vec<(String, Vec<(f64, f64)>)> = tops
        .iter()
        .map(|r| {
            (
                format!("{}, {}", r.technique, label(r)),
                region_names
                    .iter()
                    .map(|n| {
                        r.region(n)
                            .map_or((0.0, 0.0), |x| (x.sums.bias2, x.sums.variance))
                    })
                    .collect(),
            )
        })
        .collect();
    plots::region_bars(
        &out.join("plots/regions.svg"),
        "relative bias^2 (dark) and variance (light) per region, largest budgets",
        region_names,
        &bars,
    )?;
    blocks.push(Block::Figures(vec![(
        "plots/regions.svg".into(),
        "bias^2 + variance = MSE per region".into(),
    )]));
    let mut rows = Vec::new();
    for r in &tops {
        for x in &r.regions {
            rows.push(vec![
                r.technique.to_string(),
                label(r),
                x.region.to_string(),
                f(x.sums.bias2),
                f(x.sums.variance),
                f(x.sums.mse),
                format!("{:.4}", x.errors.mean_ratio),
                f(x.errors.flip),
            ]);
        }
    }
    blocks.push(Block::Table(
        [
            "technique",
            "budget",
            "region",
            "bias^2",
            "variance",
            "MSE",
            "mean / ref",
            "FLIP",
        ]
        .map(String::from)
        .to_vec(),
        rows,
    ));
    Ok(())
}

/// For time budgets 1, 2, 5, 10, ... seconds: the technique with the least whole-image
/// relMSE among the rungs that took no longer.
fn best_per_budget(ev: &Evidence) -> Block {
    let whole: Vec<&RungResult> = ev.rungs.iter().filter(|r| !is_layer(r)).collect();
    let longest = whole.iter().map(|r| r.seconds).fold(0.0, f64::max);
    let mut rows = Vec::new();
    let mut budget = 1.0f64;
    let steps = [1.0, 2.0, 5.0];
    let mut i = 0;
    while budget <= longest * 2.0 && i < 30 {
        let best = whole.iter().filter(|r| r.seconds <= budget).min_by(|a, b| {
            a.regions[0]
                .errors
                .relmse
                .total_cmp(&b.regions[0].errors.relmse)
        });
        if let Some(b) = best {
            rows.push(vec![
                format!("{budget}"),
                b.technique.to_string(),
                label(b),
                format!("{:.2}", b.seconds),
                f(b.regions[0].errors.relmse),
            ]);
        }
        i += 1;
        budget = steps[i % 3] * 10f64.powi((i / 3) as i32);
    }
    Block::Table(
        [
            "budget (s)",
            "best technique",
            "its budget",
            "time (s)",
            "relMSE",
        ]
        .map(String::from)
        .to_vec(),
        rows,
    )
}
