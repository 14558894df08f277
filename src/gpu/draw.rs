//! The drawing stages' pipelines (`raster`, `slit`): per scene look (material code or not, back
//! faces culled or not), with or without the error pass (and the positions), and per way of drawing the eyes (one
//! multiview draw, or a pass per eye), each built when a frame first needs it.

use std::collections::HashMap;
use std::mem::offset_of;
use std::sync::{Mutex, OnceLock};

use crate::core::scenes::scene::SceneVertex;
use crate::core::settings::RenderSettings;
use crate::encoding::types::DrawVertex;
use crate::gpu::device::{error_target_format, Gpu};
use crate::gpu::scene::GpuScene;
use crate::gpu::stages::GpuStage;
use crate::gpu::targets::{
    Layers, Samples, COLOR_FORMAT, DEPTH_FORMAT, HDR_FORMAT, HDR_LOCATION, OBJECT_FORMAT, POSITION_FORMAT,
};
use crate::shader::{EyesPerDraw, ShaderOptions, RASTER, SLIT};

/// The two drawing stages.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum DrawStage {
    Raster = 0,
    Slit = 1,
}

/// A drawing stage's pipelines, each made when a frame first needs it and kept by its
/// [`DrawKey`] (as bevy's specialised pipelines are kept by key).
pub(crate) struct DrawPipelines {
    pub stage: GpuStage,
    /// The raster stage composed to draw one eye per pass, on a device that draws both in one
    /// (the multisampled colour's passes draw one eye each).
    per_eye: OnceLock<GpuStage>,
    kind: DrawStage,
    pipelines: Mutex<HashMap<DrawKey, wgpu::RenderPipeline>>,
}

/// What makes one drawing pipeline differ from another: a scene's look ([`Look`]) and the parts
/// of the glTF look it compiles in ([`Lit`]), or the background (`None`); the colour target
/// alone or with the error pass's (and the surface points') targets; the eyes drawn
/// ([`Layers`]: both in one multiview draw, or one eye, a pipeline per eye with the WGSL
/// `override EYE`; the slit stage draws one eye per pass with per-eye parameters and keys every
/// eye as the left); and whether it also keeps the linear colour (`hdr`: a float target at
/// `HDR_LOCATION`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub(crate) struct DrawKey {
    pub look: Option<(Look, Lit)>,
    pub outputs: usize,
    pub layers: Layers,
    pub hdr: bool,
    /// Samples per pixel of the targets (1 but for the multisampled colour's passes).
    pub samples: u32,
}

/// What a scene's materials need of a drawing pipeline.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub(crate) enum Look {
    /// Without the fragment stage's material code (`MATERIALS = false`), for scenes whose
    /// materials are all untextured, opaque and double-sided: on lavapipe it roughly halves
    /// the fragment cost.
    Plain = 0,
    /// With it.
    Materials = 1,
    /// With it, back faces culled by the rasterizer (every used material single-sided).
    Culled = 2,
    /// With it but without `discard` (`DISCARDS = false`), for scenes whose materials are all
    /// opaque and double-sided (textured, or lit by the glTF BRDF): a shader that may discard
    /// loses early depth testing, so hidden fragments are shaded too (it matters where overdraw
    /// is deep).
    Shaded = 3,
}

impl Look {
    /// What a scene needs, lit by the glTF BRDF (`pbr`, which reads the materials) or not.
    pub fn of(scene: &GpuScene, pbr: bool) -> Look {
        if scene.cull_back_faces {
            Look::Culled
        } else if (scene.needs_materials || pbr) && !scene.discards {
            Look::Shaded
        } else if scene.needs_materials || pbr {
            Look::Materials
        } else {
            Look::Plain
        }
    }
}

