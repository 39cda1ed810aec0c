//! OBJ text read on every core: the file is cut into chunks at line ends, each chunk's
//! vertices, faces and directives (`o`, `g`, `usemtl`, `mtllib`) are read in parallel, and one
//! sequential pass over the directives, in file order, forms the models and reads the MTL
//! files. The result is what tobj 4's `load_obj_buf` gives with `single_index`, untriangulated
//! faces and points and lines ignored (the reader used before, whose rules the scene files
//! keep): the same models, names, material ids, vertices in the same order, indices, face
//! arities and errors (tobj's own `LoadError`, so messages are unchanged), whatever the
//! chunks. `crates/scene/src/tests/objtext.rs` holds it to tobj on tricky and mutated files.
//!
//! tobj's rules kept here: a line is split at Unicode whitespace; `#`, unknown keywords and
//! blank lines are skipped; `v` takes three floats, then a `w` that divides them or three
//! colours; `vt` two and `vn` three floats (more are ignored); an `f` or `l` corner is
//! `v[/vt[/vn]]` with 1-based or negative (relative to the count so far) indices, 0 meaning
//! none; `o` and `g` start a model when faces came before them, and so does a `usemtl` that
//! changes the material; a model's vertices are its distinct `(v, vt, vn)` triples in order
//! of first use, checked against the counts read up to the model's end. One difference:
//! tobj wraps the arithmetic of a texture or normal index near 2^63 and may read a wrong
//! element; here such an index is out of bounds.

use rayon::prelude::*;
use std::collections::HashMap;
use std::path::Path;
use tobj::LoadError;

/// An index that is absent (tobj's `MISSING_INDEX`: an empty slot, 0, or -1 past the start).
const MISSING: u64 = u64::MAX;
/// A position index kept as u32: absent, or too large for any file this reader can hold
/// (both are out of bounds).
const V_MISSING: u32 = u32::MAX;
const V_BIG: u32 = u32::MAX - 1;

/// Bytes per chunk: large enough that a chunk's fixed costs vanish, small enough that two
/// cores share the work evenly. Chunks depend on the file alone, not on the thread count.
pub(crate) const CHUNK: usize = 4 << 20;

/// One model (an `o`/`g` group, or its part under one material), as tobj's `Model` and
/// `Mesh` hold it.
#[derive(Debug, Default, PartialEq)]
pub(crate) struct ObjModel {
    pub name: String,
    pub material_id: Option<usize>,
    pub positions: Vec<f32>,
    pub normals: Vec<f32>,
    pub texcoords: Vec<f32>,
    pub indices: Vec<u32>,
    /// Each face's corner count; empty when every face is a triangle.
    pub face_arities: Vec<u32>,
}

/// A parsed OBJ file, with the directives `obj.rs` checks.
#[derive(Debug)]
pub(crate) struct ObjText {
    pub models: Vec<ObjModel>,
    /// The MTL files' materials (tobj's `Result`: an error only when none loaded).
    pub materials: Result<Vec<tobj::Material>, LoadError>,
    /// First `usemtl` line of each name: 1-based line number and name (the line trimmed,
    /// its text after the first space, trimmed).
    pub usemtl: Vec<(usize, String)>,
    /// Lines that are neither blank nor comments.
    pub lines: usize,
}

/// A directive, read in file order by the sequential pass.
#[derive(Debug)]
enum Kind {
    /// `o` or `g` with its name.
    Group(String),
    /// `usemtl`: the name as tobj reads it (after the line's first space) and as the
    /// directive list reads it (after the trimmed line's first space).
    Usemtl(String, String),
    Mtllib(String),
}

/// Where in its chunk a directive stands: its line and the counts read before it.
#[derive(Debug)]
struct Event {
    line: usize,
    faces: usize,
    corners: usize,
    counts: Counts,
    kind: Kind,
}

/// Numbers of positions, texture coordinates, normals and colour values.
#[derive(Clone, Copy, Debug, Default)]
struct Counts {
    pos: usize,
    tex: usize,
    nor: usize,
    colors: usize,
}

impl Counts {
    fn add(self, o: Counts) -> Counts {
        Counts {
            pos: self.pos + o.pos,
            tex: self.tex + o.tex,
            nor: self.nor + o.nor,
            colors: self.colors + o.colors,
        }
    }
}

