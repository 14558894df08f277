//! The generic twin test: every stage of the registry (`twister::shader::STAGES`) runs on the
//! GPU and through its CPU twin on the same cases, and the outputs must agree, one test per
//! stage. A stage is added by implementing [`Twin`] for it and naming it in `twin_of` and
//! `twin_tests!`; a registered stage without them fails `every_registered_stage_has_a_twin_test`.

mod common;
#[path = "twins/display.rs"]
mod display;
#[path = "twins/frame.rs"]
mod frame;
#[path = "twins/shadow.rs"]
mod shadow;
#[path = "twins/skin.rs"]
mod skin;
#[path = "twins/slit.rs"]
mod slit;
#[path = "twins/subdivide.rs"]
mod subdivide;
#[path = "twins/trace.rs"]
mod trace;

use glam::Vec3;
use rand::{Rng, SeedableRng};
use twister::core::scenes::builtin;
use twister::core::settings::{Method, Split};
use twister::core::shading::light::Tonemap;
use twister::cpu::reduce_error::reduce_error;
use twister::encoding::types::ErrorStats;
use twister::shader::STAGES;
use twister::{Eye, Frame, Projection, RenderSettings, Renderer, Scene, Vertical};

/// One stage's GPU-against-twin check.
trait Twin {
    type Case;
    type Output;
    /// Whether the cases read the third-party assets (the check does not run without them).
    const NEEDS_ASSETS: bool = false;
    /// Named cases.
    fn cases() -> Vec<(String, Self::Case)>;
    fn gpu(r: &Renderer, case: &Self::Case) -> Self::Output;
    fn cpu(case: &Self::Case) -> Self::Output;
    /// Err with what differs.
    fn compare(gpu: &Self::Output, cpu: &Self::Output) -> Result<(), String>;
}

/// Runs every case of a stage's twin check; returns how many ran, or every case that differs.
fn check<T: Twin>(stage: &str) -> Result<usize, Vec<String>> {
    let r = common::renderer();
    if T::NEEDS_ASSETS && !common::assets_present() {
        eprintln!("{stage}: not checked without the assets");
        return Ok(0);
    }
    let cases = T::cases();
    assert!(!cases.is_empty(), "{stage}: no twin cases");
    let differ: Vec<String> = cases
        .iter()
        .filter_map(|(name, case)| {
            let (gpu, cpu) = (T::gpu(r, case), T::cpu(case));
            T::compare(&gpu, &cpu).err().map(|e| format!("{stage}, {name}: GPU and CPU twin differ: {e}"))
        })
        .collect();
    if differ.is_empty() {
        Ok(cases.len())
    } else {
        Err(differ)
    }
}

/// A stage's twin check: how many cases agree, or what differs.
type TwinCheck = fn(&str) -> Result<usize, Vec<String>>;

/// The twin check of a registered stage, by name.
fn twin_of(stage: &str) -> Option<TwinCheck> {
    Some(match stage {
        "project_points" => check::<ProjectPoints>,
        "subdivide" => check::<subdivide::Subdivide>,
        "raster" => check::<Raster>,
        "slit" => check::<slit::Slit>,
        "trace" => check::<trace::Trace>,
        "shadow" => check::<shadow::Shadow>,
        "skin" => check::<skin::Skin>,
        "reduce_error" => check::<ReduceError>,
        "display" => check::<display::Display>,
        _ => return None,
    })
}

/// A stage's twin check as a test: every case that differs is reported (not only the first).
fn assert_twin(stage: &str) {
    let run = twin_of(stage).unwrap_or_else(|| panic!("no twin check for stage {stage}"));
    match run(stage) {
        Ok(n) => eprintln!("{stage}: {n} cases agree"),
        Err(differ) => panic!("{} cases differ:\n{}", differ.len(), differ.join("\n")),
    }
}

/// One test per stage (`cargo test --test twins subdivide` runs one).
macro_rules! twin_tests {
    ($($test:ident => $stage:literal),* $(,)?) => {
        $(
            #[test]
            fn $test() {
                assert_twin($stage);
            }
        )*
        /// The stages the tests above check.
        const TESTED: &[&str] = &[$($stage),*];
    };
}

