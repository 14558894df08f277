//! Image-based lighting from the prepared environment, CPU twin of `shaders/shared/ibl.wgsl`:
//! the split sum's prefiltered levels, SH irradiance and lobe table (`core::shading::environment`).

use glam::{Vec2, Vec3};

use crate::core::shading::environment::{ENV_LEVELS, LUT_SIZE};
use crate::core::shading::texture::MaterialTable;

/// A viewer-frame direction in the environment's frame (`env_direction`).
pub fn env_direction(table: &MaterialTable, d: Vec3) -> Vec3 {
    let r = &table.lighting.env_rotation;
    Vec3::from_slice(&r[0][..3]) * d.x + Vec3::from_slice(&r[1][..3]) * d.y + Vec3::from_slice(&r[2][..3]) * d.z
}

/// Prefiltered level k, bilinear at equirectangular coordinates st in [0, 1]² (`env_level`).
pub fn env_level(table: &MaterialTable, k: usize, st: Vec2) -> Vec3 {
    let [offset, width, height, _] = table.lighting.env_levels[k];
    let p = st * Vec2::new(width as f32, height as f32) - 0.5;
    let base = p.floor();
    let f = p - base;
    let texel = |dx: i32, dy: i32| {
        let x = (base.x as i32 + dx).rem_euclid(width as i32) as u32;
        let y = (base.y as i32 + dy).clamp(0, height as i32 - 1) as u32;
        crate::core::shading::environment::rgb9e5_decode(table.environment[(offset + y * width + x) as usize])
    };
    let top = texel(0, 0).lerp(texel(1, 0), f.x);
    let bottom = texel(0, 1).lerp(texel(1, 1), f.x);
    top.lerp(bottom, f.y)
}

/// The equirectangular coordinates in [0, 1]² of environment-frame direction e (`env_st`).
pub fn env_st(e: Vec3) -> Vec2 {
    Vec2::new(e.x.atan2(-e.z) / std::f32::consts::TAU + 0.5, 0.5 - e.y.clamp(-1.0, 1.0).asin() / std::f32::consts::PI)
}

/// The radiance around viewer-frame direction d convolved for `roughness` (`env_radiance`).
pub fn env_radiance(table: &MaterialTable, d: Vec3, roughness: f32) -> Vec3 {
    let st = env_st(env_direction(table, d));
    let lod = roughness.clamp(0.0, 1.0) * (ENV_LEVELS - 1) as f32;
    let k = (lod as usize).min(ENV_LEVELS - 2);
    let t = lod - k as f32;
    env_level(table, k, st).lerp(env_level(table, k + 1, st), t)
}

/// E(n)/π at viewer-frame normal n (`env_irradiance`).
pub fn env_irradiance(table: &MaterialTable, n: Vec3) -> Vec3 {
    let sh = table.lighting.env_sh.map(|c| Vec3::from_slice(&c[..3]));
    crate::core::shading::environment::irradiance(&sh, env_direction(table, n))
}

/// The split-sum table (A, B) at n·v and roughness (`env_lut`).
pub fn env_lut(table: &MaterialTable, nv: f32, roughness: f32) -> Vec2 {
    let n = LUT_SIZE as f32;
    let p = (Vec2::new(nv, roughness) * n - 0.5).clamp(Vec2::ZERO, Vec2::splat(n - 1.0));
    let base = p.floor().min(Vec2::splat(n - 2.0));
    let f = p - base;
    let mut out = Vec2::ZERO;
    for corner in 0..4u32 {
        let (dx, dy) = (corner & 1, corner >> 1);
        let w = if dx == 1 { f.x } else { 1.0 - f.x } * if dy == 1 { f.y } else { 1.0 - f.y };
        let i = table.lighting.env_lut as usize
            + (base.y as usize + dy as usize) * LUT_SIZE
            + base.x as usize
            + dx as usize;
        out += w * crate::core::shading::environment::unpack_half2(table.environment[i]);
    }
    out
}

/// The environment's light reflected towards v by a surface with unit normal n (`ibl_radiance`).
pub fn ibl_radiance(table: &MaterialTable, n: Vec3, v: Vec3, base: Vec3, metallic: f32, roughness: f32) -> Vec3 {
    let nv = n.dot(v).clamp(1e-4, 1.0);
    let ab = env_lut(table, nv, roughness);
    let f0 = Vec3::splat(0.04).lerp(base, metallic);
    let e_ss = f0 * ab.x + ab.y;
    let e_ms = 1.0 - (ab.x + ab.y);
    let f_avg = f0 + (1.0 - f0) / 21.0;
    let f_ms = e_ss * f_avg / (1.0 - e_ms * f_avg);
    let irradiance = env_irradiance(table, n);
    let specular = env_radiance(table, 2.0 * nv * n - v, roughness) * e_ss + irradiance * f_ms * e_ms;
    let c_diff = base.lerp(Vec3::ZERO, metallic);
    specular + c_diff * irradiance * (Vec3::ONE - e_ss - f_ms * e_ms).max(Vec3::ZERO)
}
