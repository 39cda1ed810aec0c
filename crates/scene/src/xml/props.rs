//! One plugin element's parameters (`<float name=...>`, `<rgb>`, `<transform>`, nested
//! plugins, `<ref>`s), read by name and typed as Mitsuba 3 types them. Every child a
//! converter does not read is reported by [`Plugin::finish`], so nothing a file asks for is
//! dropped in silence.

use super::tree::Elem;
use crate::error::SceneError;
use glam::{DMat3, DMat4, DVec3};
use std::cell::RefCell;
use std::collections::HashMap;

/// Elements with an `id`, for `<ref>`.
pub(super) type Ids<'a> = HashMap<&'a str, &'a Elem>;

/// The tags that hold a value rather than an object.
const VALUE_TAGS: [&str; 9] = [
    "float",
    "integer",
    "boolean",
    "string",
    "rgb",
    "spectrum",
    "point",
    "vector",
    "transform",
];

/// A colour parameter: a constant or a texture plugin.
pub(super) enum Color<'a> {
    Rgb([f32; 3]),
    Texture(&'a Elem),
}

pub(super) struct Plugin<'a> {
    pub e: &'a Elem,
    pub kind: &'a str,
    ids: &'a Ids<'a>,
    used: RefCell<Vec<bool>>,
}

impl<'a> Plugin<'a> {
    /// `e` as a plugin: it must have a `type`.
    pub fn new(e: &'a Elem, ids: &'a Ids<'a>) -> Result<Plugin<'a>, SceneError> {
        let kind = e
            .attr("type")
            .ok_or_else(|| e.err("has no `type` attribute"))?;
        Ok(Plugin {
            e,
            kind,
            ids,
            used: RefCell::new(vec![false; e.children.len()]),
        })
    }

    pub fn err(&self, problem: impl std::fmt::Display) -> SceneError {
        self.e.err(problem)
    }

    pub fn warning(&self, problem: impl std::fmt::Display) -> String {
        self.e.warning(problem)
    }

    /// The value child named `name`, marked read.
    fn value(&self, name: &str) -> Option<&'a Elem> {
        let (i, c) = self.find_value(name)?;
        self.mark(i);
        Some(c)
    }

    /// The value child named `name` and its index, not marked read.
    fn find_value(&self, name: &str) -> Option<(usize, &'a Elem)> {
        self.e
            .children
            .iter()
            .enumerate()
            .find(|(_, c)| VALUE_TAGS.contains(&c.tag.as_str()) && c.attr("name") == Some(name))
    }

