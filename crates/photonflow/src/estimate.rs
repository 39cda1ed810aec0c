//! `estimate`: the density stage on cached photon sets. It never traces: a missing or stale
//! set is an error that says to run `trace` first, so swapping the estimator costs only the
//! estimate (issue 5: "swap the estimator stage alone").

use crate::cache::IrradianceCache;
use crate::pipeline::{self, CacheKey};
use crate::progress::Progress;
use density::{EstimateParams, IndexKind, Kernel, KnnHint, Neighbor, PhotonMap};
use eye::{Irradiance, MapLookup, PhotonMethod, RenderOptions};
use film::{Image, Normalize};
use glam::Vec3;
use scene::Scene;
use std::cell::RefCell;
use std::path::{Path, PathBuf};
use std::time::Instant;
use store::{MapKind, MappedStore};

/// Settings of one estimate, from the scene's `[estimate.global]` / `[estimate.caustic]`
/// tables with command-line overrides applied to the global map's.
pub struct EstimateArgs {
    pub method: PhotonMethod,
    pub photons: Option<u64>,
    pub cache: PathBuf,
    pub spp: Option<u32>,
    pub threads: Option<usize>,
    pub out: Option<PathBuf>,
    pub k: Option<usize>,
    pub kernel: Option<Kernel>,
    pub topo: Option<f32>,
    pub drop_kth: bool,
    pub reference: Option<PathBuf>,
    pub exposure: f32,
    pub label: Option<String>,
    /// Correct global-map estimates for boundary bias (kernel mass on the surface).
    pub boundary: bool,
    /// Final gathering reads irradiance precomputed at every n-th global photon (0: off).
    pub gather_cache: usize,
}

pub fn parse_kernel(s: &str) -> Result<Kernel, String> {
    Ok(match s {
        "uniform" | "box" => Kernel::Uniform,
        "silverman" | "simpson" => Kernel::Silverman,
        "epanechnikov" => Kernel::Epanechnikov,
        "triweight" => Kernel::Triweight,
        "gaussian" => Kernel::Gaussian,
        "gaussian-jensen" => Kernel::GaussianJensen,
        "cone" => Kernel::Cone { k: 1.0 },
        _ => match s.strip_prefix("cone:").map(str::parse::<f32>) {
            Some(Ok(k)) if k >= 1.0 && k.is_finite() => Kernel::Cone { k },
            _ => {
                return Err(format!(
                    "unknown kernel `{s}` (uniform, silverman, epanechnikov, triweight, gaussian, \
                     gaussian-jensen, cone, cone:K with K >= 1)"
                ));
            }
        },
    })
}

pub fn kernel_name(k: Kernel) -> String {
    match k {
        Kernel::Uniform => "uniform".into(),
        Kernel::Silverman => "silverman".into(),
        Kernel::Epanechnikov => "epanechnikov".into(),
        Kernel::Triweight => "triweight".into(),
        Kernel::Gaussian => "gaussian".into(),
        Kernel::GaussianJensen => "gaussian-jensen".into(),
        Kernel::Cone { k } => format!("cone:{k}"),
    }
}

/// Defaults of the course framework (scene-facts.md): k = 1000 for the global map, 250 for
/// the caustic map, box kernel, same-side test.
fn map_params(scene: &Scene, which: &str, default_k: usize) -> Result<EstimateParams, String> {
    let table = scene
        .file
        .estimate
        .get(which)
        .cloned()
        .unwrap_or_else(|| toml::Value::Table(toml::Table::new()));
    let mut t = match table {
        toml::Value::Table(t) => t,
        other => {
            return Err(format!(
                "{}: [estimate.{which}] must be a table, not {other}",
                scene.path.display()
            ));
        }
    };
    t.entry("k")
        .or_insert(toml::Value::Integer(default_k as i64));
    toml::Value::Table(t)
        .try_into()
        .map_err(|e| format!("{}: [estimate.{which}]: {e}", scene.path.display()))
}

pub fn params(scene: &Scene, a: &EstimateArgs) -> Result<(EstimateParams, EstimateParams), String> {
    for key in scene.file.estimate.keys() {
        if key != "global" && key != "caustic" {
            return Err(format!(
                "{}: [estimate] has unknown table `{key}` (known: global, caustic)",
                scene.path.display()
            ));
        }
    }
    let mut g = map_params(scene, "global", 1000)?;
    let c = map_params(scene, "caustic", 250)?;
    if let Some(k) = a.k {
        g.k = k;
    }
    if let Some(kern) = a.kernel {
        g.kernel = kern;
    }
    if let Some(eps) = a.topo {
        g.topo = Some(eps);
    }
    g.drop_kth |= a.drop_kth;
    for (name, p) in [("global", &g), ("caustic", &c)] {
        if p.k == 0 || p.k > 1 << 20 {
            return Err(format!(
                "estimate.{name}.k = {} must be in 1..=1048576",
                p.k
            ));
        }
        if let Some(eps) = p.topo
            && !(eps > 0.0 && eps <= 1.0)
        {
            return Err(format!("estimate.{name}.topo = {eps} must be in (0, 1]"));
        }
    }
    Ok((g, c))
}

