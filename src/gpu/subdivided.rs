//! The projection methods (`adaptive`, `fixed:N`, `vertex`): the `subdivide` stage's compute
//! passes, then the `raster` stage draws the subdivided triangles indirectly for both eyes (one
//! multiview draw, or a pass per eye). The schedule is a [`FramePlan`]: everything in one
//! submission, or, where a buffer overflowed, chunks of triangles and pieces drawn one after
//! another into the same targets.

use std::time::Instant;

use crate::core::frame::{Frame, FrameStats, Timing};
use crate::core::settings::RenderSettings;
use crate::encoding::params::raster_params;
use crate::encoding::subdivide::subdivide_params;
use crate::encoding::types::{SubdivideCounters, SubdivideParams};
use crate::error::{Error, Result};
use crate::gpu::device::Gpu;
use crate::gpu::draw::{DrawKey, DrawPipelines, DrawStage, Lit, Look};
use crate::gpu::frame::{FrameEnd, FrameResources, Method};
use crate::gpu::frame_plan::{on_overflow, Capacities, FramePlan, Overflow, SubdivisionBuffers};
use crate::gpu::scene::GpuScene;
use crate::gpu::subdivide::{SubdivideStage, COUNTERS_SIZE};
use crate::gpu::targets::{Layers, Targets};
use crate::gpu::timestamps as stamp;

/// GPU times (ms) of a one-submission frame, from its timestamps.
struct GpuTimes {
    subdivide: f64,
    /// The subdivision's passes: `plan` (with `active_cuts`), `plan_cuts`, `lattice`.
    passes: [f64; 3],
    raster: f64,
    frame: f64,
}

/// The projection methods' stages: the subdivision and the raster's drawing pipelines.
pub(crate) struct SubdividedMethod {
    pub subdivide: SubdivideStage,
    raster: DrawPipelines,
}

impl SubdividedMethod {
    /// The stages, with the cylinder's subdivision and the usual drawing pipeline built now (a
    /// GPU error building them shows when the renderer is made, not mid-frame).
    pub fn new(gpu: &Gpu) -> SubdividedMethod {
        let raster = DrawPipelines::new(gpu, DrawStage::Raster);
        let layers = Layers::passes(gpu.eyes_per_draw)[0];
        raster.keyed(gpu, DrawKey { look: Some((Look::Plain, Lit::default())), outputs: 1, layers, hdr: false });
        SubdividedMethod { subdivide: SubdivideStage::new(gpu), raster }
    }
}

impl Method for SubdividedMethod {
    /// The subdivided frame: follows the [`FramePlan`].
    fn draw(
        &self,
        gpu: &Gpu,
        end: &FrameEnd,
        res: &mut FrameResources,
        scene: &GpuScene,
        settings: &RenderSettings,
    ) -> Result<Frame> {
        let start = Instant::now();
        let mut stats = FrameStats { triangles_in: scene.triangle_count as u64, ..Default::default() };
        let p = settings.projection();
        res.targets(gpu, p.width, p.height, settings.measure.positions, settings.shading.hdr);
        let budget = Capacities::budget(settings.subdivision.memory_mb, gpu.max_binding());
        let n = scene.triangle_count;
        let mut plan = FramePlan::first(n, res.buffers.as_ref().map(|b| b.capacity), budget);
        if let FramePlan::OneSubmission(want) = plan {
            SubdivisionBuffers::ensure(&mut res.buffers, gpu, want, scene);
            let b = res.buffers.as_ref().expect("ensured");
            if b.cut_list_capacity < n {
                // More triangles than one binding lists for `plan_cuts`: chunks.
                plan = plan.after_overflow(budget);
            }
        }
        if let FramePlan::OneSubmission(_) = plan {
            let b = res.buffers.as_ref().expect("ensured");
            let targets = res.targets.as_ref().expect("made");
            let mut params = subdivide_params(settings, 0, n);
            let capacity = b.capacity.min(budget);
            params.piece_capacity = capacity.pieces;
            params.triangle_capacity = capacity.triangles;
            let t = Instant::now();
            if let Some((counters, times)) =
                self.render_one_submission(gpu, res, scene, settings, targets, b, params)?
            {
                stats.ms_frame = t.elapsed().as_secs_f64() * 1e3;
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
                stats.pieces = counters.pieces as u64;
                stats.triangles_out = counters.triangles as u64;
                stats.nodes_out = counters.nodes as u64;
                stats.chunks = 1;
                stats.max_sub_edge_px = f32::from_bits(counters.max_edge_bits);
                return end.finish(gpu, targets, settings, stats, start);
            }
            plan = plan.after_overflow(budget);
        }
        let FramePlan::Chunked { mut want, budget } = plan else { unreachable!("a one-submission frame returned") };
        self.render_chunked(gpu, res, scene, settings, &mut want, budget, &mut stats)?;
        stats.ms_frame = stats.ms_subdivide.unwrap_or(0.0) + stats.ms_raster.unwrap_or(0.0);
        stats.timing = Timing::WallPerPass;
        let targets = res.targets.as_ref().expect("made");
        end.finish(gpu, targets, settings, stats, start)
    }
}

