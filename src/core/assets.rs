//! Where the third-party assets are (the Stanford bunny, the cow, Sponza, the Khronos glTF
//! samples, an HDR environment: `../shared/assets`, described in its README). twister never
//! ships them: the benchmarks read them, and the tests that need them run only where they are.
//!
//! The folder is `TWISTER_ASSETS` where that is set, else `../shared/assets` relative to the
//! working directory (the project's root, where `cargo test` and the README's commands run).

use std::path::PathBuf;

/// The environment variable that names the assets folder.
pub const ASSETS_VAR: &str = "TWISTER_ASSETS";
/// The folder used when [`ASSETS_VAR`] is not set.
pub const DEFAULT_ASSETS: &str = "../shared/assets";
/// The environment variable naming a folder where tests that did not run for want of the assets
/// leave one file each (`scripts/test.sh` counts them).
pub const SKIPPED_VAR: &str = "TWISTER_ASSET_SKIPS";

/// The assets folder (it may not exist).
pub fn root() -> PathBuf {
    std::env::var_os(ASSETS_VAR).map_or_else(|| PathBuf::from(DEFAULT_ASSETS), PathBuf::from)
}

/// For a test that needs the assets: whether they are here (at `root`, usually [`root`]). Where they are not, the test is
/// recorded as not run (one line on stderr, one file under [`SKIPPED_VAR`]) and the caller
/// returns; under CI (`CI=true`) they must be here, so a missing folder panics, naming it —
/// CI can never turn green without them.
pub fn present_for_test(root: &std::path::Path, test: &str) -> bool {
    if root.is_dir() {
        return true;
    }
    if std::env::var("CI").is_ok_and(|v| v == "true" || v == "1") {
        panic!(
            "{test}: the third-party assets are missing ({} not found; set {ASSETS_VAR}), and CI must run every test",
            root.display()
        );
    }
    eprintln!("{test}: not run ({} not found; set {ASSETS_VAR})", root.display());
    if let Some(dir) = std::env::var_os(SKIPPED_VAR) {
        use std::sync::atomic::{AtomicU32, Ordering};
        static N: AtomicU32 = AtomicU32::new(0);
        let n = N.fetch_add(1, Ordering::Relaxed);
        let file = PathBuf::from(dir).join(format!("{}-{n}", std::process::id()));
        // Best effort: the count is a report, not a result.
        let _ = std::fs::create_dir_all(file.parent().unwrap()).and_then(|_| std::fs::write(&file, test));
    }
    false
}
