//! One chunk of an OBJ file read on its own: vertices, faces with their indices resolved as
//! far as the chunk knows, and the directives for the sequential pass.

use super::words::{Words, as_index, decimal, floats, index, int, v32};
use super::{Counts, Event, Kind, MISSING};
use tobj::LoadError;

/// What one chunk holds.
#[derive(Default)]
pub(super) struct Chunk {
    pub(super) pos: Vec<f32>,
    pub(super) tex: Vec<f32>,
    pub(super) nor: Vec<f32>,
    pub(super) colors: usize,
    /// Each corner's position index, resolved (relative ones once the counts before the
    /// chunk are known, through `rel`).
    pub(super) v: Vec<u32>,
    /// Texture and normal indices per corner: empty until the chunk's first corner with one.
    pub(super) vt: Vec<u64>,
    pub(super) vn: Vec<u64>,
    /// Corners per face (points and lines included, as tobj keeps them until export).
    pub(super) arity: Vec<u32>,
    /// Negative indices: corner, slot (0 v, 1 vt, 2 vn) and the value relative to the start
    /// of the chunk.
    pub(super) rel: Vec<(usize, u8, i64)>,
    pub(super) events: Vec<Event>,
    /// The chunk's first error: its line and what tobj says.
    pub(super) error: Option<(usize, LoadError)>,
    pub(super) lines: usize,
    pub(super) nonblank: usize,
}

impl Chunk {
    pub(super) fn counts(&self) -> Counts {
        Counts {
            pos: self.pos.len() / 3,
            tex: self.tex.len() / 2,
            nor: self.nor.len() / 3,
            colors: self.colors,
        }
    }

    pub(super) fn event(&mut self, line: usize, kind: Kind) {
        self.events.push(Event {
            line,
            faces: self.arity.len(),
            corners: self.v.len(),
            counts: self.counts(),
            kind,
        });
    }

    /// One corner `v[/vt[/vn]]` (tobj's `VertexIndices::parse`).
    pub(super) fn corner(&mut self, word: &str) -> bool {
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
    pub(super) fn plain(&mut self, line: &[u8]) -> bool {
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
    pub(super) fn line(&mut self, n: usize, line: &str) -> Result<(), LoadError> {
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
pub(super) fn read_chunk(bytes: &[u8]) -> Chunk {
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
pub(super) fn cuts(bytes: &[u8], size: usize) -> Vec<usize> {
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
