//! The prepared environment cached on disk (issue 17): preparing the split sum of a 1k map takes
//! about half a second on two cores (and every glTF render prepares the neutral studio), so the
//! result is kept under a key of what it depends on — the radiance itself and the preparation's
//! parameters — and read back instead of prepared again.
//!
//! Where: the folder of `core::caches::disk_cache` (`TWISTER_CACHE_DIR`, empty or `off` turns it off). A
//! file is written whole (`disk_cache::write_whole`), so a reader never sees half of one; one
//! that does not read back
//! exactly (wrong magic, size or checksum: truncated, corrupt, another version) is prepared
//! again and replaced. The cache is an optimisation: failing to read or write it is silent.

use std::path::{Path, PathBuf};

use glam::Vec3;

use crate::core::caches::disk_cache::{cache_dir, fnv1a, write_whole, FNV_OFFSET};
use crate::core::shading::environment::{
    Environment, PreparedEnvironment, ENV_LEVELS, LUT_SAMPLES, LUT_SIZE, MAX_ENV_WIDTH, PREFILTER_SAMPLES,
};

const MAGIC: &[u8; 8] = b"TWENVC01";
/// The largest cache file read (a prepared 2048-wide map is about 12 MiB).
const MAX_FILE_BYTES: u64 = 64 << 20;

/// The key of an environment's preparation: its size and radiance, and the preparation's
/// parameters (a change to them makes new keys).
fn key(env: &Environment) -> u64 {
    let params =
        [ENV_LEVELS as u32, LUT_SIZE as u32, PREFILTER_SAMPLES, LUT_SAMPLES, MAX_ENV_WIDTH, env.width, env.height];
    let hash = fnv1a(bytemuck::cast_slice(&params), FNV_OFFSET);
    fnv1a(bytemuck::cast_slice(&env.radiance), hash)
}

/// The file of `env`'s preparation in `dir`.
pub fn cache_file(dir: &Path, env: &Environment) -> PathBuf {
    dir.join(format!("environment-{:016x}.bin", key(env)))
}

/// The bytes of a cache file: magic, levels, table offset, irradiance, texel count, texels,
/// then the FNV-1a checksum of all before it.
fn encode(p: &PreparedEnvironment) -> Vec<u8> {
    let mut out = MAGIC.to_vec();
    for level in p.levels {
        out.extend(level.iter().flat_map(|v| v.to_le_bytes()));
    }
    out.extend(p.lut_offset.to_le_bytes());
    out.extend(p.sh.iter().flat_map(|c| c.to_array()).flat_map(f32::to_le_bytes));
    out.extend((p.texels.len() as u64).to_le_bytes());
    out.extend(p.texels.iter().flat_map(|t| t.to_le_bytes()));
    let sum = fnv1a(&out, FNV_OFFSET);
    out.extend(sum.to_le_bytes());
    out
}

/// A cache file's preparation (named `name`, not shown as the background), or None unless it
/// reads back exactly.
fn decode(bytes: &[u8], name: &str) -> Option<PreparedEnvironment> {
    let (body, sum) = bytes.split_at_checked(bytes.len().checked_sub(8)?)?;
    if body.get(..8)? != MAGIC || fnv1a(body, FNV_OFFSET) != u64::from_le_bytes(sum.try_into().ok()?) {
        return None;
    }
    let mut words = body[8..].chunks_exact(4).map(|c| u32::from_le_bytes(c.try_into().expect("4 bytes")));
    let mut next = || words.next();
    let mut levels = [[0u32; 3]; ENV_LEVELS];
    for level in &mut levels {
        *level = [next()?, next()?, next()?];
    }
    let lut_offset = next()?;
    let mut sh = [Vec3::ZERO; 9];
    for c in &mut sh {
        *c = Vec3::new(f32::from_bits(next()?), f32::from_bits(next()?), f32::from_bits(next()?));
    }
    let count = next()? as u64 | (next()? as u64) << 32;
    let texels: Vec<u32> = std::iter::from_fn(next).collect();
    (texels.len() as u64 == count).then(|| PreparedEnvironment {
        name: name.to_string(),
        texels,
        levels,
        lut_offset,
        sh,
        background: false,
    })
}

impl Environment {
    /// The preparation ([`Environment::prepare`]) read from the cache in `dir` if it holds it,
    /// else prepared and written there (None: no cache).
    pub fn prepare_cached_in(&self, dir: Option<&Path>) -> PreparedEnvironment {
        let Some(dir) = dir else { return self.prepare() };
        let file = cache_file(dir, self);
        let cached = std::fs::metadata(&file)
            .ok()
            .filter(|m| m.len() <= MAX_FILE_BYTES)
            .and_then(|_| std::fs::read(&file).ok())
            .and_then(|bytes| decode(&bytes, &self.name));
        if let Some(prepared) = cached {
            return prepared;
        }
        let prepared = self.prepare();
        write_whole(dir, &file, &encode(&prepared));
        prepared
    }

    /// The same with the cache folder of [`cache_dir`].
    pub fn prepare_cached(&self) -> PreparedEnvironment {
        self.prepare_cached_in(cache_dir().as_deref())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_preparation_reads_back_exactly_and_a_damaged_file_does_not() {
        let env = Environment::uniform(Vec3::new(0.2, 0.5, 0.9));
        let p = env.prepare();
        let bytes = encode(&p);
        assert_eq!(decode(&bytes, &env.name).unwrap(), p);
        for cut in [0, 7, 8, 100, bytes.len() - 1] {
            assert!(decode(&bytes[..cut], &env.name).is_none(), "cut at {cut}");
        }
        for flip in [0, 9, 200, bytes.len() - 9, bytes.len() - 1] {
            let mut damaged = bytes.clone();
            damaged[flip] ^= 0x10;
            assert!(decode(&damaged, &env.name).is_none(), "byte {flip} flipped");
        }
        // Another radiance, another key.
        let other = Environment::uniform(Vec3::new(0.2, 0.5, 0.91));
        assert_ne!(key(&env), key(&other));
    }
}
