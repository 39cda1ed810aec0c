//! `composite`: combines the output directories of separate runs of one view (the rules are
//! the `composite` crate's: layers of one name averaged by count, disjoint layers summed) and
//! writes the result as a run directory of its own, which can be composited again.
//!
//! Paths inside this module name the crate as `::composite`, because this module has the
//! crate's name.

use film::ToneMap;
use std::path::{Path, PathBuf};

/// Reads every input, composites them and writes `image.exr` (linear), `image.png`
/// (tone-mapped with `exposure` stops), `layers/<name>.exr` and `image.json` into `out`.
/// An input is a run's output directory or its `image.exr` (or `image.json`). Nothing is
/// written unless every input reads and the inputs combine.
pub fn run(inputs: &[PathBuf], out: &Path, exposure: f32) -> Result<(), String> {
    if !exposure.is_finite() {
        return Err(format!("--exposure {exposure} must be finite"));
    }
    if inputs.is_empty() {
        return Err("composite: no inputs given".into());
    }
    let mut dirs = Vec::with_capacity(inputs.len());
    for p in inputs {
        dirs.push(run_dir(p)?);
    }
    refuse_overwriting_an_input(&dirs, out)?;
    render::output::check_out(out)?;
    let mut loaded = Vec::with_capacity(dirs.len());
    for d in &dirs {
        loaded.push(load(d)?);
    }
    let c = ::composite::composite(loaded)?;
    write(&c, out, exposure)?;

    let layers: Vec<String> = c
        .layers
        .iter()
        .map(|l| {
            let classes: Vec<&str> = l.classes.iter().map(|c| c.name()).collect();
            format!(
                "{} [{}] {} {} from {}",
                l.name,
                classes.join(", "),
                l.count,
                l.count_kind,
                l.inputs.len()
            )
        })
        .collect();
    println!(
        "composited {} runs of {}x{}: {}",
        c.inputs.len(),
        c.width,
        c.height,
        layers.join("; ")
    );
    if !c.missing.is_empty() {
        let missing: Vec<&str> = c.missing.iter().map(|c| c.name()).collect();
        println!(
            "missing: no input estimates {}; the image lacks that light",
            missing.join(", ")
        );
    }
    println!(
        "wrote {}/image.exr (linear), image.png (gamma {}), layers/ and image.json",
        out.display(),
        ToneMap::default().gamma
    );
    Ok(())
}

/// The run directory `p` names: `p` itself, or the directory of its `image.exr` or
/// `image.json`.
fn run_dir(p: &Path) -> Result<PathBuf, String> {
    if p.is_dir() {
        return Ok(p.to_path_buf());
    }
    match p.file_name().and_then(|n| n.to_str()) {
        Some("image.exr" | "image.json") => Ok(match p.parent() {
            Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
            _ => PathBuf::from("."),
        }),
        _ => Err(format!(
            "{}: not a run's output directory or the image.exr in one",
            p.display()
        )),
    }
}

/// Writing into an input's directory would replace the run it holds.
fn refuse_overwriting_an_input(dirs: &[PathBuf], out: &Path) -> Result<(), String> {
    let Ok(out_c) = std::fs::canonicalize(out) else {
        return Ok(()); // `out` does not exist yet, so it is no input
    };
    for d in dirs {
        if std::fs::canonicalize(d).is_ok_and(|c| c == out_c) {
            return Err(format!(
                "{}: the output directory is an input; choose another --out",
                out.display()
            ));
        }
    }
    Ok(())
}

/// One run: its `image.json` and the EXR of each layer it lists.
fn load(dir: &Path) -> Result<::composite::Input, String> {
    let json_path = dir.join("image.json");
    // Only regular files are opened: a FIFO would block.
    if std::fs::metadata(&json_path).is_ok_and(|m| !m.is_file()) {
        return Err(format!("{}: not a regular file", json_path.display()));
    }
    let text = std::fs::read_to_string(&json_path)
        .map_err(|e| format!("{}: cannot read: {e}", json_path.display()))?;
    let meta =
        ::composite::Meta::from_json(&text).map_err(|e| format!("{}: {e}", json_path.display()))?;
    let mut layers = Vec::with_capacity(meta.layers.len());
    for l in &meta.layers {
        // Layer names are checked to be plain file names ([A-Za-z0-9_-]+) by `from_json`.
        let path = dir.join("layers").join(format!("{}.exr", l.name));
        let img = render::output::read_exr(&path)?;
        layers.push((l.name.clone(), img));
    }
    Ok(::composite::Input {
        label: dir.display().to_string(),
        meta,
        layers,
    })
}

/// Writes the directory whole in a staging directory and renames it into place.
fn write(c: &::composite::Composite, out: &Path, exposure: f32) -> Result<(), String> {
    let tone = ToneMap {
        exposure,
        ..ToneMap::default()
    };
    let mut json = c.json();
    json["tone_map"] = serde_json::json!({ "gamma": tone.gamma, "exposure": tone.exposure });
    let text = serde_json::to_string_pretty(&json).map_err(|e| e.to_string())? + "\n";

    let staged = render::output::stage(out)?;
    let dir = staged.path();
    let layers = dir.join("layers");
    std::fs::create_dir(&layers)
        .map_err(|e| format!("{}: cannot create: {e}", layers.display()))?;
    for l in &c.layers {
        film::write_exr(layers.join(format!("{}.exr", l.name)), &l.image)
            .map_err(|e| e.to_string())?;
    }
    film::write_exr(dir.join("image.exr"), &c.image).map_err(|e| e.to_string())?;
    film::write_png(dir.join("image.png"), &c.image, &tone).map_err(|e| e.to_string())?;
    film::write_atomic(&dir.join("image.json"), text.as_bytes()).map_err(|e| e.to_string())?;
    staged.publish()
}
