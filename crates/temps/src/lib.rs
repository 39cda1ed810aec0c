//! `temps`: the temporary files and staging directories that become published files or
//! directories by a rename (photon files, images, shards). Each is named
//! `.<name>.tmp-<pid>-<n>` beside what it becomes (hidden, so globs such as `shards/*` skip
//! it), and is
//! - registered while this process holds it, so that a signal handler can remove every one
//!   before the process exits ([`remove_live_before_exit`]);
//! - removed when dropped unpublished (an error, a panic unwinding);
//! - removed by a later run writing into the same directory once its process is gone
//!   ([`remove_stale`]: kill -9, power loss), which the pid in its name tells.
//!
//! Creating, publishing and removing a temp all take one lock, and the signal handler keeps
//! it until the process exits: no temp can appear, or be half published, between the
//! handler's removal and the exit.

use std::ffi::OsString;
use std::fs::File;
use std::io;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Mutex, MutexGuard};

#[cfg(test)]
mod tests;

/// What comes between a temp's name and its owner's pid.
const MARK: &str = ".tmp-";

#[derive(Clone, Copy, PartialEq, Eq, Debug)]
enum Kind {
    File,
    Dir,
}

/// Temps of this process, oldest first.
static LIVE: Mutex<Vec<(PathBuf, Kind)>> = Mutex::new(Vec::new());

/// Makes names unique within this process (the pid separates processes).
static COUNTER: AtomicU64 = AtomicU64::new(0);

fn live() -> MutexGuard<'static, Vec<(PathBuf, Kind)>> {
    // A panic elsewhere must not stop the cleanup: the list stays valid whatever happened.
    LIVE.lock().unwrap_or_else(|e| e.into_inner())
}

/// A fresh name beside `target`: `.<name>.tmp-<pid>-<n>`.
fn fresh(target: &Path) -> io::Result<PathBuf> {
    let name = target
        .file_name()
        .ok_or_else(|| io::Error::new(io::ErrorKind::InvalidInput, "the path has no file name"))?;
    let n = COUNTER.fetch_add(1, Ordering::Relaxed);
    let mut tmp = OsString::from(".");
    tmp.push(name);
    tmp.push(format!("{MARK}{}-{n}", std::process::id()));
    Ok(target.with_file_name(tmp))
}

fn remove(path: &Path, kind: Kind) -> bool {
    match kind {
        Kind::File => std::fs::remove_file(path).is_ok(),
        Kind::Dir => std::fs::remove_dir_all(path).is_ok(),
    }
}

/// A temporary file or staging directory of this process: removed when dropped, unless
/// [`Temp::publish`]ed.
#[derive(Debug)]
pub struct Temp {
    path: PathBuf,
    kind: Kind,
    published: bool,
}

impl Temp {
    /// A new empty file beside `target`, to be written and then published as `target`.
    pub fn file(target: &Path) -> io::Result<(Temp, File)> {
        Temp::create(target, Kind::File, |p| File::create_new(p))
    }

    /// A new empty directory beside `target` (whose parent must exist), to be filled and then
    /// published as `target`.
    pub fn dir(target: &Path) -> io::Result<Temp> {
        Temp::create(target, Kind::Dir, |p| std::fs::create_dir(p)).map(|(t, ())| t)
    }

    /// Moves the file or directory at `path` out of the way, to a temp name beside it: it is
    /// removed when the returned temp is dropped, by a signal handler, or by a later run.
    pub fn aside(path: &Path) -> io::Result<Temp> {
        let kind = match std::fs::symlink_metadata(path)? {
            m if m.is_dir() => Kind::Dir,
            _ => Kind::File,
        };
        let (t, ()) = Temp::create(path, kind, |tmp| {
            // A rename would replace a file (or an empty directory) of that name.
            if std::fs::symlink_metadata(tmp).is_ok() {
                return Err(io::ErrorKind::AlreadyExists.into());
            }
            std::fs::rename(path, tmp)
        })?;
        Ok(t)
    }