twin_tests! {
    project_points_matches_its_cpu_twin => "project_points",
    subdivide_matches_its_cpu_twin => "subdivide",
    raster_matches_its_cpu_twin => "raster",
    slit_matches_its_cpu_twin => "slit",
    trace_matches_its_cpu_twin => "trace",
    shadow_matches_its_cpu_twin => "shadow",
    skin_matches_its_cpu_twin => "skin",
    reduce_error_matches_its_cpu_twin => "reduce_error",
    display_matches_its_cpu_twin => "display",
}

/// Every registered stage has a twin check and a test of its own.
#[test]
fn every_registered_stage_has_a_twin_test() {
    for stage in STAGES {
        assert!(
            twin_of(stage.name).is_some() && TESTED.contains(&stage.name),
            "stage {} has no twin test: implement Twin for it in tests/twins.rs and add it to twin_tests!",
            stage.name
        );
    }
}

// ---- project_points ----

struct ProjectPoints;

impl Twin for ProjectPoints {
    type Case = (Projection, Eye, Vec<Vec3>);
    type Output = (Projection, Vec<[f32; 4]>);
    fn cases() -> Vec<(String, Self::Case)> {
        let mut rng = rand::rngs::StdRng::seed_from_u64(1);
        let points: Vec<Vec3> = (0..5000)
            .map(|_| {
                let radius: f32 = rng.random_range(0.05f32..40.0);
                let theta: f32 = rng.random_range(-std::f32::consts::PI..std::f32::consts::PI);
                Vec3::new(radius * theta.sin(), rng.random_range(-3.0f32..3.0), -radius * theta.cos())
            })
            .collect();
        let mut out = Vec::new();
        for vertical in [Vertical::Paper, Vertical::Exact] {
            for eye in Eye::BOTH {
                let p = Projection { vertical, ..Projection::default() };
                out.push((format!("{vertical:?} {eye:?}"), (p, eye, points.clone())));
            }
        }
        // The full sphere: points in every direction (the poles and the pole merge's fade).
        let sphere_points: Vec<Vec3> = (0..5000)
            .map(|_| {
                let (a, b): (f32, f32) =
                    (rng.random_range(-1.0..1.0), rng.random_range(-std::f32::consts::PI..std::f32::consts::PI));
                let d = 10f32.powf(rng.random_range(-1.0..1.6));
                let h = (1.0 - a * a).sqrt();
                Vec3::new(d * h * b.sin(), d * a, -d * h * b.cos())
            })
            .collect();
        for (convergence, pole_merge) in [(None, Some((60.0, 75.0))), (Some(1.5), Some((45.0, 80.0))), (None, None)] {
            for eye in Eye::BOTH {
                let p = Projection { convergence, pole_merge, ..Projection::equirect(4096) };
                out.push((format!("sphere {convergence:?} {pole_merge:?} {eye:?}"), (p, eye, sphere_points.clone())));
            }
        }
        // VR180: the same points, half of them behind (outside the image).
        for eye in Eye::BOTH {
            out.push((format!("vr180 {eye:?}"), (Projection::vr180(2048), eye, sphere_points.clone())));
            let head = twister::core::panoramas::head::Head { offset: [0.3, 0.1, -0.2], turn: 0.35 };
            let tracked = Projection { vertical: Vertical::Exact, head: Some(head), ..Projection::default() };
            out.push((format!("a tracked head {eye:?}"), (tracked, eye, points.clone())));
            let dome = Projection { fov: 240.0, dome_tilt: 20.0, ..Projection::fisheye(2048) };
            out.push((format!("fisheye 240° tilted 20° {eye:?}"), (dome, eye, sphere_points.clone())));
            out.push((format!("cubemap {eye:?}"), (Projection::cubemap(3 * 1024), eye, sphere_points.clone())));
            // The CAVE: points seen through the wall and around it, before and beyond it.
            let cave = common::cave(0, 2048, Vec3::new(0.2, 0.1, 0.3), 25.0);
            let [corner, right, up] = cave.cave_wall();
            let mut rng = rand::rngs::StdRng::seed_from_u64(3);
            let through: Vec<Vec3> = (0..5000)
                .map(|_| {
                    let (a, b, t) =
                        (rng.random_range(-0.2..1.2), rng.random_range(-0.2..1.2), rng.random_range(0.2..5.0));
                    t * (corner + a * right + b * up)
                })
                .collect();
            out.push((format!("a CAVE's front wall {eye:?}"), (cave, eye, through)));
        }
        out
    }
    fn gpu(r: &Renderer, (p, eye, points): &Self::Case) -> Self::Output {
        (*p, r.project_points(p, *eye, points).unwrap())
    }
    fn cpu((p, eye, points): &Self::Case) -> Self::Output {
        (*p, twister::cpu::project_points::project_points(p, *eye, points))
    }
    /// Within a thousandth of a pixel on or near the image; far off it (near the eye circle,
    /// |y| up to 10⁵ px) f32 itself resolves only ~1e-7 relative.
    fn compare((p, gpu): &Self::Output, (_, cpu): &Self::Output) -> Result<(), String> {
        if cpu.iter().filter(|c| c[3] == 1.0).count() < 4500 {
            return Err("too few points seen to test".into());
        }
        for (i, (g, c)) in gpu.iter().zip(cpu).enumerate() {
            if g[3] != c[3] {
                return Err(format!("point {i}: seen on one side only"));
            }
            if c[3] == 0.0 {
                continue;
            }
            let near_image = c[1] > -(p.height as f32) && c[1] < 2.0 * p.height as f32;
            // Beyond the fisheye's circle (towards the point opposite its axis, where the image
            // folds) the angle around the axis is ill-conditioned: a hundredth of a pixel.
            let tolerance = match (near_image, p.shows_pixel(c[0], c[1])) {
                (true, true) => 1e-3,
                (true, false) => 1e-2,
                (false, _) => 1e-6 * c[1].abs(),
            };
            // On the sphere, columns near the poles are short: compare the distance they make.
            let (_, lat) = p.pixel_to_screen(c[0], c[1]);
            let equirect = p.panorama.is_equirectangular();
            let squeeze = if equirect { lat.cos() } else { 1.0 };
            if !(p.wrapped_dx(g[0], c[0]) * squeeze < tolerance.max(1e-3) && (g[1] - c[1]).abs() < tolerance) {
                return Err(format!("point {i}: GPU {g:?}, CPU {c:?}"));
            }
        }
        Ok(())
    }
}

