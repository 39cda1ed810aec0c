//! Checking inputs against each other, the canonical order, and the f64 accumulation.

use crate::{Class, CountKind, LayerMeta, Meta};
use film::Image;
use serde_json::{Value, json};

/// One run to composite: its `image.json` and its layer images.
#[derive(Clone, Debug, PartialEq)]
pub struct Input {
    /// Names the input in errors and in the result (the binary uses the run's path).
    pub label: String,
    pub meta: Meta,
    /// One image per layer of `meta`, by name, in any order.
    pub layers: Vec<(String, Image)>,
}

impl Input {
    /// An input from the text of its `image.json`; a parse error starts with `label`.
    pub fn new(
        label: impl Into<String>,
        json: &str,
        layers: Vec<(String, Image)>,
    ) -> Result<Input, String> {
        let label = label.into();
        let meta = Meta::from_json(json).map_err(|e| format!("{label}: {e}"))?;
        Ok(Input {
            label,
            meta,
            layers,
        })
    }

    /// The image of layer `name`; exists for every layer of a checked input.
    fn image(&self, name: &str) -> &Image {
        &self
            .layers
            .iter()
            .find(|(n, _)| n == name)
            .expect("checked: every layer has an image")
            .1
    }

    /// Everything about one input that needs no other input.
    fn check(&self) -> Result<(), String> {
        let m = &self.meta;
        m.validate()?;
        for (i, (name, _)) in self.layers.iter().enumerate() {
            if !m.layers.iter().any(|l| l.name == *name) {
                return Err(format!(
                    "layer image '{name}' is not listed in the layers of image.json"
                ));
            }
            if self.layers[..i].iter().any(|(n, _)| n == name) {
                return Err(format!("layer image '{name}' is given twice"));
            }
        }
        for l in &m.layers {
            let name = &l.name;
            let Some((_, img)) = self.layers.iter().find(|(n, _)| n == name) else {
                return Err(format!("layer '{name}' has no image"));
            };
            if (img.width, img.height) != (m.width, m.height) {
                return Err(format!(
                    "layer '{name}' is {}x{} but image.json says {}x{}",
                    img.width, img.height, m.width, m.height
                ));
            }
            if Some(img.data.len()) != img.width.checked_mul(img.height) {
                return Err(format!(
                    "layer '{name}' holds {} pixels but {}x{} needs {}",
                    img.data.len(),
                    img.width,
                    img.height,
                    img.width.saturating_mul(img.height)
                ));
            }
            if let Some(i) = img
                .data
                .iter()
                .position(|p| p.iter().any(|v| !v.is_finite()))
            {
                let p = img.data[i];
                let what = if p.iter().any(|v| v.is_nan()) {
                    "NaN"
                } else {
                    "infinite"
                };
                return Err(format!(
                    "layer '{name}': pixel ({}, {}) is {what}",
                    i % img.width,
                    i / img.width
                ));
            }
        }
        Ok(())
    }
}

/// One layer of the result: the count-weighted average of every input layer of its name.
#[derive(Clone, Debug, PartialEq)]
pub struct CompositeLayer {
    pub name: String,
    /// In canonical order.
    pub classes: Vec<Class>,
    /// `Σ cᵢ` over the inputs that hold the layer: the weight of the result.
    pub count: f64,
    pub count_kind: CountKind,
    /// Labels of the inputs that hold the layer, in canonical order.
    pub inputs: Vec<String>,
    pub image: Image,
}

/// The combined result.
#[derive(Clone, Debug, PartialEq)]
pub struct Composite {
    pub view_hash: String,
    pub width: usize,
    pub height: usize,
    /// Ordered by their first class (canonical class order; the class sets are disjoint).
    pub layers: Vec<CompositeLayer>,
    /// The sum of the layers (in f64, in layer order, rounded once), as `film::composite`.
    pub image: Image,
    /// Classes that no layer estimates: the image lacks that light.
    pub missing: Vec<Class>,
    /// Labels of all inputs, in canonical order.
    pub inputs: Vec<String>,
}

impl Composite {
    /// The result's own [`Meta`] (layers sorted by name, as [`Meta::from_json`] gives them).
    pub fn meta(&self) -> Meta {
        let mut layers: Vec<LayerMeta> = self
            .layers
            .iter()
            .map(|l| LayerMeta {
                name: l.name.clone(),
                classes: l.classes.clone(),
                count: l.count,
                count_kind: l.count_kind,
            })
            .collect();
        layers.sort_by(|a, b| a.name.cmp(&b.name));
        Meta {
            view_hash: self.view_hash.clone(),
            width: self.width,
            height: self.height,
            layers,
            seed: None,
        }
    }

