//! The headless renderer. A frame is drawn by one method's driver ([`Method`]): the projection
//! methods' subdivided raster (`gpu/subdivided.rs`: the `subdivide` stage, then `raster`), the
//! slit mosaic (`gpu/slit.rs`) or the ray tracer (`gpu/trace.rs`); the shadow maps are drawn
//! before it where the lights need them (`gpu/shadow.rs`), and after it the targets are read
//! back and, with the error pass, reduced (`gpu/reduce_error.rs`). Pipelines, targets, uniforms
//! and buffers are made once and reused across frames. Every frame runs inside GPU error
//! scopes, so a GPU error is one [`Error::Gpu`] line.

use std::sync::{Mutex, OnceLock};

use glam::Vec3;

use crate::core::frame::{EyeImage, Frame};
use crate::core::panoramas::projection::{Eye, Projection};
use crate::core::scenes::scene::Scene;
use crate::core::settings::{Method as MethodName, RenderSettings};
use crate::encoding::frame::{record_frame, FrameFacts, FrameRecording, FrameStep};
use crate::encoding::schedule::Schedule;
use crate::encoding::subdivide::SubdivideOutput;
use crate::encoding::types::{SlitParams, SubdivideParams, TraceParams};
use crate::error::{Error, Result};
use crate::gpu::device::Gpu;
use crate::gpu::display::{DisplayStage, ShownFrame};
use crate::gpu::frame::{EndStages, FrameEnd, FrameResources, Method, STAGING_SIZE};
use crate::gpu::project_points::ProjectPointsStage;
use crate::gpu::scene::GpuScene;
use crate::gpu::shadow::ShadowStage;
use crate::gpu::skin::SkinStage;
use crate::gpu::slit::SlitMethod;
use crate::gpu::subdivided::SubdividedMethod;
use crate::gpu::timestamps::Timestamps;
use crate::gpu::trace::TraceMethod;

/// The most bytes of both eyes' colour a strip of tiles holds (`Renderer::tiles`).
pub const STRIP_BYTES: u64 = 128 << 20;

/// The most bytes of both eyes' colour a frame drawn whole holds (vr8k's 256 MiB is drawn whole;
/// vr16k's 1 GiB in strips): beyond it the targets and the image would take memory without
/// bound (vr16k drawn whole peaked at 14 GiB on the software driver).
pub const WHOLE_FRAME_BYTES: u64 = 512 << 20;

/// A frame cut into tiles: the frame's size and the tiles' (the last column and strip may be
/// smaller), drawn strip by strip.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Tiles {
    pub width: u32,
    pub height: u32,
    pub tile_w: u32,
    pub tile_h: u32,
    /// The cubemap's face side, whose squares no tile column straddles (0: none): a face's
    /// draw then meets a tile's edge only at its own (multisampled coverage at a scissor
    /// inside a tile differed on lavapipe).
    pub face: u32,
}

impl Tiles {
    /// The whole frame as one tile.
    pub fn whole(width: u32, height: u32) -> Tiles {
        Tiles { width, height, tile_w: width, tile_h: height, face: 0 }
    }

    /// The tile columns: (first column, width), left to right; within each face's columns
    /// for a cubemap cut across.
    pub fn columns(&self) -> Vec<(u32, u32)> {
        let spans: Vec<(u32, u32)> = if self.face > 0 && self.tile_w < self.width {
            (0..self.width / self.face).map(|k| (k * self.face, self.face)).collect()
        } else {
            vec![(0, self.width)]
        };
        let step = self.tile_w.max(1);
        spans
            .into_iter()
            .flat_map(|(start, len)| {
                (start..start + len).step_by(step as usize).map(move |x| (x, step.min(start + len - x)))
            })
            .collect()
    }

    /// How many tiles the frame has.
    pub fn count(&self) -> u32 {
        self.columns().len() as u32 * self.height.div_ceil(self.tile_h)
    }
}

/// Copies a tile's rows (`w` texels of `per` values) into a strip `width` texels wide at
/// column `x`.
fn place<T: Copy>(to: &mut [T], from: &[T], width: usize, x: usize, w: usize, per: usize) {
    for (row, src) in from.chunks_exact(w * per).enumerate() {
        let at = (row * width + x) * per;
        to[at..at + w * per].copy_from_slice(src);
    }
}

