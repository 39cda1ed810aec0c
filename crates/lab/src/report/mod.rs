//! The evidence's outputs: tables (`evidence.md`, `evidence.json`), maps and images per rung,
//! SVG plots, and the lab report as `report.md` and `report.html` side by side. One list of
//! blocks renders to both, so the two never disagree; every link is relative to the output
//! folder, which can be copied and read offline.

mod blocks;
mod cells;
mod comparisons;
mod figures;
mod sweep;
mod tables;
mod technique;

pub use blocks::{Block, html, links, markdown};

use crate::evidence::{Evidence, slug};
use cells::{is_layer, slug_of};
use figures::{crop, crops, png, rung_files};
use film::{Mask, ToneMap};
use scene::Scene;
use std::path::Path;
use sweep::k_blocks;
use tables::write_tables;

/// Writes everything: `evidence.md`, `evidence.json`, `maps/`, `images/`, `plots/`,
/// `report.md` and `report.html` in `out`.
pub fn write(
    out: &Path,
    ev: &Evidence,
    scene: &Scene,
    regions: &[(&'static str, Mask)],
) -> Result<(), String> {
    let mkdir = |d: &Path| std::fs::create_dir_all(d).map_err(|e| format!("{}: {e}", d.display()));
    for d in ["maps", "images", "plots"] {
        mkdir(&out.join(d))?;
    }
    let tone = ToneMap::default();
    let crops = crops(scene, regions);
    let mut blocks = Vec::new();
    let title = format!("Evidence: {}", ev.scene.display());
    blocks.push(Block::Heading(1, title.clone()));
    blocks.push(Block::Para(format!(
        "{} independent runs per budget (seeds 1 to {}); errors against {}. relMSE is \
         `(v - r)^2 / (r^2 + 0.01)`, relMSE pbrt is `(v - r)^2 / (r + 0.01)^2`, FLIP is \
         LDR-FLIP (Andersson et al. 2020, NVIDIA's implementation; exposure 1, gamma 2.2), each \
         the mean over the runs. bias^2 and variance are relative (divided by `r^2 + 0.01` per \
         pixel) and come from the runs: bias^2 = max(0, (mean - r)^2 - s^2 / K), so bias^2 + \
         variance is one run's relMSE. Regions come from the scene's geometry: the caustic under \
         the glass sphere, the box's inner edges and corners, its outer rim (the open front), \
         the glass sphere, the open walls. Times are the mean seconds of one run on this \
         machine, photon tracing included. Tables of every number: `evidence.md`, \
         `evidence.json`.",
        ev.seeds, ev.seeds, ev.reference
    )));
    if let Some(q) = &ev.quick {
        blocks.push(Block::Para(q.clone()));
    }
    for s in &ev.skipped {
        blocks.push(Block::Para(format!("Left out: {s}.")));
    }

    // The reference and its crops.
    let refdir = out.join("images");
    let reference = &ev.reference_image;
    png(&refdir.join("reference.png"), reference, &tone)?;
    let mut figs = vec![("images/reference.png".to_string(), "reference".to_string())];
    for (name, rect) in &crops {
        let file = format!("reference-{}.png", slug(name));
        png(&refdir.join(&file), &crop(reference, *rect, 2), &tone)?;
        figs.push((format!("images/{file}"), format!("reference, {name}")));
    }
    blocks.push(Block::Figures(figs));

    // Maps and images of every rung.
    for r in &ev.rungs {
        rung_files(out, r, &tone, &crops, &slug_of(r), true)?;
    }
    // The sweep's maps as pictures only (the tables hold its numbers).
    for s in &ev.sweep {
        let name = slug(&format!("k-sweep-{}-k{}-{}", s.variant, s.k, s.photons));
        rung_files(out, &s.rung, &tone, &[], &name, false)?;
    }

    // The techniques, each at its largest budget.
    let mut names: Vec<&str> = Vec::new();
    for r in &ev.rungs {
        if !names.contains(&r.technique) {
            names.push(r.technique);
        }
    }
    technique::section(ev, &names, &crops, &mut blocks);

    // Error against time.
    let whole: Vec<&str> = names
        .iter()
        .copied()
        .filter(|n| ev.rungs.iter().any(|r| r.technique == *n && !is_layer(r)))
        .collect();
    comparisons::error_vs_time(out, ev, &names, &whole, &mut blocks)?;

    // Bias and variance per region.
    let region_names: Vec<&str> = regions
        .iter()
        .filter(|(_, m)| m.count() > 0)
        .map(|(n, _)| *n)
        .collect();
    comparisons::regions(out, ev, &whole, &region_names, &mut blocks)?;

    // The k sweep.
    k_blocks(out, ev, &region_names, &mut blocks)?;

    // The tables and the JSON of every number.
    write_tables(out, ev)?;
    let md = markdown(&blocks);
    film::write_atomic(&out.join("report.md"), md.as_bytes()).map_err(|e| e.to_string())?;
    let page = html(&title, &blocks);
    film::write_atomic(&out.join("report.html"), page.as_bytes()).map_err(|e| e.to_string())?;
    // Every link must resolve: a report with a missing picture is a broken report.
    for l in links(&blocks) {
        if !out.join(&l).is_file() {
            return Err(format!(
                "{}: the report links {l}, which was not written",
                out.display()
            ));
        }
    }
    Ok(())
}
