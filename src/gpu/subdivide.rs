//! The `subdivide` stage on the GPU (shaders/subdivide.wgsl; CPU twin `cpu::subdivide`): its
//! pipelines per panorama, its bind groups, and its two schedules.
//!
//! - **One submission** (the usual frame, [`SubdivideStage::encode`]): the counters and the
//!   edge marks cleared; `active_cuts`, `ring_cuts` and `plan` over every triangle;
//!   `plan_cuts_args` and `plan_cuts` (indirect, over the triangles `plan` listed);
//!   `lattice_args`, `lattice` (indirect, one invocation per piece), `finalize` (the draw's
//!   arguments). The raster follows in the same submission.
//! - **Chunked** ([`SubdivideStage::run_active_cuts`], then [`SubdivideStage::run`] with `plan`
//!   over a range of triangles and `lattice` over a range of pieces, the counters read between):
//!   where a buffer overflowed, or for the read-back over ranges.
//!
//! [`SubdivideStage::readback`] runs either schedule and reads the output back: what the twin
//! test compares with `cpu::subdivide`.

use std::sync::OnceLock;

use crate::core::projection::PanoramaKind;
use crate::core::settings::RenderSettings;
use crate::encoding::constants::PIECES_FROM_COUNTER;
use crate::encoding::subdivide::{subdivide_params, SubdivideOutput};
use crate::encoding::types::{DrawVertex, SubdivideCounters, SubdivideParams};
use crate::error::Result;
use crate::gpu::device::Gpu;
use crate::gpu::frame_plan::{Capacities, SubdivisionBuffers, INDICES_SIZE, NODE_SIZE};
use crate::gpu::scene::GpuScene;
use crate::gpu::stages::GpuStage;
use crate::gpu::timestamps::{self as stamp, Timestamps};
use crate::shader::SUBDIVIDE;

pub(crate) const COUNTERS_SIZE: u64 = std::mem::size_of::<SubdivideCounters>() as u64;

/// Which schedule a read-back runs (see the module doc).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Schedule {
    /// The usual frame's: everything in one submission, indirect dispatches sized on the GPU.
    OneSubmission,
    /// The chunked frame's: `plan` over ranges of this many triangles, `lattice` over all the
    /// pieces of a range, the counters read between.
    Chunked { triangles_per_chunk: u32 },
}

/// The stage's pipelines for one panorama, one per entry point.
struct Variant {
    active_cuts: wgpu::ComputePipeline,
    ring_cuts: wgpu::ComputePipeline,
    plan: wgpu::ComputePipeline,
    plan_cuts_args: wgpu::ComputePipeline,
    plan_cuts: wgpu::ComputePipeline,
    lattice_args: wgpu::ComputePipeline,
    lattice: wgpu::ComputePipeline,
    finalize: wgpu::ComputePipeline,
}

/// The `subdivide` stage: its layouts, and its pipelines built for each panorama when first
/// needed (the WGSL `override PANORAMAS` compiles the other panorama's projection out).
pub(crate) struct SubdivideStage {
    stage: GpuStage,
    variants: [OnceLock<Variant>; 2],
}

impl SubdivideStage {
    /// The stage, with the cylinder's pipelines built now (a GPU error building them shows
    /// when the renderer is made, not mid-frame).
    pub fn new(gpu: &Gpu) -> SubdivideStage {
        let stage =
            SubdivideStage { stage: GpuStage::new(gpu, &SUBDIVIDE), variants: [OnceLock::new(), OnceLock::new()] };
        stage.variant(gpu, PanoramaKind::Cylinder);
        stage
    }

    fn variant(&self, gpu: &Gpu, panorama: PanoramaKind) -> &Variant {
        let (k, bits) = match panorama {
            PanoramaKind::Cylinder => (0, 1.0),
            PanoramaKind::Equirect => (1, 2.0),
        };
        self.variants[k].get_or_init(|| {
            let constants = [("PANORAMAS", bits)];
            let make = |entry| self.stage.compute_with(gpu, entry, &constants);
            Variant {
                active_cuts: make("active_cuts"),
                ring_cuts: make("ring_cuts"),
                plan: make("plan"),
                plan_cuts_args: make("plan_cuts_args"),
                plan_cuts: make("plan_cuts"),
                lattice_args: make("lattice_args"),
                lattice: make("lattice"),
                finalize: make("finalize"),
            }
        })
    }

