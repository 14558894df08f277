// Shared surface work of the drawing stages and the ray tracer: the material table and texture
// sampling, the surface colour (alpha mask / screen-door blend, single-sided culling), headlight
// shading in linear light, and the pixel geometry (a pixel's screen point and ray, the
// display-position error of seed 002 §4.1 and the distance along a pixel's ray). Imported by
// fragment.wgsl (raster, slit) and trace.wgsl. CPU twins: src/cpu/fragment.rs.

#import projection
#import constants

// ---- Materials and textures (layout: src/core/material.rs, packing: src/core/texture.rs) ----

// false: every material of the scene is untextured, opaque and double-sided, so a fragment's
// colour is its vertex colour and nothing is discarded; the renderer then compiles the material
// code out (a pipeline constant), which restores early depth testing.
override MATERIALS: bool = true;

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
    let top = mips[m.first_mip];
    let size = vec2<f32>(f32(top.width), f32(top.height));
    let lambda = log2(max(length(duv_dx * size), length(duv_dy * size)));
    let last = f32(m.mip_count - 1u);
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
        let level = mips[m.first_mip + u32(select(l0, l1, k >= 4u))];
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
    let m = materials[min(material, arrayLength(&materials) - 1u)];
    if (m.double_sided == 0u && !front_facing) {
        return vec4<f32>(-1.0);
    }
    var c = color;
    if (m.texture != NO_TEXTURE && m.mip_count > 0u) {
        c *= sample_texture(m, uv, duv_dx, duv_dy);
    }
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
