//! The glTF look, first part (issue 17): the metallic-roughness BRDF against the specification's
//! formulas, punctual lights and emission read from glTF files, and stereo-correct highlights
//! (each eye sees a glossy sphere's highlight where its own eye point puts it).

mod common;

use glam::{Vec2, Vec3};
use twister::core::scenes::builtin;
use twister::core::scenes::load::load_scene;
use twister::core::shading::light::{Light, LightKind, LightingMode, Tonemap};
use twister::core::shading::material::Material;
use twister::cpu::fragment::{brdf, pixel_ray};
use twister::{Eye, Projection, RenderSettings, Scene, Vertical};

/// The glTF 2.0 BRDF written from the specification's Appendix B in its angle form: GGX
/// D = α² / (π cos⁴θ_h (α² + tan²θ_h)²), Smith G1 = 2 / (1 + √(1 + α² tan²θ)), Fresnel–Schlick,
/// f = (1 − F) c_diff / π + F D G1(l) G1(v) / (4 cos θ_l cos θ_v).
fn spec_brdf(n: Vec3, v: Vec3, l: Vec3, base: Vec3, metallic: f32, roughness: f32) -> Vec3 {
    let h = (l + v).normalize();
    let alpha = (roughness * roughness) as f64;
    let a2 = alpha * alpha;
    let cos_h = n.dot(h) as f64;
    let tan2 = |c: f64| (1.0 - c * c) / (c * c);
    let d = a2 / (std::f64::consts::PI * cos_h.powi(4) * (a2 + tan2(cos_h)).powi(2));
    let g1 = |c: f64| 2.0 / (1.0 + (1.0 + a2 * tan2(c)).sqrt());
    let (cl, cv) = (n.dot(l) as f64, n.dot(v) as f64);
    let spec = d * g1(cl) * g1(cv) / (4.0 * cl * cv);
    let f0 = Vec3::splat(0.04).lerp(base, metallic);
    let f = f0 + (Vec3::ONE - f0) * (1.0 - v.dot(h).abs()).powi(5);
    let c_diff = base * (1.0 - metallic);
    (Vec3::ONE - f) * c_diff / std::f32::consts::PI + f * spec as f32
}

#[test]
fn the_brdf_is_the_specifications_at_sampled_angles() {
    let mut checked = 0;
    for i in 0..400 {
        let a = i as f32 * 0.731;
        let n = Vec3::new(0.2 * a.sin(), 1.0, 0.3 * (1.3 * a).cos()).normalize();
        let v = Vec3::new((2.1 * a).sin(), 0.4 + 0.5 * (0.7 * a).cos().abs(), (1.7 * a).cos()).normalize();
        let l = Vec3::new((3.3 * a).cos(), 0.3 + 0.6 * (1.1 * a).sin().abs(), (0.9 * a).sin()).normalize();
        if n.dot(v) < 0.05 || n.dot(l) < 0.05 {
            continue;
        }
        let base = Vec3::new(0.9, 0.5 + 0.4 * a.sin(), 0.2);
        let (metallic, roughness) = ((i % 5) as f32 / 4.0, 0.1 + (i % 9) as f32 / 10.0);
        let (got, want) = (brdf(n, v, l, base, metallic, roughness), spec_brdf(n, v, l, base, metallic, roughness));
        assert!(
            (got - want).abs().max_element() <= 2e-3 * want.max_element().max(1.0),
            "sample {i}: {got} vs {want} (metallic {metallic}, roughness {roughness})"
        );
        checked += 1;
    }
    assert!(checked > 150, "{checked} samples");
}

/// The weighted centre (x, y) of the pixels whose value is at least 90 % of the largest.
fn peak_centre(values: &[f32], width: u32) -> Vec2 {
    let max = values.iter().cloned().fold(0.0f32, f32::max);
    assert!(max > 0.0, "no highlight");
    let (mut sum, mut weight) = (Vec2::ZERO, 0.0);
    for (i, &v) in values.iter().enumerate() {
        if v >= 0.9 * max {
            let w = v - 0.9 * max + 1e-6;
            sum += w * Vec2::new((i as u32 % width) as f32 + 0.5, (i as u32 / width) as f32 + 0.5);
            weight += w;
        }
    }
    sum / weight
}

