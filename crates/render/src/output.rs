//! A run's output directory: `image.exr` (linear), `image.png` (tone-mapped), `layers/`,
//! `image.json` (settings, counts, layer classes, timings, errors against a reference) and
//! `scene.toml`, the resolved scene file that reproduces the run bit for bit. Everything that
//! can fail (the reference, the settings' serialisation) is checked before the first byte is
//! written. The directory is written whole in a staging directory beside it and renamed into
//! place ([`Staged`]): under its name there is the old run or the new one, never half of one,
//! whenever the process stops (an error, a signal, kill -9).

use crate::rendered::Rendered;
use crate::settings::Settings;
use film::{Image, Mask, ToneMap};
use scene::Scene;
use std::path::Path;

/// How to write a run.
pub struct OutputOptions<'a> {
    pub out: &'a Path,
    pub exposure: f32,
    /// Compare with this linear image (read from the path) and record the errors.
    pub reference: Option<(&'a Path, &'a Image)>,
    /// Recorded as `label` (the output directory's method part).
    pub label: &'a str,
    pub threads: usize,
    pub seconds: f64,
}

/// Writes `r` into `o.out`; returns the image (the sum of the layers) and the metrics
/// against the reference, if any.
pub fn write(
    scene: &Scene,
    settings: &Settings,
    r: &Rendered,
    o: &OutputOptions,
) -> Result<(Image, Option<film::Metrics>), String> {
    if !o.exposure.is_finite() {
        return Err(format!("--exposure {} must be finite", o.exposure));
    }
    let parts: Vec<(&Image, f32)> = r.layers.iter().map(|l| (&l.image, 1.0)).collect();
    let image = film::composite(&parts).map_err(|e| e.to_string())?;
    let metrics = match o.reference {
        Some((p, reference)) => Some(
            film::metrics(&image, reference, None).map_err(|e| format!("{}: {e}", p.display()))?,
        ),
        None => None,
    };
    // A run stopped by a time budget is reproduced by the passes it made.
    let settings = &settings.with_made(r);
    let scene_text = settings.resolved_scene_text(scene)?;
    let tone = ToneMap {
        exposure: o.exposure,
        ..ToneMap::default()
    };
    // Snapshots of a progressive run: each image with its passes, seconds and, against the
    // reference, its error; one run gives an error-against-time series.
    let mut snapshot_images = Vec::new();
    let mut snapshots = Vec::new();
    for snap in &r.snapshots {
        let parts: Vec<(&Image, f32)> = snap.layers.iter().map(|l| (&l.image, 1.0)).collect();
        let img = film::composite(&parts).map_err(|e| e.to_string())?;
        let m = match o.reference {
            Some((p, reference)) => Some(
                film::metrics(&img, reference, None)
                    .map_err(|e| format!("{}: {e}", p.display()))?,
            ),
            None => None,
        };
        let file = format!("snapshots/pass-{:05}.exr", snap.passes);
        snapshots.push(serde_json::json!({
            "passes": snap.passes,
            "seconds": snap.seconds,
            "image": file,
            "relmse": m.as_ref().map(|m| m.relmse),
            "rmse": m.as_ref().map(|m| m.rmse),
        }));
        snapshot_images.push((file, img));
    }
    // The compositing contract first, through the type that reads it back; then the run's
    // facts beside it.
    let meta = composite::Meta {
        view_hash: format!("{:016x}", scene.view_hash),
        width: image.width,
        height: image.height,
        layers: r
            .layers
            .iter()
            .map(|l| composite::LayerMeta {
                name: l.name.clone(),
                classes: l.classes.clone(),
                count: l.count as f64,
                count_kind: l.count_kind,
            })
            .collect(),
        seed: Some(scene.seed()),
    };
    meta.validate()
        .map_err(|e| format!("{}: the run's layers: {e}", o.out.display()))?;
    let mut json = meta.to_json();
    if let Some(obj) = json.as_object_mut() {
        for (k, v) in [
            ("scene", scene.path.display().to_string().into()),
            ("scene_hash", format!("{:016x}", scene.content_hash).into()),
            ("image_hash", format!("{:016x}", scene.image_hash).into()),
            ("photon_hash", format!("{:016x}", scene.photon_hash).into()),
            (
                "settings_hash",
                format!("{:016x}", settings.hash(scene)).into(),
            ),
            ("method", settings.method.name().into()),
            ("label", o.label.into()),
            ("threads", o.threads.into()),
            ("time_total_s", o.seconds.into()),
            (
                "tone_map",
                serde_json::json!({ "gamma": tone.gamma, "exposure": tone.exposure }),
            ),
            (
                "reference",
                o.reference.map(|(p, _)| p.display().to_string()).into(),
            ),
            ("rmse", metrics.as_ref().map(|m| m.rmse).into()),
            ("relmse", metrics.as_ref().map(|m| m.relmse).into()),
            ("mae", metrics.as_ref().map(|m| m.mae).into()),
            ("mean", metrics.as_ref().map(|m| m.mean_a).into()),
            ("mean_reference", metrics.as_ref().map(|m| m.mean_b).into()),
        ] {
            obj.insert(k.to_string(), v);
        }
        for (k, v) in &r.info {
            obj.insert(k.clone(), v.clone());
        }
        if !snapshots.is_empty() {
            obj.insert(
                "snapshots".into(),
                serde_json::Value::Array(snapshots.clone()),
            );
        }
    }
    let json_text = serde_json::to_string_pretty(&json).map_err(|e| e.to_string())? + "\n";

    let staged = stage(o.out)?;
    // Errors name the files by the place they were going to (the staging directory is
    // removed).
    write_files(
        &staged,
        &image,
        &tone,
        r,
        &snapshot_images,
        &scene_text,
        &json_text,
    )
    .map_err(|e| staged.named(e))?;
    staged.publish()?;
    Ok((image, metrics))
}

