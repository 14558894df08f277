//! GPU timestamps of a frame's passes, where the adapter has timestamp queries: one query set
//! (begin/end of each of the subdivision's passes — `active_cuts` … `lattice_triangles`, see
//! `encoding::subdivide::one_submission` — and of the raster, whose pair follows the last
//! pass's) with its resolve buffer, made once; and the timed submission of the one-pass frames
//! (slit, trace).

use std::time::Instant;

use crate::core::frame::{FrameStats, Timing};
use crate::error::Result;
use crate::gpu::device::Gpu;

/// Queries: a pair per timed pass of the subdivision, and the raster's.
pub const COUNT: u32 = 2 * crate::encoding::subdivide::TIMED_PASSES + 2;

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

    /// Resolves the first `count` timestamps and copies them to `staging` at `offset` (encoded,
    /// not submitted).
    pub fn resolve(&self, enc: &mut wgpu::CommandEncoder, staging: &wgpu::Buffer, offset: u64, count: u32) {
        enc.resolve_query_set(&self.set, 0..count, &self.resolve, 0);
        enc.copy_buffer_to_buffer(&self.resolve, 0, staging, offset, 8 * count as u64);
    }

    /// Timestamp writes at the begin and end (`first`, `first` + 1) of a compute pass.
    pub fn pass_writes(&self, first: u32) -> wgpu::ComputePassTimestampWrites<'_> {
        wgpu::ComputePassTimestampWrites {
            query_set: &self.set,
            beginning_of_pass_write_index: Some(first),
            end_of_pass_write_index: Some(first + 1),
        }
    }

    /// Milliseconds between two ticks.
    pub fn ms(&self, from: u64, to: u64) -> f64 {
        to.saturating_sub(from) as f64 * self.period_ns * 1e-6
    }
}

/// The timestamp writes of render pass `p` of `count` into `query` at slots (begin, end): the
/// start of the first pass and the end of the last only (a pass with neither gets none).
pub fn first_and_last(
    query: Option<(&wgpu::QuerySet, u32, u32)>,
    p: usize,
    count: usize,
) -> Option<wgpu::RenderPassTimestampWrites<'_>> {
    let (first, last) = (p == 0, p + 1 == count);
    query.filter(|_| first || last).map(|(query_set, begin, end)| wgpu::RenderPassTimestampWrites {
        query_set,
        beginning_of_pass_write_index: first.then_some(begin),
        end_of_pass_write_index: last.then_some(end),
    })
}

/// A compute pass, timed at queries `first` and `first` + 1 where there are timestamps.
pub fn compute_pass<'e>(
    enc: &'e mut wgpu::CommandEncoder,
    label: &str,
    timestamps: Option<&Timestamps>,
    first: u32,
) -> wgpu::ComputePass<'e> {
    enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
        label: Some(label),
        timestamp_writes: timestamps.map(|t| t.pass_writes(first)),
    })
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
        t.resolve(&mut enc, staging, 0, 2);
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
