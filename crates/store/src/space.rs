//! The free space a trace checks before it starts.

use std::path::Path;

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
