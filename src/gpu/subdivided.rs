//! The projection methods (`adaptive`, `fixed:N`, `vertex`): the `subdivide` stage's compute
//! passes, then the `raster` stage draws the subdivided triangles indirectly for both eyes (one
//! multiview draw, or a pass per eye). The schedule is a `FramePlan`: everything in one
//! submission, or, where a buffer overflowed, chunks of triangles and pieces drawn one after
//! another into the same targets.

use std::time::Instant;

use crate::core::frame::{Frame, FrameStats, Timing};
use crate::core::panoramas::projection::PanoramaKind;
use crate::core::settings::RenderSettings;
use crate::encoding::frame::FrameStep;
use crate::encoding::params::raster_params;
use crate::encoding::recording::Recording;
use crate::encoding::schedule::{run_plan, Capacities, SubdivisionEngine};
use crate::encoding::subdivide::PassTiming;
use crate::encoding::types::{ProjectionUniform, RasterParams, SubdivideCounters, SubdivideParams};
use crate::error::Result;
use crate::gpu::device::Gpu;
use crate::gpu::draw::{DrawPipelines, DrawStage};
use crate::gpu::frame::{FrameEnd, FrameResources, Method};
use crate::gpu::frame_plan::SubdivisionBuffers;
use crate::gpu::scene::GpuScene;
use crate::gpu::subdivide::{FrameBuffers, SubdivideStage, COUNTERS_SIZE};
use crate::gpu::targets::{Layers, Samples, Targets};
use crate::gpu::timestamps as stamp;

