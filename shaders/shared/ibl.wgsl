// Image-based lighting from the prepared environment (split sum: prefiltered levels, SH
// irradiance, the lobe table; src/core/shading/environment.rs). CPU twin: src/cpu/fragment/ibl.rs.

#import projection
#import constants
#import surface_bindings
#import brdf

// ---- Image-based lighting (src/core/shading/environment.rs; twins in fragment.rs) ----

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
// Fdez-Agüera's multiple-scattering term; see src/core/shading/environment.rs).
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