/// What one chunk holds.
#[derive(Default)]
struct Chunk {
    pos: Vec<f32>,
    tex: Vec<f32>,
    nor: Vec<f32>,
    colors: usize,
    /// Each corner's position index, resolved (relative ones once the counts before the
    /// chunk are known, through `rel`).
    v: Vec<u32>,
    /// Texture and normal indices per corner: empty until the chunk's first corner with one.
    vt: Vec<u64>,
    vn: Vec<u64>,
    /// Corners per face (points and lines included, as tobj keeps them until export).
    arity: Vec<u32>,
    /// Negative indices: corner, slot (0 v, 1 vt, 2 vn) and the value relative to the start
    /// of the chunk.
    rel: Vec<(usize, u8, i64)>,
    events: Vec<Event>,
    /// The chunk's first error: its line and what tobj says.
    error: Option<(usize, LoadError)>,
    lines: usize,
    nonblank: usize,
}

/// Whitespace-separated words, as `str::split_whitespace` gives them, bytes compared
/// directly for ASCII.
struct Words<'a> {
    rest: &'a str,
}

impl<'a> Words<'a> {
    fn span(&self, from: usize, ws: bool) -> usize {
        let b = self.rest.as_bytes();
        let mut i = from;
        while let Some(&c) = b.get(i) {
            let (is_ws, len) = if c < 0x80 {
                (c == b' ' || (0x09..=0x0d).contains(&c), 1)
            } else {
                match self.rest.get(i..).and_then(|s| s.chars().next()) {
                    Some(ch) => (ch.is_whitespace(), ch.len_utf8()),
                    None => (false, 1),
                }
            };
            if is_ws != ws {
                break;
            }
            i += len;
        }
        i
    }
}

impl<'a> Iterator for Words<'a> {
    type Item = &'a str;
    fn next(&mut self) -> Option<&'a str> {
        let start = self.span(0, true);
        let end = self.span(start, false);
        let word = self.rest.get(start..end)?;
        self.rest = self.rest.get(end..).unwrap_or("");
        (!word.is_empty()).then_some(word)
    }
}

/// tobj's `parse_floatn`: `n` floats from the next `n` words.
fn floats(w: &mut Words, out: &mut Vec<f32>, n: usize) -> bool {
    for _ in 0..n {
        match w.next().map(str::parse::<f32>) {
            Some(Ok(x)) => out.push(x),
            _ => return false,
        }
    }
    true
}

/// An index word as `isize::from_str` reads it: plain digits quickly, anything else by std.
fn int(s: &str) -> Option<i64> {
    let b = s.as_bytes();
    if !b.is_empty() && b.len() <= 18 && b.iter().all(u8::is_ascii_digit) {
        return Some(b.iter().fold(0i64, |a, &d| a * 10 + (d - b'0') as i64));
    }
    s.parse::<isize>().ok().map(|x| x as i64)
}

/// A word of decimal digits with at most one `.` and an optional sign, as `f32::from_str`
/// reads it, or `None` for anything else (an exponent, `inf`, more digits than below), which
/// the general path reads. Clinger's fast path: a significand below 2^24 and a power of ten
/// up to 10^10 are both exact in f32, so their quotient is the correctly rounded value, as
/// std's (correctly rounding) parser gives it.
pub(crate) fn decimal(w: &[u8]) -> Option<f32> {
    let (neg, digits) = match w {
        [b'-', rest @ ..] => (true, rest),
        [b'+', rest @ ..] => (false, rest),
        _ => (false, w),
    };
    if digits.is_empty() || digits.len() > 12 {
        return None;
    }
    let (mut m, mut scale, mut dot, mut any) = (0u64, 0usize, false, false);
    for &c in digits {
        match c {
            b'0'..=b'9' => {
                m = m * 10 + (c - b'0') as u64;
                scale += dot as usize;
                any = true;
            }
            b'.' if !dot => dot = true,
            _ => return None,
        }
    }
    const TEN: [f32; 11] = [1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10];
    let &p = TEN.get(scale)?;
    if !any || m > 1 << 24 {
        return None;
    }
    let x = m as f32 / p;
    Some(if neg { -x } else { x })
}

/// A position index of 1 to 9 digits (no sign, not 0), as [`Chunk::corner`] resolves it.
fn index(w: &[u8]) -> Option<u32> {
    if w.is_empty() || w.len() > 9 || !w.iter().all(u8::is_ascii_digit) {
        return None;
    }
    let x = w.iter().fold(0u32, |a, &d| a * 10 + (d - b'0') as u32);
    x.checked_sub(1)
}