// ---- raster (with the fragment module and the error pass) ----

struct Raster;

/// Per eye: colour (RGBA8), display-position error (−1 where none), object id + 1 and the
/// distance from the pixel's eye point (+∞ where none).
type EyeOutputs = [(Vec<u8>, Vec<f32>, Vec<u32>, Vec<f32>); 2];

fn measured(scene: &Scene, settings: &RenderSettings) -> Frame {
    common::render(scene, &settings.with_measure_error(true).with_depth(true))
}

fn frame_outputs(frame: &Frame) -> EyeOutputs {
    let m = frame.measurement.as_ref().expect("measured");
    let depth = frame.depth.as_ref().expect("depth measured");
    [0, 1].map(|k| (frame.eye(Eye::BOTH[k]).rgba.clone(), m.error[k].clone(), m.object[k].clone(), depth[k].clone()))
}

/// How far a pixel's display-position error may differ between the GPU and the twin: 0.02 px
/// (a hardware GPU's interpolation differs from the twin's by ~0.002 px), in the error's unit:
/// with `error_angle`, the arcminutes 0.02 px spans on the equator.
fn error_tolerance(settings: &RenderSettings) -> f32 {
    let p = settings.projection();
    if settings.measure.error_angle {
        0.02 * 360.0 * 60.0 / p.width as f32
    } else {
        0.02
    }
}