/// The photon maps behind [`eye::Irradiance`], with a per-thread neighbour buffer.
struct Maps<'a> {
    global: Option<PhotonMap>,
    caustic: Option<PhotonMap>,
    gp: EstimateParams,
    cp: EstimateParams,
    /// Boundary-bias correction of global-map estimates (see [`kernel_mass_on_surface`]).
    boundary: Option<&'a Scene>,
    /// Precomputed global-map irradiance, answering every global lookup (final gathering).
    gather_cache: Option<IrradianceCache>,
}

/// Per-thread query state: the neighbour buffer, and one k-NN hint per map. A tile is
/// rendered row by row on one thread, so consecutive queries are neighbours and the previous
/// query's radius seeds the next search (exact either way; density's `knn_hinted`).
struct QueryState {
    scratch: Vec<Neighbor>,
    hints: [KnnHint; 2],
}

thread_local! {
    static STATE: RefCell<QueryState> = const {
        RefCell::new(QueryState { scratch: Vec::new(), hints: [KnnHint::NONE; 2] })
    };
}

impl Maps<'_> {
    /// The estimate from the maps themselves (no cache): irradiance and the radius used,
    /// with the boundary correction for the global map when asked for. `hint` carries the
    /// previous query's radius (exact either way; density's `knn_hinted`).
    fn estimate(
        &self,
        map: MapLookup,
        p: Vec3,
        n: Vec3,
        hint: &mut KnnHint,
        scratch: &mut Vec<Neighbor>,
    ) -> (Vec3, f32) {
        let (m, params) = match map {
            MapLookup::Global => (&self.global, &self.gp),
            MapLookup::Caustic => (&self.caustic, &self.cp),
        };
        let Some(m) = m else {
            return (Vec3::ZERO, 0.0);
        };
        let e = m.irradiance_hinted(p, n, params, hint, scratch);
        match (map, self.boundary) {
            // The hint now holds the radius the estimate used.
            (MapLookup::Global, Some(scene)) if !scratch.is_empty() => {
                let mass = kernel_mass_on_surface(scene, p, n, hint.r, params.kernel);
                (e / mass.max(MIN_MASS), hint.r)
            }
            _ => (e, hint.r),
        }
    }
}

impl Irradiance for Maps<'_> {
    fn irradiance(&self, map: MapLookup, p: Vec3, n: Vec3) -> Vec3 {
        if let (MapLookup::Global, Some(c)) = (map, &self.gather_cache)
            && let Some(e) = c.lookup(p, n)
        {
            return e;
        }
        STATE.with_borrow_mut(|st| {
            let hint = &mut st.hints[(map == MapLookup::Caustic) as usize];
            self.estimate(map, p, n, hint, &mut st.scratch).0
        })
    }
}

/// Kernel mass below which the boundary correction stops growing (a point in a corner of
/// three walls keeps about a quarter of its disc): bounds the gain, so noise cannot blow up.
const MIN_MASS: f32 = 0.2;

/// Fraction of the kernel's mass whose support lies on the surface through `x` (normal `n`):
/// the estimate divides by pi r^2 as if the whole disc of radius `r` were surface, so
/// dividing by this fraction removes boundary bias ("cut and normalise"; algorithms.md §2.5
/// remedy 1; the ray-cast support test follows Tobler & Maierhofer 2006). Quadrature: 4
/// equal-area rings x 8 angles; a point counts as surface if a short probe ray from just
/// above it along `-n` meets a surface parallel to this one within twice that height.
pub(crate) fn kernel_mass_on_surface(
    scene: &Scene,
    x: Vec3,
    n: Vec3,
    r: f32,
    kernel: Kernel,
) -> f32 {
    if !(r > 0.0 && r.is_finite()) {
        return 1.0;
    }
    let frame = math::Frame::from_z(n);
    let h = 0.01 * r;
    let (mut on, mut all) = (0.0f64, 0.0f64);
    for ring in 0..4 {
        let t = ((ring as f32 + 0.5) / 4.0).sqrt();
        let w = kernel.weight(t as f64);
        for a in 0..8 {
            // Offsets keep points off the axes, where walls of an axis-aligned box would cut
            // through them.
            let phi = std::f32::consts::TAU * (a as f32 + 0.25 + 0.5 * (ring % 2) as f32) / 8.0;
            let q = x + frame.to_world(Vec3::new(t * r * phi.cos(), t * r * phi.sin(), 0.0));
            let probe = geom::Ray {
                o: q + h * n,
                d: -n,
                t_max: 2.0 * h,
            };
            all += w;
            if let Some(hit) = scene.geometry.intersect(&probe)
                && hit.point.n.dot(n).abs() > 0.99
            {
                on += w;
            }
        }
    }
    if all > 0.0 { (on / all) as f32 } else { 1.0 }
}

