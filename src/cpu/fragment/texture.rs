//! Texture sampling from the packed texel table, CPU twin of `shaders/shared/texture.wgsl`: every
//! wrap, filter and mipmap mode per texture, the level from the screen derivatives of the
//! texture coordinates, texels decoded from sRGB before filtering.

use glam::{Vec2, Vec4};

use crate::core::shading::color::srgb_to_linear;
use crate::core::shading::material::{Filter, Material, MipLevel, Mipmap, Wrap};
use crate::core::shading::texture::MaterialTable;

/// Texel index `i` folded into `0..n` by a wrap mode.
pub fn wrap_index(i: i32, n: i32, mode: u32) -> i32 {
    if mode == Wrap::ClampToEdge as u32 {
        i.clamp(0, n - 1)
    } else if mode == Wrap::MirroredRepeat as u32 {
        let m = i.rem_euclid(2 * n);
        if m >= n {
            2 * n - 1 - m
        } else {
            m
        }
    } else {
        i.rem_euclid(n)
    }
}

/// The linear-light RGBA of texel (x, y) of a level.
pub(super) fn texel(table: &MaterialTable, level: &MipLevel, x: i32, y: i32) -> Vec4 {
    let t = table.texels[(level.offset + y as u32 * level.width + x as u32) as usize].to_le_bytes();
    let c = t.map(|b| b as f32 / 255.0);
    Vec4::new(srgb_to_linear(c[0]), srgb_to_linear(c[1]), srgb_to_linear(c[2]), c[3])
}

/// Samples one mip level at `uv` (texture space: 0..1 across the image, v down) with a filter.
fn sample_level(table: &MaterialTable, m: &Material, first_mip: u32, level: u32, uv: Vec2, filter: u32) -> Vec4 {
    let level = &table.mips[(first_mip + level) as usize];
    let (w, h) = (level.width as i32, level.height as i32);
    let p = uv.clamp(Vec2::splat(-1e6), Vec2::splat(1e6)) * Vec2::new(w as f32, h as f32);
    // Nearest: the texel containing p. Linear: the four texels around p, weights by distance.
    let (base, f) = if filter == Filter::Linear as u32 {
        let q = p - 0.5;
        (q.floor(), q - q.floor())
    } else {
        (p.floor(), Vec2::ZERO)
    };
    let mut sum = Vec4::ZERO;
    for corner in 0..4i32 {
        let (dx, dy) = (corner & 1, corner >> 1);
        let weight = (if dx == 1 { f.x } else { 1.0 - f.x }) * (if dy == 1 { f.y } else { 1.0 - f.y });
        let x = wrap_index(base.x as i32 + dx, w, m.wrap_u);
        let y = wrap_index(base.y as i32 + dy, h, m.wrap_v);
        sum += weight * texel(table, level, x, y);
    }
    sum
}

/// Samples a material's base colour texture at `uv` with the screen-space derivatives of uv,
/// anisotropically (EXT_texture_filter_anisotropic's reference): P_max and P_min the longer and
/// shorter footprint axis in level-0 texels, N = min(⌈P_max / P_min⌉, `lighting.anisotropy`)
/// probes spaced evenly along the longer axis, each at level of detail λ = log2(P_max / N) (one
/// probe: isotropic, the longest axis); λ ≤ 0 magnifies (magnification filter, level 0), else the
/// minification filter on level 0 (no mipmaps), the nearest level, or a blend of the two nearest.
pub fn sample_texture(table: &MaterialTable, m: &Material, uv: Vec2, duv_dx: Vec2, duv_dy: Vec2) -> Vec4 {
    sample_levels(table, m, m.first_mip, m.mip_count, uv, duv_dx, duv_dy)
}

/// The number of probes along the footprint's longer axis (1 ..= `anisotropy`).
pub fn anisotropic_probes(anisotropy: u32, p_max: f32, p_min: f32) -> u32 {
    if anisotropy <= 1 || !(p_max > p_min) {
        return 1;
    }
    (p_max / p_min.max(p_max / 16.0)).ceil().clamp(1.0, anisotropy as f32) as u32
}

/// The same for the texture whose mip chain starts at `first_mip` (a material's maps), with the
/// material's sampler (`sample_levels`).
pub fn sample_levels(
    table: &MaterialTable,
    m: &Material,
    first_mip: u32,
    mip_count: u32,
    uv: Vec2,
    duv_dx: Vec2,
    duv_dy: Vec2,
) -> Vec4 {
    let top = &table.mips[first_mip as usize];
    let size = Vec2::new(top.width as f32, top.height as f32);
    let (px, py) = ((duv_dx * size).length(), (duv_dy * size).length());
    let p_max = px.max(py);
    let probes = anisotropic_probes(table.lighting.anisotropy, p_max, px.min(py));
    let axis = if px >= py { duv_dx } else { duv_dy };
    let lambda = (p_max / probes as f32).log2();
    let last = (mip_count - 1) as f32;
    // (first level, second level, weight of the second, filter)
    let (l0, l1, t, filter) = if !(lambda > 0.0) {
        (0.0, 0.0, 0.0, m.mag_filter)
    } else if m.mipmap == Mipmap::None as u32 {
        (0.0, 0.0, 0.0, m.min_filter)
    } else if m.mipmap == Mipmap::Nearest as u32 {
        let l = (lambda.min(last) + 0.5).floor();
        (l, l, 0.0, m.min_filter)
    } else {
        let l = lambda.min(last);
        (l.floor(), (l.floor() + 1.0).min(last), l - l.floor(), m.min_filter)
    };
    let mut out = Vec4::ZERO;
    for probe in 0..probes {
        let at = if probes > 1 { uv + axis * ((probe as f32 + 0.5) / probes as f32 - 0.5) } else { uv };
        for (k, level) in [l0, l1].into_iter().enumerate() {
            let weight = if k == 0 { 1.0 - t } else { t };
            if weight > 0.0 {
                out += weight * sample_level(table, m, first_mip, level as u32, at, filter);
            }
        }
    }
    out / probes as f32
}
