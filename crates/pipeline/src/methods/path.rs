//! `path`: the independent path-traced reference (`eye::render`), `render.spp` samples per
//! pixel. With `render.caustics` off it leaves out the paths splatting owns: the `caustic`
//! layer, and `caustic_indirect` too when `[estimate.splat] indirect` is on.

use super::{CountKind, Layer, LayerSpec, Rendered, Run};
use eye::Part;

pub(super) fn render(run: &Run, progress: &(dyn Fn(u64) + Sync)) -> Result<Rendered, String> {
    let r = &run.settings.render;
    let opts = eye::RenderOptions {
        caustics: r.caustics,
        caustic_indirect: r.caustics || !run.settings.estimate.splat.indirect,
        ..run.render_options(r.spp)
    };
    let path_opts = eye::PathOptions {
        caustics: opts.caustics,
        caustic_indirect: opts.caustic_indirect,
        ..eye::PathOptions::from_scene(run.scene)
    };
    let t0 = std::time::Instant::now();
    let film = eye::render(run.scene, &opts, progress);
    let seconds = t0.elapsed().as_secs_f64();
    // Each path-traced layer is one class; a layer the caustic switches empty is left out,
    // so a splatted layer can take its place.
    let parts: Vec<Part> = Part::ALL
        .into_iter()
        .filter(|&p| path_opts.estimates(p))
        .collect();
    let specs: Vec<LayerSpec> = parts
        .iter()
        .map(|p| {
            (
                p.name(),
                std::slice::from_ref(&super::CLASSES[*p as usize]),
                r.spp as u64,
                CountKind::Spp,
            )
        })
        .collect();
    let layers: Vec<Layer> = super::layers(&film, r.spp, &specs)?;
    let (w, h) = (
        run.scene.camera.width as u64,
        run.scene.camera.height as u64,
    );
    let samples = w * h * r.spp as u64;
    let mut info = serde_json::Map::new();
    for (k, v) in [
        ("spp", serde_json::json!(r.spp)),
        ("caustics", r.caustics.into()),
        ("caustic_indirect", opts.caustic_indirect.into()),
        ("max_depth", r.max_depth.into()),
        ("rr_depth", r.rr_depth.into()),
        ("samples", samples.into()),
        ("time_render_s", seconds.into()),
        ("samples_per_s", (samples as f64 / seconds).into()),
    ] {
        info.insert(k.to_string(), v);
    }
    Ok(Rendered {
        layers,
        plan: None,
        info,
        passes: None,
        snapshots: Vec::new(),
    })
}
