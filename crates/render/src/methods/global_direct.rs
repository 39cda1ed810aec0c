//! `global-direct`: the global photon map shown directly at the first diffuse surface seen
//! from the eye (worksheet 7's visualisation), with the `[estimate]` kernel, topological test
//! and boundary correction.

use crate::rendered::{CountKind, Rendered};
use crate::run::Run;
use film::Class;

pub(super) fn render(run: &Run, progress: &(dyn Fn(u64) + Sync)) -> Result<Rendered, String> {
    let inputs = crate::run::photon_inputs(run, false)?;
    let spp = run.settings.estimate.spp;
    let t0 = std::time::Instant::now();
    let film =
        eye::render_global_direct(run.scene, &run.render_options(spp), &inputs.maps, progress);
    let seconds = t0.elapsed().as_secs_f64();
    let mut info = crate::run::photon_info(run, &inputs);
    info.insert("time_render_s".into(), seconds.into());
    let photons = run.settings.emit.photons;
    Ok(Rendered {
        layers: crate::run::layers(
            &film,
            spp,
            &[
                ("emitted", &[Class::Emitted], spp as u64, CountKind::Spp),
                (
                    "global",
                    &[
                        Class::Direct,
                        Class::Indirect,
                        Class::Caustic,
                        Class::CausticIndirect,
                    ],
                    photons,
                    CountKind::PhotonPaths,
                ),
            ],
        )?,
        plan: Some(inputs.plan),
        ..Rendered::new(Vec::new(), info)
    })
}
