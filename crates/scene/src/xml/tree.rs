//! The XML files as one tree of elements: `<include>`s spliced in, `<default>`s and `-D`
//! values substituted for `$name`, the names of version 0.x files upgraded as Mitsuba 3
//! upgrades them, each element with the file and line it came from.

use crate::error::SceneError;
use crate::load::read_regular;
use std::path::{Path, PathBuf};
use std::rc::Rc;

/// Deepest chain of `<include>`s: a file that includes itself fails here, not by the stack.
const MAX_INCLUDE_DEPTH: usize = 16;

/// Where an element was written.
#[derive(Clone, Debug)]
pub(super) struct Loc {
    pub file: Rc<PathBuf>,
    pub line: u32,
}

impl Loc {
    pub fn err(&self, problem: impl std::fmt::Display) -> SceneError {
        SceneError::new(&*self.file, format!("line {}: {problem}", self.line))
    }

    pub fn warning(&self, problem: impl std::fmt::Display) -> String {
        format!("{}: line {}: {problem}", self.file.display(), self.line)
    }

    /// The directory of the file the element is in: its file names are relative to it.
    pub fn dir(&self) -> &Path {
        self.file.parent().unwrap_or(Path::new(""))
    }
}

/// One element, its attributes substituted.
#[derive(Debug)]
pub(super) struct Elem {
    pub tag: String,
    pub attrs: Vec<(String, String)>,
    pub children: Vec<Elem>,
    pub at: Loc,
}

impl Elem {
    pub fn attr(&self, name: &str) -> Option<&str> {
        self.attrs
            .iter()
            .find(|(k, _)| k == name)
            .map(|(_, v)| v.as_str())
    }

    /// `<tag type="t" name="n" id="i">`, for messages.
    pub fn describe(&self) -> String {
        let mut s = format!("<{}", self.tag);
        for key in ["type", "name", "id"] {
            if let Some(v) = self.attr(key) {
                s += &format!(" {key}=\"{v}\"");
            }
        }
        s + ">"
    }

    pub fn err(&self, problem: impl std::fmt::Display) -> SceneError {
        self.at.err(format_args!("{}: {problem}", self.describe()))
    }

    pub fn warning(&self, problem: impl std::fmt::Display) -> String {
        self.at
            .warning(format_args!("{}: {problem}", self.describe()))
    }

    /// Every element below this one and this one, depth first.
    pub fn walk<'a>(&'a self, out: &mut Vec<&'a Elem>) {
        out.push(self);
        for c in &self.children {
            c.walk(out);
        }
    }
}

/// Reads `path` (a `<scene>`) and everything it includes.
pub(super) fn read(path: &Path, defines: &[(String, String)]) -> Result<Elem, SceneError> {
    let mut r = Reader {
        params: defines.to_vec(),
        chain: Vec::new(),
    };
    let (root, children) = r.file(path)?;
    Ok(Elem { children, ..root })
}

struct Reader {
    /// `-D` values first, then `<default>`s in document order; the first of a name wins.
    params: Vec<(String, String)>,
    /// The files being read, outermost first.
    chain: Vec<PathBuf>,
}

impl Reader {
    /// A file's `<scene>` element (without children) and its children.
    fn file(&mut self, path: &Path) -> Result<(Elem, Vec<Elem>), SceneError> {
        if self.chain.len() >= MAX_INCLUDE_DEPTH {
            return Err(SceneError::new(
                path,
                format!(
                    "included {MAX_INCLUDE_DEPTH} files deep (does a file include itself?): {}",
                    self.chain
                        .iter()
                        .map(|p| p.display().to_string())
                        .collect::<Vec<_>>()
                        .join(" -> ")
                ),
            ));
        }
        let bytes = read_regular(path)
            .map_err(|e| SceneError::new(path, format!("cannot read scene file: {e}")))?;
        let text = String::from_utf8(bytes)
            .map_err(|_| SceneError::new(path, "cannot read scene file: it is not UTF-8 text"))?;
        let doc = roxmltree::Document::parse(&text)
            .map_err(|e| SceneError::new(path, format!("malformed XML: {e}")))?;
        let file = Rc::new(path.to_path_buf());
        let root = doc.root_element();
        let at = |n: roxmltree::Node| Loc {
            file: file.clone(),
            line: doc.text_pos_at(n.range().start).row,
        };
        if root.tag_name().name() != "scene" {
            return Err(at(root).err(format_args!(
                "the root element is <{}>, not <scene>",
                root.tag_name().name()
            )));
        }
        let version = root
            .attribute("version")
            .ok_or_else(|| at(root).err("<scene> has no `version` attribute (e.g. \"3.0.0\")"))?;
        let major: u32 = version
            .split('.')
            .next()
            .and_then(|m| m.trim().parse().ok())
            .ok_or_else(|| {
                at(root).err(format_args!("<scene version=\"{version}\">: not a version"))
            })?;
        if major > 3 {
            return Err(at(root).err(format_args!(
                "<scene version=\"{version}\">: photonflow reads versions up to 3"
            )));
        }
        self.chain.push(path.to_path_buf());
        let mut children = Vec::new();
        for c in root.children().filter(roxmltree::Node::is_element) {
            self.element(c, &at, major < 2, &mut children)?;
        }
        self.chain.pop();
        let scene = Elem {
            tag: "scene".into(),
            attrs: vec![("version".into(), version.into())],
            children: Vec::new(),
            at: at(root),
        };
        Ok((scene, children))
    }