/// A black glossy sphere under a directional light shows only its specular highlight. Each eye
/// must see it where the GGX lobe peaks for that eye's own viewing rays (ray–sphere hits with the
/// exact normal, an oracle that shares no code with the renderer) — not where it would be seen
/// from the centre — so the highlight's place differs between the eyes as the eye offsets say.
#[test]
fn each_eye_sees_the_highlight_where_its_own_eye_point_puts_it() {
    let projection =
        Projection { width: 1024, height: 256, vertical: Vertical::Exact, eye_radius: 0.2, ..Projection::default() };
    let (centre, radius) = (Vec3::new(0.0, 0.0, -1.2), 0.4);
    let mut scene = builtin::sphere_scene(20000, centre, radius, "glossy");
    scene.materials = vec![Material { metallic: 0.0, roughness: 0.25, ..Default::default() }];
    for v in &mut scene.vertices {
        v.material = 1;
        v.color = [0.0, 0.0, 0.0, 1.0];
    }
    let to_light = Vec3::new(0.45, 0.6, 0.66).normalize();
    scene.lights = vec![Light {
        kind: LightKind::Directional,
        position: Vec3::ZERO,
        direction: -to_light,
        color: Vec3::splat(1.0),
        range: None,
        inner_cone: 0.0,
        outer_cone: 0.0,
    }];
    let settings = RenderSettings::new(projection).with_tonemap(Tonemap::None).with_exposure_ev(-2.0);
    let frame = common::render(&scene, &settings);
    let alpha2 = (0.25f32 * 0.25).powi(2);
    let ggx = |n: Vec3, v: Vec3| {
        let c = n.dot((to_light + v).normalize()).max(0.0);
        alpha2 / (c * c * (alpha2 - 1.0) + 1.0).powi(2)
    };
    let mut centres = Vec::new();
    for eye in Eye::BOTH {
        let img = frame.eye(eye);
        let rendered: Vec<f32> = img.rgba.chunks(4).map(|p| p[0] as f32 + p[1] as f32 + p[2] as f32).collect();
        let got = peak_centre(&rendered, projection.width);
        // The lobe along each pixel's own ray, seen from its eye point, and from the centre.
        let (mut own, mut central) = (Vec::new(), Vec::new());
        for i in 0..(projection.width * projection.height) {
            let xy = Vec2::new((i % projection.width) as f32 + 0.5, (i / projection.width) as f32 + 0.5);
            let (o, d) = pixel_ray(&projection, eye, xy);
            let oc = o - centre;
            let b = oc.dot(d);
            let disc = b * b - (oc.length_squared() - radius * radius);
            let (mut a, mut c) = (0.0, 0.0);
            let t = -b - disc.max(0.0).sqrt();
            if disc > 0.0 && t > 0.0 {
                let p = o + t * d;
                let n = (p - centre).normalize();
                a = ggx(n, -d);
                c = ggx(n, (-p).normalize());
            }
            own.push(a);
            central.push(c);
        }
        let (want, from_centre) = (peak_centre(&own, projection.width), peak_centre(&central, projection.width));
        eprintln!(
            "{eye:?}: highlight at {got}, its eye point predicts {want}, the centre would put it at {from_centre}"
        );
        assert!(got.distance(want) < 1.5, "{eye:?}: highlight at {got}, predicted {want}");
        assert!(got.distance(from_centre) > 3.0, "{eye:?}: the centre's view would put it at {from_centre} too");
        // Where the highlight sits on the sphere's image: relative to the sphere's centre there.
        let q = projection.project(centre, eye).unwrap();
        let [cx, cy] = projection.to_pixel(q.u, q.v);
        centres.push(got - Vec2::new(cx, cy));
    }
    eprintln!("highlight relative to the sphere's centre: left {}, right {}", centres[0], centres[1]);
    assert!(centres[0].distance(centres[1]) > 3.0, "the eyes see the highlight at the same place: {centres:?}");
}

