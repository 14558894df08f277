// A surface's colour and shading, shared by the drawing stages and the ray tracer: the surface
// colour (alpha mask / screen-door blend, single-sided culling), headlight shading in linear
// light, the glTF look (texture maps and their tangent frame, the lights with their shadow maps,
// image-based lighting), built on the modules it imports. Imported by fragment.wgsl (raster,
// slit) and trace.wgsl. CPU twin: src/cpu/fragment/mod.rs.

#import projection
#import constants
#import surface_bindings
#import texture
#import brdf
#import ibl
#import pixel_error

// Screen-door threshold of a pixel for BLEND materials: a 4×4 ordered-dither (Bayer) matrix,
// so a surface of opacity a covers about a of the pixels, independently of drawing order; a
// point off the pixel's centre (a traced sample) shifts it by its offset along x, so that the
// standard sample positions of one pixel get thresholds evenly spaced over 0..1 (a pixel of N
// traced samples shows the share a of them).
fn blend_threshold(frag_xy: vec2<f32>) -> f32 {
    var bayer = array<f32, 16>(0.0, 8.0, 2.0, 10.0, 12.0, 4.0, 14.0, 6.0, 3.0, 11.0, 1.0, 9.0, 15.0, 7.0, 13.0, 5.0);
    let x = u32(frag_xy.x) % 4u;
    let y = u32(frag_xy.y) % 4u;
    return fract((bayer[4u * y + x] + 0.5) / 16.0 + 0.5 + fract(frag_xy.x) - 1.0);
}

// The linear surface colour of a fragment before its alpha test; alpha −1 for a single-sided
// face seen from behind.
fn surface_rgba(material: u32, color: vec4<f32>, uv: vec2<f32>, duv_dx: vec2<f32>, duv_dy: vec2<f32>,
                front_facing: bool) -> vec4<f32> {
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
    return c;
}

// The linear surface colour of a fragment; alpha < 0 where it is discarded (a single-sided
// face seen from behind, alpha below the MASK cutoff, a BLEND fragment the screen door leaves out).
fn surface_color(material: u32, color: vec4<f32>, uv: vec2<f32>, duv_dx: vec2<f32>, duv_dy: vec2<f32>,
                 frag_xy: vec2<f32>, front_facing: bool) -> vec4<f32> {
    let c = surface_rgba(material, color, uv, duv_dx, duv_dy, front_facing);
    if (!MATERIALS || c.a < 0.0) {
        return c;
    }
    let m = materials[min(material, arrayLength(&materials) - 1u)];
    if ((m.alpha_mode == ALPHA_MASK && c.a < m.alpha_cutoff)
        || (m.alpha_mode == ALPHA_BLEND && c.a <= blend_threshold(frag_xy))) {
        return vec4<f32>(-1.0);
    }
    return vec4<f32>(c.rgb, max(c.a, 0.0));
}

// How much a MASK material's alpha changes over one pixel: |a·α(uv + ∂uv/∂x) − alpha| + |a·α(uv +
// ∂uv/∂y) − alpha| of its texture α (a the vertex alpha, `alpha` the fragment's, a·α(uv)), as
// fwidth would give it but from the texture itself, the same on every adapter and in the CPU
// twin; 0 for other materials.
fn mask_alpha_width(material: u32, vertex_alpha: f32, alpha: f32, uv: vec2<f32>, duv_dx: vec2<f32>,
                    duv_dy: vec2<f32>) -> f32 {
    if (!MATERIALS) {
        return 0.0;
    }
    let m = materials[min(material, arrayLength(&materials) - 1u)];
    if (m.alpha_mode != ALPHA_MASK || m.texture == NO_TEXTURE || m.mip_count == 0u) {
        return 0.0;
    }
    let ax = vertex_alpha * sample_texture(m, uv + duv_dx, duv_dx, duv_dy).a;
    let ay = vertex_alpha * sample_texture(m, uv + duv_dy, duv_dx, duv_dy).a;
    return abs(ax - alpha) + abs(ay - alpha);
}

