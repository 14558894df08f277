//! CPU twin of `shaders/shared/fragment.wgsl`, the fragment work shared by the drawing stages: the
//! surface colour (material: base colour texture with its sampler, alpha mask / screen-door
//! blend, single-sided culling), headlight shading in linear light with an sRGB-encoded output,
//! and the display-position error (seed 002 §4.1): the distance in pixels between the pixel
//! centre where a surface point was drawn and where the projection puts it.

use glam::{Vec2, Vec3, Vec4};

pub use crate::core::color::display_bytes;
use crate::core::color::srgb_to_linear;
use crate::core::environment::{ENV_LEVELS, LUT_SIZE};
use crate::core::light::{tonemap, GpuLight, LightKind, NO_SHADOW_MAP};
use crate::core::material::{AlphaMode, Filter, Material, MipLevel, Mipmap, Wrap, NO_TEXTURE};
pub use crate::core::projection::pixel_ray;
use crate::core::projection::{Eye, PanoramaKind, Projection};
use crate::core::shadow::{
    cube_face, shadow_coordinates, LIGHT_OFFSET_TEXELS, NORMAL_OFFSET_TEXELS, SHADOW_CUBE, SHADOW_ORTHOGRAPHIC,
};
use crate::core::texture::MaterialTable;

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

/// The glTF 2.0 BRDF (`brdf` in surface.wgsl; specification Appendix B): Lambert diffuse of
/// c_diff = base·(1 − metallic) weighted by 1 − F, plus GGX D · Smith separable Vis · F, with
/// α = roughness² and Fresnel–Schlick from f0 = mix(0.04, base, metallic). `n`, `v`, `l` unit.
pub fn brdf(n: Vec3, v: Vec3, l: Vec3, base: Vec3, metallic: f32, roughness: f32) -> Vec3 {
    let h = (l + v).normalize();
    let nl = n.dot(l).max(0.0);
    let nv = n.dot(v).abs().max(1e-4);
    let nh = n.dot(h).max(0.0);
    let vh = v.dot(h).abs();
    let alpha = (roughness * roughness).max(1e-3);
    let a2 = alpha * alpha;
    let f0 = Vec3::splat(0.04).lerp(base, metallic);
    let fresnel = f0 + (Vec3::ONE - f0) * (1.0 - vh).powf(5.0);
    let k = nh * nh * (a2 - 1.0) + 1.0;
    let d = a2 / (std::f32::consts::PI * k * k);
    let g_l = 2.0 * nl / (nl + (a2 + (1.0 - a2) * nl * nl).sqrt());
    let g_v = 2.0 * nv / (nv + (a2 + (1.0 - a2) * nv * nv).sqrt());
    let vis = g_l * g_v / (4.0 * nl * nv).max(1e-8);
    let c_diff = base.lerp(Vec3::ZERO, metallic);
    (Vec3::ONE - fresnel) * c_diff / std::f32::consts::PI + fresnel * d * vis
}