/// A resolved index as tobj's `usize` (`(count + x) as usize` for negative `x`).
fn as_index(x: i64) -> u64 {
    x as u64
}

fn v32(x: u64) -> u32 {
    if x == MISSING {
        V_MISSING
    } else {
        u32::try_from(x).map_or(V_BIG, |v| v.min(V_BIG))
    }
}

impl Chunk {
    fn counts(&self) -> Counts {
        Counts {
            pos: self.pos.len() / 3,
            tex: self.tex.len() / 2,
            nor: self.nor.len() / 3,
            colors: self.colors,
        }
    }

    fn event(&mut self, line: usize, kind: Kind) {
        self.events.push(Event {
            line,
            faces: self.arity.len(),
            corners: self.v.len(),
            counts: self.counts(),
            kind,
        });
    }

    /// One corner `v[/vt[/vn]]` (tobj's `VertexIndices::parse`).
    fn corner(&mut self, word: &str) -> bool {
        let mut idx = [MISSING; 3];
        let corner = self.v.len();
        for (slot, part) in word.split('/').enumerate() {
            if part.is_empty() {
                continue;
            }
            let Some(x) = int(part) else { return false };
            let Some(out) = idx.get_mut(slot) else {
                return false;
            };
            *out = if x < 0 {
                let count = match slot {
                    0 => self.pos.len() / 3,
                    1 => self.tex.len() / 2,
                    _ => self.nor.len() / 3,
                };
                self.rel.push((corner, slot as u8, count as i64 + x));
                MISSING
            } else {
                as_index(x - 1)
            };
        }
        let [v, vt, vn] = idx;
        self.v.push(v32(v));
        for (col, x) in [(&mut self.vt, vt), (&mut self.vn, vn)] {
            if x != MISSING || !col.is_empty() {
                col.resize(corner, MISSING);
                col.push(x);
            }
        }
        true
    }

    /// A plain `v x y z` or `f a b c ...` line (ASCII spaces or tabs between words, simple
    /// decimals, positive indices, no texture or normal index in the chunk so far) read
    /// without the general path's word splitting and parsing: most of a large file. `false`
    /// leaves the chunk as it was, for [`Chunk::line`]'s general reading.
    fn plain(&mut self, line: &[u8]) -> bool {
        let blank = |c: &u8| *c == b' ' || *c == b'\t';
        let (kind, rest) = match line {
            [k @ (b'v' | b'f'), c, rest @ ..] if blank(c) => (*k, rest),
            _ => return false,
        };
        let mut words = rest.split(blank).filter(|w| !w.is_empty());
        if kind == b'v' {
            let mut xyz = [0.0f32; 3];
            for x in &mut xyz {
                match words.next().and_then(decimal) {
                    Some(v) => *x = v,
                    None => return false,
                }
            }
            if words.next().is_some() {
                return false;
            }
            self.pos.extend_from_slice(&xyz);
        } else {
            if !(self.vt.is_empty() && self.vn.is_empty()) {
                return false;
            }
            let before = self.v.len();
            for w in words {
                match index(w) {
                    Some(v) => self.v.push(v),
                    None => {
                        self.v.truncate(before);
                        return false;
                    }
                }
            }
            if self.v.len() == before {
                return false;
            }
            self.arity.push((self.v.len() - before) as u32);
        }
        self.nonblank += 1;
        true
    }

