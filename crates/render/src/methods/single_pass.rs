//! What the methods whose blocks are single passes share (`caustic-splat`, `light`, `vcm`):
//! the run as blocks of one pass each, and the pass loop's interface, over a method that
//! says how to render pass `j` alone ([`PassMethod`]).

use crate::passes::Pass;
use crate::rendered::{Layer, Rendered};
use crate::run::{Accumulate, Blocks};
use crate::settings::{Knob, Settings};
use glam::DVec3;

/// JSON facts for `image.json`.
pub(super) type Facts = serde_json::Map<String, serde_json::Value>;

/// A method rendered in independent passes: pass `j`'s sums are a function of the scene and
/// `j` alone, so a shard of passes and the whole run add up alike.
pub(super) trait PassMethod {
    /// Where its passes are counted.
    const KNOB: Knob;
    /// How messages name it ("light tracing").
    const NAME: &'static str;
    fn settings(&self) -> &Settings;
    /// Passes added so far.
    fn passes(&self) -> u32;
    fn layer_names(&self) -> Vec<String>;
    /// Pass `pass`'s f64 sums per pixel, per layer.
    fn render_pass(
        &mut self,
        pass: u64,
        progress: &(dyn Fn(u64) + Sync),
    ) -> Result<Vec<Vec<DVec3>>, String>;
    fn add_pass(&mut self, sums: &[Vec<DVec3>]);
    /// The layers so far: each the mean over the passes made.
    fn layers_so_far(&self) -> Vec<Layer>;
    fn facts(&self) -> Facts;
}

/// A [`PassMethod`] as the pass loop and the block runner want it.
pub(super) struct Passes<M>(pub M);

/// The run of `m` as blocks: the settings' passes, one block each.
pub(super) fn blocks<'a, M: PassMethod + 'a>(m: M) -> Blocks<'a> {
    let passes = M::KNOB.get(m.settings()) as u64;
    Blocks {
        acc: Box::new(Passes(m)),
        blocks: (0..passes).map(|j| j..j + 1).collect(),
        unit: "passes",
    }
}

impl<M: PassMethod> Accumulate for Passes<M> {
    fn layer_names(&self) -> Vec<String> {
        self.0.layer_names()
    }

    fn block(
        &mut self,
        block: std::ops::Range<u64>,
        progress: &(dyn Fn(u64) + Sync),
    ) -> Result<Vec<Vec<DVec3>>, String> {
        if block.end != block.start + 1 {
            return Err(format!(
                "{}'s blocks are single passes, not {block:?}",
                M::NAME
            ));
        }
        self.0.render_pass(block.start, progress)
    }

    fn add(&mut self, sums: &[Vec<DVec3>], _passes: u64) {
        self.0.add_pass(sums);
    }

    fn finish(&self, seconds: f64) -> Rendered {
        let mut info = self.0.facts();
        info.insert("time_render_s".into(), seconds.into());
        Rendered {
            passes: Some(self.0.passes()),
            ..Rendered::new(self.0.layers_so_far(), info)
        }
    }
}

impl<M: PassMethod> crate::passes::Progressive for Passes<M> {
    fn done(&self) -> u32 {
        self.0.passes()
    }

    fn total(&self) -> u32 {
        M::KNOB.get(self.0.settings())
    }

    fn limit(&self) -> (u32, String) {
        (M::KNOB.max(), M::KNOB.at_max())
    }

    /// One pass, whatever `_pass` allows: passes are the unit of the mean.
    fn step(&mut self, _pass: Pass, progress: &(dyn Fn(u64) + Sync)) -> Result<(), String> {
        let sums = self.0.render_pass(self.0.passes() as u64, progress)?;
        self.0.add_pass(&sums);
        Ok(())
    }

    fn layers(&self) -> Vec<Layer> {
        self.0.layers_so_far()
    }

    fn finish(&self, seconds: f64) -> Rendered {
        Accumulate::finish(self, seconds)
    }
}
