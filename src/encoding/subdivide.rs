//! The `subdivide` stage's encoding: its parameters built from the settings, the cuts around the
//! axis it reports, and its output as both the GPU (read back) and the CPU twin give it.

use crate::core::panoramas::panorama::ImageMap;
use crate::core::panoramas::projection::{PanoramaKind, Projection};
use crate::core::settings::{RenderSettings, SplitRule};
use crate::encoding::constants::{AXIS_CLEARANCE_MAX, AXIS_CLEARANCE_MIN, OFFSET_SPLIT_FACTOR, PLAN_CUTS_SPLIT};
use crate::encoding::recording::{Command, Recording, SubdivideBuffer};
use crate::encoding::types::{DrawVertex, SubdivideCounters, SubdivideParams};

/// The `subdivide` stage's parameters for a range of input triangles (capacities and piece
/// ranges are left for the caller, 0).
pub fn subdivide_params(settings: &RenderSettings, first_triangle: u32, triangle_count: u32) -> SubdivideParams {
    let projection = settings.projection();
    // The image the subdivision measures edges on (the cubemap: the sphere at its faces'
    // resolution; `Projection::measured`).
    let measured = projection.measured();
    let sub = &settings.subdivision;
    let (rule, fixed_n) = sub.method.split_rule();
    // The error split on the equirectangular panoramas draws nodes off their projections
    // (`cpu::subdivide::offsets`), which halves each triangle's largest error: it splits at
    // OFFSET_SPLIT_FACTOR·τ for about the error τ gives without them.
    let node_offsets = projection.panorama.is_equirectangular() && rule == SplitRule::AdaptiveError;
    // The cubemap's faces, each drawn as a pinhole from the eye points (`cpu::raster::clip_w`).
    let pinhole_faces = projection.model().image_map() == ImageMap::Cubemap;
    SubdivideParams {
        view: settings.view().to_cols_array_2d(),
        projection: (&measured).into(),
        axis_clearance: axis_clearance(projection),
        triangle_count,
        first_triangle,
        method: rule as u32,
        fixed_n,
        edge_px: sub.edge_px,
        max_error_px: sub.max_error_px * if node_offsets { OFFSET_SPLIT_FACTOR } else { 1.0 },
        max_div: sub.max_div.max(1),
        piece_capacity: 0,
        triangle_capacity: 0,
        first_piece: 0,
        piece_count: 0,
        measure_edges: (settings.measure.edges || settings.measure.error) as u32,
        vertical_limit: projection.vertical_limit(),
        by_azimuth: (SplitRule::spaces_by_azimuth(rule as u32) && !pinhole_faces) as u32,
        seamless: projection.model().turn_share().is_none() as u32,
        pinhole_faces: pinhole_faces as u32,
        node_offsets: node_offsets as u32,
        antipode_cos: projection
            .dome_antipode_cone(projection.chord_dip_px(
                rule == SplitRule::AdaptiveError,
                sub.edge_px,
                sub.max_error_px,
            ))
            .unwrap_or(2.0),
        _pad: 0,
    }
}

/// ρ, the half-diagonal of the square cut around the axis: the eye radius clamped to
/// `[AXIS_CLEARANCE_MIN, AXIS_CLEARANCE_MAX]`·R_T = [10⁻⁵, 10⁻³]·R_T. At most d_e, so only points no
/// eye sees are removed, unless d_e < 10⁻⁵·R_T (a mono camera): then the removed points within
/// 10⁻⁵·R_T of the axis could show only if they were as close to the eyes' height. Small, so that
/// the paper model's image of a ceiling just above the eyes reaches past the top of the image;
/// not smaller, so that the thin parts beside the square keep distinct lattice nodes in f32.
///
/// The sphere with pole merge sees every point near the axis (at the poles the eyes meet at the
/// centre), and so does the sphere with converging rays (a ray crosses the axis where it meets
/// the convergence sphere, so the points within d_e of the axis show): there ρ is
/// `AXIS_CLEARANCE_MIN` metres, so the hole the square leaves at a pole (the colatitudes below
/// ρ/h for a surface h above or below the eyes) is smaller than half a pixel row unless
/// h < 2ρ·H/π (1.3 cm at 4096×2048); the sphere's and the cubemap's pole then close it.
pub fn axis_clearance(projection: &Projection) -> f32 {
    if projection.panorama.is_sphere() && (projection.pole_merge.is_some() || projection.convergence.is_some()) {
        return AXIS_CLEARANCE_MIN;
    }
    let rt = projection.screen_radius;
    projection.eye_radius.clamp(AXIS_CLEARANCE_MIN * rt, AXIS_CLEARANCE_MAX * rt)
}