    /// The bind group of `entry`: params, vertices, indices, pieces, output nodes, counters,
    /// draw args, lattice dispatch, per-object edge scale, cut list, output indices, triangle
    /// edges, cut edges (twice: read-write and read-only) (the order of `SUBDIVIDE.bindings`).
    fn bind_group(
        &self,
        gpu: &Gpu,
        entry: &str,
        uniform: &wgpu::Buffer,
        scene: &GpuScene,
        b: &SubdivisionBuffers,
    ) -> wgpu::BindGroup {
        let buffers = [
            uniform,
            &scene.vertices,
            &scene.indices,
            &b.pieces,
            &b.nodes,
            &b.counters,
            &b.draw_args,
            &b.lattice_dispatch,
            &scene.object_edge_scale,
            &b.cut_list,
            &b.indices,
            &scene.triangle_edges,
            &b.cut_edges,
            &b.cut_edges,
        ];
        self.stage.bind_group(gpu, Some(entry), 0, &buffers)
    }

    /// Encodes the one-submission schedule's three compute passes (timed apart where the
    /// adapter has timestamps): the cuts (both rings) and `plan`; `plan_cuts`; the lattice and
    /// `finalize`. `params` covers every triangle, its pieces counted on the GPU.
    #[allow(clippy::too_many_arguments)]
    pub fn encode(
        &self,
        gpu: &Gpu,
        enc: &mut wgpu::CommandEncoder,
        uniform: &wgpu::Buffer,
        scene: &GpuScene,
        b: &SubdivisionBuffers,
        params: &SubdivideParams,
        panorama: PanoramaKind,
        timestamps: Option<&Timestamps>,
    ) {
        let params = SubdivideParams { first_piece: 0, piece_count: PIECES_FROM_COUNTER, ..*params };
        gpu.queue.write_buffer(uniform, 0, bytemuck::bytes_of(&params));
        let group = |entry| self.bind_group(gpu, entry, uniform, scene, b);
        let [active_cuts, ring_cuts, plan, lattice_args, lattice, finalize] =
            ["active_cuts", "ring_cuts", "plan", "lattice_args", "lattice", "finalize"].map(group);
        let cut_groups = ["plan_cuts_args", "plan_cuts"].map(group);
        let variant = self.variant(gpu, panorama);
        enc.clear_buffer(&b.counters, 0, None);
        enc.clear_buffer(&b.cut_edges, 0, None);
        {
            let mut pass = stamp::compute_pass(enc, "plan", timestamps, stamp::PLAN);
            let (x, y) = gpu.workgroups(params.triangle_count, 64);
            for (pipeline, group) in
                [(&variant.active_cuts, &active_cuts), (&variant.ring_cuts, &ring_cuts), (&variant.plan, &plan)]
            {
                pass.set_pipeline(pipeline);
                pass.set_bind_group(0, group, &[]);
                pass.dispatch_workgroups(x, y, 1);
            }
        }
        {
            let mut pass = stamp::compute_pass(enc, "plan_cuts", timestamps, stamp::PLAN_CUTS);
            Self::encode_plan_cuts(variant, &mut pass, b, &cut_groups);
        }
        let mut pass = stamp::compute_pass(enc, "lattice", timestamps, stamp::LATTICE);
        pass.set_pipeline(&variant.lattice_args);
        pass.set_bind_group(0, &lattice_args, &[]);
        pass.dispatch_workgroups(1, 1, 1);
        pass.set_pipeline(&variant.lattice);
        pass.set_bind_group(0, &lattice, &[]);
        pass.dispatch_workgroups_indirect(&b.lattice_dispatch, 0);
        pass.set_pipeline(&variant.finalize);
        pass.set_bind_group(0, &finalize, &[]);
        pass.dispatch_workgroups(1, 1, 1);
    }

