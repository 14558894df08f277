// Shared surface work of the drawing stages and the ray tracer: the material table and texture
// sampling, the surface colour (alpha mask / screen-door blend, single-sided culling), headlight
// shading in linear light, the glTF look (metallic-roughness BRDF, punctual lights, texture maps
// and their tangent frame, image-based lighting from the environment, tone mapping), and the
// pixel geometry (a pixel's screen point and ray, the display-position error of seed 002 §4.1 and
// the distance along a pixel's ray). Imported by fragment.wgsl (raster, slit) and trace.wgsl.
// CPU twins: src/cpu/fragment.rs.

#import projection
#import constants

// ---- Materials and textures (layout: src/core/material.rs, packing: src/core/texture.rs) ----

// false: every material of the scene is untextured, opaque and double-sided, so a fragment's
// colour is its vertex colour and nothing is discarded; the renderer then compiles the material
// code out (a pipeline constant), which restores early depth testing.
override MATERIALS: bool = true;

// false: no material of the scene can discard a fragment (all opaque and double-sided), so the
// fragment entry points leave `discard` out and the rasterizer may test depth before shading.
override DISCARDS: bool = true;

// Parts of the glTF look a pipeline compiles in (src/gpu/draw.rs, `Lit`): the BRDF at all, the
// environment's image-based lighting, the texture maps. lavapipe runs every branch under a mask,
// so a part a frame does not use is left out rather than skipped. The ray tracer keeps all
// (the uniform `lighting` decides).
override PBR: bool = true;
override ENVIRONMENT: bool = true;
override MAPS: bool = true;

// false: the frame has no shadow maps (no directional or spot light, `--no-shadows`, the ray
// tracer, which shadows by rays); the drawing pipelines then leave the look-up out.
override SHADOW_MAPS: bool = true;

// NO_TEXTURE, WRAP_*, FILTER_*, MIPMAP_*, ALPHA_*: from `constants` (src/core/material.rs).

struct Material {
    texture: u32,
    wrap_u: u32,
    wrap_v: u32,
    mag_filter: u32,
    min_filter: u32,
    mipmap: u32,
    alpha_mode: u32,
    alpha_cutoff: f32,
    double_sided: u32,
    first_mip: u32,
    mip_count: u32,
    mirror: f32,        // the ray tracer's optics (src/core/material.rs)
    transmission: f32,
    ior: f32,
    metallic: f32,      // glTF metallic-roughness factors
    roughness: f32,
    emissive_r: f32,    // emitted linear colour (× KHR_materials_emissive_strength)
    emissive_g: f32,
    emissive_b: f32,
    // The glTF maps: texture (unused here), first mip level, level count (0: none).
    mr_texture: u32,
    mr_first_mip: u32,
    mr_mip_count: u32,
    normal_texture: u32,
    normal_first_mip: u32,
    normal_mip_count: u32,
    normal_scale: f32,
    occlusion_texture: u32,
    occlusion_first_mip: u32,
    occlusion_mip_count: u32,
    occlusion_strength: f32,
    emissive_texture: u32,
    emissive_first_mip: u32,
    emissive_mip_count: u32,
}

// A punctual light (KHR_lights_punctual, src/core/light.rs), viewer frame: colour × intensity
// (candela; lux for directional lights), range 0 = unlimited, spot cone cosines.
struct Light {
    position: vec3<f32>,
    kind: u32,
    direction: vec3<f32>,
    range: f32,
    color: vec3<f32>,
    inner_cos: f32,
    outer_cos: f32,
    shadow_map: u32,    // its shadow map (src/core/shadow.rs), or NO_SHADOW_MAP
    _pad1: u32,
    _pad2: u32,
}

// The frame's lighting (`LightingParams`): lights in use, the glTF BRDF (1) or the headlight
// (0), 2^EV, the tone mapping; the environment's image-based lighting (src/core/environment.rs):
// on or off, where its split-sum table starts, the rotation
// from the viewer frame to the environment's, the irradiance's SH coefficients and the
// prefiltered levels (first texel, width, height).
struct Lighting {
    count: u32,
    pbr: u32,
    exposure: f32,
    tonemap: u32,
    environment: u32,
    env_background: u32,
    env_lut: u32,
    shadows: u32,
    env_rotation: array<vec4<f32>, 3>,
    env_sh: array<vec4<f32>, 9>,
    env_levels: array<vec4<u32>, ENV_LEVELS>,
}

struct MipLevel {
    offset: u32,
    width: u32,
    height: u32,
    _pad: u32,
}

@group(1) @binding(0) var<storage, read> materials: array<Material>;
@group(1) @binding(1) var<storage, read> mips: array<MipLevel>;
// RGBA8 sRGB texels, one per u32, rows top to bottom, levels and textures one after the other.
@group(1) @binding(2) var<storage, read> texels: array<u32>;
@group(1) @binding(3) var<storage, read> lights: array<Light>;
@group(1) @binding(4) var<uniform> lighting: Lighting;
// The environment's prefiltered levels (RGB9E5) and split-sum table (two half floats); a single
// entry when none (src/core/environment.rs).
@group(1) @binding(5) var<storage, read> environment: array<u32>;