/// Most photons one map may hold: the kd-tree indexes with u32.
const MAX_MAP_PHOTONS: u64 = u32::MAX as u64 - 1;

fn load_map(path: &Path, key: &CacheKey, kind: MapKind) -> Result<PhotonMap, String> {
    let store = MappedStore::open(path).map_err(|e| e.to_string())?;
    store.check(&key.expect(kind)).map_err(|e| e.to_string())?;
    if store.header().stored > MAX_MAP_PHOTONS {
        return Err(format!(
            "{}: {} photons exceed the {MAX_MAP_PHOTONS} one map can index",
            path.display(),
            store.header().stored
        ));
    }
    // Photon powers from `emit` already carry the 1/N of the emitted count the header records,
    // so the map divides by 1.
    Ok(PhotonMap::build(store.to_vec(), 1, IndexKind::KdTree))
}

pub struct EstimateOutput {
    pub seconds: f64,
}

pub fn estimate(scene: &Scene, a: &EstimateArgs) -> Result<EstimateOutput, String> {
    let t0 = Instant::now();
    let emit_params = crate::trace::params(scene, a.photons)?;
    let plan = emit::Plan::for_scene(scene, &emit_params)
        .map_err(|e| format!("{}: {e}", scene.path.display()))?;
    let key = CacheKey::new(scene, &emit_params);
    let needed: Vec<MapKind> = match a.method {
        PhotonMethod::GlobalDirect => vec![MapKind::Global],
        PhotonMethod::FinalGather { .. } => pipeline::planned_kinds(&plan),
    };
    // Both methods read the global map as the full light arriving at a surface, direct hits
    // included; final gathering also needs the caustic map wherever the scene can make
    // caustics. A missing set would silently darken a layer, so it is an error.
    let incomplete = if !plan.global {
        Some(
            "the effects plan traces no global photons (no diffuse surface, or [photons] global = false)",
        )
    } else if !emit_params.store_direct {
        Some(
            "[photons] store_direct = false leaves direct light out of the global map these methods read",
        )
    } else if matches!(a.method, PhotonMethod::FinalGather { .. })
        && !emit_params.caustic
        && scene.materials.iter().any(|m| m.is_specular())
    {
        Some("[photons] caustic = false leaves the caustic layer of final gathering empty")
    } else {
        None
    };
    if let Some(why) = incomplete {
        return Err(format!("{}: {why}", scene.path.display()));
    }
    let (gp, cp) = params(scene, a)?;
    if a.boundary && gp.topo.is_none() {
        return Err(format!(
            "{}: --boundary needs the topological test (--topo EPS): the correction divides by \
             the share of the disc on this surface, so photons from other surfaces must be \
             excluded first or they are amplified too",
            scene.path.display()
        ));
    }
    let mut global = None;
    let mut caustic = None;
    for kind in needed {
        let path = key.file(&a.cache, kind);
        if !path.exists() {
            return Err(format!(
                "{}: no cached photon set for this scene and these parameters; run `trace` first",
                path.display()
            ));
        }
        let m = load_map(&path, &key, kind)?;
        if m.is_empty() && kind == MapKind::Global {
            eprintln!(
                "warning: {}: the global photon set is empty",
                path.display()
            );
        }
        match kind {
            MapKind::Global => global = Some(m),
            MapKind::Caustic => caustic = Some(m),
        }
    }
    let t_load = t0.elapsed().as_secs_f64();
    let mut maps = Maps {
        global,
        caustic,
        gp,
        cp,
        boundary: a.boundary.then_some(scene),
        gather_cache: None,
    };
    let t_cache = Instant::now();
    if let (PhotonMethod::FinalGather { .. }, true) = (a.method, a.gather_cache > 0) {
        // The cache stores exactly what a direct lookup would answer at its points,
        // boundary correction included.
        let c = IrradianceCache::build(
            scene,
            maps.global.as_ref(),
            a.gather_cache,
            &|x, n, h, s| maps.estimate(MapLookup::Global, x, n, h, s),
        );
        println!(
            "irradiance cache: {} points (every {}th global photon) in {:.2} s",
            c.len(),
            a.gather_cache,
            t_cache.elapsed().as_secs_f64()
        );
        maps.gather_cache = Some(c);
    }
    let t_cache = t_cache.elapsed().as_secs_f64();
    let spp = a.spp.unwrap_or(1);
    if a.threads == Some(0) {
        return Err("--threads must be at least 1".into());
    }
    if let PhotonMethod::FinalGather { rays } = a.method
        && rays > 1 << 16
    {
        return Err(format!("--gather-rays {rays} is absurd (at most 65536)"));
    }
    if spp == 0 || spp > 1 << 20 {
        return Err(format!("--spp {spp} must be in 1..=1048576"));
    }
    let opts = RenderOptions {
        spp,
        caustics: true,
        threads: a.threads,
        tile: scene.render().tile,
    };
    let (w, h) = (scene.camera.width as u64, scene.camera.height as u64);
    let method_name = match a.method {
        PhotonMethod::GlobalDirect => "global-direct".to_string(),
        PhotonMethod::FinalGather { rays } => format!("final-gather-{rays}"),
    };
    let progress = Progress::new("estimate", w * h * spp as u64, "samples");
    let t1 = Instant::now();
    let film = eye::render_photon_map(scene, &opts, a.method, &maps, &|n| progress.inc(n));
    let t_render = t1.elapsed().as_secs_f64();
    progress.finish();

    let label = a.label.clone().unwrap_or_else(|| method_name.clone());
    let out = a
        .out
        .clone()
        .unwrap_or_else(|| crate::render::default_out(&scene.path, &label));
    let layers: Vec<(String, Image)> = film
        .layer_names()
        .into_iter()
        .map(|n| {
            let img = film
                .layer(n)
                .expect("listed")
                .resolve(Normalize::Constant(spp as f64));
            (n.to_string(), img)
        })
        .collect();
    let image = crate::render::write_outputs(&out, &layers, a.exposure)?;
    let metrics = match &a.reference {
        Some(r) => {
            let reference = film::read_exr(r).map_err(|e| e.to_string())?;
            Some(film::metrics(&image, &reference, None).map_err(|e| e.to_string())?)
        }
        None => None,
    };
    let seconds = t0.elapsed().as_secs_f64();
    let json = serde_json::json!({
        "scene": scene.path.display().to_string(),
        "scene_hash": format!("{:016x}", scene.content_hash),
        "image_hash": format!("{:016x}", scene.image_hash),
        "photon_hash": format!("{:016x}", scene.photon_hash),
        "method": method_name,
        "label": label,
        "spp": spp,
        "photons_emitted": emit_params.photons,
        "global_photons": maps.global.as_ref().map_or(0, |m| m.len()),
        "caustic_photons": maps.caustic.as_ref().map_or(0, |m| m.len()),
        "global_estimate": maps.gp,
        "caustic_estimate": maps.cp,
        "kernel": kernel_name(maps.gp.kernel),
        "boundary_correction": a.boundary,
        "gather_cache_stride": maps.gather_cache.as_ref().map(|_| a.gather_cache),
        "time_gather_cache_s": t_cache,
        "time_load_and_index_s": t_load,
        "time_render_s": t_render,
        "time_total_s": seconds,
        "reference": a.reference.as_ref().map(|p| p.display().to_string()),
        "rmse": metrics.as_ref().map(|m| m.rmse),
        "relmse": metrics.as_ref().map(|m| m.relmse),
        "mae": metrics.as_ref().map(|m| m.mae),
        "mean": metrics.as_ref().map(|m| m.mean_a),
        "mean_reference": metrics.as_ref().map(|m| m.mean_b),
    });
    let text = serde_json::to_string_pretty(&json).map_err(|e| e.to_string())? + "\n";
    film::write_atomic(&out.join("image.json"), text.as_bytes()).map_err(|e| e.to_string())?;
    film::write_atomic(&out.join("plan.txt"), plan.to_string().as_bytes())
        .map_err(|e| e.to_string())?;
    println!(
        "estimated {label}: {}x{} at {spp} spp in {t_render:.2} s (+{t_load:.2} s loading and indexing {} photons)",
        w,
        h,
        maps.global.as_ref().map_or(0, |m| m.len()) + maps.caustic.as_ref().map_or(0, |m| m.len())
    );
    if let Some(m) = &metrics {
        println!("against the reference: {m}");
    }
    println!(
        "wrote {}/image.{{exr,png,json}}, layers/, plan.txt",
        out.display()
    );
    Ok(EstimateOutput { seconds })
}
