//! Precomputed irradiance for final gathering (Christensen 1999, "Faster photon map global
//! illumination", JGT 4(1)): estimate irradiance once at every `stride`-th photon of the
//! global map, then answer each final-gather lookup with the nearest precomputed point on a
//! surface facing the same way. Final gathering averages many such lookups, which hides the
//! piecewise-constant approximation; a k = 1000 estimate per gather ray would cost ~50x more.

use density::{Index, IndexKind, KnnHint, MapPhoton, Neighbor, PhotonMap};
use glam::Vec3;
use rayon::prelude::*;
use scene::Scene;
use std::cell::RefCell;

pub struct IrradianceCache {
    index: Index,
    normals: Vec<Vec3>,
    irradiance: Vec<Vec3>,
    /// Radius of each point's own estimate: a lookup farther away than that is not answered
    /// by this point (Christensen 1999 uses the same bound).
    radius: Vec<f32>,
}

/// An irradiance estimate at a point with a normal, returning `(E, radius used)`.
pub type Estimator<'a> =
    dyn Fn(Vec3, Vec3, &mut KnnHint, &mut Vec<Neighbor>) -> (Vec3, f32) + Sync + 'a;

/// Unit normal of the surface a photon landed on, turned towards the side it arrived from.
fn photon_normal(scene: &Scene, p: &MapPhoton) -> Option<Vec3> {
    let n = scene.surface_normal(p.surface, p.position)?;
    Some(if n.dot(p.direction) > 0.0 { -n } else { n })
}

impl IrradianceCache {
    /// Precomputes irradiance with `estimate` at every `stride`-th photon of `map` (in the
    /// map's spatial order, so consecutive queries are neighbours and the k-NN hint pays
    /// off). Deterministic: each value depends only on its point, whatever the thread count.
    pub fn build(
        scene: &Scene,
        map: Option<&PhotonMap>,
        stride: usize,
        estimate: &Estimator,
    ) -> Self {
        let picked: Vec<(Vec3, Vec3)> = map
            .into_iter()
            .flat_map(|m| m.iter())
            .step_by(stride.max(1))
            .filter_map(|p| Some((p.position, photon_normal(scene, &p)?)))
            .collect();
        let values: Vec<(Vec3, f32)> = picked
            .par_chunks(1024)
            .flat_map_iter(|chunk| {
                let mut hint = KnnHint::NONE;
                let mut scratch = Vec::new();
                chunk
                    .iter()
                    .map(|&(x, n)| estimate(x, n, &mut hint, &mut scratch))
                    .collect::<Vec<_>>()
            })
            .collect();
        let points: Vec<[f32; 3]> = picked.iter().map(|(p, _)| p.to_array()).collect();
        IrradianceCache {
            index: Index::build(IndexKind::KdTree, &points),
            normals: picked.iter().map(|(_, n)| *n).collect(),
            irradiance: values.iter().map(|v| v.0).collect(),
            radius: values.iter().map(|v| v.1).collect(),
        }
    }

    pub fn len(&self) -> usize {
        self.irradiance.len()
    }

    pub fn is_empty(&self) -> bool {
        self.irradiance.is_empty()
    }

    /// Irradiance of the nearest precomputed point (among the 8 nearest) whose normal is
    /// within ~25 degrees of `n` and whose own estimate radius reaches `x`; `None` if there is
    /// none, and the caller estimates from the map instead.
    pub fn lookup(&self, x: Vec3, n: Vec3) -> Option<Vec3> {
        thread_local! {
            static SCRATCH: RefCell<Vec<Neighbor>> = const { RefCell::new(Vec::new()) };
        }
        SCRATCH.with_borrow_mut(|s| {
            self.index.knn(x, 8, f32::INFINITY, s);
            s.iter()
                .find(|nb| {
                    let i = nb.index as usize;
                    self.normals[i].dot(n) > 0.9 && nb.d2 <= self.radius[i] * self.radius[i]
                })
                .map(|nb| self.irradiance[nb.index as usize])
        })
    }
}