// A light's shadow map (src/core/shadow.rs): viewer frame → the light's clip space, its first
// depth, its side in texels, a texel's world size (at unit distance along the axis when
// perspective), its kind: SHADOW_ORTHOGRAPHIC, SHADOW_PERSPECTIVE, or SHADOW_CUBE (a point
// light's six faces, +x −x +y −y +z −z, this the first).
struct ShadowMap {
    clip_from_viewer: mat4x4<f32>,
    offset: u32,
    size: u32,
    texel: f32,
    projection: u32,
}

// The frame's shadow maps and their depths (rows top to bottom, maps one after the other),
// rendered by the `shadow` stage; a single entry each when none.
@group(1) @binding(6) var<storage, read> shadow_maps: array<ShadowMap>;
@group(1) @binding(7) var<storage, read> shadow_depths: array<f32>;

fn srgb_to_linear(c: vec3<f32>) -> vec3<f32> {
    return select(pow((c + 0.055) / 1.055, vec3<f32>(2.4)), c / 12.92, c <= vec3<f32>(0.04045));
}

fn euclid_mod(i: i32, n: i32) -> i32 {
    let r = i % n;
    return select(r, r + n, r < 0);
}

// Texel index i folded into 0..n by a wrap mode.
fn wrap_index(i: i32, n: i32, mode: u32) -> i32 {
    if (mode == WRAP_CLAMP) {
        return clamp(i, 0, n - 1);
    }
    if (mode == WRAP_MIRROR) {
        let m = euclid_mod(i, 2 * n);
        return select(m, 2 * n - 1 - m, m >= n);
    }
    return euclid_mod(i, n);
}

// Samples a material's base colour texture (linear light) at uv with the screen-space
// derivatives of uv: level of detail λ = log2 of the longest footprint in level-0 texels;
// λ ≤ 0 magnifies (magnification filter, level 0), else the minification filter on level 0
// (no mipmaps), the nearest level, or a blend of the two nearest. Filtering is done by hand
// with one loop over (level, corner), so every wrap mode is exact and the function has one
// texel read (lavapipe inlines every call).
fn sample_texture(m: Material, uv_in: vec2<f32>, duv_dx: vec2<f32>, duv_dy: vec2<f32>) -> vec4<f32> {
    return sample_levels(m, m.first_mip, m.mip_count, uv_in, duv_dx, duv_dy);
}

// The same for the texture whose mip chain starts at `first_mip` (the material's maps), with the
// material's sampler.
fn sample_levels(m: Material, first_mip: u32, mip_count: u32, uv_in: vec2<f32>, duv_dx: vec2<f32>,
                 duv_dy: vec2<f32>) -> vec4<f32> {
    let top = mips[first_mip];
    let size = vec2<f32>(f32(top.width), f32(top.height));
    let lambda = log2(max(length(duv_dx * size), length(duv_dy * size)));
    let last = f32(mip_count - 1u);
    var l0 = 0.0;
    var l1 = 0.0;
    var t = 0.0;
    var texel_filter = m.min_filter;
    if (!(lambda > 0.0)) {
        texel_filter = m.mag_filter;
    } else if (m.mipmap == MIPMAP_NEAREST) {
        l0 = floor(min(lambda, last) + 0.5);
        l1 = l0;
    } else if (m.mipmap != MIPMAP_NONE) {
        let l = min(lambda, last);
        l0 = floor(l);
        l1 = min(l0 + 1.0, last);
        t = l - l0;
    }
    let uv = clamp(uv_in, vec2<f32>(-1e6), vec2<f32>(1e6));
    var out = vec4<f32>(0.0);
    for (var k = 0u; k < 8u; k++) {
        let level_weight = select(1.0 - t, t, k >= 4u);
        if (!(level_weight > 0.0)) {
            continue;
        }
        let level = mips[first_mip + u32(select(l0, l1, k >= 4u))];
        let n = vec2<i32>(i32(level.width), i32(level.height));
        let p = uv * vec2<f32>(n);
        // Nearest: the texel containing p. Linear: the four texels around p.
        var base = floor(p);
        var f = vec2<f32>(0.0);
        if (texel_filter == FILTER_LINEAR) {
            base = floor(p - 0.5);
            f = p - 0.5 - base;
        }
        let dx = i32(k & 1u);
        let dy = i32((k >> 1u) & 1u);
        let weight = select(1.0 - f.x, f.x, dx == 1) * select(1.0 - f.y, f.y, dy == 1) * level_weight;
        if (!(weight > 0.0)) {
            continue;
        }
        let x = wrap_index(i32(base.x) + dx, n.x, m.wrap_u);
        let y = wrap_index(i32(base.y) + dy, n.y, m.wrap_v);
        let c = unpack4x8unorm(texels[level.offset + u32(y) * level.width + u32(x)]);
        out += weight * vec4<f32>(srgb_to_linear(c.rgb), c.a);
    }
    return out;
}

