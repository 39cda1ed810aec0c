//! `path`: the independent path-traced reference (`eye::render`), `render.spp` samples per
//! pixel. With `render.caustics` off it leaves out the paths splatting owns: the `caustic`
//! layer, and `caustic_indirect` too when `[estimate.splat] indirect` is on.
//!
//! Progressive (`crate::passes`): the samples are rendered in passes of 1, 1, 2, 4, ...
//! samples per pixel, at most an eighth of the run each (so a pass never takes more than the
//! time already spent, or an eighth of the run; passes cost a film each, so there are few of
//! them), pixel sample `s` drawing what it would in one run of all of them. Under a time
//! budget a pass also holds at most the samples a small share of the budget makes at the
//! rate so far (`passes::BUDGET_SHARE`): the doubling stops there and equal passes follow.
//! Every pass is a power of two no larger than the largest one dividing the samples made, so
//! every power of two of samples still ends a pass (and has its snapshot). The run records
//! the samples made.

use crate::rendered::{CountKind, Layer, Rendered};
use crate::run::Run;
use crate::settings::Knob;
use film::Class;
use glam::DVec3;

/// A pass holds at most this share of a run's samples.
pub(crate) const MIN_PASSES: u32 = 8;

/// A path-traced image being accumulated pass by pass: per layer, f64 sums per pixel.
pub(super) struct Progressive<'a> {
    run: &'a Run<'a>,
    opts: eye::RenderOptions,
    parts: Vec<Class>,
    sums: Vec<Vec<DVec3>>,
    /// Samples per pixel made so far.
    pub samples: u32,
    /// Blocks (passes) added so far.
    blocks: u32,
}

impl<'a> Progressive<'a> {
    pub(super) fn new(run: &'a Run<'a>) -> Progressive<'a> {
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
        // Each path-traced layer is one class; a layer the caustic switches empty is left
        // out, so a splatted layer can take its place.
        let parts: Vec<Class> = Class::ALL
            .into_iter()
            .filter(|&p| path_opts.estimates(p))
            .collect();
        let pixels = (run.scene.camera.width * run.scene.camera.height) as usize;
        Progressive {
            run,
            opts,
            sums: vec![vec![DVec3::ZERO; pixels]; parts.len()],
            parts,
            samples: 0,
            blocks: 0,
        }
    }

    /// Passes (blocks) added so far.
    pub(super) fn passes(&self) -> u32 {
        self.blocks
    }

    /// Samples of the next pass within `pass` (see [`next_pass`]).
    pub(super) fn next_pass(&self, pass: crate::passes::Pass) -> u32 {
        next_pass(self.samples, pass.end, pass.at_most)
    }

    /// The layers' names, in the order [`Progressive::block`] returns their sums.
    pub(super) fn layer_names(&self) -> Vec<String> {
        self.parts.iter().map(|p| p.name().to_string()).collect()
    }

    /// The f64 sums per pixel of samples `range` of every pixel, per layer: one pass, the unit
    /// a shard renders and a merge adds.
    pub(super) fn block(
        &self,
        range: std::ops::Range<u32>,
        progress: &(dyn Fn(u64) + Sync),
    ) -> Result<Vec<Vec<DVec3>>, String> {
        let opts = eye::RenderOptions {
            spp: range.end - range.start,
            first_sample: range.start,
            ..self.opts
        };
        let film = eye::render(self.run.scene, &opts, progress);
        let w = self.run.scene.camera.width as usize;
        let pixels = self.sums.first().map_or(0, Vec::len);
        self.parts
            .iter()
            .map(|part| {
                let layer = film
                    .layer(part.name())
                    .ok_or_else(|| format!("the eye pass wrote no `{}` layer", part.name()))?;
                Ok((0..pixels)
                    .map(|i| DVec3::from_array(layer.sum(i % w, i / w)))
                    .collect())
            })
            .collect()
    }

    /// Adds a block of `n` samples per pixel ([`Progressive::block`]'s sums) to the image.
    pub(super) fn add(&mut self, block: &[Vec<DVec3>], n: u32) {
        for (sums, b) in self.sums.iter_mut().zip(block) {
            for (s, v) in sums.iter_mut().zip(b) {
                *s += *v;
            }
        }
        self.samples += n;
        self.blocks += 1;
    }

    /// Renders the next `n` samples of every pixel and adds them.
    pub(super) fn step(&mut self, n: u32, progress: &(dyn Fn(u64) + Sync)) -> Result<(), String> {
        let opts = eye::RenderOptions {
            spp: n,
            first_sample: self.samples,
            ..self.opts
        };
        // Straight into the sums: the same values as `block` then `add`, without a film.
        eye::render_into(self.run.scene, &opts, &self.parts, &mut self.sums, progress);
        self.samples += n;
        self.blocks += 1;
        Ok(())
    }

    /// What `image.json` records of the path tracer.
    pub(super) fn facts(
        &self,
        seconds: f64,
        passes: u32,
    ) -> serde_json::Map<String, serde_json::Value> {
        let r = &self.run.settings.render;
        let samples = (self.run.scene.camera.width * self.run.scene.camera.height) as u64
            * self.samples as u64;
        let mut info = serde_json::Map::new();
        for (k, v) in [
            ("spp", serde_json::json!(self.samples)),
            ("caustics", r.caustics.into()),
            ("caustic_indirect", self.opts.caustic_indirect.into()),
            ("max_depth", r.max_depth.into()),
            ("rr_depth", r.rr_depth.into()),
            (
                "sampler",
                serde_json::to_value(r.sampler).unwrap_or_default(),
            ),
            ("samples", samples.into()),
            ("path_passes", passes.into()),
            ("time_render_s", seconds.into()),
            ("samples_per_s", (samples as f64 / seconds).into()),
        ] {
            info.insert(k.to_string(), v);
        }
        info
    }

    /// The layers so far, each the mean over the samples made.
    pub(super) fn layers(&self) -> Vec<Layer> {
        let (w, h) = (
            self.run.scene.camera.width as usize,
            self.run.scene.camera.height as usize,
        );
        let n = self.samples.max(1) as f64;
        self.parts
            .iter()
            .zip(&self.sums)
            .map(|(part, sums)| Layer {
                name: part.name().to_string(),
                classes: vec![*part],
                image: film::Image::from_fn(w, h, |x, y| {
                    (sums[y * w + x] / n).as_vec3().to_array()
                }),
                count: self.samples as u64,
                count_kind: CountKind::Spp,
            })
            .collect()
    }
}