    /// Makes it under the lock, so that it is registered before a signal handler can look.
    fn create<T>(
        target: &Path,
        kind: Kind,
        make: impl Fn(&Path) -> io::Result<T>,
    ) -> io::Result<(Temp, T)> {
        let mut live = live();
        loop {
            let path = fresh(target)?;
            match make(&path) {
                Ok(made) => {
                    live.push((path.clone(), kind));
                    let t = Temp {
                        path,
                        kind,
                        published: false,
                    };
                    return Ok((t, made));
                }
                // Left by an earlier process that had this pid: take the next name.
                Err(e) if e.kind() == io::ErrorKind::AlreadyExists => continue,
                Err(e) => return Err(e),
            }
        }
    }

    /// A staging directory for the directory `target`: its parent made if missing, and the
    /// staging directories and set-aside copies of `target` that dead processes left beside
    /// it removed first (returned, to be reported).
    pub fn stage(target: &Path) -> io::Result<(Temp, Vec<Stale>)> {
        if let Some(parent) = target.parent().filter(|p| !p.as_os_str().is_empty()) {
            std::fs::create_dir_all(parent)?;
        }
        let stale = remove_stale_of(target);
        Ok((Temp::dir(target)?, stale))
    }

    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Publishes it as `to`, replacing what is there without a moment when `to` is half of
    /// either: the old one is moved aside ([`Temp::aside`]), this one renamed into place, and
    /// the old one removed. A failed rename puts the old one back (and removes this one).
    /// Returns the old one if it could not be removed (a part of it read-only, say): it stays
    /// under its temp name, for a later run to remove once it can.
    pub fn replace(self, to: &Path) -> io::Result<Option<Stuck>> {
        let old = match std::fs::symlink_metadata(to) {
            Ok(_) => Some(Temp::aside(to)?),
            Err(e) if e.kind() == io::ErrorKind::NotFound => None,
            Err(e) => return Err(e),
        };
        if let Err(e) = self.publish(to) {
            if let Some(old) = old {
                let _ = old.publish(to);
            }
            return Err(e);
        }
        Ok(old.and_then(|o| o.remove().err()))
    }

    /// Removes it now, saying why it could not be (dropping it says nothing).
    pub fn remove(mut self) -> Result<(), Stuck> {
        let mut live = live();
        let removed = match self.kind {
            Kind::File => std::fs::remove_file(&self.path),
            Kind::Dir => std::fs::remove_dir_all(&self.path),
        };
        live.retain(|(p, _)| *p != self.path);
        // Whatever is left is no longer this process's to remove.
        self.published = true;
        removed.map_err(|error| Stuck {
            path: self.path.clone(),
            error,
        })
    }

    /// Renames it to `to` (replacing a file there), after which it is no longer a temp. On
    /// failure it is removed.
    pub fn publish(mut self, to: &Path) -> io::Result<()> {
        let mut live = live();
        let renamed = std::fs::rename(&self.path, to);
        if renamed.is_ok() {
            live.retain(|(p, _)| *p != self.path);
            self.published = true;
        }
        drop(live);
        renamed
    }
}

impl Drop for Temp {
    fn drop(&mut self) {
        if !self.published {
            let mut live = live();
            remove(&self.path, self.kind);
            live.retain(|(p, _)| *p != self.path);
        }
    }
}

/// A temp that could not be removed, and why.
#[derive(Debug)]
pub struct Stuck {
    pub path: PathBuf,
    pub error: io::Error,
}

/// Counts of temps removed.
#[derive(Clone, Copy, PartialEq, Eq, Debug, Default)]
pub struct Removed {
    pub files: usize,
    pub dirs: usize,
}

impl std::fmt::Display for Removed {
    fn fmt(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        let s =
            |n: usize, one: &str, many: &str| format!("{n} {}", if n == 1 { one } else { many });
        write!(
            f,
            "{} and {}",
            s(self.files, "unfinished file", "unfinished files"),
            s(self.dirs, "staging directory", "staging directories")
        )
    }
}

/// Removes the registered temps that `pick` selects: files first, then directories (a
/// directory may hold some of the files).
fn remove_live(live: &mut Vec<(PathBuf, Kind)>, pick: impl Fn(&Path) -> bool) -> Removed {
    let mut removed = Removed::default();
    for kind in [Kind::File, Kind::Dir] {
        live.retain(|(p, k)| {
            if *k != kind || !pick(p) {
                return true;
            }
            if remove(p, kind) {
                match kind {
                    Kind::File => removed.files += 1,
                    Kind::Dir => removed.dirs += 1,
                }
            }
            false
        });
    }
    removed
}

