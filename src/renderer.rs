//! The headless renderer: the `subdivide` compute pre-pass (`plan`, then `lattice`), then the
//! `raster` stage draws the subdivided triangles indirectly for each eye into RGBA8 + depth, and
//! the images are read back.
//!
//! Memory: the piece and output buffers together stay within `memory_mb` (and each within the
//! device's storage-binding limit). Both passes count what they wanted to write and never write
//! past the end. When a `plan` over a range of triangles overflows the piece buffer, the buffer
//! grows if the budget allows, else the range is halved; likewise a `lattice` over a range of
//! pieces and the output buffer. Ranges are drawn one after another into the same targets
//! (`chunks` in the stats), so nothing is dropped; a single piece that cannot fit is an error.

use std::time::Instant;

use glam::{Mat4, Vec3};
use wgpu::util::DeviceExt;

use crate::gpu::Gpu;
use crate::gpu_types::{DrawIndirectArgs, DrawVertex, RasterParams, SubdivideCounters, SubdivideParams};
use crate::projection::{Eye, Projection};
use crate::reduce::{ErrorStats, ReduceParams};
use crate::scene::Scene;
use crate::shaders;
use crate::slit::{object_spheres, slit_params, slits, sphere_in_slit, SlitCamera};
use crate::subdivide::{subdivide_params, Method, SubdivideOutput, DEFAULT_EDGE_PX, DEFAULT_MAX_DIV};
use crate::texture::MaterialTable;

/// The colour target holds display (sRGB-encoded) values; the fragment stage writes linear light
/// and the target encodes it (cheaper than encoding in the shader on lavapipe).
pub const COLOR_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8UnormSrgb;
pub const OBJECT_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R32Uint;
pub const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;
const DRAW_VERTEX_SIZE: u64 = std::mem::size_of::<DrawVertex>() as u64;
const TRIANGLE_SIZE: u64 = 3 * DRAW_VERTEX_SIZE;
const PIECE_SIZE: u64 = 16;
/// Workgroups of 64 invocations for `count` items, as (x, y) within the 65,535 limit per dimension.
fn workgroups(count: u32) -> (u32, u32) {
    let groups = count.div_ceil(64).max(1);
    if groups <= 65535 {
        (groups, 1)
    } else {
        (65535, groups.div_ceil(65535))
    }
}

/// What to do when a pass wanted `requested` slots of a buffer: grow the buffer to it if the
/// budget `max` allows, else halve the range of `count` items the pass ran on; Err when a single
/// item cannot fit.
fn on_overflow(requested: u32, max: u32, count: u32, want: &mut u32, chunk: &mut u32) -> Result<(), ()> {
    if requested <= max {
        *want = requested;
    } else if count > 1 {
        *chunk = count / 2;
    } else {
        return Err(());
    }
    Ok(())
}

/// GPU times of a one-submission frame, ms: (subdivision, raster, whole frame).
type FrameTimes = (f64, f64, f64);

/// Default memory budget for the subdivision buffers, MiB.
pub const DEFAULT_MEMORY_MB: u32 = 256;

/// Where the viewer stands and how the images are made.
#[derive(Clone, Debug)]
pub struct RenderSettings {
    pub projection: Projection,
    /// Viewer position in scene coordinates.
    pub viewer: Vec3,
    /// Turn of the view about +y in degrees; positive turns left (counter-clockwise from above).
    pub yaw_deg: f32,
    /// Background colour, each channel in [0, 1].
    pub background: [f32; 3],
    /// Ambient term of the headlight shading.
    pub ambient: f32,
    /// How triangles are subdivided.
    pub method: Method,
    /// L: the longest projected edge wanted from `adaptive`, pixels.
    pub edge_px: f32,
    /// N_max: the largest lattice step of one piece.
    pub max_div: u32,
    /// Budget for the piece and output buffers, MiB.
    pub memory_mb: u32,
    /// Measure the longest visible output edge (`FrameStats::max_sub_edge_px`); costs a few
    /// projections per output triangle.
    pub measure_edges: bool,
    /// Run the error pass: every fragment also writes its display-position error and object
    /// id, reduced to statistics on the GPU (slower; off for plain rendering and speed runs).
    pub measure_error: bool,
    /// Test hook: draws everything shifted by this many pixels (x right, y down) while the
    /// error pass measures against the true projection.
    #[doc(hidden)]
    pub shift_px: [f32; 2],
}

impl Default for RenderSettings {
    fn default() -> Self {
        RenderSettings {
            projection: Projection::default(),
            viewer: Vec3::ZERO,
            yaw_deg: 0.0,
            background: [0.1, 0.1, 0.12],
            ambient: 0.3,
            method: Method::Adaptive,
            edge_px: DEFAULT_EDGE_PX,
            max_div: DEFAULT_MAX_DIV,
            memory_mb: DEFAULT_MEMORY_MB,
            measure_edges: false,
            measure_error: false,
            shift_px: [0.0; 2],
        }
    }
}

impl RenderSettings {
    /// World → viewer frame: translate the viewer to the origin, then undo the yaw.
    pub fn view(&self) -> Mat4 {
        Mat4::from_rotation_y(-self.yaw_deg.to_radians()) * Mat4::from_translation(-self.viewer)
    }

    /// Parameters of the `subdivide` stage (capacities and ranges left for the caller).
    pub fn subdivide_params(&self, first_triangle: u32, triangle_count: u32) -> SubdivideParams {
        subdivide_params(
            &self.projection,
            self.view(),
            self.method,
            self.edge_px,
            self.max_div,
            first_triangle,
            triangle_count,
            0,
            0,
        )
        .with_measure_edges(self.measure_edges || self.measure_error)
    }

    pub fn validate(&self) -> Result<(), String> {
        self.projection.validate()?;
        if !(self.edge_px.is_finite() && self.edge_px >= 0.25) {
            return Err(format!("--edge-px must be a number of pixels ≥ 0.25, got {}", self.edge_px));
        }
        if !(1..=64).contains(&self.max_div) {
            return Err(format!("--max-div must be between 1 and 64, got {}", self.max_div));
        }
        if let Method::Slit(w) = self.method {
            if w > self.projection.width {
                return Err(format!("slit:{w} is wider than the image ({} columns)", self.projection.width));
            }
        }
        if self.memory_mb < 8 {
            return Err(format!("--memory-mb must be at least 8, got {}", self.memory_mb));
        }
        Ok(())
    }

    pub fn raster_params(&self, eye: Eye) -> RasterParams {
        RasterParams {
            projection: (&self.projection).into(),
            eye_sign: eye.sign(),
            ambient: self.ambient,
            shift_px: self.shift_px,
        }
    }
}

/// One eye's image, tightly packed RGBA8 rows, top row first.
#[derive(Clone, Debug)]
pub struct EyeImage {
    pub width: u32,
    pub height: u32,
    pub rgba: Vec<u8>,
}

impl EyeImage {
    pub fn pixel(&self, x: u32, y: u32) -> [u8; 4] {
        let i = 4 * (y * self.width + x) as usize;
        [self.rgba[i], self.rgba[i + 1], self.rgba[i + 2], self.rgba[i + 3]]
    }
}

