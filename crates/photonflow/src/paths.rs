//! Where outputs go when the command line does not say: the binary picks every path the
//! libraries write to.

use render::shard::ShardId;
use std::path::{Path, PathBuf};

/// Default output directory: `out/<scene dir>-<scene file stem>-<label>`.
pub fn run_out(scene: &Path, label: &str) -> PathBuf {
    let stem = scene
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "scene".into());
    let parent = scene
        .parent()
        .and_then(|p| p.file_name())
        .map(|s| s.to_string_lossy().into_owned());
    let name = match parent {
        Some(p) if !p.is_empty() => format!("{p}-{stem}"),
        _ => stem,
    };
    PathBuf::from("out").join(format!("{name}-{label}"))
}

/// Where a shard goes without `--out`: `out/shards/<scene dir>-<stem>-<what>-<I>-of-<N>`.
pub fn shard_out(scene: &Path, what: &str, shard: ShardId) -> PathBuf {
    let run = run_out(scene, what);
    let name = run.file_name().map(|n| n.to_string_lossy().into_owned());
    PathBuf::from("out").join("shards").join(format!(
        "{}-{}-of-{}",
        name.unwrap_or_default(),
        shard.index,
        shard.count
    ))
}