fn write_files(
    staged: &Staged,
    image: &Image,
    tone: &ToneMap,
    r: &Rendered,
    snapshot_images: &[(String, Image)],
    scene_text: &str,
    json_text: &str,
) -> Result<(), String> {
    let out = staged.path();
    let mkdir = |d: &Path| {
        std::fs::create_dir(d).map_err(|e| format!("{}: cannot create: {e}", d.display()))
    };
    mkdir(&out.join("layers"))?;
    film::write_exr(out.join("image.exr"), image).map_err(|e| e.to_string())?;
    film::write_png(out.join("image.png"), image, tone).map_err(|e| e.to_string())?;
    for l in &r.layers {
        film::write_exr(out.join("layers").join(format!("{}.exr", l.name)), &l.image)
            .map_err(|e| e.to_string())?;
    }
    if !snapshot_images.is_empty() {
        mkdir(&out.join("snapshots"))?;
    }
    for (file, img) in snapshot_images {
        film::write_exr(out.join(file), img).map_err(|e| e.to_string())?;
    }
    let w = |name: &str, bytes: &[u8]| {
        film::write_atomic(&out.join(name), bytes).map_err(|e| e.to_string())
    };
    w("scene.toml", scene_text.as_bytes())?;
    if let Some(plan) = &r.plan {
        w("plan.txt", plan.to_string().as_bytes())?;
    }
    w("image.json", json_text.as_bytes())?;
    Ok(())
}

/// What a run directory holds (and all it may hold to be replaced by another run).
pub const RUN_FILES: [&str; 7] = [
    "image.exr",
    "image.png",
    "image.json",
    "scene.toml",
    "plan.txt",
    "layers",
    "snapshots",
];

/// A kind of output directory that is written whole and replaced whole: what it is called in
/// messages and the names it may hold (anything else there is the user's, and refused).
#[derive(Clone, Copy)]
pub struct Layout {
    /// "a run directory", "an evidence directory", ...
    pub what: &'static str,
    /// The flag that names it, for the message that refuses one.
    pub flag: &'static str,
    /// Whether a name directly inside belongs to this kind of directory.
    pub holds: fn(&str) -> bool,
}

