//! A frame's resources and its end: what a renderer keeps between frames (targets, uniforms,
//! the subdivision's buffers), the [`Method`] each way of drawing a frame implements, and
//! [`FrameEnd`], which reads a drawn frame back and reduces its error.

use std::time::Instant;

use crate::core::frame::{EyeImage, Frame, FrameStats, Measurement};
use crate::core::settings::RenderSettings;
use crate::encoding::frame::{FrameRecording, FrameStep};
use crate::error::Result;
use crate::gpu::device::Gpu;
use crate::gpu::display::ShownFrame;
use crate::gpu::frame_plan::SubdivisionBuffers;
use crate::gpu::reduce_error::ReduceStage;
use crate::gpu::scene::GpuScene;
use crate::gpu::subdivide::COUNTERS_SIZE;
use crate::gpu::targets::{copy_eyes_to_buffer, Targets};
use crate::gpu::timestamps::{self as stamp, Timestamps};

/// What a renderer keeps between frames.
pub(crate) struct FrameResources {
    pub buffers: Option<SubdivisionBuffers>,
    /// Targets of the last image size.
    pub targets: Option<Targets>,
    pub timestamps: Option<Timestamps>,
    pub subdivide_params: wgpu::Buffer,
    /// Both eyes' (left, right), as the raster stage's `array<RasterParams, 2>`; the cubemap's
    /// six face draws each at its own offset ([`raster_params_stride`]).
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

/// The distance between the raster parameters of the cubemap's face draws in their buffer: a
/// `[RasterParams; 2]` rounded up to the adapter's uniform offset alignment.
pub(crate) fn raster_params_stride(gpu: &Gpu) -> u64 {
    let size = std::mem::size_of::<[crate::encoding::types::RasterParams; 2]>() as u64;
    size.next_multiple_of(gpu.limits.min_uniform_buffer_offset_alignment.max(1) as u64)
}

impl FrameResources {
    /// The targets for this size (with the positions target if `positions`, the linear colour's
    /// if `hdr`, the multisampled colour for `samples` > 1), made anew only when the size, the
    /// linear colour or the samples changed or the positions target is wanted and missing.
    pub fn targets(
        &mut self,
        gpu: &Gpu,
        width: u32,
        height: u32,
        positions: bool,
        hdr: bool,
        samples: u32,
    ) -> &Targets {
        if !self.targets.as_ref().is_some_and(|t| {
            t.width == width
                && t.height == height
                && (t.position.is_some() || !positions)
                && t.hdr == hdr
                && t.multisampled.as_ref().map_or(1, |m| m.samples) == samples
        }) {
            // The old ones first: a large frame's targets twice over may not fit.
            self.targets = None;
            self.targets = Some(Targets::new(gpu, width, height, positions, hdr, samples));
        }
        self.targets.as_ref().expect("just made")
    }
}

pub(crate) const STAGING_SIZE: u64 = COUNTERS_SIZE + 8 * stamp::COUNT as u64;

/// A way of drawing a frame (as pbrt's `Integrator`): the projection methods' subdivided
/// raster, the slit mosaic, the ray tracer — the GPU's side of a recording's drawing step
/// (`encoding::frame::FrameStep`). Each draws into the frame's resources and ends with
/// [`FrameEnd::finish`].
pub(crate) trait Method {
    fn draw(
        &self,
        gpu: &Gpu,
        end: &FrameEnd,
        res: &mut FrameResources,
        scene: &GpuScene,
        settings: &RenderSettings,
        step: &FrameStep,
    ) -> Result<Frame>;
}

/// The stages at the end of every frame, kept by the renderer: the `reduce_error` stage (built
/// when first needed).
#[derive(Default)]
pub(crate) struct EndStages {
    reduce: std::sync::OnceLock<ReduceStage>,
}

/// One frame's end, its recording's last steps: the read-back of its targets and, with the
/// error pass, the reduction. A frame the live window shows (`show`) keeps its colour on the GPU
/// instead, copied into a storage buffer for the display stage (`shown`).
pub(crate) struct FrameEnd<'a> {
    pub stages: &'a EndStages,
    pub recording: &'a FrameRecording,
    pub show: bool,
    pub shown: std::cell::OnceCell<ShownFrame>,
}

impl FrameEnd<'_> {
    /// Reads the targets back and reduces the error: the end of every render.
    pub fn finish(&self, gpu: &Gpu, targets: &Targets, mut stats: FrameStats, start: Instant) -> Result<Frame> {
        let t = Instant::now();
        let [left, right] = if self.show {
            let (texels, row_texels) =
                copy_eyes_to_buffer(gpu, &targets.color, wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC);
            let (width, height) = (targets.width, targets.height);
            let shown = ShownFrame { texels, width, height, row_texels, layers: 2 };
            let _ = self.shown.set(shown);
            [0, 1].map(|_| EyeImage { width, height, rgba: Vec::new() })
        } else {
            targets.read_colors(gpu)?
        };
        let steps = &self.recording.steps;
        let read = steps.iter().find_map(|s| match *s {
            FrameStep::ReadBack { hdr, depth, positions, error } => Some((hdr, depth, positions, error)),
            _ => None,
        });
        let (hdr, depth, positions, _) = read.unwrap_or_default();
        let hdr = if hdr && targets.hdr { Some(targets.read_hdr(gpu)?) } else { None };
        stats.ms_readback = t.elapsed().as_secs_f64() * 1e3;
        let depth = if depth { Some(targets.read_distances(gpu)?) } else { None };
        let positions = if positions { Some(targets.read_positions(gpu)?) } else { None };
        let reduce = steps.iter().find_map(|s| match *s {
            FrameStep::ReduceError { per_eye } => Some(per_eye),
            _ => None,
        });
        let measurement = match reduce {
            Some(per_eye) => {
                let object = targets.read_objects(gpu)?;
                let reduce = self.stages.reduce.get_or_init(|| ReduceStage::new(gpu));
                let (stats, error) = reduce.reduce(gpu, targets, per_eye)?;
                Some(Measurement { error, object, stats })
            }
            None => None,
        };
        stats.ms_total = start.elapsed().as_secs_f64() * 1e3;
        Ok(Frame { left, right, stats, measurement, depth, positions, hdr })
    }
}