/// What a render cost and drew. Times are wall-clock milliseconds around submit-and-wait.
#[derive(Clone, Debug, Default, serde::Serialize)]
pub struct FrameStats {
    pub triangles_in: u64,
    /// Triangles the subdivision produced (seam copies included), all drawn.
    pub triangles_out: u64,
    pub pieces: u64,
    /// Largest projected length of an output edge with an end on the screen rows, pixels.
    pub max_sub_edge_px: f32,
    /// Number of `lattice` + raster rounds the scene needed to fit the memory budget.
    pub chunks: u32,
    /// Wall time of the frame's GPU work, subdivision and raster of both eyes, from the first
    /// submission until it completed (read-backs excluded).
    pub ms_frame: f64,
    /// Where `ms_subdivide` and `ms_raster` come from: "gpu-timestamps" or "wall".
    pub timing: &'static str,
    /// GPU time of the frame's work from GPU timestamp queries (start of the first pass to the
    /// end of the last), where the adapter has them and the frame ran in one submission.
    pub ms_gpu: Option<f64>,
    pub ms_subdivide: f64,
    pub ms_raster: f64,
    pub ms_readback: f64,
    /// The error reduction (and the read-back of the per-pixel errors).
    pub ms_error: f64,
    pub ms_total: f64,
}

pub struct Frame {
    pub left: EyeImage,
    pub right: EyeImage,
    pub stats: FrameStats,
    /// The error pass's outputs, when `RenderSettings::measure_error` was set.
    pub measurement: Option<Measurement>,
}

/// What the error pass measured (seed 002 §4.1).
pub struct Measurement {
    /// Display-position error per pixel, left and right eye (−1: background or unseen).
    pub error: [Vec<f32>; 2],
    /// Object id + 1 per pixel, left and right eye (0: background).
    pub object: [Vec<u32>; 2],
    /// The GPU reduction of `error` over both eyes.
    pub stats: ErrorStats,
}

impl Frame {
    pub fn eye(&self, eye: Eye) -> &EyeImage {
        match eye {
            Eye::Left => &self.left,
            Eye::Right => &self.right,
        }
    }
}

/// A scene uploaded to the GPU.
pub struct GpuScene {
    pub vertices: wgpu::Buffer,
    pub indices: wgpu::Buffer,
    pub triangle_count: u32,
    /// Each object's triangles (first, count) and bounding sphere, for the slit renderer's culling.
    pub objects: Vec<(u32, u32, Vec3, f32)>,
    /// The material table the fragment stage reads (group 1): materials, mip levels, texels.
    pub materials: [wgpu::Buffer; 3],
    /// What the packing of the textures had to say (levels dropped to fit the budget).
    pub warnings: Vec<String>,
    /// Per object: the factor on L of the adaptive subdivision (1; the level of detail sets it).
    pub object_edge_scale: wgpu::Buffer,
    /// Whether some material is textured, not opaque or single-sided (else the drawing stages
    /// use their plain pipelines).
    pub needs_materials: bool,
}

impl GpuScene {
    /// Validates and uploads a scene; fails with a clear message if it cannot fit the device.
    pub fn upload(gpu: &Gpu, scene: &Scene) -> Result<GpuScene, String> {
        scene.validate()?;
        let vbytes = std::mem::size_of_val(scene.vertices.as_slice()) as u64;
        let ibytes = std::mem::size_of_val(scene.indices.as_slice()) as u64;
        let max = gpu.limits.max_storage_buffer_binding_size.min(gpu.limits.max_buffer_size);
        if vbytes > max || ibytes > max {
            return Err(format!(
                "scene too big for this GPU: {} vertices ({} MiB) and {} triangles ({} MiB); one buffer may hold at most {} MiB",
                scene.vertices.len(),
                vbytes >> 20,
                scene.triangle_count(),
                ibytes >> 20,
                max >> 20
            ));
        }
        let vertices = init_buffer(
            gpu,
            "scene vertices",
            bytemuck::cast_slice(&scene.vertices),
            wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::VERTEX,
        );
        let indices = init_buffer(
            gpu,
            "scene indices",
            bytemuck::cast_slice(&scene.indices),
            wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::INDEX,
        );
        let objects = scene
            .objects
            .iter()
            .zip(object_spheres(scene))
            .map(|(o, (c, r))| (o.first_triangle, o.triangle_count, c, r))
            .collect();
        // Textures get at most a quarter of the device's largest binding (max/16 texels of 4
        // bytes; levels are dropped, largest first, with a warning).
        let table = MaterialTable::of(scene, (max / 16) as usize);
        let storage = |label: &str, bytes: &[u8]| init_buffer(gpu, label, bytes, wgpu::BufferUsages::STORAGE);
        let materials = [
            storage("materials", bytemuck::cast_slice(&table.materials)),
            storage("mip levels", bytemuck::cast_slice(&table.mips)),
            storage("texels", bytemuck::cast_slice(&table.texels)),
        ];
        let ones = vec![1.0f32; scene.objects.len().max(1)];
        let needs_materials = table.needs_materials();
        Ok(GpuScene {
            vertices,
            indices,
            triangle_count: scene.triangle_count() as u32,
            objects,
            materials,
            warnings: table.warnings,
            object_edge_scale: storage("object edge scale", bytemuck::cast_slice(&ones)),
            needs_materials,
        })
    }
}

impl GpuScene {
    /// The scene as a level-of-detail selection draws it: the same vertices and materials, the
    /// selection's triangles (a new index buffer, the only upload) and per-object factors on L.
    pub fn with_lod(&self, gpu: &Gpu, selection: &crate::lod::LodSelection) -> GpuScene {
        let scales = selection.edge_scales();
        GpuScene {
            vertices: self.vertices.clone(),
            indices: init_buffer(
                gpu,
                "lod indices",
                bytemuck::cast_slice(&selection.indices),
                wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::INDEX,
            ),
            triangle_count: (selection.indices.len() / 3) as u32,
            objects: self
                .objects
                .iter()
                .zip(&selection.objects)
                .map(|(&(_, _, c, r), o)| (o.first_triangle, o.triangle_count, c, r))
                .collect(),
            materials: self.materials.clone(),
            warnings: self.warnings.clone(),
            object_edge_scale: init_buffer(
                gpu,
                "object edge scale",
                bytemuck::cast_slice(&scales),
                wgpu::BufferUsages::STORAGE,
            ),
            needs_materials: self.needs_materials,
        }
    }
}

/// A buffer holding `bytes` (16 zero bytes when empty: bindings may not be empty).
fn init_buffer(gpu: &Gpu, label: &str, bytes: &[u8], usage: wgpu::BufferUsages) -> wgpu::Buffer {
    let contents = if bytes.is_empty() { &[0u8; 16][..] } else { bytes };
    gpu.device.create_buffer_init(&wgpu::util::BufferInitDescriptor { label: Some(label), contents, usage })
}

/// The two drawing stages.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum DrawStage {
    Raster = 0,
    Slit = 1,
}

