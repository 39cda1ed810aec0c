//! The method list and defaults that README.md and `cargo xtask`'s help spell by hand are the
//! method table's (`render::methods::METHODS`), and a scene without `render.method` renders
//! the default they document. README's command table lists every command of the binary and
//! of `cargo xtask`, one short line each.

use render::methods::{ESTIMATE_DEFAULT, METHODS};
use scene::Method;
use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn read(rel: &str) -> String {
    std::fs::read_to_string(root().join(rel)).unwrap_or_else(|e| panic!("{rel}: {e}"))
}

fn table() -> Vec<String> {
    METHODS.iter().map(|r| r.method.name()).collect()
}

/// The quoted names on the line of `text` that starts (after spaces) with `start`.
fn quoted_on(text: &str, start: &str) -> Vec<String> {
    let line = text
        .lines()
        .find(|l| l.trim_start().starts_with(start))
        .unwrap_or_else(|| panic!("no line starting with `{start}`"));
    line.split('"')
        .skip(1)
        .step_by(2)
        .map(str::to_string)
        .collect()
}

/// README's scene-file schema: `method = "<default>"  # or "<the others>", ...`.
fn readme_default_and_methods() -> (String, Vec<String>) {
    let names = quoted_on(&read("README.md"), "method = \"");
    (names[0].clone(), names)
}

#[test]
fn the_method_table_has_one_row_per_method_in_order() {
    let rows: Vec<Method> = METHODS.iter().map(|r| r.method).collect();
    assert_eq!(rows, Method::ALL);
    for r in &METHODS {
        assert!(!r.help.is_empty() && !r.table.is_empty(), "{}", r.method);
        // A method with passes records them; a time budget needs passes to stop after.
        assert_eq!(
            r.passes.is_some(),
            r.method != Method::GlobalDirect && r.method != Method::FinalGather,
            "{}",
            r.method
        );
    }
    assert!(render::methods::row(ESTIMATE_DEFAULT).reads_photon_maps());
}

#[test]
fn readme_lists_the_method_table_and_its_default() {
    let (default, mut names) = readme_default_and_methods();
    assert_eq!(default, Method::default().name(), "README's default method");
    names.sort();
    let mut want = table();
    want.sort();
    assert_eq!(names, want, "README's method list");
}

#[test]
fn xtask_help_lists_the_method_table_and_its_defaults() {
    let help = read("xtask/src/flags.rs");
    let render = help
        .lines()
        .find(|l| l.trim_start().starts_with("render SCENE [--method "))
        .expect("xtask's render line");
    let list = render.split("--method ").nth(1).unwrap_or("");
    let mut names: Vec<String> = list
        .trim_end_matches(']')
        .split('|')
        .map(str::to_string)
        .collect();
    names.sort();
    let mut want = table();
    want.sort();
    assert_eq!(names, want, "xtask's method list");
    assert!(
        help.contains(&format!("render.method (default {})", Method::default())),
        "xtask's help names another default than {}",
        Method::default()
    );
    let estimate = help
        .lines()
        .find(|l| l.trim_start().starts_with("estimate SCENE [--method "))
        .expect("xtask's estimate line");
    let maps: Vec<String> = METHODS
        .iter()
        .filter(|r| r.reads_photon_maps())
        .map(|r| r.method.name())
        .collect();
    assert!(
        estimate.contains(&format!("[--method {}]", maps.join("|"))),
        "{estimate}"
    );
    assert!(
        help.contains(&format!("(default {ESTIMATE_DEFAULT})")),
        "xtask's help names another estimate default than {ESTIMATE_DEFAULT}"
    );
}

/// Renders the furnace scene (no `method` in it) without `--method`, as a new user would, and
/// checks that `image.json` names the method README documents as the default.
#[test]
fn render_without_method_renders_the_documented_default() {
    let scene = root().join("scenes/furnace/furnace.toml");
    assert!(
        !read("scenes/furnace/furnace.toml").contains("method"),
        "the furnace scene must leave `method` out for this test"
    );
    let out = std::env::temp_dir().join(format!("photonflow-default-{}", std::process::id()));
    let cache = out.join("cache");
    let (code, err) = photonflow::run_args([
        "photonflow",
        "render",
        scene.to_str().unwrap(),
        "--photons",
        "2000",
        "--passes",
        "1",
        "--threads",
        "1",
        "--out",
        out.join("run").to_str().unwrap(),
        "--cache",
        cache.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err:?}");
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("run/image.json")).unwrap())
            .unwrap();
    let _ = std::fs::remove_dir_all(&out);
    let (default, _) = readme_default_and_methods();
    assert_eq!(json["method"], default.as_str());
}

