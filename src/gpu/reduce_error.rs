//! The `reduce_error` stage on the GPU (twin `cpu::reduce_error`): error statistics of both
//! eyes' error targets.

use crate::error::Result;
use crate::gpu::renderer::Renderer;
use crate::gpu::targets::{copy_eyes_to_buffer, unpad_eyes, Targets};
use crate::shader::constants::BINS;
use crate::shader::types::{ErrorStats, ReduceParams, Totals};

/// Invocations per workgroup of `accumulate` (`WG` in the WGSL).
const WORKGROUP: u32 = 256;

impl Renderer {
    /// Runs `reduce_error` over the error targets of both eyes; also returns the per-pixel errors.
    pub(crate) fn reduce_errors(&self, targets: &Targets) -> Result<(ErrorStats, [Vec<f32>; 2])> {
        let gpu = &self.gpu;
        let (w, h) = (targets.width, targets.height);
        let (errors, stride) =
            copy_eyes_to_buffer(gpu, &targets.error, wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC);
        let (gx, gy) = gpu.workgroups(2 * w * h, WORKGROUP);
        let params = ReduceParams {
            width: w,
            height: h,
            row_stride: stride,
            images: 2,
            partial_count: gx * gy,
            ..Default::default()
        };
        let uniform = gpu.init_buffer("reduce params", bytemuck::bytes_of(&params), wgpu::BufferUsages::UNIFORM);
        let storage = |label, size: u64| gpu.storage_buffer(label, size, wgpu::BufferUsages::empty());
        let histogram = storage("histogram", 4 * BINS as u64);
        let partials = storage("partial sums", 8 * (gx * gy) as u64);
        let totals = storage("totals", std::mem::size_of::<Totals>() as u64);
        let result = storage("error stats", std::mem::size_of::<ErrorStats>() as u64);
        let buffers = [&uniform, &errors, &histogram, &partials, &totals, &result];
        let accumulate = self.reduce.bind_group(gpu, Some("accumulate"), 0, &buffers);
        let finish = self.reduce.bind_group(gpu, Some("finish"), 0, &buffers);
        let mut enc = gpu.device.create_command_encoder(&Default::default());
        enc.clear_buffer(&histogram, 0, None);
        enc.clear_buffer(&totals, 0, None);
        {
            let mut pass = enc.begin_compute_pass(&Default::default());
            pass.set_pipeline(&self.accumulate);
            pass.set_bind_group(0, &accumulate, &[]);
            pass.dispatch_workgroups(gx, gy, 1);
            pass.set_pipeline(&self.finish);
            pass.set_bind_group(0, &finish, &[]);
            pass.dispatch_workgroups(1, 1, 1);
        }
        gpu.queue.submit([enc.finish()]);
        let stats: ErrorStats =
            *bytemuck::from_bytes(&gpu.download(&result, std::mem::size_of::<ErrorStats>() as u64)?);
        let per_eye = unpad_eyes(&gpu.download(&errors, errors.size())?, w, h, stride);
        Ok((stats, per_eye.map(|v| v.into_iter().map(f32::from_bits).collect())))
    }
}