    /// Clears the counters and the edge marks and runs `active_cuts` and `ring_cuts` over every
    /// triangle of the scene: the start of a chunked schedule.
    pub fn run_active_cuts(
        &self,
        gpu: &Gpu,
        uniform: &wgpu::Buffer,
        scene: &GpuScene,
        buffers: &SubdivisionBuffers,
        params: &SubdivideParams,
        panorama: PanoramaKind,
    ) {
        let params = SubdivideParams { first_triangle: 0, triangle_count: scene.triangle_count, ..*params };
        gpu.queue.write_buffer(uniform, 0, bytemuck::bytes_of(&params));
        let groups = ["active_cuts", "ring_cuts"].map(|e| self.bind_group(gpu, e, uniform, scene, buffers));
        let variant = self.variant(gpu, panorama);
        let mut enc = gpu.device.create_command_encoder(&Default::default());
        enc.clear_buffer(&buffers.counters, 0, None);
        enc.clear_buffer(&buffers.cut_edges, 0, None);
        {
            let mut pass = enc.begin_compute_pass(&Default::default());
            let (x, y) = gpu.workgroups(scene.triangle_count, 64);
            for (pipeline, group) in [&variant.active_cuts, &variant.ring_cuts].into_iter().zip(&groups) {
                pass.set_pipeline(pipeline);
                pass.set_bind_group(0, group, &[]);
                pass.dispatch_workgroups(x, y, 1);
            }
        }
        gpu.queue.submit([enc.finish()]);
    }

    /// Runs one compute entry point (`plan` with `plan_cuts` after it, or `lattice`) over
    /// `count` invocations, then `finalize`, and returns the counters afterwards (the frame's
    /// cuts, from [`Self::run_active_cuts`], are kept).
    #[allow(clippy::too_many_arguments)]
    pub fn run(
        &self,
        gpu: &Gpu,
        entry: &str,
        uniform: &wgpu::Buffer,
        scene: &GpuScene,
        buffers: &SubdivisionBuffers,
        params: &SubdivideParams,
        panorama: PanoramaKind,
        count: u32,
    ) -> Result<SubdivideCounters> {
        gpu.queue.write_buffer(uniform, 0, bytemuck::bytes_of(params));
        let variant = self.variant(gpu, panorama);
        let pipeline = if entry == "plan" { &variant.plan } else { &variant.lattice };
        let bind_group = self.bind_group(gpu, entry, uniform, scene, buffers);
        let cut_groups = ["plan_cuts_args", "plan_cuts"].map(|e| self.bind_group(gpu, e, uniform, scene, buffers));
        let finalize = self.bind_group(gpu, "finalize", uniform, scene, buffers);
        let mut enc = gpu.device.create_command_encoder(&Default::default());
        enc.clear_buffer(&buffers.counters, 0, Some(SubdivideCounters::RUN_BYTES));
        {
            let mut pass = enc.begin_compute_pass(&Default::default());
            pass.set_pipeline(pipeline);
            pass.set_bind_group(0, &bind_group, &[]);
            let (x, y) = gpu.workgroups(count, 64);
            pass.dispatch_workgroups(x, y, 1);
            if entry == "plan" {
                Self::encode_plan_cuts(variant, &mut pass, buffers, &cut_groups);
            }
            pass.set_pipeline(&variant.finalize);
            pass.set_bind_group(0, &finalize, &[]);
            pass.dispatch_workgroups(1, 1, 1);
        }
        gpu.queue.submit([enc.finish()]);
        let bytes = gpu.download(&buffers.counters, COUNTERS_SIZE)?;
        Ok(*bytemuck::from_bytes(&bytes))
    }

    /// `plan_cuts_args` and `plan_cuts` (the triangles `plan` listed), after `plan`.
    fn encode_plan_cuts(
        variant: &Variant,
        pass: &mut wgpu::ComputePass,
        b: &SubdivisionBuffers,
        groups: &[wgpu::BindGroup; 2],
    ) {
        pass.set_pipeline(&variant.plan_cuts_args);
        pass.set_bind_group(0, &groups[0], &[]);
        pass.dispatch_workgroups(1, 1, 1);
        pass.set_pipeline(&variant.plan_cuts);
        pass.set_bind_group(0, &groups[1], &[]);
        pass.dispatch_workgroups_indirect(&b.lattice_dispatch, 12);
    }

