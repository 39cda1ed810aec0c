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
//!
//! The files: `words.rs` (words and numbers, as tobj reads them), `chunk.rs` (one chunk read
//! on its own), `former.rs` (the sequential pass: directives, models, their vertices),
//! `plain.rs` (a large model without texture or normal indices, numbered on every core).

mod chunk;
mod former;
mod plain;
mod words;

pub(crate) use former::form;
pub(crate) use plain::{PARALLEL, Parallel};
#[cfg(test)]
pub(crate) use words::decimal;

use chunk::{Chunk, cuts, read_chunk};
use rayon::prelude::*;
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
