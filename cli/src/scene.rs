//! From a scene option to what a command renders: load, scale, fit, place the viewer (a file
//! camera follows the scene), select the level of detail, upload; and the warnings the user
//! should read on the way.

use glam::{Mat4, Vec3};

use crate::args::{ViewArgs, Viewer};
use twister::core::detail::lod::{LodChain, LodSelection};
use twister::core::detail::visual_field::{Field, Gaze};
use twister::core::scenes::bvh::SceneBvh;
use twister::core::scenes::load::load_scene;
use twister::core::scenes::scene::MAX_COORDINATE;
use twister::core::settings::Method;
use twister::error::{Error, Result};
use twister::gpu::Gpu;
use twister::{GpuScene, RenderSettings, Renderer, Scene};

/// The environment variable that chooses an adapter by a part of its name.
pub const ADAPTER_VAR: &str = "TWISTER_ADAPTER";

/// The GPU and its renderer, with the adapter's description for reports: the adapter whose name
/// contains `TWISTER_ADAPTER` where that is set, else the default one.
pub fn open_renderer() -> Result<(Renderer, String)> {
    let gpu = Gpu::with_adapter(std::env::var(ADAPTER_VAR).ok().filter(|v| !v.is_empty()).as_deref())?;
    let adapter = gpu.adapter_description();
    Ok((Renderer::new(gpu)?, adapter))
}

/// Prints a warning line for the user (stderr).
pub fn warn(spec: &str, warning: &str) {
    eprintln!("warning: {spec}: {warning}");
}

/// Loads and places a scene: `--scale`, then `--fit`; a `camera[:N]` viewer takes that
/// camera's place and yaw (the camera moved with the scene): the settings returned say so.
/// Prints the loader's warnings. `loaded`: the file already loaded (a caller that keeps
/// scenes, as the Python package does), placed as a copy.
pub fn place(
    spec: &str,
    loaded: Option<&Scene>,
    fit: Option<f32>,
    view: &ViewArgs,
    settings: RenderSettings,
) -> Result<(Scene, RenderSettings)> {
    let mut scene = match loaded {
        Some(scene) => scene.clone(),
        None => load_scene(spec, settings.projection())?,
    };
    for w in &scene.warnings {
        warn(spec, w);
    }
    if view.scale != 1.0 {
        scene.transform(Mat4::from_scale(Vec3::splat(view.scale)));
        check_in_range(&scene, spec, "--scale")?;
    }
    if let Some(d) = fit {
        scene.fit(d, settings.projection())?;
        check_in_range(&scene, spec, "--fit")?;
    }
    if let Viewer::Camera(n) = view.viewer {
        let cam = scene.cameras.get(n).ok_or_else(|| {
            Error::scene(spec, format!("--viewer camera:{n}, but the file has {} cameras", scene.cameras.len()))
        })?;
        let placed = settings.with_viewer(Vec3::from(cam.position)).with_yaw_deg(settings.view.yaw_deg + cam.yaw_deg);
        return Ok((scene, placed));
    }
    Ok((scene, settings))
}

/// After a transform: coordinates beyond what the projection computes in f32 (or an overflow
/// to infinity) are the option's fault, not the file's.
fn check_in_range(scene: &Scene, spec: &str, option: &'static str) -> Result<()> {
    let fits = |c: &f32| c.abs() <= MAX_COORDINATE;
    if scene.vertices.iter().all(|v| v.position.iter().all(fits))
        && scene.cameras.iter().all(|c| c.position.iter().all(fits))
    {
        Ok(())
    } else {
        Err(Error::option(option, format!("puts {spec} beyond ±{MAX_COORDINATE:e} m, more than twister draws")))
    }
}

/// A scene ready to render, and the settings to render it with.
pub struct Prepared {
    pub gpu_scene: GpuScene,
    /// The settings as placed with the scene (a file camera's viewer, the ray tracer's gaze),
    /// validated: read only from here on.
    pub settings: RenderSettings,
    /// The placed scene (a sequence poses it frame by frame).
    pub scene: Scene,
    pub selection: Option<LodSelection>,
    pub gaze: Option<Gaze>,
}

