//! The pipelines' cache on disk: wgpu's `PipelineCache` (a Vulkan pipeline cache), where the
//! adapter has one, loaded when the device opens and saved when it closes if pipelines were
//! built meanwhile, so that a fresh process does less of the driver's compiling.
//!
//! Where: the folder of `core::caches::disk_cache` (`TWISTER_CACHE_DIR`, `off` or empty: none). One
//! file per adapter class (`wgpu::util::pipeline_cache_key`) and build of the shaders (a hash of
//! every WGSL source and of twister's version): a newer build's file replaces the older one's. A damaged, foreign or unreadable file is ignored and replaced
//! (wgpu checks the header and falls back to an empty cache); a cache that cannot be written
//! is skipped. Never an error, never a message.

use std::hash::{Hash, Hasher};
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};

use crate::core::caches::disk_cache::{cache_dir, fnv1a, write_whole, FNV_OFFSET};

/// The cache and its file.
pub struct DiskPipelineCache {
    pub cache: wgpu::PipelineCache,
    path: PathBuf,
    /// Whether a pipeline was built with the cache since it was loaded.
    used: AtomicBool,
    /// A hash of the file's bytes as loaded (unchanged data is not written again).
    loaded: u64,
}

/// FNV-1a as a `Hasher`, for hashing the shader sources' parts in turn.
struct Fnv(u64);

impl Hasher for Fnv {
    fn finish(&self) -> u64 {
        self.0
    }
    fn write(&mut self, bytes: &[u8]) {
        self.0 = fnv1a(bytes, self.0);
    }
}

/// A hash of what the pipelines are built from: every WGSL source, the generated constants and
/// twister's version.
fn shader_hash() -> u64 {
    let mut h = Fnv(FNV_OFFSET);
    env!("CARGO_PKG_VERSION").hash(&mut h);
    crate::encoding::constants::wgsl().hash(&mut h);
    for stage in crate::shader::STAGES {
        for file in stage.files() {
            file.source.hash(&mut h);
        }
    }
    for (name, source) in crate::shader::SHARED {
        (name, source).hash(&mut h);
    }
    h.finish()
}

impl DiskPipelineCache {
    /// The cache for `device`, loaded from its file if there is one; None where the adapter has
    /// no pipeline cache or there is no cache directory.
    pub fn open(device: &wgpu::Device, info: &wgpu::AdapterInfo) -> Option<DiskPipelineCache> {
        if !device.features().contains(wgpu::Features::PIPELINE_CACHE) {
            return None;
        }
        let key = wgpu::util::pipeline_cache_key(info)?;
        let path = cache_dir()?.join(format!("{key}-{:016x}", shader_hash()));
        let data = std::fs::read(&path).ok();
        // SAFETY: the data is only what `PipelineCache::get_data` wrote for this adapter class
        // (the file name holds its key); wgpu validates the header and, with `fallback`, makes
        // an empty cache from anything it does not accept.
        let cache = unsafe {
            device.create_pipeline_cache(&wgpu::PipelineCacheDescriptor {
                label: Some("twister pipelines"),
                data: data.as_deref(),
                fallback: true,
            })
        };
        let loaded = data.as_deref().map_or(0, |d| fnv1a(d, FNV_OFFSET));
        Some(DiskPipelineCache { cache, path, used: AtomicBool::new(false), loaded })
    }

    /// The cache, for a pipeline about to be built with it.
    pub fn for_build(&self) -> &wgpu::PipelineCache {
        self.used.store(true, Ordering::Relaxed);
        &self.cache
    }

    /// Writes the cache to its file if pipelines were built with it and its data changed (a
    /// temporary file renamed into place, so that a concurrent reader sees a whole file), and
    /// removes the files of older builds for the same adapter class. Failures are ignored.
    pub fn save(&self) {
        if !self.used.swap(false, Ordering::Relaxed) {
            return;
        }
        let Some(data) = self.cache.get_data() else { return };
        if fnv1a(&data, FNV_OFFSET) == self.loaded && self.path.exists() {
            return;
        }
        let (Some(dir), Some(name)) = (self.path.parent(), self.path.file_name()) else { return };
        if !write_whole(dir, &self.path, &data) {
            return;
        }
        let name = name.to_string_lossy();
        let Some((class, _)) = name.rsplit_once('-') else { return };
        for entry in std::fs::read_dir(dir).into_iter().flatten().flatten() {
            let other = entry.file_name().to_string_lossy().into_owned();
            if other != name && other.rsplit_once('-').is_some_and(|(c, _)| c == class) {
                let _ = std::fs::remove_file(entry.path());
            }
        }
    }
}