impl SubdividedMethod {
    /// The usual frame, in one submission (see [`FramePlan::OneSubmission`]). Returns None if a
    /// buffer overflowed; else the counters and, with timestamp queries, the GPU times (ms) of
    /// the subdivision, the raster and the whole frame.
    #[allow(clippy::too_many_arguments)]
    fn render_one_submission(
        &self,
        gpu: &Gpu,
        res: &FrameResources,
        scene: &GpuScene,
        settings: &RenderSettings,
        targets: &Targets,
        b: &SubdivisionBuffers,
        params: SubdivideParams,
    ) -> Result<Option<(SubdivideCounters, Option<GpuTimes>)>> {
        let timestamps = res.timestamps.as_ref();
        let mut enc = gpu.device.create_command_encoder(&Default::default());
        let panorama = settings.projection().panorama;
        self.subdivide.encode(gpu, &mut enc, &res.subdivide_params, scene, b, &params, panorama, timestamps);
        self.encode_raster(
            gpu,
            &mut enc,
            res,
            scene,
            targets,
            b,
            settings,
            true,
            timestamps.map(|t| (&t.set, stamp::RASTER, stamp::RASTER + 1)),
        );
        enc.copy_buffer_to_buffer(&b.counters, 0, &res.staging, 0, COUNTERS_SIZE);
        if let Some(t) = timestamps {
            t.resolve(&mut enc, &res.staging, COUNTERS_SIZE, stamp::COUNT);
        }
        gpu.queue.submit([enc.finish()]);
        let bytes = gpu.read_buffer(&res.staging)?;
        let counters: SubdivideCounters = *bytemuck::from_bytes(&bytes[..COUNTERS_SIZE as usize]);
        if counters.pieces > params.piece_capacity || counters.output_units() > params.triangle_capacity {
            return Ok(None);
        }
        let times = timestamps.map(|t| {
            let ticks: &[u64] = bytemuck::cast_slice(&bytes[COUNTERS_SIZE as usize..]);
            let span = |first: u32| t.ms(ticks[first as usize], ticks[first as usize + 1]);
            GpuTimes {
                subdivide: t.ms(ticks[0], ticks[stamp::LATTICE as usize + 1]),
                passes: [span(stamp::PLAN), span(stamp::PLAN_CUTS), span(stamp::LATTICE)],
                raster: span(stamp::RASTER),
                frame: t.ms(ticks[0], ticks[stamp::RASTER as usize + 1]),
            }
        });
        Ok(Some((counters, times)))
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
        let uniform = &res.raster_params;
        gpu.queue.write_buffer(uniform, 0, bytemuck::cast_slice(&raster_params(settings)));
        let bind_group = self.raster.stage.bind_group(gpu, None, 0, &[uniform]);
        let passes = Layers::passes(gpu.eyes_per_draw);
        for (k, &layers) in passes.iter().enumerate() {
            let pipeline = self.raster.get(gpu, scene, settings, layers);
            let writes = timestamps.map(|(q, begin, end)| wgpu::RenderPassTimestampWrites {
                query_set: q,
                beginning_of_pass_write_index: (k == 0).then_some(begin),
                end_of_pass_write_index: (k + 1 == passes.len()).then_some(end),
            });
            let mut pass = targets.begin_pass(enc, layers, settings, clear, writes);
            pass.set_bind_group(0, &bind_group, &[]);
            pass.set_bind_group(1, &materials, &[]);
            if clear && scene.shows_environment(settings) {
                pass.set_pipeline(&self.raster.background(gpu, settings, layers));
                pass.draw(0..3, 0..1);
            }
            pass.set_pipeline(&pipeline);
            pass.set_vertex_buffer(0, buffers.nodes.slice(..));
            pass.set_index_buffer(buffers.indices.slice(..), wgpu::IndexFormat::Uint32);
            pass.draw_indexed_indirect(&buffers.draw_args, 0);
        }
    }

