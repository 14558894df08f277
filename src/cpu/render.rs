//! A whole frame on the CPU: a frame's recording (`encoding::frame`) run step by step through
//! the twins of the GPU's stages — `shadow` (the lights' maps), `subdivide` by the step's plan
//! (`encoding::schedule::run_plan`, the one overflow policy), `raster` (one sample at each
//! pixel's centre: colour, error, object, distance; with several samples, the multisampled
//! colour and its resolve), `slit`, `trace` and `reduce_error` — as `Renderer::render_recorded`
//! runs the same recording on the GPU. The oracle a test compares a GPU frame against, without
//! assembling the stages itself.

use crate::core::frame::ErrorStats;
use crate::core::panoramas::projection::Eye;
use crate::core::scenes::bvh::SceneBvh;
use crate::core::scenes::scene::Scene;
use crate::core::settings::RenderSettings;
use crate::core::shading::texture::MaterialTable;
use crate::cpu::multisample::raster_multisampled;
use crate::cpu::raster::{raster, RasterImage};
use crate::cpu::reduce_error::reduce_error;
use crate::cpu::shadow::shadow;
use crate::cpu::slit::{slit, slit_multisampled};
use crate::cpu::subdivide::passes::run_planned;
use crate::cpu::trace::TraceOutput;
use crate::encoding::frame::{record_frame, FrameFacts, FrameRecording, FrameStep};
use crate::encoding::params::{raster_params, trace_params};
use crate::encoding::slits::{slit_params, slits};
use crate::encoding::types::DrawVertex;
use crate::error::{Error, Result};

/// The largest storage binding the CPU engine records its frames with: none (its buffers are
/// bounded by the memory budget alone, which holds any adapter's budget: a GPU's recording
/// runs on the CPU within it).
pub const CPU_MAX_BINDING: u64 = u64::MAX;

/// A frame drawn by the CPU twins.
pub struct CpuFrame {
    /// Per eye: the colour (resolved, with several samples) and the centre sample's error,
    /// object and distance.
    pub eyes: [RasterImage; 2],
    /// The subdivision's triangles (three vertices each), over all its ranges.
    pub triangles: Vec<DrawVertex>,
    /// The subdivision's output ranges drawn (1 for one submission).
    pub chunks: u32,
    /// The error's statistics, where the recording reduces it.
    pub error_stats: Option<ErrorStats>,
    /// The ray tracer's rays and triangle tests, where it traced the frame.
    pub traced: Option<(u64, u64)>,
}

/// The material table a frame's drawing stages read: the scene's materials with its lights,
/// the lighting mode, and the shadow maps drawn by the shadow stage's twin.
pub fn lit_table(scene: &Scene, settings: &RenderSettings) -> MaterialTable {
    let (lights, lighting, maps) =
        settings.shadowed_lighting(&scene.lights, scene.physically_based, scene.environment.as_deref(), scene.bounds());
    let table = scene.material_table(usize::MAX);
    let depths = shadow(&scene.vertices, &scene.indices, &table, settings.view(), &maps);
    table.with_lighting(lights, lighting).with_shadows(maps, depths)
}

/// Records the frame `settings` draw of `scene` as the CPU engine holds it (no buffers kept
/// from an earlier frame; bindings of any size, [`CPU_MAX_BINDING`]).
pub fn record(scene: &Scene, settings: &RenderSettings) -> FrameRecording {
    let (_, _, maps) =
        settings.shadowed_lighting(&scene.lights, scene.physically_based, scene.environment.as_deref(), scene.bounds());
    let facts = FrameFacts {
        triangles: scene.triangle_count() as u32,
        shadow_maps: maps.len() as u32,
        cached: None,
        max_binding: CPU_MAX_BINDING,
    };
    record_frame(settings, &facts)
}

/// Draws `scene` with `settings` through the CPU twins: its recording ([`record`]) run.
pub fn render(scene: &Scene, settings: &RenderSettings) -> Result<CpuFrame> {
    render_recorded(scene, settings, &record(scene, settings))
}

