//! obvhs' PLOC (the `ploc` module of obvhs 0.4, `build_ploc_from_leaves` without its parallel and
//! rebuild paths) over lean buffers: the same merges in the same order, so the same `Bvh2`
//! node for node (`crates/geom/src/tests/bvh4.rs` checks it against `build_bvh2`), at about
//! half the memory. Then obvhs' reinsertion, its searches on every core.
//!
//! obvhs keeps two lists of 48-byte nodes of the primitives' count and a sort buffer for the
//! whole build, beside the `Bvh2` it fills; at 4M triangles that was 580 MB of scratch at the
//! load's peak. Here the lists hold 32-byte nodes, the sort buffer is freed once the leaves are
//! in Morton order, and both lists shrink to each pass's survivors, so scratch and output
//! together stay near the finished `Bvh2`'s size.
//!
//! Each PLOC pass runs on every core in fixed chunks of nodes: a node's choice of neighbour
//! reads only the pass's input, and its output slots (in the next list and in the `Bvh2`)
//! follow from prefix sums of the chunks' counts, so every thread count writes what the
//! sequential pass writes.

use bytemuck::{Pod, Zeroable};
use glam::{DVec3, Vec3, Vec3A};
use obvhs::aabb::Aabb;
use obvhs::bvh2::reinsertion::{Reinsertion, find_reinsertion, reinsert_node};
use obvhs::bvh2::{Bvh2, DEFAULT_MAX_STACK_DEPTH, node::Bvh2Node};
use obvhs::ploc::SortPrecision;
use obvhs::ploc::morton::{morton_encode_u64_unorm, morton_encode_u128_unorm};
use rayon::prelude::*;
use rdst::{RadixKey, RadixSort};

/// A node awaiting its merge: box, and a leaf's primitive count and first index or an inner
/// node's 0 and first child (in `Bvh2::nodes`), as in `Bvh2Node`.
#[derive(Clone, Copy, Default, Pod, Zeroable)]
#[repr(C, align(16))]
pub(crate) struct Work {
    min: Vec3,
    prim_count: u32,
    max: Vec3,
    first_index: u32,
}

impl Work {
    pub(crate) fn leaf(b: Aabb, first_index: u32) -> Work {
        Work {
            min: b.min.into(),
            prim_count: 1,
            max: b.max.into(),
            first_index,
        }
    }

    #[inline(always)]
    pub(crate) fn aabb(&self) -> Aabb {
        Aabb::new(Vec3A::from(self.min), Vec3A::from(self.max))
    }

    #[inline(always)]
    fn node(&self) -> Bvh2Node {
        Bvh2Node::new(self.aabb(), self.prim_count, self.first_index)
    }
}

/// obvhs' sort keys, the same layout and radix levels, so its sorts order them alike.
#[derive(Clone, Copy, Pod, Zeroable)]
#[repr(C)]
struct Morton64 {
    code: u64,
    index: u64,
}

impl RadixKey for Morton64 {
    const LEVELS: usize = 8;

    #[inline(always)]
    fn get_level(&self, level: usize) -> u8 {
        self.code.get_level(level)
    }
}

#[derive(Clone, Copy, Pod, Zeroable)]
#[repr(C)]
struct Morton128 {
    code: u128,
    index: u64,
    padding: u64,
}

impl RadixKey for Morton128 {
    const LEVELS: usize = 16;

    #[inline(always)]
    fn get_level(&self, level: usize) -> u8 {
        self.code.get_level(level)
    }
}

/// The leaves in Morton order of their centres (obvhs' `sort_nodes_by_morton`: its sequential
/// sort, the codes and the gather on every core).
fn sorted(leaves: &[Work], precision: SortPrecision, scale: DVec3, offset: DVec3) -> Vec<Work> {
    let center = |w: &Work| w.aabb().center().as_dvec3() * scale + offset;
    match precision {
        SortPrecision::U64 => {
            let mut m: Vec<Morton64> = leaves
                .par_iter()
                .enumerate()
                .map(|(i, w)| Morton64 {
                    code: morton_encode_u64_unorm(center(w)),
                    index: i as u64,
                })
                .collect();
            if m.len() <= 250_000 {
                m.sort_unstable_by_key(|m| m.code);
            } else {
                m.radix_sort_unstable();
            }
            m.par_iter().map(|m| leaves[m.index as usize]).collect()
        }
        SortPrecision::U128 => {
            let mut m: Vec<Morton128> = leaves
                .par_iter()
                .enumerate()
                .map(|(i, w)| Morton128 {
                    code: morton_encode_u128_unorm(center(w)),
                    index: i as u64,
                    padding: 0,
                })
                .collect();
            if m.len() <= 250_000 {
                m.sort_unstable_by_key(|m| m.code);
            } else {
                m.radix_sort_unstable();
            }
            m.par_iter().map(|m| leaves[m.index as usize]).collect()
        }
    }
}

