//! Shared helpers for the command line's tests: the library's test helpers (tests/common at the
//! workspace's root) and the `twister` binary.
#![allow(dead_code, unused_imports)]

#[path = "../../../tests/common/mod.rs"]
mod library;
pub use library::*;

/// The `twister` binary, with Mesa's device-select layer quiet and the assets folder set (the
/// binary looks for it from the working directory, and these tests run in cli/).
pub fn twister() -> std::process::Command {
    let mut c = std::process::Command::new(env!("CARGO_BIN_EXE_twister"));
    c.env("NODEVICE_SELECT", "1").env(twister::core::assets::ASSETS_VAR, assets_root());
    c
}