/// The light arriving from `light` at `p` (viewer frame): the unit direction towards it and the
/// factor on its colour (`light_at` in surface.wgsl).
pub fn light_at(light: &GpuLight, p: Vec3) -> (Vec3, f32) {
    if light.kind == LightKind::Directional as u32 {
        return (-Vec3::from(light.direction), 1.0);
    }
    let to_light = Vec3::from(light.position) - p;
    let d2 = to_light.length_squared().max(1e-8);
    let l = to_light / d2.sqrt();
    let mut scale = 1.0 / d2;
    if light.range > 0.0 {
        let r = d2 * d2 / (light.range * light.range * light.range * light.range);
        let w = (1.0 - r).clamp(0.0, 1.0);
        scale *= w * w;
    }
    if light.kind == LightKind::Spot as u32 {
        let cd = Vec3::from(light.direction).dot(-l);
        let t = ((cd - light.outer_cos) / (light.inner_cos - light.outer_cos).max(1e-4)).clamp(0.0, 1.0);
        scale *= t * t;
    }
    (l, scale)
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
/// offsets and the filter in `core::shadow`).
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

// ---- Image-based lighting (`core::environment`; surface.wgsl's twins) ----

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
        crate::core::environment::rgb9e5_decode(table.environment[(offset + y * width + x) as usize])
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
    crate::core::environment::irradiance(&sh, env_direction(table, n))
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
        out += w * crate::core::environment::unpack_half2(table.environment[i]);
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

/// The angle a pixel spans, radians (`pixel_spread` in surface.wgsl): the larger of its width
/// (2π/W, on the sphere × cos latitude) and its height (on the cylinder 1/(pixels_per_v·R_T),
/// seen from the eyes about R_T away; on the sphere 1/pixels_per_v). A ray cone grows by this
/// much per metre.
pub fn pixel_spread(projection: &Projection, frag_xy: Vec2) -> f32 {
    let (_, v) = projection.pixel_to_screen(frag_xy.x - 0.5, frag_xy.y - 0.5);
    let across = std::f32::consts::TAU / projection.width as f32;
    match projection.panorama {
        PanoramaKind::Equirect => (across * v.cos()).max(1.0 / projection.pixels_per_v()),
        PanoramaKind::Cylinder => across.max(1.0 / (projection.pixels_per_v() * projection.screen_radius)),
    }
}

/// The display-position error of surface point `p` drawn at pixel centre `frag_xy`: the
/// distance in pixels to where the projection puts it (wrapping around the panorama), or with
/// `angle` the angle between the two directions seen from the centre, in arcminutes; −1 where
/// no eye sees the point.
pub fn pixel_error(projection: &Projection, eye: Eye, p: Vec3, frag_xy: Vec2, angle: bool) -> f32 {
    match projection.project(p, eye) {
        None => -1.0,
        Some(q) if angle => {
            let a = projection.screen_direction(q.u, q.v);
            let (u, v) = projection.pixel_to_screen(frag_xy.x - 0.5, frag_xy.y - 0.5);
            let b = projection.screen_direction(u, v);
            a.cross(b).length().atan2(a.dot(b)).to_degrees() * 60.0
        }
        Some(q) => {
            let [x, y] = projection.to_pixel(q.u, q.v);
            Vec2::new(projection.wrapped_dx(x, frag_xy.x), y - frag_xy.y).length()
        }
    }
}

/// What `--depth` writes: the distance in metres along the ray of the pixel at `frag_xy` to the
/// plane through surface point `p` with normal `n` (the drawn triangle's plane: exact for flat
/// input triangles, however coarse the subdivision), or |p − eye point| where the ray runs
/// nearly within the plane.
pub fn pixel_distance(projection: &Projection, eye: Eye, p: Vec3, n: Vec3, frag_xy: Vec2) -> f32 {
    let (origin, dir) = pixel_ray(projection, eye, frag_xy);
    let denom = dir.dot(n);
    if denom.abs() > 1e-3 * n.length() {
        let t = (p - origin).dot(n) / denom;
        if t > 0.0 {
            return t;
        }
    }
    (p - origin).length()
}

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
fn texel(table: &MaterialTable, level: &MipLevel, x: i32, y: i32) -> Vec4 {
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

/// Samples a material's base colour texture at `uv` with the screen-space derivatives of uv:
/// level of detail λ = log2 of the longest footprint in level-0 texels; λ ≤ 0 magnifies
/// (magnification filter, level 0), else the minification filter on level 0 (no mipmaps), the
/// nearest level, or a blend of the two nearest.
pub fn sample_texture(table: &MaterialTable, m: &Material, uv: Vec2, duv_dx: Vec2, duv_dy: Vec2) -> Vec4 {
    sample_levels(table, m, m.first_mip, m.mip_count, uv, duv_dx, duv_dy)
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
    let lambda = (duv_dx * size).length().max((duv_dy * size).length()).log2();
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
    for (k, level) in [l0, l1].into_iter().enumerate() {
        let weight = if k == 0 { 1.0 - t } else { t };
        if weight > 0.0 {
            out += weight * sample_level(table, m, first_mip, level as u32, uv, filter);
        }
    }
    out
}

/// Screen-door threshold of a pixel for BLEND materials: a 4×4 ordered-dither (Bayer) matrix,
/// so a surface of opacity a covers about a of the pixels, independently of drawing order.
pub fn blend_threshold(frag_xy: Vec2) -> f32 {
    const BAYER: [f32; 16] = [0.0, 8.0, 2.0, 10.0, 12.0, 4.0, 14.0, 6.0, 3.0, 11.0, 1.0, 9.0, 15.0, 7.0, 13.0, 5.0];
    let (x, y) = (frag_xy.x as u32 % 4, frag_xy.y as u32 % 4);
    (BAYER[(4 * y + x) as usize] + 0.5) / 16.0
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
    let m = &table.materials[(s.material as usize).min(table.materials.len() - 1)];
    if m.double_sided == 0 && !s.front_facing {
        return None;
    }
    let mut c = s.color;
    if m.texture != NO_TEXTURE && m.mip_count > 0 {
        c *= sample_texture(table, m, s.uv, s.duv_dx, s.duv_dy);
    }
    if (m.alpha_mode == AlphaMode::Mask as u32 && c.w < m.alpha_cutoff)
        || (m.alpha_mode == AlphaMode::Blend as u32 && c.w <= blend_threshold(s.frag_xy))
    {
        return None;
    }
    Some(c)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::core::color::linear_to_srgb;
    use crate::core::texture::Texture;

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