    /// `image.json` of the result, in the contract every run follows (see [`Meta`]), so a
    /// composite can be composited again; adds `"method": "composite"`, `missing` (class
    /// names) and `inputs` (labels).
    pub fn json(&self) -> Value {
        let mut v = self.meta().to_json();
        if let Value::Object(m) = &mut v {
            m.insert("method".into(), json!("composite"));
            let missing: Vec<&str> = self.missing.iter().map(|c| c.name()).collect();
            m.insert("missing".into(), json!(missing));
            m.insert("inputs".into(), json!(self.inputs));
        }
        v
    }

    /// The result as an input to a further composite.
    pub fn into_input(self, label: impl Into<String>) -> Input {
        let meta = self.meta();
        Input {
            label: label.into(),
            meta,
            layers: self.layers.into_iter().map(|l| (l.name, l.image)).collect(),
        }
    }
}

const FNV_OFFSET: u64 = 0xcbf2_9ce4_8422_2325;
const FNV_PRIME: u64 = 0x0000_0100_0000_01b3;

fn fnv1a(mut h: u64, bytes: &[u8]) -> u64 {
    for &b in bytes {
        h ^= u64::from(b);
        h = h.wrapping_mul(FNV_PRIME);
    }
    h
}

/// The canonical key of a checked input: a description of its layers (names, classes,
/// count kinds, count bits) and a hash of their names and pixel bytes, both over the layers
/// sorted by name. Neither depends on the order inputs or layers were given in.
fn canonical_key(input: &Input) -> (String, u64) {
    let mut layers: Vec<&LayerMeta> = input.meta.layers.iter().collect();
    layers.sort_by(|a, b| a.name.cmp(&b.name));
    let mut desc = String::new();
    let mut h = FNV_OFFSET;
    for l in layers {
        let classes: Vec<&str> = l.classes.iter().map(|c| c.name()).collect();
        desc += &format!(
            "{}={}:{}:{:016x};",
            l.name,
            classes.join(","),
            l.count_kind.name(),
            l.count.to_bits()
        );
        h = fnv1a(h, l.name.as_bytes());
        h = fnv1a(h, &[0]);
        for p in &input.image(&l.name).data {
            for v in p {
                h = fnv1a(h, &v.to_bits().to_le_bytes());
            }
        }
    }
    (desc, h)
}

/// A layer name of the result and where it comes from.
struct Group {
    name: String,
    classes: Vec<Class>,
    count_kind: CountKind,
    /// `(input, layer)` indices, in canonical input order.
    members: Vec<(usize, usize)>,
}

fn class_list(classes: &[Class]) -> String {
    let names: Vec<&str> = classes.iter().map(|c| c.name()).collect();
    format!("[{}]", names.join(", "))
}

