//! Shards merged: `trace --shard`, `render --shard` (the path tracer, and
//! splatting's passes as the progressive method) and `merge`, through the command line in
//! process, against the one-machine run byte for byte, with 1, 3 and 7 shards given in
//! scrambled order. The refusals of bad shard sets are cases of `bad_input`'s table.

use crate::kit::{TempDir, cli, write_worksheet};
use std::path::{Path, PathBuf};

/// The worksheet scene at 20 x 20 pixels, written into `dir` (its mesh named by absolute path).
fn scene(dir: &Path) -> PathBuf {
    write_worksheet(dir, "s.toml", 20, "\n[estimate.splat]\nphotons = 3000\n")
}

fn run(args: &str) {
    let (code, msg) = cli(args.split(' ').map(String::from));
    assert_eq!(code, 0, "`{args}`: {msg:?}");
}

/// Every file under `dir` (relative path, bytes), sorted, leaving out what records time.
fn files(dir: &Path) -> Vec<(String, Vec<u8>)> {
    fn walk(root: &Path, d: &Path, out: &mut Vec<(String, Vec<u8>)>) {
        for e in std::fs::read_dir(d).unwrap().flatten() {
            let p = e.path();
            if p.is_dir() {
                walk(root, &p, out);
            } else {
                let rel = p.strip_prefix(root).unwrap().display().to_string();
                out.push((rel, std::fs::read(&p).unwrap()));
            }
        }
    }
    let mut out = Vec::new();
    walk(dir, dir, &mut out);
    out.sort();
    out
}

/// Shards `0..n` of `cmd` (which ends in `--shard`), each into `<dir>/<tag>-<n>-<i>`, merged
/// into `<dir>/<tag>-<n>`, the inputs given in a scrambled order (merge sorts them).
fn sharded(dir: &Path, tag: &str, cmd: &str, n: u32) -> PathBuf {
    let d = dir.display();
    let mut shards: Vec<String> = (0..n)
        .map(|i| {
            let out = format!("{d}/{tag}-{n}-{i}");
            run(&format!("{cmd} {i}/{n} --out {out}"));
            out
        })
        .collect();
    shards.rotate_left(n as usize / 2);
    shards.reverse();
    let merged = dir.join(format!("{tag}-{n}"));
    run(&format!(
        "merge {} --out {}",
        shards.join(" "),
        merged.display()
    ));
    merged
}

#[test]
fn photon_files_from_1_3_and_7_shards_are_the_one_machine_files() {
    let tmp = TempDir::new("shards-trace");
    let s = scene(tmp.path());
    let d = tmp.path().display();
    // 30000 paths store more photons than one 64 Ki chunk of a photon file holds: the merge
    // re-chunks across shard boundaries.
    run(&format!(
        "trace {} --photons 30000 --threads 2 --cache {d}/one",
        s.display()
    ));
    let one: Vec<_> = files(&tmp.path().join("one"))
        .into_iter()
        .filter(|(f, _)| f.ends_with(".photons"))
        .collect();
    assert_eq!(one.len(), 2, "a global and a caustic set");
    assert!(
        one.iter().any(|(_, b)| b.len() > 32 * 65_536),
        "more than one chunk"
    );
    for n in [1, 3, 7] {
        let cmd = format!("trace {} --photons 30000 --threads 2 --shard", s.display());
        let merged = sharded(tmp.path(), "trace", &cmd, n);
        assert_eq!(files(&merged), one, "{n} shards");
    }
}

/// The run directory's image and layers (image.json and scene.toml record times and paths).
fn image_files(dir: &Path) -> Vec<(String, Vec<u8>)> {
    files(dir)
        .into_iter()
        .filter(|(f, _)| f.ends_with(".exr") && !f.starts_with("snapshots"))
        .collect()
}

#[test]
fn path_traced_and_splatted_images_from_1_3_and_7_shards_are_the_one_machine_images() {
    let tmp = TempDir::new("shards-render");
    let s = scene(tmp.path());
    let d = tmp.path().display();
    // `path` in its passes of 1, 1, 2, 2, ... samples; `caustic-splat` (progressive: new eye
    // vertices and photons every pass) in 7 passes.
    for (tag, flags) in [
        ("path", "--method path --spp 16"),
        ("splat", "--method caustic-splat --passes 7"),
    ] {
        run(&format!(
            "render {} {flags} --threads 2 --out {d}/{tag}-one",
            s.display()
        ));
        let one = image_files(&tmp.path().join(format!("{tag}-one")));
        assert!(one.len() >= 2, "{tag}: image and layers: {}", one.len());
        for n in [1, 3, 7] {
            let cmd = format!("render {} {flags} --threads 2 --shard", s.display());
            let merged = sharded(tmp.path(), tag, &cmd, n);
            assert_eq!(image_files(&merged), one, "{tag}, {n} shards");
            // The merged run is a run: its scene.toml renders it again.
            let a = std::fs::read_to_string(merged.join("scene.toml")).unwrap();
            let b = std::fs::read_to_string(tmp.path().join(format!("{tag}-one/scene.toml")));
            assert_eq!(a, b.unwrap(), "{tag}, {n} shards: scene.toml");
        }
    }
}
