//! `path+splat`: the path tracer without the paths splatting owns (`render.caustics` off:
//! exactly `L S+ D S* E` with D the first diffuse vertex from the eye, and with `[estimate.
//! splat] indirect` also the caustics seen through further diffuse bounces), plus those
//! paths by photon differential splatting. The layers partition path space (`eye::Part`), so nothing
//! is counted twice and nothing is missed; they are composited as `composite` would.

use super::{Rendered, Run};

pub(super) fn render(run: &Run, progress: &(dyn Fn(u64) + Sync)) -> Result<Rendered, String> {
    let mut settings = run.settings.clone();
    settings.render.caustics = false;
    let path_run = Run {
        settings: &settings,
        ..*run
    };
    let mut r = super::path::render(&path_run, progress)?;
    // The splat's progress counts photons, not samples: it reports through its own line.
    let (caustic, info, passes) = super::caustic_splat::caustic_layers(run, &|_| {})?;
    r.layers.extend(caustic);
    r.info.extend(info);
    r.passes = Some(passes);
    Ok(r)
}