/// obvhs' `SearchCache`: the costs a node computed for the nodes after it, read back by them.
struct SearchCache<const D: usize>([[f32; D]; D]);

impl<const D: usize> SearchCache<D> {
    #[inline]
    fn back(&self, index: usize, other: usize) -> f32 {
        self.0[other % D][index % D]
    }

    #[inline]
    fn front(&mut self, index: usize, other: usize) -> &mut f32 {
        &mut self.0[index % D][other % D]
    }

    fn find_best_node(&mut self, index: usize, nodes: &[Work]) -> i8 {
        let mut best_node = index;
        let mut best_cost = f32::INFINITY;
        let begin = index - D.min(index);
        let end = (index + D + 1).min(nodes.len());
        for other in begin..index {
            let area = self.back(index, other);
            if area <= best_cost {
                best_node = other;
                best_cost = area;
            }
        }
        let our = nodes[index].aabb();
        for (other, node) in nodes.iter().enumerate().take(end).skip(index + 1) {
            let cost = our.union(&node.aabb()).half_area();
            *self.front(index, other) = cost;
            if cost <= best_cost {
                best_node = other;
                best_cost = cost;
            }
        }
        (best_node as i64 - index as i64) as i8
    }
}

/// Nodes per parallel task of a PLOC pass: many tasks per core, and each task's fixed cost
/// (a warmed search cache, a split of the outputs) small beside its work. Tasks depend on
/// the node count alone, and each computes what the sequential pass does for its nodes.
const PASS_CHUNK: usize = 1 << 14;

/// Shrinks `v` to `len`, handing the rest of its allocation back.
fn shrink<T>(v: &mut Vec<T>, len: usize) {
    v.truncate(len);
    if v.capacity() > len + len / 8 {
        v.shrink_to_fit();
    }
}