/// Combines runs of one view: layers of one name (and one class set) are averaged weighted
/// by count, layers of disjoint classes are summed into the image. The result is
/// bit-identical for every order of `inputs`. Errors are one line starting with the label of
/// the input at fault (and naming the other input involved, if any).
pub fn composite(inputs: Vec<Input>) -> Result<Composite, String> {
    if inputs.is_empty() {
        return Err("composite: no inputs".into());
    }
    for input in &inputs {
        input.check().map_err(|e| format!("{}: {e}", input.label))?;
    }

    // The canonical order. Equal (description, hash) pairs are adjacent after sorting.
    let mut keyed: Vec<((String, u64), Input)> =
        inputs.into_iter().map(|i| (canonical_key(&i), i)).collect();
    keyed.sort_by(|(ka, a), (kb, b)| ka.cmp(kb).then_with(|| a.label.cmp(&b.label)));
    for w in keyed.windows(2) {
        if w[0].0 == w[1].0 {
            return Err(format!(
                "{}: its layers and counts are bit-identical to those of {}: the same run \
                 given twice (or run with the same seed), not an independent estimate",
                w[1].1.label, w[0].1.label
            ));
        }
    }
    let inputs: Vec<Input> = keyed.into_iter().map(|(_, i)| i).collect();

    let first = &inputs[0];
    let (view_hash, width, height) = (&first.meta.view_hash, first.meta.width, first.meta.height);
    for input in &inputs[1..] {
        let m = &input.meta;
        if m.view_hash != *view_hash {
            return Err(format!(
                "{}: view_hash {} differs from {view_hash} of {}: not the same view",
                input.label, m.view_hash, first.label
            ));
        }
        if (m.width, m.height) != (width, height) {
            return Err(format!(
                "{}: size {}x{} differs from {width}x{height} of {}",
                input.label, m.width, m.height, first.label
            ));
        }
    }

    // Runs averaged into one layer must be independent: one seed means shared random streams.
    for (i, a) in inputs.iter().enumerate() {
        for b in &inputs[..i] {
            let (Some(sa), Some(sb)) = (a.meta.seed, b.meta.seed) else {
                continue;
            };
            let shared = a
                .meta
                .layers
                .iter()
                .find(|l| b.meta.layers.iter().any(|o| o.name == l.name));
            if let (true, Some(l)) = (sa == sb, shared) {
                return Err(format!(
                    "{}: seed {sa} is also the seed of {}, and both estimate layer '{}': runs \
                     with one seed share their random numbers (render again with --seed)",
                    a.label, b.label, l.name
                ));
            }
        }
    }

    // Layer names of the result, each with its inputs; classes disjoint between names.
    let mut groups: Vec<Group> = Vec::new();
    for (i, input) in inputs.iter().enumerate() {
        let mut order: Vec<usize> = (0..input.meta.layers.len()).collect();
        order.sort_by(|&a, &b| input.meta.layers[a].name.cmp(&input.meta.layers[b].name));
        for li in order {
            let l = &input.meta.layers[li];
            let mut classes = l.classes.clone();
            classes.sort();
            if let Some(g) = groups.iter_mut().find(|g| g.name == l.name) {
                let other = &inputs[g.members[0].0].label;
                if g.classes != classes {
                    return Err(format!(
                        "{}: layer '{}' estimates {} but {} in {other}: double counting",
                        input.label,
                        l.name,
                        class_list(&classes),
                        class_list(&g.classes)
                    ));
                }
                if g.count_kind != l.count_kind {
                    return Err(format!(
                        "{}: layer '{}' counts {} but {} in {other}: cannot weigh them together",
                        input.label, l.name, l.count_kind, g.count_kind
                    ));
                }
                g.members.push((i, li));
                continue;
            }
            for g in &groups {
                if let Some(c) = classes.iter().find(|c| g.classes.contains(c)) {
                    return Err(format!(
                        "{}: layer '{}' estimates class {c}, which layer '{}' of {} estimates \
                         too: double counting",
                        input.label, l.name, g.name, inputs[g.members[0].0].label
                    ));
                }
            }
            groups.push(Group {
                name: l.name.clone(),
                classes,
                count_kind: l.count_kind,
                members: vec![(i, li)],
            });
        }
    }
    groups.sort_by_key(|g| g.classes[0]);

    let mut layers = Vec::with_capacity(groups.len());
    for g in groups {
        let mut acc = vec![[0.0f64; 3]; width * height];
        let mut total = 0.0f64;
        for &(i, li) in &g.members {
            let count = inputs[i].meta.layers[li].count;
            total += count;
            for (a, p) in acc.iter_mut().zip(&inputs[i].image(&g.name).data) {
                for c in 0..3 {
                    a[c] += count * f64::from(p[c]);
                }
            }
        }
        let data: Vec<[f32; 3]> = acc
            .iter()
            .map(|a| {
                [
                    (a[0] / total) as f32,
                    (a[1] / total) as f32,
                    (a[2] / total) as f32,
                ]
            })
            .collect();
        // The result is itself an input to later composites, whose counts are bounded too.
        if total > crate::meta::MAX_COUNT {
            return Err(format!(
                "composite: layer '{}': the counts sum to {total}, beyond 2^53 (the largest \
                 count an image.json may hold)",
                g.name
            ));
        }
        if !total.is_finite() || data.iter().flatten().any(|v| !v.is_finite()) {
            return Err(format!(
                "composite: layer '{}': the count-weighted sum overflows",
                g.name
            ));
        }
        layers.push(CompositeLayer {
            inputs: g
                .members
                .iter()
                .map(|&(i, _)| inputs[i].label.clone())
                .collect(),
            name: g.name,
            classes: g.classes,
            count: total,
            count_kind: g.count_kind,
            image: Image {
                width,
                height,
                data,
            },
        });
    }

    let parts: Vec<(&Image, f32)> = layers.iter().map(|l| (&l.image, 1.0)).collect();
    let image = film::composite(&parts).map_err(|e| format!("composite: {e}"))?;
    if image.data.iter().flatten().any(|v| !v.is_finite()) {
        return Err("composite: the sum of the layers overflows f32".into());
    }
    let missing = Class::ALL
        .into_iter()
        .filter(|c| !layers.iter().any(|l| l.classes.contains(c)))
        .collect();
    Ok(Composite {
        view_hash: view_hash.clone(),
        width,
        height,
        layers,
        image,
        missing,
        inputs: inputs.iter().map(|i| i.label.clone()).collect(),
    })
}
