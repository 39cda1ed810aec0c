use serde::{Deserialize, Serialize};

/// What a photon run traces. Serialisable because the values are hashed and written into
/// photon files by the caller: a cached photon set is reused only for equal parameters.
#[derive(Clone, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct EmitParams {
    /// Photon *paths* emitted from the lights (not photons stored): the `N` of the flux
    /// `Φ / N` and of every estimator's normalisation.
    pub photons: u64,
    /// Most surface hits a path is followed through. The first hit is hit 1, so `1` keeps only
    /// the direct hits and `0` traces nothing. Russian roulette ends nearly every path long
    /// before the default 64 (the path tracer's cut too); at 16 the light of later bounces,
    /// rho^16 of the total (0.15% in the worksheet's Cornell box), went missing.
    pub max_depth: u32,
    /// Whether the global set keeps a path's first (direct) hit. The course framework does;
    /// renderers that compute direct light by light sampling leave it out.
    pub store_direct: bool,
    /// Trace the global set (every diffuse hit), if the scene can produce it.
    pub global: bool,
    /// Trace the caustic set (first diffuse hit of an L S+ D path), if the scene can produce it.
    pub caustic: bool,
}

impl Default for EmitParams {
    fn default() -> Self {
        EmitParams {
            photons: 200_000,
            max_depth: 64,
            store_direct: true,
            global: true,
            caustic: true,
        }
    }
}
