//! The techniques the evidence compares, each a method with its knobs and a ladder of
//! budgets, and the k sweep's series.

use density::Kernel;
use render::Overrides;
use scene::Method;

/// One technique of the evidence: a method with its knobs, and its ladder of budgets.
pub struct Technique {
    pub name: &'static str,
    pub overrides: Overrides,
    /// What each rung sets: `spp`, `photons` or `passes`.
    pub budget: Budget,
    pub ladder: Vec<u64>,
    /// Compare this layer alone (with the reference's layer of that name) instead of the
    /// whole image: the caustic map against splatting.
    pub layer: Option<&'static str>,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Budget {
    Spp,
    Photons,
    Passes,
    /// Caustic paths per splatting pass.
    SplatPhotons,
}

impl Budget {
    pub fn name(self) -> &'static str {
        match self {
            Budget::Spp => "spp",
            Budget::Photons => "photon paths",
            Budget::Passes => "passes",
            Budget::SplatPhotons => "caustic paths",
        }
    }

    pub fn apply(self, o: &Overrides, n: u64) -> Overrides {
        let mut o = o.clone();
        match self {
            Budget::Spp => o.spp = Some(n as u32),
            Budget::Photons => o.photons = Some(n),
            Budget::Passes => o.passes = Some(n as u32),
            Budget::SplatPhotons => o.splat_photons = Some(n),
        }
        o
    }
}

/// The techniques the issue names: the path tracer, path + splatted caustics, the global
/// map shown directly (box and Silverman kernels, + the topological test, + boundary
/// correction), final gathering, SPPM, vertex connection and merging, and the caustic map against splatting (the `caustic`
/// layer alone: `L S+ D E`, caustics seen directly).
pub fn techniques(quick: bool) -> Vec<Technique> {
    let ladder = |q: &[u64], full: &[u64]| if quick { q.to_vec() } else { full.to_vec() };
    let gd = |kernel: Kernel, topo: Option<f32>, boundary: bool| Overrides {
        method: Some(Method::GlobalDirect),
        kernel: Some(kernel),
        topo: Some(topo),
        boundary: Some(boundary),
        ..Overrides::default()
    };
    let m = |method| Overrides {
        method: Some(method),
        ..Overrides::default()
    };
    vec![
        Technique {
            name: "path",
            overrides: m(Method::Path),
            budget: Budget::Spp,
            layer: None,
            ladder: ladder(&[2, 8], &[16, 64, 128]),
        },
        Technique {
            name: "path+splat",
            overrides: m(Method::PathSplat),
            budget: Budget::Spp,
            layer: None,
            ladder: ladder(&[2, 8], &[4, 16, 64]),
        },
        Technique {
            name: "global map, box",
            overrides: gd(Kernel::Uniform, None, false),
            budget: Budget::Photons,
            layer: None,
            ladder: ladder(&[50_000, 200_000], &[100_000, 400_000, 1_600_000]),
        },
        Technique {
            name: "global map, Silverman",
            overrides: gd(Kernel::Silverman, None, false),
            budget: Budget::Photons,
            layer: None,
            ladder: ladder(&[50_000, 200_000], &[100_000, 400_000, 1_600_000]),
        },
        Technique {
            name: "global map, Silverman + topological test",
            overrides: gd(Kernel::Silverman, Some(0.1), false),
            budget: Budget::Photons,
            layer: None,
            ladder: ladder(&[50_000, 200_000], &[100_000, 400_000, 1_600_000]),
        },
        Technique {
            name: "global map, Silverman + topological test + boundary correction",
            overrides: gd(Kernel::Silverman, Some(0.1), true),
            budget: Budget::Photons,
            layer: None,
            ladder: ladder(&[50_000, 200_000], &[100_000, 400_000, 1_600_000]),
        },
        Technique {
            name: "final gathering",
            overrides: m(Method::FinalGather),
            budget: Budget::Spp,
            layer: None,
            ladder: ladder(&[1], &[1, 2]),
        },
        Technique {
            name: "sppm",
            overrides: m(Method::Sppm),
            budget: Budget::Passes,
            layer: None,
            ladder: ladder(&[2, 8], &[4, 16, 64]),
        },
        Technique {
            name: "vcm",
            overrides: m(Method::Vcm),
            budget: Budget::Passes,
            layer: None,
            ladder: ladder(&[2, 8], &[4, 16, 64]),
        },
        // The caustic map as the course's final gathering makes it (k = 250, every path of
        // the trace paid for, the global set's included, and direct light; one gather ray
        // straight into the global map, no irradiance cache: the least indirect light final
        // gathering computes), against photon-differential splatting onto eye vertices (no
        // map, no global set).
        Technique {
            name: "caustic map (k-NN)",
            overrides: Overrides {
                method: Some(Method::FinalGather),
                gather_rays: Some(1),
                gather_cache: Some(0),
                ..Overrides::default()
            },
            budget: Budget::Photons,
            layer: Some("caustic"),
            ladder: ladder(&[100_000, 400_000], &[200_000, 1_000_000, 4_000_000]),
        },
        Technique {
            name: "caustic splat (differentials)",
            overrides: Overrides {
                method: Some(Method::CausticSplat),
                splat_indirect: Some(false),
                ..Overrides::default()
            },
            budget: Budget::SplatPhotons,
            layer: Some("caustic"),
            ladder: ladder(&[100_000, 400_000], &[250_000, 1_000_000, 4_000_000]),
        },
    ]
}

/// The sweep's series: kernel, topological test, boundary correction.
pub const SWEEP_VARIANTS: [(&str, Kernel, Option<f32>, bool); 4] = [
    ("box", Kernel::Uniform, None, false),
    ("Silverman", Kernel::Silverman, None, false),
    (
        "Silverman + topological test",
        Kernel::Silverman,
        Some(0.1),
        false,
    ),
    (
        "Silverman + topological test + boundary",
        Kernel::Silverman,
        Some(0.1),
        true,
    ),
];

/// The series of the sweep whose photon count grows with k (Silverman, the fixed count's
/// paths at k = 1000).
pub const GROWN: &str = "Silverman, photons grown with k";

pub fn slug(s: &str) -> String {
    s.chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() {
                c.to_ascii_lowercase()
            } else {
                '-'
            }
        })
        .collect::<String>()
        .split('-')
        .filter(|p| !p.is_empty())
        .collect::<Vec<_>>()
        .join("-")
}
