//! `path+splat`: the path tracer without the paths splatting owns (`render.caustics` off:
//! exactly `L S+ D S* E` with D the first diffuse vertex from the eye, and with `[estimate.
//! splat] indirect` also the caustics seen through further diffuse bounces), plus those
//! paths by photon differential splatting. The layers partition path space (`eye::Part`), so
//! nothing is counted twice and nothing is missed; they are composited as `composite` would.
//!
//! Both run progressively and interleaved: after each path-traced pass, splatting passes
//! catch up with the same share of theirs (its share of the samples), so a snapshot (whenever the path tracer's samples
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
    let t0 = std::time::Instant::now();
    let mut image = path::Progressive::new(&path_run);
    let mut splat = caustic_splat::Progressive::new(run);
    let mut snapshots = Vec::new();
    let mut passes = 0;
    while image.samples < spp {
        image.step(image.next_pass(spp), progress)?;
        passes += 1;
        // Splatting keeps pace with the path tracer's share of samples made. Its progress
        // counts photons, not samples: it reports through its own line.
        let due = (splat_passes as u64 * image.samples as u64)
            .div_ceil(spp as u64)
            .max(1) as u32;
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
    let mut info = image.facts(seconds, passes);
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
