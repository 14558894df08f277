//! The `project_points` stage on the GPU (twin `cpu::project_points`): pixel positions of
//! viewer-frame points for one eye, the check of the WGSL projection against the CPU oracle.

use std::sync::OnceLock;

use glam::Vec3;

use crate::core::panoramas::projection::{Eye, Projection};
use crate::encoding::types::ProjectParams;
use crate::error::Result;
use crate::gpu::device::Gpu;
use crate::gpu::stages::GpuStage;
use crate::shader::PROJECT_POINTS;

/// The stage's layouts and pipeline, made on first use.
#[derive(Default)]
pub(crate) struct ProjectPointsStage(OnceLock<(GpuStage, wgpu::ComputePipeline)>);

impl ProjectPointsStage {
    /// `[pixel x, pixel y, depth, 1]` per point, or zeros where no eye sees it. The pipeline is
    /// built on first use; any number of points (none included) within the device's buffer size.
    pub fn project(&self, gpu: &Gpu, projection: &Projection, eye: Eye, points: &[Vec3]) -> Result<Vec<[f32; 4]>> {
        if points.is_empty() {
            return Ok(Vec::new());
        }
        gpu.scoped("projecting points", || {
            let (stage, pipeline) = self.0.get_or_init(|| {
                let stage = GpuStage::new(gpu, &PROJECT_POINTS);
                let pipeline = stage.compute(gpu, "project_points");
                (stage, pipeline)
            });
            let params = ProjectParams {
                projection: projection.into(),
                eye_sign: eye.sign(),
                count: points.len() as u32,
                _pad: [0.0; 2],
            };
            let uniform = gpu.init_buffer("project params", bytemuck::bytes_of(&params), wgpu::BufferUsages::UNIFORM);
            let input: Vec<[f32; 4]> = points.iter().map(|p| [p.x, p.y, p.z, 1.0]).collect();
            let input = gpu.init_buffer("points", bytemuck::cast_slice(&input), wgpu::BufferUsages::STORAGE);
            let size = (points.len() * 16) as u64;
            let output = gpu.storage_buffer("pixels", size, wgpu::BufferUsages::empty());
            let bind_group = stage.bind_group(gpu, Some("project_points"), 0, &[&uniform, &input, &output]);
            let mut enc = gpu.device.create_command_encoder(&Default::default());
            {
                let mut pass = enc.begin_compute_pass(&Default::default());
                pass.set_pipeline(pipeline);
                pass.set_bind_group(0, &bind_group, &[]);
                let (x, y) = gpu.workgroups(points.len() as u32, 64);
                pass.dispatch_workgroups(x, y, 1);
            }
            gpu.queue.submit([enc.finish()]);
            Ok(bytemuck::cast_slice(&gpu.download(&output, size)?).to_vec())
        })
    }
}