    /// Runs the whole stage on a scene with `schedule` and reads its output back (the GPU side
    /// of the twin test). Buffers grow until the output fits; a chunked schedule's ranges are
    /// concatenated (indices moved by the nodes before them).
    pub fn readback(
        &self,
        gpu: &Gpu,
        scene: &GpuScene,
        settings: &RenderSettings,
        schedule: Schedule,
    ) -> Result<SubdivideOutput> {
        gpu.scoped("subdividing", || {
            let panorama = settings.projection().panorama;
            let n = scene.triangle_count;
            let mut cache = None;
            let uniform = gpu.uniform_buffer::<SubdivideParams>("subdivide params");
            let mut want = Capacities { pieces: n.max(64), triangles: n.saturating_mul(4).max(1024) };
            let read = |b: &SubdivisionBuffers, counters: &SubdivideCounters| -> Result<(Vec<DrawVertex>, Vec<u32>)> {
                let nodes = gpu.download(&b.nodes, counters.nodes as u64 * NODE_SIZE)?;
                let indices = gpu.download(&b.indices, counters.triangles as u64 * INDICES_SIZE)?;
                Ok((bytemuck::cast_slice(&nodes).to_vec(), bytemuck::cast_slice(&indices).to_vec()))
            };
            let chunk = match schedule {
                Schedule::OneSubmission => loop {
                    let b = SubdivisionBuffers::ensure(&mut cache, gpu, want, scene);
                    let mut params = subdivide_params(settings, 0, n);
                    (params.piece_capacity, params.triangle_capacity) = (b.capacity.pieces, b.capacity.triangles);
                    let mut enc = gpu.device.create_command_encoder(&Default::default());
                    self.encode(gpu, &mut enc, &uniform, scene, b, &params, panorama, None);
                    gpu.queue.submit([enc.finish()]);
                    let counters: SubdivideCounters = *bytemuck::from_bytes(&gpu.download(&b.counters, COUNTERS_SIZE)?);
                    if counters.pieces > b.capacity.pieces || counters.output_units() > b.capacity.triangles {
                        want = Capacities {
                            pieces: want.pieces.max(counters.pieces),
                            triangles: want.triangles.max(counters.output_units()),
                        };
                        continue;
                    }
                    let (nodes, indices) = read(b, &counters)?;
                    return Ok(SubdivideOutput::indexed(
                        nodes,
                        indices,
                        counters.pieces,
                        f32::from_bits(counters.max_edge_bits),
                        counters.cuts(),
                    ));
                },
                Schedule::Chunked { triangles_per_chunk } => triangles_per_chunk.max(1),
            };
            let (mut nodes, mut indices, mut pieces, mut max_edge, mut cuts) = (Vec::new(), Vec::new(), 0, 0.0f32, 0);
            let mut first = 0;
            let b = SubdivisionBuffers::ensure(&mut cache, gpu, want, scene);
            self.run_active_cuts(gpu, &uniform, scene, b, &subdivide_params(settings, 0, n), panorama);
            while first < n {
                let count = chunk.min(n - first);
                let b = SubdivisionBuffers::ensure(&mut cache, gpu, want, scene);
                let mut params = subdivide_params(settings, first, count);
                (params.piece_capacity, params.triangle_capacity) = (b.capacity.pieces, b.capacity.triangles);
                let planned = self.run(gpu, "plan", &uniform, scene, b, &params, panorama, count)?;
                if planned.pieces > b.capacity.pieces {
                    want.pieces = planned.pieces;
                    continue;
                }
                (params.first_piece, params.piece_count) = (0, planned.pieces);
                let done = self.run(gpu, "lattice", &uniform, scene, b, &params, panorama, planned.pieces)?;
                if done.output_units() > b.capacity.triangles {
                    want.triangles = done.output_units();
                    continue;
                }
                let (chunk_nodes, chunk_indices) = read(b, &done)?;
                indices.extend(chunk_indices.iter().map(|i| i + nodes.len() as u32));
                nodes.extend(chunk_nodes);
                pieces += planned.pieces;
                max_edge = max_edge.max(f32::from_bits(done.max_edge_bits));
                cuts = done.cuts();
                first += count;
            }
            Ok(SubdivideOutput::indexed(nodes, indices, pieces, max_edge, cuts))
        })
    }
}
