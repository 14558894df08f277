//! The trace stage's twin check (tests/twins.rs): both eyes of traced frames on the GPU against
//! `cpu::trace`, with the rays traced and the triangle tests made.

use glam::Vec3;
use twister::core::scenes::builtin;
use twister::core::settings::Method;
use twister::{GpuScene, Projection, RenderSettings, Renderer, Scene, Vertical};

use super::{common, compare_eyes, frame_outputs, EyeOutputs, Twin};

pub struct Trace;

/// The demo room with its objects 1 and 2 made a tinted half mirror and a glass (transmission 0.8,
/// index 1.3): the ray tracer's mirror and refraction rays.
fn optics_demo() -> Scene {
    let mut scene = builtin::demo();
    scene.materials.push(twister::core::shading::material::Material { mirror: 0.6, ..Default::default() });
    scene.materials.push(twister::core::shading::material::Material {
        transmission: 0.8,
        ior: 1.3,
        ..Default::default()
    });
    let base = scene.materials.len() as u32 - 1;
    for v in &mut scene.vertices {
        if v.object == 1 || v.object == 2 {
            v.material = base + v.object - 1;
        }
    }
    scene
}

/// The demo room with two dense mirror spheres (3,200 triangles each), one ahead and one to the
/// right: objects with long level-of-detail chains.
fn lod_spheres() -> Scene {
    let mut scene = optics_demo();
    // Vertex material k is `materials[k − 1]`: optics_demo's mirror.
    let mirror = scene.materials.len() as u32 - 1;
    for (name, centre) in [("ahead", Vec3::new(0.0, 0.0, -1.6)), ("right", Vec3::new(1.5, -0.2, -0.3))] {
        let s = builtin::sphere_scene(3200, centre, 0.45, name);
        let first = scene.vertices.len();
        scene.add_mesh(name, &s.vertices, &s.indices);
        scene.vertices[first..].iter_mut().for_each(|v| v.material = mirror);
    }
    scene
}

/// A checker floor and a mirror sphere on it (the trace twin: textures by ray cones, reflected).
fn mirror_over_checker() -> Scene {
    let mut scene = common::checker_floor();
    scene.materials.push(twister::core::shading::material::Material { mirror: 0.7, ..Default::default() });
    let s = builtin::sphere_scene(800, Vec3::new(0.0, -0.3, -2.0), 0.5, "mirror");
    let first = scene.vertices.len();
    scene.add_mesh("mirror", &s.vertices, &s.indices);
    scene.vertices[first..].iter_mut().for_each(|v| v.material = 2);
    scene
}

/// The lit spheres and a mirror sphere in the studio, shown as the background too.
fn mirror_in_studio() -> Scene {
    let mut scene = common::lit_spheres();
    scene.environment = Some(common::studio(true));
    scene.materials.push(twister::core::shading::material::Material { mirror: 0.8, ..Default::default() });
    let s = builtin::sphere_scene(800, Vec3::new(0.0, 0.2, 1.6), 0.5, "mirror");
    let first = scene.vertices.len();
    scene.add_mesh("mirror", &s.vertices, &s.indices);
    let m = scene.materials.len() as u32;
    scene.vertices[first..].iter_mut().for_each(|v| v.material = m);
    scene
}

/// The tracer's cases on every panorama and view (the demo room).
fn trace_panorama_cases(cylinder: Projection, sphere: Projection) -> Vec<(String, (Scene, RenderSettings))> {
    let moved = RenderSettings::new(cylinder)
        .with_method(Method::Trace)
        .with_viewer(Vec3::new(0.3, 0.2, -0.4))
        .with_yaw_deg(35.0);
    vec![
        ("demo".into(), (builtin::demo(), RenderSettings::new(cylinder).with_method(Method::Trace))),
        ("demo, viewer moved and turned".into(), (builtin::demo(), moved)),
        (
            "demo on the sphere, converging".into(),
            (builtin::demo(), RenderSettings::new(sphere).with_method(Method::Trace)),
        ),
        (
            "demo seen by a tracked head".into(),
            (
                builtin::demo(),
                RenderSettings::new(Projection {
                    head: Some(twister::core::panoramas::head::Head { offset: [0.3, 0.1, -0.2], turn: 0.35 }),
                    ..cylinder
                })
                .with_method(Method::Trace),
            ),
        ),
        (
            "demo on a 200° fisheye".into(),
            (
                builtin::demo(),
                RenderSettings::new(Projection { fov: 200.0, ..Projection::fisheye(96) }).with_method(Method::Trace),
            ),
        ),
        (
            "demo on VR180".into(),
            (builtin::demo(), RenderSettings::new(Projection::vr180(96)).with_method(Method::Trace)),
        ),
        (
            "demo on a CAVE's floor".into(),
            (
                builtin::demo(),
                RenderSettings::new(common::cave(2, 64, glam::Vec3::new(0.2, 0.1, 0.3), 25.0))
                    .with_method(Method::Trace),
            ),
        ),
        (
            "demo on the cubemap".into(),
            (builtin::demo(), RenderSettings::new(Projection::cubemap(96)).with_method(Method::Trace)),
        ),
    ]
}