// Screen-door threshold of a pixel for BLEND materials: a 4×4 ordered-dither (Bayer) matrix,
// so a surface of opacity a covers about a of the pixels, independently of drawing order.
fn blend_threshold(frag_xy: vec2<f32>) -> f32 {
    var bayer = array<f32, 16>(0.0, 8.0, 2.0, 10.0, 12.0, 4.0, 14.0, 6.0, 3.0, 11.0, 1.0, 9.0, 15.0, 7.0, 13.0, 5.0);
    let x = u32(frag_xy.x) % 4u;
    let y = u32(frag_xy.y) % 4u;
    return (bayer[4u * y + x] + 0.5) / 16.0;
}

// The linear surface colour of a fragment; alpha < 0 where it is discarded (a single-sided
// face seen from behind, alpha below the MASK cutoff, a BLEND fragment the screen door leaves out).
fn surface_color(material: u32, color: vec4<f32>, uv: vec2<f32>, duv_dx: vec2<f32>, duv_dy: vec2<f32>,
                 frag_xy: vec2<f32>, front_facing: bool) -> vec4<f32> {
    if (!MATERIALS) {
        return color;
    }
    let index = min(material, arrayLength(&materials) - 1u);
    if (materials[index].double_sided == 0u && !front_facing) {
        return vec4<f32>(-1.0);
    }
    var c = color;
    if (materials[index].texture != NO_TEXTURE && materials[index].mip_count > 0u) {
        let m = materials[index];
        c *= sample_texture(m, uv, duv_dx, duv_dy);
    }
    let m = materials[index];
    if ((m.alpha_mode == ALPHA_MASK && c.a < m.alpha_cutoff)
        || (m.alpha_mode == ALPHA_BLEND && c.a <= blend_threshold(frag_xy))) {
        return vec4<f32>(-1.0);
    }
    return vec4<f32>(c.rgb, max(c.a, 0.0));
}

// Linear colour × (ambient + (1 − ambient)·|n·l|), the light at the viewer, two-sided. The
// colour target is sRGB: it encodes what this returns (the CPU twin encodes explicitly).
fn shade(ambient: f32, view_position: vec3<f32>, normal: vec3<f32>, color: vec4<f32>) -> vec4<f32> {
    let n_len = length(normal);
    var lambert = 1.0;
    if (n_len > 1e-6) {
        lambert = abs(dot(normal / n_len, -normalize(view_position)));
    }
    let lit = clamp(color.rgb * (ambient + (1.0 - ambient) * lambert), vec3<f32>(0.0), vec3<f32>(1.0));
    return vec4<f32>(lit, 1.0);
}

// ---- The glTF look (issue 17): metallic-roughness BRDF, punctual lights, tone mapping ----

// The glTF 2.0 BRDF (specification, Appendix B) for unit normal n, view v, light l: Lambert
// diffuse of c_diff = base·(1 − metallic) weighted by 1 − F, and the GGX specular D·Vis·F with
// α = roughness², Smith's separable visibility and Fresnel–Schlick from f0 = mix(0.04, base,
// metallic). Returns f (the caller multiplies by n·l and the light). `brdf` in fragment.rs.
fn brdf(n: vec3<f32>, v: vec3<f32>, l: vec3<f32>, base: vec3<f32>, metallic: f32, roughness: f32) -> vec3<f32> {
    let h = normalize(l + v);
    let nl = max(dot(n, l), 0.0);
    let nv = max(abs(dot(n, v)), 1e-4);
    let nh = max(dot(n, h), 0.0);
    let vh = abs(dot(v, h));
    let alpha = max(roughness * roughness, 1e-3);
    let a2 = alpha * alpha;
    let f0 = mix(vec3<f32>(0.04), base, metallic);
    let fresnel = f0 + (1.0 - f0) * pow(1.0 - vh, 5.0);
    let k = nh * nh * (a2 - 1.0) + 1.0;
    let d = a2 / (PI * k * k);
    let g_l = 2.0 * nl / (nl + sqrt(a2 + (1.0 - a2) * nl * nl));
    let g_v = 2.0 * nv / (nv + sqrt(a2 + (1.0 - a2) * nv * nv));
    let vis = g_l * g_v / max(4.0 * nl * nv, 1e-8);
    let c_diff = mix(base, vec3<f32>(0.0), metallic);
    return (1.0 - fresnel) * c_diff / PI + fresnel * d * vis;
}

