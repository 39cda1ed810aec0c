//! `path+splat`: the path tracer without the paths splatting owns (`render.caustics` off:
//! exactly `L S+ D S* E` with D the first diffuse vertex from the eye, and with `[estimate.
//! splat] indirect` also the caustics seen through further diffuse bounces), plus those
//! paths by photon differential splatting. The layers partition path space (`film::Class`),
//! so nothing is counted twice and nothing is missed; they are composited as `composite`
//! would.
//!
//! Both run progressively and interleaved: after each path-traced pass, splatting passes
//! catch up with the same share of theirs (its share of the samples), so a snapshot (whenever
//! the path tracer's samples are a power of two) or a time budget finds both about equally
//! far along.

use super::{caustic_splat, path};
use crate::passes::Pass;
use crate::rendered::{Layer, Rendered};
use crate::run::Run;
use crate::settings::Knob;

struct PathSplat<'a> {
    image: path::Progressive<'a>,
    splat: caustic_splat::Progressive<'a>,
    spp: u32,
    splat_passes: u32,
}

impl crate::passes::Progressive for PathSplat<'_> {
    fn done(&self) -> u32 {
        self.image.samples
    }

    fn total(&self) -> u32 {
        self.spp
    }

    fn limit(&self) -> (u32, String) {
        // Splatting's passes keep their ratio to the samples past the settings' counts: the
        // samples stop where either reaches its bound.
        let by_splat = Knob::SplatPasses.max() as u64 * self.spp as u64 / self.splat_passes as u64;
        let spp = Knob::RenderSpp;
        if spp.max() as u64 <= by_splat {
            (spp.max(), spp.at_max())
        } else {
            (by_splat as u32, Knob::SplatPasses.at_max())
        }
    }

    fn step(&mut self, pass: Pass, progress: &(dyn Fn(u64) + Sync)) -> Result<(), String> {
        self.image.step(self.image.next_pass(pass), progress)?;
        // Splatting keeps pace with the path tracer's share of samples made (of the settings'
        // counts, so a time budget keeps their ratio). Its progress counts photons, not
        // samples: it reports through its own line.
        let due = (self.splat_passes as u64 * self.image.samples as u64)
            .div_ceil(self.spp as u64)
            .max(1) as u32;
        while self.splat.passes < due {
            self.splat.step(&|_| {})?;
        }
        Ok(())
    }

    fn layers(&self) -> Vec<Layer> {
        let mut l = self.image.layers();
        l.extend(self.splat.layers());
        l
    }

    fn finish(&self, seconds: f64) -> Rendered {
        let mut info = self.image.facts(seconds, self.image.passes());
        info.extend(self.splat.facts());
        Rendered {
            passes: Some(self.splat.passes),
            samples: Some(self.image.samples),
            ..Rendered::new(self.layers(), info)
        }
    }
}

pub(super) fn render(run: &Run, progress: &(dyn Fn(u64) + Sync)) -> Result<Rendered, String> {
    let mut settings = run.settings.clone();
    settings.render.caustics = false;
    let path_run = Run {
        settings: &settings,
        ..*run
    };
    let mut p = PathSplat {
        image: path::Progressive::new(&path_run),
        splat: caustic_splat::Progressive::new(run),
        spp: settings.render.spp,
        splat_passes: settings.estimate.splat.passes,
    };
    crate::passes::run(&mut p, run.settings.time, progress)
}
