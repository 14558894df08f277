//! The `subdivide` stage on the GPU (shaders/subdivide/, one file per pass; CPU twin `cpu::subdivide`): its
//! pipelines per panorama, its bind groups, and the replay of its recordings.
//!
//! - **One submission** (the usual frame, [`SubdivideStage::encode`]): the `one_submission`
//!   recording encoded before the raster, in the same submission.
//! - **Any recording, submitted** ([`SubdivideStage::submit`]): what the schedules of
//!   `encoding::schedule` replay through an engine — the chunked frame's (`gpu::subdivided`)
//!   and the read-back's ([`SubdivideStage::readback`], what the twin test compares with the
//!   CPU twin running the same schedule).

use std::sync::OnceLock;

use crate::core::panoramas::panorama::{EyeModel, ImageMap};
use crate::core::panoramas::projection::PanoramaKind;
use crate::core::settings::RenderSettings;
use crate::encoding::constants::PIECES_FROM_COUNTER;
use crate::encoding::recording::{Command, Recording, SubdivideBuffer};
use crate::encoding::schedule::{run_schedule, Capacities, Schedule, SubdivisionEngine, INDICES_SIZE, NODE_SIZE};
use crate::encoding::subdivide::{
    cut_probe, missed, one_submission, timed_passes, PassTiming, Passes, SubdivideOutput, CUT_PASSES,
};
use crate::encoding::types::{DrawVertex, SubdivideCounters, SubdivideParams};
use crate::error::Result;
use crate::gpu::device::Gpu;
use crate::gpu::frame_plan::SubdivisionBuffers;
use crate::gpu::scene::GpuScene;
use crate::gpu::stages::GpuStage;
use crate::gpu::timestamps::{self as stamp, Timestamps};
use crate::shader::{
    StandIn, CAVE_OFF, CUBEMAP_OFF, FISHEYE_OFF, HEAD_OFF, ROWS_OFF, SPACING_OFF, SPHERE_OFF, SUBDIVIDE,
};

pub(crate) const COUNTERS_SIZE: u64 = std::mem::size_of::<SubdivideCounters>() as u64;
// The frame's timestamps are read back as u64s right after the counters.
const _: () = assert!(COUNTERS_SIZE % 8 == 0);