/// A drawing pipeline: colour only (`fs_main`) or with the error pass (`fs_error`); with the
/// fragment stage's material code (`MATERIALS`) or without.
fn draw_pipeline(
    gpu: &Gpu,
    module: &wgpu::ShaderModule,
    stage: DrawStage,
    measure: bool,
    materials: bool,
) -> wgpu::RenderPipeline {
    // Raster: the subdivided `DrawVertex`; slit: the scene's `SceneVertex` (see gpu_types.rs).
    let draw_attributes = wgpu::vertex_attr_array![
        0 => Float32x3, 1 => Float32, 2 => Float32x3, 3 => Uint32, 4 => Float32x4, 5 => Float32x2, 6 => Uint32
    ];
    let scene_attributes = [
        wgpu::VertexAttribute { format: wgpu::VertexFormat::Float32x3, offset: 0, shader_location: 0 },
        wgpu::VertexAttribute { format: wgpu::VertexFormat::Float32x3, offset: 16, shader_location: 1 },
        wgpu::VertexAttribute { format: wgpu::VertexFormat::Float32x4, offset: 32, shader_location: 2 },
        wgpu::VertexAttribute { format: wgpu::VertexFormat::Uint32, offset: 28, shader_location: 3 },
        wgpu::VertexAttribute { format: wgpu::VertexFormat::Float32x2, offset: 48, shader_location: 4 },
        wgpu::VertexAttribute { format: wgpu::VertexFormat::Uint32, offset: 12, shader_location: 5 },
    ];
    let (label, layout) = match stage {
        DrawStage::Raster => (
            "raster",
            wgpu::VertexBufferLayout {
                array_stride: DRAW_VERTEX_SIZE,
                step_mode: wgpu::VertexStepMode::Vertex,
                attributes: &draw_attributes,
            },
        ),
        DrawStage::Slit => (
            "slit",
            wgpu::VertexBufferLayout {
                array_stride: std::mem::size_of::<crate::gpu_types::SceneVertex>() as u64,
                step_mode: wgpu::VertexStepMode::Vertex,
                attributes: &scene_attributes,
            },
        ),
    };
    let all_targets = [COLOR_FORMAT, gpu.error_target.format(), OBJECT_FORMAT]
        .map(|format| Some(wgpu::ColorTargetState { format, blend: None, write_mask: wgpu::ColorWrites::ALL }));
    let constants = [("MATERIALS", materials as u32 as f64)];
    gpu.device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some(label),
        layout: None,
        vertex: wgpu::VertexState {
            module,
            entry_point: Some("vs_main"),
            compilation_options: Default::default(),
            buffers: &[Some(layout)],
        },
        primitive: wgpu::PrimitiveState {
            topology: wgpu::PrimitiveTopology::TriangleList,
            cull_mode: None,
            ..Default::default()
        },
        depth_stencil: Some(wgpu::DepthStencilState {
            format: DEPTH_FORMAT,
            depth_write_enabled: Some(true),
            depth_compare: Some(wgpu::CompareFunction::Less),
            stencil: Default::default(),
            bias: Default::default(),
        }),
        multisample: Default::default(),
        fragment: Some(wgpu::FragmentState {
            module,
            entry_point: Some(if measure { "fs_error" } else { "fs_main" }),
            compilation_options: wgpu::PipelineCompilationOptions { constants: &constants, ..Default::default() },
            targets: if measure { &all_targets } else { &all_targets[..1] },
        }),
        multiview_mask: None,
        cache: None,
    })
}

/// Reusable GPU buffers of the subdivision, with their capacities.
struct Buffers {
    pieces: wgpu::Buffer,
    piece_capacity: u32,
    triangles: wgpu::Buffer,
    triangle_capacity: u32,
    counters: wgpu::Buffer,
    draw_args: wgpu::Buffer,
    /// Indirect dispatch arguments of `lattice` in the one-submission frame.
    lattice_dispatch: wgpu::Buffer,
}

pub struct Renderer {
    pub gpu: Gpu,
    plan: wgpu::ComputePipeline,
    lattice: wgpu::ComputePipeline,
    lattice_args: wgpu::ComputePipeline,
    finalize: wgpu::ComputePipeline,
    /// Drawing pipelines, [colour only, with the error pass], for scenes whose materials are all
    /// plain (untextured, opaque, double-sided): the fragment stage's material code is compiled
    /// out (`MATERIALS = false`), which on lavapipe roughly halves the fragment cost.
    raster: [wgpu::RenderPipeline; 2],
    slit: [wgpu::RenderPipeline; 2],
    raster_module: wgpu::ShaderModule,
    slit_module: wgpu::ShaderModule,
    /// The same with the material code ([raster, slit] × [colour only, error pass]), made when
    /// a scene first needs them.
    with_materials: std::sync::OnceLock<[[wgpu::RenderPipeline; 2]; 2]>,
    accumulate: wgpu::ComputePipeline,
    finish: wgpu::ComputePipeline,
    buffers: std::sync::Mutex<Option<Buffers>>,
}

/// Per-eye render targets: colour, display-position error, object id, depth.
struct Targets {
    color: [wgpu::Texture; 2],
    error: [wgpu::Texture; 2],
    object: [wgpu::Texture; 2],
    depth: [wgpu::Texture; 2],
}