/// The renderer: the device, each method's driver and the stages they share, and the
/// resources kept between frames.
pub struct Renderer {
    pub gpu: Gpu,
    subdivided: OnceLock<SubdividedMethod>,
    slit: OnceLock<SlitMethod>,
    trace: TraceMethod,
    shadow: OnceLock<ShadowStage>,
    end: EndStages,
    skin: SkinStage,
    project_points: ProjectPointsStage,
    display: OnceLock<DisplayStage>,
    resources: Mutex<FrameResources>,
}

impl Renderer {
    /// The renderer on a device: its uniforms and read-back buffer now; the stages' shader
    /// modules and pipelines when a frame first needs them (only those it uses: a still in a
    /// fresh process builds little), inside that frame's error scope.
    pub fn new(gpu: Gpu) -> Result<Renderer> {
        let resources = gpu.scoped("making the frame's resources", || {
            Ok(FrameResources {
                buffers: None,
                targets: None,
                timestamps: Timestamps::new(&gpu),
                subdivide_params: gpu.storage_params_buffer::<SubdivideParams>("subdivide params"),
                raster_params: gpu.device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some("raster params"),
                    size: crate::gpu::frame::raster_params_stride(&gpu)
                        * crate::core::panoramas::cubemap::CUBE_FACES.len() as u64,
                    usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
                    mapped_at_creation: false,
                }),
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
            })
        })?;
        Ok(Renderer {
            gpu,
            subdivided: OnceLock::new(),
            slit: OnceLock::new(),
            trace: TraceMethod::default(),
            shadow: OnceLock::new(),
            end: EndStages::default(),
            skin: SkinStage::default(),
            project_points: ProjectPointsStage::default(),
            display: OnceLock::new(),
            resources: Mutex::new(resources),
        })
    }

    fn subdivided(&self) -> &SubdividedMethod {
        self.subdivided.get_or_init(|| SubdividedMethod::new(&self.gpu))
    }

    /// Renders both eyes of an uploaded scene.
    pub fn render(&self, scene: &GpuScene, settings: &RenderSettings) -> Result<Frame> {
        settings.validate()?;
        self.check_size(settings)?;
        if self.draws_directly(settings) {
            return Ok(self.render_direct(scene, settings, false)?.0);
        }
        self.render_larger(scene, settings, &crate::gpu::targets::sample_counts(&self.gpu))
    }

    /// Whether the adapter draws a frame's sample count itself (the ray tracer traces any count:
    /// a ray per sample); else [`Renderer::render_larger`] makes it up.
    fn draws_directly(&self, settings: &RenderSettings) -> bool {
        let counts = crate::gpu::targets::sample_counts(&self.gpu);
        counts.contains(&settings.shading.samples) || settings.subdivision.method == MethodName::Trace
    }

    /// How a frame is cut into tiles when it is larger than the adapter draws at once (its
    /// texture side, its read-back buffer), than `max_tile` pixels a side, or than
    /// `WHOLE_FRAME_BYTES` of colour: None where it is drawn whole. Tiles are at most the texture's side (divided by the larger image a sample
    /// count beyond the adapter's needs), and strips of them (the frame's width, the tile's
    /// height) hold at most `STRIP_BYTES` of both eyes' colour.
    pub fn tiles(&self, settings: &RenderSettings, max_tile: Option<u32>) -> Option<Tiles> {
        let p = settings.projection();
        let (kx, ky) = self.larger_factor(settings);
        let side = (self.gpu.limits.max_texture_dimension_2d / kx.max(ky)).min(max_tile.unwrap_or(u32::MAX)).max(16);
        let padded_row = |w: u32| (4 * w as u64 * kx as u64).div_ceil(256) * 256;
        let fits_buffer = |w: u32, h: u32| 2 * padded_row(w) * h as u64 * ky as u64 <= self.gpu.limits.max_buffer_size;
        let small = 8 * p.width as u64 * p.height as u64 <= WHOLE_FRAME_BYTES;
        if small
            && p.width <= side
            && p.height <= side
            && fits_buffer(p.width, p.height)
            && max_tile.is_none_or(|m| m >= p.width.max(p.height))
        {
            return None;
        }
        let tile_w = p.width.min(side);
        let rows_buffer = (self.gpu.limits.max_buffer_size / (2 * padded_row(tile_w) * ky as u64)).max(1);
        let rows_strip = (STRIP_BYTES / (8 * p.width as u64)).max(1);
        let tile_h = (p.height.min(side) as u64).min(rows_buffer).min(rows_strip).max(1) as u32;
        let face = p.model().tile_face(p);
        Some(Tiles { width: p.width, height: p.height, tile_w, tile_h, face })
    }

    /// A frame in tiles ([`Renderer::tiles`]), handed on strip by strip from the top: each
    /// strip's first row and its frame (the frame's width, the tile's height: both eyes' colour,
    /// and the depth and linear colour where `settings` measure them). The error pass and the
    /// surface points are not drawn. Returns the frame's statistics, summed over the tiles.
    pub fn render_tiled(
        &self,
        scene: &GpuScene,
        settings: &RenderSettings,
        tiles: Tiles,
        mut strip: impl FnMut(u32, Frame) -> Result<()>,
    ) -> Result<crate::core::frame::FrameStats> {
        let settings = settings.with_measure_error(false).with_positions(false);
        let p = *settings.projection();
        let mut stats = crate::core::frame::FrameStats::default();
        let width = tiles.width as usize;
        for y in (0..tiles.height).step_by(tiles.tile_h as usize) {
            let h = tiles.tile_h.min(tiles.height - y);
            let n = width * h as usize;
            let eye = || EyeImage { width: tiles.width, height: h, rgba: vec![0; 4 * n] };
            let mut whole = Frame {
                left: eye(),
                right: eye(),
                stats: Default::default(),
                measurement: None,
                depth: settings.measure.depth.then(|| [vec![0.0; n], vec![0.0; n]]),
                positions: None,
                hdr: settings.shading.hdr.then(|| [vec![[0.0; 3]; n], vec![[0.0; 3]; n]]),
            };
            for (x, w) in tiles.columns() {
                let w = w as usize;
                let tile = settings.with_projection(Projection { tile: Some([x, y, w as u32, h]), ..p });
                let frame = self.render(scene, &tile)?;
                // Row by row into the strip: each eye's colour, depth and linear colour.
                let x = x as usize;
                place(&mut whole.left.rgba, &frame.left.rgba, width, x, w, 4);
                place(&mut whole.right.rgba, &frame.right.rgba, width, x, w, 4);
                if let (Some(to), Some(from)) = (whole.depth.as_mut(), frame.depth.as_ref()) {
                    (0..2).for_each(|k| place(&mut to[k], &from[k], width, x, w, 1));
                }
                if let (Some(to), Some(from)) = (whole.hdr.as_mut(), frame.hdr.as_ref()) {
                    (0..2).for_each(|k| place(&mut to[k], &from[k], width, x, w, 1));
                }
                stats.add_tile(&frame.stats);
            }
            strip(y, whole)?;
        }
        Ok(stats)
    }

    /// How many times larger (x, y) a frame is drawn for a sample count beyond the adapter's
    /// ([`Renderer::render_larger`]); (1, 1) where the adapter draws it.
    fn larger_factor(&self, settings: &RenderSettings) -> (u32, u32) {
        if self.draws_directly(settings) {
            return (1, 1);
        }
        let n = settings.shading.samples;
        let counts = crate::gpu::targets::sample_counts(&self.gpu);
        let base = counts.iter().copied().filter(|&c| n % c == 0 && c < n).max().unwrap_or(1);
        let cells = n / base;
        (1u32 << cells.ilog2().div_ceil(2), 1u32 << (cells.ilog2() / 2))
    }

    /// `--samples N` beyond the adapter's counts: the colour drawn at a larger size with the
    /// most samples the adapter has that divide N (kx × ky pixels per pixel, kx·ky·base = N),
    /// then box-filtered in linear light ([`EyeImage::box_filtered`]). The subdivision's L and τ
    /// are scaled with the image, so that its geometry is that of the frame's size. The outputs
    /// at the pixels' centres (depth, the error pass, the linear colour) come from a frame of the
    /// asked size with one sample, drawn first.
    fn render_larger(&self, scene: &GpuScene, settings: &RenderSettings, counts: &[u32]) -> Result<Frame> {
        let n = settings.shading.samples;
        let base = counts.iter().copied().filter(|&c| n % c == 0 && c < n).max().unwrap_or(1);
        let (kx, ky) = self.larger_factor(settings);
        let p = *settings.projection();
        let (width, height) = (p.width.saturating_mul(kx), p.height.saturating_mul(ky));
        let tile = p.tile.map(|[x, y, w, h]| [x * kx, y * ky, w * kx, h * ky]);
        let [drawn_w, drawn_h] = p.image_size().map(|v| v as u64);
        let max = self.gpu.limits.max_texture_dimension_2d as u64;
        if drawn_w * kx as u64 > max || drawn_h * ky as u64 > max {
            let (width, height) = (drawn_w * kx as u64, drawn_h * ky as u64);
            return Err(Error::setting(
                "shading.samples",
                format!(
                    "the adapter draws up to {base} samples per pixel; {n} would need a {kx}x{ky} larger image, \
                     {width}x{height}, beyond its largest ({max}x{max}): ask for {base} or fewer"
                ),
            ));
        }
        let k = kx.min(ky) as f32;
        let method = match settings.subdivision.method {
            MethodName::Slit(w) => MethodName::Slit(w * kx),
            m => m,
        };
        let larger = settings
            .with_projection(Projection { width, height, tile, ..p })
            .with_method(method)
            .with_edge_px(settings.subdivision.edge_px * k)
            .with_max_error_px(settings.subdivision.max_error_px * k)
            .with_samples(base)
            .with_measure_error(false)
            .with_depth(false)
            .with_positions(false)
            .with_hdr(false);
        self.check_size(&larger)?;
        let centre_outputs = settings.measure.outputs() > 1 || settings.shading.hdr;
        let centre =
            if centre_outputs { Some(self.render_direct(scene, &settings.with_samples(1), false)?.0) } else { None };
        let drawn = self.render_direct(scene, &larger, false)?.0;
        let (left, right) = (drawn.left.box_filtered(kx, ky), drawn.right.box_filtered(kx, ky));
        let mut frame = match centre {
            Some(centre) => Frame { left, right, ..centre },
            None => Frame { left, right, ..drawn },
        };
        frame.stats.samples = n;
        frame.stats.sampling = format!(
            "{base} sample{} per pixel of a {kx}x{ky} larger image, box-filtered{}",
            if base > 1 { "s" } else { "" },
            if centre_outputs { "; depth, error and linear colour at the centres" } else { "" }
        );
        Ok(frame)
    }

    /// A frame at the sample count the adapter draws; shown (`show`): its colour kept on the
    /// GPU for the live window instead of read back.
    fn render_direct(
        &self,
        scene: &GpuScene,
        settings: &RenderSettings,
        show: bool,
    ) -> Result<(Frame, Option<ShownFrame>)> {
        let shadow_maps = scene.write_lighting(&self.gpu, settings);
        let recording = self.record_with(scene, settings, shadow_maps.len());
        self.run_recording(scene, settings, &recording, &shadow_maps, show)
    }

    /// Records the frame `settings` draw of `scene` as this renderer would now
    /// ([`record_frame`] with what it holds): what [`Renderer::render_recorded`] runs.
    pub fn record(&self, scene: &GpuScene, settings: &RenderSettings) -> FrameRecording {
        let (_, _, maps) = settings.shadowed_lighting(
            &scene.lights,
            scene.physically_based,
            scene.environment.as_deref(),
            scene.bounds,
        );
        self.record_with(scene, settings, maps.len())
    }

    /// [`Renderer::record`] with the lights' `shadow_maps` known.
    fn record_with(&self, scene: &GpuScene, settings: &RenderSettings, shadow_maps: usize) -> FrameRecording {
        let resources = self.resources.lock().unwrap_or_else(|e| e.into_inner());
        let facts = FrameFacts {
            triangles: scene.triangle_count,
            shadow_maps: shadow_maps as u32,
            cached: resources.buffers.as_ref().map(|b| b.capacity),
            max_binding: self.gpu.max_binding(),
        };
        record_frame(settings, &facts)
    }

    /// Draws a recorded frame of `scene` ([`Renderer::record`]; the CPU twins run the same
    /// recording, `cpu::render::render_recorded`), at a sample count the adapter draws. A
    /// recording that cannot draw the frame the settings record (other steps, other slits; its
    /// subdivision's plan is free) is one error.
    pub fn render_recorded(
        &self,
        scene: &GpuScene,
        settings: &RenderSettings,
        recording: &FrameRecording,
    ) -> Result<Frame> {
        settings.validate()?;
        self.check_size(settings)?;
        if !self.draws_directly(settings) {
            let (n, counts) = (settings.shading.samples, crate::gpu::targets::sample_counts(&self.gpu));
            return Err(Error::setting(
                "shading.samples",
                format!("a recorded frame is drawn at a sample count the adapter has ({counts:?}), not {n}: `render` makes up the others"),
            ));
        }
        let shadow_maps = scene.write_lighting(&self.gpu, settings);
        recording.check(&self.record_with(scene, settings, shadow_maps.len()))?;
        Ok(self.run_recording(scene, settings, recording, &shadow_maps, false)?.0)
    }

    /// Runs a frame's recording, step by step: the shadow maps, the method's drawing, then its
    /// end (the read-back and the reduction, `FrameEnd`).
    fn run_recording(
        &self,
        scene: &GpuScene,
        settings: &RenderSettings,
        recording: &FrameRecording,
        shadow_maps: &[crate::core::shading::shadow::GpuShadowMap],
        show: bool,
    ) -> Result<(Frame, Option<ShownFrame>)> {
        let mut resources = self.resources.lock().unwrap_or_else(|e| e.into_inner());
        self.gpu.scoped("rendering a frame", || {
            let end = FrameEnd { stages: &self.end, recording, show, shown: std::cell::OnceCell::new() };
            let mut drawn = None;
            for step in &recording.steps {
                let method: &dyn Method = match step {
                    FrameStep::Shadow { .. } => {
                        let shadow = self.shadow.get_or_init(|| ShadowStage::new(&self.gpu));
                        shadow.draw_maps(&self.gpu, scene, settings.view(), shadow_maps)?;
                        continue;
                    }
                    FrameStep::Subdivided { .. } => self.subdivided(),
                    FrameStep::Slit { .. } => self.slit.get_or_init(|| SlitMethod::new(&self.gpu)),
                    FrameStep::Trace => &self.trace,
                    // The frame's end, run by the drawing step's `FrameEnd::finish`.
                    FrameStep::ReadBack { .. } | FrameStep::ReduceError { .. } => continue,
                };
                drawn = Some(method.draw(&self.gpu, &end, &mut resources, scene, settings, step)?);
            }
            let mut frame = drawn.ok_or_else(|| Error::Gpu("the frame's recording draws nothing".into()))?;
            let n = settings.shading.samples;
            frame.stats.samples = n;
            frame.stats.sampling = match crate::gpu::targets::Samples::passes(settings).as_slice() {
                [_] if n == 1 => "1 sample at each pixel's centre".to_string(),
                _ if settings.subdivision.method == MethodName::Trace => {
                    format!("{n} rays per pixel at the standard sample positions; error, object and distance of the centre's ray")
                }
                [_] => format!("multisampled {n} (a pass per eye)"),
                _ => format!("multisampled {n} (a pass per eye), depth, error and linear colour at the centres"),
            };
            Ok((frame, end.shown.into_inner()))
        })
    }

    /// Renders both eyes for the live window: the same frame as [`Renderer::render`], its
    /// colour left on the GPU for the display stage (the images of the returned frame are
    /// empty), or, for a sample count beyond the adapter's (box-filtered on the CPU), uploaded.
    pub fn render_shown(&self, scene: &GpuScene, settings: &RenderSettings) -> Result<(Frame, ShownFrame)> {
        settings.validate()?;
        self.check_size(settings)?;
        if !self.draws_directly(settings) {
            let frame = self.render_larger(scene, settings, &crate::gpu::targets::sample_counts(&self.gpu))?;
            let shown = ShownFrame::upload(&self.gpu, &[&frame.left, &frame.right]);
            return Ok((frame, shown));
        }
        let (frame, shown) = self.render_direct(scene, settings, true)?;
        let shown = shown.ok_or_else(|| Error::Gpu("the frame's colour was not kept for the window".into()))?;
        Ok((frame, shown))
    }

    /// The display stage (the live window's), built when first asked for.
    pub fn display(&self) -> &DisplayStage {
        self.display.get_or_init(|| DisplayStage::new(&self.gpu))
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
        let [width, height] = p.image_size();
        let max = self.gpu.limits.max_texture_dimension_2d;
        if width > max || height > max {
            return Err(Error::setting(
                "view.projection.width/height",
                format!(
                    "{width}x{height} is larger than this GPU's largest image, {max}x{max}: draw it in tiles \
                     (`render` does where it can)"
                ),
            ));
        }
        // Both eyes' colour targets are read back through one buffer (rows padded to 256
        // bytes); with the error pass, each eye's error target is bound as storage (both at once
        // when they fit one binding).
        let padded_row = (4 * width as u64).div_ceil(256) * 256;
        let eyes_bytes = 2 * padded_row * height as u64;
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
                    width,
                    height,
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
        if settings.projection().model().drawn_as_pinhole() {
            return Err(Error::setting(
                "view.projection.wall",
                "a CAVE wall is drawn as one perspective per eye, without subdivision: there is none to read back",
            ));
        }
        self.subdivided().subdivide.readback(&self.gpu, scene, settings, schedule)
    }
}
