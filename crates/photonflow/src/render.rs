//! `render` (path-traced reference or a layer set of it) and `compare`.

use crate::progress::Progress;
use film::{Image, Mask, Normalize, ToneMap};
use std::path::{Path, PathBuf};

pub struct RenderArgs {
    pub scene: PathBuf,
    pub spp: Option<u32>,
    pub no_caustics: bool,
    pub threads: Option<usize>,
    pub out: Option<PathBuf>,
    pub exposure: f32,
}

/// Default output directory: `out/<scene file stem>-<method>`.
pub fn default_out(scene: &Path, method: &str) -> PathBuf {
    let stem = scene
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "scene".into());
    let parent = scene
        .parent()
        .and_then(|p| p.file_name())
        .map(|s| s.to_string_lossy().into_owned());
    let name = match parent {
        Some(p) if !p.is_empty() => format!("{p}-{stem}"),
        _ => stem,
    };
    PathBuf::from("out").join(format!("{name}-{method}"))
}

pub fn path(a: RenderArgs) -> Result<(), String> {
    let s = scene::Scene::load(&a.scene).map_err(|e| e.to_string())?;
    let spp = a.spp.unwrap_or(s.render().spp);
    if spp == 0 || spp > 1 << 24 {
        return Err(format!("--spp {spp} must be in 1..=16777216"));
    }
    if a.threads == Some(0) {
        return Err("--threads must be at least 1".into());
    }
    let out = a.out.unwrap_or_else(|| default_out(&a.scene, "path"));
    let (w, h) = (s.camera.width as u64, s.camera.height as u64);
    let opts = eye::RenderOptions {
        spp,
        caustics: !a.no_caustics,
        threads: a.threads,
        tile: s.render().tile,
    };
    let threads = a.threads.unwrap_or_else(rayon::current_num_threads);
    let progress = Progress::new("path", w * h * spp as u64, "samples");
    let film = eye::render(&s, &opts, &|n| progress.inc(n));
    let secs = progress.finish();
    let samples = w * h * spp as u64;

    let mut layers: Vec<(String, Image)> = Vec::new();
    for name in film.layer_names() {
        let img = film
            .layer(name)
            .expect("listed layer exists")
            .resolve(Normalize::Constant(spp as f64));
        layers.push((name.to_string(), img));
    }
    let image = write_outputs(&out, &layers, a.exposure)?;
    let tone = ToneMap {
        exposure: a.exposure,
        ..ToneMap::default()
    };
    let json = serde_json::json!({
        "scene": a.scene.display().to_string(),
        "scene_hash": format!("{:016x}", s.content_hash),
        "image_hash": format!("{:016x}", s.image_hash),
        "photon_hash": format!("{:016x}", s.photon_hash),
        "method": "path",
        "spp": spp,
        "caustics": !a.no_caustics,
        "seed": s.seed(),
        "width": w,
        "height": h,
        "threads": threads,
        "max_depth": s.render().max_depth,
        "rr_depth": s.render().rr_depth,
        "time_s": secs,
        "samples": samples,
        "samples_per_s": samples as f64 / secs,
        "layers": layers.iter().map(|(n, _)| n.clone()).collect::<Vec<_>>(),
        "tone_map": { "gamma": tone.gamma, "exposure": tone.exposure },
    });
    let text = serde_json::to_string_pretty(&json).map_err(|e| e.to_string())? + "\n";
    film::write_atomic(&out.join("image.json"), text.as_bytes()).map_err(|e| e.to_string())?;
    println!(
        "rendered {}x{} at {spp} spp in {secs:.2} s ({:.3} M samples/s on {threads} threads)",
        w,
        h,
        samples as f64 / secs / 1e6
    );
    println!(
        "wrote {}/image.exr (linear), image.png (gamma {}), layers/ and image.json",
        out.display(),
        tone.gamma
    );
    let _ = image;
    Ok(())
}

/// Writes the sum of `layers` as `image.exr` (linear) and `image.png` (tone-mapped), and each
/// layer as `layers/<name>.exr`; returns the sum.
pub fn write_outputs(
    out: &Path,
    layers: &[(String, Image)],
    exposure: f32,
) -> Result<Image, String> {
    let parts: Vec<(&Image, f32)> = layers.iter().map(|(_, i)| (i, 1.0)).collect();
    let image = film::composite(&parts).map_err(|e| e.to_string())?;
    let tone = ToneMap {
        exposure,
        ..ToneMap::default()
    };
    std::fs::create_dir_all(out.join("layers"))
        .map_err(|e| format!("{}: cannot create output directory: {e}", out.display()))?;
    film::write_exr(out.join("image.exr"), &image).map_err(|e| e.to_string())?;
    film::write_png(out.join("image.png"), &image, &tone).map_err(|e| e.to_string())?;
    for (name, img) in layers {
        film::write_exr(out.join("layers").join(format!("{name}.exr")), img)
            .map_err(|e| e.to_string())?;
    }
    Ok(image)
}

pub fn compare(a: &Path, b: &Path, mask: Option<[usize; 4]>) -> Result<(), String> {
    let ia = film::read_exr(a).map_err(|e| e.to_string())?;
    let ib = film::read_exr(b).map_err(|e| e.to_string())?;
    let mask = mask.map(|[x0, y0, x1, y1]| Mask::rect(ia.width, ia.height, x0, y0, x1, y1));
    let m = film::metrics(&ia, &ib, mask.as_ref()).map_err(|e| e.to_string())?;
    println!("{m}");
    Ok(())
}
