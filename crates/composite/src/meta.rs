//! What a run says about itself: the `image.json` contract, parsed from and written to JSON.

use film::Class;
use serde_json::{Map, Value, json};
use std::fmt;

/// What a layer's count counts. Layers of one name are averaged by count, which is only
/// meaningful when every input counts the same thing.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum CountKind {
    /// Samples per pixel (path tracing, photon-map eye passes).
    Spp,
    /// Emitted photon paths (photon splatting).
    PhotonPaths,
}

impl CountKind {
    /// The name used in `image.json`.
    pub fn name(self) -> &'static str {
        match self {
            CountKind::Spp => "spp",
            CountKind::PhotonPaths => "photon_paths",
        }
    }

    /// The kind of a name used in `image.json`, if it is one.
    pub fn from_name(name: &str) -> Option<CountKind> {
        [CountKind::Spp, CountKind::PhotonPaths]
            .into_iter()
            .find(|k| k.name() == name)
    }
}

impl fmt::Display for CountKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// One layer of a run: its name (also its file name, `layers/<name>.exr`), the classes it
/// estimates and its weight.
#[derive(Clone, Debug, PartialEq)]
pub struct LayerMeta {
    pub name: String,
    pub classes: Vec<Class>,
    /// Positive, at most [`MAX_COUNT`]. Integral for single runs; a composite's count is a sum
    /// of them.
    pub count: f64,
    pub count_kind: CountKind,
}

/// The part of `image.json` compositing needs. Other fields of the file are ignored.
///
/// ```json
/// { "view_hash": "0123456789abcdef", "width": 512, "height": 512,
///   "count": 64, "count_kind": "spp",
///   "layers": { "emitted": ["emitted"], "direct": ["direct"],
///               "indirect": ["indirect", "caustic_indirect"], "caustic": ["caustic"] },
///   "layer_counts": { "caustic": { "count": 1000000, "count_kind": "photon_paths" } } }
/// ```
///
/// `count`/`count_kind` at the top level weigh every layer that `layer_counts` (optional)
/// does not list. A composite whose layers have different weights lists every layer in
/// `layer_counts` and writes the top-level pair only when all layers share it.
#[derive(Clone, Debug, PartialEq)]
pub struct Meta {
    /// Geometry, materials and camera: only images of one view may be combined.
    pub view_hash: String,
    pub width: usize,
    pub height: usize,
    /// Sorted by name by [`Meta::from_json`]; any order is accepted.
    pub layers: Vec<LayerMeta>,
    /// The seed of the run's random streams, if it had one (a composite has none). Two runs
    /// with one seed share their random numbers: they are not independent estimates.
    pub seed: Option<u64>,
}

fn count_of(v: &Value, what: &str) -> Result<f64, String> {
    let c = v
        .as_f64()
        .ok_or_else(|| format!("{what} {v} is not a number"))?;
    check_count(c).map_err(|e| format!("{what} {e}"))?;
    Ok(c)
}

/// Largest count: 2^53, the largest integer up to which an f64 holds every integer. Counts
/// are samples or photon paths, integers, and no run makes 2^53 of them; a count of 1e300
/// would weigh every other run of its layer down to nothing.
pub const MAX_COUNT: f64 = 9_007_199_254_740_992.0;

fn check_count(c: f64) -> Result<(), String> {
    // 1e300 as written, not as its 301 digits.
    let shown = if c.abs() >= 1e16 {
        format!("{c:e}")
    } else {
        format!("{c}")
    };
    if !(c.is_finite() && c > 0.0) {
        Err(format!("{shown} must be positive and finite"))
    } else if c > MAX_COUNT {
        Err(format!(
            "{shown} exceeds 2^53 = {}: counts are samples or photon paths, integers an f64 \
             holds exactly",
            MAX_COUNT as u64
        ))
    } else {
        Ok(())
    }
}

