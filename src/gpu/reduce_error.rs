//! The `reduce_error` stage on the GPU (twin `cpu::reduce_error`): error statistics of both
//! eyes' error targets.

use crate::encoding::constants::BINS;
use crate::encoding::types::{ErrorStats, ReduceParams, Totals};
use crate::error::Result;
use crate::gpu::device::Gpu;
use crate::gpu::stages::GpuStage;
use crate::gpu::targets::{copy_eyes_to_buffer, Targets};
use crate::shader::REDUCE_ERROR;

/// Invocations per workgroup of `accumulate` (`WG` in the WGSL).
const WORKGROUP: u32 = 256;

/// The stage's layouts and its two pipelines (`accumulate`, `finish`).
pub(crate) struct ReduceStage {
    stage: GpuStage,
    accumulate: wgpu::ComputePipeline,
    finish: wgpu::ComputePipeline,
}

impl ReduceStage {
    pub fn new(gpu: &Gpu) -> ReduceStage {
        let stage = GpuStage::new(gpu, &REDUCE_ERROR);
        ReduceStage { accumulate: stage.compute(gpu, "accumulate"), finish: stage.compute(gpu, "finish"), stage }
    }

    /// Runs `reduce_error` over the error targets of both eyes; also returns the per-pixel errors.
    /// Both eyes in one dispatch where they fit one storage binding, else one dispatch per eye
    /// (each eye's rows bound as a range; their sums and histogram add up).
    pub fn reduce(&self, gpu: &Gpu, targets: &Targets, per_eye: bool) -> Result<(ErrorStats, [Vec<f32>; 2])> {
        let (w, h) = (targets.width, targets.height);
        let (errors, stride) =
            copy_eyes_to_buffer(gpu, &targets.error, wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC);
        let eye_bytes = errors.size() / 2;
        let together = errors.size() <= gpu.max_binding() && !per_eye;
        let dispatches: Vec<(u64, u64, u32)> =
            if together { vec![(0, errors.size(), 2)] } else { vec![(0, eye_bytes, 1), (eye_bytes, eye_bytes, 1)] };
        let (gx, gy) = gpu.workgroups(if together { 2 * w * h } else { w * h }, WORKGROUP);
        let partial_count = gx * gy * dispatches.len() as u32;
        let storage = |label, size: u64| gpu.storage_buffer(label, size, wgpu::BufferUsages::empty());
        let histogram = storage("histogram", 4 * BINS as u64);
        let partials = storage("partial sums", 8 * partial_count as u64);
        let totals = storage("totals", std::mem::size_of::<Totals>() as u64);
        let result = storage("error stats", std::mem::size_of::<ErrorStats>() as u64);
        let mut enc = gpu.device.create_command_encoder(&Default::default());
        enc.clear_buffer(&histogram, 0, None);
        enc.clear_buffer(&totals, 0, None);
        let mut uniforms = Vec::new();
        for (k, &(offset, size, images)) in dispatches.iter().enumerate() {
            let params = ReduceParams {
                width: w,
                height: h,
                row_stride: stride,
                images,
                partial_count,
                partial_offset: k as u32 * gx * gy,
                ..Default::default()
            };
            let uniform = gpu.init_buffer("reduce params", bytemuck::bytes_of(&params), wgpu::BufferUsages::UNIFORM);
            let range = wgpu::BufferBinding { buffer: &errors, offset, size: std::num::NonZeroU64::new(size) };
            let buffers = [
                uniform.as_entire_buffer_binding(),
                range,
                histogram.as_entire_buffer_binding(),
                partials.as_entire_buffer_binding(),
                totals.as_entire_buffer_binding(),
                result.as_entire_buffer_binding(),
            ];
            let accumulate = self.stage.bind_group_ranges(gpu, Some("accumulate"), 0, &buffers);
            {
                let mut pass = enc.begin_compute_pass(&Default::default());
                pass.set_pipeline(&self.accumulate);
                pass.set_bind_group(0, &accumulate, &[]);
                pass.dispatch_workgroups(gx, gy, 1);
                if k + 1 == dispatches.len() {
                    let finish = self.stage.bind_group_ranges(gpu, Some("finish"), 0, &buffers);
                    pass.set_pipeline(&self.finish);
                    pass.set_bind_group(0, &finish, &[]);
                    pass.dispatch_workgroups(1, 1, 1);
                }
            }
            uniforms.push(uniform);
        }
        gpu.queue.submit([enc.finish()]);
        let stats: ErrorStats =
            *bytemuck::from_bytes(&gpu.download(&result, std::mem::size_of::<ErrorStats>() as u64)?);
        Ok((stats, targets.read_errors(gpu)?))
    }
}