/// GPU times (ms) of a one-submission frame, from its timestamps.
struct GpuTimes {
    subdivide: f64,
    /// Each of the subdivision's passes, in schedule order (`encoding::subdivide::timed_passes`).
    passes: Vec<(&'static str, f64)>,
    raster: f64,
    frame: f64,
}

/// The projection methods' stages: the subdivision and the raster's drawing pipelines.
pub(crate) struct SubdividedMethod {
    pub subdivide: SubdivideStage,
    raster: DrawPipelines,
}

impl SubdividedMethod {
    /// The stages; their pipelines are built when a frame first needs them.
    pub fn new(gpu: &Gpu) -> SubdividedMethod {
        SubdividedMethod { subdivide: SubdivideStage::new(gpu), raster: DrawPipelines::new(gpu, DrawStage::Raster) }
    }
}

impl Method for SubdividedMethod {
    /// The subdivided frame: its step's plan, followed by the one overflow policy
    /// ([`run_plan`]) with this frame's engine ([`FrameDraw`]).
    fn draw(
        &self,
        gpu: &Gpu,
        end: &FrameEnd,
        res: &mut FrameResources,
        scene: &GpuScene,
        settings: &RenderSettings,
        step: &FrameStep,
    ) -> Result<Frame> {
        let start = Instant::now();
        let FrameStep::Subdivided { plan, chunk } = *step else {
            return Err(crate::error::Error::Gpu(format!("the subdivided method was given the step {step:?}")));
        };
        let p = settings.projection();
        let [tile_w, tile_h] = p.image_size();
        res.targets(gpu, tile_w, tile_h, settings.measure.positions, settings.shading.hdr, settings.shading.samples);
        let n = scene.triangle_count;
        let panorama = p.panorama;
        let mut engine = FrameDraw { method: self, gpu, res, scene, settings, panorama, clock: FrameClock::default() };
        let totals = run_plan(&mut engine, settings, n, plan, chunk)?;
        let clock = engine.clock;
        let mut stats = FrameStats {
            triangles_in: n as u64,
            pieces: totals.pieces,
            triangles_out: totals.triangles,
            nodes_out: totals.nodes,
            chunks: totals.chunks,
            max_sub_edge_px: totals.max_edge_px,
            max_pieces_per_invocation: totals.max_pieces,
            max_output_per_invocation: totals.max_output,
            subdivide_invocations: totals.invocations,
            ..Default::default()
        };
        match clock.one_submission {
            // Drawn in one submission: its GPU times where timestamps were written.
            Some((ms, times)) if !clock.chunked => {
                stats.ms_frame = ms;
                match times {
                    Some(times) => {
                        stats.timing = Timing::GpuTimestamps;
                        stats.ms_subdivide = Some(times.subdivide);
                        stats.ms_subdivide_passes = Some(times.passes);
                        stats.ms_raster = Some(times.raster);
                        stats.ms_gpu = Some(times.frame);
                    }
                    None => stats.timing = Timing::WallOneSubmission,
                }
            }
            _ => {
                stats.ms_subdivide = Some(clock.subdivide);
                stats.ms_raster = Some(clock.raster);
                stats.ms_frame = clock.subdivide + clock.raster;
                stats.timing = Timing::WallPerPass;
            }
        }
        let targets = res.targets.as_ref().expect("made");
        end.finish(gpu, targets, stats, start)
    }
}

impl SubdividedMethod {
    /// The usual frame, in one submission (see `FramePlan::OneSubmission`): the subdivision,
    /// the raster (drawn before the counters are read: a frame whose buffers overflowed is drawn
    /// again by chunks), the counters and timestamps read back. The counters and, with timestamp
    /// queries, the GPU times (ms) of the subdivision, the raster and the whole frame.
    fn render_one_submission(
        &self,
        gpu: &Gpu,
        res: &FrameResources,
        scene: &GpuScene,
        settings: &RenderSettings,
        params: SubdivideParams,
    ) -> Result<(SubdivideCounters, Option<GpuTimes>)> {
        let timestamps = res.timestamps.as_ref();
        let targets = res.targets.as_ref().expect("made");
        let b = res.buffers.as_ref().expect("ensured");
        let mut enc = gpu.device.create_command_encoder(&Default::default());
        let panorama = settings.projection().panorama;
        let timing = PassTiming::of(timestamps.is_some(), settings.measure.pass_times);
        let timed = std::thread::scope(|scope| {
            // The raster's pipelines built beside the subdivision's (building them is most of a
            // fresh process's time on a CPU driver; a built one is only looked up).
            let raster = scope.spawn(|| self.raster_pipelines(gpu, scene, settings));
            let timed = self.subdivide.encode(
                gpu,
                &mut enc,
                &res.subdivide_params,
                scene,
                b,
                &params,
                panorama,
                timestamps,
                timing,
            );
            raster.join().expect("building the raster's pipelines panicked");
            timed
        });
        // The raster's pair of queries after the subdivision's timed passes.
        let raster_query = 2 * timed.len() as u32;
        self.encode_raster(
            gpu,
            &mut enc,
            res,
            scene,
            targets,
            b,
            settings,
            true,
            timestamps.map(|t| (&t.set, raster_query, raster_query + 1)),
        );
        enc.copy_buffer_to_buffer(&b.counters, 0, &res.staging, 0, COUNTERS_SIZE);
        if let Some(t) = timestamps {
            t.resolve(&mut enc, &res.staging, COUNTERS_SIZE, raster_query + 2);
        }
        gpu.queue.submit([enc.finish()]);
        let bytes = gpu.read_buffer(&res.staging)?;
        let counters: SubdivideCounters = *bytemuck::from_bytes(&bytes[..COUNTERS_SIZE as usize]);
        if counters.overflowed(params.piece_capacity, params.triangle_capacity) {
            return Ok((counters, None));
        }
        let times = timestamps.map(|t| {
            let ticks: &[u64] = bytemuck::cast_slice(&bytes[COUNTERS_SIZE as usize..]);
            let span = |first: u32| t.ms(ticks[first as usize], ticks[first as usize + 1]);
            // Each subdivision pass from the end of the one before (the first from its begin):
            // lavapipe writes a pass's begin late at times, after work that is the pass's own.
            let mut pass_from = ticks[0];
            let passes = timed
                .iter()
                .map(|&(label, first)| {
                    let end = ticks[first as usize + 1];
                    (label, t.ms(std::mem::replace(&mut pass_from, end), end))
                })
                .collect();
            GpuTimes {
                subdivide: t.ms(ticks[0], ticks[raster_query as usize - 1]),
                passes,
                raster: span(raster_query),
                frame: t.ms(ticks[0], ticks[raster_query as usize + 1]),
            }
        });
        Ok((counters, times))
    }

