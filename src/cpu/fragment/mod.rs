//! CPU twin of `shaders/shared/surface.wgsl` and `fragment.wgsl`, the fragment work shared by the
//! drawing stages and the ray tracer: the surface colour (material: base colour texture with its
//! sampler, alpha mask / screen-door blend, single-sided culling), headlight shading in linear
//! light with an sRGB-encoded output, the glTF look's shading. Its modules mirror the WGSL
//! modules of the same names: [`texture`], [`brdf`], [`ibl`], [`pixel_error`].

pub mod brdf;
pub mod ibl;
pub mod pixel_error;
pub mod texture;

pub use brdf::{brdf, light_at};
pub use ibl::{env_direction, env_irradiance, env_level, env_lut, env_radiance, env_st, ibl_radiance};
pub use pixel_error::{pixel_distance, pixel_error, pixel_spread};
#[cfg(test)]
use texture::texel;
pub use texture::{sample_levels, sample_texture, wrap_index};

use glam::{Vec2, Vec3, Vec4};

pub use crate::core::panoramas::projection::pixel_ray;
use crate::core::panoramas::projection::{Eye, Projection};
pub use crate::core::shading::color::display_bytes;
use crate::core::shading::light::{tonemap, GpuLight, NO_SHADOW_MAP};
use crate::core::shading::material::{AlphaMode, NO_TEXTURE};
use crate::core::shading::shadow::{
    cube_face, shadow_coordinates, LIGHT_OFFSET_TEXELS, NORMAL_OFFSET_TEXELS, SHADOW_CUBE, SHADOW_ORTHOGRAPHIC,
};
use crate::core::shading::texture::MaterialTable;

/// Linear colour × (ambient + (1 − ambient)·|n·l|), the light at the viewer, two-sided; as
/// sRGB-encoded RGBA8 (the colour target holds display values).
pub fn shade(ambient: f32, view_position: Vec3, normal: Vec3, color: Vec4) -> [u8; 4] {
    display_bytes(shade_linear(ambient, view_position, normal, color))
}

/// The same in linear light, each channel clamped to [0, 1] (`shade` in surface.wgsl).
pub fn shade_linear(ambient: f32, view_position: Vec3, normal: Vec3, color: Vec4) -> Vec3 {
    let lambert = if normal.length() > 1e-6 { normal.normalize().dot(-view_position.normalize()).abs() } else { 1.0 };
    let s = ambient + (1.0 - ambient) * lambert;
    (color.truncate() * s).clamp(Vec3::ZERO, Vec3::ONE)
}

/// A surface's shaded colour as display bytes (`shade_surface` in surface.wgsl): with the
/// table's lighting the glTF BRDF under its lights, seen from the eye's own point for the pixel
/// (its ray's origin), plus ambient × diffuse colour and emission, tone mapped; else the
/// headlight ([`shade`]).
#[allow(clippy::too_many_arguments)]
pub fn shade_surface(
    table: &MaterialTable,
    ambient: f32,
    projection: &Projection,
    eye: Eye,
    view_position: Vec3,
    normal: Vec3,
    color: Vec4,
    surface: &Surface,
    dp_dx: Vec3,
    dp_dy: Vec3,
) -> [u8; 4] {
    let (material, frag_xy) = (surface.material, surface.frag_xy);
    if table.lighting.pbr == 0 {
        return shade(ambient, view_position, normal, color);
    }
    let (origin, _) = pixel_ray(projection, eye, frag_xy);
    let (duv_dx, duv_dy) = (surface.duv_dx, surface.duv_dy);
    let maps =
        surface_maps(table, material, surface.uv, duv_dx, duv_dy, [dp_dx, dp_dy], [duv_dx, duv_dy], surface.tangent);
    let v = (origin - view_position).normalize();
    let c = pbr_radiance(table, ambient, v, view_position, normal, color, &maps, 0);
    display_bytes(tonemap(c, &table.lighting))
}

