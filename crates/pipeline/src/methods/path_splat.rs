//! `path+splat`: the path tracer without the paths splatting owns (`render.caustics` off:
//! exactly `L S+ D S* E` with D the first diffuse vertex from the eye, and with `[estimate.
//! splat] indirect` also the caustics seen through further diffuse bounces), plus those
//! paths by photon differential splatting. The layers partition path space (`eye::Part`), so
//! nothing is counted twice and nothing is missed; they are composited as `composite` would.
//!
//! Both run progressively and interleaved: after each path-traced pass, splatting passes
//! catch up with the same share of theirs, so a snapshot (whenever the path tracer's samples
//! are a power of two) or a time budget finds both about equally far along.

use super::{Rendered, Run, Snapshot, caustic_splat, path};

pub(super) fn render(run: &Run, progress: &(dyn Fn(u64) + Sync)) -> Result<Rendered, String> {
    let mut settings = run.settings.clone();
    settings.render.caustics = false;
    let path_run = Run {
        settings: &settings,
        ..*run
    };
    let spp = settings.render.spp;
    let splat_passes = settings.estimate.splat.passes;
    let per_pass = path::Progressive::pass_samples(spp);
    let path_passes = spp.div_ceil(per_pass) as u64;
    let t0 = std::time::Instant::now();
    let mut image = path::Progressive::new(&path_run);
    let mut splat = caustic_splat::Progressive::new(run);
    let mut snapshots = Vec::new();
    let mut k = 0u64;
    while image.samples < spp {
        image.step(per_pass.min(spp - image.samples), progress)?;
        k += 1;
        // The splat's progress counts photons, not samples: it reports through its own line.
        let due = (splat_passes as u64 * k).div_ceil(path_passes).max(1) as u32;
        while splat.passes < due {
            splat.step(&|_| {})?;
        }
        let elapsed = t0.elapsed().as_secs_f64();
        let layers = || {
            let mut l = image.layers();
            l.extend(splat.layers());
            l
        };
        if image.samples.is_power_of_two() || image.samples == spp {
            snapshots.push(Snapshot {
                passes: image.samples,
                seconds: elapsed,
                layers: layers(),
            });
        }
        if run.settings.time.is_some_and(|t| elapsed >= t) {
            break;
        }
    }
    let seconds = t0.elapsed().as_secs_f64();
    let mut info = image.facts(seconds, per_pass);
    info.extend(splat.facts());
    let mut layers = image.layers();
    layers.extend(splat.layers());
    Ok(Rendered {
        layers,
        plan: None,
        info,
        passes: Some(splat.passes),
        samples: Some(image.samples),
        snapshots,
    })
}