/// `estimate` without `--method` on a scene whose method reads no photon maps runs the
/// default README documents, from the photon sets a `trace` cached.
#[test]
fn estimate_without_method_runs_the_documented_default() {
    let readme = read("README.md");
    assert!(
        readme.contains(&format!("else `{ESTIMATE_DEFAULT}`")),
        "README names another estimate default than {ESTIMATE_DEFAULT}"
    );
    let scene = root().join("scenes/furnace/furnace.toml");
    let out = std::env::temp_dir().join(format!("photonflow-estimate-{}", std::process::id()));
    let cache = out.join("cache");
    let (s, c) = (scene.to_str().unwrap(), cache.to_str().unwrap());
    let common = ["--photons", "2000", "--threads", "1", "--cache", c];
    let (code, err) =
        photonflow::run_args([["photonflow", "trace", s].as_slice(), &common].concat());
    assert_eq!(code, 0, "{err:?}");
    let run = out.join("run");
    let (code, err) = photonflow::run_args(
        [
            ["photonflow", "estimate", s, "--out", run.to_str().unwrap()].as_slice(),
            &common,
        ]
        .concat(),
    );
    assert_eq!(code, 0, "{err:?}");
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(run.join("image.json")).unwrap()).unwrap();
    let _ = std::fs::remove_dir_all(&out);
    assert_eq!(json["method"], ESTIMATE_DEFAULT.name().as_str());
}

/// The quoted names of the `pub const NAME: &[&str] = &[...];` list in `xtask/src/flags.rs`
/// (xtask links no renderer crate, so its lists are read from the source).
fn xtask_list(name: &str) -> Vec<String> {
    let src = read("xtask/src/flags.rs");
    let start = format!("pub const {name}: &[&str] = &[");
    let at = src
        .find(&start)
        .unwrap_or_else(|| panic!("xtask/src/flags.rs: no `{name}` list"))
        + start.len();
    let end = src[at..].find("];").expect("the list's end") + at;
    src[at..end]
        .split('"')
        .skip(1)
        .step_by(2)
        .map(str::to_string)
        .collect()
}

/// The commands `cargo xtask` runs itself, with no photonflow command behind them.
pub fn xtask_own_commands() -> Vec<String> {
    xtask_list("OWN")
}

/// The binary's commands as `cargo xtask` spells them: `bench-<what>` is `bench <what>`.
fn cli_commands() -> Vec<String> {
    let mut v: Vec<String> = photonflow::command()
        .get_subcommands()
        .map(|c| c.get_name().replacen("bench-", "bench ", 1))
        .collect();
    v.sort();
    v
}

/// The rows of README's command table (section "## Commands"), as their cells.
fn readme_command_rows() -> Vec<Vec<String>> {
    let readme = read("README.md");
    let section = readme
        .split("\n## ")
        .find(|s| s.starts_with("Commands\n"))
        .expect("README has no `## Commands` section");
    section
        .lines()
        .filter(|l| l.starts_with("| `cargo xtask "))
        .map(|l| {
            l.trim_matches('|')
                .split(" | ")
                .map(|c| c.trim().to_string())
                .collect()
        })
        .collect()
}

/// `cargo xtask render SCENE ...` is `render`; `cargo xtask bench rays ...` is `bench rays`.
fn readme_commands() -> Vec<String> {
    let mut v: Vec<String> = readme_command_rows()
        .iter()
        .map(|row| {
            let mut words = row[0].trim_matches('`').split_whitespace().skip(2);
            match (words.next(), words.next()) {
                (Some("bench"), Some(what)) => format!("bench {what}"),
                (Some(c), _) => c.to_string(),
                (None, _) => panic!("README: an empty command in {row:?}"),
            }
        })
        .collect();
    v.sort();
    v
}

#[test]
fn xtask_forwards_every_command_of_the_binary() {
    let mut forwarded: Vec<String> = xtask_list("FORWARDED")
        .into_iter()
        .chain(xtask_list("BENCHES").iter().map(|w| format!("bench {w}")))
        .collect();
    forwarded.sort();
    assert_eq!(forwarded, cli_commands(), "xtask/src/flags.rs's lists");
}

#[test]
fn readme_lists_every_command_once_in_a_short_line() {
    let mut want: Vec<String> = cli_commands()
        .into_iter()
        .chain(xtask_own_commands())
        .collect();
    want.sort();
    assert_eq!(readme_commands(), want, "README's command table");
    for row in readme_command_rows() {
        assert_eq!(row.len(), 2, "README's command table: {row:?}");
        for cell in &row {
            assert!(
                cell.chars().count() <= 200,
                "README's command table: a cell of {} characters (the details belong in \
                 the command's --help): {cell}",
                cell.chars().count()
            );
        }
    }
}
