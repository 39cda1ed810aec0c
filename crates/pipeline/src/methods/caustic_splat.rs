//! `caustic-splat`: the caustic layers alone (`L S+ D S* E`, D the first diffuse vertex from
//! the eye, and with `[estimate.splat] indirect` the caustics seen through further diffuse
//! bounces) by photon differential splatting onto eye vertices, with no photon map (the
//! course framework's `splat_caustics_map`). `[estimate.splat]` holds its knobs.

use super::{CountKind, Layer, Rendered, Run};
use crate::splat;

/// JSON facts for `image.json`.
type Facts = serde_json::Map<String, serde_json::Value>;

/// The splatted caustic layers (`caustic`, and `caustic_indirect` when the settings follow
/// caustic paths past their first diffuse hit), the passes made and the JSON facts.
pub(super) fn caustic_layers(
    run: &Run,
    progress: &(dyn Fn(u64) + Sync),
) -> Result<(Vec<Layer>, Facts, u32), String> {
    let s = run.settings;
    let sp = &s.estimate.splat;
    let mut params = s.emit.clone();
    if sp.photons > 0 {
        params.photons = sp.photons;
    }
    let (w, h) = (
        run.scene.camera.width as usize,
        run.scene.camera.height as usize,
    );
    let mut images = [vec![glam::DVec3::ZERO; w * h], vec![]];
    if sp.indirect {
        images[1] = vec![glam::DVec3::ZERO; w * h];
    }
    // Passes until the count, or the time budget once a pass has been made. Each pass makes
    // new eye vertices (new pixel samples) and new photons, so the mean over passes
    // converges in both.
    let t_splat = std::time::Instant::now();
    let mut t_vertices = 0.0;
    let mut passes = 0u32;
    let mut max_in_flight = 0;
    let mut vertices = 0;
    while passes < sp.passes {
        let t0 = std::time::Instant::now();
        let eyes = splat::eye_index(run.scene, sp, s.estimate.spp, passes as u64, run.threads);
        t_vertices += t0.elapsed().as_secs_f64();
        vertices += eyes.len();
        let splatter = splat::Splatter {
            scene: run.scene,
            params: &params,
            settings: sp,
            eyes: &eyes,
        };
        let stats = splatter.pass(passes as u64, &mut images, run.threads(), progress)?;
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
    for p in images.iter_mut().flatten() {
        *p /= passes as f64;
    }
    let mut info = serde_json::Map::new();
    for (k, v) in [
        ("splat", serde_json::json!(sp)),
        ("splat_photons_emitted", params.photons.into()),
        ("eye_vertices", vertices.into()),
        (
            "splat_indirect_radius",
            splat::indirect_radius(run.scene, sp).into(),
        ),
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
    let names: &[&'static str] = if sp.indirect {
        &["caustic", "caustic_indirect"]
    } else {
        &["caustic"]
    };
    let layers = names
        .iter()
        .zip(&images)
        .map(|(&name, pixels)| Layer {
            name: name.into(),
            classes: vec![name],
            image: splat::to_image(run.scene, pixels),
            count: passes as u64 * params.photons,
            count_kind: CountKind::PhotonPaths,
        })
        .collect();
    Ok((layers, info, passes))
}

pub(super) fn render(run: &Run, progress: &(dyn Fn(u64) + Sync)) -> Result<Rendered, String> {
    let (layers, info, passes) = caustic_layers(run, progress)?;
    Ok(Rendered {
        layers,
        plan: None,
        info,
        passes: Some(passes),
        snapshots: Vec::new(),
    })
}