/// The cuts around the axis that a frame makes (see `cpu::subdivide::triangle_cuts`): bit 0 the quadrant cuts
/// (planes x = 0 and z = 0) and the square around the axis, bit k ≥ 1 the diamond c_k
/// (`band_bound`). With no bit set, no triangle is cut.
pub type AxisCuts = u64;

/// The stage's output, and counters the GPU keeps too.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SubdivideOutput {
    /// Every piece's lattice nodes, once per seam copy (the raster's vertex buffer).
    pub nodes: Vec<DrawVertex>,
    /// The output triangles: three indices into `nodes` each.
    pub indices: Vec<u32>,
    /// The same triangles as three vertices each (`nodes` by `indices`), for comparisons.
    pub vertices: Vec<DrawVertex>,
    pub pieces: u32,
    /// Largest projected length, in pixels, of an output edge with an end on the screen rows.
    pub max_sub_edge_px: f32,
    /// The cuts around the axis the frame made (`active_cuts`).
    pub cuts: AxisCuts,
    /// Pieces drawn as a sliver's strip (the twin's count, for tests; 0 from the GPU).
    pub strips: u32,
    /// Pieces drawn in rows (`Rows`; the twin's count, for tests; 0 from the GPU).
    pub rows: u32,
    /// Pieces that are halves of a long thin part's bands (`band_cell`; likewise).
    pub bands: u32,
    /// Triangles that ask for no cuts cut at edges they share with ones that do (the twin's
    /// count, for tests; 0 from the GPU).
    pub edge_splits: u32,
    /// The most piece or part records one `plan`, `plan_cuts` or `plan_parts` invocation
    /// appended (from a schedule's run; 0 from the twin's direct run), and the most nodes or
    /// triangles one work item of `lattice_nodes` or `lattice_triangles` wrote.
    pub max_pieces: u32,
    pub max_output: u32,
    /// The most nodes or candidate triangles one piece has, seam copies included (a measure of
    /// its own flipped re-triangulates it) ...
    pub max_piece_output: u32,
    /// ... and one part has, its pieces' and seam copies included:
    /// what a count flipped on one of its edges changes, the part planned again whole (the
    /// twin's, for the twin test's slack; 0 from the GPU).
    pub max_part_output: u32,
}

/// Indexed triangles as three vertices each.
pub fn expand(nodes: &[DrawVertex], indices: &[u32]) -> Vec<DrawVertex> {
    indices.iter().map(|&i| nodes[i as usize]).collect()
}

impl SubdivideOutput {
    /// An output from its nodes and indices (the GPU's read-back), with `vertices` expanded.
    pub fn indexed(
        nodes: Vec<DrawVertex>,
        indices: Vec<u32>,
        pieces: u32,
        max_sub_edge_px: f32,
        cuts: AxisCuts,
    ) -> Self {
        let vertices = expand(&nodes, &indices);
        SubdivideOutput { nodes, indices, vertices, pieces, max_sub_edge_px, cuts, ..Default::default() }
    }
}

