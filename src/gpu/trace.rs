//! The ray tracer on the GPU (`trace` stage, twin `cpu::trace`): one compute dispatch over
//! every pixel of both eyes, writing colour, error, object id and distance into buffers that
//! are copied into the render targets' layers, so read-back, error statistics and outputs are
//! those of the other methods.

use std::time::Instant;

use crate::core::frame::{Frame, FrameStats};
use crate::core::panoramas::projection::{ray_hit_points, Projection};
use crate::core::scenes::bvh::SceneBvh;
use crate::core::settings::RenderSettings;
use crate::encoding::constants::TRACE_COUNT_SLOTS;
use crate::encoding::params::trace_params;
use crate::encoding::types::TraceParams;
use crate::error::{Error, Result};
use crate::gpu::device::Gpu;
use crate::gpu::frame::{FrameEnd, FrameResources, Method};
use crate::gpu::scene::GpuScene;
use crate::gpu::stages::GpuStage;
use crate::gpu::targets::Targets;
use crate::gpu::timestamps::submit_timed_pass;

/// The ray tracer: its stage and pipelines without and with the material code, made on first
/// use.
#[derive(Default)]
pub(crate) struct TraceMethod(std::sync::OnceLock<(GpuStage, [wgpu::ComputePipeline; 2])>);

impl Method for TraceMethod {
    fn draw(
        &self,
        gpu: &Gpu,
        end: &FrameEnd,
        res: &mut FrameResources,
        scene: &GpuScene,
        settings: &RenderSettings,
        _: &crate::encoding::frame::FrameStep,
    ) -> Result<Frame> {
        let start = Instant::now();
        let Some(bvh) = &scene.bvh else {
            return Err(Error::setting(
                "subdivision.method",
                "trace needs the scene's BVH, and this scene was uploaded without one (GpuScene::with_bvh; a level-of-detail selection has none yet)",
            ));
        };
        let p = settings.projection();
        let row_texels = Self::prepare_outputs(gpu, res, p)?;
        let counts = res.trace_counts.clone().expect("made with the outputs");
        let res = &*res;
        let targets = res.targets.as_ref().expect("made");
        let (_, _, outputs) = res.trace_outputs.as_ref().expect("made");
        let (stage, pipelines) = self.0.get_or_init(|| {
            let stage = GpuStage::new(gpu, &crate::shader::TRACE);
            let pipelines =
                [0.0, 1.0].map(|m| stage.compute_with(gpu, "trace", &[("MATERIALS", m), ("SHADOW_MAPS", 0.0)]));
            (stage, pipelines)
        });
        let params = trace_params(settings, row_texels);
        let params = TraceParams {
            original_root: bvh.original_root,
            original_level: SceneBvh::original_level_of(bvh.first_step, params.lod_min_share),
            ..params
        };
        gpu.queue.write_buffer(&res.trace_params, 0, bytemuck::bytes_of(&params));
        let group1 = scene.material_buffers();
        let [color, error, object, distance] = outputs;
        let buffers = [&res.trace_params, &scene.vertices, &bvh.indices, &bvh.nodes, &bvh.levels];
        let outputs_and_counts = [color, error, object, distance, &counts];
        let group0: Vec<&wgpu::Buffer> = buffers.into_iter().chain(outputs_and_counts).collect();
        let bind_group = stage.bind_group(gpu, Some("trace"), 0, &group0);
        let materials = stage.bind_group(gpu, Some("trace"), 1, &group1.each_ref());
        let timestamps = res.timestamps.as_ref();
        let t = Instant::now();
        let mut enc = gpu.device.create_command_encoder(&Default::default());
        enc.clear_buffer(&counts, 0, None);
        {
            let mut pass = crate::gpu::timestamps::compute_pass(&mut enc, "trace", timestamps, 0);
            pass.set_pipeline(&pipelines[(scene.needs_materials || scene.has_optics || scene.pbr(settings)) as usize]);
            pass.set_bind_group(0, &bind_group, &[]);
            pass.set_bind_group(1, &materials, &[]);
            let [w, h] = p.image_size();
            pass.dispatch_workgroups(w.div_ceil(8), h.div_ceil(8), 2);
        }
        copy_to_targets(&mut enc, outputs, targets, row_texels, p);
        let mut stats = FrameStats { triangles_in: scene.triangle_count as u64, chunks: 1, ..Default::default() };
        submit_timed_pass(gpu, enc, timestamps, &res.staging, t, &mut stats)?;
        // The counters are read after the frame's time is taken.
        let words = gpu.download(&counts, 8 * TRACE_COUNT_SLOTS as u64)?;
        let words: &[u32] = bytemuck::cast_slice(&words);
        stats.rays_traced = Some(words.iter().step_by(2).map(|&w| w as u64).sum());
        stats.triangle_tests = Some(words.iter().skip(1).step_by(2).map(|&w| w as u64).sum());
        // The surface points are where the pixels' rays meet their hits.
        // (The recording reads the distances back in their place: `encoding::frame`.)
        let wanted = settings.measure.positions;
        let mut frame = end.finish(gpu, targets, stats, start)?;
        if wanted {
            frame.positions = Some(ray_hit_points(p, frame.depth.as_ref().expect("read with the positions")));
            if !settings.measure.depth {
                frame.depth = None;
            }
        }
        Ok(frame)
    }
}