    /// The chunked schedule (see [`FramePlan::Chunked`]): wall times per pass.
    #[allow(clippy::too_many_arguments)]
    fn render_chunked(
        &self,
        gpu: &Gpu,
        res: &mut FrameResources,
        scene: &GpuScene,
        settings: &RenderSettings,
        want: &mut Capacities,
        budget: Capacities,
        stats: &mut FrameStats,
    ) -> Result<()> {
        let n = scene.triangle_count;
        let panorama = settings.projection().panorama;
        let mut clock = ChunkClock::default();
        let (mut first_tri, mut tri_chunk) = (0u32, n.max(1));
        let b = SubdivisionBuffers::ensure(&mut res.buffers, gpu, *want, scene);
        tri_chunk = tri_chunk.min(b.cut_list_capacity);
        let t = Instant::now();
        let cuts_params = subdivide_params(settings, 0, n);
        self.subdivide.run_active_cuts(gpu, &res.subdivide_params, scene, b, &cuts_params, panorama);
        clock.subdivide += t.elapsed().as_secs_f64() * 1e3;
        while first_tri < n || !clock.drawn {
            let tri_count = tri_chunk.min(n - first_tri);
            let b = SubdivisionBuffers::ensure(&mut res.buffers, gpu, *want, scene);
            let mut params = subdivide_params(settings, first_tri, tri_count);
            params.piece_capacity = b.capacity.pieces.min(budget.pieces);
            params.triangle_capacity = b.capacity.triangles;
            let t = Instant::now();
            let planned =
                self.subdivide.run(gpu, "plan", &res.subdivide_params, scene, b, &params, panorama, tri_count)?;
            clock.subdivide += t.elapsed().as_secs_f64() * 1e3;
            if planned.pieces > params.piece_capacity {
                match on_overflow(planned.pieces, budget.pieces, tri_count) {
                    Overflow::Grow(p) => want.pieces = p,
                    Overflow::Halve(c) => tri_chunk = c,
                    Overflow::TooBig => {
                        return Err(too_small(
                            settings,
                            format!(
                                "one triangle needs {} pieces; raise the edge length L or the memory budget",
                                planned.pieces
                            ),
                        ))
                    }
                }
                continue;
            }
            stats.pieces += planned.pieces as u64;
            let pieces = planned.pieces;
            self.draw_pieces(gpu, res, scene, settings, &mut params, pieces, (want, budget), stats, &mut clock)?;
            first_tri += tri_count;
        }
        stats.ms_subdivide = Some(clock.subdivide);
        stats.ms_raster = Some(clock.raster);
        Ok(())
    }

    /// The lattices of a chunk's `pieces` planned pieces, in ranges that fit the output buffer
    /// (grown within the budget, else halved), each range drawn into the targets at once.
    #[allow(clippy::too_many_arguments)]
    fn draw_pieces(
        &self,
        gpu: &Gpu,
        res: &mut FrameResources,
        scene: &GpuScene,
        settings: &RenderSettings,
        params: &mut SubdivideParams,
        pieces: u32,
        (want, budget): (&mut Capacities, Capacities),
        stats: &mut FrameStats,
        clock: &mut ChunkClock,
    ) -> Result<()> {
        let panorama = settings.projection().panorama;
        let (mut first_piece, mut piece_chunk) = (0u32, pieces.max(1));
        let mut piece_done = false;
        while first_piece < pieces || !piece_done {
            let piece_count = piece_chunk.min(pieces - first_piece);
            let b = SubdivisionBuffers::ensure(&mut res.buffers, gpu, *want, scene);
            params.first_piece = first_piece;
            params.piece_count = piece_count;
            params.triangle_capacity = b.capacity.triangles.min(budget.triangles);
            let t = Instant::now();
            let done =
                self.subdivide.run(gpu, "lattice", &res.subdivide_params, scene, b, params, panorama, piece_count)?;
            clock.subdivide += t.elapsed().as_secs_f64() * 1e3;
            if done.output_units() > params.triangle_capacity {
                match on_overflow(done.output_units(), budget.triangles, piece_count) {
                    Overflow::Grow(t) => want.triangles = t,
                    Overflow::Halve(c) => piece_chunk = c,
                    Overflow::TooBig => {
                        let why = format!(
                            "one piece makes {} triangles and nodes; lower the fixed N or raise the memory budget",
                            done.output_units()
                        );
                        return Err(too_small(settings, why));
                    }
                }
                continue;
            }
            let t = Instant::now();
            let targets = res.targets.as_ref().expect("made");
            let b = res.buffers.as_ref().expect("ensured");
            let mut enc = gpu.device.create_command_encoder(&Default::default());
            self.encode_raster(gpu, &mut enc, res, scene, targets, b, settings, !clock.drawn, None);
            gpu.queue.submit([enc.finish()]);
            gpu.wait();
            clock.raster += t.elapsed().as_secs_f64() * 1e3;
            clock.drawn = true;
            piece_done = true;
            stats.triangles_out += done.triangles as u64;
            stats.nodes_out += done.nodes as u64;
            stats.chunks += 1;
            stats.max_sub_edge_px = stats.max_sub_edge_px.max(f32::from_bits(done.max_edge_bits));
            first_piece += piece_count;
        }
        Ok(())
    }
}

/// A chunked frame's wall times (ms) of the subdivision and the raster, and whether a range has
/// been drawn (the first clears the targets).
#[derive(Default)]
struct ChunkClock {
    subdivide: f64,
    raster: f64,
    drawn: bool,
}

/// The memory budget cannot hold what one triangle or piece makes.
fn too_small(settings: &RenderSettings, why: String) -> Error {
    let memory_mb = settings.subdivision.memory_mb;
    Error::setting("subdivision.memory_mb", format!("{memory_mb} is too small: {why}"))
}