/// Whether the frame's background shows the environment (one the user gave, lit by the BRDF).
pub fn shows_environment(table: &MaterialTable) -> bool {
    let l = &table.lighting;
    l.pbr != 0 && l.environment != 0 && l.env_background != 0
}

/// The background at a pixel: the environment along the pixel's own ray, tone mapped
/// (`fs_background` in fragment.wgsl).
pub fn background_color(table: &MaterialTable, projection: &Projection, eye: Eye, frag_xy: Vec2) -> [u8; 4] {
    let (_, dir) = pixel_ray(projection, eye, frag_xy);
    display_bytes(tonemap(env_level(table, 0, env_st(env_direction(table, dir))), &table.lighting))
}

/// The glTF BRDF's linear colour, before tone mapping, of surface point `view_position` seen
/// along unit `v` (towards the eye): the table's lights, ambient × diffuse colour, emission
/// (`pbr_radiance` in surface.wgsl).
#[allow(clippy::too_many_arguments)]
pub fn pbr_radiance(
    table: &MaterialTable,
    ambient: f32,
    v: Vec3,
    view_position: Vec3,
    normal: Vec3,
    color: Vec4,
    maps: &SurfaceMaps,
    first_light: usize,
) -> Vec3 {
    let n = shading_normal(normal, v, maps);
    let base = color.truncate().max(Vec3::ZERO);
    let mut c = maps.emissive;
    if table.lighting.environment != 0 {
        c += maps.occlusion * ibl_radiance(table, n, v, base, maps.metallic, maps.roughness);
    } else {
        c += maps.occlusion * ambient * base.lerp(Vec3::ZERO, maps.metallic);
    }
    for light in table.lights[..table.lighting.count as usize].iter().skip(first_light) {
        let mut term = light_term(light, n, v, view_position, base, maps);
        // The drawing pipelines compile the look-up in where the frame has maps (`SHADOW_MAPS`).
        if !table.shadow_maps.is_empty() && light.shadow_map != NO_SHADOW_MAP && term.cmpgt(Vec3::ZERO).any() {
            let (l, _) = light_at(light, view_position);
            term *= shadow_visibility(table, light.shadow_map, view_position, normal, l);
        }
        c += term;
    }
    c
}

/// The share of a light reaching p by its shadow map (`shadow_visibility` in surface.wgsl; the
/// offsets and the filter in `core::shading::shadow`).
pub fn shadow_visibility(table: &MaterialTable, first_map: u32, p: Vec3, normal: Vec3, l: Vec3) -> f32 {
    let mut map = first_map;
    if table.shadow_maps[map as usize].projection == SHADOW_CUBE {
        map += cube_face(l);
    }
    let m = &table.shadow_maps[map as usize];
    let q0 = m.matrix() * p.extend(1.0);
    if q0.w <= 0.0 {
        return 1.0;
    }
    let t = m.texel * if m.projection == SHADOW_ORTHOGRAPHIC { 1.0 } else { q0.w };
    let n = if normal.dot(normal) > 1e-12 { normal.normalize() } else { Vec3::ZERO };
    let n = if n.dot(l) >= 0.0 { n } else { -n };
    let Some((x, y, z)) = shadow_coordinates(m, p + (NORMAL_OFFSET_TEXELS * n + LIGHT_OFFSET_TEXELS * l) * t) else {
        return 1.0;
    };
    let (sx, sy, size) = (x - 0.5, y - 0.5, m.size as f32);
    if !(z < 1.0) || sx < -1.0 || sy < -1.0 || sx > size || sy > size {
        return 1.0;
    }
    let (cx, cy) = (sx.floor(), sy.floor());
    let (fx, fy) = (sx - cx, sy - cy);
    let lit = [0, 1, 2, 3].map(|k| {
        let tx = (cx as i32 + (k & 1)).clamp(0, m.size as i32 - 1) as u32;
        let ty = (cy as i32 + (k >> 1)).clamp(0, m.size as i32 - 1) as u32;
        if z <= table.shadow_depths[(m.offset + ty * m.size + tx) as usize] {
            1.0
        } else {
            0.0
        }
    });
    let mix = |a: f32, b: f32, t: f32| a + (b - a) * t;
    mix(mix(lit[0], lit[1], fx), mix(lit[2], lit[3], fx), fy)
}

