//! Unit tests of xtask's own logic: argument parsing and the benchmark record. The repository
//! rules live in `tidy.rs`.

use std::path::Path;

use crate::benchmarks::{self, cpu_model, replace_section, section, utc};
use crate::flags::{self, Bench, Cmd};

fn strings(v: &[&str]) -> Vec<String> {
    v.iter().map(|s| s.to_string()).collect()
}

fn bench(args: &[&str]) -> Bench {
    match flags::parse(&strings(args)) {
        Ok(Cmd::Bench(b)) => b,
        _ => panic!("{args:?} is not a benchmark"),
    }
}

#[test]
fn bench_commands_keep_what_was_typed_and_add_the_default_scene() {
    let b = bench(&["bench", "rays", "--compare"]);
    assert_eq!(b.what, "rays");
    assert_eq!(b.typed, ["rays", "--compare"]);
    assert_eq!(b.args, ["bench-rays", flags::DEFAULT_SCENE, "--compare"]);
    let b = bench(&["bench", "photons", "scenes/corner/corner.toml"]);
    assert_eq!(b.args, ["bench-photons", "scenes/corner/corner.toml"]);
    let b = bench(&["bench", "store", "--photons", "100"]);
    assert_eq!(b.args, ["bench-store", "--photons", "100"]);
    // Accuracy takes cases; without one, the committed suite.
    let b = bench(&["bench", "accuracy", "--budgets", "1,2"]);
    assert_eq!(
        b.args,
        [
            "bench-accuracy",
            "--suite",
            flags::ACCURACY_SUITE,
            "--budgets",
            "1,2"
        ]
    );
    let b = bench(&["bench", "accuracy", "--case", "s.toml,a.exr,b.exr"]);
    assert_eq!(b.args, ["bench-accuracy", "--case", "s.toml,a.exr,b.exr"]);
    assert!(flags::parse(&strings(&["bench", "nope"])).is_err());
    // A benchmark's help is photonflow's, run plainly: nothing recorded in the docs (it once
    // replaced the benchmark's section with the help text).
    for help in ["--help", "-h"] {
        assert!(matches!(
            flags::parse(&strings(&["bench", "rays", "--compare", help])),
            Ok(Cmd::Photonflow(a)) if a == ["bench-rays", "--compare", help]
        ));
    }
    for own in ["fuzz", "gen-scenes", "slurm-demo", "bench"] {
        assert!(matches!(
            flags::parse(&strings(&[own, "--help"])),
            Ok(Cmd::Help)
        ));
    }
    let e = flags::parse(&strings(&["bench"])).err().unwrap_or_default();
    assert!(e.contains("which benchmark?") && e.contains("rays"), "{e}");
    let e = flags::parse(&strings(&["bench", "nope"]))
        .err()
        .unwrap_or_default();
    assert!(e.contains("`nope` is not a benchmark"), "{e}");
}

const DOC: &str = "\
# Benchmarks

Intro.

## bench store

(moved from the crate docs)

| a | b |

## bench knn

Placeholder.
";

#[test]
fn a_section_is_replaced_in_place_and_the_others_kept() {
    let new = "## bench store\n\nnew numbers\n";
    let out = replace_section(DOC, "store", new);
    assert_eq!(
        out,
        "# Benchmarks\n\nIntro.\n\n## bench store\n\nnew numbers\n\n## bench knn\n\nPlaceholder.\n"
    );
    // Replacing again changes nothing: the record is idempotent.
    assert_eq!(replace_section(&out, "store", new), out);
    // The last section runs to the end of the file.
    let out = replace_section(DOC, "knn", "## bench knn\n\nk\n");
    assert!(out.ends_with("| a | b |\n\n## bench knn\n\nk\n"), "{out}");
    assert!(out.starts_with("# Benchmarks\n\nIntro.\n\n## bench store\n"));
}

#[test]
fn a_new_section_is_appended_and_headings_in_output_do_not_end_sections() {
    let out = replace_section(DOC, "rays", "## bench rays\n\nr\n");
    assert_eq!(out, format!("{DOC}\n## bench rays\n\nr\n"));
    // `## ` inside a fenced block is output, not a heading; `## bench rays2` is another
    // benchmark.
    let doc = "# B\n\n## bench rays\n\n```text\n## not a heading\n```\n\n## bench rays2\n\nx\n";
    let out = replace_section(doc, "rays", "## bench rays\n\nnew\n");
    assert_eq!(out, "# B\n\n## bench rays\n\nnew\n\n## bench rays2\n\nx\n");
}

#[test]
fn a_section_holds_command_date_machine_and_fenced_output() {
    let b = bench(&["bench", "rays", "--runs", "3"]);
    let s = section(&b, "2024-01-02 03:04 UTC", "2 CPUs", "line `x`\n```\n\n");
    assert_eq!(
        s,
        format!(
            "## bench rays\n\n\
             - command: `cargo xtask bench rays --runs 3`\n\
             - runs: `photonflow bench-rays {} --runs 3` (profile `release-lto`)\n\
             - date: 2024-01-02 03:04 UTC\n\
             - machine: 2 CPUs\n\n\
             ````text\nline `x`\n```\n````\n",
            flags::DEFAULT_SCENE
        )
    );
    // Arguments the shell would split are quoted.
    let b = bench(&["bench", "knn", "--label", "a b"]);
    assert!(section(&b, "", "", "").contains("`cargo xtask bench knn --label 'a b'`"));
}

