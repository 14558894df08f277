//! The headless renderer. A frame is drawn by one method's driver ([`Method`]): the projection
//! methods' subdivided raster (`gpu/subdivided.rs`: the `subdivide` stage, then `raster`), the
//! slit mosaic (`gpu/slit.rs`) or the ray tracer (`gpu/trace.rs`); the shadow maps are drawn
//! before it where the lights need them (`gpu/shadow.rs`), and after it the targets are read
//! back and, with the error pass, reduced (`gpu/reduce_error.rs`). Pipelines, targets, uniforms
//! and buffers are made once and reused across frames. Every frame runs inside GPU error
//! scopes, so a GPU error is one [`Error::Gpu`] line.

use std::sync::Mutex;
use std::time::Instant;

use glam::Vec3;

use crate::core::frame::{Frame, FrameStats, Measurement};
use crate::core::projection::{Eye, Projection};
use crate::core::scene::Scene;
use crate::core::settings::{Method as MethodName, RenderSettings};
use crate::encoding::subdivide::SubdivideOutput;
use crate::encoding::types::{RasterParams, SlitParams, SubdivideParams, TraceParams};
use crate::error::{Error, Result};
use crate::gpu::device::Gpu;
use crate::gpu::frame_plan::SubdivisionBuffers;
use crate::gpu::project_points::ProjectPointsStage;
use crate::gpu::reduce_error::ReduceStage;
use crate::gpu::scene::GpuScene;
use crate::gpu::shadow::ShadowStage;
use crate::gpu::skin::SkinStage;
use crate::gpu::slit::SlitMethod;
use crate::gpu::subdivide::{Schedule, COUNTERS_SIZE};
use crate::gpu::subdivided::SubdividedMethod;
use crate::gpu::targets::Targets;
use crate::gpu::timestamps::{self as stamp, Timestamps};
use crate::gpu::trace::TraceMethod;

/// What a renderer keeps between frames.
pub(crate) struct FrameResources {
    pub buffers: Option<SubdivisionBuffers>,
    /// Targets of the last image size.
    pub targets: Option<Targets>,
    pub timestamps: Option<Timestamps>,
    pub subdivide_params: wgpu::Buffer,
    /// Both eyes' (left, right), as the raster stage's `array<RasterParams, 2>`.
    pub raster_params: wgpu::Buffer,
    pub slit_params: [wgpu::Buffer; 2],
    /// Counters and timestamps of a one-submission frame.
    pub staging: wgpu::Buffer,
    pub trace_params: wgpu::Buffer,
    /// The ray tracer's outputs of the last image size: (padded row texels, height, colour,
    /// error, object and distance buffers), and its counters of rays and triangle tests.
    pub trace_outputs: Option<(u32, u32, [wgpu::Buffer; 4])>,
    pub trace_counts: Option<wgpu::Buffer>,
}

impl FrameResources {
    /// The targets for this size, made anew only when the size changed.
    /// The targets for this size (with the positions target if `positions`), made anew only
    /// when the size changed or the positions target is wanted and missing.
    pub fn targets(&mut self, gpu: &Gpu, width: u32, height: u32, positions: bool, hdr: bool) -> &Targets {
        if !self.targets.as_ref().is_some_and(|t| {
            t.width == width && t.height == height && (t.position.is_some() || !positions) && t.hdr == hdr
        }) {
            self.targets = Some(Targets::new(gpu, width, height, positions, hdr));
        }
        self.targets.as_ref().expect("just made")
    }
}

const STAGING_SIZE: u64 = COUNTERS_SIZE + 8 * stamp::COUNT as u64;

/// A way of drawing a frame (as pbrt's `Integrator`): the projection methods' subdivided
/// raster, the slit mosaic, the ray tracer. Each reads the frame's resources and ends with
/// [`Renderer::finish_frame`].
pub(crate) trait Method {
    fn draw(
        &self,
        r: &Renderer,
        res: &mut FrameResources,
        scene: &GpuScene,
        settings: &RenderSettings,
    ) -> Result<Frame>;
}