/// Which parts of the glTF look a pipeline compiles in (`PBR`, `ENVIRONMENT`, `MAPS` in
/// surface.wgsl). lavapipe runs every branch of a fragment shader under a mask, so code a frame
/// does not use still costs (docs/results.md has the figures). Each part is compiled in only
/// where the frame uses it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub(crate) struct Lit {
    pub pbr: bool,
    pub environment: bool,
    pub maps: bool,
    /// The shadow maps' look-up (`SHADOW_MAPS`).
    pub shadows: bool,
    /// The panorama drawn (`PANORAMAS` in projection.wgsl: the others' code compiled out); the
    /// fisheye's also discards fragments outside its circle (`CIRCLE`; compiled out elsewhere,
    /// which keeps early depth testing).
    pub panoramas: u32,
}

impl Lit {
    /// What a frame of `scene` lit by the glTF BRDF (`pbr`) or not needs.
    pub fn of(scene: &GpuScene, settings: &RenderSettings) -> Lit {
        let pbr = scene.pbr(settings);
        Lit {
            pbr,
            environment: pbr && scene.environment.is_some(),
            maps: pbr && scene.has_maps,
            shadows: scene.shadow_maps(settings),
            panoramas: settings.projection().model().shader_bits(),
        }
    }
}

impl DrawPipelines {
    pub fn new(gpu: &Gpu, kind: DrawStage) -> DrawPipelines {
        let stage = GpuStage::new(gpu, if kind == DrawStage::Raster { &RASTER } else { &SLIT });
        DrawPipelines { stage, per_eye: OnceLock::new(), kind, pipelines: Mutex::new(HashMap::new()) }
    }

    /// The pipeline for a frame of `scene` with `settings` (its look, what of the glTF look it
    /// uses, its outputs, its colour target), drawing `layers` into `samples`' targets.
    pub fn get(
        &self,
        gpu: &Gpu,
        scene: &GpuScene,
        settings: &RenderSettings,
        layers: Layers,
        samples: Samples,
    ) -> wgpu::RenderPipeline {
        let look = (Look::of(scene, scene.pbr(settings)), Lit::of(scene, settings));
        self.keyed(gpu, DrawKey { look: Some(look), ..Self::frame_key(settings, layers, samples) })
    }

    /// The background's pipeline (the environment along each pixel's ray, colour only), for a
    /// frame with `settings` drawing `layers` into `samples`' targets; drawn first, where
    /// `shows_environment`.
    pub fn background(
        &self,
        gpu: &Gpu,
        settings: &RenderSettings,
        layers: Layers,
        samples: Samples,
    ) -> wgpu::RenderPipeline {
        self.keyed(gpu, Self::frame_key(settings, layers, samples))
    }

    /// A frame's key without its look (the background's): every output at the pixels' centres,
    /// or the multisampled colour alone.
    fn frame_key(settings: &RenderSettings, layers: Layers, samples: Samples) -> DrawKey {
        match samples {
            Samples::Centre => DrawKey {
                look: None,
                outputs: settings.measure.outputs(),
                layers,
                hdr: settings.shading.hdr,
                samples: 1,
            },
            Samples::Multi(n) => DrawKey { look: None, outputs: 1, layers, hdr: false, samples: n },
        }
    }

    /// The stage whose module a pipeline drawing `layers` is built from.
    fn stage_for(&self, gpu: &Gpu, layers: Layers) -> &GpuStage {
        match (self.kind, layers, gpu.eyes_per_draw) {
            (DrawStage::Raster, Layers::Eye(_), EyesPerDraw::Both) => self.per_eye.get_or_init(|| {
                GpuStage::with_options(gpu, &RASTER, ShaderOptions { eyes: EyesPerDraw::One, ..gpu.shader_options() })
            }),
            _ => &self.stage,
        }
    }

    /// The pipeline of `key`, made the first time it is asked for.
    pub fn keyed(&self, gpu: &Gpu, key: DrawKey) -> wgpu::RenderPipeline {
        let key = match (self.kind, key.layers) {
            (DrawStage::Slit, Layers::Eye(_)) => DrawKey { layers: Layers::Eye(0), ..key },
            _ => key,
        };
        let mut pipelines = self.pipelines.lock().unwrap_or_else(|e| e.into_inner());
        pipelines
            .entry(key)
            .or_insert_with(|| draw_pipeline(gpu, self.stage_for(gpu, key.layers), self.kind, key))
            .clone()
    }