/// The invocations each dispatch of `recording` ran, read from the counters after it (the
/// indirect ones: `plan_cuts` over the listed triangles, `lattice` over the pieces counted): the
/// balance of the subdivision's work, with `max_pieces` and `max_output`.
pub fn dispatched(
    recording: &Recording,
    params: &SubdivideParams,
    counters: &SubdivideCounters,
) -> Vec<(&'static str, u64)> {
    let listed = counters.cut_count as u64 + counters.cut_wide as u64;
    let pieces = counters.pieces.min(params.piece_capacity) as u64;
    recording
        .commands
        .iter()
        .filter_map(|c| match *c {
            Command::Dispatch { entry, invocations } => Some((entry, invocations as u64)),
            Command::DispatchIndirect { entry: "plan_cuts", .. } => {
                Some(("plan_cuts", PLAN_CUTS_SPLIT as u64 * listed))
            }
            Command::DispatchIndirect { entry: "plan_parts", .. } => {
                Some(("plan_parts", counters.parts.min(params.piece_capacity) as u64))
            }
            Command::DispatchIndirect { entry: "lattice_nodes", .. } => {
                Some(("lattice_nodes", counters.node_items.min(params.triangle_capacity) as u64))
            }
            Command::DispatchIndirect { entry: "lattice_rows", .. } => {
                Some(("lattice_rows", counters.row_items.min(3 * params.triangle_capacity) as u64))
            }
            Command::DispatchIndirect { entry: "lattice_rows_plan", .. } => {
                Some(("lattice_rows_plan", counters.pending.min(params.piece_capacity) as u64))
            }
            Command::DispatchIndirect { entry: "lattice_triangles", .. } => {
                Some(("lattice_triangles", counters.triangle_items.min(params.triangle_capacity) as u64))
            }
            Command::DispatchIndirect { entry, .. } => Some((entry, pieces)),
            _ => None,
        })
        .collect()
}

/// Byte offsets in `lattice_dispatch` of the indirect dispatches' workgroup counts: `lattice`
/// (written by `lattice_args`), `plan_cuts` (`plan_cuts_args`), `plan_parts` (`plan_parts_args`),
/// `lattice_nodes` and `lattice_triangles` (`lattice_work_args`), `lattice_rows` and
/// `lattice_rows_plan` (`lattice_rows_args`).
pub const DISPATCH_LATTICE: u64 = 0;
pub const DISPATCH_PLAN_CUTS: u64 = 12;
pub const DISPATCH_PLAN_PARTS: u64 = 24;
pub const DISPATCH_LATTICE_NODES: u64 = 36;
pub const DISPATCH_LATTICE_TRIANGLES: u64 = 48;
pub const DISPATCH_LATTICE_ROWS: u64 = 60;
pub const DISPATCH_LATTICE_ROWS_PLAN: u64 = 72;
/// Words of `lattice_dispatch`.
pub const DISPATCH_WORDS: usize = 21;

/// The most passes of the one-submission schedule ([`one_submission`]), each timed (where it is)
/// by a pair of timestamp queries: its begin at 2i, its end at 2i + 1.
pub const TIMED_PASSES: u32 = 10;

/// How the one-submission schedule's passes are timed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PassTiming {
    /// Three compute passes, none timed.
    Untimed,
    /// Three compute passes, each timed: `plan` (`active_cuts`, `ring_cuts`, `plan`),
    /// `plan_cuts` (with `plan_parts`), `lattice` (with the rows' and the work items' passes).
    Grouped,
    /// A timed compute pass for each main entry point (its setup pass with it, `finalize` with
    /// the last). Each pass boundary and pair of timestamps costs lavapipe ~0.3–0.5 ms, which
    /// weighs most on small frames.
    EachPass,
}

impl PassTiming {
    /// With timestamps (`timed`): each pass apart where `each_pass`, else the three groups.
    pub fn of(timed: bool, each_pass: bool) -> PassTiming {
        match (timed, each_pass) {
            (false, _) => PassTiming::Untimed,
            (true, false) => PassTiming::Grouped,
            (true, true) => PassTiming::EachPass,
        }
    }
}

/// The three groups `Grouped` times the passes in, in schedule order.
pub const PASS_GROUPS: [&str; 3] = ["plan", "plan_cuts", "lattice"];

/// The group of `PASS_GROUPS` a main entry point's pass falls in (a group's own name gives it).
pub fn pass_group(entry: &str) -> &'static str {
    match entry {
        "active_cuts" | "ring_cuts" | "plan" => PASS_GROUPS[0],
        "plan_cuts" | "plan_parts" => PASS_GROUPS[1],
        _ => PASS_GROUPS[2],
    }
}