impl Renderer {
    pub fn new(gpu: Gpu) -> Renderer {
        let device = &gpu.device;
        let subdivide_module = shaders::load(device, &shaders::SUBDIVIDE, gpu.error_target);
        let compute = |entry: &str| {
            device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: Some(entry),
                layout: None,
                module: &subdivide_module,
                entry_point: Some(entry),
                compilation_options: Default::default(),
                cache: None,
            })
        };
        let plan = compute("plan");
        let lattice = compute("lattice");
        let finalize = compute("finalize");
        let lattice_args = compute("lattice_args");
        let raster_module = shaders::load(device, &shaders::RASTER, gpu.error_target);
        let raster = [false, true].map(|m| draw_pipeline(&gpu, &raster_module, DrawStage::Raster, m, false));
        let slit_module = shaders::load(device, &shaders::SLIT, gpu.error_target);
        let slit = [false, true].map(|m| draw_pipeline(&gpu, &slit_module, DrawStage::Slit, m, false));
        let reduce_module = shaders::load(device, &shaders::REDUCE_ERROR, gpu.error_target);
        let reduce = |entry: &str| {
            device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: Some(entry),
                layout: None,
                module: &reduce_module,
                entry_point: Some(entry),
                compilation_options: Default::default(),
                cache: None,
            })
        };
        let (accumulate, finish) = (reduce("accumulate"), reduce("finish"));

        Renderer {
            gpu,
            plan,
            lattice,
            lattice_args,
            finalize,
            raster,
            slit,
            raster_module,
            slit_module,
            with_materials: Default::default(),
            accumulate,
            finish,
            buffers: std::sync::Mutex::new(None),
        }
    }

    /// The largest buffer the stages can bind on this device, bytes.
    fn max_binding(&self) -> u64 {
        self.gpu.limits.max_storage_buffer_binding_size.min(self.gpu.limits.max_buffer_size)
    }

    /// Capacities (pieces, triangles) allowed by a memory budget: a quarter for pieces.
    fn max_capacities(&self, memory_mb: u32) -> (u32, u32) {
        let budget = memory_mb as u64 * (1 << 20);
        let pieces = (budget / 4).min(self.max_binding()) / PIECE_SIZE;
        let triangles = (budget - budget / 4).min(self.max_binding()) / TRIANGLE_SIZE;
        (pieces.min(u32::MAX as u64) as u32, triangles.min(u32::MAX as u64) as u32)
    }

    /// Makes sure the cached buffers hold at least these capacities. Each buffer is replaced
    /// only if it is too small, so growing the output keeps the pieces already planned.
    fn ensure_buffers(&self, cache: &mut Option<Buffers>, pieces: u32, triangles: u32) {
        let device = &self.gpu.device;
        let storage = |label, size: u64, extra| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size,
                usage: wgpu::BufferUsages::STORAGE
                    | wgpu::BufferUsages::COPY_SRC
                    | wgpu::BufferUsages::COPY_DST
                    | extra,
                mapped_at_creation: false,
            })
        };
        let make_pieces = |n: u32| storage("pieces", n.max(1) as u64 * PIECE_SIZE, wgpu::BufferUsages::empty());
        let make_triangles =
            |n: u32| storage("subdivided triangles", n.max(1) as u64 * TRIANGLE_SIZE, wgpu::BufferUsages::VERTEX);
        match cache {
            None => {
                *cache = Some(Buffers {
                    pieces: make_pieces(pieces),
                    piece_capacity: pieces.max(1),
                    triangles: make_triangles(triangles),
                    triangle_capacity: triangles.max(1),
                    counters: storage(
                        "counters",
                        std::mem::size_of::<SubdivideCounters>() as u64,
                        wgpu::BufferUsages::empty(),
                    ),
                    draw_args: storage(
                        "draw args",
                        std::mem::size_of::<DrawIndirectArgs>() as u64,
                        wgpu::BufferUsages::INDIRECT,
                    ),
                    lattice_dispatch: storage("lattice dispatch", 16, wgpu::BufferUsages::INDIRECT),
                });
            }
            Some(b) => {
                if b.piece_capacity < pieces {
                    b.pieces = make_pieces(pieces);
                    b.piece_capacity = pieces;
                }
                if b.triangle_capacity < triangles {
                    b.triangles = make_triangles(triangles);
                    b.triangle_capacity = triangles;
                }
            }
        }
    }

    /// A bind group for one entry point of the subdivide stage, from the bindings it uses:
    /// 0 params, 1 vertices, 2 indices, 3 pieces, 4 triangles, 5 counters, 6 draw args,
    /// 7 lattice dispatch, 8 per-object edge scale.
    fn subdivide_bind_group(
        &self,
        pipeline: &wgpu::ComputePipeline,
        used: &[u32],
        uniform: &wgpu::Buffer,
        scene: &GpuScene,
        b: &Buffers,
    ) -> wgpu::BindGroup {
        let all = [
            uniform,
            &scene.vertices,
            &scene.indices,
            &b.pieces,
            &b.triangles,
            &b.counters,
            &b.draw_args,
            &b.lattice_dispatch,
            &scene.object_edge_scale,
        ];
        let entries: Vec<wgpu::BindGroupEntry> = used
            .iter()
            .map(|&i| wgpu::BindGroupEntry { binding: i, resource: all[i as usize].as_entire_binding() })
            .collect();
        self.gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: None,
            layout: &pipeline.get_bind_group_layout(0),
            entries: &entries,
        })
    }

    fn uniform<T: bytemuck::Pod>(&self, label: &str, value: &T) -> wgpu::Buffer {
        self.gpu.device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some(label),
            contents: bytemuck::bytes_of(value),
            usage: wgpu::BufferUsages::UNIFORM,
        })
    }

    /// Runs one compute entry point of the subdivide stage (`plan` or `lattice`) over `count`
    /// invocations, then `finalize`, and returns the counters afterwards.
    fn run_subdivide(
        &self,
        pipeline: &wgpu::ComputePipeline,
        scene: &GpuScene,
        buffers: &Buffers,
        params: &SubdivideParams,
        count: u32,
    ) -> SubdivideCounters {
        let uniform = self.uniform("subdivide params", params);
        let used: &[u32] =
            if std::ptr::eq(pipeline, &self.plan) { &[0, 1, 2, 3, 5, 8] } else { &[0, 1, 2, 3, 4, 5, 8] };
        let main_bg = self.subdivide_bind_group(pipeline, used, &uniform, scene, buffers);
        let finalize_bg = self.subdivide_bind_group(&self.finalize, &[0, 5, 6], &uniform, scene, buffers);
        let mut enc = self.gpu.device.create_command_encoder(&Default::default());
        enc.clear_buffer(&buffers.counters, 0, None);
        {
            let mut pass = enc.begin_compute_pass(&Default::default());
            pass.set_pipeline(pipeline);
            pass.set_bind_group(0, &main_bg, &[]);
            let (x, y) = workgroups(count);
            pass.dispatch_workgroups(x, y, 1);
            pass.set_pipeline(&self.finalize);
            pass.set_bind_group(0, &finalize_bg, &[]);
            pass.dispatch_workgroups(1, 1, 1);
        }
        self.gpu.queue.submit([enc.finish()]);
        let bytes = self.gpu.download(&buffers.counters, std::mem::size_of::<SubdivideCounters>() as u64);
        *bytemuck::from_bytes(&bytes)
    }

    /// The usual frame, in one submission: `plan`, `lattice` (its size read from the piece
    /// counter on the GPU), `finalize`, and both eyes' raster, then one read of the counters.
    /// Returns None if a buffer overflowed (the caller then takes the careful path); else the
    /// counters and, where the adapter has timestamp queries, the GPU times (ms) of the
    /// subdivision and of the raster.
    fn render_one_submission(
        &self,
        scene: &GpuScene,
        settings: &RenderSettings,
        targets: &Targets,
        b: &Buffers,
        mut params: SubdivideParams,
    ) -> Option<(SubdivideCounters, Option<FrameTimes>)> {
        const PIECES_FROM_COUNTER: u32 = u32::MAX;
        let device = &self.gpu.device;
        params.first_piece = 0;
        params.piece_count = PIECES_FROM_COUNTER;
        let uniform = self.uniform("subdivide params", &params);
        let plan_bg = self.subdivide_bind_group(&self.plan, &[0, 1, 2, 3, 5, 8], &uniform, scene, b);
        let args_bg = self.subdivide_bind_group(&self.lattice_args, &[0, 5, 7], &uniform, scene, b);
        let lattice_bg = self.subdivide_bind_group(&self.lattice, &[0, 1, 2, 3, 4, 5, 8], &uniform, scene, b);
        let finalize_bg = self.subdivide_bind_group(&self.finalize, &[0, 5, 6], &uniform, scene, b);
        let timestamps = self.timestamp_query_set();
        let mut enc = device.create_command_encoder(&Default::default());
        enc.clear_buffer(&b.counters, 0, None);
        {
            let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("subdivide"),
                timestamp_writes: timestamps.as_ref().map(|q| wgpu::ComputePassTimestampWrites {
                    query_set: q,
                    beginning_of_pass_write_index: Some(0),
                    end_of_pass_write_index: Some(1),
                }),
            });
            pass.set_pipeline(&self.plan);
            pass.set_bind_group(0, &plan_bg, &[]);
            let (x, y) = workgroups(params.triangle_count);
            pass.dispatch_workgroups(x, y, 1);
            pass.set_pipeline(&self.lattice_args);
            pass.set_bind_group(0, &args_bg, &[]);
            pass.dispatch_workgroups(1, 1, 1);
            pass.set_pipeline(&self.lattice);
            pass.set_bind_group(0, &lattice_bg, &[]);
            pass.dispatch_workgroups_indirect(&b.lattice_dispatch, 0);
            pass.set_pipeline(&self.finalize);
            pass.set_bind_group(0, &finalize_bg, &[]);
            pass.dispatch_workgroups(1, 1, 1);
        }
        self.encode_raster(&mut enc, scene, targets, b, settings, true, timestamps.as_ref().map(|q| (q, 2, 3)));
        let counter_size = std::mem::size_of::<SubdivideCounters>() as u64;
        let staging = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("frame readback"),
            size: counter_size + 32,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        enc.copy_buffer_to_buffer(&b.counters, 0, &staging, 0, counter_size);
        let resolve = timestamps.as_ref().map(|q| {
            let resolve = device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("timestamps"),
                size: 32,
                usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            });
            enc.resolve_query_set(q, 0..4, &resolve, 0);
            enc.copy_buffer_to_buffer(&resolve, 0, &staging, counter_size, 32);
            resolve
        });
        self.gpu.queue.submit([enc.finish()]);
        let bytes = self.gpu.read_buffer(&staging);
        let counters: SubdivideCounters = *bytemuck::from_bytes(&bytes[..counter_size as usize]);
        if counters.pieces > params.piece_capacity || counters.triangles > params.triangle_capacity {
            return None;
        }
        let times = resolve.map(|_| {
            let t: &[u64] = bytemuck::cast_slice(&bytes[counter_size as usize..]);
            (self.ticks_to_ms(t[0], t[1]), self.ticks_to_ms(t[2], t[3]), self.ticks_to_ms(t[0], t[3]))
        });
        Some((counters, times))
    }

    /// A query set of 4 timestamps, where the adapter has timestamp queries.
    fn timestamp_query_set(&self) -> Option<wgpu::QuerySet> {
        self.gpu.features.contains(wgpu::Features::TIMESTAMP_QUERY).then(|| {
            self.gpu.device.create_query_set(&wgpu::QuerySetDescriptor {
                label: Some("frame times"),
                ty: wgpu::QueryType::Timestamp,
                count: 4,
            })
        })
    }

    /// Resolves the first `count` timestamps into a mappable buffer (encoded, not submitted).
    fn resolve_timestamps(&self, enc: &mut wgpu::CommandEncoder, q: &wgpu::QuerySet, count: u32) -> wgpu::Buffer {
        let size = 8 * count as u64;
        let resolve = self.gpu.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("timestamps"),
            size,
            usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        let staging = self.gpu.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("timestamps readback"),
            size,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        enc.resolve_query_set(q, 0..count, &resolve, 0);
        enc.copy_buffer_to_buffer(&resolve, 0, &staging, 0, size);
        staging
    }

    fn ticks_to_ms(&self, a: u64, b: u64) -> f64 {
        b.saturating_sub(a) as f64 * self.gpu.queue.get_timestamp_period() as f64 * 1e-6
    }

    /// Runs the whole subdivide stage on a scene and reads its output back: the GPU side of the
    /// CPU-twin tests. Buffers are sized to hold everything at once.
    pub fn subdivide_readback(&self, scene: &GpuScene, settings: &RenderSettings) -> SubdivideOutput {
        let mut cache = None;
        let mut params = settings.subdivide_params(0, scene.triangle_count);
        let (mut pieces_cap, mut tris_cap) =
            (scene.triangle_count.max(64), scene.triangle_count.saturating_mul(4).max(1024));
        loop {
            self.ensure_buffers(&mut cache, pieces_cap, tris_cap);
            let b = cache.as_ref().unwrap();
            params.piece_capacity = b.piece_capacity;
            params.triangle_capacity = b.triangle_capacity;
            let planned = self.run_subdivide(&self.plan, scene, b, &params, scene.triangle_count);
            if planned.pieces > b.piece_capacity {
                pieces_cap = planned.pieces;
                continue;
            }
            params.first_piece = 0;
            params.piece_count = planned.pieces;
            let done = self.run_subdivide(&self.lattice, scene, b, &params, planned.pieces);
            if done.triangles > b.triangle_capacity {
                tris_cap = done.triangles;
                continue;
            }
            let bytes = self.gpu.download(&b.triangles, done.triangles as u64 * TRIANGLE_SIZE);
            return SubdivideOutput {
                vertices: bytemuck::cast_slice(&bytes).to_vec(),
                pieces: planned.pieces,
                max_sub_edge_px: f32::from_bits(done.max_edge_bits),
            };
        }
    }

    fn targets(&self, projection: &Projection) -> Targets {
        let make = |format, usage, label| {
            self.gpu.device.create_texture(&wgpu::TextureDescriptor {
                label: Some(label),
                size: wgpu::Extent3d { width: projection.width, height: projection.height, depth_or_array_layers: 1 },
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format,
                usage,
                view_formats: &[],
            })
        };
        let color_usage = wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC;
        let depth_usage = wgpu::TextureUsages::RENDER_ATTACHMENT;
        let error_format = self.gpu.error_target.format();
        Targets {
            color: [make(COLOR_FORMAT, color_usage, "left colour"), make(COLOR_FORMAT, color_usage, "right colour")],
            error: [make(error_format, color_usage, "left error"), make(error_format, color_usage, "right error")],
            object: [make(OBJECT_FORMAT, color_usage, "left object"), make(OBJECT_FORMAT, color_usage, "right object")],
            depth: [make(DEPTH_FORMAT, depth_usage, "left depth"), make(DEPTH_FORMAT, depth_usage, "right depth")],
        }
    }

    /// Begins the render pass of eye `k` on its targets, clearing them first if `clear`
    /// (background colour, error −1, object 0, depth 1).
    fn begin_eye_pass<'e>(
        &self,
        enc: &'e mut wgpu::CommandEncoder,
        targets: &Targets,
        k: usize,
        settings: &RenderSettings,
        clear: bool,
        timestamp_writes: Option<wgpu::RenderPassTimestampWrites<'e>>,
    ) -> wgpu::RenderPass<'e> {
        let outputs = if settings.measure_error { 3 } else { 1 };
        let views: Vec<wgpu::TextureView> = [&targets.color[k], &targets.error[k], &targets.object[k]][..outputs]
            .iter()
            .map(|t| t.create_view(&Default::default()))
            .collect();
        let depth_view = targets.depth[k].create_view(&Default::default());
        // The background is given as display values; the sRGB target takes linear ones.
        let [r, g, b] = settings.background.map(|c| crate::fragment::srgb_to_linear(c) as f64);
        let no_error = match self.gpu.error_target {
            crate::shaders::ErrorTarget::Float => -1.0,
            crate::shaders::ErrorTarget::UintBits => (-1.0f32).to_bits() as f64,
        };
        let clears = [
            wgpu::Color { r, g, b, a: 1.0 },
            wgpu::Color { r: no_error, ..wgpu::Color::TRANSPARENT },
            wgpu::Color::TRANSPARENT,
        ];
        let attachments: Vec<Option<wgpu::RenderPassColorAttachment>> = views
            .iter()
            .zip(clears)
            .map(|(view, c)| {
                Some(wgpu::RenderPassColorAttachment {
                    view,
                    depth_slice: None,
                    resolve_target: None,
                    ops: wgpu::Operations {
                        load: if clear { wgpu::LoadOp::Clear(c) } else { wgpu::LoadOp::Load },
                        store: wgpu::StoreOp::Store,
                    },
                })
            })
            .collect();
        enc.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some(Eye::BOTH[k].name()),
            color_attachments: &attachments,
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: &depth_view,
                depth_ops: Some(wgpu::Operations {
                    load: if clear { wgpu::LoadOp::Clear(1.0) } else { wgpu::LoadOp::Load },
                    store: wgpu::StoreOp::Store,
                }),
                stencil_ops: None,
            }),
            timestamp_writes,
            occlusion_query_set: None,
            multiview_mask: None,
        })
    }

    /// Encodes the raster of both eyes (clearing the targets first if `clear`); with a query
    /// set, writes timestamps at the start of the first eye's pass and the end of the second's.
    #[allow(clippy::too_many_arguments)]
    fn encode_raster(
        &self,
        enc: &mut wgpu::CommandEncoder,
        scene: &GpuScene,
        targets: &Targets,
        buffers: &Buffers,
        settings: &RenderSettings,
        clear: bool,
        timestamps: Option<(&wgpu::QuerySet, u32, u32)>,
    ) {
        let pipeline = self.draw_pipeline(DrawStage::Raster, scene, settings.measure_error);
        for (k, eye) in Eye::BOTH.into_iter().enumerate() {
            let uniform = self.uniform("raster params", &settings.raster_params(eye));
            let bg = self.gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: None,
                layout: &pipeline.get_bind_group_layout(0),
                entries: &[wgpu::BindGroupEntry { binding: 0, resource: uniform.as_entire_binding() }],
            });
            let writes = timestamps.map(|(q, begin, end)| wgpu::RenderPassTimestampWrites {
                query_set: q,
                beginning_of_pass_write_index: (k == 0).then_some(begin),
                end_of_pass_write_index: (k == 1).then_some(end),
            });
            let mut pass = self.begin_eye_pass(enc, targets, k, settings, clear, writes);
            pass.set_pipeline(pipeline);
            pass.set_bind_group(0, &bg, &[]);
            pass.set_bind_group(1, &self.material_bind_group(pipeline, scene), &[]);
            pass.set_vertex_buffer(0, buffers.triangles.slice(..));
            pass.draw_indirect(&buffers.draw_args, 0);
        }
    }

    /// The drawing pipeline for a scene: plain where its materials allow, else with materials.
    fn draw_pipeline(&self, stage: DrawStage, scene: &GpuScene, measure: bool) -> &wgpu::RenderPipeline {
        let m = measure as usize;
        if !scene.needs_materials {
            return match stage {
                DrawStage::Raster => &self.raster[m],
                DrawStage::Slit => &self.slit[m],
            };
        }
        let all = self.with_materials.get_or_init(|| {
            [(DrawStage::Raster, &self.raster_module), (DrawStage::Slit, &self.slit_module)]
                .map(|(s, module)| [false, true].map(|m| draw_pipeline(&self.gpu, module, s, m, true)))
        });
        &all[stage as usize][m]
    }

    /// The material table of a scene bound for a drawing pipeline (group 1).
    fn material_bind_group(&self, pipeline: &wgpu::RenderPipeline, scene: &GpuScene) -> wgpu::BindGroup {
        self.gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("materials"),
            layout: &pipeline.get_bind_group_layout(1),
            entries: &[0, 1, 2]
                .map(|k| wgpu::BindGroupEntry { binding: k as u32, resource: scene.materials[k].as_entire_binding() }),
        })
    }

    /// Draws the subdivided triangles into both eyes' targets and waits.
    fn raster_eyes(
        &self,
        scene: &GpuScene,
        targets: &Targets,
        buffers: &Buffers,
        settings: &RenderSettings,
        clear: bool,
    ) {
        let mut enc = self.gpu.device.create_command_encoder(&Default::default());
        self.encode_raster(&mut enc, scene, targets, buffers, settings, clear, None);
        self.gpu.queue.submit([enc.finish()]);
        self.gpu.wait();
    }

    /// Copies a 4-byte-per-texel texture of each eye into one buffer (rows padded to 256
    /// bytes, eyes one after the other). Returns the buffer and the padded row length in texels.
    fn copy_eyes_to_buffer(&self, textures: &[wgpu::Texture; 2], usage: wgpu::BufferUsages) -> (wgpu::Buffer, u32) {
        let (w, h) = (textures[0].width(), textures[0].height());
        let padded = (4 * w).div_ceil(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT) * wgpu::COPY_BYTES_PER_ROW_ALIGNMENT;
        let buffer = self.gpu.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("eye texels"),
            size: 2 * (padded * h) as u64,
            usage: usage | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let mut enc = self.gpu.device.create_command_encoder(&Default::default());
        for (k, texture) in textures.iter().enumerate() {
            enc.copy_texture_to_buffer(
                wgpu::TexelCopyTextureInfo {
                    texture,
                    mip_level: 0,
                    origin: wgpu::Origin3d::ZERO,
                    aspect: wgpu::TextureAspect::All,
                },
                wgpu::TexelCopyBufferInfo {
                    buffer: &buffer,
                    layout: wgpu::TexelCopyBufferLayout {
                        offset: k as u64 * (padded * h) as u64,
                        bytes_per_row: Some(padded),
                        rows_per_image: Some(h),
                    },
                },
                wgpu::Extent3d { width: w, height: h, depth_or_array_layers: 1 },
            );
        }
        self.gpu.queue.submit([enc.finish()]);
        (buffer, padded / 4)
    }

    /// Unpads the texels of both eyes from a buffer made by `copy_eyes_to_buffer`.
    fn unpad_eyes(data: &[u8], w: u32, h: u32, stride: u32) -> [Vec<u32>; 2] {
        let words: &[u32] = bytemuck::cast_slice(data);
        std::array::from_fn(|k| {
            let base = k * (stride * h) as usize;
            (0..h as usize).flat_map(|y| words[base + y * stride as usize..][..w as usize].iter().copied()).collect()
        })
    }

    /// Runs the `reduce_error` stage over the error targets of both eyes; also returns the
    /// per-pixel errors.
    fn reduce_errors(&self, targets: &Targets) -> (ErrorStats, [Vec<f32>; 2]) {
        let device = &self.gpu.device;
        let (w, h) = (targets.error[0].width(), targets.error[0].height());
        let (errors, stride) =
            self.copy_eyes_to_buffer(&targets.error, wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC);
        let pixels = 2 * w * h;
        let groups = pixels.div_ceil(256);
        let (gx, gy) = if groups <= 65535 { (groups, 1) } else { (65535, groups.div_ceil(65535)) };
        let params =
            ReduceParams { width: w, height: h, row_stride: stride, images: 2, partial_count: gx * gy, _pad: [0; 3] };
        let uniform = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("reduce params"),
            contents: bytemuck::bytes_of(&params),
            usage: wgpu::BufferUsages::UNIFORM,
        });
        let storage = |label, size: u64| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size,
                usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            })
        };
        let histogram = storage("histogram", 4 * crate::reduce::BINS as u64);
        let partials = storage("partial sums", 8 * (gx * gy) as u64);
        let totals = storage("totals", 8);
        let result = storage("error stats", std::mem::size_of::<ErrorStats>() as u64);
        let entries = [(0, &uniform), (1, &errors), (2, &histogram), (3, &partials), (4, &totals), (5, &result)];
        let bind = |pipeline: &wgpu::ComputePipeline, used: &[u32]| {
            let e: Vec<wgpu::BindGroupEntry> = entries
                .iter()
                .filter(|(b, _)| used.contains(b))
                .map(|(b, buf)| wgpu::BindGroupEntry { binding: *b, resource: buf.as_entire_binding() })
                .collect();
            device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: None,
                layout: &pipeline.get_bind_group_layout(0),
                entries: &e,
            })
        };
        let accumulate_bg = bind(&self.accumulate, &[0, 1, 2, 3, 4]);
        let finish_bg = bind(&self.finish, &[0, 2, 3, 4, 5]);
        let mut enc = device.create_command_encoder(&Default::default());
        enc.clear_buffer(&histogram, 0, None);
        enc.clear_buffer(&totals, 0, None);
        {
            let mut pass = enc.begin_compute_pass(&Default::default());
            pass.set_pipeline(&self.accumulate);
            pass.set_bind_group(0, &accumulate_bg, &[]);
            pass.dispatch_workgroups(gx, gy, 1);
            pass.set_pipeline(&self.finish);
            pass.set_bind_group(0, &finish_bg, &[]);
            pass.dispatch_workgroups(1, 1, 1);
        }
        self.gpu.queue.submit([enc.finish()]);
        let stats: ErrorStats =
            *bytemuck::from_bytes(&self.gpu.download(&result, std::mem::size_of::<ErrorStats>() as u64));
        let per_eye = Self::unpad_eyes(&self.gpu.download(&errors, errors.size()), w, h, stride);
        (stats, per_eye.map(|v| v.into_iter().map(f32::from_bits).collect()))
    }

    /// Reads both eyes' colour targets back.
    fn read_colors(&self, targets: &Targets) -> [EyeImage; 2] {
        let (w, h) = (targets.color[0].width(), targets.color[0].height());
        let (buffer, stride) = self.copy_eyes_to_buffer(&targets.color, wgpu::BufferUsages::COPY_SRC);
        Self::unpad_eyes(&self.gpu.download(&buffer, buffer.size()), w, h, stride).map(|texels| EyeImage {
            width: w,
            height: h,
            rgba: bytemuck::cast_slice(&texels).to_vec(),
        })
    }

    /// The slit-mosaic reference renderer: one draw per slit and visible object, per eye.
    fn render_slit(&self, scene: &GpuScene, settings: &RenderSettings, width: u32) -> Result<Frame, String> {
        let start = Instant::now();
        let device = &self.gpu.device;
        let projection = &settings.projection;
        let targets = self.targets(projection);
        let view = settings.view();
        let eye_slits = Eye::BOTH.map(|eye| slits(projection, eye, width));
        let cameras: Vec<SlitCamera> = eye_slits.iter().flatten().map(|s| s.camera).collect();
        let camera_buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("slit cameras"),
            contents: bytemuck::cast_slice(&cameras),
            usage: wgpu::BufferUsages::STORAGE,
        });
        let spheres: Vec<(u32, u32, Vec3, f32)> =
            scene.objects.iter().map(|&(first, count, c, r)| (first, count, view.transform_point3(c), r)).collect();
        let mut stats = FrameStats { triangles_in: scene.triangle_count as u64, chunks: 1, ..Default::default() };
        let t = Instant::now();
        let timestamps = self.timestamp_query_set();
        let mut enc = device.create_command_encoder(&Default::default());
        for (k, eye) in Eye::BOTH.into_iter().enumerate() {
            let params = slit_params(projection, view, eye, settings.ambient);
            let uniform = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("slit params"),
                contents: bytemuck::bytes_of(&params),
                usage: wgpu::BufferUsages::UNIFORM,
            });
            let bg = device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: None,
                layout: &self.draw_pipeline(DrawStage::Slit, scene, settings.measure_error).get_bind_group_layout(0),
                entries: &[
                    wgpu::BindGroupEntry { binding: 0, resource: uniform.as_entire_binding() },
                    wgpu::BindGroupEntry { binding: 1, resource: camera_buffer.as_entire_binding() },
                ],
            });
            let writes = timestamps.as_ref().map(|q| wgpu::RenderPassTimestampWrites {
                query_set: q,
                beginning_of_pass_write_index: (k == 0).then_some(0),
                end_of_pass_write_index: (k == 1).then_some(1),
            });
            let mut pass = self.begin_eye_pass(&mut enc, &targets, k, settings, true, writes);
            let pipeline = self.draw_pipeline(DrawStage::Slit, scene, settings.measure_error);
            pass.set_pipeline(pipeline);
            pass.set_bind_group(0, &bg, &[]);
            pass.set_bind_group(1, &self.material_bind_group(pipeline, scene), &[]);
            pass.set_vertex_buffer(0, scene.vertices.slice(..));
            pass.set_index_buffer(scene.indices.slice(..), wgpu::IndexFormat::Uint32);
            let first_instance = (k * eye_slits[0].len()) as u32;
            for (i, slit) in eye_slits[k].iter().enumerate() {
                pass.set_scissor_rect(slit.first_column, 0, slit.end_column - slit.first_column, projection.height);
                let instance = first_instance + i as u32;
                for &(first, count, center, radius) in &spheres {
                    if sphere_in_slit(&params, slit, center, radius) {
                        pass.draw_indexed(3 * first..3 * (first + count), 0, instance..instance + 1);
                        stats.triangles_out += count as u64;
                    }
                }
            }
        }
        let resolved = timestamps.as_ref().map(|q| self.resolve_timestamps(&mut enc, q, 2));
        self.gpu.queue.submit([enc.finish()]);
        self.gpu.wait();
        stats.ms_raster = t.elapsed().as_secs_f64() * 1e3;
        stats.ms_frame = stats.ms_raster;
        stats.timing = "wall";
        if let Some(buffer) = resolved {
            let ticks: Vec<u64> = bytemuck::cast_slice(&self.gpu.read_buffer(&buffer)).to_vec();
            stats.ms_gpu = Some(self.ticks_to_ms(ticks[0], ticks[1]));
        }
        Ok(self.finish_frame(&targets, settings, stats, start))
    }

    /// Reads the targets back and reduces the error: the end of every render.
    fn finish_frame(
        &self,
        targets: &Targets,
        settings: &RenderSettings,
        mut stats: FrameStats,
        start: Instant,
    ) -> Frame {
        let t = Instant::now();
        let [left, right] = self.read_colors(targets);
        stats.ms_readback = t.elapsed().as_secs_f64() * 1e3;
        let t = Instant::now();
        let measurement = settings.measure_error.then(|| {
            let (objects, stride) = self.copy_eyes_to_buffer(&targets.object, wgpu::BufferUsages::COPY_SRC);
            let object =
                Self::unpad_eyes(&self.gpu.download(&objects, objects.size()), left.width, left.height, stride);
            let (stats, error) = self.reduce_errors(targets);
            Measurement { error, object, stats }
        });
        stats.ms_error = t.elapsed().as_secs_f64() * 1e3;
        stats.ms_total = start.elapsed().as_secs_f64() * 1e3;
        Frame { left, right, stats, measurement }
    }

    /// Renders both eyes of an uploaded scene.
    pub fn render(&self, scene: &GpuScene, settings: &RenderSettings) -> Result<Frame, String> {
        settings.validate()?;
        if let Method::Slit(width) = settings.method {
            return self.render_slit(scene, settings, width);
        }
        let start = Instant::now();
        let mut stats = FrameStats { triangles_in: scene.triangle_count as u64, ..Default::default() };
        let targets = self.targets(&settings.projection);
        let (max_pieces, max_tris) = self.max_capacities(settings.memory_mb);
        let mut cache = self.buffers.lock().unwrap_or_else(|e| e.into_inner());
        let n = scene.triangle_count;
        // Start from the cached buffers, or a guess; grow on overflow within the budget.
        // Capacities in use never exceed the budget, whatever size the cached buffers have.
        let (mut want_pieces, mut want_tris) =
            cache.as_ref().map_or((n.saturating_add(1024), n.saturating_mul(4).saturating_add(4096)), |b| {
                (b.piece_capacity, b.triangle_capacity)
            });
        want_pieces = want_pieces.min(max_pieces);
        want_tris = want_tris.min(max_tris);
        // The usual frame is one submission; the careful loop below runs only when a buffer
        // overflowed, and grows the buffers or chunks the scene.
        self.ensure_buffers(&mut cache, want_pieces, want_tris);
        if let Some(b) = cache.as_ref() {
            let mut params = settings.subdivide_params(0, n);
            params.piece_capacity = b.piece_capacity.min(max_pieces);
            params.triangle_capacity = b.triangle_capacity.min(max_tris);
            let t = Instant::now();
            if let Some((counters, times)) = self.render_one_submission(scene, settings, &targets, b, params) {
                stats.ms_frame = t.elapsed().as_secs_f64() * 1e3;
                (stats.ms_subdivide, stats.ms_raster, stats.timing) = match times {
                    Some((subdivide, raster, _)) => (subdivide, raster, "gpu-timestamps"),
                    None => (0.0, stats.ms_frame, "wall"),
                };
                stats.ms_gpu = times.map(|t| t.2);
                stats.pieces = counters.pieces as u64;
                stats.triangles_out = counters.triangles as u64;
                stats.chunks = 1;
                stats.max_sub_edge_px = f32::from_bits(counters.max_edge_bits);
                drop(cache);
                return Ok(self.finish_frame(&targets, settings, stats, start));
            }
        }
        stats.timing = "wall";
        let mut max_edge = 0.0f32;
        let (mut first_tri, mut tri_chunk) = (0u32, n.max(1));
        let mut cleared = false;
        while first_tri < n || !cleared {
            let tri_count = tri_chunk.min(n - first_tri);
            self.ensure_buffers(&mut cache, want_pieces, want_tris);
            let b = cache.as_ref().unwrap();
            let mut params = settings.subdivide_params(first_tri, tri_count);
            params.piece_capacity = b.piece_capacity.min(max_pieces);
            params.triangle_capacity = b.triangle_capacity;
            let t = Instant::now();
            let planned = self.run_subdivide(&self.plan, scene, b, &params, tri_count);
            stats.ms_subdivide += t.elapsed().as_secs_f64() * 1e3;
            if planned.pieces > params.piece_capacity {
                on_overflow(planned.pieces, max_pieces, tri_count, &mut want_pieces, &mut tri_chunk).map_err(|_| {
                    format!(
                        "one triangle needs {} pieces, more than --memory-mb {} allows; raise --edge-px or --memory-mb",
                        planned.pieces, settings.memory_mb
                    )
                })?;
                continue;
            }
            stats.pieces += planned.pieces as u64;
            let (mut first_piece, mut piece_chunk) = (0u32, planned.pieces.max(1));
            let mut piece_done = false;
            while first_piece < planned.pieces || !piece_done {
                let piece_count = piece_chunk.min(planned.pieces - first_piece);
                self.ensure_buffers(&mut cache, want_pieces, want_tris);
                let b = cache.as_ref().unwrap();
                params.first_piece = first_piece;
                params.piece_count = piece_count;
                params.triangle_capacity = b.triangle_capacity.min(max_tris);
                let t = Instant::now();
                let done = self.run_subdivide(&self.lattice, scene, b, &params, piece_count);
                stats.ms_subdivide += t.elapsed().as_secs_f64() * 1e3;
                if done.triangles > params.triangle_capacity {
                    on_overflow(done.triangles, max_tris, piece_count, &mut want_tris, &mut piece_chunk).map_err(|_| {
                        format!(
                            "one piece makes {} triangles, more than --memory-mb {} allows; lower the fixed N or raise --memory-mb",
                            done.triangles, settings.memory_mb
                        )
                    })?;
                    continue;
                }
                let t = Instant::now();
                self.raster_eyes(scene, &targets, b, settings, !cleared);
                stats.ms_raster += t.elapsed().as_secs_f64() * 1e3;
                cleared = true;
                piece_done = true;
                stats.triangles_out += done.triangles as u64;
                stats.chunks += 1;
                max_edge = max_edge.max(f32::from_bits(done.max_edge_bits));
                first_piece += piece_count;
            }
            first_tri += tri_count;
        }
        drop(cache);
        stats.max_sub_edge_px = max_edge;
        stats.ms_frame = stats.ms_subdivide + stats.ms_raster;
        Ok(self.finish_frame(&targets, settings, stats, start))
    }
}