    /// The scene's material table (group 1).
    pub fn material_bind_group(&self, gpu: &Gpu, scene: &GpuScene) -> wgpu::BindGroup {
        let buffers = scene.material_buffers();
        self.stage.bind_group(gpu, None, 1, &buffers.each_ref())
    }
}

fn attribute(format: wgpu::VertexFormat, offset: usize, shader_location: u32) -> wgpu::VertexAttribute {
    wgpu::VertexAttribute { format, offset: offset as u64, shader_location }
}

/// A drawing pipeline: colour only (`fs_main`, 1 output), with the error pass (`fs_error`, 4) or
/// also the surface points (`fs_position`, 5); with the
/// fragment stage's material code (`MATERIALS`) or without; culling back faces (counter-clockwise
/// on screen is the front, as `front_facing` in the fragment stage) or not; both eyes as a
/// multiview pipeline, or one (the raster stage's `EYE`).
fn draw_pipeline(
    gpu: &Gpu,
    stage: &GpuStage,
    kind: DrawStage,
    DrawKey { look, outputs, layers, hdr, samples }: DrawKey,
) -> wgpu::RenderPipeline {
    // None: the background triangle (no vertex buffer; colour only; behind everything).
    let background = look.is_none();
    let (look, lit) = look
        .unwrap_or((Look::Materials, Lit { pbr: true, environment: true, maps: false, shadows: false, panoramas: 7 }));
    let (stride, attributes) = vertex_layout(kind);
    let layout = wgpu::VertexBufferLayout {
        array_stride: stride as u64,
        step_mode: wgpu::VertexStepMode::Vertex,
        attributes: &attributes,
    };
    let buffers = [Some(layout)];
    let targets = color_targets(gpu, outputs, hdr, background);
    let mut constants = look_constants(look, lit);
    let coverage = samples > 1 && !background && matches!(look, Look::Materials | Look::Culled);
    if coverage {
        constants.push(("SAMPLES", samples as f64));
    }
    let multiview_mask = match layers {
        Layers::Both => std::num::NonZeroU32::new(0b11),
        Layers::Eye(k) => {
            if kind == DrawStage::Raster {
                constants.push(("EYE", k as f64));
            }
            None
        }
    };
    gpu.device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some(stage.stage.name),
        layout: Some(stage.draw_layout()),
        vertex: wgpu::VertexState {
            module: stage.module(gpu, None),
            entry_point: Some(if background { "vs_background" } else { "vs_main" }),
            compilation_options: wgpu::PipelineCompilationOptions { constants: &constants, ..Default::default() },
            buffers: if background { &[] } else { &buffers },
        },
        primitive: wgpu::PrimitiveState {
            topology: wgpu::PrimitiveTopology::TriangleList,
            front_face: wgpu::FrontFace::Ccw,
            cull_mode: (look == Look::Culled && !background).then_some(wgpu::Face::Back),
            ..Default::default()
        },
        depth_stencil: Some(wgpu::DepthStencilState {
            format: DEPTH_FORMAT,
            depth_write_enabled: Some(!background),
            depth_compare: Some(if background { wgpu::CompareFunction::Always } else { wgpu::CompareFunction::Less }),
            stencil: Default::default(),
            bias: Default::default(),
        }),
        multisample: wgpu::MultisampleState { count: samples, ..Default::default() },
        fragment: Some(wgpu::FragmentState {
            module: stage.module(gpu, None),
            entry_point: Some(match (background, outputs) {
                (true, _) => "fs_background",
                // Alpha to coverage where the multisampled colour's materials may discard.
                (_, 1) if coverage => "fs_coverage",
                (_, 1) => "fs_main",
                (_, 4) => "fs_error",
                _ => "fs_position",
            }),
            compilation_options: wgpu::PipelineCompilationOptions { constants: &constants, ..Default::default() },
            targets: &targets,
        }),
        multiview_mask,
        cache: gpu.pipeline_cache(),
    })
}

