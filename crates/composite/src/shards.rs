//! Shards of one run, merged: the pure rules `photonflow merge` applies (no IO). A run's work
//! is a list of index ranges (photon paths, or blocks of samples or passes); shard `I` of `N`
//! did one contiguous stretch of them. A merge takes the shards in order of their ranges,
//! refuses a set that leaves a gap or covers an index twice, and adds f64 block sums in the
//! one fixed order the one-machine run adds them in, so the merged result is bit-identical.

use std::ops::Range;

/// Shard `index` of `count` (0-based: `SLURM_ARRAY_TASK_ID` and `JOB_COMPLETION_INDEX` are).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ShardId {
    pub index: u32,
    pub count: u32,
}

impl ShardId {
    /// Parses `I/N` with `I < N`.
    pub fn parse(s: &str) -> Result<ShardId, String> {
        let bad = || format!("`{s}`: expected I/N with 0 <= I < N (shards count from 0)");
        let (i, n) = s.split_once('/').ok_or_else(bad)?;
        let (index, count) = (
            i.trim().parse::<u32>().map_err(|_| bad())?,
            n.trim().parse::<u32>().map_err(|_| bad())?,
        );
        if index >= count {
            return Err(bad());
        }
        Ok(ShardId { index, count })
    }

    /// This shard's part of `0..total`: `[I T / N, (I + 1) T / N)`, so shards differ by at
    /// most one index and together cover `0..total` exactly.
    pub fn range(&self, total: u64) -> Range<u64> {
        let at = |i: u32| (total as u128 * i as u128 / self.count as u128) as u64;
        at(self.index)..at(self.index + 1)
    }

    /// The blocks (consecutive ranges covering `0..total`) this shard owns: those that start
    /// inside [`ShardId::range`]. Blocks are the unit of work; a shard never splits one.
    pub fn blocks(&self, blocks: &[Range<u64>], total: u64) -> Range<usize> {
        let r = self.range(total);
        let first = blocks.partition_point(|b| b.start < r.start);
        let end = blocks.partition_point(|b| b.start < r.end);
        first..end
    }
}

impl std::fmt::Display for ShardId {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}/{}", self.index, self.count)
    }
}

/// What a merge knows of one shard: where it came from (named in every refusal), which shard
/// it says it is and the indices it covers.
#[derive(Clone, Debug)]
pub struct Part {
    pub label: String,
    pub shard: ShardId,
    pub range: Range<u64>,
}

/// The order in which to merge `parts` so that they cover `0..total` exactly once, or a
/// one-line refusal naming the file: a shard given twice, shards that overlap (of sets with
/// another N, say), one that is missing, or one whose range is not its shard's. `expected`
/// is the range a shard must cover (its indices, or its blocks).
pub fn cover(
    parts: &[Part],
    total: u64,
    expected: &dyn Fn(ShardId) -> Range<u64>,
) -> Result<Vec<usize>, String> {
    for p in parts {
        if p.range != expected(p.shard) {
            return Err(format!(
                "{}: shard {} should cover {:?} of 0..{total}, but covers {:?}",
                p.label,
                p.shard,
                expected(p.shard),
                p.range
            ));
        }
    }
    for (i, p) in parts.iter().enumerate() {
        if let Some(q) = parts[..i].iter().find(|q| q.shard == p.shard) {
            return Err(format!(
                "{}: duplicates {} (both are shard {})",
                p.label, q.label, p.shard
            ));
        }
    }
    let mut order: Vec<usize> = (0..parts.len()).collect();
    order.sort_by_key(|&i| {
        (
            parts[i].range.start,
            parts[i].range.end,
            parts[i].shard.count,
        )
    });
    let mut end = 0;
    let mut prev: Option<&Part> = None;
    for &i in &order {
        let p = &parts[i];
        if let Some(q) = prev
            && p.range.start < end
        {
            return Err(format!(
                "{}: overlaps {} (shard {} covers {:?}, shard {} covers {:?})",
                p.label, q.label, p.shard, p.range, q.shard, q.range
            ));
        }
        if p.range.start > end {
            return Err(missing(p, end, p.range.start, expected));
        }
        end = end.max(p.range.end);
        prev = Some(p);
    }
    if end < total {
        // Indices past the last shard: name the set's last file.
        return match prev {
            Some(p) => Err(missing(p, end, total, expected)),
            None => Err("merge: no shards given".into()),
        };
    }
    Ok(order)
}

fn missing(near: &Part, from: u64, to: u64, expected: &dyn Fn(ShardId) -> Range<u64>) -> String {
    let n = near.shard.count;
    let lost: Vec<String> = (0..n)
        .map(|index| ShardId { index, count: n })
        .filter(|&s| {
            let r = expected(s);
            r.start < to && r.end > from
        })
        .map(|s| s.to_string())
        .collect();
    format!(
        "{}: a shard of its set of {n} is missing ({}): nothing covers {from}..{to}",
        near.label,
        lost.join(", ")
    )
}

/// Adds `blocks` (f64 sums per pixel of consecutive blocks of one layer) from zero in the
/// order given: the one fixed order both the one-machine run and a merge of its shards use.
pub fn fold(pixels: usize, blocks: &[&[[f64; 3]]]) -> Vec<[f64; 3]> {
    let mut sum = vec![[0.0f64; 3]; pixels];
    for b in blocks {
        for (s, v) in sum.iter_mut().zip(b.iter()) {
            for c in 0..3 {
                s[c] += v[c];
            }
        }
    }
    sum
}