    /// The tag of the value child named `name` (`float`, `string`, ...), not marking it read.
    pub fn tag_of(&self, name: &str) -> Option<&'a str> {
        self.find_value(name).map(|(_, c)| c.tag.as_str())
    }

    /// Child `i` marked read.
    fn mark(&self, i: usize) {
        if let Some(u) = self.used.borrow_mut().get_mut(i) {
            *u = true;
        }
    }

    /// `c`, or for a `<ref>` the element it names.
    fn resolve(&self, c: &'a Elem) -> Result<&'a Elem, SceneError> {
        if c.tag != "ref" {
            return Ok(c);
        }
        let id = c
            .attr("id")
            .ok_or_else(|| c.err("needs the `id` it refers to"))?;
        self.ids
            .get(id)
            .copied()
            .ok_or_else(|| c.err(format_args!("refers to `{id}`, which no element declares")))
    }

    /// Marks a parameter read without reading it (one whose every value draws the same).
    pub fn ignore(&self, name: &str) {
        let _ = self.value(name);
    }

    /// The nested plugins of `tag` (`bsdf`, `emitter`, ...), `<ref>`s resolved, marked read.
    pub fn objects(&self, tag: &str) -> Result<Vec<&'a Elem>, SceneError> {
        let mut out = Vec::new();
        for (i, c) in self.e.children.iter().enumerate() {
            let target = self.resolve(c)?;
            if target.tag == tag {
                self.mark(i);
                out.push(target);
            }
        }
        Ok(out)
    }

    /// At most one nested plugin of `tag`.
    pub fn object(&self, tag: &str) -> Result<Option<&'a Elem>, SceneError> {
        let all = self.objects(tag)?;
        if all.len() > 1 {
            return Err(self.err(format_args!(
                "has {} <{tag}>s; photonflow reads one",
                all.len()
            )));
        }
        Ok(all.into_iter().next())
    }

    pub fn float(&self, name: &str) -> Result<Option<f64>, SceneError> {
        let Some(c) = self.value(name) else {
            return Ok(None);
        };
        if !matches!(c.tag.as_str(), "float" | "integer") {
            return Err(c.err("must be a <float>"));
        }
        number(c, "value").map(Some)
    }

    pub fn float_or(&self, name: &str, default: f64) -> Result<f64, SceneError> {
        Ok(self.float(name)?.unwrap_or(default))
    }

    pub fn integer(&self, name: &str) -> Result<Option<i64>, SceneError> {
        let Some(c) = self.value(name) else {
            return Ok(None);
        };
        let v = text(c, "value")?;
        if c.tag != "integer" {
            return Err(c.err("must be an <integer>"));
        }
        v.trim()
            .parse()
            .map(Some)
            .map_err(|_| c.err(format_args!("`{v}` is not an integer")))
    }

    pub fn boolean(&self, name: &str) -> Result<Option<bool>, SceneError> {
        let Some(c) = self.value(name) else {
            return Ok(None);
        };
        let v = text(c, "value")?;
        if c.tag != "boolean" {
            return Err(c.err("must be a <boolean>"));
        }
        match v.trim() {
            "true" => Ok(Some(true)),
            "false" => Ok(Some(false)),
            _ => Err(c.err(format_args!("`{v}` is neither true nor false"))),
        }
    }

    pub fn string(&self, name: &str) -> Result<Option<&'a str>, SceneError> {
        let Some(c) = self.value(name) else {
            return Ok(None);
        };
        if c.tag != "string" {
            return Err(c.err("must be a <string>"));
        }
        text(c, "value").map(Some)
    }

    /// A colour: `<rgb>`, a uniform `<spectrum>` or `<float>`, or a texture (nested,
    /// referenced, or a `<texture name=...>`).
    pub fn color(&self, name: &str) -> Result<Option<Color<'a>>, SceneError> {
        if let Some(c) = self.value(name) {
            return match c.tag.as_str() {
                "rgb" => rgb(c).map(|v| Some(Color::Rgb(v))),
                "float" | "integer" => Ok(Some(Color::Rgb([number(c, "value")? as f32; 3]))),
                "spectrum" => {
                    let v = text(c, "value")?;
                    match v.trim().parse::<f64>() {
                        Ok(x) if x.is_finite() => Ok(Some(Color::Rgb([x as f32; 3]))),
                        _ => Err(c.err(format_args!(
                            "`{v}`: photonflow reads a spectrum given as one number; give \
                             other colours as <rgb>"
                        ))),
                    }
                }
                _ => Err(c.err("must be a colour (<rgb>, <spectrum> or <float>)")),
            };
        }
        for (i, c) in self.e.children.iter().enumerate() {
            if c.attr("name") != Some(name) || !matches!(c.tag.as_str(), "texture" | "ref") {
                continue;
            }
            let t = self.resolve(c)?;
            if t.tag != "texture" {
                return Err(c.err(format_args!("refers to {}, not a texture", t.describe())));
            }
            self.mark(i);
            return Ok(Some(Color::Texture(t)));
        }
        Ok(None)
    }

    /// A constant colour (a texture is refused).
    pub fn rgb(&self, name: &str, default: [f32; 3]) -> Result<[f32; 3], SceneError> {
        match self.color(name)? {
            None => Ok(default),
            Some(Color::Rgb(v)) => Ok(v),
            Some(Color::Texture(t)) => Err(t.err(format_args!(
                "`{name}` of {} as a texture: photonflow reads a constant there",
                self.e.describe()
            ))),
        }
    }

    pub fn point(&self, name: &str) -> Result<Option<DVec3>, SceneError> {
        let Some(c) = self.value(name) else {
            return Ok(None);
        };
        if !matches!(c.tag.as_str(), "point" | "vector") {
            return Err(c.err("must be a <point> or <vector>"));
        }
        vec3(c, 0.0).map(Some)
    }

    pub fn transform(&self, name: &str) -> Result<Option<DMat4>, SceneError> {
        let Some(c) = self.value(name) else {
            return Ok(None);
        };
        if c.tag != "transform" {
            return Err(c.err("must be a <transform>"));
        }
        transform(c).map(Some)
    }

    /// Every child nothing read, as warnings: photonflow leaves them out.
    pub fn finish(self, warnings: &mut Vec<String>) {
        for (c, used) in self.e.children.iter().zip(self.used.into_inner()) {
            if !used {
                warnings.push(self.e.warning(format_args!(
                    "{} (line {}) is not read by photonflow: left out",
                    c.describe(),
                    c.at.line
                )));
            }
        }
    }
}

fn text<'a>(c: &'a Elem, key: &str) -> Result<&'a str, SceneError> {
    c.attr(key)
        .ok_or_else(|| c.err(format_args!("needs `{key}`")))
}

fn parse_number(c: &Elem, s: &str) -> Result<f64, SceneError> {
    match s.trim().parse::<f64>() {
        Ok(v) if v.is_finite() => Ok(v),
        _ => Err(c.err(format_args!("`{s}` is not a finite number"))),
    }
}

fn number(c: &Elem, key: &str) -> Result<f64, SceneError> {
    parse_number(c, text(c, key)?)
}

/// Numbers separated by commas and/or spaces.
fn numbers(c: &Elem, s: &str) -> Result<Vec<f64>, SceneError> {
    s.split(|ch: char| ch == ',' || ch.is_whitespace())
        .filter(|t| !t.is_empty())
        .map(|t| parse_number(c, t))
        .collect()
}