fn gltf(path: &str) -> Scene {
    let p = Projection::default();
    load_scene(common::asset(&format!("gltf/{path}")).to_str().unwrap(), &p).expect("load")
}

#[test]
fn punctual_lights_and_pbr_factors_are_read_from_gltf() {
    if !common::assets_present() {
        return;
    }
    let lamp = gltf("LightsPunctualLamp/glTF/LightsPunctualLamp.gltf");
    assert_eq!(lamp.lights.len(), 5, "{:?}", lamp.lights);
    assert!(lamp.lights.iter().all(|l| l.kind == LightKind::Point && l.color.is_finite()));
    // Intensities 15, 1.5, 80, 80 and 180 cd times the colours.
    let mut peaks: Vec<f32> = lamp.lights.iter().map(|l| l.color.max_element()).collect();
    peaks.sort_by(f32::total_cmp);
    assert!((peaks[0] - 1.5).abs() < 1e-3 && (peaks[4] - 180.0).abs() < 1e-2, "{peaks:?}");
    let spheres = gltf("MetalRoughSpheresNoTextures/glTF-Binary/MetalRoughSpheresNoTextures.glb");
    let (mut metallic, mut roughness): (Vec<f32>, Vec<f32>) =
        spheres.materials.iter().map(|m| (m.metallic, m.roughness)).unzip();
    for v in [&mut metallic, &mut roughness] {
        v.sort_by(f32::total_cmp);
        v.dedup_by(|a, b| (*a - *b).abs() < 1e-3);
    }
    assert!(metallic.len() >= 5 && roughness.len() >= 5, "{metallic:?} {roughness:?}");
    assert!(metallic[0] < 0.05 && *metallic.last().unwrap() > 0.95, "{metallic:?}");
}

/// EmissiveStrengthTest: five cubes of emissive colour [0.1, 0.5, 0.9] at strengths 1, 2, 4, 8
/// and 16 (KHR_materials_emissive_strength) grow brighter from left to right (green channel:
/// 0.5 × strength, tone mapped).
#[test]
fn emissive_strength_orders_the_cubes_brightness() {
    if !common::assets_present() {
        return;
    }
    let glb = common::asset("gltf/EmissiveStrengthTest/glTF-Binary/EmissiveStrengthTest.glb");
    let p = Projection { width: 1200, height: 300, ..Projection::default() };
    let mut scene = load_scene(glb.to_str().unwrap(), &p).expect("load");
    let mut strengths: Vec<f32> = scene.materials.iter().map(|m| m.emissive_b / 0.9).collect();
    strengths.sort_by(f32::total_cmp);
    strengths.dedup_by(|a, b| (*a - *b).abs() < 1e-3);
    assert!(strengths.windows(2).all(|w| w[1] > w[0]) && strengths.len() >= 5, "{strengths:?}");
    scene.fit(3.0, &p).unwrap();
    let settings = RenderSettings::new(p).with_lighting(LightingMode::Pbr).with_ambient(0.0).with_measure_error(true);
    let frame = common::render(&scene, &settings);
    let objects = &frame.measurement.as_ref().unwrap().object[0];
    // Per object: mean x and mean brightness (blue channel) of its pixels.
    let mut per: std::collections::BTreeMap<u32, (f64, f64, f64)> = Default::default();
    for (i, &o) in objects.iter().enumerate() {
        if o != 0 {
            let e = per.entry(o).or_default();
            e.0 += (i as u32 % p.width) as f64;
            e.1 += frame.left.rgba[4 * i + 1] as f64;
            e.2 += 1.0;
        }
    }
    // The emissive cubes (the scene's other objects are dark).
    let mut cubes: Vec<(f64, f64)> =
        per.values().filter(|e| e.2 > 50.0 && e.1 > 10.0 * e.2).map(|e| (e.0 / e.2, e.1 / e.2)).collect();
    cubes.sort_by(|a, b| a.0.total_cmp(&b.0));
    eprintln!("cubes (x, green level): {cubes:?}");
    assert!(cubes.len() >= 5, "{cubes:?}");
    assert!(
        cubes.windows(2).all(|w| w[1].1 >= w[0].1 - 0.5) && cubes[0].1 + 20.0 < cubes[cubes.len() - 1].1,
        "{cubes:?}"
    );
}

