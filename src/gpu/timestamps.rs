//! GPU timestamps of a frame's passes, where the adapter has timestamp queries: one query set
//! of four (subdivision begin/end, raster begin/end) with its resolve buffer, made once.

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
