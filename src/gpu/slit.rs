//! The slit-mosaic reference renderer on the GPU (`slit` stage, twin `cpu::slit`): one draw per
//! slit and visible object, per eye, with all slit cameras in one buffer.

use crate::encoding::frame::FrameStep;
use std::time::Instant;

use crate::core::frame::{Frame, FrameStats};
use crate::core::panoramas::projection::Eye;
use crate::core::settings::RenderSettings;
use crate::encoding::slits::{slit_params, slits, sphere_in_slit};
use crate::encoding::types::SlitCamera;
use crate::error::Result;
use crate::gpu::device::Gpu;
use crate::gpu::draw::{DrawPipelines, DrawStage};
use crate::gpu::frame::{FrameEnd, FrameResources, Method};
use crate::gpu::scene::GpuScene;
use crate::gpu::targets::{Layers, Samples};
use crate::gpu::timestamps::{self as stamp, submit_timed_pass};

/// The slit renderer: its drawing pipelines.
pub(crate) struct SlitMethod {
    pipelines: DrawPipelines,
}

impl SlitMethod {
    pub fn new(gpu: &Gpu) -> SlitMethod {
        SlitMethod { pipelines: DrawPipelines::new(gpu, DrawStage::Slit) }
    }
}

impl Method for SlitMethod {
    fn draw(
        &self,
        gpu: &Gpu,
        end: &FrameEnd,
        res: &mut FrameResources,
        scene: &GpuScene,
        settings: &RenderSettings,
        step: &FrameStep,
    ) -> Result<Frame> {
        // slit:W, or a CAVE wall's one camera per eye (every projection method: a perspective).
        let FrameStep::Slit { width } = *step else {
            return Err(crate::error::Error::Gpu(format!("the slit method was given the step {step:?}")));
        };
        let start = Instant::now();
        let projection = settings.projection();
        let (positions, samples) = (settings.measure.positions, settings.shading.samples);
        let [tile_w, tile_h] = projection.image_size();
        res.targets(gpu, tile_w, tile_h, positions, false, samples);
        let res = &*res;
        let targets = res.targets.as_ref().expect("made");
        let view = settings.view();
        let eye_slits = Eye::BOTH.map(|eye| slits(projection, eye, width));
        // Object centres in the viewer frame, once (the culling below runs per slit and object).
        let centers: Vec<_> = scene.objects.iter().map(|o| view.transform_point3(o.center)).collect();
        let cameras: Vec<SlitCamera> = eye_slits.iter().flatten().map(|s| s.camera).collect();
        let camera_buffer =
            gpu.init_buffer("slit cameras", bytemuck::cast_slice(&cameras), wgpu::BufferUsages::STORAGE);
        let mut stats = FrameStats { triangles_in: scene.triangle_count as u64, chunks: 1, ..Default::default() };
        let materials = self.pipelines.material_bind_group(gpu, scene);
        let timestamps = res.timestamps.as_ref();
        let t = Instant::now();
        let mut enc = gpu.device.create_command_encoder(&Default::default());
        // Every output at the pixels' centres, then (or only) the multisampled colour.
        let passes: Vec<(Samples, usize)> =
            Samples::passes(settings).into_iter().flat_map(|samples| [(samples, 0), (samples, 1)]).collect();
        for (p, &(samples, k)) in passes.iter().enumerate() {
            let eye = Eye::BOTH[k];
            let pipeline = self.pipelines.get(gpu, scene, settings, Layers::Eye(0), samples);
            let params = slit_params(projection, view, eye, settings.shading.ambient, settings.measure.error_angle);
            gpu.queue.write_buffer(&res.slit_params[k], 0, bytemuck::bytes_of(&params));
            let bind_group = self.pipelines.stage.bind_group(gpu, None, 0, &[&res.slit_params[k], &camera_buffer]);
            let writes = stamp::first_and_last(timestamps.map(|t| (&t.set, 0, 1)), p, passes.len());
            let mut pass = targets.begin_samples_pass(&mut enc, samples, Layers::Eye(k), settings, true, writes);
            pass.set_bind_group(0, &bind_group, &[]);
            pass.set_bind_group(1, &materials, &[]);
            if scene.shows_environment(settings) {
                pass.set_pipeline(&self.pipelines.background(gpu, settings, Layers::Eye(k), samples));
                pass.draw(0..3, 0..1);
            }
            pass.set_pipeline(&pipeline);
            pass.set_vertex_buffer(0, scene.vertices.slice(..));
            pass.set_index_buffer(scene.indices.slice(..), wgpu::IndexFormat::Uint32);
            let first_instance = (k * eye_slits[0].len()) as u32;
            for (i, slit) in eye_slits[k].iter().enumerate() {
                let Some([x, y, w, h]) = slit.scissor(projection) else { continue }; // outside this tile
                pass.set_scissor_rect(x, y, w, h);
                let instance = first_instance + i as u32;
                for (o, &center) in scene.objects.iter().zip(&centers) {
                    if sphere_in_slit(&params, slit, center, o.radius) {
                        let first = o.first_triangle;
                        pass.draw_indexed(3 * first..3 * (first + o.triangle_count), 0, instance..instance + 1);
                        if p < 2 {
                            // Counted in the first kind of pass only.
                            stats.triangles_out += o.triangle_count as u64;
                        }
                    }
                }
            }
        }
        targets.copy_resolved(&mut enc);
        submit_timed_pass(gpu, enc, timestamps, &res.staging, t, &mut stats)?;
        end.finish(gpu, targets, stats, start)
    }
}