/// Places the scene and uploads it, with its BVH when one of `methods` traces rays; with
/// `--lod visual-field`, draws the gaze's selection (tinted by level when `overlay`). The
/// settings come back placed with the scene and validated.
pub fn prepare(
    renderer: &Renderer,
    spec: &str,
    fit: Option<f32>,
    view: &ViewArgs,
    settings: RenderSettings,
    overlay: bool,
    methods: &[Method],
) -> Result<Prepared> {
    prepare_loaded(renderer, spec, None, fit, view, settings, overlay, methods)
}

/// [`prepare`] of a scene already loaded from `spec` (see [`place`]).
#[allow(clippy::too_many_arguments)]
pub fn prepare_loaded(
    renderer: &Renderer,
    spec: &str,
    loaded: Option<&Scene>,
    fit: Option<f32>,
    view: &ViewArgs,
    settings: RenderSettings,
    overlay: bool,
    methods: &[Method],
) -> Result<Prepared> {
    view.check_light(methods)?;
    let mut lod = view.lod()?;
    // The ray tracer's level of detail: each object's chain down to P3 of its triangles.
    let mut trace_min_share = None;
    let mut settings = settings;
    if let (Some((params, gaze)), true) = (&lod, methods.contains(&Method::Trace)) {
        // The ray tracer's level of detail is per ray (seed 000), not a selection of objects.
        if methods.len() > 1 {
            return Err(Error::option(
                "--lod",
                "with --method trace, the level of detail is per ray: run trace apart from the other methods",
            ));
        }
        settings = settings.with_trace_gaze(Some(*gaze)).with_trace_min_share(params.p3);
        trace_min_share = Some(params.p3);
        lod = None;
    }
    let (mut scene, settings) = place(spec, loaded, fit, view, settings)?;
    settings.validate()?;
    if let Some([azimuth, elevation, lux]) = view.sun {
        scene.lights.push(twister::core::shading::light::Light::sun(azimuth, elevation, lux));
    }
    let selection =
        lod.map(|(params, gaze)| LodChain::build(&scene, params.p3).select(&scene, settings.view(), &gaze, &params));
    if let (Some(sel), true) = (&selection, overlay) {
        twister::core::detail::lod::tint(&mut scene, sel);
    }
    scene.environment = view.environment(&scene)?.map(std::sync::Arc::new);
    let mut gpu_scene = GpuScene::upload(&renderer.gpu, &scene)?;
    if methods.contains(&Method::Trace) {
        gpu_scene = match trace_min_share {
            None => gpu_scene.with_bvh(&renderer.gpu, &scene)?,
            Some(share) => {
                let chain = LodChain::build(&scene, share);
                gpu_scene.with_built_bvh(
                    &renderer.gpu,
                    &scene.name,
                    &SceneBvh::build(&scene.vertices, &chain.levels),
                )?
            }
        };
    }
    for w in &gpu_scene.warnings {
        warn(spec, w);
    }
    if let Some(sel) = &selection {
        gpu_scene = gpu_scene.with_lod(&renderer.gpu, sel);
    }
    Ok(Prepared { gpu_scene, settings, scene, selection, gaze: lod.map(|(_, g)| g) })
}

/// The LOD part of the stats: triangles selected and, per field, objects and triangles.
pub fn lod_stats(selection: &Option<LodSelection>) -> serde_json::Value {
    let Some(sel) = selection else { return serde_json::Value::Null };
    let per = |f: Field| {
        let c: Vec<_> = sel.chosen.iter().filter(|c| c.field == f).collect();
        serde_json::json!({ "objects": c.len(), "triangles": c.iter().map(|c| c.triangles as u64).sum::<u64>() })
    };
    serde_json::json!({
        "triangles_selected": sel.triangle_count(),
        "central": per(Field::Central),
        "peripheral": per(Field::Peripheral),
        "outside": per(Field::Outside),
    })
}
