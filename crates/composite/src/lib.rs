//! `composite`: the fifth stage. Combines the layered images of separate runs of one view
//! (path-traced references, photon-map estimates, photon-splatted caustics) into one image.
//!
//! Every run describes itself in an `image.json` (parsed here from a string, see
//! [`Meta::from_json`]): the view it shows (`view_hash`, `width`, `height`), its weight
//! (`count` of `count_kind` "spp" or "photon_paths") and its `layers`, each naming the
//! light-path [`Class`]es it estimates. Two rules combine layers:
//!
//! - **Same name, same classes: average.** Such layers are independent estimates of one
//!   quantity; the result is `Σ cᵢ Lᵢ / Σ cᵢ` per pixel and channel, in f64, which needs one
//!   `count_kind` per layer name. The result's count is `Σ cᵢ`, so a composite can itself be
//!   composited with later runs and weigh what it holds.
//! - **Disjoint classes: sum.** Layers with different names must estimate disjoint classes;
//!   the image is the sum of the (averaged) layers. Any overlap would count light twice and
//!   is refused. Classes no input covers are reported in [`Composite::missing`], not refused:
//!   a partial composite (e.g. without caustics) is a legitimate result.
//!
//! Key decisions:
//! - **Order independence.** Inputs are sorted by a canonical key that does not depend on
//!   the order they were given in (their layer set and counts, an FNV-1a hash of their pixel
//!   bytes, their label as the last tie-break) and accumulated in that order, so every
//!   permutation of the inputs gives a bit-identical result (f64 sums are not associative,
//!   and an f32 rounding tie can expose their last bit).
//! - **Refuse, naming the input.** Every error is one line that starts with the label of the
//!   offending input (its path in the binary) and says what is wrong.
//! - **No IO.** The binary reads `image.json` and the layer EXRs and writes the result; this
//!   crate only sees strings and [`film::Image`]s.

mod combine;
mod meta;
pub mod shards;

pub use combine::{Composite, CompositeLayer, Input, composite};
pub use film::Class;
pub use meta::{CountKind, LayerMeta, Meta};

#[cfg(test)]
mod tests;