/// Runs a frame's recording through the CPU twins, step by step. A recording that cannot draw
/// the frame the settings record (`FrameRecording::check`) is one error.
pub fn render_recorded(scene: &Scene, settings: &RenderSettings, recording: &FrameRecording) -> Result<CpuFrame> {
    settings.validate()?;
    recording.check(&record(scene, settings))?;
    // The shadow step's maps are drawn with the material table (`lit_table`).
    let table = lit_table(scene, settings);
    let mut frame = None;
    for step in &recording.steps {
        match *step {
            FrameStep::Shadow { .. } | FrameStep::ReadBack { .. } => {}
            FrameStep::Subdivided { plan, chunk } => {
                let (out, totals) = run_planned(settings, &scene.vertices, &scene.indices, plan, chunk)?;
                let eyes = raster_eyes(settings, &out.vertices, &table);
                frame = Some(CpuFrame { triangles: out.vertices, chunks: totals.chunks, ..drawn(eyes) });
            }
            FrameStep::Slit { width } => frame = Some(drawn(slit_eyes(scene, settings, &table, width))),
            FrameStep::Trace => {
                let out = trace_eyes(scene, settings, &table);
                frame = Some(CpuFrame { traced: Some((out.rays, out.triangle_tests)), ..drawn(out.images) });
            }
            FrameStep::ReduceError { .. } => {
                let f = frame.as_mut().ok_or_else(|| Error::Gpu("reduce_error before a drawing step".into()))?;
                f.error_stats = Some(reduce_error(f.eyes.iter().map(|e| e.error.as_slice())));
            }
        }
    }
    frame.ok_or_else(|| Error::Gpu("the frame's recording draws nothing".into()))
}

/// A frame drawn without the subdivision.
fn drawn(eyes: [RasterImage; 2]) -> CpuFrame {
    CpuFrame { eyes, triangles: Vec::new(), chunks: 1, error_stats: None, traced: None }
}

/// `raster` over the subdivided triangles, both eyes; with several samples, the multisampled
/// colour resolved.
fn raster_eyes(settings: &RenderSettings, triangles: &[DrawVertex], table: &MaterialTable) -> [RasterImage; 2] {
    let (background, samples) = (settings.shading.background, settings.shading.samples);
    let params = raster_params(settings);
    let mut eyes = raster(&params, triangles, table, background);
    if samples > 1 {
        let resolved = raster_multisampled(&params, triangles, table, background, samples);
        for (eye, rgba) in eyes.iter_mut().zip(resolved) {
            eye.rgba = rgba;
        }
    }
    eyes
}

/// `slit`: each eye's slits `width` columns wide (a CAVE wall: its one camera per eye); with
/// several samples, the multisampled pass's colour, the rest at the pixels' centres.
fn slit_eyes(scene: &Scene, settings: &RenderSettings, table: &MaterialTable, width: u32) -> [RasterImage; 2] {
    let p = settings.projection();
    let (background, samples) = (settings.shading.background, settings.shading.samples);
    Eye::BOTH.map(|eye| {
        let params = slit_params(p, settings.view(), eye, settings.shading.ambient, settings.measure.error_angle);
        let mut img = slit(&params, &slits(p, eye, width), scene, table, background);
        if samples > 1 {
            img.rgba = slit_multisampled(&params, &slits(p, eye, width), scene, table, background, samples);
        }
        img
    })
}

/// The BVH a traced frame of `scene` walks: the scene's, or with a gaze its levels of detail's
/// (`GpuScene::with_built_bvh` uploads the same for the GPU).
pub fn traced_bvh(scene: &Scene, settings: &RenderSettings) -> SceneBvh {
    match settings.shading.trace_gaze {
        None => SceneBvh::of_scene(scene),
        Some(_) => {
            let chain = crate::core::detail::lod::LodChain::build(scene, settings.shading.trace_min_share);
            SceneBvh::build(&scene.vertices, &chain.levels)
        }
    }
}

/// `trace`: a ray per sample over [`traced_bvh`].
fn trace_eyes(scene: &Scene, settings: &RenderSettings, table: &MaterialTable) -> TraceOutput {
    let bvh = traced_bvh(scene, settings);
    let params = trace_params(settings, settings.projection().width);
    crate::cpu::trace::trace(&params, &scene.vertices, &bvh, table)
}
