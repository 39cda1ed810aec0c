//! The photon maps behind [`eye::Irradiance`]: the adapter through which the eye pass reads
//! density estimates (the stage crates `eye` and `density` never see each other).

use crate::boundary::{MIN_MASS, kernel_mass_on_surface};
use crate::gather_cache::IrradianceCache;
use density::{EstimateParams, IndexKind, KnnHint, Neighbor, PhotonMap};
use eye::{Irradiance, MapLookup};
use glam::Vec3;
use scene::Scene;
use std::cell::RefCell;
use store::{MapKind, PerKind};

/// Photon maps with their estimate parameters, the optional boundary correction of the
/// global map, and the optional irradiance cache that answers global lookups.
pub struct Maps<'a> {
    pub maps: PerKind<Option<PhotonMap>>,
    pub params: PerKind<EstimateParams>,
    /// Boundary-bias correction of global-map estimates (see [`kernel_mass_on_surface`]).
    pub boundary: Option<&'a Scene>,
    /// Precomputed global-map irradiance, answering every global lookup (final gathering).
    pub gather_cache: Option<IrradianceCache>,
}

/// Per-thread query state: the neighbour buffer, and one k-NN hint per map. A tile is
/// rendered row by row on one thread, so consecutive queries are neighbours and the previous
/// query's radius seeds the next search (exact either way; density's `knn_hinted`).
struct QueryState {
    scratch: Vec<Neighbor>,
    hints: [KnnHint; 2],
}

thread_local! {
    static STATE: RefCell<QueryState> = const {
        RefCell::new(QueryState { scratch: Vec::new(), hints: [KnnHint::NONE; 2] })
    };
}

fn kind_of(map: MapLookup) -> MapKind {
    match map {
        MapLookup::Global => MapKind::Global,
        MapLookup::Caustic => MapKind::Caustic,
    }
}

impl Maps<'_> {
    /// The estimate from the maps themselves (no cache): irradiance and the radius used,
    /// with the boundary correction for the global map when asked for. `hint` carries the
    /// previous query's radius (exact either way; density's `knn_hinted`).
    pub fn estimate(
        &self,
        kind: MapKind,
        p: Vec3,
        n: Vec3,
        hint: &mut KnnHint,
        scratch: &mut Vec<Neighbor>,
    ) -> (Vec3, f32) {
        let params = &self.params[kind];
        let Some(m) = &self.maps[kind] else {
            return (Vec3::ZERO, 0.0);
        };
        let e = m.irradiance_hinted(p, n, params, hint, scratch);
        if scratch.is_empty() {
            return (e, 0.0);
        }
        // The radius the estimate used: the hint's k-th distance, or with fewer than k
        // photons in reach (and no finite r_max) the farthest one found.
        let r = if hint.r.is_finite() {
            hint.r
        } else {
            scratch.iter().map(|nb| nb.d2).fold(0.0f32, f32::max).sqrt()
        };
        match (kind, self.boundary) {
            (MapKind::Global, Some(scene)) => {
                let mass = kernel_mass_on_surface(scene, p, n, r, params);
                (e / mass.max(MIN_MASS), r)
            }
            _ => (e, r),
        }
    }

    /// Photons in all maps.
    pub fn photons(&self) -> usize {
        self.maps
            .iter()
            .map(|(_, m)| m.as_ref().map_or(0, |m| m.len()))
            .sum()
    }
}

impl Irradiance for Maps<'_> {
    fn irradiance(&self, map: MapLookup, p: Vec3, n: Vec3) -> Vec3 {
        let kind = kind_of(map);
        if let (MapKind::Global, Some(c)) = (kind, &self.gather_cache)
            && let Some(e) = c.lookup(p, n)
        {
            return e;
        }
        STATE.with_borrow_mut(|st| {
            let hint = &mut st.hints[kind.slot()];
            self.estimate(kind, p, n, hint, &mut st.scratch).0
        })
    }
}

/// Most photons one map may hold: the kd-tree indexes with u32.
pub const MAX_MAP_PHOTONS: u64 = u32::MAX as u64 - 1;

/// Loads the cached sets `kinds` of `key` from `dir` as photon maps (never traces: a missing
/// set is an error that says to run `trace`).
pub fn load(
    dir: &std::path::Path,
    key: &photons::CacheKey,
    kinds: &[MapKind],
) -> Result<PerKind<Option<PhotonMap>>, String> {
    let mut maps: PerKind<Option<PhotonMap>> = PerKind::default();
    for &kind in kinds {
        let store = photons::cache::open(dir, key, kind)?;
        let path = key.file(dir, kind);
        if store.header().stored > MAX_MAP_PHOTONS {
            return Err(format!(
                "{}: {} photons exceed the {MAX_MAP_PHOTONS} one map can index",
                path.display(),
                store.header().stored
            ));
        }
        if store.header().stored == 0 && kind == MapKind::Global {
            eprintln!(
                "warning: {}: the global photon set is empty",
                path.display()
            );
        }
        // Photon powers from `emit` already carry the 1/N of the emitted count the header
        // records (the photon-power invariant), so the map sums them as they are.
        maps[kind] = Some(PhotonMap::build(store.to_vec(), IndexKind::KdTree));
    }
    Ok(maps)
}
