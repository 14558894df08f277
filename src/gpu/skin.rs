//! The `skin` stage on the GPU (twin `cpu::skin`): an animated scene posed in a compute pass
//! that writes the scene's vertex buffer, before `subdivide` reads it. The sources and morph
//! offsets are uploaded on the first pose; each frame writes only the instances' matrices, the
//! joint matrices and the morph weights.

use std::sync::OnceLock;

use crate::core::scenes::scene::Scene;
use crate::encoding::skin::{SkinData, SkinFrame};
use crate::encoding::types::SkinParams;
use crate::error::{Error, Result};
use crate::gpu::device::Gpu;
use crate::gpu::scene::{GpuRig, GpuScene};
use crate::gpu::stages::GpuStage;
use crate::shader::SKIN;

const IDENTITY: [[[f32; 4]; 4]; 1] =
    [[[1.0, 0.0, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0], [0.0, 0.0, 0.0, 1.0]]];

/// The stage's layouts and pipeline, made on the first pose.
#[derive(Default)]
pub(crate) struct SkinStage(OnceLock<(GpuStage, wgpu::ComputePipeline)>);

impl SkinStage {
    /// Poses `scene` at time t of clip `clip` (None: the rest pose) on the GPU: its lights and
    /// cameras on the CPU (`Scene::pose_with`, vertices left), its vertices by the skin stage
    /// into `gpu_scene`'s vertex buffer; the bounds the shadow maps fit follow the pose. A scene
    /// without a rig is left as it is.
    pub fn pose(
        &self,
        gpu: &Gpu,
        gpu_scene: &mut GpuScene,
        scene: &mut Scene,
        clip: Option<usize>,
        t: f32,
    ) -> Result<()> {
        let Some(rig) = scene.rig.as_deref() else { return Ok(()) };
        let frame = SkinFrame::of(rig, clip, t);
        if gpu_scene.rig.is_none() {
            gpu_scene.rig = Some(upload_rig(gpu, &scene.name, SkinData::of(rig), &frame)?);
        } else if let Some(rig_gpu) = &gpu_scene.rig {
            // The first pose made the buffers with its tables; later ones write theirs.
            for (buffer, bytes) in [
                (&rig_gpu.instances, bytemuck::cast_slice::<_, u8>(&frame.instances)),
                (&rig_gpu.joints, bytemuck::cast_slice(&frame.joints)),
                (&rig_gpu.weights, bytemuck::cast_slice(&frame.weights)),
            ] {
                if !bytes.is_empty() {
                    gpu.queue.write_buffer(buffer, 0, bytes);
                }
            }
        }
        let rig_gpu = gpu_scene.rig.as_ref().expect("made on the first pose");
        let (stage, pipeline) = self.0.get_or_init(|| {
            let stage = GpuStage::new(gpu, &SKIN);
            let pipeline = stage.compute(gpu, "skin");
            (stage, pipeline)
        });
        let count = rig_gpu.data.sources.len() as u32;
        gpu.scoped("posing the scene", || {
            let group = stage.bind_group(
                gpu,
                Some("skin"),
                0,
                &[
                    &rig_gpu.params,
                    &rig_gpu.sources,
                    &rig_gpu.deltas,
                    &rig_gpu.instances,
                    &rig_gpu.joints,
                    &rig_gpu.weights,
                    &gpu_scene.vertices,
                ],
            );
            let mut enc = gpu.device.create_command_encoder(&Default::default());
            {
                let mut pass = enc.begin_compute_pass(&Default::default());
                pass.set_pipeline(pipeline);
                pass.set_bind_group(0, &group, &[]);
                let (x, y) = gpu.workgroups(count, 64);
                pass.dispatch_workgroups(x, y, 1);
            }
            gpu.queue.submit([enc.finish()]);
            Ok(())
        })?;
        scene.pose_with(clip, t, false);
        gpu_scene.lights = scene.lights.clone();
        gpu_scene.bounds = frame.bounds(&rig_gpu.data).or(gpu_scene.bounds);
        gpu_scene.shadows.lock().unwrap_or_else(|e| e.into_inner()).drawn.clear();
        Ok(())
    }
}

/// The skin stage's tables on the GPU, made on the first pose with its frame's matrices and
/// weights. Fails with one line where the animated vertices are more than the device binds.
fn upload_rig(gpu: &Gpu, name: &str, data: SkinData, frame: &SkinFrame) -> Result<GpuRig> {
    let bytes = std::mem::size_of_val(data.sources.as_slice()).max(std::mem::size_of_val(data.deltas.as_slice()));
    if bytes as u64 > gpu.max_binding() {
        return Err(Error::scene(name, "its animated vertices are more than this GPU binds"));
    }
    let storage = |label: &str, bytes: &[u8], write: bool| {
        let copy = if write { wgpu::BufferUsages::COPY_DST } else { wgpu::BufferUsages::empty() };
        gpu.init_buffer(label, bytes, wgpu::BufferUsages::STORAGE | copy)
    };
    Ok(GpuRig {
        params: gpu.init_buffer(
            "skin params",
            bytemuck::bytes_of(&SkinParams { count: data.sources.len() as u32, ..Default::default() }),
            wgpu::BufferUsages::UNIFORM,
        ),
        sources: storage("skin sources", bytemuck::cast_slice(&data.sources), false),
        deltas: storage("morph offsets", bytemuck::cast_slice(&data.deltas), false),
        instances: storage("skin instances", bytemuck::cast_slice(&frame.instances), true),
        // At least one matrix: a binding of mat4x4 holds 64 bytes or more.
        joints: storage(
            "joint matrices",
            bytemuck::cast_slice(if frame.joints.is_empty() { &IDENTITY } else { &frame.joints[..] }),
            true,
        ),
        weights: storage("morph weights", bytemuck::cast_slice(&frame.weights), true),
        data,
    })
}
