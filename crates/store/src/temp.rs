//! Temporary photon files (`<path>.tmp-<pid>-<n>`, see [`crate::StoreWriter`]): the ones this
//! process is writing, which a Ctrl-C handler removes before exiting, and stale ones left by
//! a process that died without cleaning up (kill -9, power loss), which the next trace in the
//! same directory removes. Also the free space a trace checks before it starts.

use std::path::{Path, PathBuf};
use std::sync::Mutex;

/// Temp files of writers alive in this process.
static LIVE: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

fn live() -> std::sync::MutexGuard<'static, Vec<PathBuf>> {
    // A panic elsewhere must not stop the cleanup: the list stays valid whatever happened.
    LIVE.lock().unwrap_or_else(|e| e.into_inner())
}

pub(crate) fn register(tmp: &Path) {
    live().push(tmp.to_path_buf());
}

pub(crate) fn unregister(tmp: &Path) {
    live().retain(|p| p != tmp);
}

/// Removes every temporary photon file this process is writing and returns how many it
/// removed. For a signal handler that then exits: the writers are not told.
pub fn remove_live_temp_files() -> usize {
    remove_live_where(|_| true)
}

/// [`remove_live_temp_files`] for the files `pick` selects (tests run writers in parallel).
pub(crate) fn remove_live_where(pick: impl Fn(&Path) -> bool) -> usize {
    let mut files = live();
    let mut removed = 0;
    files.retain(|p| {
        if !pick(p) {
            return true;
        }
        removed += std::fs::remove_file(p).is_ok() as usize;
        false
    });
    removed
}

/// The pid in a temp file's name `<name>.tmp-<pid>-<n>`, or `None` for any other name.
pub fn temp_owner(name: &str) -> Option<u32> {
    let (_, tail) = name.rsplit_once(".tmp-")?;
    let (pid, n) = tail.split_once('-')?;
    let digits = |s: &str| !s.is_empty() && s.bytes().all(|b| b.is_ascii_digit());
    (digits(pid) && digits(n)).then(|| pid.parse().ok())?
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

/// Removes the temporary photon files in `dir` whose writing process is gone (their content
/// is unfinished and no run will ever finish or read it); returns them with their pids.
/// Files of live processes, this one included, are left alone.
pub fn remove_stale_temp_files(dir: &Path) -> Vec<(PathBuf, u32)> {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return Vec::new();
    };
    let mut removed = Vec::new();
    for e in entries.flatten() {
        let name = e.file_name();
        let Some(pid) = name.to_str().and_then(temp_owner) else {
            continue;
        };
        let is_file = e.file_type().is_ok_and(|t| t.is_file());
        if is_file && !alive(pid) && std::fs::remove_file(e.path()).is_ok() {
            removed.push((e.path(), pid));
        }
    }
    removed
}

/// Bytes available to this user on the file system holding `dir`, where it can be asked.
pub fn free_space(dir: &Path) -> Option<u64> {
    #[cfg(unix)]
    {
        let s = nix::sys::statvfs::statvfs(dir).ok()?;
        Some((s.blocks_available() as u64).saturating_mul(s.fragment_size() as u64))
    }
    #[cfg(not(unix))]
    {
        let _ = dir;
        None
    }
}