/// The renderer: the device, each method's driver and the stages they share, and the
/// resources kept between frames.
pub struct Renderer {
    pub gpu: Gpu,
    subdivided: SubdividedMethod,
    slit: SlitMethod,
    trace: TraceMethod,
    shadow: ShadowStage,
    reduce: ReduceStage,
    skin: SkinStage,
    project_points: ProjectPointsStage,
    resources: Mutex<FrameResources>,
}

impl Renderer {
    /// Builds the usual frame's pipelines now (a GPU error here is returned, not a panic); the
    /// others are built when first needed.
    pub fn new(gpu: Gpu) -> Result<Renderer> {
        let (subdivided, slit, shadow, reduce, resources) = gpu.scoped("building the pipelines", || {
            let resources = FrameResources {
                buffers: None,
                targets: None,
                timestamps: Timestamps::new(&gpu),
                subdivide_params: gpu.uniform_buffer::<SubdivideParams>("subdivide params"),
                raster_params: gpu.uniform_buffer::<[RasterParams; 2]>("raster params"),
                slit_params: Eye::BOTH.map(|e| gpu.uniform_buffer::<SlitParams>(&format!("{} slit params", e.name()))),
                staging: gpu.device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some("frame readback"),
                    size: STAGING_SIZE,
                    usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
                    mapped_at_creation: false,
                }),
                trace_params: gpu.uniform_buffer::<TraceParams>("trace params"),
                trace_outputs: None,
                trace_counts: None,
            };
            Ok((
                SubdividedMethod::new(&gpu),
                SlitMethod::new(&gpu),
                ShadowStage::new(&gpu),
                ReduceStage::new(&gpu),
                resources,
            ))
        })?;
        Ok(Renderer {
            gpu,
            subdivided,
            slit,
            trace: TraceMethod::default(),
            shadow,
            reduce,
            skin: SkinStage::default(),
            project_points: ProjectPointsStage::default(),
            resources: Mutex::new(resources),
        })
    }

    /// Renders both eyes of an uploaded scene.
    pub fn render(&self, scene: &GpuScene, settings: &RenderSettings) -> Result<Frame> {
        settings.validate()?;
        self.check_size(settings)?;
        let mut resources = self.resources.lock().unwrap_or_else(|e| e.into_inner());
        let shadow_maps = scene.write_lighting(&self.gpu, settings);
        if settings.shading.hdr && matches!(settings.subdivision.method, MethodName::Slit(_) | MethodName::Trace) {
            return Err(Error::setting(
                "shading.hdr",
                "the linear colour comes from the projection methods (vertex, fixed, adaptive); slit and trace write display colours",
            ));
        }
        self.shadow.draw_maps(&self.gpu, scene, settings.view(), &shadow_maps)?;
        let method: &dyn Method = match settings.subdivision.method {
            MethodName::Slit(_) => &self.slit,
            MethodName::Trace => &self.trace,
            _ => &self.subdivided,
        };
        self.gpu.scoped("rendering a frame", || method.draw(self, &mut resources, scene, settings))
    }

    /// Poses `scene` at time t of clip `clip` (None: the rest pose) on the GPU (the skin
    /// stage, `gpu::skin`); a scene without a rig is left as it is.
    pub fn pose(&self, gpu_scene: &mut GpuScene, scene: &mut Scene, clip: Option<usize>, t: f32) -> Result<()> {
        self.skin.pose(&self.gpu, gpu_scene, scene, clip, t)
    }

    /// `[pixel x, pixel y, depth, 1]` per point, or zeros where no eye sees it (the
    /// `project_points` stage: the check of the WGSL projection).
    pub fn project_points(&self, projection: &Projection, eye: Eye, points: &[Vec3]) -> Result<Vec<[f32; 4]>> {
        self.project_points.project(&self.gpu, projection, eye, points)
    }

    /// The depths of a scene's shadow maps as the last frame drew them (`bytes` of them).
    pub fn shadow_depths(&self, scene: &GpuScene, bytes: u64) -> Result<Vec<f32>> {
        crate::gpu::shadow::shadow_depths(&self.gpu, scene, bytes)
    }

    /// Fails with one line when the image cannot be drawn on this device.
    fn check_size(&self, settings: &RenderSettings) -> Result<()> {
        let p = settings.projection();
        let max = self.gpu.limits.max_texture_dimension_2d;
        if p.width > max || p.height > max {
            return Err(Error::setting(
                "view.projection.width/height",
                format!("{}x{} is larger than this GPU's largest image, {max}x{max}", p.width, p.height),
            ));
        }
        // Both eyes' colour targets are read back through one buffer (rows padded to 256
        // bytes); with the error pass, each eye's error target is bound as storage (both at once
        // when they fit one binding).
        let padded_row = (4 * p.width as u64).div_ceil(256) * 256;
        let eyes_bytes = 2 * padded_row * p.height as u64;
        let max_buffer = self.gpu.limits.max_buffer_size;
        let (limit, what) = if settings.measure.error {
            (max_buffer.min(2 * self.gpu.max_binding()), "the error pass's buffers")
        } else {
            (max_buffer, "the read-back buffer")
        };
        if eyes_bytes > limit {
            return Err(Error::setting(
                "view.projection.width/height",
                format!(
                    "{}x{} needs {} MiB for {what}, more than this GPU's {} MiB: use a smaller image",
                    p.width,
                    p.height,
                    eyes_bytes >> 20,
                    limit >> 20
                ),
            ));
        }
        Ok(())
    }

    /// Runs the whole subdivide stage on a scene with `schedule` and reads its output back:
    /// the GPU side of the twin test.
    pub fn subdivide_readback(
        &self,
        scene: &GpuScene,
        settings: &RenderSettings,
        schedule: Schedule,
    ) -> Result<SubdivideOutput> {
        self.subdivided.subdivide.readback(&self.gpu, scene, settings, schedule)
    }

    /// Reads the targets back and reduces the error: the end of every render.
    pub(crate) fn finish_frame(
        &self,
        targets: &Targets,
        settings: &RenderSettings,
        mut stats: FrameStats,
        start: Instant,
    ) -> Result<Frame> {
        let t = Instant::now();
        let (hdr, [left, right]) = if targets.hdr {
            // The linear colour, and as display bytes clamped (the frame is not tone mapped).
            let hdr = targets.read_hdr(&self.gpu)?;
            let image = |eye: &Vec<[f32; 3]>| crate::core::frame::EyeImage {
                width: targets.width,
                height: targets.height,
                rgba: eye.iter().flat_map(|c| crate::core::color::display_bytes(glam::Vec3::from(*c))).collect(),
            };
            let images = [image(&hdr[0]), image(&hdr[1])];
            (Some(hdr), images)
        } else {
            (None, targets.read_colors(&self.gpu)?)
        };
        stats.ms_readback = t.elapsed().as_secs_f64() * 1e3;
        let depth = if settings.measure.depth { Some(targets.read_distances(&self.gpu)?) } else { None };
        let positions = if settings.measure.positions { Some(targets.read_positions(&self.gpu)?) } else { None };
        let measurement = if settings.measure.error {
            let object = targets.read_objects(&self.gpu)?;
            let (stats, error) = self.reduce.reduce(&self.gpu, targets, settings.measure.reduce_per_eye)?;
            Some(Measurement { error, object, stats })
        } else {
            None
        };
        stats.ms_total = start.elapsed().as_secs_f64() * 1e3;
        Ok(Frame { left, right, stats, measurement, depth, positions, hdr })
    }
}
