//! The glTF look's maths, CPU twin of `shaders/shared/brdf.wgsl`: the metallic-roughness BRDF
//! (glTF 2.0 Appendix B) and the punctual lights' radiance at a point (tone mapping:
//! `core::shading::light::tonemap`).

use glam::Vec3;

use crate::core::shading::light::{GpuLight, LightKind};

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
