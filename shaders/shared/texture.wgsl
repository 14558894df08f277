// Texture sampling from the packed texel table (every wrap, filter and mipmap mode exact per
// texture; the level from the screen derivatives of the texture coordinates). CPU twin:
// src/cpu/fragment/texture.rs.

#import constants
#import surface_bindings

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
// derivatives of uv, anisotropically (EXT_texture_filter_anisotropic's reference): P_max and
// P_min the longer and shorter footprint axis in level-0 texels, N = min(⌈P_max / P_min⌉,
// `lighting.anisotropy`) probes spaced evenly along the longer axis, each at level of detail
// λ = log2(P_max / N) (one probe: the longest axis, isotropic); λ ≤ 0 magnifies (magnification
// filter, level 0), else the minification filter on level 0 (no mipmaps), the nearest level, or
// a blend of the two nearest. Filtering is done by hand with one loop over (probe, level,
// corner), so every wrap mode is exact and the function has one texel read (lavapipe inlines
// every call).
fn sample_texture(m: Material, uv_in: vec2<f32>, duv_dx: vec2<f32>, duv_dy: vec2<f32>) -> vec4<f32> {
    return sample_levels(m, m.first_mip, m.mip_count, uv_in, duv_dx, duv_dy);
}

// The number of probes along the footprint's longer axis (1 .. `lighting.anisotropy`).
fn anisotropic_probes(p_max: f32, p_min: f32) -> u32 {
    if (lighting.anisotropy <= 1u || !(p_max > p_min)) {
        return 1u;
    }
    return u32(clamp(ceil(p_max / max(p_min, p_max / 16.0)), 1.0, f32(lighting.anisotropy)));
}

// The same for the texture whose mip chain starts at `first_mip` (the material's maps), with the
// material's sampler.
fn sample_levels(m: Material, first_mip: u32, mip_count: u32, uv_in: vec2<f32>, duv_dx: vec2<f32>,
                 duv_dy: vec2<f32>) -> vec4<f32> {
    let top = mips[first_mip];
    let size = vec2<f32>(f32(top.width), f32(top.height));
    let px = length(duv_dx * size);
    let py = length(duv_dy * size);
    let p_max = max(px, py);
    let probes = anisotropic_probes(p_max, min(px, py));
    let axis = select(duv_dy, duv_dx, px >= py);
    let lambda = log2(p_max / f32(probes));
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
    var out = vec4<f32>(0.0);
    for (var k = 0u; k < 8u * probes; k++) {
        let level_weight = select(1.0 - t, t, (k & 4u) != 0u);
        if (!(level_weight > 0.0)) {
            continue;
        }
        var probe_uv = uv_in;
        if (probes > 1u) {
            probe_uv += axis * ((f32(k / 8u) + 0.5) / f32(probes) - 0.5);
        }
        let uv = clamp(probe_uv, vec2<f32>(-1e6), vec2<f32>(1e6));
        let level = mips[first_mip + u32(select(l0, l1, (k & 4u) != 0u))];
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
    return out / f32(probes);
}
