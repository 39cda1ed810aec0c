//! Repository rules that a compiler does not check, run by plain `cargo test` (rust-analyzer's
//! `tidy.rs` habit):
//! - dependencies between our crates follow the table below (`ALLOWED`, described in
//!   `ARCHITECTURE.md`): vocabulary at the
//!   bottom, stage crates independent of each other, the binary on top;
//! - every crate opts into the workspace lints;
//! - no ignore or should-panic attributes on tests: a test that cannot fail, or hides a known
//!   failure, is a defect here;
//! - no dangling pointers in comments and docs: a reader of the repository must be able to
//!   open every file a comment names, so comments name no notes kept outside it and no path
//!   that does not exist (papers, books and public projects are cited by name instead).

/// Which of our crates each crate may depend on (normal, dev and build dependencies alike).
/// Crates not listed may use any of ours (the binary and the end-to-end tests).
#[cfg(test)]
const ALLOWED: &[(&str, &[&str])] = &[
    ("math", &[]),
    ("geom", &["math"]),
    ("scene", &["math", "geom", "bsdf"]),
    ("bsdf", &["math"]),
    // Temporary files and staging directories: what a signal or a later run removes.
    ("temps", &[]),
    ("film", &["temps"]),
    ("store", &["math", "temps"]),
    ("eye", &["math", "geom", "scene", "bsdf", "film"]),
    // Both subpaths of vertex connection and merging: a stage of its own, beside `eye` and
    // `emit`, knowing neither.
    ("vcm", &["math", "geom", "scene", "bsdf"]),
    (
        "emit",
        &["math", "geom", "scene", "bsdf", "film", "store", "flow"],
    ),
    (
        "density",
        &["math", "geom", "scene", "bsdf", "film", "store"],
    ),
    // The compositing stage: images in, an image out.
    ("composite", &["film"]),
    // The channel machinery: knows no photon, no scene.
    ("flow", &[]),
    // The photon stage: photon files are its contract; it never sees `density` or `eye`.
    (
        "photons",
        &[
            "math",
            "geom",
            "scene",
            "bsdf",
            "film",
            "store",
            "emit",
            "composite",
            "flow",
            "temps",
        ],
    ),
    // The eye side wired as a library: above every stage, below `lab` and the binary.
    (
        "render",
        &[
            "math",
            "geom",
            "scene",
            "bsdf",
            "film",
            "store",
            "eye",
            "vcm",
            "emit",
            "density",
            "composite",
            "flow",
            "photons",
            "temps",
        ],
    ),
    // Studies built on `render`, which never imports them.
    (
        "lab",
        &[
            "math",
            "geom",
            "scene",
            "bsdf",
            "film",
            "store",
            "eye",
            "vcm",
            "emit",
            "density",
            "composite",
            "flow",
            "photons",
            "render",
            "temps",
        ],
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
    /// (images where it is told), `temps` (temp files beside those, and the stale ones in the
    /// directories it is given).
    #[test]
    fn libraries_do_no_io_of_their_own() {
        // `photons` reads and writes photon caches and shard directories, `render` run
        // directories and image shards, `lab` its reports and the reference it caches, all
        // at paths their caller (the binary, or a test) passes in.
        let io_crates = [
            "scene",
            "store",
            "film",
            "temps",
            "photons",
            "render",
            "lab",
            "photonflow",
        ];
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

    /// Notes that live outside the repository: a comment citing them leaves the reader with
    /// nothing to open. Spelled in pieces so this file does not trip its own check.
    const OUTSIDE_NOTES: &[&str] = &[
        concat!("algorithms", ".md"),
        concat!("scene-", "facts"),
        concat!("worksheet-7", ".txt"),
        concat!("style-", "anchors"),
        concat!("../", "shared"),
        concat!("shared/", "reference"),
    ];

    /// Extensions of the kinds of file the repository holds: a token with a `/` that ends in
    /// one of them names a repository file. Images are left out on purpose: every `.exr` and
    /// `.png` a comment names is an output.
    const REPO_EXTENSIONS: &[&str] = &["rs", "md", "toml", "obj", "mtl", "txt", "json"];

    /// Top-level directories: a token starting with one of them names a repository path.
    const REPO_DIRS: &[&str] = &["crates/", "scenes/", "tests/", "xtask/", "docs/"];

    /// Paths a run writes, not repository files, so they need not exist: the binary's output
    /// directory (`--out` and `--cache` default to `out/...`, which git ignores) and cargo's
    /// `target/`. Placeholders (`<name>`, `{}`), globs and URLs are skipped by
    /// `looks_like_repo_path` instead.
    const OUTPUT_PREFIXES: &[&str] = &["out/", "target/"];

    /// Whether `line` cites one of the authors' style notes by its label: `STYLE_NOTE`, or
    /// the word anchor(s) followed by an uppercase letter that is not the start of a word
    /// (`B2.6`, `C)`).
    fn cites_style_note(line: &str) -> bool {
        const STYLE_NOTE: &str = concat!("style ", "anchor");
        // ASCII lowercasing keeps byte offsets, so indices into `lower` index `line` too.
        let lower = line.to_ascii_lowercase();
        if lower.contains(STYLE_NOTE) {
            return true;
        }
        lower.match_indices("anchor").any(|(i, w)| {
            if i > 0 && lower.as_bytes()[i - 1].is_ascii_alphanumeric() {
                return false;
            }
            let rest = &line[i + w.len()..];
            let rest = rest.strip_prefix('s').unwrap_or(rest);
            let Some(rest) = rest.strip_prefix(' ') else {
                return false;
            };
            let mut c = rest.chars();
            c.next().is_some_and(|a| a.is_ascii_uppercase())
                && c.next().is_none_or(|b| !b.is_ascii_alphabetic())
        })
    }

    /// The comment part of a line of Rust (`//`) or TOML (`#`): the whole line when it starts
    /// with the marker, else what follows a marker after whitespace and outside a string (an
    /// even number of quotes before it), which leaves `https://` and `"#..."` alone.
    fn comment<'a>(line: &'a str, marker: &str) -> Option<&'a str> {
        let t = line.trim_start();
        if let Some(rest) = t.strip_prefix(marker) {
            return Some(rest);
        }
        line.match_indices(marker).find_map(|(i, _)| {
            let before = &line[..i];
            (before.ends_with([' ', '\t']) && before.matches('"').count().is_multiple_of(2))
                .then(|| &line[i + marker.len()..])
        })
    }

    fn looks_like_repo_path(t: &str) -> bool {
        if t.contains(['<', '>', '{', '}', '*', '$']) || t.contains("://") {
            return false; // placeholders, format strings, globs, variables, URLs
        }
        let bare = t.strip_prefix("./").unwrap_or(t);
        if OUTPUT_PREFIXES.iter().any(|p| bare.starts_with(p)) {
            return false;
        }
        let ext = Path::new(t).extension().and_then(|e| e.to_str());
        (t.contains('/') && ext.is_some_and(|e| REPO_EXTENSIONS.contains(&e)))
            || REPO_DIRS.iter().any(|d| bare.starts_with(d))
    }

    /// The tokens of `text` that look like repository paths, without a trailing `:line` or
    /// `#fragment` and sentence punctuation.
    fn path_tokens(text: &str) -> impl Iterator<Item = &str> {
        text.split(|c: char| c.is_whitespace() || "`\"'()[],;|=".contains(c))
            .filter(|t| !t.contains("://"))
            .map(|t| t.split(['#', ':']).next().unwrap_or(""))
            .map(|t| t.trim_end_matches(['.', '!', '?']))
            .filter(|t| looks_like_repo_path(t))
    }

    /// `base/p` with `.` and `..` resolved, if it stays inside the repository.
    fn normalise(base: &Path, p: &str) -> Option<PathBuf> {
        if p.starts_with('/') {
            return None;
        }
        let mut out = PathBuf::new();
        for c in base.join(p).components() {
            match c {
                std::path::Component::Normal(n) => out.push(n),
                std::path::Component::CurDir => {}
                std::path::Component::ParentDir => {
                    if !out.pop() {
                        return None;
                    }
                }
                _ => return None,
            }
        }
        Some(out)
    }

    /// Dangling pointers in the text of the repository file `rel`, as `file:line: problem`.
    /// A path may be relative to the repository root, to the file's directory or to its
    /// crate's root (`src/main.rs` here); in a file outside every crate (top-level docs) to
    /// any crate's root, since those speak of the files each crate has.
    /// `crates` lists the crate roots and `exists` answers for repository-relative paths, so
    /// the check runs on strings in its own test.
    fn dangling(
        rel: &Path,
        text: &str,
        crates: &[PathBuf],
        exists: &dyn Fn(&Path) -> bool,
    ) -> Vec<String> {
        let ext = rel.extension().and_then(|e| e.to_str()).unwrap_or("");
        let dir = rel.parent().unwrap_or(Path::new(""));
        let own_crate = crates.iter().filter(|c| rel.starts_with(c)).max();
        let mut bases = vec![PathBuf::new(), dir.to_path_buf()];
        match own_crate {
            Some(c) => bases.push(c.clone()),
            None => bases.extend(crates.iter().cloned()),
        }
        let mut out = Vec::new();
        // In Markdown, ```text blocks hold program output (benchmark results), a record rather
        // than a pointer; every other line is checked.
        let mut fence: Option<(usize, bool)> = None;
        for (i, line) in text.lines().enumerate() {
            let at = format!("{}:{}", rel.display(), i + 1);
            for name in OUTSIDE_NOTES {
                if line.contains(name) {
                    out.push(format!("{at}: `{name}` lives outside the repository"));
                }
            }
            if cites_style_note(line) {
                out.push(format!(
                    "{at}: cites a style note kept outside the repository; name the habit \
                     and the project it comes from instead"
                ));
            }
            let checked = match ext {
                "rs" => comment(line, "//"),
                "toml" => comment(line, "#"),
                "md" => {
                    let t = line.trim();
                    let ticks = t.len() - t.trim_start_matches('`').len();
                    match fence {
                        Some((n, _)) if ticks >= n && t.trim_matches('`').is_empty() => {
                            fence = None;
                            None
                        }
                        Some((_, output)) => (!output).then_some(line),
                        None if ticks >= 3 => {
                            fence = Some((ticks, t[ticks..].trim() == "text"));
                            None
                        }
                        None => Some(line),
                    }
                }
                _ => None,
            };
            for tok in checked.into_iter().flat_map(path_tokens) {
                let found = bases
                    .iter()
                    .filter_map(|b| normalise(b, tok))
                    .any(|p| exists(&p));
                if !found {
                    out.push(format!("{at}: `{tok}` names no file in the repository"));
                }
            }
        }
        out
    }

    /// The files whose comments and docs are checked, repository-relative.
    fn documented_files() -> Vec<PathBuf> {
        let root = root();
        let mut files = Vec::new();
        for d in ["crates", "tests", "xtask"] {
            rust_files(&root.join(d), &mut files);
        }
        let mut by_ext = |dir: &Path, ext: &str, deep: bool| {
            let mut stack = vec![dir.to_path_buf()];
            while let Some(d) = stack.pop() {
                let Ok(entries) = std::fs::read_dir(&d) else {
                    continue; // docs/ may not exist yet
                };
                for e in entries {
                    let p = e.unwrap().path();
                    if p.is_dir() {
                        if deep && !p.ends_with("target") {
                            stack.push(p);
                        }
                    } else if p.extension().is_some_and(|x| x == ext) {
                        files.push(p);
                    }
                }
            }
        };
        by_ext(&root, "md", false);
        by_ext(&root.join("docs"), "md", true);
        by_ext(&root.join("crates"), "md", true);
        by_ext(&root.join("scenes"), "toml", true);
        for m in ["Cargo.toml", "xtask/Cargo.toml", "tests/Cargo.toml"] {
            files.push(root.join(m));
        }
        for c in our_crates() {
            let manifest = root.join("crates").join(c).join("Cargo.toml");
            if manifest.exists() {
                // (a crate being created may not have one yet)
                files.push(manifest);
            }
        }
        let mut rel: Vec<PathBuf> = files
            .into_iter()
            .map(|f| f.strip_prefix(&root).unwrap().to_path_buf())
            .collect();
        rel.sort();
        rel.dedup();
        rel
    }

    #[test]
    fn no_dangling_paths_in_comments_and_docs() {
        let root = root();
        let mut crates: Vec<PathBuf> = our_crates()
            .into_iter()
            .map(|c| Path::new("crates").join(c))
            .collect();
        crates.extend(["xtask".into(), "tests".into()]);
        let exists = |p: &Path| root.join(p).exists();
        let mut problems = Vec::new();
        for rel in documented_files() {
            let text = std::fs::read_to_string(root.join(&rel)).unwrap();
            problems.extend(dangling(&rel, &text, &crates, &exists));
        }
        assert!(
            problems.is_empty(),
            "comments and docs point to files that are not in the repository:\n{}",
            problems.join("\n")
        );
    }

    /// The issue tracker is not in the repository: a comment or doc that cites an issue by
    /// number points nowhere a reader can follow.
    #[test]
    fn no_issue_numbers_in_comments_and_docs() {
        let root = root();
        let mut problems = Vec::new();
        for rel in documented_files() {
            let text = std::fs::read_to_string(root.join(&rel)).unwrap();
            problems.extend(issue_numbers(&rel, &text));
        }
        assert!(
            problems.is_empty(),
            "comments and docs cite issues the repository does not hold:\n{}",
            problems.join("\n")
        );
    }

    /// Lines of `text` that cite an issue by number: the word, plural or not, then a number,
    /// with or without `#`.
    fn issue_numbers(rel: &Path, text: &str) -> Vec<String> {
        let mut out = Vec::new();
        for (i, line) in text.lines().enumerate() {
            let lower = line.to_lowercase();
            let mut rest = lower.as_str();
            while let Some(at) = rest.find("issue") {
                let word_start = !rest[..at].ends_with(|c: char| c.is_ascii_alphanumeric());
                let after = rest[at + 5..].trim_start_matches('s');
                let after = after.trim_start_matches([' ', '#']);
                if word_start && after.starts_with(|c: char| c.is_ascii_digit()) {
                    out.push(format!("{}:{}: {}", rel.display(), i + 1, line.trim()));
                    break;
                }
                rest = &rest[at + 5..];
            }
        }
        out
    }

    #[test]
    fn issue_numbers_are_found() {
        let f = |t: &str| issue_numbers(Path::new("a.rs"), t).len();
        let cited = concat!(
            "//! Shards (iss",
            "ue 14): x\n// Iss",
            "ue #3\n// iss",
            "ues 4, 5\n"
        );
        assert_eq!(f(cited), 3);
        assert_eq!(
            f("// a known issue: 12 photons\n// tissue 1\n// an issue, k = 250\n"),
            0
        );
    }

    #[test]
    fn dangling_paths_are_found_on_strings() {
        let crates = [PathBuf::from("crates/geom")];
        let present = [
            "crates/geom/src/lib.rs",
            "crates/geom/src/tests.rs",
            "scenes",
        ];
        let exists = |p: &Path| present.iter().any(|q| p == Path::new(q));
        let check = |rel: &str, text: &str| dangling(Path::new(rel), text, &crates, &exists);
        let rs = "crates/geom/src/ray.rs";

        // Existing files, from the root, the file's directory and its crate's root.
        assert!(
            check(
                rs,
                "/// see `crates/geom/src/lib.rs`, lib.rs and src/tests.rs.\n"
            )
            .is_empty()
        );
        assert!(check(rs, "//! compare (./tests.rs) with ../src/lib.rs: fine\n").is_empty());
        // Outputs, placeholders, URLs, fractions and code are not paths.
        let not_paths = "// out/a/image.json, layers/<name>.exr, {}/x.rs, \
                         https://example.org/a.md, 1/1.5, GB/s\nlet a = \"crates/nope.rs\";\n";
        assert!(
            check(rs, not_paths).is_empty(),
            "{:?}",
            check(rs, not_paths)
        );

        // Dangling: a missing file, a trailing comment, a path leaving the repository.
        let e = check(rs, "fn f() {}\n/// see `crates/geom/src/gone.rs`.\n");
        assert_eq!(
            e,
            ["crates/geom/src/ray.rs:2: `crates/geom/src/gone.rs` names no file in the repository"]
        );
        assert_eq!(check(rs, "let x = 1; // as in scenes/x/y.toml\n").len(), 1);
        assert_eq!(check(rs, "// ../../../../etc/notes.md\n").len(), 1);
        // Markdown: every line but program output in ```text blocks.
        let md = "see docs/gone.md\n```sh\ncargo run scenes/gone.toml\n```\n```text\nwrote docs/x.md\n```\n";
        assert_eq!(check("README.md", md).len(), 2);
        // Notes outside the repository, by name and by style-note label, anywhere in a file.
        let notes = format!(
            "// the {} table\nlet s = \"{}\";\n// ({} B2.6)\n// ({}s A3.4, C)\n",
            concat!("algorithms", ".md"),
            concat!("../", "shared/x"),
            concat!("style ", "anchor"),
            "anchor",
        );
        assert_eq!(check(rs, &notes).len(), 4, "{:?}", check(rs, &notes));
        assert!(check(rs, "// anchored at Anchor Point, anchor Alpha\n").is_empty());
    }
}
