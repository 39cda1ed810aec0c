//! `caustic-splat`: the caustic layer alone (`L S+ D S* E`, D the first diffuse vertex from
//! the eye) by photon differential splatting onto eye vertices, with no photon map (the
//! course framework's `splat_caustics_map`). `[estimate.splat]` holds its knobs.

use super::{CountKind, Layer, Rendered, Run};
use crate::splat::{self, EyeIndex};

/// The splatted caustic layer, its photon count and its JSON facts.
pub(super) fn caustic_layer(
    run: &Run,
    progress: &(dyn Fn(u64) + Sync),
) -> Result<(Layer, serde_json::Map<String, serde_json::Value>), String> {
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
    let (pixels, stats) =
        splat::splat_caustics(run.scene, &params, sp, &eyes, run.threads(), progress)?;
    let mut info = serde_json::Map::new();
    for (k, v) in [
        ("splat", serde_json::json!(sp)),
        ("splat_photons_emitted", params.photons.into()),
        ("eye_vertices", eyes.len().into()),
        ("splat_max_radius", splat::max_radius(run.scene, sp).into()),
        ("time_eye_vertices_s", t_vertices.into()),
        ("time_splat_s", stats.seconds.into()),
        (
            "splat_photons_per_s",
            (params.photons as f64 / stats.seconds).into(),
        ),
    ] {
        info.insert(k.to_string(), v);
    }
    let layer = Layer {
        name: "caustic".into(),
        classes: vec!["caustic"],
        image: splat::to_image(run.scene, &pixels),
        count: params.photons,
        count_kind: CountKind::PhotonPaths,
    };
    Ok((layer, info))
}

pub(super) fn render(run: &Run, progress: &(dyn Fn(u64) + Sync)) -> Result<Rendered, String> {
    let (layer, info) = caustic_layer(run, progress)?;
    Ok(Rendered {
        layers: vec![layer],
        plan: None,
        info,
    })
}