/// What a light adds at view_position (unit normal n facing v): the BRDF × its colour × its
/// falloff × n·l (`light_term` in surface.wgsl).
pub fn light_term(light: &GpuLight, n: Vec3, v: Vec3, view_position: Vec3, base: Vec3, maps: &SurfaceMaps) -> Vec3 {
    let (l, scale) = light_at(light, view_position);
    let nl = n.dot(l);
    if nl > 0.0 && scale > 0.0 {
        brdf(n, v, l, base, maps.metallic, maps.roughness) * Vec3::from(light.color) * (scale * nl)
    } else {
        Vec3::ZERO
    }
}

/// The unit normal the BRDF shades with (`shading_normal`): the given one (v where there is
/// none), turned to the side the eye sees, perturbed by the normal map.
pub fn shading_normal(normal: Vec3, v: Vec3, maps: &SurfaceMaps) -> Vec3 {
    let n = if normal.length_squared() < 1e-12 { v } else { normal.normalize() };
    let side = if n.dot(v) >= 0.0 { 1.0 } else { -1.0 };
    if maps.tangent.w != 0.0 && maps.normal.z < 1.0 {
        // The file's frame: bitangent (n × t)·sign(w); from the back the whole normal turns.
        let t = maps.tangent.truncate() - n * n.dot(maps.tangent.truncate());
        if t.dot(t) > 1e-12 {
            let tu = t.normalize();
            let b = n.cross(tu) * if maps.tangent.w >= 0.0 { 1.0 } else { -1.0 };
            return side * (tu * maps.normal.x + b * maps.normal.y + n * maps.normal.z).normalize();
        }
    }
    mapped_normal(side * n, maps)
}

/// A surface's BRDF inputs with its material's texture maps applied (`SurfaceMaps` in
/// surface.wgsl): metallic, roughness, occlusion, emission, the normal map's tangent-space
/// normal ((0, 0, 1) without one), and two in-plane position differentials with their
/// texture-coordinate differences (the tangent frame).
#[derive(Clone, Copy, Debug)]
pub struct SurfaceMaps {
    pub metallic: f32,
    pub roughness: f32,
    pub occlusion: f32,
    pub emissive: Vec3,
    pub normal: Vec3,
    pub dp: [Vec3; 2],
    pub duv: [Vec2; 2],
    /// The file's tangent (viewer frame, sign w), zero where none.
    pub tangent: Vec4,
}

/// The maps sampled at uv with the sampling derivatives duv_dx, duv_dy (`surface_maps`).
#[allow(clippy::too_many_arguments)]
pub fn surface_maps(
    table: &MaterialTable,
    material: u32,
    uv: Vec2,
    duv_dx: Vec2,
    duv_dy: Vec2,
    dp: [Vec3; 2],
    duv: [Vec2; 2],
    tangent: Vec4,
) -> SurfaceMaps {
    let m = &table.materials[(material as usize).min(table.materials.len() - 1)];
    let mut s = SurfaceMaps {
        metallic: m.metallic,
        roughness: m.roughness,
        occlusion: 1.0,
        emissive: Vec3::new(m.emissive_r, m.emissive_g, m.emissive_b),
        normal: Vec3::Z,
        dp,
        duv,
        tangent,
    };
    let maps = [
        (m.mr_first_mip, m.mr_mip_count),
        (m.normal_first_mip, m.normal_mip_count),
        (m.occlusion_first_mip, m.occlusion_mip_count),
        (m.emissive_first_mip, m.emissive_mip_count),
    ];
    for (j, (first, count)) in maps.into_iter().enumerate() {
        if count == 0 {
            continue;
        }
        let t = sample_levels(table, m, first, count, uv, duv_dx, duv_dy);
        match j {
            0 => {
                s.roughness *= t.y;
                s.metallic *= t.z;
            }
            1 => {
                let xy = (Vec2::new(t.x, t.y) * 2.0 - 1.0) * m.normal_scale;
                s.normal = Vec3::new(xy.x, xy.y, t.z * 2.0 - 1.0).normalize();
            }
            2 => s.occlusion = 1.0 + m.occlusion_strength * (t.x - 1.0),
            _ => s.emissive *= t.truncate(),
        }
    }
    s
}

