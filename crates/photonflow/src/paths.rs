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

/// `target` as a path relative to the directory `base` (absolute when they share no root).
pub fn relative_to(target: &Path, base: &Path) -> Result<String, String> {
    use std::path::Component;
    let abs = |p: &Path| std::path::absolute(p).map_err(|e| format!("{}: {e}", p.display()));
    let (t, b) = (abs(target)?, abs(base)?);
    // Lexical: `a/../b` is not resolved through links, as the scene file resolves it.
    fn norm(p: &Path) -> Vec<Component<'_>> {
        let mut out: Vec<Component> = Vec::new();
        for c in p.components() {
            match c {
                Component::CurDir => {}
                Component::ParentDir if matches!(out.last(), Some(Component::Normal(_))) => {
                    out.pop();
                }
                c => out.push(c),
            }
        }
        out
    }
    let (t, b) = (norm(&t), norm(&b));
    let common = t.iter().zip(&b).take_while(|(x, y)| x == y).count();
    // Sharing only the root (or a drive): the absolute path reads better than `../../..`.
    let roots = t
        .iter()
        .take_while(|c| matches!(c, Component::Prefix(_) | Component::RootDir))
        .count();
    if common <= roots {
        return Ok(t.iter().collect::<PathBuf>().to_string_lossy().into_owned());
    }
    let mut rel = PathBuf::new();
    for _ in common..b.len() {
        rel.push("..");
    }
    for c in t.iter().skip(common) {
        rel.push(c);
    }
    Ok(rel.to_string_lossy().into_owned())
}

/// Writes `bytes` to `path` whole or not at all: a temp file beside it, renamed into place.
pub fn write_whole(path: &Path, bytes: &[u8]) -> Result<(), String> {
    use std::io::Write;
    let fail = |e: std::io::Error| format!("{}: cannot write it: {e}", path.display());
    let (temp, mut f) = temps::Temp::file(path).map_err(fail)?;
    f.write_all(bytes)
        .and_then(|()| f.sync_all())
        .map_err(fail)?;
    drop(f);
    temp.publish(path).map_err(fail)
}