/// `<rgb value="r, g, b">` (or one grey value).
fn rgb(c: &Elem) -> Result<[f32; 3], SceneError> {
    let v = numbers(c, text(c, "value")?)?;
    match v.as_slice() {
        [g] => Ok([*g as f32; 3]),
        [r, g, b] => Ok([*r as f32, *g as f32, *b as f32]),
        _ => Err(c.err("needs one or three numbers")),
    }
}

/// `x`, `y`, `z` attributes (each `default` when absent) or `value="x, y, z"`.
fn vec3(c: &Elem, default: f64) -> Result<DVec3, SceneError> {
    if let Some(v) = c.attr("value") {
        return match numbers(c, v)?.as_slice() {
            [x, y, z] => Ok(DVec3::new(*x, *y, *z)),
            [s] => Ok(DVec3::splat(*s)),
            _ => Err(c.err("`value` needs three numbers")),
        };
    }
    let axis = |k: &str| c.attr(k).map_or(Ok(default), |s| parse_number(c, s));
    Ok(DVec3::new(axis("x")?, axis("y")?, axis("z")?))
}

/// A `<transform>`: its operations in order, each applied after the ones before.
pub(super) fn transform(t: &Elem) -> Result<DMat4, SceneError> {
    let mut m = DMat4::IDENTITY;
    for op in &t.children {
        let step = match op.tag.as_str() {
            "translate" => DMat4::from_translation(vec3(op, 0.0)?),
            "scale" => {
                let s = vec3(op, 1.0)?;
                DMat4::from_scale(s)
            }
            "rotate" => {
                // The axis by `x`, `y`, `z` (Mitsuba 3 reads no `axis` attribute), taken as
                // written: Mitsuba's `Transform4f::rotate` is Rodrigues' formula
                // `cos I + sin [a]x + (1 - cos) a a^T` without normalising `a`, so an axis
                // of length other than 1 scales and shears, there and here alike.
                let a = vec3(op, 0.0)?;
                if a == DVec3::ZERO {
                    return Err(op.err("the axis is zero"));
                }
                let (sin, cos) = number(op, "angle")?.to_radians().sin_cos();
                let cross = DMat3::from_cols(
                    DVec3::new(0.0, a.z, -a.y),
                    DVec3::new(-a.z, 0.0, a.x),
                    DVec3::new(a.y, -a.x, 0.0),
                );
                let outer = DMat3::from_cols(a * a.x, a * a.y, a * a.z);
                let rot =
                    DMat3::from_diagonal(DVec3::splat(cos)) + cross * sin + outer * (1.0 - cos);
                // Entries within 1e-12 of 0 or +-1 snapped, as the scene file's `rotate`
                // does: a turn of 90 or 180 degrees keeps axis-aligned walls exact.
                let r = rot.to_cols_array();
                DMat4::from_mat3(DMat3::from_cols_array(&r.map(|x| {
                    if x.abs() < 1e-12 {
                        0.0
                    } else if (x.abs() - 1.0).abs() < 1e-12 {
                        x.signum()
                    } else {
                        x
                    }
                })))
            }
            "matrix" => {
                let v = numbers(op, text(op, "value")?)?;
                match v.len() {
                    16 => {
                        let mut cols = [0.0; 16];
                        cols.copy_from_slice(&v);
                        DMat4::from_cols_array(&cols).transpose()
                    }
                    9 => {
                        let mut cols = [0.0; 9];
                        cols.copy_from_slice(&v);
                        DMat4::from_mat3(DMat3::from_cols_array(&cols).transpose())
                    }
                    n => return Err(op.err(format_args!("needs 9 or 16 numbers, not {n}"))),
                }
            }
            "lookat" => {
                let p = |k: &str| -> Result<DVec3, SceneError> {
                    match numbers(op, text(op, k)?)?.as_slice() {
                        [x, y, z] => Ok(DVec3::new(*x, *y, *z)),
                        _ => Err(op.err(format_args!("`{k}` needs three numbers"))),
                    }
                };
                let origin = p("origin")?;
                let target = p("target")?;
                let up = if op.attr("up").is_some() {
                    p("up")?
                } else {
                    DVec3::Y
                };
                // Mitsuba 3's look-at frame: columns left, up, forward, origin.
                let dir = (target - origin)
                    .try_normalize()
                    .ok_or_else(|| op.err("origin and target coincide"))?;
                let left = up
                    .cross(dir)
                    .try_normalize()
                    .ok_or_else(|| op.err("`up` is parallel to the view direction"))?;
                let new_up = dir.cross(left);
                DMat4::from_cols(
                    left.extend(0.0),
                    new_up.extend(0.0),
                    dir.extend(0.0),
                    origin.extend(1.0),
                )
            }
            other => {
                return Err(op.err(format_args!(
                    "unknown transform operation <{other}> (photonflow reads translate, rotate, \
                     scale, matrix, lookat)"
                )));
            }
        };
        m = step * m;
    }
    if !m.is_finite() {
        return Err(t.err("the transform is not finite"));
    }
    Ok(m)
}