    /// One line; `Err` stops the chunk.
    fn line(&mut self, n: usize, line: &str) -> Result<(), LoadError> {
        if self.plain(line.as_bytes()) {
            return Ok(());
        }
        let mut w = Words { rest: line };
        let Some(first) = w.next() else {
            return Ok(());
        };
        if !first.starts_with('#') {
            self.nonblank += 1;
        }
        match first {
            "v" => {
                if !floats(&mut w, &mut self.pos, 3) {
                    return Err(LoadError::PositionParseError);
                }
                let Some(a) = w.next() else { return Ok(()) };
                match (w.next(), w.next()) {
                    (None, _) => {
                        let s: f32 = a.parse().map_err(|_| LoadError::PositionParseError)?;
                        if s == 0.0 {
                            return Err(LoadError::ScalingByZeroError);
                        }
                        let k = self.pos.len().saturating_sub(3);
                        for c in self.pos.get_mut(k..).unwrap_or_default() {
                            *c /= s;
                        }
                    }
                    (Some(_), None) => return Err(LoadError::ColorParseError),
                    (Some(b), Some(c)) => {
                        if w.next().is_some() {
                            return Err(LoadError::ColorParseError);
                        }
                        for x in [a, b, c] {
                            if x.parse::<f32>().is_err() {
                                break;
                            }
                            self.colors += 1;
                        }
                    }
                }
            }
            "vt" if !floats(&mut w, &mut self.tex, 2) => return Err(LoadError::TexcoordParseError),
            "vn" if !floats(&mut w, &mut self.nor, 3) => return Err(LoadError::NormalParseError),
            "f" | "l" => {
                let before = self.v.len();
                for word in w {
                    if !self.corner(word) {
                        return Err(LoadError::FaceParseError);
                    }
                }
                self.arity.push((self.v.len() - before) as u32);
            }
            "o" | "g" => {
                let mut c = line.chars();
                c.next();
                let name = c.as_str().trim();
                let name = if name.is_empty() {
                    "unnamed_object"
                } else {
                    name
                };
                self.event(n, Kind::Group(name.to_string()));
            }
            "mtllib" => {
                let file = line.split_once(' ').unwrap_or_default().1.trim();
                self.event(n, Kind::Mtllib(file.to_string()));
            }
            "usemtl" => {
                let name = line.split_once(' ').unwrap_or_default().1.trim();
                if name.is_empty() {
                    return Err(LoadError::MaterialParseError);
                }
                let listed = line.trim().split_once(' ').unwrap_or_default().1.trim();
                self.event(n, Kind::Usemtl(name.to_string(), listed.to_string()));
            }
            _ => {}
        }
        Ok(())
    }
}

/// Reads `bytes[range]`, which starts at a line start and ends after a line end (or at the
/// end of the file).
fn read_chunk(bytes: &[u8]) -> Chunk {
    let mut c = Chunk::default();
    // Line ends are ASCII: a chunk is valid UTF-8 up to the first line that is not.
    let (text, bad) = match std::str::from_utf8(bytes) {
        Ok(t) => (t, false),
        Err(e) => (
            std::str::from_utf8(bytes.get(..e.valid_up_to()).unwrap_or_default())
                .unwrap_or_default(),
            true,
        ),
    };
    let mut lines = text.split('\n').peekable();
    let mut n = 0;
    while let Some(line) = lines.next() {
        let last = lines.peek().is_none();
        if last && bad {
            // The line holding the invalid byte: `BufRead::lines` fails there.
            c.error = Some((n, LoadError::ReadError));
            break;
        }
        if last && line.is_empty() {
            break;
        }
        if let Err(e) = c.line(n, line.strip_suffix('\r').unwrap_or(line)) {
            c.error = Some((n, e));
            break;
        }
        n += 1;
    }
    c.lines = n;
    c
}

/// Chunk boundaries: after the first `\n` at or past every multiple of `size`.
fn cuts(bytes: &[u8], size: usize) -> Vec<usize> {
    let mut cuts = vec![0];
    let mut at = 0;
    while at + size < bytes.len() {
        let from = at + size;
        match bytes
            .get(from..)
            .and_then(|b| b.iter().position(|&c| c == b'\n'))
        {
            Some(p) => at = from + p + 1,
            None => break,
        }
        if at >= bytes.len() {
            break;
        }
        cuts.push(at);
    }
    cuts.push(bytes.len());
    cuts
}

/// The MTL materials loaded so far (tobj's `TmpMaterials`).
#[derive(Default)]
struct Materials {
    list: Vec<tobj::Material>,
    map: HashMap<String, usize>,
    err: Option<LoadError>,
}

impl Materials {
    fn merge(&mut self, r: tobj::MTLLoadResult) {
        match r {
            Ok((mut mats, map)) => {
                let offset = self.list.len();
                self.list.append(&mut mats);
                for (k, v) in map {
                    self.map.insert(k, v + offset);
                }
            }
            Err(e) => self.err = Some(e),
        }
    }
}

/// A face position: chunk, face and corner within it.
#[derive(Clone, Copy, Default)]
struct At {
    chunk: usize,
    face: usize,
    corner: usize,
}

/// The sequential pass: models formed and exported in file order.
struct Former<'c> {
    chunks: &'c [Chunk],
    base: Vec<Counts>,
    pos: Vec<f32>,
    tex: Vec<f32>,
    nor: Vec<f32>,
    /// The export's vertex table: the latest model vertex of each position index
    /// (`u32::MAX`: none yet), chained through `extra` where a position has several texture or
    /// normal indices.
    slot: Vec<u32>,
    models: Vec<ObjModel>,
    name: String,
    mat: Option<usize>,
    start: At,
    par: Parallel,
}

