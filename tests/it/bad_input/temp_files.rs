//! Temporary files: a stale one of a dead process is removed by the next run writing there.

use super::*;

fn cases() -> Vec<Case> {
    vec![
        // Temporary files.
        Case {
            name: "a stale temp file of a dead process",
            files: with(good(), "cache/.x.photons.tmp-999999999-0", text("partial")),
            setup: vec![],
            prepare: None,
            args: "trace {d}/s.toml --photons 2000 --cache {d}/cache",
            code: 0,
            words: &[],
            check: absent("cache/.x.photons.tmp-999999999-0"),
        },
        Case {
            name: "merge: a stale temp file of a dead process in --out",
            files: with(good(), "m/.x.photons.tmp-999999999-0", text("partial")),
            setup: vec![
                "trace {d}/s.toml --photons 2000 --shard 0/2 --out {d}/a0",
                "trace {d}/s.toml --photons 2000 --shard 1/2 --out {d}/a1",
            ],
            prepare: None,
            args: "merge {d}/a0 {d}/a1 --out {d}/m",
            code: 0,
            words: &[],
            check: absent("m/.x.photons.tmp-999999999-0"),
        },
    ]
}

#[test]
fn bad_input_table() {
    run_table("temp-files", cases());
}