/// The unit normal n perturbed by the normal map (`mapped_normal`): T = ∇u, B = ∇v in the
/// surface's plane (Schüler's cotangent frame, orientation taken out), the map's +y against v.
pub fn mapped_normal(n: Vec3, s: &SurfaceMaps) -> Vec3 {
    if s.normal.z >= 1.0 {
        return n;
    }
    let dp1perp = n.cross(s.dp[0]);
    let dp2perp = s.dp[1].cross(n);
    let orientation = if n.dot(s.dp[0].cross(s.dp[1])) >= 0.0 { 1.0 } else { -1.0 };
    let t = (dp2perp * s.duv[0].x + dp1perp * s.duv[1].x) * orientation;
    let b = (dp2perp * s.duv[0].y + dp1perp * s.duv[1].y) * orientation;
    let scale2 = t.length_squared().max(b.length_squared());
    if !(scale2 > 1e-30) {
        return n;
    }
    let k = 1.0 / scale2.sqrt();
    (t * (k * s.normal.x) - b * (k * s.normal.y) + n * s.normal.z).normalize()
}

// ---- Image-based lighting (`core::shading::environment`; surface.wgsl's twins) ----

/// Screen-door threshold of a pixel for BLEND materials (`blend_threshold` in surface.wgsl): a
/// 4×4 ordered-dither (Bayer) matrix, shifted by a point's offset from the pixel's centre along x
/// (a traced sample's), so that the standard sample positions of one pixel get thresholds evenly
/// spaced over 0..1.
pub fn blend_threshold(frag_xy: Vec2) -> f32 {
    const BAYER: [f32; 16] = [0.0, 8.0, 2.0, 10.0, 12.0, 4.0, 14.0, 6.0, 3.0, 11.0, 1.0, 9.0, 15.0, 7.0, 13.0, 5.0];
    let (x, y) = (frag_xy.x as u32 % 4, frag_xy.y as u32 % 4);
    let t = (BAYER[(4 * y + x) as usize] + 0.5) / 16.0 + 0.5 + frag_xy.x.fract() - 1.0;
    t - t.floor()
}

/// How much a MASK material's alpha changes over one pixel (`mask_alpha_width` in surface.wgsl):
/// |a·α(uv + ∂uv/∂x) − alpha| + |a·α(uv + ∂uv/∂y) − alpha| of its texture α, a the vertex alpha,
/// `alpha` the fragment's (a·α(uv)); 0 for other materials.
pub fn mask_alpha_width(table: &MaterialTable, s: &Surface, alpha: f32) -> f32 {
    let m = &table.materials[(s.material as usize).min(table.materials.len() - 1)];
    if m.alpha_mode != AlphaMode::Mask as u32 || m.texture == NO_TEXTURE || m.mip_count == 0 {
        return 0.0;
    }
    let at = |uv: Vec2| s.color.w * sample_texture(table, m, uv, s.duv_dx, s.duv_dy).w;
    (at(s.uv + s.duv_dx) - alpha).abs() + (at(s.uv + s.duv_dy) - alpha).abs()
}