/// Builds `bvh` (fresh: its primitive indices `0..n`, its nodes unwritten) over `leaves`,
/// whose boxes bound `total`; obvhs' `build_ploc_from_leaves::<D, false>`.
pub(crate) fn build<const D: usize>(
    bvh: &mut Bvh2,
    leaves: Vec<Work>,
    total: Aabb,
    precision: SortPrecision,
    search_depth_threshold: usize,
) {
    let prim_count = leaves.len();
    if prim_count == 0 {
        return;
    }
    let nodes_count = 2 * prim_count - 1;
    bvh.nodes.resize(nodes_count, Bvh2Node::default());
    let mut insert_index = nodes_count;
    let scale = 1.0 / total.diagonal().as_dvec3();
    let offset = -total.min.as_dvec3() * scale;

    let mut current = sorted(&leaves, precision, scale, offset);
    // The unsorted leaves' allocation becomes the next pass's list.
    let mut next = leaves;
    let mut merge = vec![0i8; prim_count];
    let mut depth = 0;
    let mut count = prim_count;
    while count > 1 {
        let nodes = &current[..count];
        let merge = &mut merge[..count];
        let cost = |i: usize| nodes[i].aabb().union(&nodes[i + 1].aabb()).half_area();
        if D == 1 || depth < search_depth_threshold {
            // Each node towards the cheaper of its two neighbours, the left on a tie.
            merge
                .par_chunks_mut(PASS_CHUNK)
                .enumerate()
                .for_each(|(c, m)| {
                    let start = c * PASS_CHUNK;
                    let mut last_cost = if start == 0 {
                        f32::INFINITY
                    } else {
                        cost(start - 1)
                    };
                    for (i, m) in (start..).zip(m) {
                        if i == count - 1 {
                            *m = -1;
                        } else {
                            let cost = cost(i);
                            *m = if last_cost < cost { -1 } else { 1 };
                            last_cost = cost;
                        }
                    }
                });
        } else {
            merge
                .par_chunks_mut(PASS_CHUNK)
                .enumerate()
                .for_each(|(c, m)| {
                    let start = c * PASS_CHUNK;
                    let mut cache = SearchCache::<D>([[0.0; D]; D]);
                    // The costs the `D` nodes before the chunk leave in the cache for its first
                    // nodes, as the sequential pass has them.
                    for index in start.saturating_sub(D)..start {
                        cache.find_best_node(index, nodes);
                    }
                    for (index, best) in (start..).zip(m) {
                        *best = cache.find_best_node(index, nodes);
                    }
                });
        }
        let merge = &*merge;
        // What node `index` adds: itself unmerged (`Some(false)`), the pair it closes with
        // an earlier node (`Some(true)`), or nothing (its pair closes at the later node).
        let action = |index: usize| {
            let best = (index as i64 + merge[index] as i64) as usize;
            if best as i64 + merge[best] as i64 != index as i64 {
                Some(false)
            } else if best > index {
                None
            } else {
                Some(true)
            }
        };
        // Per chunk of nodes: how many it passes on, and how many pairs it merges.
        let sizes: Vec<(usize, usize)> = (0..count.div_ceil(PASS_CHUNK))
            .into_par_iter()
            .map(|c| {
                let range = c * PASS_CHUNK..((c + 1) * PASS_CHUNK).min(count);
                range.fold((0, 0), |(n, m), i| match action(i) {
                    None => (n, m),
                    Some(pair) => (n + 1, m + pair as usize),
                })
            })
            .collect();
        let (survivors, pairs) = sizes.iter().fold((0, 0), |(n, m), &(a, b)| (n + a, m + b));
        // Each chunk's part of `next`, and of the nodes below `insert_index` (the first
        // chunk's pairs the highest, each pair below the one before it).
        let mut parts = Vec::with_capacity(sizes.len());
        let (mut rest_next, mut rest_nodes) = (&mut next[..survivors], {
            let (_, hi) = bvh.nodes.split_at_mut(insert_index - 2 * pairs);
            &mut hi[..2 * pairs]
        });
        let mut top = insert_index;
        for (c, &(n, m)) in sizes.iter().enumerate() {
            let (out, r) = std::mem::take(&mut rest_next).split_at_mut(n);
            rest_next = r;
            let split = rest_nodes.len() - 2 * m;
            let (r, ins) = std::mem::take(&mut rest_nodes).split_at_mut(split);
            rest_nodes = r;
            parts.push((c, out, ins, top));
            top -= 2 * m;
        }
        parts.into_par_iter().for_each(|(c, out, ins, top)| {
            let mut next_idx = 0;
            let mut insert = top;
            for index in c * PASS_CHUNK..((c + 1) * PASS_CHUNK).min(count) {
                let Some(pair) = action(index) else { continue };
                out[next_idx] = if pair {
                    let best = (index as i64 + merge[index] as i64) as usize;
                    let (left, right) = (nodes[index], nodes[best]);
                    insert -= 2;
                    let at = insert - (top - ins.len());
                    ins[at] = left.node();
                    ins[at + 1] = right.node();
                    let b = left.aabb().union(&right.aabb());
                    Work {
                        min: b.min.into(),
                        prim_count: 0,
                        max: b.max.into(),
                        first_index: insert as u32,
                    }
                } else {
                    nodes[index]
                };
                next_idx += 1;
            }
        });
        insert_index -= 2 * pairs;
        std::mem::swap(&mut next, &mut current);
        count = survivors;
        shrink(&mut current, count);
        shrink(&mut next, count);
        depth += 1;
    }
    debug_assert_eq!(insert_index, 1);
    bvh.nodes[0] = current[0].node();
    bvh.max_depth = DEFAULT_MAX_STACK_DEPTH.max(depth + 1);
    bvh.children_are_ordered_after_parents = true;
}

/// obvhs' reinsertion candidate: its sort key and layout, so its radix sort orders them alike.
#[derive(Clone, Copy)]
struct Candidate {
    node_id: u32,
    cost: f32,
}

impl RadixKey for Candidate {
    const LEVELS: usize = 4;

    #[inline]
    fn get_level(&self, level: usize) -> u8 {
        (-self.cost).get_level(level)
    }
}

/// obvhs' `ReinsertionOptimizer::run(bvh, batch_size_ratio, None)` (obvhs 0.4 without its
/// `parallel` feature; Meister and Bittner, "Parallel Reinsertion for Bounding Volume
/// Hierarchy Optimization", 2018) with each batch's searches spread over the cores. A search
/// only reads the tree, and the moves are still made one after another in obvhs' order, so
/// the tree is obvhs' node for node, whatever the thread count.
pub(crate) fn reinsert(bvh: &mut Bvh2, batch_size_ratio: f32) {
    if bvh.nodes.is_empty() || bvh.nodes[0].is_leaf() || batch_size_ratio <= 0.0 {
        return;
    }
    bvh.init_parents_if_uninit();
    bvh.children_are_ordered_after_parents = false;
    let mut touched = vec![false; bvh.nodes.len()];
    let mut candidates: Vec<Candidate> = Vec::new();
    // Batches of 1, 1/3, 1/5, ..., 1/31 of the ratio: more of the time near the root.
    for n in (1..32).step_by(2) {
        let ratio = 1.0 / n as f32;
        let batch = (((bvh.nodes.len() as f32 * batch_size_ratio) * ratio) as usize).max(1);
        let node_count = bvh.nodes.len().min(batch + 1);
        // The first `2 node_count` nodes by area, largest first (obvhs' `find_candidates`).
        candidates.clear();
        candidates.extend(
            bvh.nodes
                .iter()
                .take(node_count * 2)
                .enumerate()
                .skip(1)
                .map(|(i, node)| Candidate {
                    node_id: i as u32,
                    cost: node.aabb().half_area(),
                }),
        );
        candidates.radix_sort_unstable();
        let tree = &*bvh;
        let mut moves: Vec<Reinsertion> = candidates[..node_count - 1]
            .par_iter()
            .map(|c| find_reinsertion(tree, c.node_id as usize))
            .filter(|r| r.area_diff > 0.0)
            .collect();
        // obvhs' comparison (`partial_cmp`) on positive areas: the same order.
        moves.sort_unstable_by(|a, b| b.area_diff.total_cmp(&a.area_diff));
        touched.fill(false);
        for r in &moves {
            let (from, to) = (r.from as usize, r.to as usize);
            let conflicts = [
                to,
                from,
                Bvh2Node::get_sibling_id(from),
                bvh.parents[to] as usize,
                bvh.parents[from] as usize,
            ];
            if conflicts.iter().any(|&i| touched[i]) {
                continue;
            }
            for i in conflicts {
                touched[i] = true;
            }
            reinsert_node(bvh, from, to);
        }
    }
}