// The light arriving from `light` at p (viewer frame): the unit direction towards it (xyz) and
// the factor on its colour (w): 1 for a directional light; 1/d² times the range window for
// point and spot lights, a spot light also times its cone (`light_at` in fragment.rs).
fn light_at(light: Light, p: vec3<f32>) -> vec4<f32> {
    if (light.kind == LIGHT_DIRECTIONAL) {
        return vec4<f32>(-light.direction, 1.0);
    }
    let to_light = light.position - p;
    let d2 = max(dot(to_light, to_light), 1e-8);
    let l = to_light / sqrt(d2);
    var scale = 1.0 / d2;
    if (light.range > 0.0) {
        let r = d2 * d2 / (light.range * light.range * light.range * light.range);
        let w = clamp(1.0 - r, 0.0, 1.0);
        scale *= w * w;
    }
    if (light.kind == LIGHT_SPOT) {
        let cd = dot(light.direction, -l);
        let t = clamp((cd - light.outer_cos) / max(light.inner_cos - light.outer_cos, 1e-4), 0.0, 1.0);
        scale *= t * t;
    }
    return vec4<f32>(l, scale);
}

// Khronos PBR Neutral tone mapping (`pbr_neutral` in light.rs).
fn pbr_neutral(c_in: vec3<f32>) -> vec3<f32> {
    let start = 0.8 - 0.04;
    let desaturation = 0.15;
    let x = min(c_in.r, min(c_in.g, c_in.b));
    let offset = select(0.04, x - 6.25 * x * x, x < 0.08);
    var c = c_in - offset;
    let peak = max(c.r, max(c.g, c.b));
    if (peak < start) {
        return c;
    }
    let d = 1.0 - start;
    let new_peak = 1.0 - d * d / (peak + d - start);
    c *= new_peak / peak;
    let g = 1.0 - 1.0 / (desaturation * (peak - new_peak) + 1.0);
    return mix(c, vec3<f32>(new_peak), g);
}

// The tone mapped colour, 0..1 (`tonemap` in light.rs).
fn tonemap(c_in: vec3<f32>) -> vec3<f32> {
    let c = max(c_in * lighting.exposure, vec3<f32>(0.0));
    if (lighting.tonemap == TONEMAP_LINEAR) {
        return c;  // a float colour target (`--hdr`)
    }
    var out = c;
    if (lighting.tonemap == TONEMAP_PBR_NEUTRAL) {
        out = pbr_neutral(c);
    } else if (lighting.tonemap == TONEMAP_ACES) {
        out = (c * (2.51 * c + 0.03)) / (c * (2.43 * c + 0.59) + 0.14);
    }
    return clamp(out, vec3<f32>(0.0), vec3<f32>(1.0));
}

// A surface's shaded linear colour: with `lighting.pbr`, the glTF BRDF under the scene's lights
// seen from the drawn eye's own point on the eye circle for the pixel at `frag_xy` (its ray's
// origin: highlights differ between the eyes), plus ambient × the diffuse colour and the
// emission, tone mapped; else the headlight (`shade`). `shade_surface` in fragment.rs.
fn shade_surface(material: u32, ambient: f32, proj: Projection, eye_sign: f32, frag_xy: vec2<f32>,
                 view_position: vec3<f32>, normal: vec3<f32>, tangent: vec4<f32>, color: vec4<f32>, uv: vec2<f32>,
                 duv_dx: vec2<f32>, duv_dy: vec2<f32>, dp_dx: vec3<f32>, dp_dy: vec3<f32>) -> vec4<f32> {
    if (!MATERIALS || !PBR || lighting.pbr == 0u) {
        return shade(ambient, view_position, normal, color);
    }
    let eye = pixel_ray(proj, eye_sign, frag_xy).origin;
    let maps = surface_maps(material, uv, duv_dx, duv_dy, dp_dx, dp_dy, duv_dx, duv_dy, tangent);
    return vec4<f32>(tonemap(pbr_radiance(ambient, normalize(eye - view_position), view_position, normal, color,
                                          maps, 0u)), 1.0);
}

// A surface's BRDF inputs with the material's texture maps applied: metallic and roughness
// (× the metallic-roughness map's blue and green), occlusion (1 + strength·(red − 1)), emission
// (× the emissive map), the normal map's tangent-space normal ((0, 0, 1) without one), and the
// tangent frame: the file's tangent where it gives one (xyz and the bitangent's sign w, viewer
// frame; w = 0: none), else two in-plane position differentials with their texture-coordinate
// differences. `surface_maps` in fragment.rs.
struct SurfaceMaps {
    metallic: f32,
    roughness: f32,
    occlusion: f32,
    emissive: vec3<f32>,
    normal: vec3<f32>,
    dp1: vec3<f32>,
    dp2: vec3<f32>,
    duv1: vec2<f32>,
    duv2: vec2<f32>,
    tangent: vec4<f32>,
}