fn kind_of(v: &Value, what: &str) -> Result<CountKind, String> {
    let s = v
        .as_str()
        .ok_or_else(|| format!("{what} {v} is not a string"))?;
    CountKind::from_name(s)
        .ok_or_else(|| format!("{what} \"{s}\" is unknown (expected \"spp\" or \"photon_paths\")"))
}

/// `count` and `count_kind` in `obj`, both or neither.
fn weight_of(obj: &Map<String, Value>, what: &str) -> Result<Option<(f64, CountKind)>, String> {
    match (obj.get("count"), obj.get("count_kind")) {
        (None, None) => Ok(None),
        (Some(c), Some(k)) => Ok(Some((
            count_of(c, &format!("{what}count"))?,
            kind_of(k, &format!("{what}count_kind"))?,
        ))),
        (Some(_), None) => Err(format!(
            "{what}count_kind is missing (expected \"spp\" or \"photon_paths\")"
        )),
        (None, Some(_)) => Err(format!("{what}count is missing")),
    }
}

fn dim_of(obj: &Map<String, Value>, key: &str) -> Result<usize, String> {
    let v = obj.get(key).ok_or_else(|| format!("{key} is missing"))?;
    v.as_u64()
        .and_then(|n| usize::try_from(n).ok())
        .ok_or_else(|| format!("{key} {v} is not a non-negative integer"))
}

/// A count as JSON: an integer when it is one (exactly representable), else a float.
fn count_json(c: f64) -> Value {
    if c.fract() == 0.0 && (0.0..=MAX_COUNT).contains(&c) {
        json!(c as u64)
    } else {
        json!(c)
    }
}

fn valid_layer_name(name: &str) -> bool {
    !name.is_empty()
        && name
            .bytes()
            .all(|b| b.is_ascii_alphanumeric() || b == b'_' || b == b'-')
}

impl Meta {
    /// Parses the compositing fields of an `image.json` and checks them ([`Meta::validate`]).
    /// Errors are one line without the file's name (the caller knows it).
    pub fn from_json(text: &str) -> Result<Meta, String> {
        let v: Value = serde_json::from_str(text).map_err(|e| format!("invalid JSON: {e}"))?;
        let obj = v.as_object().ok_or("not a JSON object")?;
        let view_hash = match obj.get("view_hash") {
            Some(Value::String(s)) => s.clone(),
            Some(other) => return Err(format!("view_hash {other} is not a string")),
            None => return Err("view_hash is missing".into()),
        };
        let width = dim_of(obj, "width")?;
        let height = dim_of(obj, "height")?;
        let default = weight_of(obj, "")?;
        let layer_obj = match obj.get("layers") {
            Some(Value::Object(m)) => m,
            Some(_) => {
                return Err("layers is not an object of layer name -> [classes]".into());
            }
            None => return Err("layers is missing".into()),
        };
        let counts_obj = match obj.get("layer_counts") {
            None => None,
            Some(Value::Object(m)) => Some(m),
            Some(_) => return Err("layer_counts is not an object".into()),
        };
        if let Some(m) = counts_obj
            && let Some(name) = m.keys().find(|k| !layer_obj.contains_key(*k))
        {
            return Err(format!(
                "layer_counts names layer '{name}' that layers lacks"
            ));
        }
        let mut layers = Vec::with_capacity(layer_obj.len());
        for (name, classes) in layer_obj {
            let list = classes
                .as_array()
                .ok_or_else(|| format!("layer '{name}': classes {classes} are not a list"))?;
            let mut cs = Vec::with_capacity(list.len());
            for c in list {
                let s = c
                    .as_str()
                    .ok_or_else(|| format!("layer '{name}': class {c} is not a string"))?;
                let class: Class = s.parse().map_err(|e| format!("layer '{name}': {e}"))?;
                cs.push(class);
            }
            let own = match counts_obj.and_then(|m| m.get(name)) {
                None => None,
                Some(Value::Object(o)) => weight_of(o, &format!("layer_counts.{name}."))?,
                Some(_) => return Err(format!("layer_counts.{name} is not an object")),
            };
            let (count, count_kind) = own.or(default).ok_or_else(|| {
                format!(
                    "layer '{name}': count and count_kind are missing (give them at the top \
                     level or in layer_counts)"
                )
            })?;
            let mut classes = cs;
            classes.sort();
            layers.push(LayerMeta {
                name: name.clone(),
                classes,
                count,
                count_kind,
            });
        }
        layers.sort_by(|a, b| a.name.cmp(&b.name));
        let seed = match obj.get("seed") {
            None | Some(Value::Null) => None,
            Some(v) => Some(
                v.as_u64()
                    .ok_or_else(|| format!("seed {v} is not a non-negative integer"))?,
            ),
        };
        let meta = Meta {
            view_hash,
            width,
            height,
            layers,
            seed,
        };
        meta.validate()?;
        Ok(meta)
    }