impl Former<'_> {
    fn corner_vt(&self, c: &Chunk, i: usize) -> (u64, u64) {
        let get = |col: &Vec<u64>| col.get(i).copied().unwrap_or(MISSING);
        (get(&c.vt), get(&c.vn))
    }

    /// Exports the faces from `self.start` to `end` as tobj's `export_faces` does, against
    /// the counts read before the directive that ends the model.
    fn pop(&mut self, end: At, counts: Counts) -> Result<(), LoadError> {
        let mut m = ObjModel {
            name: self.name.clone(),
            material_id: self.mat,
            ..ObjModel::default()
        };
        if let Some((positions, indices, face_arities)) =
            plain_model(self.chunks, self.start, end, &self.pos, counts, self.par)
        {
            self.models.push(ObjModel {
                positions,
                indices,
                face_arities,
                ..m
            });
            self.start = end;
            return Ok(());
        }
        // Per new vertex: its texture and normal index and the next vertex of its position.
        let mut extra: Vec<(u64, u64, u32)> = Vec::new();
        let mut used: Vec<u32> = Vec::new();
        let mut triangles_only = true;
        let mut faces = 0usize;
        let mut at = self.start;
        let result = (|| {
            while (at.chunk, at.face) < (end.chunk, end.face) {
                let Some(c) = self.chunks.get(at.chunk) else {
                    break;
                };
                let stop = if at.chunk == end.chunk {
                    end.face
                } else {
                    c.arity.len()
                };
                while at.face < stop {
                    let n = c.arity.get(at.face).copied().unwrap_or(0) as usize;
                    let first = at.corner;
                    at.face += 1;
                    at.corner += n;
                    if n == 1 || n == 2 {
                        continue; // points and lines are ignored
                    }
                    for i in first..first + n {
                        let v = c.v.get(i).copied().unwrap_or(V_MISSING);
                        let (vt, vn) = self.corner_vt(c, i);
                        let id = self.vertex(&mut m, &mut extra, &mut used, v, vt, vn, counts)?;
                        m.indices.push(id);
                    }
                    if n != 3 && triangles_only {
                        triangles_only = false;
                        m.face_arities = vec![3; faces];
                    }
                    if !triangles_only {
                        m.face_arities.push(n as u32);
                    }
                    faces += 1;
                }
                if at.chunk == end.chunk {
                    break;
                }
                at = At {
                    chunk: at.chunk + 1,
                    face: 0,
                    corner: 0,
                };
            }
            Ok(())
        })();
        for v in used {
            if let Some(s) = self.slot.get_mut(v as usize) {
                *s = u32::MAX;
            }
        }
        result?;
        self.models.push(m);
        self.start = end;
        Ok(())
    }

    /// tobj's `add_vertex`: the model's vertex for `(v, vt, vn)`, added and checked when new.
    #[allow(clippy::too_many_arguments)]
    fn vertex(
        &mut self,
        m: &mut ObjModel,
        extra: &mut Vec<(u64, u64, u32)>,
        used: &mut Vec<u32>,
        v: u32,
        vt: u64,
        vn: u64,
        counts: Counts,
    ) -> Result<u32, LoadError> {
        let vi = v as usize;
        let plain = vt == MISSING && vn == MISSING;
        let head = self.slot.get(vi).copied().unwrap_or(u32::MAX);
        if extra.is_empty() {
            // Every vertex so far is plain: one per position, no chain to walk.
            if head != u32::MAX && plain {
                return Ok(head);
            }
        } else {
            let mut k = head;
            while let Some(&(t, n, next)) = extra.get(k as usize) {
                if (t, n) == (vt, vn) {
                    return Ok(k);
                }
                k = next;
            }
        }
        if v >= V_BIG || vi >= counts.pos {
            return Err(LoadError::FaceVertexOutOfBounds);
        }
        let id = (m.positions.len() / 3) as u32;
        m.positions
            .extend_from_slice(self.pos.get(3 * vi..3 * vi + 3).unwrap_or_default());
        if counts.tex > 0 && vt != MISSING {
            let t = usize::try_from(vt).ok().filter(|&t| t < counts.tex);
            let t = t.ok_or(LoadError::FaceTexCoordOutOfBounds)?;
            m.texcoords
                .extend_from_slice(self.tex.get(2 * t..2 * t + 2).unwrap_or_default());
        }
        if counts.nor > 0 && vn != MISSING {
            let n = usize::try_from(vn).ok().filter(|&n| n < counts.nor);
            let n = n.ok_or(LoadError::FaceNormalOutOfBounds)?;
            m.normals
                .extend_from_slice(self.nor.get(3 * n..3 * n + 3).unwrap_or_default());
        }
        if counts.colors > 0 && vi.saturating_mul(3).saturating_add(2) >= counts.colors {
            return Err(LoadError::FaceColorOutOfBounds);
        }
        if !plain || !extra.is_empty() {
            // From the first corner with a texture or normal index on, every vertex is chained
            // (the plain ones before it are each alone on their position).
            extra.resize(id as usize, (MISSING, MISSING, u32::MAX));
            extra.push((vt, vn, head));
        }
        if let Some(s) = self.slot.get_mut(vi) {
            if *s == u32::MAX {
                used.push(v);
            }
            *s = id;
        }
        Ok(id)
    }
}

