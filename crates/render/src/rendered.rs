//! What a method makes: layers tagged with the light-path classes they estimate and the
//! count that weighs them, the run's facts for `image.json`, and a progressive run's
//! snapshots.

use emit::Plan;
use film::Image;

/// One layer of an image: its name, the light-path classes (`film::Class`) it estimates, its
/// pixels (already divided by the sample count), and its weight when runs are composited:
/// samples per pixel for layers the eye pass estimates alone, photon paths for layers made
/// from photons.
pub struct Layer {
    pub name: String,
    pub classes: Vec<film::Class>,
    pub image: Image,
    pub count: u64,
    pub count_kind: CountKind,
}

/// What a method made.
pub struct Rendered {
    pub layers: Vec<Layer>,
    /// The effects plan, for photon methods.
    pub plan: Option<Plan>,
    /// Method-specific facts for `image.json` (settings used, photon counts, timings).
    pub info: serde_json::Map<String, serde_json::Value>,
    /// Photon passes made, for progressive methods (the resolved scene records them).
    pub passes: Option<u32>,
    /// Path-traced samples per pixel made (recorded as `render.spp`: a time budget may stop
    /// the path tracer early).
    pub samples: Option<u32>,
    /// The image after 1, 2, 4, 8, ... passes and the last, for progressive methods: one
    /// run gives an error-against-time series.
    pub snapshots: Vec<Snapshot>,
}

impl Rendered {
    /// Layers and facts, nothing else: no plan, passes, samples or snapshots.
    pub fn new(layers: Vec<Layer>, info: serde_json::Map<String, serde_json::Value>) -> Rendered {
        Rendered {
            layers,
            plan: None,
            info,
            passes: None,
            samples: None,
            snapshots: Vec::new(),
        }
    }
}

/// A progressive method's image after some passes.
pub struct Snapshot {
    pub passes: u32,
    /// Seconds since the passes began.
    pub seconds: f64,
    pub layers: Vec<Layer>,
}

/// What a layer's count counts: the compositing stage's own type, so `image.json` is spelled
/// in one place.
pub use composite::CountKind;