    /// Checks what [`Meta::from_json`] cannot express by types: a non-empty `view_hash`, a
    /// non-empty size, at least one layer, layer names usable as file names
    /// (`[A-Za-z0-9_-]+`) and unique, every layer estimating at least one class and no class
    /// twice, counts positive and at most [`MAX_COUNT`], and no class estimated by two layers.
    pub fn validate(&self) -> Result<(), String> {
        if self.view_hash.is_empty() {
            return Err("view_hash is empty".into());
        }
        if self.width == 0 || self.height == 0 {
            return Err(format!("size {}x{} is empty", self.width, self.height));
        }
        if self.layers.is_empty() {
            return Err("no layers".into());
        }
        for (i, l) in self.layers.iter().enumerate() {
            let name = &l.name;
            if !valid_layer_name(name) {
                return Err(format!(
                    "layer name '{name}' is not a file name of letters, digits, '_' and '-'"
                ));
            }
            if self.layers[..i].iter().any(|o| o.name == *name) {
                return Err(format!("layer '{name}' is listed twice"));
            }
            if l.classes.is_empty() {
                return Err(format!("layer '{name}' estimates no class"));
            }
            for (j, c) in l.classes.iter().enumerate() {
                if l.classes[..j].contains(c) {
                    return Err(format!("layer '{name}' lists class {c} twice"));
                }
            }
            check_count(l.count).map_err(|e| format!("layer '{name}': count {e}"))?;
            for o in &self.layers[..i] {
                if let Some(c) = l.classes.iter().find(|c| o.classes.contains(c)) {
                    return Err(format!(
                        "layers '{}' and '{name}' both estimate class {c}: double counting",
                        o.name
                    ));
                }
            }
        }
        Ok(())
    }

    /// The `image.json` fields of this meta (see [`Meta`]); [`Meta::from_json`] reads them
    /// back. Every layer is listed in `layer_counts`; the top-level `count`/`count_kind` are
    /// written when all layers share them.
    pub fn to_json(&self) -> Value {
        let mut layers = Map::new();
        let mut counts = Map::new();
        for l in &self.layers {
            let classes: Vec<&str> = l.classes.iter().map(|c| c.name()).collect();
            layers.insert(l.name.clone(), json!(classes));
            counts.insert(
                l.name.clone(),
                json!({ "count": count_json(l.count), "count_kind": l.count_kind.name() }),
            );
        }
        let mut m = Map::new();
        m.insert("view_hash".into(), json!(self.view_hash));
        m.insert("width".into(), json!(self.width));
        m.insert("height".into(), json!(self.height));
        if let Some(first) = self.layers.first()
            && self.layers.iter().all(|l| {
                l.count.to_bits() == first.count.to_bits() && l.count_kind == first.count_kind
            })
        {
            m.insert("count".into(), count_json(first.count));
            m.insert("count_kind".into(), json!(first.count_kind.name()));
        }
        m.insert("layers".into(), Value::Object(layers));
        m.insert("layer_counts".into(), Value::Object(counts));
        if let Some(seed) = self.seed {
            m.insert("seed".into(), json!(seed));
        }
        Value::Object(m)
    }
}