    /// The raster's passes of a frame: its samples (every output at the pixels' centres, then
    /// or only the multisampled colour) and the eyes each draws ([`Layers::passes`]).
    fn raster_passes(gpu: &Gpu, settings: &RenderSettings) -> Vec<(Samples, Layers)> {
        Samples::passes(settings)
            .into_iter()
            .flat_map(|samples| samples.layers(gpu.eyes_per_draw).iter().map(move |&layers| (samples, layers)))
            .collect()
    }

    /// Builds the pipelines a frame's raster uses, where not built yet.
    fn raster_pipelines(&self, gpu: &Gpu, scene: &GpuScene, settings: &RenderSettings) {
        for (samples, layers) in Self::raster_passes(gpu, settings) {
            self.raster.get(gpu, scene, settings, layers, samples);
            if scene.shows_environment(settings) {
                self.raster.background(gpu, settings, layers, samples);
            }
        }
    }

    /// Encodes the raster of both eyes (clearing the targets first if `clear`): one multiview
    /// pass, or a pass per eye ([`Layers::passes`]); with a query set, writes timestamps at the
    /// start of the first pass and the end of the last.
    #[allow(clippy::too_many_arguments)]
    fn encode_raster(
        &self,
        gpu: &Gpu,
        enc: &mut wgpu::CommandEncoder,
        res: &FrameResources,
        scene: &GpuScene,
        targets: &Targets,
        buffers: &SubdivisionBuffers,
        settings: &RenderSettings,
        clear: bool,
        timestamps: Option<(&wgpu::QuerySet, u32, u32)>,
    ) {
        let materials = self.raster.material_bind_group(gpu, scene);
        // One draw, or the cubemap's six: each face's parameters, and its square as the scissor.
        let draws = face_draws(gpu, &self.raster.stage, &res.raster_params, settings);
        let passes = Self::raster_passes(gpu, settings);
        for (k, &(samples, layers)) in passes.iter().enumerate() {
            let pipeline = self.raster.get(gpu, scene, settings, layers, samples);
            let writes = stamp::first_and_last(timestamps, k, passes.len());
            let mut pass = targets.begin_samples_pass(enc, samples, layers, settings, clear, writes);
            pass.set_bind_group(0, &draws[0].0, &[]);
            pass.set_bind_group(1, &materials, &[]);
            if clear && scene.shows_environment(settings) {
                pass.set_pipeline(&self.raster.background(gpu, settings, layers, samples));
                pass.draw(0..3, 0..1);
            }
            pass.set_pipeline(&pipeline);
            pass.set_vertex_buffer(0, buffers.nodes.slice(..));
            pass.set_index_buffer(buffers.indices.slice(..), wgpu::IndexFormat::Uint32);
            for (bind_group, scissor) in &draws {
                pass.set_bind_group(0, bind_group, &[]);
                if let Some([x, y, w, h]) = *scissor {
                    pass.set_scissor_rect(x, y, w, h);
                }
                pass.draw_indexed_indirect(&buffers.draw_args, 0);
            }
        }
        targets.copy_resolved(enc);
    }
}

/// The raster stage's draws of a frame: its parameters' bind group, and for the cubemap one draw
/// per face this draw's image holds, each projecting into its face (`face` in the projection
/// uniform) and kept to the face's square by the scissor (`core::panoramas::cubemap`: w = D·n clips what
/// lies behind the face).
fn face_draws(
    gpu: &Gpu,
    stage: &crate::gpu::stages::GpuStage,
    uniform: &wgpu::Buffer,
    settings: &RenderSettings,
) -> Vec<(wgpu::BindGroup, Option<[u32; 4]>)> {
    let params = raster_params(settings);
    let size = std::mem::size_of_val(&params) as u64;
    let stride = crate::gpu::frame::raster_params_stride(gpu);
    let projection = settings.projection();
    // (face, scissor): the faces a tile holds, each with its square; or the one draw.
    let faces: Vec<(u32, Option<[u32; 4]>)> =
        if projection.model().image_map() == crate::core::panoramas::panorama::ImageMap::Cubemap {
            (0..crate::core::panoramas::cubemap::CUBE_FACES.len())
                .filter_map(|f| projection.cube_face_scissor(f).map(|rect| (f as u32, Some(rect))))
                .collect()
        } else {
            vec![(0, None)]
        };
    faces
        .into_iter()
        .enumerate()
        .map(|(k, (face, scissor))| {
            let offset = k as u64 * stride;
            let face_params =
                params.map(|p| RasterParams { projection: ProjectionUniform { face, ..p.projection }, ..p });
            gpu.queue.write_buffer(uniform, offset, bytemuck::cast_slice(&face_params));
            let binding = wgpu::BufferBinding { buffer: uniform, offset, size: wgpu::BufferSize::new(size) };
            (stage.bind_group_ranges(gpu, None, 0, &[binding]), scissor)
        })
        .collect()
}

/// A subdivided frame's engine: the one-submission frame drawn as it is submitted; a chunked
/// frame's recordings submitted one by one, each range's output drawn into the targets (the
/// first range clears them).
struct FrameDraw<'a> {
    method: &'a SubdividedMethod,
    gpu: &'a Gpu,
    res: &'a mut FrameResources,
    scene: &'a GpuScene,
    settings: &'a RenderSettings,
    panorama: PanoramaKind,
    clock: FrameClock,
}