/// Only pixels on triangle edges may differ (tie-breaking and rounding at coverage edges): at
/// most `1/share` of the pixels in colour, object, distance or error (beyond `error_tolerance`
/// where both drew a surface).
fn compare_eyes(gpu: &EyeOutputs, cpu: &EyeOutputs, share: usize, error_tolerance: f32) -> Result<(), String> {
    for (k, ((gc, ge, go, gd), (cc, ce, co, cd))) in gpu.iter().zip(cpu).enumerate() {
        let total = go.len();
        let distance = gd
            .iter()
            .zip(cd)
            .filter(|(g, c)| {
                // 0.1 %, or 0.2 mm: thin needles near the axis interpolate a few cm away.
                let same = (g.is_infinite() && c.is_infinite()) || (*g - *c).abs() <= 1e-3 * c.abs() + 2e-4;
                !same
            })
            .count();
        if distance * share > total {
            return Err(format!("{:?}: {distance} of {total} distances differ", Eye::BOTH[k]));
        }
        let colour =
            gc.chunks(4).zip(cc.chunks(4)).filter(|(a, b)| a.iter().zip(*b).any(|(x, y)| x.abs_diff(*y) > 2)).count();
        let object = go.iter().zip(co).filter(|(a, b)| a != b).count();
        let both: Vec<f32> =
            ge.iter().zip(ce).filter(|(g, c)| **g >= 0.0 && **c >= 0.0).map(|(g, c)| (g - c).abs()).collect();
        let error = both.iter().filter(|d| **d > error_tolerance).count();
        if colour * share > total || object * share > total || error * share > total || both.len() * 4 < total / 10 {
            return Err(format!(
                "{:?}: {colour} colours, {object} objects and {error} errors of {total} pixels differ ({} compared, worst error difference {} px)",
                Eye::BOTH[k],
                both.len(),
                both.iter().fold(0.0f32, |a, b| a.max(*b))
            ));
        }
    }
    Ok(())
}

/// A raster case: the scene and its settings (every target compared: colour, error, object,
/// distance).
type RasterCase = (Scene, RenderSettings);

/// The raster twin's geometry cases: the demo and the evaluation triangle with each split rule
/// in both vertical models, the full sphere, eyes just under a ceiling.
fn raster_geometry_cases() -> Vec<(String, RasterCase)> {
    let mut out = Vec::new();
    for vertical in [Vertical::Paper, Vertical::Exact] {
        let projection = Projection { width: 400, height: 100, vertical, ..Projection::default() };
        out.push((format!("demo {vertical:?}"), (builtin::demo(), RenderSettings::new(projection))));
        let triangle = builtin::builtin_scene("builtin:triangle@3", &projection).unwrap();
        for method in [Method::Vertex, Method::Adaptive(Split::Length), Method::Adaptive(Split::Error)] {
            let settings = RenderSettings::new(projection).with_method(method);
            out.push((format!("triangle@3 {} {vertical:?}", method.name()), (triangle.clone(), settings)));
        }
    }
    // The full sphere, with the error in pixels and as an angle (arcminutes).
    let sphere = Projection::equirect(320);
    out.push(("demo on the sphere".into(), (builtin::demo(), RenderSettings::new(sphere))));
    out.push(("demo on VR180".into(), (builtin::demo(), RenderSettings::new(Projection::vr180(128)))));
    let head = twister::core::panoramas::head::Head { offset: [0.3, 0.1, -0.2], turn: 0.35 };
    let tracked =
        Projection { width: 256, height: 64, vertical: Vertical::Exact, head: Some(head), ..Projection::default() };
    out.push(("demo seen by a tracked head".into(), (builtin::demo(), RenderSettings::new(tracked))));
    let dome = Projection { fov: 240.0, dome_tilt: 20.0, ..Projection::fisheye(128) };
    out.push(("demo on a tilted 240° fisheye".into(), (builtin::demo(), RenderSettings::new(dome))));
    out.push(("demo on the cubemap".into(), (builtin::demo(), RenderSettings::new(Projection::cubemap(192)))));
    // A triangle 2 m ahead reaching ±60° across and 50° up and down.
    let mut triangle = Scene::new("big triangle");
    let corner = |p: [f32; 3]| twister::core::scenes::scene::SceneVertex {
        position: p,
        normal: [0.0, 0.0, 1.0],
        color: [0.8, 0.7, 0.6, 1.0],
        ..Default::default()
    };
    triangle.add_mesh(
        "t",
        &[corner([-3.5, -2.4, -2.0]), corner([3.5, -2.4, -2.0]), corner([0.0, 2.4, -2.0])],
        &[0, 1, 2],
    );
    for angle in [false, true] {
        let settings = RenderSettings::new(sphere).with_method(Method::Vertex).with_error_angle(angle);
        out.push((format!("triangle@3 on the sphere, angle {angle}"), (triangle.clone(), settings)));
    }
    // Eyes 5 cm under a ceiling in the exact vertical model: needles reaching from the
    // ceiling's image to points inside the eye circle, millions of pixels above it, drawn
    // within GUARD_BAND_PX of the image (a real GPU left a pixel between such needles).
    let cube = builtin::closed_box("cube", Vec3::splat(-1.0), Vec3::splat(1.0));
    let exact = Projection { width: 192, height: 192, vertical: Vertical::Exact, ..Projection::default() };
    let settings = RenderSettings::new(exact).with_viewer(Vec3::new(0.0, 0.95, 0.0)).with_method(Method::Fixed(7));
    out.push(("cube, eyes under the ceiling, exact".into(), (cube, settings)));
    out
}