/// The ray tracer shades with the same BRDF and lights as the drawing stages: on the lit spheres
/// (point, spot and directional lights; dielectric, metal, emissive) its colours are the
/// rasterizer's where both show the same sphere.
#[test]
fn the_ray_tracer_lights_the_spheres_as_the_rasterizer_does() {
    use twister::core::settings::{Method, Split};
    let p = Projection { width: 480, height: 120, vertical: Vertical::Exact, ..Projection::default() };
    let scene = common::lit_spheres();
    let settings = RenderSettings::new(p).with_measure_error(true);
    let drawn = common::render(&scene, &settings.with_method(Method::Adaptive(Split::Error)));
    let r = common::renderer();
    let gs = twister::GpuScene::upload(&r.gpu, &scene).and_then(|g| g.with_bvh(&r.gpu, &scene)).unwrap();
    let traced = r.render(&gs, &settings.with_method(Method::Trace)).unwrap();
    let (mut n, mut sum, mut worst) = (0u64, 0u64, 0u8);
    for (k, eye) in Eye::BOTH.into_iter().enumerate() {
        let (a, b) = (drawn.eye(eye), traced.eye(eye));
        let (oa, ob) =
            (&drawn.measurement.as_ref().unwrap().object[k], &traced.measurement.as_ref().unwrap().object[k]);
        for i in 0..(p.width * p.height) as usize {
            if oa[i] == 0 || oa[i] != ob[i] {
                continue;
            }
            for c in 0..3 {
                let d = a.rgba[4 * i + c].abs_diff(b.rgba[4 * i + c]);
                sum += d as u64;
                worst = worst.max(d);
            }
            n += 1;
        }
    }
    let mean = sum as f64 / (3 * n) as f64;
    eprintln!(
        "lit spheres: trace vs adaptive, mean colour difference {mean:.3} levels, worst {worst}, over {n} pixels"
    );
    assert!(n > 3000 && mean < 1.0, "{n} pixels, mean {mean}");
}

/// Under `--lighting auto` a physically based scene (a glTF file's) is lit by the BRDF even with
/// no lights and no environment (`--environment none`): an emissive white ball with a black base
/// colour shows its emission, as with `--lighting pbr` (it used to fall back to the headlight and
/// render black). The same scene not physically based (an OBJ's) keeps the paper's headlight.
#[test]
fn auto_lighting_keeps_a_physically_based_scenes_emission_without_lights_or_environment() {
    let mut scene = Scene::new("emissive ball");
    scene.materials = vec![Material { emissive_r: 1.0, emissive_g: 1.0, emissive_b: 1.0, ..Default::default() }];
    let ball = builtin::sphere_scene(400, Vec3::new(0.0, 0.0, -2.0), 0.5, "ball");
    scene.add_mesh("ball", &ball.vertices, &ball.indices);
    for v in &mut scene.vertices {
        v.material = 1;
        v.color = [0.0, 0.0, 0.0, 1.0];
    }
    scene.physically_based = true;
    assert!(scene.lights.is_empty() && scene.environment.is_none());
    let s = RenderSettings::new(Projection { width: 256, height: 64, ..Projection::default() }).with_ambient(0.0);
    let auto = common::render(&scene, &s);
    let pbr = common::render(&scene, &s.with_lighting(LightingMode::Pbr));
    assert!(auto.left.rgba == pbr.left.rgba && auto.right.rgba == pbr.right.rgba, "auto lights it as pbr does");
    let centre = auto.left.pixel(128, 32);
    assert!(centre[..3].iter().all(|&c| c > 150), "the emission shows: {centre:?}");
    scene.physically_based = false;
    let headlight = common::render(&scene, &s);
    assert!(headlight.left.pixel(128, 32)[..3].iter().all(|&c| c < 60), "{:?}", headlight.left.pixel(128, 32));
}