// The maps sampled at uv with the sampling derivatives duv_dx, duv_dy, in one loop (lavapipe
// inlines every call, and a shader that merely contains more code runs slower).
fn surface_maps(material: u32, uv: vec2<f32>, duv_dx: vec2<f32>, duv_dy: vec2<f32>, dp1: vec3<f32>,
                dp2: vec3<f32>, duv1: vec2<f32>, duv2: vec2<f32>, tangent: vec4<f32>) -> SurfaceMaps {
    let index = min(material, arrayLength(&materials) - 1u);
    let any_map = materials[index].mr_mip_count | materials[index].normal_mip_count
        | materials[index].occlusion_mip_count | materials[index].emissive_mip_count;
    if (!MAPS || any_map == 0u) {
        return SurfaceMaps(materials[index].metallic, materials[index].roughness, 1.0,
                           vec3<f32>(materials[index].emissive_r, materials[index].emissive_g, materials[index].emissive_b),
                           vec3<f32>(0.0, 0.0, 1.0), dp1, dp2, duv1, duv2, tangent);
    }
    let m = materials[index];
    var s = SurfaceMaps(m.metallic, m.roughness, 1.0, vec3<f32>(m.emissive_r, m.emissive_g, m.emissive_b),
                        vec3<f32>(0.0, 0.0, 1.0), dp1, dp2, duv1, duv2, tangent);
    for (var j = 0u; j < 4u; j++) {
        var first = m.mr_first_mip;
        var count = m.mr_mip_count;
        if (j == 1u) {
            first = m.normal_first_mip;
            count = m.normal_mip_count;
        } else if (j == 2u) {
            first = m.occlusion_first_mip;
            count = m.occlusion_mip_count;
        } else if (j == 3u) {
            first = m.emissive_first_mip;
            count = m.emissive_mip_count;
        }
        if (count == 0u) {
            continue;
        }
        let t = sample_levels(m, first, count, uv, duv_dx, duv_dy);
        if (j == 0u) {
            s.roughness *= t.g;
            s.metallic *= t.b;
        } else if (j == 1u) {
            let xy = (t.xy * 2.0 - 1.0) * m.normal_scale;
            s.normal = normalize(vec3<f32>(xy, t.z * 2.0 - 1.0));
        } else if (j == 2u) {
            s.occlusion = 1.0 + m.occlusion_strength * (t.r - 1.0);
        } else {
            s.emissive *= t.rgb;
        }
    }
    return s;
}

// The unit normal n perturbed by the normal map: tangent T = ∇u and bitangent B = ∇v in the
// surface's plane from the differentials (Schüler's cotangent frame, the sign of the
// differentials' orientation taken out), both scaled by the larger's length; the map's +y
// points up its image, against increasing v (glTF's convention). Unchanged without a map or
// where the texture coordinates do not vary. `mapped_normal` in fragment.rs.
fn mapped_normal(n: vec3<f32>, s: SurfaceMaps) -> vec3<f32> {
    if (s.normal.z >= 1.0) {
        return n;
    }
    let dp1perp = cross(n, s.dp1);
    let dp2perp = cross(s.dp2, n);
    let orientation = select(-1.0, 1.0, dot(n, cross(s.dp1, s.dp2)) >= 0.0);
    let t = (dp2perp * s.duv1.x + dp1perp * s.duv2.x) * orientation;
    let b = (dp2perp * s.duv1.y + dp1perp * s.duv2.y) * orientation;
    let scale2 = max(dot(t, t), dot(b, b));
    if (!(scale2 > 1e-30)) {
        return n;
    }
    let k = inverseSqrt(scale2);
    return normalize(t * (k * s.normal.x) - b * (k * s.normal.y) + n * s.normal.z);
}

// The glTF BRDF's linear colour (before tone mapping) of a surface point p (viewer frame) seen
// along the unit direction v (towards the eye): the scene's lights, ambient × the diffuse colour
// and the emission (`pbr_radiance` in fragment.rs).
fn pbr_radiance(ambient: f32, v: vec3<f32>, view_position: vec3<f32>, normal: vec3<f32>,
                color: vec4<f32>, maps: SurfaceMaps, first_light: u32) -> vec3<f32> {
    // Two-sided: the side the eye sees.
    let n = shading_normal(normal, v, maps);
    let base = max(color.rgb, vec3<f32>(0.0));
    var c = maps.emissive;
    if (ENVIRONMENT && lighting.environment != 0u) {
        c += maps.occlusion * ibl_radiance(n, v, base, maps.metallic, maps.roughness);
    } else {
        c += maps.occlusion * ambient * mix(base, vec3<f32>(0.0), maps.metallic);
    }
    for (var i = first_light; i < lighting.count; i++) {
        var term = light_term(i, n, v, view_position, base, maps);
        let map = lights[i].shadow_map;
        if (SHADOW_MAPS && map != NO_SHADOW_MAP && any(term > vec3<f32>(0.0))) {
            term *= shadow_visibility(map, view_position, normal, light_at(lights[i], view_position).xyz);
        }
        c += term;
    }
    return c;
}

