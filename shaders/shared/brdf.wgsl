// The glTF look's maths: the metallic-roughness BRDF (glTF 2.0 Appendix B), the punctual
// lights' radiance at a point, tone mapping. CPU twin: src/cpu/fragment/brdf.rs.

#import projection
#import constants
#import surface_bindings

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
    return tone(exposed(c_in));
}

// The linear colour × 2^EV, not negative: what `--hdr` writes.
fn exposed(c_in: vec3<f32>) -> vec3<f32> {
    return max(c_in * lighting.exposure, vec3<f32>(0.0));
}

// An exposed colour tone mapped for display, 0..1 (`TONEMAP_LINEAR`: as it is).
fn tone(c: vec3<f32>) -> vec3<f32> {
    if (lighting.tonemap == TONEMAP_LINEAR) {
        return c;
    }
    var out = c;
    if (lighting.tonemap == TONEMAP_PBR_NEUTRAL) {
        out = pbr_neutral(c);
    } else if (lighting.tonemap == TONEMAP_ACES) {
        out = (c * (2.51 * c + 0.03)) / (c * (2.43 * c + 0.59) + 0.14);
    }
    return clamp(out, vec3<f32>(0.0), vec3<f32>(1.0));
}
