//! Mitsuba 3 scene XML, read as a scene file: `photonflow render scene.xml` loads it through
//! the same builder as a TOML scene, and `convert` writes the TOML it becomes.
//!
//! The subset published test scenes use, each element as Mitsuba 3's documentation defines
//! it: `<scene version>`, `<default>` and `$name` (with `-D name=value`), `<include>`, `id`
//! and `<ref>`, `<transform>` (`translate`, `rotate`, `scale`, `matrix`, `lookat`); shapes
//! `obj`, `rectangle`, `cube`, `disk` (meshes) and `sphere` (analytic) with `to_world`,
//! `face_normals`, `flip_normals`, a `bsdf` and an `area` emitter; BSDFs `diffuse` (constant
//! or `bitmap`), `dielectric`, `roughdielectric`, `conductor`, `roughconductor`,
//! `twosided`; emitters `point`, `spot`, `directional`, `envmap`, `constant`; the
//! `perspective` sensor with an `hdrfilm` and a sampler's `sample_count`; an integrator's
//! `max_depth` and `rr_depth`. Anything else is refused, naming the file, the line and the
//! element; what is drawn approximately, or not read, is a `warning:` line.
//!
//! Rooms: `tree.rs` (files to elements), `props.rs` (a plugin's parameters, typed),
//! `convert.rs` (plugins to the scene file's tables).

// A decoder of untrusted bytes, as `load/` is.
#![cfg_attr(
    not(test),
    deny(
        clippy::unwrap_used,
        clippy::expect_used,
        clippy::indexing_slicing,
        clippy::panic,
        clippy::unreachable
    )
)]

mod convert;
mod props;
mod tree;

use crate::error::SceneError;
use crate::file::SceneFile;
use std::path::Path;

/// A Mitsuba 3 XML scene as the scene file it means, with the warnings reading it gave.
pub struct XmlScene {
    pub file: SceneFile,
    pub warnings: Vec<String>,
}

/// True for a path photonflow reads as Mitsuba 3 XML (its extension is `.xml`).
pub fn is_xml(path: &Path) -> bool {
    path.extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("xml"))
}

/// Reads the XML scene at `path`, `defines` (`name`, `value`) given before its `<default>`s.
pub fn read_xml(path: &Path, defines: &[(String, String)]) -> Result<XmlScene, SceneError> {
    let root = tree::read(path, defines)?;
    let mut all = Vec::new();
    root.walk(&mut all);
    let mut ids = props::Ids::new();
    for e in all {
        if let Some(id) = e.attr("id")
            && e.tag != "ref"
            && ids.insert(id, e).is_some()
        {
            return Err(e.err(format_args!("a second element with id `{id}`")));
        }
    }
    let mut c = convert::Converter::new(&ids, path);
    c.scene(&root)?;
    Ok(XmlScene {
        file: c.file,
        warnings: c.warnings,
    })
}
