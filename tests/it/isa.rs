//! The vector path (AVX2: the 8-wide BVH, `BvhKind::Bvh8`) against the baseline (SSE2: the
//! 4-wide BVH, `BvhKind::Bvh4`) on one machine, whichever `PHOTONFLOW_ISA` says: the
//! path tracer's image region by region, as ARCHITECTURE.md promises across instruction sets.

use crate::kit::{Mean, WORKSHEET, rect, region_mean, render_uncached, scene_at, sum_layers};
use geom::{BvhKind, Geometry, Isa};
use glam::DVec3;
use render::Overrides;
use scene::{Method, Scene};

const RES: u32 = 64;
const SEEDS: u64 = 4;
/// Regions of `BLOCK` x `BLOCK` pixels.
const BLOCK: usize = 8;

/// `scene` with its geometry rebuilt as `kind`.
fn with_kind(mut scene: Scene, kind: BvhKind) -> Scene {
    let (mesh, spheres) = (scene.geometry.mesh().clone(), scene.geometry.spheres());
    scene.geometry = Geometry::with_bvh(mesh, spheres.to_vec(), kind);
    assert_eq!(scene.geometry.kind(), kind);
    scene
}

/// Per region, the mean over seeds of the region's mean, and its standard error; and the
/// images' bits.
fn regions(rel: &str, kind: BvhKind) -> (Vec<Mean>, Vec<Vec<[u32; 3]>>) {
    let o = Overrides {
        method: Some(Method::Path),
        spp: Some(16),
        ..Overrides::default()
    };
    let n = RES as usize / BLOCK;
    let mut means = vec![Mean::default(); n * n];
    let mut bits = Vec::new();
    for seed in 1..=SEEDS {
        let scene = with_kind(scene_at(rel, RES, seed, |_| {}), kind);
        let r = render_uncached(&scene, &o, None);
        let img = &sum_layers(&r, |_| true);
        for (i, m) in means.iter_mut().enumerate() {
            let (x, y) = (i % n * BLOCK, i / n * BLOCK);
            m.add(region_mean(img, &rect([x, y, x + BLOCK, y + BLOCK])));
        }
        bits.push(crate::kit::bits(img));
    }
    (means, bits)
}

#[test]
fn the_vector_path_renders_the_baselines_means_in_every_region() {
    if Isa::best() != Isa::Avx2 {
        // Only the baseline runs here: `Bvh8` builds a `Bvh4` (checked in `geom`'s tests).
        return;
    }
    for rel in [WORKSHEET, "cornell-spheres/tessellated.toml"] {
        let (base, base_bits) = regions(rel, BvhKind::Bvh4);
        let (vec, vec_bits) = regions(rel, BvhKind::Bvh8);
        for (i, (b, v)) in base.iter().zip(&vec).enumerate() {
            // Four standard errors of the baseline's mean (the seeds are shared, so the two
            // paths' samples are the same wherever their hits are).
            let (d, se) = ((v.mean() - b.mean()).abs(), b.se());
            assert!(
                d.cmple(4.0 * se + DVec3::splat(1e-6)).all(),
                "{rel}: region {i}: vector {} vs baseline {} +- {se}",
                v.mean(),
                b.mean()
            );
        }
        // Each lane rounds like the baseline's: a pixel differs only where a path met two
        // primitives at the same distance.
        let pixels = base_bits.iter().map(Vec::len).sum::<usize>();
        let same = base_bits
            .iter()
            .flatten()
            .zip(vec_bits.iter().flatten())
            .filter(|(a, b)| a == b)
            .count();
        assert!(
            same as f64 >= 0.99 * pixels as f64,
            "{rel}: {same} of {pixels} pixels bit-identical"
        );
    }
}
