//! What twister's caches on disk share (the prepared environments, `core::caches::environment_cache`;
//! the driver's pipeline cache, `gpu::pipeline_cache`): the folder, the hash that keys and checks
//! their files, and the whole-file write. A cache is an optimisation: failing to read or write it
//! is silent.
//!
//! The folder: `$TWISTER_CACHE_DIR` (empty or `off`: no cache), else `$XDG_CACHE_HOME/twister`,
//! else `~/.cache/twister`; a relative `XDG_CACHE_HOME` or `HOME` is ignored (the XDG base
//! directory rule), so a cache never lands in the working folder.

use std::path::{Path, PathBuf};

/// The cache folder from the environment variables (None: caching off).
pub fn cache_dir() -> Option<PathBuf> {
    match std::env::var_os("TWISTER_CACHE_DIR") {
        Some(dir) if dir.is_empty() || dir == "off" => None,
        Some(dir) => Some(PathBuf::from(dir)),
        None => std::env::var_os("XDG_CACHE_HOME")
            .map(PathBuf::from)
            .filter(|d| d.is_absolute())
            .or_else(|| std::env::var_os("HOME").map(|h| Path::new(&h).join(".cache")).filter(|d| d.is_absolute()))
            .map(|d| d.join("twister")),
    }
}

/// The FNV-1a offset basis: the hash of nothing.
pub const FNV_OFFSET: u64 = 0xcbf2_9ce4_8422_2325;

/// FNV-1a, 64 bits, continued from `hash` (the same in every process and build).
pub fn fnv1a(bytes: &[u8], mut hash: u64) -> u64 {
    for &b in bytes {
        hash ^= b as u64;
        hash = hash.wrapping_mul(0x0100_0000_01b3);
    }
    hash
}

/// Writes `bytes` to `file` in `dir` whole: under a temporary name (this process's and thread's),
/// then renamed into place, so that a concurrent reader never sees half a file. Whether it was
/// written; a failure leaves no temporary file.
pub fn write_whole(dir: &Path, file: &Path, bytes: &[u8]) -> bool {
    let name = file.file_name().map_or_else(Default::default, |n| n.to_string_lossy().into_owned());
    let temporary = dir.join(format!(".{name}.{}-{:?}.tmp", std::process::id(), std::thread::current().id()));
    let written = std::fs::create_dir_all(dir)
        .and_then(|_| std::fs::write(&temporary, bytes))
        .and_then(|_| std::fs::rename(&temporary, file));
    if written.is_err() {
        let _ = std::fs::remove_file(&temporary);
    }
    written.is_ok()
}
