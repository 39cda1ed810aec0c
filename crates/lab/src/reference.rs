//! The one path-traced reference the studies share (`worksheet`, `evidence`, `bench
//! accuracy`): a given linear EXR, checked against the scene, or a path-traced image rendered
//! once into a directory named by what it depends on and reused while those settings hold.
//! That directory is a run directory, published whole (`render::output::Staged`): one that
//! exists is complete, whenever a run writing it stopped.

use render::{Overrides, Photons, RenderRequest, Settings};
use scene::{Method, Scene};
use std::path::{Path, PathBuf};

/// A reference's image and, for one photonflow rendered, its run directory (`image.json`
/// beside it, and `layers/` with the caustic layer).
pub struct Reference {
    pub exr: PathBuf,
    pub run: Option<PathBuf>,
}

/// The reference given as two independent halves `a` and `b` (other seeds, one budget), each
/// checked against `scene`; their mean is what every run's plain errors are measured against.
pub fn halves(scene: &Scene, a: &Path, b: &Path) -> Result<film::Halves, String> {
    film::Halves::new(
        &render::read_reference(scene, a)?,
        &render::read_reference(scene, b)?,
    )
    .map_err(|e| format!("{} and {}: {e}", a.display(), b.display()))
}

/// `given`, checked against `scene` before anything is written; else `scene` path-traced at
/// `spp` samples per pixel (caustics included) into `dir/reference-<settings hash>-<spp>spp`,
/// reused when that directory's `image.json` was written for the same settings hash (scene
/// view, seed and every setting), so a changed scene or budget renders a new one.
pub fn reference(
    scene: &Scene,
    given: Option<&Path>,
    spp: u32,
    dir: &Path,
    threads: Option<usize>,
) -> Result<Reference, String> {
    if let Some(p) = given {
        render::read_reference(scene, p)?;
        return Ok(Reference {
            exr: p.to_path_buf(),
            run: None,
        });
    }
    let overrides = Overrides {
        method: Some(Method::Path),
        spp: Some(spp),
        caustics: Some(true),
        ..Overrides::default()
    };
    let hash = Settings::new(scene, &overrides)?.hash(scene);
    let run = dir.join(format!("reference-{hash:016x}-{spp}spp"));
    let exr = run.join("image.exr");
    let reusable = std::fs::read_to_string(run.join("image.json"))
        .ok()
        .and_then(|t| serde_json::from_str::<serde_json::Value>(&t).ok())
        .is_some_and(|j| j["settings_hash"] == format!("{hash:016x}"));
    if reusable && exr.is_file() {
        println!("reference: {} (cached)", exr.display());
    } else {
        println!("reference: path tracing {spp} spp into {}", run.display());
        render::render(
            scene,
            &RenderRequest {
                overrides,
                // The path tracer reads no photons.
                cache: dir,
                photons: Photons::CacheOnly,
                threads,
                out: run.clone(),
                exposure: 0.0,
                reference: None,
                label: None,
            },
        )?;
    }
    Ok(Reference {
        exr,
        run: Some(run),
    })
}