impl Renderer {
    /// Runs the `project_points` stage: pixel positions of viewer-frame points for one eye.
    pub fn project_points(&self, projection: &Projection, eye: Eye, points: &[Vec3]) -> Vec<[f32; 4]> {
        #[repr(C)]
        #[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
        struct ProjectParams {
            projection: crate::gpu_types::ProjectionUniform,
            eye_sign: f32,
            count: u32,
            _pad: [f32; 2],
        }
        let device = &self.gpu.device;
        let module = shaders::load(device, &shaders::PROJECT_POINTS, self.gpu.error_target);
        let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some("project_points"),
            layout: None,
            module: &module,
            entry_point: Some("project_points"),
            compilation_options: Default::default(),
            cache: None,
        });
        let params = ProjectParams {
            projection: projection.into(),
            eye_sign: eye.sign(),
            count: points.len() as u32,
            _pad: [0.0; 2],
        };
        let uniform = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: None,
            contents: bytemuck::bytes_of(&params),
            usage: wgpu::BufferUsages::UNIFORM,
        });
        let input: Vec<[f32; 4]> = points.iter().map(|p| [p.x, p.y, p.z, 1.0]).collect();
        let input = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: None,
            contents: bytemuck::cast_slice(&input),
            usage: wgpu::BufferUsages::STORAGE,
        });
        let size = (points.len() * 16) as u64;
        let output = device.create_buffer(&wgpu::BufferDescriptor {
            label: None,
            size,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        let bg = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: None,
            layout: &pipeline.get_bind_group_layout(0),
            entries: &[
                wgpu::BindGroupEntry { binding: 0, resource: uniform.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 1, resource: input.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 2, resource: output.as_entire_binding() },
            ],
        });
        let mut enc = device.create_command_encoder(&Default::default());
        {
            let mut pass = enc.begin_compute_pass(&Default::default());
            pass.set_pipeline(&pipeline);
            pass.set_bind_group(0, &bg, &[]);
            pass.dispatch_workgroups((points.len() as u32).div_ceil(64), 1, 1);
        }
        self.gpu.queue.submit([enc.finish()]);
        bytemuck::cast_slice(&self.gpu.download(&output, size)).to_vec()
    }
}