// The share of a light that reaches p (viewer frame; `normal` its interpolated normal, l the unit
// direction towards the light) by the light's shadow map `map` (src/core/shadow.rs): the point
// offset along the normal (turned towards the light) and towards the light by a few texels'
// world size, its depth compared with the four nearest texels, the results weighted bilinearly.
// Points the map does not see are lit. A cube reads the face the light sees p through
// (`shadow_visibility` in fragment.rs).
fn shadow_visibility(first_map: u32, p: vec3<f32>, normal: vec3<f32>, l: vec3<f32>) -> f32 {
    var map = first_map;
    if (shadow_maps[map].projection == SHADOW_CUBE) {
        map += cube_face(l);
    }
    let m = shadow_maps[map];
    let q0 = m.clip_from_viewer * vec4<f32>(p, 1.0);
    if (q0.w <= 0.0) {
        return 1.0;
    }
    let t = m.texel * select(q0.w, 1.0, m.projection == SHADOW_ORTHOGRAPHIC);
    var n = vec3<f32>(0.0);
    if (dot(normal, normal) > 1e-12) {
        n = normalize(normal);
    }
    n = select(-n, n, dot(n, l) >= 0.0);
    let q = m.clip_from_viewer * vec4<f32>(p + (NORMAL_OFFSET_TEXELS * n + LIGHT_OFFSET_TEXELS * l) * t, 1.0);
    if (q.w <= 0.0) {
        return 1.0;
    }
    let ndc = q.xyz / q.w;
    let size = f32(m.size);
    let st = vec2<f32>(ndc.x * 0.5 + 0.5, 0.5 - ndc.y * 0.5) * size - 0.5;
    if (!(ndc.z < 1.0) || any(st < vec2<f32>(-1.0)) || any(st > vec2<f32>(size))) {
        return 1.0;
    }
    let corner = floor(st);
    let f = st - corner;
    var lit: array<f32, 4>;
    for (var k = 0u; k < 4u; k++) {
        let x = u32(clamp(i32(corner.x) + i32(k & 1u), 0, i32(m.size) - 1));
        let y = u32(clamp(i32(corner.y) + i32(k >> 1u), 0, i32(m.size) - 1));
        lit[k] = select(0.0, 1.0, ndc.z <= shadow_depths[m.offset + y * m.size + x]);
    }
    return mix(mix(lit[0], lit[1], f.x), mix(lit[2], lit[3], f.x), f.y);
}

// What light i adds at view_position (unit normal n facing v): the BRDF × its colour × its
// falloff × n·l (`light_term` in fragment.rs).
fn light_term(i: u32, n: vec3<f32>, v: vec3<f32>, view_position: vec3<f32>, base: vec3<f32>,
              maps: SurfaceMaps) -> vec3<f32> {
    let light = lights[i];
    let at = light_at(light, view_position);
    let nl = dot(n, at.xyz);
    if (nl > 0.0 && at.w > 0.0) {
        return brdf(n, v, at.xyz, base, maps.metallic, maps.roughness) * light.color * (at.w * nl);
    }
    return vec3<f32>(0.0);
}

// The unit normal the glTF BRDF shades with at a surface seen along v: the given one (v where
// there is none), turned to the side the eye sees, perturbed by the normal map (in the file's
// tangent frame where it has one, else the derivatives' frame of `mapped_normal`).
fn shading_normal(normal: vec3<f32>, v: vec3<f32>, maps: SurfaceMaps) -> vec3<f32> {
    var n = normal;
    if (dot(n, n) < 1e-12) {
        n = v;
    }
    n = normalize(n);
    let side = select(-1.0, 1.0, dot(n, v) >= 0.0);
    if (maps.tangent.w != 0.0 && maps.normal.z < 1.0) {
        // The file's frame: the tangent made normal to n, the bitangent (n × t)·sign(w) (glTF);
        // seen from the back, the whole perturbed normal turns with the face (as three.js does).
        let t = maps.tangent.xyz - n * dot(n, maps.tangent.xyz);
        if (dot(t, t) > 1e-12) {
            let tu = normalize(t);
            let b = cross(n, tu) * select(-1.0, 1.0, maps.tangent.w >= 0.0);
            return side * normalize(tu * maps.normal.x + b * maps.normal.y + n * maps.normal.z);
        }
    }
    return mapped_normal(side * n, maps);
}

// The cube face a light is seen through from p, l the unit direction towards the light: the
// major axis of −l, +x −x +y −y +z −z as 0..5 (`cube_face` in src/core/shadow.rs).
fn cube_face(l: vec3<f32>) -> u32 {
    let d = -l;
    let a = abs(d);
    if (a.x >= a.y && a.x >= a.z) {
        return select(1u, 0u, d.x >= 0.0);
    }
    if (a.y >= a.z) {
        return select(3u, 2u, d.y >= 0.0);
    }
    return select(5u, 4u, d.z >= 0.0);
}

// ---- Image-based lighting (src/core/environment.rs; twins in fragment.rs) ----

// A viewer-frame direction in the environment's frame.
fn env_direction(d: vec3<f32>) -> vec3<f32> {
    return lighting.env_rotation[0].xyz * d.x + lighting.env_rotation[1].xyz * d.y + lighting.env_rotation[2].xyz * d.z;
}

