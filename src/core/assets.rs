//! Where the third-party assets are (the Stanford bunny, the cow, Sponza, the Khronos glTF
//! samples, an HDR environment: `../shared/assets`, described in its README). twister never
//! ships them: the benchmarks read them, and the tests that need them run only where they are
//! (`tests/common`'s `assets_present`).
//!
//! The folder is `TWISTER_ASSETS` where that is set, else `../shared/assets` relative to the
//! working directory (the project's root, where `cargo test` and the README's commands run).

use std::path::PathBuf;

/// The environment variable that names the assets folder.
pub const ASSETS_VAR: &str = "TWISTER_ASSETS";
/// The folder used when [`ASSETS_VAR`] is not set.
pub const DEFAULT_ASSETS: &str = "../shared/assets";
/// The assets folder (it may not exist).
pub fn root() -> PathBuf {
    std::env::var_os(ASSETS_VAR).map_or_else(|| PathBuf::from(DEFAULT_ASSETS), PathBuf::from)
}
