//! Photon files at fault: a traced cache damaged (flipped, truncated, foreign bytes, a FIFO)
//! or missing, and a run whose photon files could never fit on the disk.

use super::*;

/// The one photon file of the case's cache, replaced by what `f` makes of its bytes (or a
/// FIFO for `None`).
fn damage_photons(d: &Path, f: impl Fn(Vec<u8>) -> Option<Vec<u8>>) {
    let file = std::fs::read_dir(d.join("cache"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .find(|p| p.extension().is_some_and(|x| x == "photons"))
        .expect("a traced photon file");
    let bytes = std::fs::read(&file).unwrap();
    std::fs::remove_file(&file).unwrap();
    match f(bytes) {
        Some(b) => std::fs::write(&file, b).unwrap(),
        None => {
            let made = std::process::Command::new("mkfifo").arg(&file).status();
            assert!(made.is_ok_and(|s| s.success()));
        }
    }
}

fn cases() -> Vec<Case> {
    vec![
        // The photon file (a traced cache, then damaged): estimate names the file.
        Case {
            name: "a photon file with a flipped header byte",
            files: good(),
            setup: vec!["trace {d}/s.toml --photons 2000 --cache {d}/cache"],
            prepare: Some(|d| {
                damage_photons(d, |mut b| {
                    b[40] ^= 0xff;
                    Some(b)
                })
            }),
            args: "estimate {d}/s.toml --photons 2000 --cache {d}/cache --out {d}/out",
            code: 1,
            words: &["-global.photons", "checksum mismatch in the header"],
            check: absent("out"),
        },
        Case {
            name: "a truncated photon file",
            files: good(),
            setup: vec!["trace {d}/s.toml --photons 2000 --cache {d}/cache"],
            prepare: Some(|d| damage_photons(d, |b| Some(b[..100].to_vec()))),
            args: "estimate {d}/s.toml --photons 2000 --cache {d}/cache --out {d}/out",
            code: 1,
            words: &["-global.photons", "truncated"],
            check: absent("out"),
        },
        Case {
            name: "a photon file of foreign bytes",
            files: good(),
            setup: vec!["trace {d}/s.toml --photons 2000 --cache {d}/cache"],
            prepare: Some(|d| damage_photons(d, |_| Some(b"not photons at all".to_vec()))),
            args: "estimate {d}/s.toml --photons 2000 --cache {d}/cache --out {d}/out",
            code: 1,
            words: &["-global.photons", "not a photon file"],
            check: absent("out"),
        },
        Case {
            name: "a photon file that is a FIFO",
            files: good(),
            setup: vec!["trace {d}/s.toml --photons 2000 --cache {d}/cache"],
            prepare: Some(|d| damage_photons(d, |_| None)),
            args: "estimate {d}/s.toml --photons 2000 --cache {d}/cache --out {d}/out",
            code: 1,
            words: &["-global.photons", "not a regular file"],
            check: absent("out"),
        },
        Case {
            name: "estimate without a traced cache",
            files: good(),
            setup: vec![],
            prepare: None,
            args: "estimate {d}/s.toml --photons 2000 --cache {d}/cache --out {d}/out",
            code: 1,
            words: &["-global.photons", "run `trace` first"],
            check: absent("out"),
        },
        // Hangs.
        Case {
            name: "photon files that could never fit",
            files: good(),
            setup: vec![],
            prepare: None,
            args: "trace {d}/s.toml --photons 1000000000000 --cache {d}/cache",
            code: 1,
            words: &[
                "s.toml",
                "1000000000000 photon paths would write",
                "bytes free",
                "at most about",
            ],
            check: absent("cache/plan.txt"),
        },
    ]
}

#[test]
fn bad_input_table() {
    run_table("photon-files", cases());
}