/// The raster twin's multisampled cases (4 samples, which every adapter draws itself): the
/// coverage of edges and the resolve, alpha to coverage for MASK and BLEND materials.
fn raster_sample_cases() -> Vec<(String, RasterCase)> {
    let projection = Projection { width: 400, height: 100, vertical: Vertical::Exact, ..Projection::default() };
    let settings = RenderSettings::new(projection).with_samples(4);
    let mut blended = builtin::demo();
    blended.materials.push(twister::core::shading::material::Material {
        alpha_mode: twister::core::shading::material::AlphaMode::Blend as u32,
        ..Default::default()
    });
    let blend = blended.materials.len() as u32;
    for v in blended.vertices.iter_mut().filter(|v| v.object == 1 || v.object == 2) {
        v.material = blend;
        v.color[3] = if v.object == 1 { 0.5 } else { 0.3 };
    }
    let screen = common::ball_over_floor(twister::core::shading::light::LightKind::Spot, true);
    vec![
        ("demo, 4 samples".into(), (builtin::demo(), settings)),
        ("demo with two BLEND objects, 4 samples".into(), (blended, settings)),
        ("ball and MASK screen, 4 samples: alpha to coverage".into(), (screen, settings.with_shadow_map_size(512))),
        (
            "demo on the sphere, 4 samples".into(),
            (builtin::demo(), RenderSettings::new(Projection::equirect(256)).with_samples(4)),
        ),
    ]
}