    /// Element `n` appended to `out` (an `<include>` appends the included file's children,
    /// a `<default>` nothing).
    fn element(
        &mut self,
        n: roxmltree::Node,
        at: &dyn Fn(roxmltree::Node) -> Loc,
        upgrade: bool,
        out: &mut Vec<Elem>,
    ) -> Result<(), SceneError> {
        let loc = at(n);
        let mut tag = n.tag_name().name().to_string();
        let mut attrs = Vec::new();
        for a in n.attributes() {
            let v = self.substitute(a.value()).map_err(|p| {
                loc.err(format_args!("<{tag} {}=\"{}\">: {p}", a.name(), a.value()))
            })?;
            attrs.push((a.name().to_string(), v));
        }
        if upgrade {
            // Mitsuba 3's reading of 0.x files: camelCase parameter names in snake_case,
            // `lookAt` as `lookat`, `srgb` as `rgb`.
            tag = match tag.as_str() {
                "lookAt" => "lookat".into(),
                "srgb" => "rgb".into(),
                _ => tag,
            };
            for (k, v) in &mut attrs {
                if k == "name" {
                    *v = snake_case(v);
                }
            }
        }
        let get = |k: &str| attrs.iter().find(|(a, _)| a == k).map(|(_, v)| v.clone());
        match tag.as_str() {
            "default" => {
                let (Some(name), Some(value)) = (get("name"), get("value")) else {
                    return Err(loc.err("<default> needs `name` and `value`"));
                };
                if !self.params.iter().any(|(k, _)| *k == name) {
                    self.params.push((name, value));
                }
                Ok(())
            }
            "include" => {
                let Some(f) = get("filename") else {
                    return Err(loc.err("<include> needs `filename`"));
                };
                let path = loc.dir().join(&f);
                let (_, children) = self.file(&path).map_err(|e| {
                    SceneError::new(
                        &e.file,
                        format!(
                            "{} (included from {} line {})",
                            e.problem,
                            loc.file.display(),
                            loc.line
                        ),
                    )
                })?;
                out.extend(children);
                Ok(())
            }
            _ => {
                let mut children = Vec::new();
                for c in n.children().filter(roxmltree::Node::is_element) {
                    self.element(c, at, upgrade, &mut children)?;
                }
                out.push(Elem {
                    tag,
                    attrs,
                    children,
                    at: loc,
                });
                Ok(())
            }
        }
    }

    /// `value` with every `$name` replaced by its parameter.
    fn substitute(&self, value: &str) -> Result<String, String> {
        let mut out = String::with_capacity(value.len());
        let mut rest = value;
        while let Some(i) = rest.find('$') {
            out.push_str(rest.get(..i).unwrap_or(""));
            let after = rest.get(i + 1..).unwrap_or("");
            let len = after
                .find(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))
                .unwrap_or(after.len());
            let name = after.get(..len).unwrap_or("");
            if name.is_empty() {
                return Err("`$` is not followed by a parameter name".into());
            }
            let Some((_, v)) = self.params.iter().find(|(k, _)| k == name) else {
                return Err(format!(
                    "`${name}` has no value: give one with `-D {name}=...` or a <default name=\"{name}\">"
                ));
            };
            out.push_str(v);
            rest = after.get(len..).unwrap_or("");
        }
        out.push_str(rest);
        Ok(out)
    }
}

/// `intIOR` -> `int_ior`, `maxDepth` -> `max_depth`: an underscore before each capital that
/// follows a lower-case letter or digit, then all lower case (Mitsuba 3's upgrade of 0.x
/// names).
fn snake_case(name: &str) -> String {
    let mut out = String::with_capacity(name.len() + 4);
    let mut prev: Option<char> = None;
    for c in name.chars() {
        if c.is_ascii_uppercase()
            && prev.is_some_and(|p| p.is_ascii_lowercase() || p.is_ascii_digit())
        {
            out.push('_');
        }
        out.push(c.to_ascii_lowercase());
        prev = Some(c);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::snake_case;

    #[test]
    fn old_names_upgrade_as_mitsuba_does() {
        assert_eq!(snake_case("intIOR"), "int_ior");
        assert_eq!(snake_case("maxDepth"), "max_depth");
        assert_eq!(snake_case("specularReflectance"), "specular_reflectance");
        assert_eq!(snake_case("radius"), "radius");
    }
}