// An RGB9E5 texel of the environment (`rgb9e5_decode` in environment.rs).
fn env_texel(i: u32) -> vec3<f32> {
    let bits = environment[i];
    let scale = exp2(f32(bits >> 27u) - 24.0);
    return vec3<f32>(f32(bits & 511u), f32((bits >> 9u) & 511u), f32((bits >> 18u) & 511u)) * scale;
}

// Prefiltered level k, bilinear at equirectangular coordinates st in [0, 1]² (longitude wraps,
// latitude clamps).
fn env_level(k: u32, st: vec2<f32>) -> vec3<f32> {
    let level = lighting.env_levels[k];
    let p = st * vec2<f32>(f32(level.y), f32(level.z)) - 0.5;
    let base = floor(p);
    let f = p - base;
    let x0 = euclid_mod(i32(base.x), i32(level.y));
    let x1 = euclid_mod(i32(base.x) + 1, i32(level.y));
    let y0 = u32(clamp(i32(base.y), 0, i32(level.z) - 1)) * level.y + level.x;
    let y1 = u32(clamp(i32(base.y) + 1, 0, i32(level.z) - 1)) * level.y + level.x;
    let top = mix(env_texel(y0 + u32(x0)), env_texel(y0 + u32(x1)), f.x);
    let bottom = mix(env_texel(y1 + u32(x0)), env_texel(y1 + u32(x1)), f.x);
    return mix(top, bottom, f.y);
}

// The equirectangular coordinates in [0, 1]² of environment-frame direction e.
fn env_st(e: vec3<f32>) -> vec2<f32> {
    return vec2<f32>(atan2(e.x, -e.z) / TAU + 0.5, 0.5 - asin(clamp(e.y, -1.0, 1.0)) / PI);
}

// The radiance around viewer-frame direction d convolved for `roughness` (levels blended).
fn env_radiance(d: vec3<f32>, roughness: f32) -> vec3<f32> {
    let st = env_st(env_direction(d));
    let lod = clamp(roughness, 0.0, 1.0) * f32(ENV_LEVELS - 1u);
    let k = min(u32(lod), ENV_LEVELS - 2u);
    let t = lod - f32(k);
    return mix(env_level(k, st), env_level(k + 1u, st), t);
}

// E(n)/π at viewer-frame normal n, from the SH coefficients (`irradiance` in environment.rs).
fn env_irradiance(n_view: vec3<f32>) -> vec3<f32> {
    let d = env_direction(n_view);
    let sh = lighting.env_sh;
    let e = sh[0].xyz * 0.282095 + (sh[1].xyz * d.y + sh[2].xyz * d.z + sh[3].xyz * d.x) * 0.488603
        + (sh[4].xyz * (d.x * d.y) + sh[5].xyz * (d.y * d.z) + sh[7].xyz * (d.x * d.z)) * 1.092548
        + sh[6].xyz * (0.315392 * (3.0 * d.z * d.z - 1.0)) + sh[8].xyz * (0.546274 * (d.x * d.x - d.y * d.y));
    return max(e, vec3<f32>(0.0));
}

// The split-sum table (A, B) at n·v and roughness, bilinear between texel centres.
fn env_lut(nv: f32, roughness: f32) -> vec2<f32> {
    let n = f32(LUT_SIZE);
    let p = clamp(vec2<f32>(nv, roughness) * n - 0.5, vec2<f32>(0.0), vec2<f32>(n - 1.0));
    let base = min(floor(p), vec2<f32>(n - 2.0));
    let f = p - base;
    let i = lighting.env_lut + u32(base.y) * LUT_SIZE + u32(base.x);
    let top = mix(unpack2x16float(environment[i]), unpack2x16float(environment[i + 1u]), f.x);
    let bottom = mix(unpack2x16float(environment[i + LUT_SIZE]), unpack2x16float(environment[i + LUT_SIZE + 1u]), f.x);
    return mix(top, bottom, f.y);
}

// The environment's light reflected towards v by a surface with unit normal n (split sum with
// Fdez-Agüera's multiple-scattering term; see src/core/environment.rs).
fn ibl_radiance(n: vec3<f32>, v: vec3<f32>, base: vec3<f32>, metallic: f32, roughness: f32) -> vec3<f32> {
    let nv = clamp(dot(n, v), 1e-4, 1.0);
    let ab = env_lut(nv, roughness);
    let f0 = mix(vec3<f32>(0.04), base, metallic);
    let e_ss = f0 * ab.x + ab.y;
    let e_ms = 1.0 - (ab.x + ab.y);
    let f_avg = f0 + (1.0 - f0) / 21.0;
    let f_ms = e_ss * f_avg / (1.0 - e_ms * f_avg);
    let irradiance = env_irradiance(n);
    let specular = env_radiance(2.0 * nv * n - v, roughness) * e_ss + irradiance * f_ms * e_ms;
    let c_diff = mix(base, vec3<f32>(0.0), metallic);
    return specular + c_diff * irradiance * max(vec3<f32>(1.0) - e_ss - f_ms * e_ms, vec3<f32>(0.0));
}