/// Alpha to coverage (`coverage_mask` in surface.wgsl): which of its pixel's `n` samples (n > 1)
/// a fragment of `alpha` covers, `alpha_width` the change of alpha over a pixel. Opaque: all;
/// a face culled: none; MASK: the alpha sharpened about its cutoff, clamp((alpha − cutoff) /
/// alpha_width + 1/2, 0, 1); BLEND: alpha. k = ⌊share·n + threshold⌋ consecutive samples from
/// the one the pixel's threshold picks.
pub fn coverage_mask(table: &MaterialTable, material: u32, alpha: f32, alpha_width: f32, frag_xy: Vec2, n: u32) -> u32 {
    let all = u32::MAX >> (32 - n);
    if alpha < 0.0 {
        return 0;
    }
    let m = &table.materials[(material as usize).min(table.materials.len() - 1)];
    let share = if m.alpha_mode == AlphaMode::Mask as u32 {
        ((alpha - m.alpha_cutoff) / alpha_width.max(1e-4) + 0.5).clamp(0.0, 1.0)
    } else if m.alpha_mode == AlphaMode::Blend as u32 {
        alpha.clamp(0.0, 1.0)
    } else {
        return all;
    };
    let threshold = blend_threshold(frag_xy);
    let k = ((share * n as f32 + threshold).floor() as u32).min(n);
    let run = if k == 0 { 0 } else { u32::MAX >> (32 - k) };
    let start = (threshold * 16.0) as u32 % n;
    ((run << start) | (run >> ((n - start) % n))) & all
}

/// A surface fragment before shading.
#[derive(Clone, Copy, Debug)]
pub struct Surface {
    pub material: u32,
    /// Interpolated vertex colour (base colour factor × vertex colour), linear.
    pub color: Vec4,
    pub uv: Vec2,
    pub duv_dx: Vec2,
    pub duv_dy: Vec2,
    pub frag_xy: Vec2,
    pub front_facing: bool,
    /// glTF's tangent (viewer frame xyz, bitangent sign w), zero where none.
    pub tangent: Vec4,
}

/// The linear surface colour of a fragment, or None where it is discarded (a single-sided face
/// seen from behind, alpha below the MASK cutoff, a BLEND fragment the screen door leaves out).
pub fn surface_color(table: &MaterialTable, s: &Surface) -> Option<Vec4> {
    let c = surface_rgba(table, s)?;
    let m = &table.materials[(s.material as usize).min(table.materials.len() - 1)];
    if (m.alpha_mode == AlphaMode::Mask as u32 && c.w < m.alpha_cutoff)
        || (m.alpha_mode == AlphaMode::Blend as u32 && c.w <= blend_threshold(s.frag_xy))
    {
        return None;
    }
    Some(c)
}

