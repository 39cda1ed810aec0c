//! `final-gather`: the course framework's standard. Direct light by next-event estimation,
//! caustics from the caustic map, indirect light by `[estimate.final_gather] rays` gather rays
//! per sample reading the global map, through an irradiance cache precomputed at every
//! `cache`-th global photon (Christensen 1999; 0 reads the map at every gather hit).

use crate::gather_cache::IrradianceCache;
use crate::rendered::{CountKind, Rendered};
use crate::run::Run;
use film::Class;
use store::MapKind;

pub(super) fn render(run: &Run, progress: &(dyn Fn(u64) + Sync)) -> Result<Rendered, String> {
    let mut inputs = crate::run::photon_inputs(run, true)?;
    let fg = run.settings.estimate.final_gather;
    let spp = run.settings.estimate.spp;
    let t_cache = std::time::Instant::now();
    // Without gather rays nothing reads the cache: do not build it.
    if fg.cache > 0 && fg.rays > 0 {
        // The cache stores exactly what a direct lookup would answer at its points, boundary
        // correction included.
        let maps = &inputs.maps;
        let c = IrradianceCache::build(
            run.scene,
            maps.maps[MapKind::Global].as_ref(),
            fg.cache,
            &|x, n, h, s| maps.estimate(MapKind::Global, x, n, h, s),
        );
        println!(
            "irradiance cache: {} points (every {}th global photon) in {:.2} s",
            c.len(),
            fg.cache,
            t_cache.elapsed().as_secs_f64()
        );
        inputs.maps.gather_cache = Some(c);
    }
    let t_cache = t_cache.elapsed().as_secs_f64();
    let t0 = std::time::Instant::now();
    let film = eye::render_final_gather(
        run.scene,
        &run.render_options(spp),
        fg.rays,
        &inputs.maps,
        progress,
    );
    let seconds = t0.elapsed().as_secs_f64();
    let mut info = crate::run::photon_info(run, &inputs);
    info.insert("gather_rays".into(), fg.rays.into());
    info.insert(
        "gather_cache_stride".into(),
        (fg.cache > 0 && fg.rays > 0).then_some(fg.cache).into(),
    );
    info.insert("time_gather_cache_s".into(), t_cache.into());
    info.insert("time_render_s".into(), seconds.into());
    let (photons, spp_count) = (run.settings.emit.photons, spp as u64);
    Ok(Rendered {
        // Emission and next-event estimation use no photons: weighed by samples; the layers
        // read from photon maps by photon paths.
        layers: crate::run::layers(
            &film,
            spp,
            &[
                ("emitted", &[Class::Emitted], spp_count, CountKind::Spp),
                ("direct", &[Class::Direct], spp_count, CountKind::Spp),
                (
                    "caustic",
                    &[Class::Caustic],
                    photons,
                    CountKind::PhotonPaths,
                ),
                (
                    "indirect",
                    &[Class::Indirect, Class::CausticIndirect],
                    photons,
                    CountKind::PhotonPaths,
                ),
            ],
        )?,
        plan: Some(inputs.plan),
        ..Rendered::new(Vec::new(), info)
    })
}
