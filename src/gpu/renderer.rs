//! The headless renderer: the `subdivide` compute pre-pass (`plan`, then `lattice`), then the
//! `raster` stage draws the subdivided triangles indirectly for both eyes (one multiview draw,
//! or a pass per eye; its pipelines in `gpu/draw.rs`); or the `slit` stage (`gpu/slit.rs`) or
//! the `trace` stage (`gpu/trace.rs`); then read-back and, with the error pass, `reduce_error`. The
//! schedule is a [`FramePlan`]; pipelines, targets, uniforms and buffers are made once and
//! reused across frames. Every frame runs inside GPU error scopes, so a GPU error is one
//! [`Error::Gpu`] line.

use std::sync::{Mutex, OnceLock};
use std::time::Instant;

use crate::core::frame::{Frame, FrameStats, Measurement, Timing};
use crate::core::projection::{Eye, PanoramaKind};
use crate::core::settings::{Method, RenderSettings};
use crate::encoding::constants::PIECES_FROM_COUNTER;
use crate::encoding::params::raster_params;
use crate::encoding::subdivide::{subdivide_params, SubdivideOutput};
use crate::encoding::types::{RasterParams, SlitParams, SubdivideCounters, SubdivideParams, TraceParams};
use crate::error::{Error, Result};
use crate::gpu::device::Gpu;
use crate::gpu::draw::{DrawKey, DrawPipelines, DrawStage, Lit, Look, ShadowPipelines};
use crate::gpu::frame_plan::{
    on_overflow, Capacities, FramePlan, Overflow, SubdivisionBuffers, INDICES_SIZE, NODE_SIZE,
};
use crate::gpu::scene::GpuScene;
use crate::gpu::stages::GpuStage;
use crate::gpu::targets::{Layers, Targets};
use crate::gpu::timestamps::{self as stamp, Timestamps};
use crate::shader::{REDUCE_ERROR, SUBDIVIDE};