/// A run's output directory ([`RUN_FILES`]).
pub const RUN: Layout = Layout {
    what: "a run directory",
    flag: "--out",
    holds: |name| RUN_FILES.contains(&name),
};

/// Refuses `out` unless a run directory may go there: absent, empty, or a run directory
/// (only [`RUN_FILES`] and temps), which the new one replaces whole. Anything else there
/// (a directory of the user's, the photon cache) is never removed.
pub fn check_out(out: &Path) -> Result<(), String> {
    check_layout(out, &RUN)
}

/// Refuses `out` unless a directory of `layout` may go there: absent, empty, or holding only
/// the names `layout` holds and temps (which the new one replaces whole).
pub fn check_layout(out: &Path, layout: &Layout) -> Result<(), String> {
    if out.file_name().is_none() {
        return Err(format!(
            "{}: {} needs a directory name",
            out.display(),
            layout.flag
        ));
    }
    let entries = match std::fs::read_dir(out) {
        Ok(e) => e,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(()),
        Err(e) if e.kind() == std::io::ErrorKind::NotADirectory => {
            return Err(format!("{}: exists and is not a directory", out.display()));
        }
        Err(e) => return Err(format!("{}: cannot read: {e}", out.display())),
    };
    for e in entries {
        let e = e.map_err(|e| format!("{}: cannot read: {e}", out.display()))?;
        let name = e.file_name();
        let name = name.to_string_lossy();
        if !(layout.holds)(&name) && temps::owner(&name).is_none() {
            return Err(format!(
                "{}: exists and is not {} (it holds `{name}`), which a run replaces whole; \
                 choose another {}",
                out.display(),
                layout.what,
                layout.flag
            ));
        }
    }
    Ok(())
}

/// An output directory being written: a staging directory beside its place, renamed into it
/// by [`Staged::publish`] (replacing the old one whole), removed if dropped before (an
/// error, Ctrl-C); one a killed process left is removed by the next run writing there.
pub struct Staged {
    tmp: temps::Temp,
    out: std::path::PathBuf,
    layout: Layout,
}

/// Starts writing the run directory `out` ([`check_out`] first).
pub fn stage(out: &Path) -> Result<Staged, String> {
    stage_as(out, &RUN)
}

/// Starts writing the directory `out` of `layout` ([`check_layout`] first).
pub fn stage_as(out: &Path, layout: &Layout) -> Result<Staged, String> {
    check_layout(out, layout)?;
    let (tmp, stale) = temps::Temp::stage(out).map_err(|e| {
        format!(
            "{}: cannot create a staging directory beside it: {e}",
            out.display()
        )
    })?;
    for s in stale {
        eprintln!("{s}");
    }
    Ok(Staged {
        tmp,
        out: out.to_path_buf(),
        layout: *layout,
    })
}

impl Staged {
    /// Where to write the directory's files.
    pub fn path(&self) -> &Path {
        self.tmp.path()
    }

    /// `e` with the staging directory's path replaced by the published directory's, for a
    /// message.
    pub fn named(&self, e: String) -> String {
        e.replace(
            &self.tmp.path().display().to_string(),
            &self.out.display().to_string(),
        )
    }

    /// Renames it into place, replacing the directory there. The old one, set aside, is
    /// removed; where part of it cannot be (a read-only mount inside it), a warning names it
    /// and the OS error: the new directory is whole all the same.
    pub fn publish(self) -> Result<(), String> {
        check_layout(&self.out, &self.layout)?;
        let stuck = self
            .tmp
            .replace(&self.out)
            .map_err(|e| format!("{}: cannot rename into place: {e}", self.out.display()))?;
        if let Some(s) = stuck {
            eprintln!(
                "warning: {}: the directory it replaced, set aside as {}, cannot be removed: \
                 {} (a later run into {} removes it once it can)",
                self.out.display(),
                s.path.display(),
                s.error,
                self.out.display()
            );
        }
        Ok(())
    }
}

