//! The evidence's outputs: tables (`evidence.md`, `evidence.json`), maps and images per rung,
//! SVG plots, and the lab report as `report.md` and `report.html` side by side. One list of
//! blocks renders to both, so the two never disagree; every link is relative to the output
//! folder, which can be copied and read offline.

use crate::evidence::{Evidence, GROWN, RungResult, SWEEP_VARIANTS, slug, techniques};
use crate::plots::{self, Series};
use film::{Image, Mask, ToneMap};
use scene::Scene;
use std::fmt::Write as _;
use std::path::Path;

/// A crop of the image: its name and pixel rectangle `(x0, y0, x1, y1)`, half open.
type Crop = (&'static str, (usize, usize, usize, usize));

/// A piece of the report.
pub enum Block {
    Heading(u8, String),
    /// A paragraph; `backticks` mark code.
    Para(String),
    Table(Vec<String>, Vec<Vec<String>>),
    /// Images side by side: (relative path, caption).
    Figures(Vec<(String, String)>),
}

/// Every relative link (images and plots) a list of blocks holds.
pub fn links(blocks: &[Block]) -> Vec<String> {
    blocks
        .iter()
        .flat_map(|b| match b {
            Block::Figures(f) => f.iter().map(|(p, _)| p.clone()).collect(),
            _ => Vec::new(),
        })
        .collect()
}

pub fn markdown(blocks: &[Block]) -> String {
    let mut s = String::new();
    for b in blocks {
        match b {
            Block::Heading(n, t) => {
                let _ = writeln!(s, "{} {t}\n", "#".repeat(*n as usize));
            }
            Block::Para(t) => {
                let _ = writeln!(s, "{t}\n");
            }
            Block::Table(head, rows) => {
                let _ = writeln!(s, "| {} |", head.join(" | "));
                let _ = writeln!(s, "|{}", "---|".repeat(head.len()));
                for r in rows {
                    let _ = writeln!(s, "| {} |", r.join(" | "));
                }
                s.push('\n');
            }
            Block::Figures(f) => {
                let cells: Vec<String> = f.iter().map(|(p, c)| format!("![{c}]({p})")).collect();
                let _ = writeln!(s, "{}\n", cells.join(" "));
                let caps: Vec<&str> = f.iter().map(|(_, c)| c.as_str()).collect();
                let _ = writeln!(s, "*{}*\n", caps.join(" · "));
            }
        }
    }
    s
}

fn escape(t: &str) -> String {
    t.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// Escaped text with `code` spans.
fn inline(t: &str) -> String {
    escape(t)
        .split('`')
        .enumerate()
        .map(|(i, p)| {
            if i % 2 == 1 {
                format!("<code>{p}</code>")
            } else {
                p.to_string()
            }
        })
        .collect()
}

pub fn html(title: &str, blocks: &[Block]) -> String {
    let mut s = format!(
        "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<title>{}</title>\n\
         <style>\nbody {{ font-family: sans-serif; max-width: 1200px; margin: 2em auto; \
         padding: 0 1em; line-height: 1.45; color: #222; }}\n\
         table {{ border-collapse: collapse; margin: 1em 0; font-size: 0.9em; }}\n\
         td, th {{ border: 1px solid #ccc; padding: 0.2em 0.5em; text-align: right; }}\n\
         td:first-child, th:first-child {{ text-align: left; }}\n\
         .figs {{ display: flex; flex-wrap: wrap; gap: 1em; }}\n\
         figure {{ margin: 0; display: table; }} figure img {{ max-width: 100%; image-rendering: pixelated; }}\n\
         figcaption {{ display: table-caption; caption-side: bottom; font-size: 0.85em; color: #555; }}\n\
         code {{ background: #f3f3f3; padding: 0 0.2em; }}\n</style>\n</head>\n<body>\n",
        escape(title)
    );
    for b in blocks {
        match b {
            Block::Heading(n, t) => {
                let _ = writeln!(s, "<h{n}>{}</h{n}>", inline(t));
            }
            Block::Para(t) => {
                let _ = writeln!(s, "<p>{}</p>", inline(t));
            }
            Block::Table(head, rows) => {
                s.push_str("<table>\n<tr>");
                for h in head {
                    let _ = write!(s, "<th>{}</th>", inline(h));
                }
                s.push_str("</tr>\n");
                for r in rows {
                    s.push_str("<tr>");
                    for c in r {
                        let _ = write!(s, "<td>{}</td>", inline(c));
                    }
                    s.push_str("</tr>\n");
                }
                s.push_str("</table>\n");
            }
            Block::Figures(f) => {
                s.push_str("<div class=\"figs\">\n");
                for (p, c) in f {
                    let _ = writeln!(
                        s,
                        "<figure><a href=\"{p}\"><img src=\"{p}\" alt=\"{a}\"></a>\
                         <figcaption>{c}</figcaption></figure>",
                        p = escape(p),
                        a = escape(c),
                        c = inline(c)
                    );
                }
                s.push_str("</div>\n");
            }
        }
    }
    s.push_str("</body>\n</html>\n");
    s
}

/// What each technique is, for the report.
fn explanation(technique: &str) -> &'static str {
    match technique {
        "path" => {
            "Unidirectional path tracing with next-event estimation and Russian roulette: \
             unbiased, so its error is all variance and falls as 1/time (slope -1). Caustics \
             (light through the glass sphere onto the floor) are found only when a diffuse \
             bounce happens to sample the sphere towards the light, hence the noise under it."
        }
        "path+splat" => {
            "The path tracer without the paths photon splatting owns (L S+ D (S* D)* E), plus \
             those paths splatted from the light with photon differentials onto the first eye \
             vertices: the caustics converge fast, the rest stays unbiased."
        }
        "global map, box" => {
            "The global photon map shown directly at the first diffuse surface: radiance from \
             the k nearest photons with the uniform (box) kernel, 1 / (pi r^2). Biased: the disc \
             averages over light that changes across it (blur at the caustic, dark at edges)."
        }
        "global map, Silverman" => {
            "As the box kernel, weighted by Silverman's K(t) = 3/pi (1 - t^2)^2: near photons \
             count more, so less blur at the same k, more noise."
        }
        "global map, Silverman + topological test" => {
            "Silverman's kernel, counting only photons on the same surface as the query (normal \
             within the test's tolerance and distance along it small): no light leaks through \
             thin walls or around corners (topological bias)."
        }
        "global map, Silverman + topological test + boundary correction" => {
            "Also divides by the share of the kernel's disc that lies on the surface, so a \
             disc cut by an edge or the box's rim is not darkened (boundary bias)."
        }
        "final gathering" => {
            "The course framework's method: direct light by light sampling, caustics from the \
             caustic map, and indirect light by gather rays into the global map (through an \
             irradiance cache): the map's blur is hidden one bounce away."
        }
        "sppm" => {
            "Stochastic progressive photon mapping: new visible points and photons every pass, \
             per-pixel radii shrinking (alpha = 2/3) so bias and variance both go to zero: \
             consistent, at rate about -2/3."
        }
        "caustic map (k-NN)" => {
            "Caustics seen directly (the `caustic` layer) from the caustic photon map, k = 250 \
             nearest photons, as final gathering makes them; its time is a whole final-gathering \
             render without gather rays (tracing and the direct light included)."
        }
        "caustic splat (differentials)" => {
            "The same layer by splatting each caustic photon with the anisotropic footprint \
             its ray differentials give (no photon map): sharp where the caustic focuses, \
             smooth where it spreads."
        }
        _ => "",
    }
}

/// The command-line flags that make a rung's first image (`photonflow render SCENE ...`).
fn flags(t: &crate::evidence::Technique, amount: u64) -> String {
    let o = t.budget.apply(&t.overrides, amount);
    let mut f = Vec::new();
    if let Some(m) = o.method {
        f.push(format!("--method {m}"));
    }
    if let Some(n) = o.spp {
        f.push(format!("--spp {n}"));
    }
    if let Some(n) = o.passes {
        f.push(format!("--passes {n}"));
    }
    if let Some(n) = o.photons {
        f.push(format!("--photons {n}"));
    }
    if let Some(k) = o.k {
        f.push(format!("--k {k}"));
    }
    if let Some(kern) = o.kernel {
        f.push(format!(
            "--kernel {}",
            if kern == density::Kernel::Uniform {
                "uniform"
            } else {
                "silverman"
            }
        ));
    }
    if let Some(Some(e)) = o.topo {
        f.push(format!("--topo {e}"));
    }
    if o.boundary == Some(true) {
        f.push("--boundary".into());
    }
    if let Some(r) = o.gather_rays {
        f.push(format!("--gather-rays {r}"));
    }
    let mut s = f.join(" ");
    if let Some(n) = o.splat_photons {
        let _ = write!(s, ", and in the scene file [estimate.splat] photons = {n}");
    }
    if o.splat_indirect == Some(false) {
        s.push_str(", indirect = false");
    }
    s
}

fn png(path: &Path, img: &Image, tone: &ToneMap) -> Result<(), String> {
    film::write_png(path, img, tone).map_err(|e| e.to_string())
}

/// `img` cut to `[x0, x1) x [y0, y1)` and enlarged `zoom` times (nearest pixel: the noise
/// stays visible as noise).
fn crop(img: &Image, (x0, y0, x1, y1): (usize, usize, usize, usize), zoom: usize) -> Image {
    Image::from_fn((x1 - x0) * zoom, (y1 - y0) * zoom, |x, y| {
        img.get(x0 + x / zoom, y0 + y / zoom)
    })
}

/// The crops the report shows: the caustic under the glass sphere and two corners of the box,
/// from the scene's geometry (squares around the caustic region and around the pixels seeing
/// the box's back corners).
fn crops(scene: &Scene, regions: &[(&'static str, Mask)]) -> Vec<Crop> {
    let (w, h) = (scene.camera.width as usize, scene.camera.height as usize);
    let side = (w.min(h) / 5).max(4);
    let square = |cx: usize, cy: usize| {
        let x0 = cx.saturating_sub(side / 2).min(w - side.min(w));
        let y0 = cy.saturating_sub(side / 2).min(h - side.min(h));
        (x0, y0, x0 + side.min(w), y0 + side.min(h))
    };
    let mut out = Vec::new();
    if let Some((_, m)) = regions.iter().find(|(n, _)| *n == "caustic")
        && m.count() > 0
    {
        let (mut sx, mut sy, mut n) = (0usize, 0usize, 0usize);
        for (i, &p) in m.pixels.iter().enumerate() {
            if p {
                sx += i % w;
                sy += i / w;
                n += 1;
            }
        }
        out.push(("caustic", square(sx / n, sy / n)));
    }
    // The pixel whose visible point is nearest each back corner (floor and ceiling, left).
    let b = scene.geometry.bounds();
    let back = if (scene.camera.eye.z - b.min.z).abs() > (scene.camera.eye.z - b.max.z).abs() {
        b.min.z
    } else {
        b.max.z
    };
    for (name, corner) in [
        ("floor corner", glam::Vec3::new(b.min.x, b.min.y, back)),
        ("ceiling corner", glam::Vec3::new(b.min.x, b.max.y, back)),
    ] {
        let mut best = (f32::INFINITY, 0, 0);
        for y in 0..h {
            for x in 0..w {
                if let Some(hit) = scene
                    .geometry
                    .intersect(&scene.camera.ray(x as f32 + 0.5, y as f32 + 0.5))
                {
                    let d = (hit.point.p - corner).length();
                    if d < best.0 {
                        best = (d, x, y);
                    }
                }
            }
        }
        if best.0.is_finite() {
            out.push((name, square(best.1, best.2)));
        }
    }
    out
}

fn f(v: f64) -> String {
    if v == 0.0 {
        "0".into()
    } else if v.abs() >= 0.01 && v.abs() < 1000.0 {
        format!("{v:.4}")
    } else {
        format!("{v:.3e}")
    }
}

fn label(r: &RungResult) -> String {
    format!("{} {}", r.amount, r.budget.name())
}

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
    blocks.push(Block::Heading(2, "The techniques".into()));
    let all = techniques(false)
        .into_iter()
        .chain(techniques(true))
        .collect::<Vec<_>>();
    let mut names: Vec<&str> = Vec::new();
    for r in &ev.rungs {
        if !names.contains(&r.technique) {
            names.push(r.technique);
        }
    }
    for name in &names {
        let rungs: Vec<&RungResult> = ev.rungs.iter().filter(|r| r.technique == *name).collect();
        let Some(top) = rungs.last() else { continue };
        let t = all.iter().find(|t| t.name == *name);
        blocks.push(Block::Heading(3, name.to_string()));
        blocks.push(Block::Para(format!(
            "{} Settings of the largest budget: `{}` (seed 1 of {}).",
            explanation(name),
            t.map_or(String::new(), |t| flags(t, top.amount)),
            ev.seeds
        )));
        let s = slug_of(top);
        let mut figs = vec![(
            format!("maps/{s}/image.png"),
            format!("{name}, {}", label(top)),
        )];
        for (c, _) in &crops {
            figs.push((format!("maps/{s}/{}.png", slug(c)), c.to_string()));
        }
        figs.push((format!("maps/{s}/bias2.png"), "bias^2".into()));
        figs.push((format!("maps/{s}/variance.png"), "variance".into()));
        blocks.push(Block::Figures(figs));
        let rows = rungs
            .iter()
            .map(|r| {
                let e = r.regions[0].errors;
                vec![
                    label(r),
                    format!("{:.2}", r.seconds),
                    f(e.relmse),
                    f(e.relmse_pbrt),
                    f(e.flip),
                    format!("{:.4}", e.mean_ratio),
                ]
            })
            .collect();
        blocks.push(Block::Table(
            [
                "budget",
                "time (s)",
                "relMSE",
                "relMSE pbrt",
                "FLIP",
                "mean / ref",
            ]
            .map(String::from)
            .to_vec(),
            rows,
        ));
    }

    // Error against time.
    blocks.push(Block::Heading(2, "Error against time".into()));
    let whole: Vec<&str> = names
        .iter()
        .copied()
        .filter(|n| ev.rungs.iter().any(|r| r.technique == *n && !is_layer(r)))
        .collect();
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
        &series(&whole, "image", false),
        &slopes,
    )?;
    plots::log_log(
        &out.join("plots/flip-vs-time.svg"),
        "FLIP against time, whole image",
        "seconds per run",
        "mean LDR-FLIP",
        &series(&whole, "image", true),
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

    // Bias and variance per region.
    blocks.push(Block::Heading(2, "Bias and variance per region".into()));
    let region_names: Vec<&str> = regions
        .iter()
        .filter(|(_, m)| m.count() > 0)
        .map(|(n, _)| *n)
        .collect();
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
        &region_names,
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

fn is_layer(r: &RungResult) -> bool {
    techniques(false)
        .iter()
        .any(|t| t.name == r.technique && t.layer.is_some())
}

fn slug_of(r: &RungResult) -> String {
    slug(&format!("{}-{}", r.technique, r.amount))
}

/// A rung's files under `maps/<name>/`: bias² and variance (EXR if `exr`, and false colour
/// on a square-root scale up to the 99th percentile of their sum), the mean (EXR if `exr`),
/// the first run's image and its crops (PNG).
fn rung_files(
    out: &Path,
    r: &RungResult,
    tone: &ToneMap,
    crops: &[Crop],
    name: &str,
    exr: bool,
) -> Result<(), String> {
    let dir = out.join("maps").join(name);
    std::fs::create_dir_all(&dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    let mut both: Vec<f64> = r
        .maps
        .bias2
        .iter()
        .zip(&r.maps.variance)
        .map(|(b, v)| b + v)
        .collect();
    both.sort_by(f64::total_cmp);
    let top = both.get(both.len() * 99 / 100).copied().unwrap_or(1.0);
    let linear = ToneMap {
        gamma: 1.0,
        exposure: 0.0,
    };
    for (name, map) in [("bias2", &r.maps.bias2), ("variance", &r.maps.variance)] {
        if exr {
            film::write_exr(dir.join(format!("{name}.exr")), &r.maps.image(map))
                .map_err(|e| e.to_string())?;
        }
        png(
            &dir.join(format!("{name}.png")),
            &r.maps.false_colour(map, top),
            &linear,
        )?;
    }
    if exr {
        film::write_exr(dir.join("mean.exr"), &r.maps.mean).map_err(|e| e.to_string())?;
    }
    png(&dir.join("image.png"), &r.first, tone)?;
    for (name, rect) in crops {
        png(
            &dir.join(format!("{}.png", slug(name))),
            &crop(&r.first, *rect, 2),
            tone,
        )?;
    }
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

/// The worksheet's trade-off: bias² and variance against k per kernel and region, photons
/// grown with k, and the boundary-bias discussion with its measured correction.
fn k_blocks(
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

    // Boundary bias: the darkening at the edges and the rim, with and without the correction.
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
    Ok(())
}

/// `evidence.md` (every rung and sweep point per region) and `evidence.json`.
fn write_tables(out: &Path, ev: &Evidence) -> Result<(), String> {
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