/// A `Bvh2` node in 32 bytes for the collapse: its box, and an inner node's first child
/// (the second follows it) or a leaf's primitive.
#[derive(Clone, Copy, Pod, Zeroable)]
#[repr(C, align(16))]
pub(crate) struct Node2 {
    min: Vec3,
    /// Inner: the first child. Leaf: `u32::MAX`.
    first: u32,
    max: Vec3,
    /// Leaf: the primitive (not its slot in `primitive_indices`).
    pub(crate) prim: u32,
}

impl Node2 {
    #[inline(always)]
    pub(crate) fn aabb(&self) -> Aabb {
        Aabb::new(Vec3A::from(self.min), Vec3A::from(self.max))
    }

    #[inline(always)]
    pub(crate) fn children(&self) -> Option<(usize, usize)> {
        (self.first != u32::MAX).then(|| (self.first as usize, self.first as usize + 1))
    }
}

/// Sixteen bytes at sixteen-byte alignment: the unit `compact` moves nodes in.
#[derive(Clone, Copy, Pod, Zeroable)]
#[repr(C, align(16))]
struct Chunk([u32; 4]);

/// `bvh`'s nodes as `Node2`, written over its own node list (a node moves to an earlier
/// address, over nodes already read) and the list then shrunk: no second list of nodes at any
/// time, and `bvh`'s other lists freed. Leaves must hold one primitive each.
///
/// Node `i` moves from chunks `3i..3i + 3` to `2i..2i + 2`: once nodes `..a` have moved,
/// nodes `a..3a / 2` write only where nodes before `a` were read, so each such range moves on
/// every core, into the same places as one after another.
pub(crate) fn compact(mut bvh: Bvh2) -> Vec<Node2> {
    let nodes = std::mem::take(&mut bvh.nodes);
    let prims = std::mem::take(&mut bvh.primitive_indices);
    drop(bvh);
    let len = nodes.len();
    let mut c: Vec<Chunk> = bytemuck::allocation::cast_vec(nodes);
    let node2 = |from: &[Chunk], to: &mut [Chunk]| {
        let n: Bvh2Node = bytemuck::cast([from[0], from[1], from[2]]);
        let b = n.aabb();
        let (first, prim) = if n.prim_count == 0 {
            (n.first_index, 0)
        } else {
            // A leaf's first primitive (the only one); an unreachable node's anything.
            let p = prims.get(n.first_index as usize);
            (u32::MAX, p.copied().unwrap_or(u32::MAX))
        };
        let out = Node2 {
            min: b.min.into(),
            first,
            max: b.max.into(),
            prim,
        };
        let [x, y]: [Chunk; 2] = bytemuck::cast(out);
        to[0] = x;
        to[1] = y;
    };
    // The first nodes one after another (their moves overlap their own reads).
    let mut a = len.min(1 << 10);
    for i in 0..a {
        let from: [Chunk; 3] = [c[3 * i], c[3 * i + 1], c[3 * i + 2]];
        node2(&from, &mut c[2 * i..2 * i + 2]);
    }
    while a < len {
        let b = (a + a / 2).min(len);
        let (done, rest) = c.split_at_mut(3 * a);
        done[2 * a..2 * b]
            .par_chunks_mut(2)
            .zip(rest[..3 * (b - a)].par_chunks(3))
            .for_each(|(to, from)| node2(from, to));
        a = b;
    }
    drop(prims);
    c.truncate(2 * len);
    c.shrink_to_fit();
    bytemuck::allocation::cast_vec(c)
}
