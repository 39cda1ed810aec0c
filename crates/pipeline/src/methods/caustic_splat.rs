//! `caustic-splat`: the caustic layer alone (`L S+ D S* E`, D the first diffuse vertex from
//! the eye) by photon differential splatting onto eye vertices, with no photon map (the
//! course framework's `splat_caustics_map`). `[estimate.splat]` holds its knobs.

use super::{CountKind, Layer, Rendered, Run};
use crate::splat::{self, EyeIndex};

/// The splatted caustic layer, its photon count and its JSON facts.
pub(super) fn caustic_layer(
    run: &Run,
    progress: &(dyn Fn(u64) + Sync),
) -> Result<(Layer, serde_json::Map<String, serde_json::Value>, u32), String> {
    let s = run.settings;
    let sp = &s.estimate.splat;
    let mut params = s.emit.clone();
    if sp.photons > 0 {
        params.photons = sp.photons;
    }
    let t0 = std::time::Instant::now();
    let vertices = eye::eye_vertices(
        run.scene,
        &eye::VertexOptions {
            spp: s.estimate.spp,
            splits: sp.splits,
            threads: run.threads,
        },
    );
    let eyes = EyeIndex::new(vertices);
    let t_vertices = t0.elapsed().as_secs_f64();
    let (w, h) = (
        run.scene.camera.width as usize,
        run.scene.camera.height as usize,
    );
    let mut pixels = vec![glam::DVec3::ZERO; w * h];
    // Passes until the count, or the time budget once a pass has been made.
    let t_splat = std::time::Instant::now();
    let mut passes = 0u32;
    let mut max_in_flight = 0;
    let splatter = splat::Splatter {
        scene: run.scene,
        params: &params,
        settings: sp,
        eyes: &eyes,
    };
    while passes < sp.passes {
        let stats = splatter.pass(passes as u64, &mut pixels, run.threads(), progress)?;
        max_in_flight = max_in_flight.max(stats.max_in_flight);
        passes += 1;
        let elapsed = t_splat.elapsed().as_secs_f64();
        if sp.passes > 1 {
            eprintln!(
                "splat pass {passes}/{}: {:.2} s, {:.3} M photons/s",
                sp.passes,
                elapsed,
                (passes as u64 * params.photons) as f64 / elapsed / 1e6
            );
        }
        if s.time.is_some_and(|t| elapsed >= t) {
            break;
        }
    }
    let seconds = t_splat.elapsed().as_secs_f64();
    for p in &mut pixels {
        *p /= passes as f64;
    }
    let mut info = serde_json::Map::new();
    for (k, v) in [
        ("splat", serde_json::json!(sp)),
        ("splat_photons_emitted", params.photons.into()),
        ("eye_vertices", eyes.len().into()),
        ("splat_max_radius", splat::max_radius(run.scene, sp).into()),
        ("splat_passes", passes.into()),
        ("splat_max_chunks_in_flight", max_in_flight.into()),
        ("time_eye_vertices_s", t_vertices.into()),
        ("time_splat_s", seconds.into()),
        (
            "splat_photons_per_s",
            ((passes as u64 * params.photons) as f64 / seconds).into(),
        ),
    ] {
        info.insert(k.to_string(), v);
    }
    let layer = Layer {
        name: "caustic".into(),
        classes: vec!["caustic"],
        image: splat::to_image(run.scene, &pixels),
        count: passes as u64 * params.photons,
        count_kind: CountKind::PhotonPaths,
    };
    Ok((layer, info, passes))
}

pub(super) fn render(run: &Run, progress: &(dyn Fn(u64) + Sync)) -> Result<Rendered, String> {
    let (layer, info, passes) = caustic_layer(run, progress)?;
    Ok(Rendered {
        layers: vec![layer],
        plan: None,
        info,
        passes: Some(passes),
    })
}
