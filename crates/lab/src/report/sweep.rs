//! The report's k sweep: bias² and variance against k per kernel and region, and the
//! boundary-bias correction measured.

use super::blocks::Block;
use super::cells::f;
use crate::evidence::{Evidence, GROWN, SWEEP_VARIANTS, slug};
use crate::plots;
use std::path::Path;

/// The worksheet's trade-off: bias² and variance against k per kernel and region, photons
/// grown with k, and the boundary-bias discussion with its measured correction.
pub(super) fn k_blocks(
    out: &Path,
    ev: &Evidence,
    region_names: &[&str],
    blocks: &mut Vec<Block>,
) -> Result<(), String> {
    if ev.sweep.is_empty() {
        return Ok(());
    }
    blocks.push(Block::Heading(
        2,
        "The global map's k: bias against variance".into(),
    ));
    blocks.push(Block::Para(format!(
        "The global map shown directly from {} photon paths, k swept for each kernel, with and \
         without the topological test and the boundary correction; and photons grown with k \
         ({GROWN}: photons / k fixed at the sweep's count / 1000, so the disc keeps its size: the bias stays while the noise falls). A larger k \
         averages more photons (less variance) over a larger disc (more bias where the light \
         changes across it: the caustic, the edges).",
        ev.sweep_photons
    )));
    let mut variants: Vec<&str> = SWEEP_VARIANTS.iter().map(|v| v.0).collect();
    variants.push(GROWN);
    let mut figs = Vec::new();
    for region in region_names {
        let series: Vec<plots::KSeries> = variants
            .iter()
            .map(|v| {
                (
                    v.to_string(),
                    ev.sweep
                        .iter()
                        .filter(|s| s.variant == *v)
                        .filter_map(|s| {
                            let x = s.rung.region(region)?;
                            Some((s.k as f64, x.sums.bias2, x.sums.variance))
                        })
                        .collect(),
                )
            })
            .collect();
        let file = format!("plots/k-{}.svg", slug(region));
        plots::bias_variance_k(
            &out.join(&file),
            &format!("{region}: bias^2 and variance against k"),
            &series,
        )?;
        figs.push((file, region.to_string()));
    }
    blocks.push(Block::Figures(figs));
    let mut rows = Vec::new();
    for s in &ev.sweep {
        for x in &s.rung.regions {
            rows.push(vec![
                s.variant.clone(),
                s.k.to_string(),
                s.photons.to_string(),
                format!("{:.2}", s.rung.seconds),
                x.region.to_string(),
                f(x.sums.bias2),
                f(x.sums.variance),
                f(x.errors.relmse),
                format!("{:.4}", x.errors.mean_ratio),
            ]);
        }
    }
    blocks.push(Block::Table(
        [
            "kernel",
            "k",
            "photon paths",
            "time (s)",
            "region",
            "bias^2",
            "variance",
            "relMSE",
            "mean / ref",
        ]
        .map(String::from)
        .to_vec(),
        rows,
    ));
    boundary_blocks(ev, blocks);
    Ok(())
}

/// Boundary bias: the darkening at the edges and the rim, with and without the correction.
fn boundary_blocks(ev: &Evidence, blocks: &mut Vec<Block>) {
    blocks.push(Block::Heading(2, "Boundary bias and its correction".into()));
    blocks.push(Block::Para(
        "Where a surface ends (the box's inner edges and corners, its open rim), the disc of \
         the k nearest photons reaches past it: the photons all lie on one side, the estimate \
         divides by the whole disc's area and comes out dark. The correction divides instead by \
         the share of the kernel's mass that lies on the surface (the disc clipped by the \
         surface's edges). Below: mean over the region divided by the reference's mean \
         (1 = no bias) and the relative bias^2, Silverman's kernel with the topological test, \
         without and with the correction."
            .into(),
    ));
    let (without, with) = (SWEEP_VARIANTS[2].0, SWEEP_VARIANTS[3].0);
    let ks: Vec<usize> = {
        let mut k: Vec<usize> = ev
            .sweep
            .iter()
            .filter(|s| s.variant == without)
            .map(|s| s.k)
            .collect();
        k.dedup();
        k
    };
    let mut rows = Vec::new();
    for region in ["edges and corners", "outer rim", "open walls"] {
        for &k in &ks {
            let get = |v: &str| {
                ev.sweep
                    .iter()
                    .find(|s| s.variant == v && s.k == k)
                    .and_then(|s| s.rung.region(region))
            };
            if let (Some(a), Some(b)) = (get(without), get(with)) {
                rows.push(vec![
                    region.to_string(),
                    k.to_string(),
                    format!("{:.4}", a.errors.mean_ratio),
                    format!("{:.4}", b.errors.mean_ratio),
                    f(a.sums.bias2),
                    f(b.sums.bias2),
                ]);
            }
        }
    }
    blocks.push(Block::Table(
        [
            "region",
            "k",
            "mean / ref without",
            "mean / ref with",
            "bias^2 without",
            "bias^2 with",
        ]
        .map(String::from)
        .to_vec(),
        rows,
    ));
}