impl SubdivisionEngine for FrameDraw<'_> {
    fn ensure(&mut self, want: Capacities) -> Capacities {
        SubdivisionBuffers::ensure(&mut self.res.buffers, self.gpu, want, self.scene).capacity
    }

    fn replay(&mut self, recording: &Recording, params: &SubdivideParams) -> Result<SubdivideCounters> {
        let t = Instant::now();
        let b = self.res.buffers.as_ref().expect("ensured before a replay");
        let frame = FrameBuffers { params: &self.res.subdivide_params, scene: self.scene, b };
        let counters = self.method.subdivide.submit(self.gpu, recording, &frame, params, self.panorama)?;
        self.clock.subdivide += t.elapsed().as_secs_f64() * 1e3;
        Ok(counters)
    }

    fn take(&mut self, _: &SubdivideCounters) -> Result<()> {
        let t = Instant::now();
        if !self.clock.chunked {
            // Each chunk's pass loads what the eye's earlier chunks drew: no samples shared by
            // the eyes.
            self.res.targets.as_mut().expect("made").give_each_eye_its_samples(self.gpu);
            self.clock.chunked = true;
        }
        let (gpu, res) = (self.gpu, &*self.res);
        let targets = res.targets.as_ref().expect("made");
        let b = res.buffers.as_ref().expect("ensured");
        let mut enc = gpu.device.create_command_encoder(&Default::default());
        self.method.encode_raster(gpu, &mut enc, res, self.scene, targets, b, self.settings, !self.clock.drawn, None);
        gpu.queue.submit([enc.finish()]);
        gpu.wait();
        self.clock.raster += t.elapsed().as_secs_f64() * 1e3;
        self.clock.drawn = true;
        Ok(())
    }

    /// The one-submission frame ([`SubdividedMethod::render_one_submission`]), again where it
    /// needed the cut passes before they were built.
    fn replay_and_take(&mut self, _: &Recording, params: &SubdivideParams) -> Result<SubdivideCounters> {
        let t = Instant::now();
        let (method, gpu, scene, settings) = (self.method, self.gpu, self.scene, self.settings);
        let mut done = method.render_one_submission(gpu, self.res, scene, settings, *params)?;
        if method.subdivide.missed_cuts(gpu, self.panorama, params, &done.0) {
            done = method.render_one_submission(gpu, self.res, scene, settings, *params)?;
        }
        self.clock.one_submission = Some((t.elapsed().as_secs_f64() * 1e3, done.1));
        Ok(done.0)
    }
}

/// A subdivided frame's times (ms): the one submission's (wall, and the GPU's where timed), or a
/// chunked frame's wall times of the subdivision and the raster; whether a range has been drawn
/// by chunks (the first clears the targets) and whether the frame went by chunks.
#[derive(Default)]
struct FrameClock {
    one_submission: Option<(f64, Option<GpuTimes>)>,
    subdivide: f64,
    raster: f64,
    drawn: bool,
    chunked: bool,
}