impl TraceMethod {
    /// The frame's targets and the ray tracer's outputs for the image size (rows padded to 256
    /// bytes, as buffer-to-texture copies need: the padded row's texels are returned) and its
    /// counters, made anew only when the size changed. Fails with one line where an output is
    /// more than the device binds.
    fn prepare_outputs(gpu: &Gpu, res: &mut FrameResources, p: &Projection) -> Result<u32> {
        let [width, height] = p.image_size();
        let row_texels = width.div_ceil(64) * 64;
        let bytes = 4 * row_texels as u64 * height as u64 * 2;
        if bytes > gpu.max_binding() {
            return Err(Error::setting(
                "view.projection.width/height",
                format!(
                    "{}x{} needs {} MiB per output of the ray tracer, more than this GPU binds ({} MiB): use a smaller image",
                    width,
                    height,
                    bytes >> 20,
                    gpu.max_binding() >> 20
                ),
            ));
        }
        res.targets(gpu, width, height, false, false, 1);
        if !res.trace_outputs.as_ref().is_some_and(|(r, h, _)| *r == row_texels && *h == height) {
            let make = |what: &str| gpu.storage_buffer(&format!("trace {what}"), bytes, wgpu::BufferUsages::empty());
            res.trace_outputs = Some((row_texels, height, ["colour", "error", "object", "distance"].map(make)));
        }
        let counts_bytes = 8 * TRACE_COUNT_SLOTS as u64;
        res.trace_counts
            .get_or_insert_with(|| gpu.storage_buffer("trace counts", counts_bytes, wgpu::BufferUsages::empty()));
        Ok(row_texels)
    }
}

/// Copies the ray tracer's outputs (colour, error, object, distance; both eyes, rows of
/// `row_texels`) into the frame's targets, whose read-back the other methods share.
fn copy_to_targets(
    enc: &mut wgpu::CommandEncoder,
    outputs: &[wgpu::Buffer; 4],
    targets: &Targets,
    row_texels: u32,
    p: &Projection,
) {
    for (buffer, texture) in outputs.iter().zip([&targets.color, &targets.error, &targets.object, &targets.distance]) {
        enc.copy_buffer_to_texture(
            wgpu::TexelCopyBufferInfo {
                buffer,
                layout: wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(4 * row_texels),
                    rows_per_image: Some(p.image_size()[1]),
                },
            },
            texture.as_image_copy(),
            wgpu::Extent3d { width: p.image_size()[0], height: p.image_size()[1], depth_or_array_layers: 2 },
        );
    }
}
