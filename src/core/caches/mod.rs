//! Caches on disk: the prepared environment and the files they live in.

pub mod disk_cache;
pub mod environment_cache;