/// The faces of one chunk that a model holds, and the corner its first face starts at.
struct Span<'c> {
    c: &'c Chunk,
    faces: std::ops::Range<usize>,
    corner: usize,
}

impl Span<'_> {
    /// `f(first corner, corners)` of each face the model keeps (points and lines are ignored).
    fn each(&self, mut f: impl FnMut(usize, usize)) {
        let mut k = self.corner;
        for face in self.faces.clone() {
            let n = self.c.arity.get(face).copied().unwrap_or(0) as usize;
            if n != 1 && n != 2 {
                f(k, n);
            }
            k += n;
        }
    }
}

/// When [`plain_model`] takes a model, and its task size: tests make both small.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Parallel {
    /// Corners below which a model is numbered sequentially only (0: every plain model is
    /// numbered in parallel, however small).
    pub min_corners: usize,
    /// Corners per task of the numbering.
    pub block: usize,
}

pub(crate) const PARALLEL: Parallel = Parallel {
    min_corners: 1 << 16,
    block: 1 << 16,
};

/// What [`Former::pop`] makes of a large model whose corners carry no texture or normal index
/// (the file has no colours, every index is in range), on every core: positions, indices and
/// arities, bit for bit the sequential result, whose vertices are the positions in order of
/// first use. `None` leaves the model to the sequential path (a small model, one with texture
/// or normal indices, or one that fails, whose error that path gives).
fn plain_model(
    chunks: &[Chunk],
    start: At,
    end: At,
    pos: &[f32],
    counts: Counts,
    par: Parallel,
) -> Option<(Vec<f32>, Vec<u32>, Vec<u32>)> {
    use std::sync::atomic::{AtomicU32, Ordering::Relaxed};
    if counts.colors > 0 {
        return None;
    }
    let last = end.chunk.min(chunks.len().checked_sub(1)?);
    let spans: Vec<Span> = (start.chunk..=last)
        .filter_map(|ci| {
            let c = chunks.get(ci)?;
            let first = if ci == start.chunk { start.face } else { 0 };
            let stop = if ci == end.chunk {
                end.face
            } else {
                c.arity.len()
            };
            let corner = if ci == start.chunk { start.corner } else { 0 };
            (first < stop).then_some(Span {
                c,
                faces: first..stop,
                corner,
            })
        })
        .collect();
    // Each span's faces as the model keeps them (points and lines are ignored): corners, and
    // whether all are triangles and all plain.
    let stats: Vec<(usize, bool, bool)> = spans
        .par_iter()
        .map(|s| {
            let (mut corners, mut triangles, mut plain) = (0, true, true);
            let missing = |col: &Vec<u64>, r: std::ops::Range<usize>| {
                col.get(r).is_none_or(|x| x.iter().all(|&t| t == MISSING))
            };
            s.each(|k, n| {
                corners += n;
                triangles &= n == 3;
                plain &= missing(&s.c.vt, k..k + n) && missing(&s.c.vn, k..k + n);
            });
            (corners, triangles, plain)
        })
        .collect();
    let total: usize = stats.iter().map(|s| s.0).sum();
    // A model much smaller than the file's positions would spend more on its tables.
    let small = total < par.min_corners || total < counts.pos / 4;
    if (small && par.min_corners > 0) || total >= u32::MAX as usize || !stats.iter().all(|s| s.2) {
        return None;
    }
    // The corners' position indices, each span's written by its own task.
    let mut indices = vec![0u32; total];
    let mut rest = &mut indices[..];
    let mut jobs = Vec::with_capacity(spans.len());
    for (s, st) in spans.iter().zip(&stats) {
        let (mine, after) = rest.split_at_mut(st.0);
        jobs.push((s, mine));
        rest = after;
    }
    let in_range = jobs.into_par_iter().all(|(s, out)| {
        let mut at = out.iter_mut();
        let mut ok = true;
        s.each(|k, n| {
            for i in k..k + n {
                let v = s.c.v.get(i).copied().unwrap_or(V_MISSING);
                ok &= v < V_BIG && (v as usize) < counts.pos;
                if let Some(o) = at.next() {
                    *o = v;
                }
            }
        });
        ok
    });
    if !in_range {
        return None;
    }
    let arities = if stats.iter().all(|s| s.1) {
        Vec::new()
    } else {
        spans
            .par_iter()
            .flat_map_iter(|s| {
                let mut a = Vec::new();
                s.each(|_, n| a.push(n as u32));
                a
            })
            .collect()
    };
    // Each position's first corner (the least, whichever task sees it first), then the new
    // vertices of each block counted, numbered from the counts before the block and their
    // positions copied, then every corner given its position's vertex.
    let table = || -> Vec<AtomicU32> {
        (0..counts.pos)
            .into_par_iter()
            .map(|_| AtomicU32::new(u32::MAX))
            .collect()
    };
    let first = table();
    let blocks = || indices.par_chunks(par.block).enumerate();
    blocks().for_each(|(b, blk)| {
        for (j, &v) in blk.iter().enumerate() {
            let i = (b * par.block + j) as u32;
            if let Some(f) = first.get(v as usize).filter(|f| f.load(Relaxed) > i) {
                f.fetch_min(i, Relaxed);
            }
        }
    });
    let is_new = |b: usize, j: usize, v: u32| {
        first
            .get(v as usize)
            .is_some_and(|f| f.load(Relaxed) == (b * par.block + j) as u32)
    };
    let news: Vec<usize> = blocks()
        .map(|(b, blk)| {
            (blk.iter().enumerate())
                .filter(|&(j, &v)| is_new(b, j, v))
                .count()
        })
        .collect();
    let mut positions = vec![0f32; 3 * news.iter().sum::<usize>()];
    let mut rest = &mut positions[..];
    let mut outs = Vec::with_capacity(news.len());
    let mut id = 0u32;
    for &n in &news {
        let (mine, after) = rest.split_at_mut(3 * n);
        outs.push((id, mine));
        rest = after;
        id += n as u32;
    }
    let ids = table();
    blocks().zip(outs).for_each(|((b, blk), (mut id, out))| {
        let mut out = out.as_chunks_mut::<3>().0.iter_mut();
        for (j, &v) in blk.iter().enumerate() {
            if !is_new(b, j, v) {
                continue;
            }
            let (Some(slot), Some(o)) = (ids.get(v as usize), out.next()) else {
                continue;
            };
            slot.store(id, Relaxed);
            let vi = v as usize;
            o.copy_from_slice(pos.get(3 * vi..3 * vi + 3).unwrap_or(&[0.0; 3]));
            id += 1;
        }
    });
    indices
        .par_iter_mut()
        .for_each(|x| *x = ids.get(*x as usize).map_or(0, |i| i.load(Relaxed)));
    Some((positions, indices, arities))
}