// The screen point (u, v) at image position (x, y) (`Projection::pixel_to_screen`).
fn from_pixel(proj: Projection, xy: vec2<f32>) -> vec2<f32> {
    return vec2<f32>((xy.x / proj.width - 0.5) * TAU, (0.5 * proj.height - xy.y) / proj.pixels_per_v);
}

// The unit direction, seen from the centre, of screen point (u, v): on the cylinder the screen
// point (R_T sin u, v, −R_T cos u), on the sphere longitude u, latitude v.
fn screen_direction(proj: Projection, uv: vec2<f32>) -> vec3<f32> {
    if (is_sphere(proj)) {
        return vec3<f32>(cos(uv.y) * sin(uv.x), sin(uv.y), -cos(uv.y) * cos(uv.x));
    }
    return normalize(vec3<f32>(proj.screen_radius * sin(uv.x), uv.y, -proj.screen_radius * cos(uv.x)));
}

// The angle a pixel spans, radians (`pixel_spread` in fragment.rs): the larger of its width
// (2π/W, on the sphere × cos latitude) and its height (on the cylinder 1/(pixels_per_v·R_T) seen
// from the eyes, about R_T away; on the sphere 1/pixels_per_v).
fn pixel_spread(proj: Projection, frag_xy: vec2<f32>) -> f32 {
    let uv = from_pixel(proj, frag_xy);
    if (is_sphere(proj)) {
        return max(TAU / proj.width * cos(uv.y), 1.0 / proj.pixels_per_v);
    }
    return max(TAU / proj.width, 1.0 / (proj.pixels_per_v * proj.screen_radius));
}

// The display-position error of surface point p drawn at pixel centre `frag_xy` for this eye: the
// distance in pixels to where the projection puts p (horizontal distance wrapping around the
// panorama), or with `angle` the angle between the two directions in arcminutes; −1 where no eye
// sees p.
fn pixel_error(proj: Projection, eye_sign: f32, p: vec3<f32>, frag_xy: vec2<f32>, angle: bool) -> f32 {
    if (!sees(proj, p)) {
        return -1.0;
    }
    let uvd = project_with_azimuth(proj, p, azimuth(p), eye_sign);
    if (angle) {
        let a = screen_direction(proj, uvd.xy);
        let b = screen_direction(proj, from_pixel(proj, frag_xy));
        return precise_atan2(length(cross(a, b)), dot(a, b)) * (180.0 * 60.0 / PI);
    }
    let ideal = to_pixel(proj, uvd.x, uvd.y);
    var dx = abs(ideal.x - frag_xy.x);
    dx = min(dx, proj.width - dx);
    return length(vec2<f32>(dx, ideal.y - frag_xy.y));
}

struct Ray {
    origin: vec3<f32>,
    dir: vec3<f32>,
}

// The ray of the pixel at `frag_xy` (`pixel_ray` in fragment.rs): on the sphere the pixel's ray
// (`Projection::sphere_ray`); on the cylinder from the eye whose tangent ray meets the screen at
// the pixel's column (viewing direction φ = u − s·asin(d_e/R_T)) through the pixel's screen point.
fn pixel_ray(proj: Projection, eye_sign: f32, frag_xy: vec2<f32>) -> Ray {
    let uv = from_pixel(proj, frag_xy);
    if (is_sphere(proj)) {
        let d = vec3<f32>(cos(uv.y) * sin(uv.x), sin(uv.y), -cos(uv.y) * cos(uv.x));
        let origin = eye_sign * pole_fade(proj, abs(uv.y)) * proj.eye_radius * vec3<f32>(cos(uv.x), 0.0, sin(uv.x));
        if (proj.convergence > 0.0) {
            return Ray(origin, normalize(proj.convergence * d - origin));
        }
        return Ray(origin, d);
    }
    let phi = uv.x - eye_sign * precise_asin(proj.eye_radius / proj.screen_radius);
    let origin = eye_sign * proj.eye_radius * vec3<f32>(cos(phi), 0.0, sin(phi));
    let screen = vec3<f32>(proj.screen_radius * sin(uv.x), uv.y, -proj.screen_radius * cos(uv.x));
    return Ray(origin, normalize(screen - origin));
}

// The distance along the pixel's ray to the plane through p with normal n (the drawn triangle's
// plane), or |p − eye point| where the ray runs nearly within the plane (`pixel_distance`).
fn pixel_distance(proj: Projection, eye_sign: f32, p: vec3<f32>, n: vec3<f32>, frag_xy: vec2<f32>) -> f32 {
    let ray = pixel_ray(proj, eye_sign, frag_xy);
    let denom = dot(ray.dir, n);
    if (abs(denom) > 1e-3 * length(n)) {
        let t = dot(p - ray.origin, n) / denom;
        if (t > 0.0) {
            return t;
        }
    }
    return length(p - ray.origin);
}
