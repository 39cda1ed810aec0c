//! A large model without texture or normal indices, numbered on every core.

use super::chunk::Chunk;
use super::former::{At, Span};
use super::{Counts, MISSING, V_BIG, V_MISSING};
use rayon::prelude::*;

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
pub(super) fn plain_model(
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