/// Starts a compute pass before `entry` where `timing` has one there: every main entry point's
/// under `EachPass`, else where its group (the pass's name) differs from the current pass's;
/// timed at the next pair of queries unless `Untimed`.
fn pass(r: &mut Recording, entry: &'static str, timing: PassTiming) {
    let label = if timing == PassTiming::EachPass { entry } else { pass_group(entry) };
    let current = r.commands.iter().rev().find_map(|c| match *c {
        Command::Pass { label, .. } => Some(label),
        _ => None,
    });
    if current != Some(label) {
        let index = 2 * timed_passes(r).len() as u32;
        r.pass(label, (timing != PassTiming::Untimed).then_some(index));
    }
}

/// The timed passes of a recording, in order: (label, the index of its begin query; its end's
/// is the next).
pub fn timed_passes(r: &Recording) -> Vec<(&'static str, u32)> {
    r.commands
        .iter()
        .filter_map(|c| match *c {
            Command::Pass { label, timestamp: Some(index) } => Some((label, index)),
            _ => None,
        })
        .collect()
}

/// The usual frame's schedule, in one submission over `triangles` input triangles: the counters
/// and the edge marks cleared; `active_cuts`, `ring_cuts` and `plan` over every triangle;
/// `plan_cuts_args`, then `plan_cuts` over the triangles `plan` listed, `plan_parts_args`, then
/// `plan_parts` over the parts it cut; `lattice_args`, then `lattice` over the pieces counted on
/// the GPU, the rows' passes where the frame has them, `lattice_work_args`, then `lattice_nodes`
/// and `lattice_triangles` over the work items `lattice` appended, and `finalize` (the draw's
/// arguments). In compute passes as `timing` says.
pub fn one_submission(triangles: u32, passes: Passes, timing: PassTiming) -> Recording {
    let mut r = Recording::default();
    r.clear(SubdivideBuffer::Counters, None).clear(SubdivideBuffer::CutEdges, None);
    for entry in ["active_cuts", "ring_cuts", "plan"] {
        pass(&mut r, entry, timing);
        r.dispatch(entry, triangles);
    }
    cut_and_plan_parts(&mut r, timing);
    pass(&mut r, "lattice", timing);
    r.dispatch("lattice_args", 1).dispatch_indirect("lattice", SubdivideBuffer::LatticeDispatch, DISPATCH_LATTICE);
    lattice_work(&mut r, passes, timing);
    r.dispatch("finalize", 1);
    debug_assert!(timed_passes(&r).len() as u32 <= TIMED_PASSES);
    r
}

/// `plan_cuts` over the triangles `plan` listed, then `plan_parts` over the parts it cut (each
/// after its one-thread setup pass): a quadrant near a pole or beside a floor has many bands,
/// which one invocation planned in turn made the frame's longest threads.
fn cut_and_plan_parts(r: &mut Recording, timing: PassTiming) {
    pass(r, "plan_cuts", timing);
    r.dispatch("plan_cuts_args", 1).dispatch_indirect(
        "plan_cuts",
        SubdivideBuffer::LatticeDispatch,
        DISPATCH_PLAN_CUTS,
    );
    pass(r, "plan_parts", timing);
    r.dispatch("plan_parts_args", 1).dispatch_indirect(
        "plan_parts",
        SubdivideBuffer::LatticeDispatch,
        DISPATCH_PLAN_PARTS,
    );
}

/// The passes a frame's schedules dispatch besides those every frame has.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Passes {
    /// `lattice_rows` and `lattice_rows_plan`: pieces may be drawn in rows (the sphere, under an
    /// adaptive rule).
    pub rows: bool,
}

impl Passes {
    /// A frame's: its panorama and its split rule (`SubdivideParams::method`).
    pub fn of(panorama: PanoramaKind, method: u32) -> Passes {
        Passes { rows: panorama.is_sphere() && SplitRule::is_adaptive(method) }
    }