/// The stage's pipelines for one panorama, one per entry point: those every frame runs, built
/// with the variant, and the cut passes ([`CUT_PASSES`]), built when a frame first needs them.
struct Variant {
    pipelines: Vec<(&'static str, wgpu::ComputePipeline)>,
    cut_passes: OnceLock<Vec<(&'static str, wgpu::ComputePipeline)>>,
    build: Build,
}

impl Variant {
    /// The pipeline of an entry point a recording names, if built.
    fn pipeline(&self, entry: &str) -> Option<&wgpu::ComputePipeline> {
        lookup(&self.pipelines, entry).or_else(|| self.cut_passes.get().and_then(|cuts| lookup(cuts, entry)))
    }

    /// The cut passes, built now if they are not yet.
    fn build_cut_passes(&self, gpu: &Gpu, stage: &GpuStage, passes: Passes) {
        self.cut_passes.get_or_init(|| {
            let used: Vec<_> =
                one_submission(1, passes, PassTiming::Untimed).entries().filter(|e| CUT_PASSES.contains(e)).collect();
            Builder::new(&self.build, gpu, stage).run(build_threads(), &used, |_| {})
        });
    }
}

/// The entry points whose pipelines a [`cut_probe`] runs.
const PROBED: [&str; 3] = ["active_cuts", "ring_cuts", "plan"];

/// Asks the GPU whether a frame needs the cut passes, given the pipelines of [`PROBED`].
type Probe<'a> = dyn for<'p> Fn(Pipelines<'p>) -> bool + 'a;

/// The pipeline of an entry point, where built.
type Pipelines<'p> = &'p dyn Fn(&str) -> Option<&'p wgpu::ComputePipeline>;

/// How a variant's pipelines are built: its constants and stand-ins.
struct Build {
    constants: [(&'static str, f64); 6],
    stand_ins: Vec<StandIn>,
}

type Built = Vec<(&'static str, wgpu::ComputePipeline)>;

/// The passes by how long lavapipe takes to build them, longest first (`examples/shader_sizes`);
/// the others (small) after them.
const LONGEST_FIRST: [&str; 7] =
    ["lattice", "plan_cuts", "lattice_rows_plan", "lattice_triangles", "lattice_nodes", "lattice_rows", "plan_parts"];

/// What a variant's build threads share: the entry points still to build (the next at the end),
/// whether more may come, and those built.
struct Queue {
    pending: Vec<&'static str>,
    closed: bool,
    built: Built,
    /// A build thread panicked (its pipeline will never come).
    failed: bool,
}

/// Pipelines built on as many threads as the CPU has cores, the longest first: the driver builds
/// each on one thread, so the longest (`lattice`) is the floor of a variant's build, and a thread
/// per pipeline made it share the cores with all the others until the end.
struct Builder<'b> {
    build: &'b Build,
    gpu: &'b Gpu,
    stage: &'b GpuStage,
    queue: std::sync::Mutex<Queue>,
    changed: std::sync::Condvar,
}

impl<'b> Builder<'b> {
    fn new(build: &'b Build, gpu: &'b Gpu, stage: &'b GpuStage) -> Builder<'b> {
        let queue = Queue { pending: Vec::new(), closed: false, built: Vec::new(), failed: false };
        Builder { build, gpu, stage, queue: std::sync::Mutex::new(queue), changed: std::sync::Condvar::new() }
    }

    fn lock(&self) -> std::sync::MutexGuard<'_, Queue> {
        self.queue.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// Queues `entries` before those waiting, longest first (in the order given where neither is
    /// among [`LONGEST_FIRST`]).
    fn push(&self, entries: &[&'static str]) {
        let rank = |e: &str| LONGEST_FIRST.iter().position(|l| *l == e).unwrap_or(LONGEST_FIRST.len());
        let mut first: Vec<&'static str> = entries.to_vec();
        first.sort_by_key(|e| rank(e)); // stable
        let mut queue = self.lock();
        queue.pending.extend(first.into_iter().rev());
        self.changed.notify_all();
    }

    /// One build thread: the next entry point until none is left and none may come.
    fn work(&self) {
        loop {
            let entry = {
                let mut queue = self.lock();
                loop {
                    if let Some(e) = queue.pending.pop() {
                        break e;
                    }
                    if queue.closed {
                        return;
                    }
                    queue = self.changed.wait(queue).unwrap_or_else(|e| e.into_inner());
                }
            };
            // Whoever waits hears of a panic here rather than waiting for ever.
            let failed = Failed(self);
            let b = self.build;
            let pipeline = self.stage.compute_standing_in(self.gpu, entry, &b.constants, &b.stand_ins);
            std::mem::forget(failed);
            self.lock().built.push((entry, pipeline));
            self.changed.notify_all();
        }
    }

    /// Waits until `entries` are built; their pipelines (handles: the threads go on meanwhile).
    fn wait_for(&self, entries: &[&str]) -> Built {
        let mut queue = self.lock();
        while !entries.iter().all(|e| queue.built.iter().any(|(b, _)| b == e)) {
            assert!(!queue.failed, "a pipeline build panicked");
            queue = self.changed.wait(queue).unwrap_or_else(|e| e.into_inner());
        }
        queue.built.iter().filter(|(b, _)| entries.contains(b)).cloned().collect()
    }

    /// No more entry points: the threads end once the queue is empty.
    fn close(&self) {
        self.lock().closed = true;
        self.changed.notify_all();
    }

    /// Builds `entries` on `threads` threads (and any queued while they run, until closed by
    /// `during`, which runs beside them); all that was built.
    fn run(self, threads: usize, entries: &[&'static str], during: impl FnOnce(&Builder)) -> Built {
        self.push(entries);
        std::thread::scope(|scope| {
            for _ in 0..threads {
                scope.spawn(|| self.work());
            }
            during(&self);
            self.close();
        });
        self.queue.into_inner().unwrap_or_else(|e| e.into_inner()).built
    }
}

/// Marks the queue failed when dropped (a build thread unwinding).
struct Failed<'a, 'b>(&'a Builder<'b>);

impl Drop for Failed<'_, '_> {
    fn drop(&mut self) {
        self.0.lock().failed = true;
        self.0.changed.notify_all();
    }
}

/// Threads for a variant's build: the CPU's cores.
fn build_threads() -> usize {
    std::thread::available_parallelism().map_or(2, |n| n.get())
}

fn lookup<'a>(built: &'a Built, entry: &str) -> Option<&'a wgpu::ComputePipeline> {
    built.iter().find(|(name, _)| *name == entry).map(|(_, p)| p)
}

/// The projection code a variant keeps (the others' is left out: see [`SubdivideStage::variant`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
enum VariantProjection {
    Cylinder,
    /// The cylinder seen by a tracked head.
    Head,
    /// The sphere and VR180 (with the cubemap's pinholes where `pinhole`).
    Sphere,
    Fisheye,
}

/// What a variant of the stage's pipelines is built for, its key (as draw.rs keys its pipelines
/// by `DrawKey`): the projection, spacing by azimuth, the split rule, converging rays, the edge
/// measure, the vertical model and pinhole faces.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
struct VariantKey {
    projection: VariantProjection,
    spacing: bool,
    rule: u32,
    converging: bool,
    measuring: bool,
    exact: bool,
    pinhole: bool,
}

impl VariantKey {
    fn of(panorama: PanoramaKind, params: &SubdivideParams) -> VariantKey {
        let model = panorama.model();
        let projection = match (model.eye_model(), model.image_map()) {
            (_, ImageMap::Fisheye) => VariantProjection::Fisheye,
            (EyeModel::Sphere, _) => VariantProjection::Sphere,
            _ if params.projection.head_on != 0.0 => VariantProjection::Head,
            _ => VariantProjection::Cylinder,
        };
        VariantKey {
            projection,
            spacing: params.by_azimuth != 0,
            rule: params.method.min(3),
            converging: params.projection.convergence > 0.0,
            measuring: params.measure_edges != 0,
            exact: params.projection.vertical_exact != 0,
            pinhole: params.pinhole_faces != 0,
        }
    }
}

/// A built variant, shared with the frames that use it.
struct VariantRef(std::sync::Arc<OnceLock<Variant>>);

impl std::ops::Deref for VariantRef {
    type Target = Variant;
    fn deref(&self) -> &Variant {
        self.0.get().expect("a variant is built before it is handed out")
    }
}

/// The `subdivide` stage: its layouts, and its pipelines built for each panorama and kind of
/// split rule when first needed (the WGSL `override PANORAMAS` compiles the other panorama's
/// projection's branches out; the cylinder's passes are composed without the sphere's projection
/// (`projection_sphere_off`), and the frames that never draw rows without them
/// (`subdivide_rows_off`): lavapipe builds a pipeline about twice as long with the code merely in it).
pub(crate) struct SubdivideStage {
    stage: GpuStage,
    /// The variants built so far, by key (each built once, outside the map's lock).
    variants: std::sync::Mutex<std::collections::HashMap<VariantKey, std::sync::Arc<OnceLock<Variant>>>>,
}

impl SubdivideStage {
    /// The stage; each panorama's pipelines are built when a frame first needs them.
    pub fn new(gpu: &Gpu) -> SubdivideStage {
        SubdivideStage { stage: GpuStage::new(gpu, &SUBDIVIDE), variants: Default::default() }
    }

    /// The pipelines for a panorama (the cylinder with or without a tracked head, the sphere
    /// and VR180, the fisheye) and a frame's split rule (`params.method`): rows on the sphere
    /// under the adaptive rules only. Each leaves out the other panoramas' projection code, and
    /// through its overrides the code of what the frame is not: the other split rules
    /// (`SPLIT_RULE`), the converging eye model where its rays are parallel (`CONVERGING`), the
    /// edge measure where it measures none (`MEASURE_EDGES`), the cylinder's other vertical
    /// model (`VERTICAL_EXACT`), the pinholes' measure where the image has none
    /// (`PINHOLE_FACES`). lavapipe's lanes run the code behind a test of the parameters
    /// whether or not one takes it (docs/results.md, *What lavapipe runs*: together about a
    /// quarter of Sponza's sphere subdivision).
    /// Built side by side on as many threads as the CPU has cores, the longest first
    /// ([`Builder`]: the driver's compiling of the large passes, `plan_cuts` and `lattice`, is
    /// most of a fresh process's time). With a `probe` (a frame's first use of the variant) the
    /// cut passes ([`CUT_PASSES`]) are built only if it says the frame needs them: it runs as
    /// soon as `plan`'s pipelines are built, the others still building.
    fn variant(
        &self,
        gpu: &Gpu,
        panorama: PanoramaKind,
        params: &SubdivideParams,
        probe: Option<&Probe>,
    ) -> VariantRef {
        let key = VariantKey::of(panorama, params);
        let slot = self.variants.lock().unwrap_or_else(|e| e.into_inner()).entry(key).or_default().clone();
        slot.get_or_init(|| self.build_variant(gpu, panorama, params.method, key, probe));
        VariantRef(slot)
    }

    /// Builds the pipelines of the variant `key` (see [`SubdivideStage::variant`]).
    fn build_variant(
        &self,
        gpu: &Gpu,
        panorama: PanoramaKind,
        method: u32,
        key: VariantKey,
        probe: Option<&Probe>,
    ) -> Variant {
        let passes = Passes::of(panorama, method);
        let rows = passes.rows;
        let VariantKey { projection, spacing, rule, converging, measuring, exact, pinhole } = key;
        // Code behind a test of the parameters costs lavapipe's SIMD lanes its time whether or
        // not any lane runs it: the frames that never run it get pipelines without it.
        let bits = match projection {
            VariantProjection::Fisheye => 6.0,
            VariantProjection::Sphere => 2.0,
            _ => 1.0,
        };
        {
            use VariantProjection::*;
            let mut stand_ins: Vec<StandIn> = match (projection, rows) {
                (Cylinder, _) => vec![ROWS_OFF, SPHERE_OFF, FISHEYE_OFF, HEAD_OFF, CUBEMAP_OFF, CAVE_OFF],
                (Head, _) => vec![ROWS_OFF, SPHERE_OFF, FISHEYE_OFF, CUBEMAP_OFF, CAVE_OFF],
                (Sphere, false) => vec![ROWS_OFF, FISHEYE_OFF, HEAD_OFF, CUBEMAP_OFF, CAVE_OFF],
                (Sphere, true) => vec![FISHEYE_OFF, HEAD_OFF, CUBEMAP_OFF, CAVE_OFF],
                (Fisheye, false) => vec![ROWS_OFF, HEAD_OFF, CUBEMAP_OFF, CAVE_OFF],
                (Fisheye, true) => vec![HEAD_OFF, CUBEMAP_OFF, CAVE_OFF],
            };
            if !spacing {
                stand_ins.push(SPACING_OFF);
            }
            let flag = |on: bool| if on { 1.0 } else { 0.0 };
            let constants = [
                ("PANORAMAS", bits),
                ("CONVERGING", flag(converging)),
                ("MEASURE_EDGES", flag(measuring)),
                ("SPLIT_RULE", rule as f64),
                ("VERTICAL_EXACT", flag(exact)),
                ("PINHOLE_FACES", flag(pinhole)),
            ];
            let build = Build { constants, stand_ins };
            let stage = &self.stage;
            // The entry points this frame's schedules dispatch (every schedule's are the usual
            // frame's): `plan`'s, the cut passes, the others.
            let used: Vec<&'static str> = one_submission(1, passes, PassTiming::Untimed).entries().collect();
            let (cuts, others): (Vec<_>, Vec<_>) = used.into_iter().partition(|e| CUT_PASSES.contains(e));
            // `plan`'s first (the probe waits for them), then the others, longest first.
            let (probed, others): (Vec<_>, Vec<_>) = others.into_iter().partition(|e| PROBED.contains(e));
            let all = [probed.as_slice(), others.as_slice()].concat();
            let mut needed = true;
            let built = Builder::new(&build, gpu, stage).run(build_threads(), &all, |b| {
                if let Some(probe) = probe {
                    let built = b.wait_for(&probed);
                    needed = probe(&|entry| lookup(&built, entry));
                }
                if needed {
                    b.push(&cuts);
                }
            });
            let (cut_passes, pipelines): (Built, Built) = built.into_iter().partition(|(e, _)| CUT_PASSES.contains(e));
            let variant = Variant { pipelines, cut_passes: OnceLock::new(), build };
            if needed {
                variant.cut_passes.set(cut_passes).ok();
            }
            variant
        }
    }

    /// The bind group of `entry` (the bindings of `SUBDIVIDE` it uses, by name).
    fn bind_group(&self, gpu: &Gpu, entry: &str, frame: &FrameBuffers) -> wgpu::BindGroup {
        let buffers: Vec<&wgpu::Buffer> = SUBDIVIDE
            .bindings
            .iter()
            .map(|b| {
                frame.get(SubdivideBuffer::bound_as(b.name).expect("every binding is a handle (tests/shaders.rs)"))
            })
            .collect();
        self.stage.bind_group(gpu, Some(entry), 0, &buffers)
    }

    /// Replays `recording` into `enc` for a frame's buffers (each named as it is bound) with
    /// `pipelines`; an entry point without one is left out (the cut passes before a frame needs
    /// them: see [`SubdivideStage::encode`]).
    fn replay<'p>(
        &self,
        gpu: &Gpu,
        enc: &mut wgpu::CommandEncoder,
        recording: &Recording,
        frame: &FrameBuffers,
        pipelines: Pipelines<'p>,
        timestamps: Option<&Timestamps>,
    ) {
        let mut pass: Option<wgpu::ComputePass<'static>> = None;
        for command in &recording.commands {
            match *command {
                Command::Clear { buffer, bytes } => {
                    drop(pass.take());
                    enc.clear_buffer(frame.get(buffer), 0, bytes);
                }
                Command::Pass { label, timestamp } => {
                    drop(pass.take());
                    let timed = timestamps.filter(|_| timestamp.is_some());
                    pass = Some(stamp::compute_pass(enc, label, timed, timestamp.unwrap_or(0)).forget_lifetime());
                }
                Command::Dispatch { entry, invocations } => {
                    let pass = pass.as_mut().expect("a recording dispatches inside a pass");
                    let Some(pipeline) = pipelines(entry) else { continue };
                    pass.set_pipeline(pipeline);
                    pass.set_bind_group(0, &self.bind_group(gpu, entry, frame), &[]);
                    let (x, y) = gpu.workgroups(invocations, 64);
                    pass.dispatch_workgroups(x, y, 1);
                }
                Command::DispatchIndirect { entry, args, offset } => {
                    let pass = pass.as_mut().expect("a recording dispatches inside a pass");
                    let Some(pipeline) = pipelines(entry) else { continue };
                    pass.set_pipeline(pipeline);
                    pass.set_bind_group(0, &self.bind_group(gpu, entry, frame), &[]);
                    pass.dispatch_workgroups_indirect(frame.get(args), offset);
                }
            }
        }
    }

    /// Encodes the one-submission schedule ([`one_submission`], its passes timed as `timing`
    /// says, with `timestamps`) and returns its timed passes ([`timed_passes`]). `params` covers
    /// every triangle, its pieces counted on the GPU.
    /// On the variant's first frame, a [`cut_probe`] submitted first tells whether the cut
    /// passes are built; where they are not, the frame leaves them out, and
    /// [`SubdivideStage::missed_cuts`] says whether it must be drawn again.
    #[allow(clippy::too_many_arguments)]
    pub fn encode(
        &self,
        gpu: &Gpu,
        enc: &mut wgpu::CommandEncoder,
        params_buffer: &wgpu::Buffer,
        scene: &GpuScene,
        b: &SubdivisionBuffers,
        params: &SubdivideParams,
        panorama: PanoramaKind,
        timestamps: Option<&Timestamps>,
        timing: PassTiming,
    ) -> Vec<(&'static str, u32)> {
        let params = SubdivideParams { first_piece: 0, piece_count: PIECES_FROM_COUNTER, ..*params };
        gpu.queue.write_buffer(params_buffer, 0, bytemuck::bytes_of(&params));
        let frame = FrameBuffers { params: params_buffer, scene, b };
        let passes = Passes::of(panorama, params.method);
        let recording = one_submission(params.triangle_count, passes, timing);
        let probe = |pipelines: Pipelines| {
            let mut enc = gpu.device.create_command_encoder(&Default::default());
            self.replay(gpu, &mut enc, &cut_probe(params.triangle_count), &frame, pipelines, None);
            gpu.queue.submit([enc.finish()]);
            // Unread counters: build them.
            gpu.download(&b.counters, COUNTERS_SIZE).map_or(true, |bytes| {
                let cut = |e: &str| !CUT_PASSES.contains(&e);
                !missed(&recording, &params, bytemuck::from_bytes(&bytes), cut).is_empty()
            })
        };
        let variant = self.variant(gpu, panorama, &params, Some(&probe));
        self.replay(gpu, enc, &recording, &frame, &|e| variant.pipeline(e), timestamps);
        timed_passes(&recording)
    }

    /// After a frame [`SubdivideStage::encode`]d with these `params`: whether it left out cut
    /// passes that its `counters` say it needed. They are built then, and the frame must be
    /// drawn again.
    pub fn missed_cuts(
        &self,
        gpu: &Gpu,
        panorama: PanoramaKind,
        params: &SubdivideParams,
        counters: &SubdivideCounters,
    ) -> bool {
        let variant = self.variant(gpu, panorama, params, None);
        if variant.cut_passes.get().is_some() {
            return false; // every frame once they are built
        }
        let passes = Passes::of(panorama, params.method);
        let recording = one_submission(params.triangle_count, passes, PassTiming::Untimed);
        if missed(&recording, params, counters, |e| variant.pipeline(e).is_some()).is_empty() {
            return false;
        }
        variant.build_cut_passes(gpu, &self.stage, passes);
        true
    }

    /// Replays `recording` with `params` as the parameters of a frame's buffers, submitted; the
    /// counters afterwards. Every pipeline it names is built first.
    pub fn submit(
        &self,
        gpu: &Gpu,
        recording: &Recording,
        frame: &FrameBuffers,
        params: &SubdivideParams,
        panorama: PanoramaKind,
    ) -> Result<SubdivideCounters> {
        let variant = self.variant(gpu, panorama, params, None);
        variant.build_cut_passes(gpu, &self.stage, Passes::of(panorama, params.method));
        gpu.queue.write_buffer(frame.params, 0, bytemuck::bytes_of(params));
        let mut enc = gpu.device.create_command_encoder(&Default::default());
        self.replay(gpu, &mut enc, recording, frame, &|e| variant.pipeline(e), None);
        gpu.queue.submit([enc.finish()]);
        let bytes = gpu.download(&frame.b.counters, COUNTERS_SIZE)?;
        Ok(*bytemuck::from_bytes(&bytes))
    }

    /// Runs the whole stage on a scene with `schedule` and reads its output back (the GPU side
    /// of the twin test): a chunked schedule's ranges concatenated, indices moved by the nodes
    /// before them.
    pub fn readback(
        &self,
        gpu: &Gpu,
        scene: &GpuScene,
        settings: &RenderSettings,
        schedule: Schedule,
    ) -> Result<SubdivideOutput> {
        gpu.scoped("subdividing", || {
            let mut engine = Readback {
                stage: self,
                gpu,
                scene,
                panorama: settings.projection().panorama,
                params: gpu.storage_params_buffer::<SubdivideParams>("subdivide params"),
                cache: None,
                nodes: Vec::new(),
                indices: Vec::new(),
            };
            let budget = Capacities::budget(settings.subdivision.memory_mb, gpu.max_binding());
            let totals = run_schedule(&mut engine, settings, scene.triangle_count, schedule, budget)?;
            Ok(totals.output(engine.nodes, engine.indices))
        })
    }
}

/// The read-back's engine: submits each recording, downloads each range's output.
struct Readback<'a> {
    stage: &'a SubdivideStage,
    gpu: &'a Gpu,
    scene: &'a GpuScene,
    panorama: PanoramaKind,
    params: wgpu::Buffer,
    cache: Option<SubdivisionBuffers>,
    nodes: Vec<DrawVertex>,
    indices: Vec<u32>,
}

impl SubdivisionEngine for Readback<'_> {
    fn ensure(&mut self, want: Capacities) -> Capacities {
        SubdivisionBuffers::ensure(&mut self.cache, self.gpu, want, self.scene).capacity
    }

    fn replay(&mut self, recording: &Recording, params: &SubdivideParams) -> Result<SubdivideCounters> {
        let b = self.cache.as_ref().expect("ensured before a replay");
        let frame = FrameBuffers { params: &self.params, scene: self.scene, b };
        self.stage.submit(self.gpu, recording, &frame, params, self.panorama)
    }

    fn take(&mut self, counters: &SubdivideCounters) -> Result<()> {
        let b = self.cache.as_ref().expect("ensured before a replay");
        let nodes = self.gpu.download(&b.nodes, counters.nodes as u64 * NODE_SIZE)?;
        let indices = self.gpu.download(&b.indices, counters.triangles as u64 * INDICES_SIZE)?;
        let offset = self.nodes.len() as u32;
        self.indices.extend(bytemuck::cast_slice::<u8, u32>(&indices).iter().map(|i| i + offset));
        self.nodes.extend_from_slice(bytemuck::cast_slice(&nodes));
        Ok(())
    }
}

/// The buffers a subdivision's recording names: the parameters, the scene's, the frame's.
pub(crate) struct FrameBuffers<'f> {
    pub params: &'f wgpu::Buffer,
    pub scene: &'f GpuScene,
    pub b: &'f SubdivisionBuffers,
}

impl FrameBuffers<'_> {
    /// The buffer behind a handle.
    fn get(&self, buffer: SubdivideBuffer) -> &wgpu::Buffer {
        use SubdivideBuffer::*;
        let (scene, b) = (self.scene, self.b);
        match buffer {
            Params => self.params,
            Vertices => &scene.vertices,
            Indices => &scene.indices,
            Pieces => &b.pieces,
            Parts => &b.parts,
            PieceWork => &b.piece_work,
            LatticeWork => &b.lattice_work,
            OutNodes => &b.nodes,
            Counters => &b.counters,
            DrawArgs => &b.draw_args,
            LatticeDispatch => &b.lattice_dispatch,
            ObjectEdgeScale => &scene.object_edge_scale,
            CutList => &b.cut_list,
            OutIndices => &b.indices,
            TriangleEdges => &scene.triangle_edges,
            CutEdges => &b.cut_edges,
        }
    }
}
