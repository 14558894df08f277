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
use crate::encoding::recording::{Command, Recording};
use crate::encoding::subdivide::{active_cuts, one_submission, pass_run, subdivide_params, SubdivideOutput};
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

impl Variant {
    /// The pipeline of an entry point a recording names.
    fn pipeline(&self, entry: &str) -> &wgpu::ComputePipeline {
        match entry {
            "active_cuts" => &self.active_cuts,
            "ring_cuts" => &self.ring_cuts,
            "plan" => &self.plan,
            "plan_cuts_args" => &self.plan_cuts_args,
            "plan_cuts" => &self.plan_cuts,
            "lattice_args" => &self.lattice_args,
            "lattice" => &self.lattice,
            "finalize" => &self.finalize,
            other => panic!("the subdivide stage has no entry point {other}"),
        }
    }
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

    /// The bind group of `entry` (the bindings of `SUBDIVIDE` it uses, by name).
    fn bind_group(&self, gpu: &Gpu, entry: &str, frame: &FrameBuffers) -> wgpu::BindGroup {
        let buffers: Vec<&wgpu::Buffer> = SUBDIVIDE.bindings.iter().map(|b| frame.named(b.name)).collect();
        self.stage.bind_group(gpu, Some(entry), 0, &buffers)
    }

    /// Replays `recording` into `enc` for a frame's buffers (each named as it is bound).
    fn replay(
        &self,
        gpu: &Gpu,
        enc: &mut wgpu::CommandEncoder,
        recording: &Recording,
        frame: &FrameBuffers,
        panorama: PanoramaKind,
        timestamps: Option<&Timestamps>,
    ) {
        let variant = self.variant(gpu, panorama);
        let mut pass: Option<wgpu::ComputePass<'static>> = None;
        for command in &recording.commands {
            match *command {
                Command::Clear { buffer, bytes } => {
                    drop(pass.take());
                    enc.clear_buffer(frame.named(buffer), 0, bytes);
                }
                Command::Pass { label, timestamp } => {
                    drop(pass.take());
                    let timed = timestamps.filter(|_| timestamp.is_some());
                    pass = Some(stamp::compute_pass(enc, label, timed, timestamp.unwrap_or(0)).forget_lifetime());
                }
                Command::Dispatch { entry, invocations } => {
                    let pass = pass.as_mut().expect("a recording dispatches inside a pass");
                    pass.set_pipeline(variant.pipeline(entry));
                    pass.set_bind_group(0, &self.bind_group(gpu, entry, frame), &[]);
                    let (x, y) = gpu.workgroups(invocations, 64);
                    pass.dispatch_workgroups(x, y, 1);
                }
                Command::DispatchIndirect { entry, args, offset } => {
                    let pass = pass.as_mut().expect("a recording dispatches inside a pass");
                    pass.set_pipeline(variant.pipeline(entry));
                    pass.set_bind_group(0, &self.bind_group(gpu, entry, frame), &[]);
                    pass.dispatch_workgroups_indirect(frame.named(args), offset);
                }
            }
        }
    }

    /// Encodes the one-submission schedule ([`one_submission`]; each pass timed where the
    /// adapter has timestamps). `params` covers every triangle, its pieces counted on the GPU.
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
        let recording = one_submission(params.triangle_count, timestamps.is_some());
        self.replay(gpu, enc, &recording, &FrameBuffers { uniform, scene, b }, panorama, timestamps);
    }

    /// The start of a chunked schedule ([`active_cuts`]), submitted.
    pub fn run_active_cuts(
        &self,
        gpu: &Gpu,
        uniform: &wgpu::Buffer,
        scene: &GpuScene,
        b: &SubdivisionBuffers,
        params: &SubdivideParams,
        panorama: PanoramaKind,
    ) {
        let params = SubdivideParams { first_triangle: 0, triangle_count: scene.triangle_count, ..*params };
        gpu.queue.write_buffer(uniform, 0, bytemuck::bytes_of(&params));
        let mut enc = gpu.device.create_command_encoder(&Default::default());
        let frame = FrameBuffers { uniform, scene, b };
        self.replay(gpu, &mut enc, &active_cuts(scene.triangle_count), &frame, panorama, None);
        gpu.queue.submit([enc.finish()]);
    }

    /// One step of a chunked schedule ([`pass_run`]: `plan` with `plan_cuts` after it, or
    /// `lattice`, over `count` invocations, then `finalize`), submitted; the counters afterwards
    /// (the frame's cuts, from [`Self::run_active_cuts`], are kept).
    #[allow(clippy::too_many_arguments)]
    pub fn run(
        &self,
        gpu: &Gpu,
        entry: &'static str,
        uniform: &wgpu::Buffer,
        scene: &GpuScene,
        b: &SubdivisionBuffers,
        params: &SubdivideParams,
        panorama: PanoramaKind,
        count: u32,
    ) -> Result<SubdivideCounters> {
        gpu.queue.write_buffer(uniform, 0, bytemuck::bytes_of(params));
        let mut enc = gpu.device.create_command_encoder(&Default::default());
        let frame = FrameBuffers { uniform, scene, b };
        self.replay(gpu, &mut enc, &pass_run(entry, count), &frame, panorama, None);
        gpu.queue.submit([enc.finish()]);
        let bytes = gpu.download(&b.counters, COUNTERS_SIZE)?;
        Ok(*bytemuck::from_bytes(&bytes))
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

/// The buffers a subdivision's recording names: the uniform, the scene's, the frame's.
struct FrameBuffers<'f> {
    uniform: &'f wgpu::Buffer,
    scene: &'f GpuScene,
    b: &'f SubdivisionBuffers,
}

impl FrameBuffers<'_> {
    /// The buffer bound as `name` (`SUBDIVIDE.bindings`).
    fn named(&self, name: &str) -> &wgpu::Buffer {
        let (scene, b) = (self.scene, self.b);
        match name {
            "params" => self.uniform,
            "vertices" => &scene.vertices,
            "indices" => &scene.indices,
            "pieces" => &b.pieces,
            "out_nodes" => &b.nodes,
            "counters" => &b.counters,
            "draw_args" => &b.draw_args,
            "lattice_dispatch" => &b.lattice_dispatch,
            "object_edge_scale" => &scene.object_edge_scale,
            "cut_list" => &b.cut_list,
            "out_indices" => &b.indices,
            "triangle_edges" => &scene.triangle_edges,
            "cut_edges" | "edge_marks_read" => &b.cut_edges,
            other => panic!("the subdivide stage binds no buffer {other}"),
        }
    }
}