/// The raster twin's look cases: image-based lighting, every glTF map, shadow maps, the BRDF
/// under each light kind and tone mapping.
fn raster_look_cases() -> Vec<(String, RasterCase)> {
    let mut out = Vec::new();
    // Image-based lighting: the lit spheres also in the neutral studio, the viewer turned
    // (the environment stays put in the scene frame). Shadow maps of 256² texels in these
    // cases: the twin draws them on the CPU.
    let mut studio = common::lit_spheres();
    studio.environment = Some(common::studio(false));
    let settings = RenderSettings::new(Projection { width: 400, height: 100, ..Projection::default() })
        .with_yaw_deg(-25.0)
        .with_viewer(Vec3::new(0.1, 0.2, 0.0));
    out.push(("lit spheres in the neutral studio".into(), (studio.clone(), settings.with_shadow_map_size(256))));
    // The environment as the background too (the triangle drawn first), on the sphere.
    studio.environment = Some(common::studio(true));
    let sphere = RenderSettings::new(Projection::equirect(256)).with_yaw_deg(30.0);
    out.push((
        "lit spheres, the studio as the background, on the sphere".into(),
        (studio, sphere.with_shadow_map_size(256)),
    ));
    // Every glTF map (metallic-roughness, normal, occlusion, emissive), u mirrored on the
    // middle quad, under a directional light and the studio.
    let mut panels = common::mapped_panels();
    panels.environment = Some(common::studio(false));
    let settings = RenderSettings::new(Projection { width: 480, height: 120, ..Projection::default() });
    out.push(("mapped panels".into(), (panels.clone(), settings)));
    // Anisotropic filtering: a striped floor at grazing angles, 16 probes, on the sphere.
    let floor = RenderSettings::new(Projection::equirect(192)).with_ambient(1.0).with_anisotropy(16);
    out.push(("striped floor, anisotropy 16".into(), (common::striped_floor(), floor)));
    out.push(("mapped panels with glTF tangents".into(), (common::with_tangents(panels), settings)));
    // Shadow maps: a ball and a masked screen over a floor under a spot light.
    let shadows = common::ball_over_floor(twister::core::shading::light::LightKind::Spot, true);
    let settings =
        RenderSettings::new(Projection { width: 400, height: 120, vertical: Vertical::Exact, ..Projection::default() });
    out.push(("ball and screen, spot light's shadow map".into(), (shadows, settings.with_shadow_map_size(512))));
    // The glTF BRDF under point, spot and directional lights, seen from a moved viewer, with
    // each tone mapping.
    let cylinder = Projection { width: 400, height: 100, vertical: Vertical::Exact, ..Projection::default() };
    for tonemap in [Tonemap::PbrNeutral, Tonemap::Aces, Tonemap::None] {
        let settings = RenderSettings::new(cylinder)
            .with_viewer(Vec3::new(0.2, 0.1, 0.3))
            .with_yaw_deg(10.0)
            .with_tonemap(tonemap);
        out.push((
            format!("lit spheres, {tonemap:?}"),
            (common::lit_spheres(), settings.with_exposure_ev(0.5).with_shadow_map_size(256)),
        ));
    }
    out
}

impl Twin for Raster {
    type Case = RasterCase;
    /// The images, and how far their errors may differ.
    type Output = (EyeOutputs, f32);
    fn cases() -> Vec<(String, Self::Case)> {
        let mut out = raster_geometry_cases();
        out.extend(raster_look_cases());
        out.extend(raster_sample_cases());
        out
    }
    fn gpu(_: &Renderer, (scene, settings): &Self::Case) -> Self::Output {
        (frame_outputs(&measured(scene, settings)), error_tolerance(settings))
    }
    fn cpu((scene, settings): &Self::Case) -> Self::Output {
        let eyes = twister::cpu::render::render(scene, settings)
            .expect("the twins' frame")
            .eyes
            .map(|img| (img.rgba, img.error, img.object, img.distance));
        (eyes, error_tolerance(settings))
    }
    fn compare((gpu, tolerance): &Self::Output, (cpu, _): &Self::Output) -> Result<(), String> {
        compare_eyes(gpu, cpu, 100, *tolerance)
    }
}

// ---- reduce_error ----

struct ReduceError;