/// FLIP of image `a` against the reference `b` inside `mask` (a rectangle, as `compare`'s).
pub fn compare_flip(a: &Image, b: &Image, mask: Option<[usize; 4]>) -> Result<f64, String> {
    let mask = mask.map(|[x0, y0, x1, y1]| Mask::rect(a.width, a.height, x0, y0, x1, y1));
    let map = film::flip(a, b, 1.0).map_err(|e| e.to_string())?;
    map.mean(mask.as_ref())
        .map_err(|e| e.to_string())?
        .ok_or_else(|| "the mask selects no pixel".to_string())
}

/// A linear EXR to compare, refused if it holds NaN or infinity (errors against it would be
/// NaN); `what` names its pixels in the message ("pixels", "reference pixels").
pub fn read_finite(p: &Path, what: &str) -> Result<Image, String> {
    let img = read_exr(p)?;
    let bad = img
        .data
        .iter()
        .filter(|px| !px.iter().all(|c| c.is_finite()))
        .count();
    if bad > 0 {
        return Err(format!(
            "{}: {bad} of {} {what} are not finite (NaN or infinity): errors against it are \
             undefined",
            p.display(),
            img.data.len()
        ));
    }
    Ok(img)
}

/// `mask` as a mask of `img` (read from `p`), refused when empty or reaching outside the image
/// (clipping it silently would measure another region).
pub fn mask_of(p: &Path, img: &Image, mask: Option<[usize; 4]>) -> Result<Option<Mask>, String> {
    match mask {
        Some([x0, y0, x1, y1]) => {
            if !(x0 < x1 && y0 < y1 && x1 <= img.width && y1 <= img.height) {
                return Err(format!(
                    "{}: --mask {x0},{y0},{x1},{y1} is not a non-empty rectangle inside the \
                     {}x{} image (x0 < x1 <= width, y0 < y1 <= height)",
                    p.display(),
                    img.width,
                    img.height
                ));
            }
            Ok(Some(Mask::rect(img.width, img.height, x0, y0, x1, y1)))
        }
        None => Ok(None),
    }
}

/// Error metrics of image `a` against reference `b` (linear EXR files), inside `mask`.
pub fn compare(a: &Path, b: &Path, mask: Option<[usize; 4]>) -> Result<film::Metrics, String> {
    let (ia, ib) = (read_finite(a, "pixels")?, read_finite(b, "pixels")?);
    let mask = mask_of(a, &ia, mask)?;
    film::metrics(&ia, &ib, mask.as_ref()).map_err(|e| format!("{}: {e}", b.display()))
}

/// Error metrics of image `a` against a reference given as two independent halves `b1` and
/// `b2` (other seeds, one budget), plain and with the reference's noise taken out
/// (`film::Halves`), inside `mask`; and the halves' mean, for FLIP.
pub fn compare_halves(
    a: &Path,
    b1: &Path,
    b2: &Path,
    mask: Option<[usize; 4]>,
) -> Result<(film::HalvesMetrics, Image), String> {
    let ia = read_finite(a, "pixels")?;
    let halves = film::Halves::new(&read_finite(b1, "pixels")?, &read_finite(b2, "pixels")?)
        .map_err(|e| format!("{} and {}: {e}", b1.display(), b2.display()))?;
    let mask = mask_of(a, &ia, mask)?;
    let m = film::metrics_halves(&ia, &halves, mask.as_ref())
        .map_err(|e| format!("{}: {e}", b1.display()))?;
    Ok((m, halves.mean))
}

/// Reads a linear EXR a user named, refusing anything but a regular file before opening it
/// (a FIFO would block the EXR reader forever).
pub fn read_exr(p: &Path) -> Result<Image, String> {
    match std::fs::metadata(p) {
        Ok(m) if !m.is_file() => {
            return Err(format!(
                "{}: not a regular file (a directory, FIFO, socket or device)",
                p.display()
            ));
        }
        _ => {}
    }
    film::read_exr(p).map_err(|e| e.to_string())
}