#[test]
fn markdown_tables_in_the_output_stand_outside_the_fences() {
    let b = bench(&["bench", "accuracy"]);
    let out = "run 1\n\n| a | b |\n|---|---|\n| 1 | 2 |\n\nnote\n| c |\n";
    let s = section(&b, "d", "m", out);
    let body = &s[s.find("```text").unwrap()..];
    assert_eq!(
        body,
        "```text\nrun 1\n```\n\n| a | b |\n|---|---|\n| 1 | 2 |\n\n```text\nnote\n```\n\n| c |\n"
    );
    // A section holding tables is still replaced whole.
    let doc = format!("# B\n\n{s}\n## bench knn\n\nk\n");
    let again = replace_section(&doc, "accuracy", &s);
    assert_eq!(again, doc);
}

/// A whole run with `echo` standing in for photonflow (it prints its arguments), in a scratch
/// root: the output lands in its section, the rest of the file stays, no temp file is left,
/// and a failed run records nothing.
#[cfg(unix)]
#[test]
fn a_run_is_recorded_in_its_section() {
    let root = std::env::temp_dir().join(format!("xtask-bench-{}", std::process::id()));
    let doc = root.join(benchmarks::DOC);
    std::fs::create_dir_all(doc.parent().unwrap()).unwrap();
    std::fs::write(&doc, DOC).unwrap();
    let b = bench(&["bench", "store", "--photons", "5"]);
    benchmarks::run(&root, Path::new("echo"), &b).unwrap();
    let text = std::fs::read_to_string(&doc).unwrap();
    assert!(text.starts_with("# Benchmarks\n\nIntro.\n\n## bench store\n\n- command: `cargo xtask bench store --photons 5`\n"));
    assert!(
        text.contains("\n```text\nbench-store --photons 5\n```\n\n## bench knn\n\nPlaceholder.\n")
    );
    assert!(!text.contains("moved from"));
    let files = std::fs::read_dir(doc.parent().unwrap()).unwrap().count();
    assert_eq!(files, 1, "a temp file was left behind");

    assert!(benchmarks::run(&root, Path::new("false"), &b).is_err());
    assert_eq!(std::fs::read_to_string(&doc).unwrap(), text);
    std::fs::remove_dir_all(&root).unwrap();
}

#[test]
fn dates_are_utc_calendar_dates() {
    assert_eq!(utc(0), "1970-01-01 00:00 UTC");
    assert_eq!(utc(951_782_400), "2000-02-29 00:00 UTC");
    assert_eq!(utc(951_868_800 + 3_723), "2000-03-01 01:02 UTC");
    assert_eq!(utc(1_704_067_199), "2023-12-31 23:59 UTC");
    assert_eq!(utc(4_107_542_400), "2100-03-01 00:00 UTC");
}

#[test]
fn the_cpu_model_comes_from_cpuinfo() {
    let info = "processor\t: 0\nmodel name\t: AMD  EPYC 7763 64-Core Processor\nprocessor\t: 1\n";
    assert_eq!(
        cpu_model(info).as_deref(),
        Some("AMD EPYC 7763 64-Core Processor")
    );
    assert_eq!(cpu_model("processor\t: 0\n"), None);
}

/// The command lists that README's table and docs/commands.md are held to (by photonflow's
/// tests) are the ones `parse` takes, and the help has an entry for each and for no other.
#[test]
fn the_command_lists_are_what_parse_takes_and_what_the_help_lists() {
    for c in flags::FORWARDED {
        assert!(
            matches!(flags::parse(&strings(&[c])), Ok(Cmd::Photonflow(a)) if a == [*c]),
            "{c}"
        );
    }
    for what in flags::BENCHES {
        assert!(
            matches!(flags::parse(&strings(&["bench", what])), Ok(Cmd::Bench(_))),
            "bench {what}"
        );
    }
    for c in flags::OWN {
        assert!(
            matches!(
                flags::parse(&strings(&[c])),
                Ok(Cmd::GenScenes | Cmd::SlurmDemo | Cmd::Fuzz(_))
            ),
            "{c}"
        );
    }
    let mut listed: Vec<String> = flags::FORWARDED
        .iter()
        .chain(flags::OWN)
        .map(|c| c.to_string())
        .chain(flags::BENCHES.iter().map(|w| format!("bench {w}")))
        .collect();
    listed.sort();
    // An entry is a line indented by two spaces: its command, and a benchmark's name.
    let mut entries: Vec<String> = flags::HELP
        .lines()
        .filter(|l| l.starts_with("  ") && !l.starts_with("   "))
        .filter_map(|l| {
            let mut words = l.split_whitespace();
            match (words.next()?, words.next()) {
                ("bench", Some("...")) => None,
                ("bench", Some(what)) => Some(format!("bench {what}")),
                (c, _) => Some(c.to_string()),
            }
        })
        .collect();
    entries.sort();
    assert_eq!(entries, listed, "xtask's help against its command lists");
}