// Alpha to coverage: which of its pixel's `n` samples (n > 1) a fragment of `alpha` covers
// (`alpha_width`: how much alpha changes over a pixel, `mask_alpha_width`). Opaque: all; a single-sided face
// seen from behind: none; MASK: the alpha sharpened about its cutoff over one pixel's change,
// clamp((alpha − cutoff) / alpha_width + 1/2, 0, 1), so that the cutoff's line through the
// texture is an edge covering its share of the pixel; BLEND: alpha itself. k = ⌊share·n +
// threshold⌋ samples (the pixel's screen-door threshold dithers the rounding, so a 4×4 block of
// pixels covers the share within 1/(16n)), consecutive from a sample the threshold picks (a
// surface behind another of the same alpha shows through the samples it leaves).
fn coverage_mask(material: u32, alpha: f32, alpha_width: f32, frag_xy: vec2<f32>, n: u32) -> u32 {
    let all = 0xffffffffu >> (32u - n);
    if (!MATERIALS) {
        return all;
    }
    if (alpha < 0.0) {
        return 0u;
    }
    let m = materials[min(material, arrayLength(&materials) - 1u)];
    var share = 1.0;
    if (m.alpha_mode == ALPHA_MASK) {
        share = clamp((alpha - m.alpha_cutoff) / max(alpha_width, 1e-4) + 0.5, 0.0, 1.0);
    } else if (m.alpha_mode == ALPHA_BLEND) {
        share = clamp(alpha, 0.0, 1.0);
    } else {
        return all;
    }
    let threshold = blend_threshold(frag_xy);
    let k = min(u32(floor(share * f32(n) + threshold)), n);
    let run = select(0u, 0xffffffffu >> (32u - max(k, 1u)), k > 0u);
    let start = u32(threshold * 16.0) % n;
    return ((run << start) | (run >> ((n - start) % n))) & all;
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

// A surface's shaded linear colour: with `lighting.pbr`, the glTF BRDF under the scene's lights
// seen from the drawn eye's own point on the eye circle for the pixel at `frag_xy` (its ray's
// origin: highlights differ between the eyes), plus ambient × the diffuse colour and the
// emission, tone mapped; else the headlight (`shade`). `shade_surface` in fragment.rs.
fn shade_surface(material: u32, ambient: f32, proj: Projection, eye_sign: f32, frag_xy: vec2<f32>,
                 view_position: vec3<f32>, normal: vec3<f32>, tangent: vec4<f32>, color: vec4<f32>, uv: vec2<f32>,
                 duv_dx: vec2<f32>, duv_dy: vec2<f32>, dp_dx: vec3<f32>, dp_dy: vec3<f32>) -> Shading {
    if (!MATERIALS || !PBR || lighting.pbr == 0u) {
        let lit = shade(ambient, view_position, normal, color);
        return Shading(lit, lit);
    }
    let eye = pixel_ray(proj, eye_sign, frag_xy).origin;
    let maps = surface_maps(material, uv, duv_dx, duv_dy, dp_dx, dp_dy, duv_dx, duv_dy, tangent);
    let linear = exposed(pbr_radiance(ambient, normalize(eye - view_position), view_position, normal, color, maps, 0u));
    return Shading(vec4<f32>(tone(linear), 1.0), vec4<f32>(linear, 1.0));
}

// A shaded fragment: the display colour (tone mapped, 0..1) and the linear colour × 2^EV
// (`--hdr`; the headlight's colour is the same).
struct Shading {
    display: vec4<f32>,
    linear: vec4<f32>,
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
// direction towards the light) by the light's shadow map `map` (src/core/shading/shadow.rs): the point
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
// major axis of −l, +x −x +y −y +z −z as 0..5 (`cube_face` in src/core/shading/shadow.rs).
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
