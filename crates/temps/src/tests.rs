use crate::{Removed, Stale, Temp, owner, remove_live_under, remove_stale, remove_stale_of};
use std::io::Write;
use std::path::{Path, PathBuf};

struct Dir(PathBuf);

impl Dir {
    fn new(name: &str) -> Dir {
        let d = std::env::temp_dir().join(format!("temps-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        Dir(d)
    }

    fn listing(&self) -> Vec<String> {
        listing(&self.0)
    }
}

impl Drop for Dir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

fn listing(d: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(d)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

/// The pid of a process that has exited (until the pid is reused).
fn dead_pid() -> u32 {
    let mut child = std::process::Command::new("true").spawn().unwrap();
    let pid = child.id();
    child.wait().unwrap();
    pid
}

#[test]
fn names_carry_the_pid_and_only_they_parse() {
    let d = Dir::new("names");
    let (t, _) = Temp::file(&d.0.join("image.exr")).unwrap();
    let name = t.path().file_name().unwrap().to_str().unwrap().to_string();
    assert!(name.starts_with(".image.exr.tmp-"), "{name}");
    assert_eq!(owner(&name), Some(std::process::id()));
    assert_eq!(owner(".a.b.tmp-12-0"), Some(12));
    for other in [
        "a.tmp-12-0",
        ".a.tmp-12",
        ".a.tmp--0",
        ".a.tmp-x-0",
        ".a.tmp-12-",
        ".a.tmp-12-0x",
        "image.exr",
    ] {
        assert_eq!(owner(other), None, "{other}");
    }
}

#[test]
fn a_published_temp_is_the_target_and_a_dropped_one_is_gone() {
    let d = Dir::new("publish");
    let target = d.0.join("a.txt");
    let (t, mut f) = Temp::file(&target).unwrap();
    f.write_all(b"new").unwrap();
    drop(f);
    t.publish(&target).unwrap();
    assert_eq!(d.listing(), ["a.txt"]);
    assert_eq!(std::fs::read(&target).unwrap(), b"new");

    let (t, _) = Temp::file(&target).unwrap();
    let s = Temp::dir(&d.0.join("shard")).unwrap();
    std::fs::write(s.path().join("x"), b"x").unwrap();
    assert_eq!(d.listing().len(), 3);
    drop((t, s));
    assert_eq!(d.listing(), ["a.txt"]);

    // Moved aside, the old file is a temp too.
    let old = Temp::aside(&target).unwrap();
    assert_eq!(d.listing().len(), 1);
    assert_eq!(owner(&d.listing()[0]), Some(std::process::id()));
    drop(old);
    assert!(d.listing().is_empty());
}

/// What the signal handler does, limited to this test's directory: other tests make temps too.
#[test]
fn live_temps_are_removed_on_request() {
    let d = Dir::new("live");
    let s = Temp::dir(&d.0.join("0")).unwrap();
    let (inner, _) = Temp::file(&s.path().join("sums.f64")).unwrap();
    let (outer, _) = Temp::file(&d.0.join("image.exr")).unwrap();
    std::fs::write(d.0.join("kept"), b"").unwrap();
    assert_eq!(remove_live_under(&d.0), Removed { files: 2, dirs: 1 });
    assert_eq!(d.listing(), ["kept"]);
    // Their owners then drop them without harm.
    drop((inner, outer, s));
    assert_eq!(d.listing(), ["kept"]);
    assert_eq!(
        Removed { files: 1, dirs: 2 }.to_string(),
        "1 unfinished file and 2 staging directories"
    );
}

/// kill -9: a later run removes the temps whose process is gone, and only those.
#[test]
fn stale_temps_are_removed_by_pid() {
    let d = Dir::new("stale");
    let dead = dead_pid();
    let stale_file = format!(".old.photons.tmp-{dead}-0");
    let stale_dir = format!(".0.tmp-{dead}-3");
    let ours = format!(".mine.exr.tmp-{}-999", std::process::id());
    let others = ["notes.tmp-1-1", ".notes.tmp-x-1"];
    for f in [&stale_file, &ours]
        .into_iter()
        .chain(&others.map(String::from))
    {
        std::fs::write(d.0.join(f), b"partial").unwrap();
    }
    std::fs::create_dir(d.0.join(&stale_dir)).unwrap();
    std::fs::write(d.0.join(&stale_dir).join("sums.f64"), b"partial").unwrap();
    // Only the target's: the stale directory is `0`'s, the file `old.photons`'.
    let of_shard = remove_stale_of(&d.0.join("0"));
    assert_eq!(of_shard.len(), 1);
    assert!(of_shard[0].dir);
    assert!(d.0.join(&stale_file).exists());
    let mut removed = of_shard;
    removed.extend(remove_stale(&d.0));
    removed.sort_by(|a, b| a.path.cmp(&b.path));
    assert_eq!(
        removed,
        [
            Stale {
                path: d.0.join(&stale_dir),
                pid: dead,
                dir: true
            },
            Stale {
                path: d.0.join(&stale_file),
                pid: dead,
                dir: false
            },
        ]
    );
    assert!(
        removed[0]
            .to_string()
            .contains("staging directory of process")
    );
    let mut want = vec![ours, others[1].to_string(), others[0].to_string()];
    want.sort();
    assert_eq!(d.listing(), want);
}

#[test]
fn a_staged_directory_replaces_the_old_one_whole() {
    let d = Dir::new("replace");
    let target = d.0.join("sub").join("run");
    // A staging directory of a dead process beside the target is swept; the parent is made.
    std::fs::create_dir_all(d.0.join("sub")).unwrap();
    let dead = d.0.join("sub").join(format!(".run.tmp-{}-0", dead_pid()));
    std::fs::create_dir(&dead).unwrap();
    let (t, stale) = Temp::stage(&target).unwrap();
    assert_eq!(stale.len(), 1, "{stale:?}");
    std::fs::write(t.path().join("a"), b"1").unwrap();
    assert!(t.replace(&target).unwrap().is_none());
    assert_eq!(listing(&d.0.join("sub")), ["run"]);
    assert_eq!(listing(&target), ["a"]);

    let (t, _) = Temp::stage(&target).unwrap();
    std::fs::write(t.path().join("b"), b"2").unwrap();
    assert!(t.replace(&target).unwrap().is_none());
    assert_eq!(listing(&d.0.join("sub")), ["run"]);
    assert_eq!(listing(&target), ["b"]);
}