    /// The passes of a frame drawn with `settings`.
    pub fn of_settings(settings: &RenderSettings) -> Passes {
        Passes::of(settings.projection().panorama, settings.subdivision.method.split_rule().0 as u32)
    }
}

/// What follows `lattice`: where pieces may be drawn in rows, `lattice_rows` over the bands it
/// listed and `lattice_rows_plan`; then its work items, `lattice_nodes`, then `lattice_triangles`
/// (which reads the nodes), each after the setup pass that counts them.
fn lattice_work(r: &mut Recording, passes: Passes, timing: PassTiming) {
    if passes.rows {
        pass(r, "lattice_rows", timing);
        r.dispatch("lattice_rows_args", 1);
        r.dispatch_indirect("lattice_rows", SubdivideBuffer::LatticeDispatch, DISPATCH_LATTICE_ROWS);
        pass(r, "lattice_rows_plan", timing);
        r.dispatch_indirect("lattice_rows_plan", SubdivideBuffer::LatticeDispatch, DISPATCH_LATTICE_ROWS_PLAN);
    }
    pass(r, "lattice_nodes", timing);
    r.dispatch("lattice_work_args", 1);
    r.dispatch_indirect("lattice_nodes", SubdivideBuffer::LatticeDispatch, DISPATCH_LATTICE_NODES);
    pass(r, "lattice_triangles", timing);
    r.dispatch_indirect("lattice_triangles", SubdivideBuffer::LatticeDispatch, DISPATCH_LATTICE_TRIANGLES);
}

/// The passes that cut triangles around the axis: `plan_cuts`, and `plan_parts` after it. They
/// are the largest pipelines to build, and many frames never run them (a room on the cylinder
/// whose floor and ceiling stay beyond the image's rows): the GPU builds them when a frame first
/// lists a triangle for them (`plan`'s counters, [`cut_probe`]).
pub const CUT_PASSES: [&str; 2] = ["plan_cuts", "plan_parts"];

/// What tells whether a frame needs [`CUT_PASSES`]: the start of [`one_submission`] up to
/// `plan` (its counters' `cut_count` and `cut_wide`).
pub fn cut_probe(triangles: u32) -> Recording {
    let mut r = active_cuts(triangles);
    r.dispatch("plan", triangles);
    r
}

/// The entry points of `recording` that had work after a run with these counters (see
/// [`dispatched`]) but are not `built`: a run that left them out must run again.
pub fn missed(
    recording: &Recording,
    params: &SubdivideParams,
    counters: &SubdivideCounters,
    built: impl Fn(&str) -> bool,
) -> Vec<&'static str> {
    let mut missed: Vec<&'static str> = dispatched(recording, params, counters)
        .into_iter()
        .filter(|&(entry, n)| n > 0 && !built(entry))
        .map(|(entry, _)| entry)
        .collect();
    missed.dedup();
    missed
}

/// The start of a chunked schedule: the counters and the edge marks cleared, then
/// `active_cuts` and `ring_cuts` over all of the scene's `triangles`.
pub fn active_cuts(triangles: u32) -> Recording {
    let mut r = Recording::default();
    r.clear(SubdivideBuffer::Counters, None).clear(SubdivideBuffer::CutEdges, None);
    r.pass("cuts", None).dispatch("active_cuts", triangles).dispatch("ring_cuts", triangles);
    r
}

/// One step of a chunked schedule: `entry` (`plan`, with `plan_cuts` and `plan_parts` after it,
/// or `lattice`, with its work items' passes) over `count` invocations, then `finalize`; the counters of this run cleared first (the
/// frame's cuts kept).
pub fn pass_run(entry: &'static str, count: u32, passes: Passes) -> Recording {
    let mut r = Recording::default();
    r.clear(SubdivideBuffer::Counters, Some(SubdivideCounters::RUN_BYTES));
    r.pass(entry, None).dispatch(entry, count);
    if entry == "plan" {
        cut_and_plan_parts(&mut r, PassTiming::Untimed);
    } else {
        lattice_work(&mut r, passes, PassTiming::Untimed);
    }
    r.dispatch("finalize", 1);
    r
}