/// The linear surface colour of a fragment before its alpha test (`surface_rgba` in
/// surface.wgsl); None for a single-sided face seen from behind.
pub fn surface_rgba(table: &MaterialTable, s: &Surface) -> Option<Vec4> {
    let m = &table.materials[(s.material as usize).min(table.materials.len() - 1)];
    if m.double_sided == 0 && !s.front_facing {
        return None;
    }
    let mut c = s.color;
    if m.texture != NO_TEXTURE && m.mip_count > 0 {
        c *= sample_texture(table, m, s.uv, s.duv_dx, s.duv_dy);
    }
    Some(c)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::core::shading::color::{linear_to_srgb, srgb_to_linear};
    use crate::core::shading::material::{Filter, Material, Mipmap, Wrap};
    use crate::core::shading::texture::Texture;

    /// Alpha to coverage against the closed form: over a 4×4 block of pixels (every screen-door
    /// threshold once) a BLEND fragment of alpha a covers a·n·16 samples within one, each pixel
    /// within one sample of a·n; opaque covers all, a culled face none; a MASK fragment's share
    /// is its alpha's distance beyond the cutoff over its width, plus one half.
    #[test]
    fn coverage_masks_cover_the_share_alpha_gives() {
        let mut t = table(Material { alpha_mode: AlphaMode::Blend as u32, ..Default::default() });
        for n in [2u32, 4, 8, 16, 32] {
            let all = if n == 32 { u32::MAX } else { (1 << n) - 1 };
            for a in [0.0f32, 0.1, 0.3, 0.5, 0.77, 1.0] {
                let masks: Vec<u32> = (0..16)
                    .map(|i| coverage_mask(&t, 1, a, 0.0, Vec2::new((i % 4) as f32 + 0.5, (i / 4) as f32 + 0.5), n))
                    .collect();
                assert!(masks.iter().all(|m| m & !all == 0), "{n} {a}: {masks:?}");
                let total: u32 = masks.iter().map(|m| m.count_ones()).sum();
                assert!((total as f32 - a * n as f32 * 16.0).abs() <= 1.0, "{n} samples, alpha {a}: {total}");
                for m in &masks {
                    assert!((m.count_ones() as f32 - a * n as f32).abs() < 1.0, "{n} {a}: {m:b}");
                }
            }
            assert_eq!(coverage_mask(&t, 1, -1.0, 0.0, Vec2::splat(0.5), n), 0, "a culled face");
        }
        t.materials[1].alpha_mode = AlphaMode::Opaque as u32;
        assert_eq!(coverage_mask(&t, 1, 0.2, 0.0, Vec2::splat(0.5), 4), 0b1111);
        t.materials[1].alpha_mode = AlphaMode::Mask as u32;
        t.materials[1].alpha_cutoff = 0.5;
        // Share 0.5 + (0.55 − 0.5)/0.2 = 0.75 of 4 samples: 3 (or 4 where the threshold rounds up).
        let k = coverage_mask(&t, 1, 0.55, 0.2, Vec2::splat(0.5), 4).count_ones();
        assert!(k == 3 || k == 4, "{k}");
        assert_eq!(coverage_mask(&t, 1, 0.3, 0.05, Vec2::splat(0.5), 4), 0, "well below the cutoff");
    }

    #[test]
    fn srgb_round_trips_every_byte() {
        for b in 0..=255u8 {
            let c = linear_to_srgb(srgb_to_linear(b as f32 / 255.0));
            assert_eq!((c * 255.0 + 0.5).floor() as u8, b);
        }
    }

    #[test]
    fn wrap_modes_fold_indices_as_gl_does() {
        let fold = |mode: Wrap| (-5..9).map(|i| wrap_index(i, 3, mode as u32)).collect::<Vec<_>>();
        assert_eq!(fold(Wrap::Repeat), [1, 2, 0, 1, 2, 0, 1, 2, 0, 1, 2, 0, 1, 2]);
        assert_eq!(fold(Wrap::ClampToEdge), [0, 0, 0, 0, 0, 0, 1, 2, 2, 2, 2, 2, 2, 2]);
        assert_eq!(fold(Wrap::MirroredRepeat), [1, 2, 2, 1, 0, 0, 1, 2, 2, 1, 0, 0, 1, 2]);
    }

    fn table(material: Material) -> MaterialTable {
        // 4×4 texture: texel (x, y) has red 60·x, green 60·y (sRGB bytes).
        let rgba = (0..16).flat_map(|i| [60 * (i % 4) as u8, 60 * (i / 4) as u8, 0, 255]).collect();
        let t = Texture { name: "t".into(), width: 4, height: 4, rgba };
        MaterialTable::build(&[Material { texture: 0, ..material }], &[t], usize::MAX)
    }

    fn encoded(c: Vec4) -> [u8; 2] {
        [c.x, c.y].map(|x| (linear_to_srgb(x) * 255.0 + 0.5).floor() as u8)
    }

    #[test]
    fn nearest_and_linear_sampling_hit_the_texels_they_should() {
        let small = Vec2::splat(0.01); // magnification
        let nearest = Material { mag_filter: Filter::Nearest as u32, ..Default::default() };
        let t = table(nearest);
        let m = &t.materials[1];
        // The centre of texel (2, 1) and a point inside it.
        for uv in [Vec2::new(2.5 / 4.0, 1.5 / 4.0), Vec2::new(2.1 / 4.0, 1.9 / 4.0)] {
            assert_eq!(encoded(sample_texture(&t, m, uv, small, small)), [120, 60]);
        }
        // Repeat: u + 3 lands on the same texel.
        assert_eq!(encoded(sample_texture(&t, m, Vec2::new(3.0 + 2.5 / 4.0, 1.5 / 4.0), small, small)), [120, 60]);
        // Linear halfway between texel centres (1, 1) and (2, 1): the linear-light mean.
        let t = table(Material::default());
        let c = sample_texture(&t, &t.materials[1], Vec2::new(2.0 / 4.0, 1.5 / 4.0), small, small);
        let mean = (srgb_to_linear(60.0 / 255.0) + srgb_to_linear(120.0 / 255.0)) / 2.0;
        assert!((c.x - mean).abs() < 1e-6 && (c.y - srgb_to_linear(60.0 / 255.0)).abs() < 1e-6, "{c}");
        // Clamp at the edge: far left of the texture reads column 0.
        let clamp = Material { wrap_u: Wrap::ClampToEdge as u32, ..Default::default() };
        let t = table(clamp);
        assert_eq!(encoded(sample_texture(&t, &t.materials[1], Vec2::new(-7.0, 1.5 / 4.0), small, small)), [0, 60]);
    }

    #[test]
    fn minification_picks_the_mip_level_of_the_footprint() {
        let t = table(Material { mipmap: Mipmap::Nearest as u32, ..Default::default() });
        let m = &t.materials[1];
        let uv = Vec2::new(0.3, 0.6);
        // A footprint of 4 texels: λ = 2, the 1×1 level (mean of all texels).
        let c = sample_texture(&t, m, uv, Vec2::new(1.0, 0.0), Vec2::new(0.0, 1.0));
        let last = t.mips[(m.first_mip + 2) as usize];
        assert_eq!((last.width, last.height), (1, 1));
        assert_eq!(c, texel(&t, &last, 0, 0));
        // Without mipmaps the same footprint reads level 0.
        let t0 =
            table(Material { mipmap: Mipmap::None as u32, min_filter: Filter::Nearest as u32, ..Default::default() });
        let c0 = sample_texture(&t0, &t0.materials[1], uv, Vec2::new(1.0, 0.0), Vec2::ZERO);
        assert_eq!(encoded(c0), [60, 120]);
    }

    #[test]
    fn alpha_modes_and_facing_decide_what_is_drawn() {
        let surface = |material: u32, alpha: f32, front_facing: bool| Surface {
            material,
            color: Vec4::new(1.0, 1.0, 1.0, alpha),
            uv: Vec2::ZERO,
            duv_dx: Vec2::ZERO,
            duv_dy: Vec2::ZERO,
            frag_xy: Vec2::new(0.5, 0.5),
            front_facing,
            tangent: Vec4::ZERO,
        };
        let mut t = MaterialTable::build(
            &[
                Material { alpha_mode: AlphaMode::Mask as u32, alpha_cutoff: 0.4, ..Default::default() },
                Material { double_sided: 0, ..Default::default() },
                Material { alpha_mode: AlphaMode::Blend as u32, ..Default::default() },
            ],
            &[],
            0,
        );
        assert!(surface_color(&t, &surface(1, 0.41, true)).is_some());
        assert!(surface_color(&t, &surface(1, 0.39, true)).is_none());
        assert!(surface_color(&t, &surface(2, 1.0, true)).is_some());
        assert!(surface_color(&t, &surface(2, 1.0, false)).is_none());
        assert!(
            surface_color(&t, &surface(0, 0.0, false)).is_some(),
            "the default material is double-sided and opaque"
        );
        // Screen door: opacity a covers round(16·a) of every 4×4 block.
        for k in 0..=16 {
            let a = k as f32 / 16.0;
            let covered = (0..16)
                .filter(|i| {
                    surface_color(
                        &t,
                        &Surface {
                            frag_xy: Vec2::new((i % 4) as f32 + 0.5, (i / 4) as f32 + 0.5),
                            ..surface(3, a, true)
                        },
                    )
                    .is_some()
                })
                .count();
            assert_eq!(covered, k, "opacity {a}");
        }
        t.materials.truncate(1);
        assert!(surface_color(&t, &surface(9, 1.0, true)).is_some(), "an id past the table uses the last entry");
    }
}
