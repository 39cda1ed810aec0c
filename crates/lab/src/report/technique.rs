//! The report's section on each technique: what it is, the flags of its largest budget, its
//! pictures and its ladder's errors.

use super::blocks::Block;
use super::cells::{f, label, slug_of};
use super::figures::Crop;
use crate::evidence::{Evidence, RungResult, slug, techniques};
use std::fmt::Write as _;

/// The techniques, each at its largest budget; `names` in the order of their rungs.
pub(super) fn section(ev: &Evidence, names: &[&str], crops: &[Crop], blocks: &mut Vec<Block>) {
    blocks.push(Block::Heading(2, "The techniques".into()));
    let all = techniques(false)
        .into_iter()
        .chain(techniques(true))
        .collect::<Vec<_>>();
    for name in names {
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
        for (c, _) in crops {
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