/// The `subdivide` stage's pipelines for one panorama, one per entry point.
struct SubdivideVariant {
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
struct SubdividePipelines {
    stage: GpuStage,
    variants: [OnceLock<SubdivideVariant>; 2],
}

impl SubdividePipelines {
    fn variant(&self, gpu: &Gpu, panorama: PanoramaKind) -> &SubdivideVariant {
        let (k, bits) = match panorama {
            PanoramaKind::Cylinder => (0, 1.0),
            PanoramaKind::Equirect => (1, 2.0),
        };
        self.variants[k].get_or_init(|| {
            let constants = [("PANORAMAS", bits)];
            let make = |entry| self.stage.compute_with(gpu, entry, &constants);
            SubdivideVariant {
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
}

/// What a renderer keeps between frames.
pub(crate) struct FrameResources {
    pub buffers: Option<SubdivisionBuffers>,
    /// Targets of the last image size.
    pub targets: Option<Targets>,
    pub timestamps: Option<Timestamps>,
    pub subdivide_params: wgpu::Buffer,
    /// Both eyes' (left, right), as the raster stage's `array<RasterParams, 2>`.
    pub raster_params: wgpu::Buffer,
    pub slit_params: [wgpu::Buffer; 2],
    /// Counters and timestamps of a one-submission frame.
    pub staging: wgpu::Buffer,
    pub trace_params: wgpu::Buffer,
    /// The ray tracer's outputs of the last image size: (padded row texels, height, colour,
    /// error, object and distance buffers), and its counters of rays and triangle tests.
    pub trace_outputs: Option<(u32, u32, [wgpu::Buffer; 4])>,
    pub trace_counts: Option<wgpu::Buffer>,
}

impl FrameResources {
    /// The targets for this size, made anew only when the size changed.
    /// The targets for this size (with the positions target if `positions`), made anew only
    /// when the size changed or the positions target is wanted and missing.
    pub fn targets(&mut self, gpu: &Gpu, width: u32, height: u32, positions: bool, hdr: bool) -> &Targets {
        if !self.targets.as_ref().is_some_and(|t| {
            t.width == width && t.height == height && (t.position.is_some() || !positions) && t.hdr == hdr
        }) {
            self.targets = Some(Targets::new(gpu, width, height, positions, hdr));
        }
        self.targets.as_ref().expect("just made")
    }
}

const COUNTERS_SIZE: u64 = std::mem::size_of::<SubdivideCounters>() as u64;
const STAGING_SIZE: u64 = COUNTERS_SIZE + 8 * stamp::COUNT as u64;

/// GPU times (ms) of a one-submission frame, from its timestamps.
struct GpuTimes {
    subdivide: f64,
    /// The subdivision's passes: `plan` (with `active_cuts`), `plan_cuts`, `lattice`.
    passes: [f64; 3],
    raster: f64,
    frame: f64,
}

pub struct Renderer {
    pub gpu: Gpu,
    subdivide: SubdividePipelines,
    pub(crate) raster: DrawPipelines,
    pub(crate) slit: DrawPipelines,
    pub(crate) shadow: ShadowPipelines,
    pub(crate) reduce: GpuStage,
    pub(crate) accumulate: wgpu::ComputePipeline,
    pub(crate) finish: wgpu::ComputePipeline,
    pub(crate) project_points: OnceLock<(GpuStage, wgpu::ComputePipeline)>,
    /// The skin stage and its pipeline (`gpu::skin`), made on the first pose.
    pub(crate) skin: OnceLock<(GpuStage, wgpu::ComputePipeline)>,
    /// The trace stage and its pipelines without and with the material code.
    pub(crate) trace: OnceLock<(GpuStage, [wgpu::ComputePipeline; 2])>,
    pub(crate) resources: Mutex<FrameResources>,
}

impl Renderer {
    /// Builds every stage's pipelines (a GPU error here is returned, not a panic).
    pub fn new(gpu: Gpu) -> Result<Renderer> {
        let built = gpu.scoped("building the pipelines", || {
            let stage = GpuStage::new(&gpu, &SUBDIVIDE);
            let subdivide = SubdividePipelines { stage, variants: [OnceLock::new(), OnceLock::new()] };
            // The cylinder's pipelines now: a GPU error building them shows here, not mid-frame.
            subdivide.variant(&gpu, PanoramaKind::Cylinder);
            let reduce = GpuStage::new(&gpu, &REDUCE_ERROR);
            let resources = FrameResources {
                buffers: None,
                targets: None,
                timestamps: Timestamps::new(&gpu),
                subdivide_params: gpu.uniform_buffer::<SubdivideParams>("subdivide params"),
                raster_params: gpu.uniform_buffer::<[RasterParams; 2]>("raster params"),
                slit_params: Eye::BOTH.map(|e| gpu.uniform_buffer::<SlitParams>(&format!("{} slit params", e.name()))),
                staging: gpu.device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some("frame readback"),
                    size: STAGING_SIZE,
                    usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
                    mapped_at_creation: false,
                }),
                trace_params: gpu.uniform_buffer::<TraceParams>("trace params"),
                trace_outputs: None,
                trace_counts: None,
            };
            let raster = DrawPipelines::new(&gpu, DrawStage::Raster);
            // The usual pipeline now, for the same reason.
            let layers = Layers::passes(gpu.eyes_per_draw)[0];
            raster.keyed(&gpu, DrawKey { look: Some((Look::Plain, Lit::default())), outputs: 1, layers, hdr: false });
            Ok((
                subdivide,
                raster,
                DrawPipelines::new(&gpu, DrawStage::Slit),
                ShadowPipelines::new(&gpu),
                reduce.compute(&gpu, "accumulate"),
                reduce.compute(&gpu, "finish"),
                reduce,
                resources,
            ))
        })?;
        let (subdivide, raster, slit, shadow, accumulate, finish, reduce, resources) = built;
        Ok(Renderer {
            gpu,
            subdivide,
            raster,
            slit,
            shadow,
            reduce,
            accumulate,
            finish,
            project_points: OnceLock::new(),
            skin: OnceLock::new(),
            trace: OnceLock::new(),
            resources: Mutex::new(resources),
        })
    }

    /// Renders both eyes of an uploaded scene.
    pub fn render(&self, scene: &GpuScene, settings: &RenderSettings) -> Result<Frame> {
        settings.validate()?;
        self.check_size(settings)?;
        let mut resources = self.resources.lock().unwrap_or_else(|e| e.into_inner());
        let shadow_maps = scene.write_lighting(&self.gpu, settings);
        if settings.shading.hdr && matches!(settings.subdivision.method, Method::Slit(_) | Method::Trace) {
            return Err(Error::setting(
                "shading.hdr",
                "the linear colour comes from the projection methods (vertex, fixed, adaptive); slit and trace write display colours",
            ));
        }
        self.draw_shadow_maps(scene, settings.view(), &shadow_maps)?;
        self.gpu.scoped("rendering a frame", || match settings.subdivision.method {
            Method::Slit(width) => self.render_slit(&mut resources, scene, settings, width),
            Method::Trace => self.render_trace(&mut resources, scene, settings),
            _ => self.render_subdivided(&mut resources, scene, settings),
        })
    }

    /// Fails with one line when the image cannot be drawn on this device.
    fn check_size(&self, settings: &RenderSettings) -> Result<()> {
        let p = settings.projection();
        let max = self.gpu.limits.max_texture_dimension_2d;
        if p.width > max || p.height > max {
            return Err(Error::setting(
                "view.projection.width/height",
                format!("{}x{} is larger than this GPU's largest image, {max}x{max}", p.width, p.height),
            ));
        }
        // Both eyes' colour targets are read back through one buffer (rows padded to 256
        // bytes); with the error pass, each eye's error target is bound as storage (both at once
        // when they fit one binding).
        let padded_row = (4 * p.width as u64).div_ceil(256) * 256;
        let eyes_bytes = 2 * padded_row * p.height as u64;
        let max_buffer = self.gpu.limits.max_buffer_size;
        let (limit, what) = if settings.measure.error {
            (max_buffer.min(2 * self.gpu.max_binding()), "the error pass's buffers")
        } else {
            (max_buffer, "the read-back buffer")
        };
        if eyes_bytes > limit {
            return Err(Error::setting(
                "view.projection.width/height",
                format!(
                    "{}x{} needs {} MiB for {what}, more than this GPU's {} MiB: use a smaller image",
                    p.width,
                    p.height,
                    eyes_bytes >> 20,
                    limit >> 20
                ),
            ));
        }
        Ok(())
    }

    /// The subdivide stage's bind group: params, vertices, indices, pieces, output nodes,
    /// counters, draw args, lattice dispatch, per-object edge scale, cut list, output indices,
    /// triangle edges, cut edges (twice: read-write and read-only) (the order of
    /// `SUBDIVIDE.bindings`).
    fn subdivide_bind_group(
        &self,
        entry: &str,
        uniform: &wgpu::Buffer,
        scene: &GpuScene,
        b: &SubdivisionBuffers,
    ) -> wgpu::BindGroup {
        self.subdivide.stage.bind_group(
            &self.gpu,
            Some(entry),
            0,
            &[
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
                &scene.cut_edges,
                &scene.cut_edges,
            ],
        )
    }

    /// The subdivide pipelines for the panorama of `params`.
    fn subdivide_for(&self, params: &SubdivideParams) -> &SubdivideVariant {
        let panorama = if params.projection.panorama == 1 { PanoramaKind::Equirect } else { PanoramaKind::Cylinder };
        self.subdivide.variant(&self.gpu, panorama)
    }

    /// Clears the counters and runs `active_cuts` and `ring_cuts` over every triangle of the
    /// scene: the start of a frame that runs `plan` and `lattice` apart (chunks, read-back).
    fn run_active_cuts(
        &self,
        uniform: &wgpu::Buffer,
        scene: &GpuScene,
        buffers: &SubdivisionBuffers,
        params: &SubdivideParams,
    ) {
        let params = SubdivideParams { first_triangle: 0, triangle_count: scene.triangle_count, ..*params };
        self.gpu.queue.write_buffer(uniform, 0, bytemuck::bytes_of(&params));
        let groups = ["active_cuts", "ring_cuts"].map(|e| self.subdivide_bind_group(e, uniform, scene, buffers));
        let variant = self.subdivide_for(&params);
        let mut enc = self.gpu.device.create_command_encoder(&Default::default());
        enc.clear_buffer(&buffers.counters, 0, None);
        enc.clear_buffer(&scene.cut_edges, 0, None);
        {
            let mut pass = enc.begin_compute_pass(&Default::default());
            let (x, y) = self.gpu.workgroups(scene.triangle_count, 64);
            for (pipeline, group) in [&variant.active_cuts, &variant.ring_cuts].into_iter().zip(&groups) {
                pass.set_pipeline(pipeline);
                pass.set_bind_group(0, group, &[]);
                pass.dispatch_workgroups(x, y, 1);
            }
        }
        self.gpu.queue.submit([enc.finish()]);
    }

    /// Runs one compute entry point of the subdivide stage (`plan` or `lattice`) over `count`
    /// invocations, then `finalize`, and returns the counters afterwards (the frame's cuts,
    /// from `run_active_cuts`, are kept).
    fn run_subdivide(
        &self,
        entry: &str,
        uniform: &wgpu::Buffer,
        scene: &GpuScene,
        buffers: &SubdivisionBuffers,
        params: &SubdivideParams,
        count: u32,
    ) -> Result<SubdivideCounters> {
        self.gpu.queue.write_buffer(uniform, 0, bytemuck::bytes_of(params));
        let variant = self.subdivide_for(params);
        let pipeline = if entry == "plan" { &variant.plan } else { &variant.lattice };
        let bind_group = self.subdivide_bind_group(entry, uniform, scene, buffers);
        let cut_groups = ["plan_cuts_args", "plan_cuts"].map(|e| self.subdivide_bind_group(e, uniform, scene, buffers));
        let finalize = self.subdivide_bind_group("finalize", uniform, scene, buffers);
        let mut enc = self.gpu.device.create_command_encoder(&Default::default());
        enc.clear_buffer(&buffers.counters, 0, Some(SubdivideCounters::RUN_BYTES));
        {
            let mut pass = enc.begin_compute_pass(&Default::default());
            pass.set_pipeline(pipeline);
            pass.set_bind_group(0, &bind_group, &[]);
            let (x, y) = self.gpu.workgroups(count, 64);
            pass.dispatch_workgroups(x, y, 1);
            if entry == "plan" {
                Self::encode_plan_cuts(variant, &mut pass, buffers, &cut_groups);
            }
            pass.set_pipeline(&variant.finalize);
            pass.set_bind_group(0, &finalize, &[]);
            pass.dispatch_workgroups(1, 1, 1);
        }
        self.gpu.queue.submit([enc.finish()]);
        let bytes = self.gpu.download(&buffers.counters, COUNTERS_SIZE)?;
        Ok(*bytemuck::from_bytes(&bytes))
    }

    /// `plan_cuts_args` and `plan_cuts` (the triangles `plan` listed), after `plan`.
    fn encode_plan_cuts(
        variant: &SubdivideVariant,
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

    /// The usual frame, in one submission (see [`FramePlan::OneSubmission`]). Returns None if a
    /// buffer overflowed; else the counters and, with timestamp queries, the GPU times (ms) of
    /// the subdivision, the raster and the whole frame.
    fn render_one_submission(
        &self,
        res: &FrameResources,
        scene: &GpuScene,
        settings: &RenderSettings,
        targets: &Targets,
        b: &SubdivisionBuffers,
        mut params: SubdivideParams,
    ) -> Result<Option<(SubdivideCounters, Option<GpuTimes>)>> {
        params.first_piece = 0;
        params.piece_count = PIECES_FROM_COUNTER;
        self.gpu.queue.write_buffer(&res.subdivide_params, 0, bytemuck::bytes_of(&params));
        let group = |entry| self.subdivide_bind_group(entry, &res.subdivide_params, scene, b);
        let groups = ["active_cuts", "ring_cuts", "plan", "lattice_args", "lattice", "finalize"].map(group);
        let cut_groups = ["plan_cuts_args", "plan_cuts"].map(group);
        let timestamps = res.timestamps.as_ref();
        let mut enc = self.gpu.device.create_command_encoder(&Default::default());
        enc.clear_buffer(&b.counters, 0, None);
        enc.clear_buffer(&scene.cut_edges, 0, None);
        // Three compute passes (timed apart where the adapter has timestamps): the cuts (both
        // rings) and `plan`, `plan_cuts`, the lattice.
        let variant = self.subdivide_for(&params);
        {
            let mut pass = stamp::compute_pass(&mut enc, "plan", timestamps, stamp::PLAN);
            let (x, y) = self.gpu.workgroups(params.triangle_count, 64);
            for (pipeline, group) in [&variant.active_cuts, &variant.ring_cuts, &variant.plan].into_iter().zip(&groups)
            {
                pass.set_pipeline(pipeline);
                pass.set_bind_group(0, group, &[]);
                pass.dispatch_workgroups(x, y, 1);
            }
        }
        {
            let mut pass = stamp::compute_pass(&mut enc, "plan_cuts", timestamps, stamp::PLAN_CUTS);
            Self::encode_plan_cuts(variant, &mut pass, b, &cut_groups);
        }
        {
            let mut pass = stamp::compute_pass(&mut enc, "lattice", timestamps, stamp::LATTICE);
            pass.set_pipeline(&variant.lattice_args);
            pass.set_bind_group(0, &groups[3], &[]);
            pass.dispatch_workgroups(1, 1, 1);
            pass.set_pipeline(&variant.lattice);
            pass.set_bind_group(0, &groups[4], &[]);
            pass.dispatch_workgroups_indirect(&b.lattice_dispatch, 0);
            pass.set_pipeline(&variant.finalize);
            pass.set_bind_group(0, &groups[5], &[]);
            pass.dispatch_workgroups(1, 1, 1);
        }
        self.encode_raster(
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
        self.gpu.queue.submit([enc.finish()]);
        let bytes = self.gpu.read_buffer(&res.staging)?;
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
        enc: &mut wgpu::CommandEncoder,
        res: &FrameResources,
        scene: &GpuScene,
        targets: &Targets,
        buffers: &SubdivisionBuffers,
        settings: &RenderSettings,
        clear: bool,
        timestamps: Option<(&wgpu::QuerySet, u32, u32)>,
    ) {
        let materials = self.raster.material_bind_group(&self.gpu, scene);
        let uniform = &res.raster_params;
        self.gpu.queue.write_buffer(uniform, 0, bytemuck::cast_slice(&raster_params(settings)));
        let bind_group = self.raster.stage.bind_group(&self.gpu, None, 0, &[uniform]);
        let passes = Layers::passes(self.gpu.eyes_per_draw);
        for (k, &layers) in passes.iter().enumerate() {
            let pipeline = self.raster.get(&self.gpu, scene, settings, layers);
            let writes = timestamps.map(|(q, begin, end)| wgpu::RenderPassTimestampWrites {
                query_set: q,
                beginning_of_pass_write_index: (k == 0).then_some(begin),
                end_of_pass_write_index: (k + 1 == passes.len()).then_some(end),
            });
            let mut pass = targets.begin_pass(enc, layers, settings, clear, writes);
            pass.set_bind_group(0, &bind_group, &[]);
            pass.set_bind_group(1, &materials, &[]);
            if clear && scene.shows_environment(settings) {
                pass.set_pipeline(&self.raster.background(&self.gpu, settings, layers));
                pass.draw(0..3, 0..1);
            }
            pass.set_pipeline(&pipeline);
            pass.set_vertex_buffer(0, buffers.nodes.slice(..));
            pass.set_index_buffer(buffers.indices.slice(..), wgpu::IndexFormat::Uint32);
            pass.draw_indexed_indirect(&buffers.draw_args, 0);
        }
    }

    /// Runs the whole subdivide stage on a scene and reads its output back: the GPU side of the
    /// CPU-twin tests. Buffers are sized to hold everything at once.
    pub fn subdivide_readback(&self, scene: &GpuScene, settings: &RenderSettings) -> Result<SubdivideOutput> {
        self.gpu.scoped("subdividing", || {
            let mut cache = None;
            let uniform = self.gpu.uniform_buffer::<SubdivideParams>("subdivide params");
            let mut params = subdivide_params(settings, 0, scene.triangle_count);
            let mut want = Capacities {
                pieces: scene.triangle_count.max(64),
                triangles: scene.triangle_count.saturating_mul(4).max(1024),
            };
            loop {
                let b = SubdivisionBuffers::ensure(&mut cache, &self.gpu, want, scene.triangle_count);
                params.piece_capacity = b.capacity.pieces;
                params.triangle_capacity = b.capacity.triangles;
                self.run_active_cuts(&uniform, scene, b, &params);
                let planned = self.run_subdivide("plan", &uniform, scene, b, &params, scene.triangle_count)?;
                if planned.pieces > b.capacity.pieces {
                    want.pieces = planned.pieces;
                    continue;
                }
                params.first_piece = 0;
                params.piece_count = planned.pieces;
                let done = self.run_subdivide("lattice", &uniform, scene, b, &params, planned.pieces)?;
                if done.output_units() > b.capacity.triangles {
                    want.triangles = done.output_units();
                    continue;
                }
                let nodes = self.gpu.download(&b.nodes, done.nodes as u64 * NODE_SIZE)?;
                let indices = self.gpu.download(&b.indices, done.triangles as u64 * INDICES_SIZE)?;
                return Ok(SubdivideOutput::indexed(
                    bytemuck::cast_slice(&nodes).to_vec(),
                    bytemuck::cast_slice(&indices).to_vec(),
                    planned.pieces,
                    f32::from_bits(done.max_edge_bits),
                    done.cuts(),
                ));
            }
        })
    }

    /// Reads the targets back and reduces the error: the end of every render.
    pub(crate) fn finish_frame(
        &self,
        targets: &Targets,
        settings: &RenderSettings,
        mut stats: FrameStats,
        start: Instant,
    ) -> Result<Frame> {
        let t = Instant::now();
        let (hdr, [left, right]) = if targets.hdr {
            // The linear colour, and as display bytes clamped (the frame is not tone mapped).
            let hdr = targets.read_hdr(&self.gpu)?;
            let image = |eye: &Vec<[f32; 3]>| crate::core::frame::EyeImage {
                width: targets.width,
                height: targets.height,
                rgba: eye.iter().flat_map(|c| crate::core::color::display_bytes(glam::Vec3::from(*c))).collect(),
            };
            let images = [image(&hdr[0]), image(&hdr[1])];
            (Some(hdr), images)
        } else {
            (None, targets.read_colors(&self.gpu)?)
        };
        stats.ms_readback = t.elapsed().as_secs_f64() * 1e3;
        let depth = if settings.measure.depth { Some(targets.read_distances(&self.gpu)?) } else { None };
        let positions = if settings.measure.positions { Some(targets.read_positions(&self.gpu)?) } else { None };
        let measurement = if settings.measure.error {
            let object = targets.read_objects(&self.gpu)?;
            let (stats, error) = self.reduce_errors(targets, settings.measure.reduce_per_eye)?;
            Some(Measurement { error, object, stats })
        } else {
            None
        };
        stats.ms_total = start.elapsed().as_secs_f64() * 1e3;
        Ok(Frame { left, right, stats, measurement, depth, positions, hdr })
    }

    /// The subdivided frame: follows the [`FramePlan`].
    fn render_subdivided(
        &self,
        res: &mut FrameResources,
        scene: &GpuScene,
        settings: &RenderSettings,
    ) -> Result<Frame> {
        let start = Instant::now();
        let mut stats = FrameStats { triangles_in: scene.triangle_count as u64, ..Default::default() };
        let p = settings.projection();
        res.targets(&self.gpu, p.width, p.height, settings.measure.positions, settings.shading.hdr);
        let budget = Capacities::budget(settings.subdivision.memory_mb, self.gpu.max_binding());
        let n = scene.triangle_count;
        let mut plan = FramePlan::first(n, res.buffers.as_ref().map(|b| b.capacity), budget);
        if let FramePlan::OneSubmission(want) = plan {
            SubdivisionBuffers::ensure(&mut res.buffers, &self.gpu, want, n);
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
            if let Some((counters, times)) = self.render_one_submission(res, scene, settings, targets, b, params)? {
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
                return self.finish_frame(targets, settings, stats, start);
            }
            plan = plan.after_overflow(budget);
        }
        let FramePlan::Chunked { mut want, budget } = plan else { unreachable!("a one-submission frame returned") };
        self.render_chunked(res, scene, settings, &mut want, budget, &mut stats)?;
        stats.ms_frame = stats.ms_subdivide.unwrap_or(0.0) + stats.ms_raster.unwrap_or(0.0);
        stats.timing = Timing::WallPerPass;
        let targets = res.targets.as_ref().expect("made");
        self.finish_frame(targets, settings, stats, start)
    }

    /// The chunked schedule (see [`FramePlan::Chunked`]): wall times per pass.
    fn render_chunked(
        &self,
        res: &mut FrameResources,
        scene: &GpuScene,
        settings: &RenderSettings,
        want: &mut Capacities,
        budget: Capacities,
        stats: &mut FrameStats,
    ) -> Result<()> {
        let n = scene.triangle_count;
        let memory_mb = settings.subdivision.memory_mb;
        let (mut ms_subdivide, mut ms_raster) = (0.0, 0.0);
        let (mut first_tri, mut tri_chunk) = (0u32, n.max(1));
        let mut cleared = false;
        let b = SubdivisionBuffers::ensure(&mut res.buffers, &self.gpu, *want, n);
        tri_chunk = tri_chunk.min(b.cut_list_capacity);
        let t = Instant::now();
        self.run_active_cuts(&res.subdivide_params, scene, b, &subdivide_params(settings, 0, n));
        ms_subdivide += t.elapsed().as_secs_f64() * 1e3;
        while first_tri < n || !cleared {
            let tri_count = tri_chunk.min(n - first_tri);
            let b = SubdivisionBuffers::ensure(&mut res.buffers, &self.gpu, *want, n);
            let mut params = subdivide_params(settings, first_tri, tri_count);
            params.piece_capacity = b.capacity.pieces.min(budget.pieces);
            params.triangle_capacity = b.capacity.triangles;
            let t = Instant::now();
            let planned = self.run_subdivide("plan", &res.subdivide_params, scene, b, &params, tri_count)?;
            ms_subdivide += t.elapsed().as_secs_f64() * 1e3;
            if planned.pieces > params.piece_capacity {
                match on_overflow(planned.pieces, budget.pieces, tri_count) {
                    Overflow::Grow(p) => want.pieces = p,
                    Overflow::Halve(c) => tri_chunk = c,
                    Overflow::TooBig => {
                        return Err(Error::setting(
                            "subdivision.memory_mb",
                            format!(
                            "{memory_mb} is too small: one triangle needs {} pieces; raise the edge length L or the memory budget",
                            planned.pieces
                        ),
                        ))
                    }
                }
                continue;
            }
            stats.pieces += planned.pieces as u64;
            let (mut first_piece, mut piece_chunk) = (0u32, planned.pieces.max(1));
            let mut piece_done = false;
            while first_piece < planned.pieces || !piece_done {
                let piece_count = piece_chunk.min(planned.pieces - first_piece);
                let b = SubdivisionBuffers::ensure(&mut res.buffers, &self.gpu, *want, n);
                params.first_piece = first_piece;
                params.piece_count = piece_count;
                params.triangle_capacity = b.capacity.triangles.min(budget.triangles);
                let t = Instant::now();
                let done = self.run_subdivide("lattice", &res.subdivide_params, scene, b, &params, piece_count)?;
                ms_subdivide += t.elapsed().as_secs_f64() * 1e3;
                if done.output_units() > params.triangle_capacity {
                    match on_overflow(done.output_units(), budget.triangles, piece_count) {
                        Overflow::Grow(t) => want.triangles = t,
                        Overflow::Halve(c) => piece_chunk = c,
                        Overflow::TooBig => {
                            return Err(Error::setting(
                                "subdivision.memory_mb",
                                format!(
                                    "{memory_mb} is too small: one piece makes {} triangles and nodes; lower the fixed N or raise the memory budget",
                                    done.output_units()
                                ),
                            ))
                        }
                    }
                    continue;
                }
                let t = Instant::now();
                let targets = res.targets.as_ref().expect("made");
                let b = res.buffers.as_ref().expect("ensured");
                let mut enc = self.gpu.device.create_command_encoder(&Default::default());
                self.encode_raster(&mut enc, res, scene, targets, b, settings, !cleared, None);
                self.gpu.queue.submit([enc.finish()]);
                self.gpu.wait();
                ms_raster += t.elapsed().as_secs_f64() * 1e3;
                cleared = true;
                piece_done = true;
                stats.triangles_out += done.triangles as u64;
                stats.nodes_out += done.nodes as u64;
                stats.chunks += 1;
                stats.max_sub_edge_px = stats.max_sub_edge_px.max(f32::from_bits(done.max_edge_bits));
                first_piece += piece_count;
            }
            first_tri += tri_count;
        }
        stats.ms_subdivide = Some(ms_subdivide);
        stats.ms_raster = Some(ms_raster);
        Ok(())
    }
}