/// The tracer's cases of optics, lights, materials, textures and samples.
fn trace_shading_cases(cylinder: Projection) -> Vec<(String, (Scene, RenderSettings))> {
    vec![
        (
            "demo with a mirror and a glass object".into(),
            (optics_demo(), RenderSettings::new(cylinder).with_method(Method::Trace)),
        ),
        (
            "demo with a mirror, a glass and a point light".into(),
            (
                optics_demo(),
                RenderSettings::new(cylinder).with_method(Method::Trace).with_light(Some(Vec3::new(0.4, 1.2, -0.8))),
            ),
        ),
        (
            "demo with a mirror and a glass object, visual-field level of detail".into(),
            (
                optics_demo(),
                RenderSettings::new(cylinder)
                    .with_method(Method::Trace)
                    .with_trace_gaze(Some(twister::core::detail::visual_field::Gaze::new(30.0, 5.0))),
            ),
        ),
        (
            "two dense spheres among the demo's objects, per-ray polygon level (eq. 10)".into(),
            (
                lod_spheres(),
                RenderSettings::new(cylinder)
                    .with_method(Method::Trace)
                    .with_light(Some(Vec3::new(0.0, 1.5, 0.0)))
                    .with_trace_gaze(Some(twister::core::detail::visual_field::Gaze::new(-20.0, 0.0)))
                    .with_trace_min_share(0.1),
            ),
        ),
        (
            "a checker floor and a mirror sphere: textures filtered by ray cones, reflected too".into(),
            (mirror_over_checker(), RenderSettings::new(cylinder).with_method(Method::Trace)),
        ),
        (
            "lit spheres: the glTF BRDF under point, spot and directional lights".into(),
            (common::lit_spheres(), RenderSettings::new(cylinder).with_method(Method::Trace).with_exposure_ev(0.5)),
        ),
        (
            "a mirror sphere and lit spheres in the studio, shown as the background and in the mirror".into(),
            (mirror_in_studio(), RenderSettings::new(cylinder).with_method(Method::Trace)),
        ),
    ]
}

/// The tracer's cases of glTF maps, rooms, samples and anisotropy.
fn trace_material_cases(cylinder: Projection, sphere: Projection) -> Vec<(String, (Scene, RenderSettings))> {
    vec![
        (
            "every glTF map on quads, u mirrored on one, the tangent frame from the triangle".into(),
            (common::mapped_panels(), RenderSettings::new(cylinder).with_method(Method::Trace)),
        ),
        (
            "every glTF map, the file's tangents".into(),
            (common::with_tangents(common::mapped_panels()), RenderSettings::new(cylinder).with_method(Method::Trace)),
        ),
        (
            "box room".into(),
            (
                builtin::builtin_scene("builtin:box-room", &cylinder).unwrap(),
                RenderSettings::new(cylinder).with_method(Method::Trace),
            ),
        ),
        (
            "4 rays per pixel: a mirror and a glass, visual-field level of detail".into(),
            (
                optics_demo(),
                RenderSettings::new(cylinder)
                    .with_method(Method::Trace)
                    .with_samples(4)
                    .with_trace_gaze(Some(twister::core::detail::visual_field::Gaze::new(30.0, 5.0))),
            ),
        ),
        (
            "a striped floor, anisotropy 16 (the ray cone's ellipse)".into(),
            (
                common::striped_floor(),
                RenderSettings::new(sphere).with_method(Method::Trace).with_ambient(1.0).with_anisotropy(16),
            ),
        ),
        (
            "8 rays per pixel: the studio as background and in a mirror, on the sphere".into(),
            (mirror_in_studio(), RenderSettings::new(sphere).with_method(Method::Trace).with_samples(8)),
        ),
    ]
}

impl Twin for Trace {
    type Case = (Scene, RenderSettings);
    /// The images, and the rays traced and triangle tests made.
    type Output = (EyeOutputs, u64, u64);
    fn cases() -> Vec<(String, Self::Case)> {
        let cylinder = Projection { width: 192, height: 48, vertical: Vertical::Exact, ..Projection::default() };
        let sphere = Projection { convergence: Some(2.0), ..Projection::equirect(128) };
        let mut cases = trace_panorama_cases(cylinder, sphere);
        cases.extend(trace_shading_cases(cylinder));
        cases.extend(trace_material_cases(cylinder, sphere));
        cases
    }
    fn gpu(r: &Renderer, (scene, settings): &Self::Case) -> Self::Output {
        let gs = GpuScene::upload(&r.gpu, scene)
            .and_then(|g| g.with_built_bvh(&r.gpu, &scene.name, &twister::cpu::render::traced_bvh(scene, settings)))
            .expect("upload");
        let frame = r.render(&gs, &settings.with_measure_error(true).with_depth(true)).expect("render");
        let (rays, tests) = (frame.stats.rays_traced.expect("counted"), frame.stats.triangle_tests.expect("counted"));
        (frame_outputs(&frame), rays, tests)
    }
    fn cpu((scene, settings): &Self::Case) -> Self::Output {
        let frame = twister::cpu::render::render(scene, settings).expect("the twins' frame");
        let (rays, tests) = frame.traced.expect("traced");
        (frame.eyes.map(|img| (img.rgba, img.error, img.object, img.distance)), rays, tests)
    }
    fn compare((gpu, g_rays, g_tests): &Self::Output, (cpu, c_rays, c_tests): &Self::Output) -> Result<(), String> {
        // The same traversal: the same counts, but for rays where rounding decides a tie.
        let near = |a: u64, b: u64, share: f64| (a as f64 - b as f64).abs() <= share * b as f64;
        if !near(*g_rays, *c_rays, 0.002) || !near(*g_tests, *c_tests, 0.01) || *c_rays == 0 {
            return Err(format!("rays {g_rays} vs {c_rays}, triangle tests {g_tests} vs {c_tests}"));
        }
        compare_eyes(gpu, cpu, 200, 0.01)
    }
}