/// A drawing pipeline's colour targets: the colour, then the measuring targets the frame
/// writes (`outputs` in all), then the linear colour at location 5 with `hdr`. The background
/// writes the colour only: the measuring targets keep their clear values.
fn color_targets(gpu: &Gpu, outputs: usize, hdr: bool, background: bool) -> Vec<Option<wgpu::ColorTargetState>> {
    let error = error_target_format(gpu.error_target);
    let all_targets =
        [COLOR_FORMAT, error, OBJECT_FORMAT, error, POSITION_FORMAT].into_iter().enumerate().map(|(k, format)| {
            let write_mask = if background && k > 0 { wgpu::ColorWrites::empty() } else { wgpu::ColorWrites::ALL };
            Some(wgpu::ColorTargetState { format, blend: None, write_mask })
        });
    let mut targets: Vec<_> = all_targets.take(outputs).collect();
    if hdr {
        // The linear colour at location 5 (`FragmentColor::hdr`), after any measuring targets.
        targets.resize(HDR_LOCATION, None);
        targets.push(Some(wgpu::ColorTargetState {
            format: HDR_FORMAT,
            blend: None,
            write_mask: wgpu::ColorWrites::ALL,
        }));
    }
    targets
}

/// The pipeline constants that compile the parts of the look in or out (surface.wgsl).
fn look_constants(look: Look, lit: Lit) -> Vec<(&'static str, f64)> {
    vec![
        ("MATERIALS", (look != Look::Plain) as u32 as f64),
        ("DISCARDS", (look != Look::Shaded) as u32 as f64),
        ("PBR", lit.pbr as u32 as f64),
        ("ENVIRONMENT", lit.environment as u32 as f64),
        ("MAPS", lit.maps as u32 as f64),
        ("SHADOW_MAPS", lit.shadows as u32 as f64),
        ("CIRCLE", (lit.panoramas & 4 != 0) as u32 as f64),
        ("PANORAMAS", lit.panoramas as f64),
    ]
}

/// A drawing stage's vertex buffer: its stride and attributes. Raster: the subdivided
/// `DrawVertex`; slit: the scene's `SceneVertex` (`VertexIn` of each WGSL file).
fn vertex_layout(kind: DrawStage) -> (usize, Vec<wgpu::VertexAttribute>) {
    use wgpu::VertexFormat::{Float32, Float32x2, Float32x3, Float32x4, Uint32};
    match kind {
        DrawStage::Raster => (
            std::mem::size_of::<DrawVertex>(),
            vec![
                attribute(Float32x3, offset_of!(DrawVertex, position), 0),
                attribute(Float32, offset_of!(DrawVertex, theta_ref), 1),
                attribute(Float32x3, offset_of!(DrawVertex, normal), 2),
                attribute(Uint32, offset_of!(DrawVertex, material), 3),
                attribute(Float32x4, offset_of!(DrawVertex, color), 4),
                attribute(Float32x2, offset_of!(DrawVertex, uv), 5),
                attribute(Uint32, offset_of!(DrawVertex, object), 6),
                attribute(Uint32, offset_of!(DrawVertex, tangent), 7),
                attribute(Float32x4, offset_of!(DrawVertex, offsets), 8),
            ],
        ),
        DrawStage::Slit => (
            std::mem::size_of::<SceneVertex>(),
            vec![
                attribute(Float32x3, offset_of!(SceneVertex, position), 0),
                attribute(Float32x3, offset_of!(SceneVertex, normal), 1),
                attribute(Float32x4, offset_of!(SceneVertex, color), 2),
                attribute(Uint32, offset_of!(SceneVertex, object), 3),
                attribute(Float32x2, offset_of!(SceneVertex, uv), 4),
                attribute(Uint32, offset_of!(SceneVertex, material), 5),
                attribute(Uint32, offset_of!(SceneVertex, tangent), 6),
            ],
        ),
    }
}