impl Twin for ReduceError {
    /// A frame's scene and settings, and its per-pixel errors of both eyes (the raster stage's,
    /// drawn once here): the GPU's `reduce_error` runs on them when the frame is drawn again in
    /// `gpu` (the same pixels, checked), the twin on the errors themselves.
    type Case = (Scene, RenderSettings, [Vec<f32>; 2]);
    type Output = ErrorStats;
    fn cases() -> Vec<(String, Self::Case)> {
        let mut out = Vec::new();
        for (name, scene, method, per_eye) in [
            ("triangle@3 vertex", "builtin:triangle@3", Method::Vertex, false),
            ("demo adaptive", "builtin:demo", Method::Adaptive(Split::Length), false),
            // One dispatch per eye, as for images beyond one storage binding.
            ("demo adaptive, one eye at a time", "builtin:demo", Method::Adaptive(Split::Length), true),
        ] {
            let projection = Projection { width: 480, height: 90, ..Projection::default() };
            let scene = builtin::builtin_scene(scene, &projection).unwrap();
            let settings = RenderSettings::new(projection).with_method(method).with_reduce_per_eye(per_eye);
            let errors = measured(&scene, &settings).measurement.unwrap().error;
            out.push((name.to_string(), (scene, settings, errors)));
        }
        out
    }
    fn gpu(_: &Renderer, (scene, settings, errors): &Self::Case) -> Self::Output {
        let m = measured(scene, settings).measurement.unwrap();
        assert!(m.error == *errors, "the frame drew other errors the second time");
        m.stats
    }
    fn cpu((_, _, errors): &Self::Case) -> Self::Output {
        reduce_error(errors.iter().map(|v| v.as_slice()))
    }
    fn compare(gpu: &Self::Output, cpu: &Self::Output) -> Result<(), String> {
        let close = |g: f32, c: f32, rel: f32| (g - c).abs() <= rel * c.max(1.0);
        let ok = gpu.count == cpu.count
            && gpu.count > 1000
            && gpu.max == cpu.max
            && close(gpu.mean, cpu.mean, 1e-4)
            && close(gpu.std_dev, cpu.std_dev, 1e-3)
            && [(gpu.p50, cpu.p50), (gpu.p90, cpu.p90), (gpu.p99, cpu.p99)].iter().all(|&(g, c)| close(g, c, 1e-4));
        if ok {
            Ok(())
        } else {
            Err(format!("GPU {gpu:?}, CPU {cpu:?}"))
        }
    }
}

// ---- stage-specific checks beyond the twin ----

#[test]
fn project_points_takes_no_points_and_more_than_one_dispatch_row() {
    let r = common::renderer();
    let projection = Projection { width: 800, height: 200, ..Projection::default() };
    assert!(r.project_points(&projection, Eye::Left, &[]).unwrap().is_empty());
    // 65,535 workgroups of 64 hold 4,194,240 points: beyond them the dispatch is 2-D, and
    // every point, the last ones included, must be projected.
    let n = 65_535 * 64 + 1000;
    let points: Vec<Vec3> = (0..n)
        .map(|i| {
            let a = i as f32 * 1e-4;
            Vec3::new(2.0 * a.sin(), (i % 7) as f32 * 0.1 - 0.3, -2.0 * a.cos())
        })
        .collect();
    let gpu = r.project_points(&projection, Eye::Right, &points).unwrap();
    assert_eq!(gpu.len(), n);
    let sample: Vec<usize> = (0..n).step_by(9973).chain(n - 1100..n).collect();
    let cpu = twister::cpu::project_points::project_points(
        &projection,
        Eye::Right,
        &sample.iter().map(|&i| points[i]).collect::<Vec<_>>(),
    );
    for (&i, c) in sample.iter().zip(&cpu) {
        let g = gpu[i];
        assert_eq!(g[3], 1.0, "point {i} was not projected");
        assert!(projection.wrapped_dx(g[0], c[0]) < 1e-2 && (g[1] - c[1]).abs() < 1e-2, "point {i}: {g:?} vs {c:?}");
    }
}

#[test]
fn a_gpu_error_inside_a_frame_scope_is_one_error_line_not_a_panic() {
    let gpu = &common::renderer().gpu;
    let too_big = gpu.limits.max_buffer_size.saturating_add(4);
    let result = gpu.scoped("making a buffer", || {
        let _ = gpu.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("too big"),
            size: too_big,
            usage: wgpu::BufferUsages::STORAGE,
            mapped_at_creation: false,
        });
        Ok(())
    });
    let err = result.expect_err("a buffer beyond the device limit must be refused").to_string();
    assert!(err.starts_with("GPU error: making a buffer:") && !err.contains('\n'), "{err}");
    // The device still works afterwards.
    assert!(gpu.scoped("nothing", || Ok(())).is_ok());
}