/// Samples of the pass after `samples` of a run to `end`: as many as made so far (at least
/// one), at most `end / MIN_PASSES` rounded up to a power of two and `at_most` rounded down
/// to one, and no more than are left. Every pass but a last remainder is a power of two no
/// larger than the largest one dividing `samples`, so every power of two of samples ends a
/// pass; with `at_most` unbounded these are the passes 1, 1, 2, 4, ... up to the cap.
pub(crate) fn next_pass(samples: u32, end: u32, at_most: u32) -> u32 {
    let cap = end.div_ceil(MIN_PASSES).max(1).next_power_of_two();
    let aligned = if samples == 0 {
        1
    } else {
        1 << samples.trailing_zeros()
    };
    let budget = 1 << at_most.max(1).ilog2();
    aligned.min(cap).min(budget).min(end - samples)
}

/// The sample ranges of a run of `spp`'s passes, in order: the blocks shards split and a
/// merge adds in this order, as the one-machine run does.
pub(crate) fn passes(spp: u32) -> Vec<std::ops::Range<u64>> {
    let mut out = Vec::new();
    let mut done = 0;
    while done < spp {
        let n = next_pass(done, spp, u32::MAX);
        out.push(done as u64..(done + n) as u64);
        done += n;
    }
    out
}

/// The path tracer's run as blocks: its passes ([`passes`]).
pub(super) fn blocks<'a>(run: &'a Run<'a>) -> crate::run::Blocks<'a> {
    crate::run::Blocks {
        acc: Box::new(Progressive::new(run)),
        blocks: passes(run.settings.render.spp),
        unit: "samples per pixel",
    }
}

impl crate::run::Accumulate for Progressive<'_> {
    fn layer_names(&self) -> Vec<String> {
        Progressive::layer_names(self)
    }

    fn block(
        &mut self,
        block: std::ops::Range<u64>,
        progress: &(dyn Fn(u64) + Sync),
    ) -> Result<Vec<Vec<DVec3>>, String> {
        Progressive::block(self, block.start as u32..block.end as u32, progress)
    }

    fn add(&mut self, sums: &[Vec<DVec3>], n: u64) {
        Progressive::add(self, sums, n as u32);
    }

    fn finish(&self, seconds: f64) -> Rendered {
        Rendered {
            samples: Some(self.samples),
            ..Rendered::new(self.layers(), self.facts(seconds, self.blocks))
        }
    }
}

impl crate::passes::Progressive for Progressive<'_> {
    fn done(&self) -> u32 {
        self.samples
    }

    fn total(&self) -> u32 {
        self.run.settings.render.spp
    }

    fn limit(&self) -> (u32, String) {
        (Knob::RenderSpp.max(), Knob::RenderSpp.at_max())
    }

    fn step(
        &mut self,
        pass: crate::passes::Pass,
        progress: &(dyn Fn(u64) + Sync),
    ) -> Result<(), String> {
        Progressive::step(self, self.next_pass(pass), progress)
    }

    fn layers(&self) -> Vec<Layer> {
        Progressive::layers(self)
    }

    fn finish(&self, seconds: f64) -> Rendered {
        crate::run::Accumulate::finish(self, seconds)
    }
}

pub(super) fn render(run: &Run, progress: &(dyn Fn(u64) + Sync)) -> Result<Rendered, String> {
    crate::passes::run(&mut Progressive::new(run), run.settings.time, progress)
}
