//! Directories an earlier command wrote, read back: shard sets `merge` refuses (missing,
//! duplicate, foreign, damaged or forged shards), `--shard` values, runs `composite` refuses.

use super::*;

/// `rel` (a text file) with `from` replaced by `to`, which must occur in it.
fn edit(d: &Path, rel: &str, from: &str, to: &str) {
    let p = d.join(rel);
    let t = std::fs::read_to_string(&p).unwrap();
    assert!(t.contains(from), "{rel} lacks `{from}`: {t}");
    std::fs::write(&p, t.replace(from, to)).unwrap();
}

fn cases() -> Vec<Case> {
    vec![
        // Runs read back by composite.
        Case {
            name: "composite of a directory that is no run",
            files: good(),
            setup: vec![],
            prepare: None,
            args: "composite {d} --out {d}/out",
            code: 1,
            words: &["image.json", "cannot read"],
            check: absent("out"),
        },
        // Accepted bad values.
        Case {
            name: "composite of a run counting 1e300 samples",
            files: good(),
            setup: vec!["render {d}/s.toml --method path --spp 1 --threads 1 --out {d}/run"],
            prepare: Some(|d| edit(d, "run/image.json", "\"count\": 1,", "\"count\": 1e300,")),
            args: "composite {d}/run --out {d}/out",
            code: 1,
            words: &["image.json", "count 1e300 exceeds 2^53"],
            check: absent("out"),
        },
        // Shards and merge: a bad set is refused naming the file, nothing written.
        Case {
            name: "merge: a shard missing",
            files: good(),
            setup: vec![
                "trace {d}/s.toml --photons 2000 --shard 0/3 --out {d}/a0",
                "trace {d}/s.toml --photons 2000 --shard 2/3 --out {d}/a2",
            ],
            prepare: None,
            args: "merge {d}/a2 {d}/a0 --out {d}/m",
            code: 1,
            words: &["a2/shard.json", "missing", "1/3"],
            check: absent("m"),
        },
        Case {
            name: "merge: the last shard missing",
            files: good(),
            setup: vec!["render {d}/s.toml --method path --spp 8 --shard 0/2 --out {d}/a0"],
            prepare: None,
            args: "merge {d}/a0 --out {d}/m",
            code: 1,
            words: &["a0/shard.json", "missing", "1/2"],
            check: absent("m"),
        },
        Case {
            name: "merge: a shard given twice",
            files: good(),
            setup: vec![
                "trace {d}/s.toml --photons 2000 --shard 0/2 --out {d}/a0",
                "trace {d}/s.toml --photons 2000 --shard 0/2 --out {d}/b0",
                "trace {d}/s.toml --photons 2000 --shard 1/2 --out {d}/a1",
            ],
            prepare: None,
            args: "merge {d}/a0 {d}/a1 {d}/b0 --out {d}/m",
            code: 1,
            words: &["b0/shard.json", "duplicates", "a0/shard.json"],
            check: absent("m"),
        },
        Case {
            name: "merge: overlapping shards of two sets",
            files: good(),
            setup: vec![
                "trace {d}/s.toml --photons 2000 --shard 0/2 --out {d}/a0",
                "trace {d}/s.toml --photons 2000 --shard 1/3 --out {d}/b1",
                "trace {d}/s.toml --photons 2000 --shard 2/3 --out {d}/b2",
            ],
            prepare: None,
            args: "merge {d}/a0 {d}/b1 {d}/b2 --out {d}/m",
            code: 1,
            words: &["b1/shard.json", "overlaps", "a0/shard.json"],
            check: absent("m"),
        },
        Case {
            name: "merge: shards of another seed",
            files: good(),
            setup: vec![
                "trace {d}/s.toml --photons 2000 --shard 0/2 --out {d}/a0",
                "trace {d}/s.toml --photons 2000 --seed 7 --shard 1/2 --out {d}/a1",
            ],
            prepare: None,
            args: "merge {d}/a0 {d}/a1 --out {d}/m",
            code: 1,
            words: &["a1/shard.json", "seed 7"],
            check: absent("m"),
        },
        Case {
            name: "merge: shards of another scene",
            files: with(
                with(good(), "t.toml", text(scene("").replace("a.obj", "b.obj"))),
                "b.obj",
                text(OBJ.replace("v 1 0 1", "v 1 0 1.5")),
            ),
            setup: vec![
                "trace {d}/s.toml --photons 2000 --shard 0/2 --out {d}/a0",
                "trace {d}/t.toml --photons 2000 --shard 1/2 --out {d}/a1",
            ],
            prepare: None,
            args: "merge {d}/a0 {d}/a1 --out {d}/m",
            code: 1,
            words: &["a1/shard.json", "scene hash"],
            check: absent("m"),
        },
        Case {
            name: "merge: image shards of another parameter set",
            files: good(),
            setup: vec![
                "render {d}/s.toml --method path --spp 8 --shard 0/2 --out {d}/a0",
                "render {d}/s.toml --method path --spp 8 --no-caustics --shard 1/2 --out {d}/a1",
            ],
            prepare: None,
            args: "merge {d}/a0 {d}/a1 --out {d}/m",
            code: 1,
            words: &["a1/shard.json", "parameter hash"],
            check: absent("m"),
        },
        Case {
            name: "merge: photon shards with an image shard",
            files: good(),
            setup: vec![
                "trace {d}/s.toml --photons 2000 --shard 0/2 --out {d}/a0",
                "render {d}/s.toml --method path --spp 8 --shard 1/2 --out {d}/a1",
            ],
            prepare: None,
            args: "merge {d}/a0 {d}/a1 --out {d}/m",
            code: 1,
            words: &["a1/shard.json", "holds image"],
            check: absent("m"),
        },
        Case {
            name: "merge: an unfinished shard (no shard.json)",
            files: with(good(), "a1/global.photons", text("partial")),
            setup: vec!["trace {d}/s.toml --photons 2000 --shard 0/2 --out {d}/a0"],
            prepare: None,
            args: "merge {d}/a0 {d}/a1 --out {d}/m",
            code: 1,
            words: &["a1/shard.json", "not a complete shard"],
            check: absent("m"),
        },
        Case {
            name: "merge: a damaged photon shard",
            files: good(),
            setup: vec![
                "trace {d}/s.toml --photons 2000 --shard 0/2 --out {d}/a0",
                "trace {d}/s.toml --photons 2000 --shard 1/2 --out {d}/a1",
            ],
            prepare: Some(|d| {
                let p = d.join("a1/global.photons");
                let mut b = std::fs::read(&p).unwrap();
                let n = b.len();
                b[n - 5] ^= 0x10;
                std::fs::write(&p, b).unwrap();
            }),
            args: "merge {d}/a0 {d}/a1 --out {d}/m",
            code: 1,
            words: &["a1/global.photons", "checksum"],
            check: absent("m"),
        },
        Case {
            name: "merge: a damaged image shard",
            files: good(),
            setup: vec!["render {d}/s.toml --method path --spp 8 --shard 0/1 --out {d}/a0"],
            prepare: Some(|d| {
                let p = d.join("a0/sums.f64");
                let mut b = std::fs::read(&p).unwrap();
                b[100] ^= 0x01;
                std::fs::write(&p, b).unwrap();
            }),
            args: "merge {d}/a0 --out {d}/m",
            code: 1,
            words: &["a0/sums.f64", "checksum"],
            check: absent("m"),
        },
        Case {
            name: "merge: a shard file whose range is not its shard's",
            files: good(),
            setup: vec!["trace {d}/s.toml --photons 2000 --shard 0/1 --out {d}/a0"],
            prepare: Some(|d| {
                let p = d.join("a0/shard.json");
                let t = std::fs::read_to_string(&p).unwrap();
                std::fs::write(&p, t.replace("\"shard\": \"0/1\"", "\"shard\": \"0/2\"")).unwrap();
            }),
            args: "merge {d}/a0 --out {d}/m",
            code: 1,
            words: &["a0/shard.json", "should cover"],
            check: absent("m"),
        },
        Case {
            name: "--shard I/N with I = N",
            files: good(),
            setup: vec![],
            prepare: None,
            args: "trace {d}/s.toml --photons 2000 --shard 3/3",
            code: 2,
            words: &["--shard", "0 <= I < N"],
            check: None,
        },
        Case {
            name: "render --shard of sppm",
            files: good(),
            setup: vec![],
            prepare: None,
            args: "render {d}/s.toml --method sppm --photons 2000 --shard 0/2 --out {d}/a0",
            code: 1,
            words: &["sppm", "depend on each other"],
            check: absent("a0"),
        },
        Case {
            name: "render --shard with a time budget",
            files: good(),
            setup: vec![],
            prepare: None,
            args: "render {d}/s.toml --method path --time 1 --shard 0/2 --out {d}/a0",
            code: 1,
            words: &["--shard", "--time"],
            check: absent("a0"),
        },
        Case {
            name: "trace --shard N of more shards than photon paths",
            files: good(),
            setup: vec![],
            prepare: None,
            args: "trace {d}/s.toml --photons 2000 --threads 1 --shard 0/4294967295 --out {d}/sh",
            code: 1,
            words: &[
                "--shard 0/4294967295",
                "a run of 2000 photon paths",
                "N must be at most 2000",
            ],
            check: absent("sh"),
        },
        Case {
            name: "render --shard N of more shards than blocks",
            files: good(),
            setup: vec![],
            prepare: None,
            args: "render {d}/s.toml --method path --spp 2 --threads 1 --shard 0/1000 --out {d}/sh",
            code: 1,
            words: &[
                "--shard 0/1000",
                "the run has 2 blocks (2 samples per pixel)",
                "N must be at most 2",
            ],
            check: absent("sh"),
        },
        Case {
            name: "render --shard N that leaves a shard of uneven blocks empty",
            files: good(),
            setup: vec![],
            // 32 samples in passes of 1, 1, 2 and seven of 4: no pass starts in 9..12, the
            // samples of shard 3 of 10.
            prepare: None,
            args: "render {d}/s.toml --method path --spp 32 --threads 1 --shard 0/10 --out {d}/sh",
            code: 1,
            words: &[
                "--shard 0/10",
                "leave shard 3/10 without one",
                "N must be at most 8",
            ],
            check: absent("sh"),
        },
        Case {
            name: "merge: an image shard with a forged count",
            files: good(),
            setup: vec![
                "render {d}/s.toml --method path --spp 2 --threads 1 --shard 0/1 --out {d}/a0",
            ],
            prepare: Some(|d| edit(d, "a0/shard.json", "\"count\": 2,", "\"count\": 99,")),
            args: "merge {d}/a0 --out {d}/m",
            code: 1,
            words: &[
                "a0/shard.json",
                "count 99, but its blocks 0..2 hold 2 samples per pixel",
            ],
            check: absent("m"),
        },
        Case {
            name: "merge: a NaN in an image shard's sums, checksum resealed",
            files: good(),
            setup: vec![
                "render {d}/s.toml --method path --spp 2 --threads 1 --shard 0/1 --out {d}/a0",
            ],
            prepare: Some(|d| {
                let p = d.join("a0/sums.f64");
                let mut s = film::read_sums(&p).unwrap();
                s.planes[1][21][2] = f64::NAN;
                film::write_sums(&p, &s).unwrap();
            }),
            args: "merge {d}/a0 --out {d}/m",
            code: 1,
            words: &["a0/sums.f64", "plane 1", "pixel (5, 1) holds [", "NaN]"],
            check: absent("m"),
        },
        Case {
            name: "merge --out inside an input shard",
            files: good(),
            setup: vec![
                "trace {d}/s.toml --photons 2000 --threads 1 --shard 0/2 --out {d}/sh/0",
                "trace {d}/s.toml --photons 2000 --threads 1 --shard 1/2 --out {d}/sh/1",
            ],
            prepare: None,
            args: "merge {d}/sh/0 {d}/sh/1 --out {d}/sh/0/merged",
            code: 1,
            words: &[
                "sh/0/merged: the output directory lies inside the input shard",
                "sh/0",
            ],
            check: absent("sh/0/merged"),
        },
        Case {
            name: "merge --out holding the input shards",
            files: good(),
            setup: vec![
                "render {d}/s.toml --method path --spp 2 --threads 1 --shard 0/2 --out {d}/sh/0",
                "render {d}/s.toml --method path --spp 2 --threads 1 --shard 1/2 --out {d}/sh/1",
            ],
            prepare: None,
            args: "merge {d}/sh/0 {d}/sh/1 --out {d}/sh",
            code: 1,
            words: &["sh: the output directory contains the input shard", "sh/0"],
            check: absent("sh/image.json"),
        },
        Case {
            name: "merge: a photon shard with a forged count",
            files: good(),
            setup: vec![
                "trace {d}/s.toml --photons 2000 --threads 1 --shard 0/2 --out {d}/sh/0",
                "trace {d}/s.toml --photons 2000 --threads 1 --shard 1/2 --out {d}/sh/1",
            ],
            prepare: Some(|d| edit(d, "sh/1/shard.json", "\"count\": 1000,", "\"count\": 999,")),
            args: "merge {d}/sh/0 {d}/sh/1 --out {d}/m",
            code: 1,
            words: &[
                "sh/1/shard.json",
                "count 999, but its range 1000..2000 holds 1000 photon paths",
            ],
            check: absent("m"),
        },
    ]
}

#[test]
fn bad_input_table() {
    run_table("shards", cases());
}
