//! PLY meshes (Turk's Polygon File Format, as Stanford's scans, Blender, MeshLab and
//! Mitsuba 3 write it): a text header of elements and their properties, then a body in
//! `ascii`, `binary_little_endian` or `binary_big_endian`. What is read: `element vertex`
//! with `x y z` (any scalar type), `nx ny nz` when all three are there, and the first of the
//! texture-coordinate pairs `u v`, `s t`, `texture_u texture_v`, `texture_s texture_t`, read
//! as Mitsuba 3 reads them (`v` from the image's top: a PLY's `v` is 1 minus the OBJ `vt` of
//! the same point, as Mitsuba's `write_ply` of an OBJ shows; Blender and MeshLab count `v`
//! up instead, so their textured PLY files come out flipped, here as in Mitsuba); `element face`
//! with its `vertex_indices` (or `vertex_index`) list, each polygon triangulated by
//! `faces.rs` as an OBJ's is. Every other element and property is read past, lists
//! included. A PLY file has no materials: the mesh's `material` key names one of the scene
//! file's.
//!
//! Hand-written rather than a crate: the maintained `ply-rs-bw` (2.0.3) panics on an element
//! count too long for `usize` (an `unwrap` in its header grammar) and allocates a vector of
//! the header's claimed count before reading a byte (`element vertex 4000000000000000`
//! aborts the process asking for 288 PB; `ply-rs`, which it forks, is unmaintained), and its
//! errors do not name the element at fault. The format is small enough that a
//! reader here is shorter than the checks around a crate would be: every count is checked
//! against the bytes that follow before anything is read or allocated by it, every problem
//! is a one-line message, and no input reaches a panic (the `deny` lints of `mod.rs`).

use super::faces::Polygons;
use super::{Builder, read_regular};
use crate::error::SceneError;
use crate::file::MeshDesc;
use glam::DMat4;
use rayon::prelude::*;

/// What photonflow reads of a PLY file: vertices (with normals and texture coordinates where
/// the file has them) and polygons, their indices checked against the vertex count.
#[derive(Debug, Default, PartialEq)]
pub(crate) struct PlyMesh {
    /// x, y, z per vertex.
    pub positions: Vec<f64>,
    /// nx, ny, nz per vertex, or empty.
    pub normals: Vec<f64>,
    /// u, v per vertex, or empty.
    pub texcoords: Vec<f32>,
    /// Every face's vertex indices, one face after another.
    pub indices: Vec<u32>,
    /// Each face's number of vertices.
    pub arities: Vec<u32>,
    /// Elements read on every core (tests check that the parallel reading was taken).
    pub parallel: usize,
}

impl Builder<'_> {
    /// PLY mesh `index` of the scene file (`ply = name`), its faces appended through `xf`
    /// under the scene-file material `material`.
    pub(super) fn load_ply(
        &mut self,
        index: usize,
        desc: &MeshDesc,
        name: &str,
        xf: DMat4,
        material: u32,
    ) -> Result<(), SceneError> {
        let path = self.dir.join(name);
        let of = format!("mesh {index} of {}", self.scene_path.display());
        let perr = |problem: String| SceneError::new(&path, format!("{problem} ({of})"));
        let bytes = read_regular(&path)
            .map_err(|e| SceneError::new(&path, format!("cannot read PLY file ({of}): {e}")))?;
        // The file's hash (one sequential pass) beside the body's reading.
        let hash = &mut *self.hash;
        let (mesh, ()) = rayon::join(|| parse(&bytes), || hash.write(&bytes));
        drop(bytes);
        let mesh = mesh.map_err(|p| perr(format!("malformed PLY file: {p}")))?;
        let polygons = Polygons {
            label: "",
            first: 0,
            uv_keys: "`u`, `v`",
            positions: &mesh.positions,
            normals: &mesh.normals,
            texcoords: &mesh.texcoords,
            indices: &mesh.indices,
            arities: &mesh.arities,
            material,
        };
        self.append_polygons(&polygons, desc, xf, &path, &perr)
    }
}

/// How the body is written.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Format {
    Ascii,
    Little,
    Big,
}

/// A property's scalar type.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Scalar {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    F32,
    F64,
}

