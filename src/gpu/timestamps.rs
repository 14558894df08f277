//! GPU timestamps of a frame's passes, where the adapter has timestamp queries: one query set
//! of four (subdivision begin/end, raster begin/end) with its resolve buffer, made once; and the
//! timed submission of the one-pass frames (slit, trace).

use std::time::Instant;

use crate::core::frame::{FrameStats, Timing};
use crate::error::Result;
use crate::gpu::device::Gpu;

pub const COUNT: u32 = 4;

pub struct Timestamps {
    pub set: wgpu::QuerySet,
    resolve: wgpu::Buffer,
    period_ns: f64,
}

impl Timestamps {
    pub fn new(gpu: &Gpu) -> Option<Timestamps> {
        gpu.features.contains(wgpu::Features::TIMESTAMP_QUERY).then(|| Timestamps {
            set: gpu.device.create_query_set(&wgpu::QuerySetDescriptor {
                label: Some("frame times"),
                ty: wgpu::QueryType::Timestamp,
                count: COUNT,
            }),
            resolve: gpu.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("timestamps"),
                size: 8 * COUNT as u64,
                usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            }),
            period_ns: gpu.queue.get_timestamp_period() as f64,
        })
    }

    /// Resolves the timestamps and copies them to `staging` at `offset` (encoded, not submitted).
    pub fn resolve(&self, enc: &mut wgpu::CommandEncoder, staging: &wgpu::Buffer, offset: u64) {
        enc.resolve_query_set(&self.set, 0..COUNT, &self.resolve, 0);
        enc.copy_buffer_to_buffer(&self.resolve, 0, staging, offset, 8 * COUNT as u64);
    }

    /// Milliseconds between two ticks.
    pub fn ms(&self, from: u64, to: u64) -> f64 {
        to.saturating_sub(from) as f64 * self.period_ns * 1e-6
    }
}

/// Submits the one-pass frame of the slit and trace stages (its timestamps, if any, at indices
/// 0 and 1), waits for it, and records its time in `stats`: the wall time since `started` as
/// `ms_frame`, and the GPU time of the pass as `ms_gpu` and `ms_raster` where timestamps exist.
pub fn submit_timed_pass(
    gpu: &Gpu,
    mut enc: wgpu::CommandEncoder,
    timestamps: Option<&Timestamps>,
    staging: &wgpu::Buffer,
    started: Instant,
    stats: &mut FrameStats,
) -> Result<()> {
    if let Some(t) = timestamps {
        t.resolve(&mut enc, staging, 0);
    }
    gpu.queue.submit([enc.finish()]);
    gpu.wait();
    stats.ms_frame = started.elapsed().as_secs_f64() * 1e3;
    stats.ms_raster = Some(stats.ms_frame);
    stats.timing = Timing::WallOneSubmission;
    if let Some(t) = timestamps {
        let bytes = gpu.read_buffer(staging)?;
        let ticks: &[u64] = bytemuck::cast_slice(&bytes[..16]);
        stats.ms_gpu = Some(t.ms(ticks[0], ticks[1]));
        stats.ms_raster = stats.ms_gpu;
        stats.timing = Timing::GpuTimestamps;
    }
    Ok(())
}
