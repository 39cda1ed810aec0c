//! Repository rules that a compiler does not check, run by plain `cargo test` (rust-analyzer's
//! `tidy.rs` habit, style anchor B2.7):
//! - dependencies between our crates follow the table in `ARCHITECTURE.md`: vocabulary at the
//!   bottom, stage crates independent of each other, the binary on top;
//! - every crate opts into the workspace lints;
//! - no ignore or should-panic attributes on tests: a test that cannot fail, or hides a known
//!   failure, is a defect here.

/// Which of our crates each crate may depend on (normal, dev and build dependencies alike).
/// Crates not listed may use any of ours (the binary and the end-to-end tests).
#[cfg(test)]
const ALLOWED: &[(&str, &[&str])] = &[
    ("math", &[]),
    ("geom", &["math"]),
    ("scene", &["math", "geom"]),
    ("bsdf", &["math"]),
    ("film", &[]),
    ("store", &["math"]),
    ("eye", &["math", "geom", "scene", "bsdf", "film"]),
    ("emit", &["math", "geom", "scene", "bsdf", "store"]),
    (
        "density",
        &["math", "geom", "scene", "bsdf", "film", "store"],
    ),
    ("xtask", &[]),
];

#[cfg(test)]
mod tests {
    use super::ALLOWED;
    use std::path::{Path, PathBuf};

    fn root() -> PathBuf {
        crate::project_root()
    }

    fn our_crates() -> Vec<String> {
        let mut v: Vec<String> = std::fs::read_dir(root().join("crates"))
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        v.sort();
        v
    }

    /// Names of our crates that a manifest mentions as dependencies: lines `name.workspace =`
    /// or `name = { path = ... }` inside a `[*dependencies]` table.
    fn local_deps(manifest: &str, ours: &[String]) -> Vec<String> {
        let mut in_deps = false;
        let mut out = Vec::new();
        for line in manifest.lines() {
            let l = line.trim();
            if l.starts_with('[') {
                in_deps = l.ends_with("dependencies]");
                continue;
            }
            if !in_deps {
                continue;
            }
            let name = l.split(['.', '=', ' ']).next().unwrap_or("");
            if ours.iter().any(|c| c == name) {
                out.push(name.to_string());
            }
        }
        out
    }

    #[test]
    fn crate_dependencies_follow_the_table() {
        let ours = our_crates();
        for krate in ours.iter().map(String::as_str).chain(["xtask"]) {
            let dir = if krate == "xtask" {
                root().join("xtask")
            } else {
                root().join("crates").join(krate)
            };
            let manifest = std::fs::read_to_string(dir.join("Cargo.toml")).unwrap();
            assert!(
                manifest.contains("[lints]\nworkspace = true"),
                "{krate}: add `[lints] workspace = true`"
            );
            let Some((_, allowed)) = ALLOWED.iter().find(|(k, _)| *k == krate) else {
                // Only the binary may see every crate; a new crate must take its place in the
                // table (and in ARCHITECTURE.md) first.
                assert!(
                    krate == "photonflow",
                    "{krate} is not in the dependency table of xtask/src/tidy.rs"
                );
                continue;
            };
            for dep in local_deps(&manifest, &ours) {
                assert!(
                    allowed.contains(&dep.as_str()),
                    "{krate} may not depend on {dep} (see xtask/src/tidy.rs and ARCHITECTURE.md)"
                );
            }
        }
    }

    /// "No IO of a library's own choosing" (ARCHITECTURE.md): outside its tests, a library
    /// crate touches the filesystem or the environment only if it is one of the IO crates:
    /// `scene` (the scene file and the files it names), `store` (photon files), `film`
    /// (images where it is told).
    #[test]
    fn libraries_do_no_io_of_their_own() {
        let io_crates = ["scene", "store", "film", "photonflow"];
        for krate in our_crates() {
            if io_crates.contains(&krate.as_str()) {
                continue;
            }
            let mut files = Vec::new();
            rust_files(&root().join("crates").join(&krate).join("src"), &mut files);
            for f in files {
                let name = f.to_string_lossy();
                if name.contains("/tests") || name.ends_with("bench.rs") {
                    continue; // tests and benchmarks write scratch files by design
                }
                let text = std::fs::read_to_string(&f).unwrap();
                for banned in [
                    concat!("std::", "fs"),
                    concat!("std::", "env"),
                    concat!("File", "::"),
                ] {
                    assert!(
                        !text.contains(banned),
                        "{}: `{banned}` in a library",
                        f.display()
                    );
                }
            }
        }
    }

    fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
        for e in std::fs::read_dir(dir).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() && !p.ends_with("target") {
                rust_files(&p, out);
            } else if p.extension().is_some_and(|x| x == "rs") {
                out.push(p);
            }
        }
    }

    #[test]
    fn no_ignored_or_should_panic_tests() {
        let mut files = Vec::new();
        for d in ["crates", "tests", "xtask"] {
            rust_files(&root().join(d), &mut files);
        }
        // Spelled in pieces so this file does not trip its own check.
        let banned = [concat!("#[", "ignore"), concat!("#[", "should_panic")];
        for f in files {
            let text = std::fs::read_to_string(&f).unwrap();
            for b in banned {
                assert!(!text.contains(b), "{}: `{b}` is not allowed", f.display());
            }
        }
    }
}