/// An OBJ file read in chunks of `chunk` bytes on every core, before its directives are
/// followed ([`form`]): the file's bytes can go once this is done. Its [`Parallel`] is
/// [`PARALLEL`].
pub(crate) struct Read(Vec<Chunk>, pub(crate) Parallel);

pub(crate) fn read(bytes: &[u8], chunk: usize) -> Read {
    let cuts = cuts(bytes, chunk.max(1));
    Read(
        cuts.par_windows(2)
            .map(|w| match w {
                [a, b] => read_chunk(bytes.get(*a..*b).unwrap_or_default()),
                _ => Chunk::default(),
            })
            .collect(),
        PARALLEL,
    )
}

/// The models of a [`read`] file, its directives followed in file order. `load_mtl` reads the
/// MTL file a `mtllib` line names when the line is reached (an error it returns is kept and
/// reading goes on, as tobj does).
pub(crate) fn form(
    read: Read,
    mut load_mtl: impl FnMut(&Path) -> tobj::MTLLoadResult,
) -> Result<ObjText, LoadError> {
    let Read(mut chunks, par) = read;
    // The counts before each chunk, then its relative indices resolved against them.
    let mut base = Vec::with_capacity(chunks.len());
    let mut total = Counts::default();
    for c in &chunks {
        base.push(total);
        total = total.add(c.counts());
    }
    chunks.par_iter_mut().zip(&base).for_each(|(c, b)| {
        let rel = std::mem::take(&mut c.rel);
        for (corner, slot, x) in rel {
            let count = match slot {
                0 => b.pos,
                1 => b.tex,
                _ => b.nor,
            };
            let x = as_index(count as i64 + x);
            match slot {
                0 => {
                    if let Some(v) = c.v.get_mut(corner) {
                        *v = v32(x);
                    }
                }
                s => {
                    let col = if s == 1 { &mut c.vt } else { &mut c.vn };
                    if x != MISSING && col.is_empty() {
                        col.resize(c.v.len(), MISSING);
                    }
                    if let Some(t) = col.get_mut(corner) {
                        *t = x;
                    }
                }
            }
        }
    });
    let concat = |f: fn(&mut Chunk) -> Vec<f32>, chunks: &mut [Chunk]| {
        let mut all = Vec::new();
        for c in chunks {
            all.append(&mut f(c));
        }
        all
    };
    let pos = concat(|c| std::mem::take(&mut c.pos), &mut chunks);
    let tex = concat(|c| std::mem::take(&mut c.tex), &mut chunks);
    let nor = concat(|c| std::mem::take(&mut c.nor), &mut chunks);
    let mut f = Former {
        chunks: &chunks,
        base,
        slot: vec![u32::MAX; pos.len() / 3],
        pos,
        tex,
        nor,
        models: Vec::new(),
        name: "unnamed_object".to_string(),
        mat: None,
        start: At::default(),
        par,
    };
    let mut mats = Materials::default();
    let mut usemtl: Vec<(usize, String)> = Vec::new();
    let (mut line_base, mut lines) = (0, 0);
    for (ci, c) in chunks.iter().enumerate() {
        let b = f.base.get(ci).copied().unwrap_or_default();
        for e in &c.events {
            let at = At {
                chunk: ci,
                face: e.faces,
                corner: e.corners,
            };
            let pending = (at.chunk, at.face) > (f.start.chunk, f.start.face)
                && faces_between(&chunks, f.start, at);
            let counts = b.add(e.counts);
            match &e.kind {
                Kind::Group(name) => {
                    if pending {
                        f.pop(at, counts)?;
                    }
                    f.name = name.clone();
                }
                Kind::Mtllib(file) => mats.merge(load_mtl(Path::new(file))),
                Kind::Usemtl(name, listed) => {
                    let new = mats.map.get(name).copied();
                    if f.mat != new && pending {
                        f.pop(at, counts)?;
                    }
                    f.mat = new;
                    if !listed.is_empty() && !usemtl.iter().any(|(_, n)| n == listed) {
                        usemtl.push((line_base + e.line + 1, listed.clone()));
                    }
                }
            }
            // A directive's pop moves the start to it; one without leaves it.
        }
        if let Some((_, e)) = c.error {
            return Err(e);
        }
        line_base += c.lines;
        lines += c.nonblank;
    }
    let end = At {
        chunk: chunks.len().saturating_sub(1),
        face: chunks.last().map_or(0, |c| c.arity.len()),
        corner: chunks.last().map_or(0, |c| c.v.len()),
    };
    f.pop(end, total)?;
    let materials = if !mats.list.is_empty() {
        Ok(mats.list)
    } else if let Some(e) = mats.err {
        Err(e)
    } else {
        Ok(Vec::new())
    };
    Ok(ObjText {
        models: f.models,
        materials,
        usemtl,
        lines,
    })
}

/// Whether any face lies between `a` and `b` (`a` before `b`).
fn faces_between(chunks: &[Chunk], a: At, b: At) -> bool {
    if a.chunk == b.chunk {
        return b.face > a.face;
    }
    let tail = chunks.get(a.chunk).is_some_and(|c| c.arity.len() > a.face);
    let middle = chunks
        .get(a.chunk + 1..b.chunk)
        .is_some_and(|cs| cs.iter().any(|c| !c.arity.is_empty()));
    tail || middle || b.face > 0
}
