//! The sequential pass over the chunks: directives followed in file order, models formed and
//! their vertices numbered (tobj's export), the MTL files read when reached.

use super::chunk::Chunk;
use super::plain::{Parallel, plain_model};
use super::words::{as_index, v32};
use super::{Counts, Kind, MISSING, ObjModel, ObjText, Read, V_BIG, V_MISSING};
use rayon::prelude::*;
use std::collections::HashMap;
use std::path::Path;
use tobj::LoadError;

/// The MTL materials loaded so far (tobj's `TmpMaterials`).
#[derive(Default)]
pub(super) struct Materials {
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
pub(super) struct At {
    pub(super) chunk: usize,
    pub(super) face: usize,
    pub(super) corner: usize,
}

/// The sequential pass: models formed and exported in file order.
pub(super) struct Former<'c> {
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
pub(super) struct Span<'c> {
    pub(super) c: &'c Chunk,
    pub(super) faces: std::ops::Range<usize>,
    pub(super) corner: usize,
}

impl Span<'_> {
    /// `f(first corner, corners)` of each face the model keeps (points and lines are ignored).
    pub(super) fn each(&self, mut f: impl FnMut(usize, usize)) {
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
pub(super) fn faces_between(chunks: &[Chunk], a: At, b: At) -> bool {
    if a.chunk == b.chunk {
        return b.face > a.face;
    }
    let tail = chunks.get(a.chunk).is_some_and(|c| c.arity.len() > a.face);
    let middle = chunks
        .get(a.chunk + 1..b.chunk)
        .is_some_and(|cs| cs.iter().any(|c| !c.arity.is_empty()));
    tail || middle || b.face > 0
}