impl Scalar {
    /// The type a header names (both the original names and the sized aliases).
    fn named(name: &str) -> Option<Scalar> {
        Some(match name {
            "char" | "int8" => Scalar::I8,
            "uchar" | "uint8" => Scalar::U8,
            "short" | "int16" => Scalar::I16,
            "ushort" | "uint16" => Scalar::U16,
            "int" | "int32" => Scalar::I32,
            "uint" | "uint32" => Scalar::U32,
            "float" | "float32" => Scalar::F32,
            "double" | "float64" => Scalar::F64,
            _ => return None,
        })
    }

    /// Bytes in a binary body.
    fn size(self) -> usize {
        match self {
            Scalar::I8 | Scalar::U8 => 1,
            Scalar::I16 | Scalar::U16 => 2,
            Scalar::I32 | Scalar::U32 | Scalar::F32 => 4,
            Scalar::F64 => 8,
        }
    }

    fn is_int(self) -> bool {
        !matches!(self, Scalar::F32 | Scalar::F64)
    }
}

/// A number read from the body.
#[derive(Clone, Copy, Debug)]
enum Num {
    Int(i64),
    Float(f64),
}

impl Num {
    fn float(self) -> f64 {
        match self {
            Num::Int(i) => i as f64,
            Num::Float(x) => x,
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Kind {
    Scalar(Scalar),
    /// A list: its length's type, its items' type.
    List(Scalar, Scalar),
}

#[derive(Debug)]
struct Property {
    name: String,
    kind: Kind,
}

#[derive(Debug)]
struct Element {
    name: String,
    count: usize,
    properties: Vec<Property>,
}

impl Element {
    fn property(&self, name: &str) -> Option<(usize, &Property)> {
        self.properties
            .iter()
            .enumerate()
            .find(|(_, p)| p.name == name)
    }

    /// Fewest bytes one entry takes in the body: every scalar's size and every list's
    /// length in binary; one character per property in ASCII.
    fn min_entry(&self, format: Format) -> usize {
        self.properties
            .iter()
            .map(|p| match (format, p.kind) {
                (Format::Ascii, _) => 1,
                (_, Kind::Scalar(t) | Kind::List(t, _)) => t.size(),
            })
            .sum()
    }
}

/// The header: the body's format, the elements in order, and where the body starts.
fn header(bytes: &[u8]) -> Result<(Format, Vec<Element>, usize), String> {
    let mut pos = 0usize;
    let mut line_no = 0usize;
    let mut format = None;
    let mut elements: Vec<Element> = Vec::new();
    loop {
        let rest = bytes.get(pos..).unwrap_or_default();
        let Some(len) = rest.iter().position(|&b| b == b'\n') else {
            return Err(if line_no == 0 && !rest.starts_with(b"ply") {
                "not a PLY file: it does not begin with `ply`".to_string()
            } else {
                "the header has no `end_header` line (or the file is cut inside it)".to_string()
            });
        };
        let raw = rest.get(..len).unwrap_or_default();
        let raw = raw.strip_suffix(b"\r").unwrap_or(raw);
        pos += len + 1;
        line_no += 1;
        let text = String::from_utf8_lossy(raw);
        let words: Vec<&str> = text.split_whitespace().collect();
        let at = |what: &str| format!("header line {line_no} (`{}`): {what}", text.trim());
        if line_no == 1 {
            if words != ["ply"] {
                return Err("not a PLY file: it does not begin with `ply`".to_string());
            }
            continue;
        }
        match words.as_slice() {
            [] | ["comment" | "obj_info", ..] => {}
            ["format", f, version] => {
                if format.is_some() {
                    return Err(at("a second `format` line"));
                }
                format = Some(match *f {
                    "ascii" => Format::Ascii,
                    "binary_little_endian" => Format::Little,
                    "binary_big_endian" => Format::Big,
                    _ => {
                        return Err(at(&format!(
                            "unknown format `{f}` (known: ascii, binary_little_endian, \
                             binary_big_endian)"
                        )));
                    }
                });
                if *version != "1.0" {
                    return Err(at(&format!("version {version}: only 1.0 exists")));
                }
            }
            ["element", name, count] => {
                let count = count
                    .parse::<u64>()
                    .ok()
                    .and_then(|c| usize::try_from(c).ok())
                    .ok_or_else(|| at(&format!("count `{count}` is not a whole number")))?;
                if elements.iter().any(|e| e.name == *name) {
                    return Err(at(&format!("a second element `{name}`")));
                }
                elements.push(Element {
                    name: name.to_string(),
                    count,
                    properties: Vec::new(),
                });
            }
            ["property", rest @ ..] => {
                let Some(element) = elements.last_mut() else {
                    return Err(at("a property before any `element` line"));
                };
                let scalar = |t: &str| {
                    Scalar::named(t).ok_or_else(|| {
                        at(&format!(
                            "unknown type `{t}` (known: char, uchar, short, ushort, int, uint, \
                             float, double, or int8 ... float64)"
                        ))
                    })
                };
                let (kind, name) = match rest {
                    ["list", count_type, item, name] => {
                        let count = scalar(count_type)?;
                        if !count.is_int() {
                            return Err(at(&format!(
                                "list `{name}`: its length's type must be an integer type, \
                                 not `{count_type}`"
                            )));
                        }
                        (Kind::List(count, scalar(item)?), name)
                    }
                    [t, name] if *t != "list" => (Kind::Scalar(scalar(t)?), name),
                    _ => return Err(at("malformed property line")),
                };
                if element.property(name).is_some() {
                    return Err(at(&format!(
                        "a second property `{name}` in element `{}`",
                        element.name
                    )));
                }
                element.properties.push(Property {
                    name: name.to_string(),
                    kind,
                });
            }
            ["end_header"] => break,
            _ => return Err(at("not a header line PLY knows")),
        }
    }
    let format = format.ok_or("the header has no `format` line")?;
    Ok((format, elements, pos))
}

/// Why a value could not be read.
enum Miss {
    /// The body ended.
    End,
    /// What was there is no number of the type.
    Bad(String),
}

/// The body, read value by value.
struct Body<'a> {
    bytes: &'a [u8],
    pos: usize,
    format: Format,
    /// The line of the last token read (ASCII), from the file's first line.
    line: usize,
}

impl<'a> Body<'a> {
    fn remaining(&self) -> usize {
        self.bytes.len().saturating_sub(self.pos)
    }

    fn take<const N: usize>(&mut self) -> Result<[u8; N], Miss> {
        let b = self
            .bytes
            .get(self.pos..self.pos.saturating_add(N))
            .and_then(|s| <[u8; N]>::try_from(s).ok())
            .ok_or(Miss::End)?;
        self.pos += N;
        Ok(b)
    }

    /// The next whitespace-separated token of an ASCII body.
    fn token(&mut self) -> Result<&'a str, Miss> {
        let bytes: &'a [u8] = self.bytes;
        let rest = bytes.get(self.pos..).unwrap_or_default();
        let skip = rest
            .iter()
            .position(|b| !b.is_ascii_whitespace())
            .ok_or(Miss::End)?;
        let gap = rest.get(..skip).unwrap_or_default();
        self.line += gap.iter().filter(|&&b| b == b'\n').count();
        let word = rest.get(skip..).unwrap_or_default();
        let len = word
            .iter()
            .position(u8::is_ascii_whitespace)
            .unwrap_or(word.len());
        self.pos += skip + len;
        let word = word.get(..len).unwrap_or_default();
        std::str::from_utf8(word)
            .map_err(|_| Miss::Bad(format!("line {}: a token that is not text", self.line)))
    }

    fn read(&mut self, t: Scalar) -> Result<Num, Miss> {
        macro_rules! bin {
            ($ty:ty, $n:literal) => {{
                let b = self.take::<$n>()?;
                if self.format == Format::Little {
                    <$ty>::from_le_bytes(b)
                } else {
                    <$ty>::from_be_bytes(b)
                }
            }};
        }
        if self.format == Format::Ascii {
            let word = self.token()?;
            let line = self.line;
            let bad = || {
                Miss::Bad(format!(
                    "line {line}: `{word}` is not a number of type {t:?}"
                ))
            };
            return if t.is_int() {
                word.parse::<i64>().map(Num::Int).map_err(|_| bad())
            } else {
                word.parse::<f64>().map(Num::Float).map_err(|_| bad())
            };
        }
        Ok(match t {
            Scalar::I8 => Num::Int(bin!(i8, 1).into()),
            Scalar::U8 => Num::Int(bin!(u8, 1).into()),
            Scalar::I16 => Num::Int(bin!(i16, 2).into()),
            Scalar::U16 => Num::Int(bin!(u16, 2).into()),
            Scalar::I32 => Num::Int(bin!(i32, 4).into()),
            Scalar::U32 => Num::Int(bin!(u32, 4).into()),
            Scalar::F32 => Num::Float(bin!(f32, 4).into()),
            Scalar::F64 => Num::Float(bin!(f64, 8)),
        })
    }

    /// A list's length, checked against the bytes that follow (each item takes at least
    /// one byte in ASCII, its size in binary).
    fn list_len(&mut self, count: Scalar, item: Scalar, name: &str) -> Result<usize, Miss> {
        let n = match self.read(count)? {
            Num::Int(n) => n,
            Num::Float(_) => {
                return Err(Miss::Bad(format!(
                    "list `{name}`: length not a whole number"
                )));
            }
        };
        let item_size = if self.format == Format::Ascii {
            1
        } else {
            item.size()
        };
        let n =
            usize::try_from(n).map_err(|_| Miss::Bad(format!("list `{name}` has length {n}")))?;
        if n.saturating_mul(item_size) > self.remaining() {
            return Err(Miss::Bad(format!(
                "list `{name}` claims {n} items of at least {item_size} bytes each, but {} \
                 bytes follow: the length is absurd or the file is cut short",
                self.remaining()
            )));
        }
        Ok(n)
    }

    /// Reads past one property's value.
    fn skip(&mut self, p: &Property) -> Result<(), Miss> {
        match p.kind {
            Kind::Scalar(t) => self.read(t).map(|_| ()),
            Kind::List(count, item) => {
                let n = self.list_len(count, item, &p.name)?;
                if self.format == Format::Ascii {
                    for _ in 0..n {
                        self.read(item)?;
                    }
                } else {
                    // Checked by `list_len`: n items fit in what follows.
                    self.pos = self.pos.saturating_add(n.saturating_mul(item.size()));
                }
                Ok(())
            }
        }
    }
}

/// What a vertex property is to photonflow.
#[derive(Clone, Copy)]
enum Role {
    Position(usize),
    Normal(usize),
    Uv(usize),
    Skip,
}

/// The roles of `vertex`'s properties, and whether it has normals and texture coordinates.
fn vertex_roles(e: &Element) -> Result<(Vec<Role>, bool, bool), String> {
    let mut roles = vec![Role::Skip; e.properties.len()];
    let mut set = |name: &str, role: Role| -> Result<bool, String> {
        let Some((i, p)) = e.property(name) else {
            return Ok(false);
        };
        if let Kind::List(..) = p.kind {
            return Err(format!(
                "property `{name}` of element `vertex` is a list, not a number"
            ));
        }
        if let Some(r) = roles.get_mut(i) {
            *r = role;
        }
        Ok(true)
    };
    for (k, axis) in ["x", "y", "z"].into_iter().enumerate() {
        if !set(axis, Role::Position(k))? {
            let has: Vec<&str> = e.properties.iter().map(|p| p.name.as_str()).collect();
            return Err(format!(
                "element `vertex` has no property `{axis}` (it has: {})",
                if has.is_empty() {
                    "none".to_string()
                } else {
                    has.join(", ")
                }
            ));
        }
    }
    let all = |names: &[&str]| names.iter().all(|n| e.property(n).is_some());
    let normals = all(&["nx", "ny", "nz"]);
    if normals {
        for (k, n) in ["nx", "ny", "nz"].into_iter().enumerate() {
            set(n, Role::Normal(k))?;
        }
    }
    let uv = [
        ["u", "v"],
        ["s", "t"],
        ["texture_u", "texture_v"],
        ["texture_s", "texture_t"],
    ]
    .into_iter()
    .find(|pair| all(pair));
    if let Some(pair) = uv {
        for (k, n) in pair.into_iter().enumerate() {
            set(n, Role::Uv(k))?;
        }
    }
    Ok((roles, normals, uv.is_some()))
}

/// The index list of `face`: its position among the properties, and its item type.
fn face_list(e: &Element) -> Result<usize, String> {
    let (i, p) = e
        .property("vertex_indices")
        .or_else(|| e.property("vertex_index"))
        .ok_or("element `face` has no `vertex_indices` list")?;
    match p.kind {
        Kind::List(_, item) if item.is_int() => Ok(i),
        Kind::List(_, item) => Err(format!(
            "list `{}` has items of type {item:?}; vertex indices are integers",
            p.name
        )),
        Kind::Scalar(_) => Err(format!(
            "property `{}` of element `face` is not a list",
            p.name
        )),
    }
}

/// Entries per task of a binary body's parallel reading.
pub(crate) const BLOCK: usize = 1 << 14;

/// A PLY file's mesh, or the problem with it (one line, without the file's name).
pub(crate) fn parse(bytes: &[u8]) -> Result<PlyMesh, String> {
    parse_with(bytes, BLOCK)
}

/// [`parse`], a binary body's vertices and faces read on every core in tasks of `block`
/// entries (0: read in order, as an ASCII body always is). The result is the same, bit for
/// bit; a problem found in parallel is found again in order, so its message is too.
pub(crate) fn parse_with(bytes: &[u8], block: usize) -> Result<PlyMesh, String> {
    let (format, elements, start) = header(bytes)?;
    let vertex = elements.iter().find(|e| e.name == "vertex");
    let Some(vertex) = vertex else {
        return Err("the file has no `element vertex`".to_string());
    };
    let (roles, has_normals, has_uv) = vertex_roles(vertex)?;
    let face = elements.iter().find(|e| e.name == "face");
    let Some(face) = face.filter(|f| f.count > 0) else {
        return Err("the file holds no faces (no `element face`, or its count is 0)".to_string());
    };
    let index_list = face_list(face)?;
    let mut body = Body {
        bytes,
        pos: start,
        format,
        line: bytes
            .get(..start)
            .unwrap_or_default()
            .iter()
            .filter(|&&b| b == b'\n')
            .count()
            + 1,
    };
    let mut mesh = PlyMesh::default();
    for e in &elements {
        if e.properties.is_empty() {
            continue;
        }
        let min = e.min_entry(format);
        if e.count.saturating_mul(min) > body.remaining() {
            return Err(format!(
                "element `{}` claims {} entries of at least {min} bytes each, but {} bytes \
                 follow: the count is absurd or the file is cut short",
                e.name,
                e.count,
                body.remaining()
            ));
        }
        let miss = |entry: usize, m: Miss| match m {
            Miss::End => format!(
                "the body ends inside element `{}` (entry {entry} of {}): the file is cut short",
                e.name, e.count
            ),
            Miss::Bad(what) => format!("element `{}` entry {entry}: {what}", e.name),
        };
        let par = block > 0 && format != Format::Ascii;
        if par && e.name == "vertex" && vertices_par(&mut body, e, &roles, &mut mesh, block) {
            continue;
        }
        if par && e.name == "face" && faces_par(&mut body, e, index_list, &mut mesh, block) {
            continue;
        }
        for entry in 0..e.count {
            if e.name == "vertex" {
                read_vertex(&mut body, e, &roles, has_normals, has_uv, &mut mesh)
            } else if e.name == "face" {
                let PlyMesh {
                    indices, arities, ..
                } = &mut mesh;
                read_face(
                    &mut body,
                    e,
                    index_list,
                    &mut |v| {
                        indices.push(v);
                        true
                    },
                    &mut |a| {
                        arities.push(a);
                        true
                    },
                )
            } else {
                e.properties.iter().try_for_each(|p| body.skip(p))
            }
            .map_err(|m| miss(entry, m))?;
        }
    }
    let nv = mesh.positions.len() / 3;
    if let Some(i) = mesh
        .indices
        .par_iter()
        .position_first(|&i| i as usize >= nv)
    {
        let mut start = 0usize;
        let f = mesh
            .arities
            .iter()
            .position(|&a| {
                start += a as usize;
                start > i
            })
            .unwrap_or_default();
        return Err(format!(
            "face {f}: vertex index {} out of range (the file has {nv} vertices)",
            mesh.indices.get(i).copied().unwrap_or_default()
        ));
    }
    Ok(mesh)
}

fn read_vertex(
    body: &mut Body,
    e: &Element,
    roles: &[Role],
    has_normals: bool,
    has_uv: bool,
    mesh: &mut PlyMesh,
) -> Result<(), Miss> {
    let (p, n, uv) = vertex(body, e, roles)?;
    mesh.positions.extend(p);
    if has_normals {
        mesh.normals.extend(n);
    }
    if has_uv {
        mesh.texcoords.extend(turned(uv));
    }
    Ok(())
}

/// Counted down from the image's top, as Mitsuba 3 writes and reads PLY files: OBJ's `vt`
/// (and the textures here) count up, so `v` turns over.
fn turned([u, v]: [f64; 2]) -> [f32; 2] {
    [u as f32, (1.0 - v) as f32]
}

/// One vertex entry: its position, normal and texture coordinates (zeros where the file has
/// none).
type Values = ([f64; 3], [f64; 3], [f64; 2]);

fn vertex(body: &mut Body, e: &Element, roles: &[Role]) -> Result<Values, Miss> {
    let (mut p, mut n, mut uv) = ([0.0f64; 3], [0.0f64; 3], [0.0f64; 2]);
    for (prop, role) in e.properties.iter().zip(roles) {
        let slot = match (*role, prop.kind) {
            (Role::Position(k), Kind::Scalar(t)) => p.get_mut(k).map(|s| (s, t)),
            (Role::Normal(k), Kind::Scalar(t)) => n.get_mut(k).map(|s| (s, t)),
            (Role::Uv(k), Kind::Scalar(t)) => uv.get_mut(k).map(|s| (s, t)),
            _ => None,
        };
        match slot {
            Some((s, t)) => *s = body.read(t)?.float(),
            None => body.skip(prop)?,
        }
    }
    Ok((p, n, uv))
}

/// A binary `vertex` element of scalars only (every entry the same size) read on every
/// core, or `false` (nothing read) for the sequential reading.
fn vertices_par(
    body: &mut Body,
    e: &Element,
    roles: &[Role],
    mesh: &mut PlyMesh,
    block: usize,
) -> bool {
    let size = e.min_entry(body.format);
    let scalars = e
        .properties
        .iter()
        .all(|p| matches!(p.kind, Kind::Scalar(_)));
    let end = body.pos.saturating_add(e.count.saturating_mul(size));
    let Some(src) = body
        .bytes
        .get(body.pos..end)
        .filter(|_| scalars && size > 0)
    else {
        return false;
    };
    let (normals, uv) = (mesh.normals.is_empty(), mesh.texcoords.is_empty());
    if !(mesh.positions.is_empty() && normals && uv) {
        return false;
    }
    let (has_n, has_uv) = (
        roles.iter().any(|r| matches!(r, Role::Normal(_))),
        roles.iter().any(|r| matches!(r, Role::Uv(_))),
    );
    let n = e.count;
    let mut p = vec![0.0f64; 3 * n];
    let mut nor = vec![0.0f64; if has_n { 3 * n } else { 0 }];
    let mut tex = vec![0.0f32; if has_uv { 2 * n } else { 0 }];
    let nors = nor.chunks_mut(3 * block).map(Some);
    let texs = tex.chunks_mut(2 * block).map(Some);
    let jobs: Vec<_> = src
        .chunks(size * block)
        .zip(p.chunks_mut(3 * block))
        .zip(nors.chain(std::iter::repeat_with(|| None)))
        .zip(texs.chain(std::iter::repeat_with(|| None)))
        .collect();
    let format = body.format;
    let ok = jobs.into_par_iter().all(|(((src, p), mut nor), mut tex)| {
        for (k, entry) in src.chunks_exact(size).enumerate() {
            let mut b = Body {
                bytes: entry,
                pos: 0,
                format,
                line: 0,
            };
            let Ok((pp, nn, uv)) = vertex(&mut b, e, roles) else {
                return false;
            };
            let put = |to: Option<&mut [f64]>, from: &[f64]| {
                if let Some(to) = to {
                    to.copy_from_slice(from);
                }
            };
            put(p.get_mut(3 * k..3 * k + 3), &pp);
            put(
                nor.as_deref_mut().and_then(|s| s.get_mut(3 * k..3 * k + 3)),
                &nn,
            );
            if let Some(t) = tex.as_deref_mut().and_then(|s| s.get_mut(2 * k..2 * k + 2)) {
                t.copy_from_slice(&turned(uv));
            }
        }
        true
    });
    if ok {
        (mesh.positions, mesh.normals, mesh.texcoords) = (p, nor, tex);
        mesh.parallel += 1;
        body.pos = end;
    }
    ok
}

/// A binary `face` element read on every core: one pass in order finds where each task's
/// entries start and how many indices they hold, then each task reads its faces into its
/// part of the lists. `false` (nothing read) leaves the element to the sequential reading,
/// which also gives any problem's message.
fn faces_par(
    body: &mut Body,
    e: &Element,
    index_list: usize,
    mesh: &mut PlyMesh,
    block: usize,
) -> bool {
    if !(mesh.indices.is_empty() && mesh.arities.is_empty()) {
        return false;
    }
    let mut scan = Body {
        bytes: body.bytes,
        pos: body.pos,
        format: body.format,
        line: body.line,
    };
    // Per task: its first byte and its number of indices.
    let mut tasks: Vec<(usize, usize)> = Vec::new();
    for entry in 0..e.count {
        if entry % block == 0 {
            tasks.push((scan.pos, 0));
        }
        for (i, prop) in e.properties.iter().enumerate() {
            let counted = match prop.kind {
                Kind::List(count, item) if i == index_list => {
                    let n = scan.list_len(count, item, &prop.name).ok();
                    let skip = n.unwrap_or(0).saturating_mul(item.size());
                    scan.pos = scan.pos.saturating_add(skip);
                    n
                }
                _ => scan.skip(prop).ok().map(|()| 0),
            };
            match (counted, tasks.last_mut()) {
                (Some(n), Some(t)) => t.1 += n,
                _ => return false,
            }
        }
    }
    let total: usize = tasks.iter().map(|t| t.1).sum();
    let mut indices = vec![0u32; total];
    let mut arities = vec![0u32; e.count];
    let mut jobs = Vec::with_capacity(tasks.len());
    let (mut rest, mut ar) = (&mut indices[..], &mut arities[..]);
    for &(start, n) in &tasks {
        let (mine, after) = rest.split_at_mut(n);
        let (faces, more) = ar.split_at_mut(block.min(ar.len()));
        jobs.push((start, mine, faces));
        (rest, ar) = (after, more);
    }
    let format = body.format;
    let ok = jobs.into_par_iter().all(|(start, idx, faces)| {
        let mut b = Body {
            bytes: body.bytes,
            pos: start,
            format,
            line: 0,
        };
        let (mut idx, mut faces) = (idx.iter_mut(), faces.iter_mut());
        (0..faces.len()).all(|_| {
            let mut index = |v| idx.next().map(|s| *s = v).is_some();
            let mut arity = |a| faces.next().map(|s| *s = a).is_some();
            read_face(&mut b, e, index_list, &mut index, &mut arity).is_ok()
        })
    });
    if ok {
        (mesh.indices, mesh.arities) = (indices, arities);
        mesh.parallel += 1;
        body.pos = scan.pos;
    }
    ok
}

/// One face entry, its indices and arity handed to `index` and `arity` (each `false` when it
/// has no room: an error).
fn read_face(
    body: &mut Body,
    e: &Element,
    index_list: usize,
    index: &mut impl FnMut(u32) -> bool,
    arity: &mut impl FnMut(u32) -> bool,
) -> Result<(), Miss> {
    for (i, prop) in e.properties.iter().enumerate() {
        let Kind::List(count, item) = prop.kind else {
            body.skip(prop)?;
            continue;
        };
        if i != index_list {
            body.skip(prop)?;
            continue;
        }
        let n = body.list_len(count, item, &prop.name)?;
        let n_arity = u32::try_from(n).map_err(|_| Miss::Bad(format!("a face of {n} vertices")))?;
        for _ in 0..n {
            let v = match body.read(item)? {
                Num::Int(v) => v,
                Num::Float(x) => return Err(Miss::Bad(format!("vertex index {x}"))),
            };
            let v = u32::try_from(v).map_err(|_| {
                Miss::Bad(format!(
                    "vertex index {v} is negative or above {}",
                    u32::MAX
                ))
            })?;
            if !index(v) {
                return Err(Miss::Bad("more indices than counted".to_string()));
            }
        }
        if !arity(n_arity) {
            return Err(Miss::Bad("more faces than counted".to_string()));
        }
    }
    Ok(())
}