/// Removes every temp of this process, for a signal handler that then exits (their owners
/// are not told). The registry stays locked: a thread that would create or publish a temp
/// waits for the exit instead.
pub fn remove_live_before_exit() -> Removed {
    let mut live = live();
    let removed = remove_live(&mut live, |_| true);
    std::mem::forget(live);
    removed
}

/// Removes the temps of this process under `dir` (tests: other tests write in parallel).
pub fn remove_live_under(dir: &Path) -> Removed {
    remove_live(&mut live(), |p| p.starts_with(dir))
}

/// The pid in a temp's name `.<name>.tmp-<pid>-<n>`, or `None` for any other name.
pub fn owner(name: &str) -> Option<u32> {
    parse(name).map(|(_, pid)| pid)
}

/// `<name>` and the pid of a temp's name `.<name>.tmp-<pid>-<n>`.
fn parse(name: &str) -> Option<(&str, u32)> {
    let (target, tail) = name.strip_prefix('.')?.rsplit_once(MARK)?;
    let (pid, n) = tail.split_once('-')?;
    let digits = |s: &str| !s.is_empty() && s.bytes().all(|b| b.is_ascii_digit());
    if !(digits(pid) && digits(n)) {
        return None;
    }
    Some((target, pid.parse().ok()?))
}

/// Whether process `pid` exists (a signal 0 that fails with ESRCH says it does not). Where
/// that cannot be asked, every process counts as alive, so nothing is removed.
fn alive(pid: u32) -> bool {
    #[cfg(unix)]
    {
        let Ok(raw) = i32::try_from(pid) else {
            return true;
        };
        if raw <= 0 {
            return true;
        }
        !matches!(
            nix::sys::signal::kill(nix::unistd::Pid::from_raw(raw), None),
            Err(nix::errno::Errno::ESRCH)
        )
    }
    #[cfg(not(unix))]
    {
        let _ = pid;
        true
    }
}

/// A temp that [`remove_stale`] removed.
#[derive(Clone, PartialEq, Eq, Debug)]
pub struct Stale {
    pub path: PathBuf,
    pub pid: u32,
    pub dir: bool,
}

impl std::fmt::Display for Stale {
    fn fmt(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        let what = if self.dir {
            "staging directory"
        } else {
            "file"
        };
        write!(
            f,
            "removed {}: an unfinished {what} of process {}, which is gone",
            self.path.display(),
            self.pid
        )
    }
}

/// Removes the temps in `dir` whose process is gone (no run will ever finish or read them).
/// Those of live processes, this one included, are left alone.
pub fn remove_stale(dir: &Path) -> Vec<Stale> {
    remove_stale_where(dir, |_| true)
}

/// [`remove_stale`] for the temps of `target` only. Pids tell only about this machine's
/// processes: a directory that writers on several machines share (shards of one run) keeps
/// the temps of the others' targets.
pub fn remove_stale_of(target: &Path) -> Vec<Stale> {
    let (Some(dir), Some(name)) = (target.parent(), target.file_name()) else {
        return Vec::new();
    };
    let dir = if dir.as_os_str().is_empty() {
        Path::new(".")
    } else {
        dir
    };
    remove_stale_where(dir, |t| name.to_str() == Some(t))
}

fn remove_stale_where(dir: &Path, pick: impl Fn(&str) -> bool) -> Vec<Stale> {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return Vec::new();
    };
    let mut removed = Vec::new();
    for e in entries.flatten() {
        let name = e.file_name();
        let Some((target, pid)) = name.to_str().and_then(parse) else {
            continue;
        };
        // Not followed: a link is nobody's temp.
        let kind = match e.file_type() {
            Ok(t) if t.is_file() => Kind::File,
            Ok(t) if t.is_dir() => Kind::Dir,
            _ => continue,
        };
        if pick(target) && !alive(pid) && remove(&e.path(), kind) {
            removed.push(Stale {
                path: e.path(),
                pid,
                dir: kind == Kind::Dir,
            });
        }
    }
    removed
}
