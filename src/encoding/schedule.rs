//! The subdivision's frame schedules, run by an engine: the GPU's (`gpu::subdivide`,
//! `gpu::subdivided`) or the CPU twin's (`cpu::subdivide::passes`), so that both run the same
//! sequence of recordings ([`crate::encoding::subdivide`]'s `one_submission`, `active_cuts`
//! and `pass_run`) with the same parameters and capacities.
//!
//! Memory: the piece and output buffers (nodes and triangle indices) together stay within
//! `memory_mb` (and each within the device's storage-binding limit). Both passes count what they
//! wanted to write and never write past the end. The usual frame is [`FramePlan::OneSubmission`]:
//! `plan` → `lattice` (sized on the GPU from the piece counter) → `finalize` → both eyes, then
//! one read of the counters. When that overflowed a buffer, the frame is redone
//! [`FramePlan::Chunked`] ([`run_chunked`]): a `plan` over a range of triangles that overflows
//! grows the piece buffer if the budget allows, else the range is halved; likewise a `lattice`
//! over a range of pieces and the output buffer. Each range's output is taken in turn (drawn
//! into the same targets, `chunks` in the stats; or read back), so nothing is dropped; a single
//! piece that cannot fit is an error.

use crate::core::settings::RenderSettings;
use crate::encoding::constants::PIECES_FROM_COUNTER;
use crate::encoding::recording::Recording;
use crate::encoding::subdivide::{
    active_cuts, dispatched, one_submission, pass_run, subdivide_params, AxisCuts, PassTiming, Passes, SubdivideOutput,
};
use crate::encoding::types::{DrawVertex, Piece, StoredWork, SubdivideCounters, SubdivideParams};
use crate::error::{Error, Result};

/// Bytes of one piece record (`pieces`) or part record (`parts`).
pub const RECORD_SIZE: u64 = std::mem::size_of::<Piece>() as u64;
/// Bytes of one unit of piece capacity: its record, room for a part record (`parts` holds as
/// many as `pieces`) and its work (`piece_work`).
pub const PIECE_SIZE: u64 = 2 * RECORD_SIZE + WORK_SIZE;
/// Bytes of a piece's work (`piece_work`).
pub const WORK_SIZE: u64 = std::mem::size_of::<StoredWork>() as u64;
/// Bytes of one work item (`lattice_work`: room for one per output unit).
pub const ITEM_SIZE: u64 = 16;
/// Bytes of one output node.
pub const NODE_SIZE: u64 = std::mem::size_of::<DrawVertex>() as u64;
/// Bytes of one output triangle's indices.
pub const INDICES_SIZE: u64 = 3 * 4;
/// Bytes of one unit of output capacity: room for a node, for a triangle's indices (the
/// lattices make about one node per output triangle or fewer: (m + 1)(m + 2)/2 for m²) and for
/// a work item (a piece has fewer than its nodes).
pub const OUTPUT_UNIT_SIZE: u64 = NODE_SIZE + INDICES_SIZE + ITEM_SIZE;

/// Capacities of the piece and output buffers: pieces, and output units (each a node and a
/// triangle's indices; `triangles` also caps the nodes).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Capacities {
    pub pieces: u32,
    pub triangles: u32,
}

impl Capacities {
    /// What a memory budget allows: a quarter for pieces, the rest for the output (nodes and
    /// indices), each buffer within the largest binding.
    pub fn budget(memory_mb: u32, max_binding: u64) -> Capacities {
        let budget = memory_mb as u64 * (1 << 20);
        let pieces = (budget / 4 / PIECE_SIZE).min(max_binding / WORK_SIZE.max(RECORD_SIZE));
        let triangles = ((budget - budget / 4) / OUTPUT_UNIT_SIZE).min(max_binding / NODE_SIZE);
        Capacities { pieces: pieces.min(u32::MAX as u64) as u32, triangles: triangles.min(u32::MAX as u64) as u32 }
    }

    pub fn min(self, other: Capacities) -> Capacities {
        Capacities { pieces: self.pieces.min(other.pieces), triangles: self.triangles.min(other.triangles) }
    }

    /// A first guess for a scene of `triangles` input triangles (a triangle is a piece or more:
    /// the cuts around the axis make a few parts of some, the pre-split pieces of large ones).
    pub fn guess(triangles: u32) -> Capacities {
        Capacities {
            pieces: triangles.saturating_mul(2).saturating_add(4096),
            triangles: triangles.saturating_mul(4).saturating_add(4096),
        }
    }
}

/// How a frame runs on the GPU.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FramePlan {
    /// Everything in one submission, with these capacities (within the budget).
    OneSubmission(Capacities, Capacities),
    /// Triangle ranges and piece ranges, each drawn in turn, starting from the capacities
    /// wanted and growing within the budget.
    Chunked { want: Capacities, budget: Capacities },
}

impl FramePlan {
    /// The usual plan: one submission with the cached buffers' capacities (or a guess from the
    /// triangle count), never beyond the budget.
    pub fn first(triangles: u32, cached: Option<Capacities>, budget: Capacities) -> FramePlan {
        FramePlan::OneSubmission(cached.unwrap_or(Capacities::guess(triangles)).min(budget), budget)
    }

    /// The plan after a one-submission frame overflowed its buffers.
    pub fn after_overflow(self, budget: Capacities) -> FramePlan {
        match self {
            FramePlan::OneSubmission(want, _) | FramePlan::Chunked { want, .. } => FramePlan::Chunked { want, budget },
        }
    }

    /// The memory budget the plan stays within.
    pub fn budget(self) -> Capacities {
        match self {
            FramePlan::OneSubmission(_, budget) | FramePlan::Chunked { budget, .. } => budget,
        }
    }
}

/// What to do when a pass wanted `requested` slots of a buffer holding at most `max` within the
/// budget, after running over `count` items.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Overflow {
    /// Grow the buffer to `requested` and run the same range again.
    Grow(u32),
    /// Run half the range.
    Halve(u32),
    /// A single item does not fit.
    TooBig,
}

pub fn on_overflow(requested: u32, max: u32, count: u32) -> Overflow {
    if requested <= max {
        Overflow::Grow(requested)
    } else if count > 1 {
        Overflow::Halve(count / 2)
    } else {
        Overflow::TooBig
    }
}

/// Which schedule a run follows.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Schedule {
    /// The usual frame's: everything in one submission, indirect dispatches sized from the
    /// counters ([`one_submission`]); the buffers grown and the whole run again on overflow.
    OneSubmission,
    /// The chunked frame's ([`run_chunked`]): `plan` over ranges of this many triangles,
    /// `lattice` over ranges of their pieces, the counters read between.
    Chunked { triangles_per_chunk: u32 },
}

/// What runs the subdivision's recordings: the GPU, or the CPU twin's passes.
pub trait SubdivisionEngine {
    /// Makes the piece and output buffers hold at least `want`; the capacities they have.
    fn ensure(&mut self, want: Capacities) -> Capacities;
    /// Replays `recording` with `params` as the stage's uniform; the counters after it.
    fn replay(&mut self, recording: &Recording, params: &SubdivideParams) -> Result<SubdivideCounters>;
    /// Takes the output of a finished run (`counters` says how much): draws it, reads it back
    /// or keeps it.
    fn take(&mut self, counters: &SubdivideCounters) -> Result<()>;
    /// The usual frame's run: replays `recording` and, where no buffer overflowed, takes its
    /// output; the counters. The GPU does both in one submission (drawing before it reads the
    /// counters back, and drawing again by chunks where they say a buffer overflowed).
    fn replay_and_take(&mut self, recording: &Recording, params: &SubdivideParams) -> Result<SubdivideCounters> {
        let counters = self.replay(recording, params)?;
        if !counters.overflowed(params.piece_capacity, params.triangle_capacity) {
            self.take(&counters)?;
        }
        Ok(counters)
    }
}

/// What a run made, over all its ranges.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct RunTotals {
    pub pieces: u64,
    pub triangles: u64,
    pub nodes: u64,
    /// Output ranges taken (1 for one submission).
    pub chunks: u32,
    /// Largest projected length of a visible output edge, pixels (when measured).
    pub max_edge_px: f32,
    /// The cuts around the axis the frame made.
    pub cuts: AxisCuts,
    /// Invocations per entry point, in the order first dispatched, over the run's replays (a
    /// chunked run's ranges redone after an overflow included: work done).
    pub invocations: Vec<(&'static str, u64)>,
    /// The most piece records one `plan` or `plan_cuts` invocation appended, and the most nodes
    /// or triangles one `lattice` invocation wrote.
    pub max_pieces: u32,
    pub max_output: u32,
}

impl RunTotals {
    /// A finished range's output.
    fn add(&mut self, done: &SubdivideCounters) {
        self.triangles += done.triangles as u64;
        self.nodes += done.nodes as u64;
        self.chunks += 1;
        self.max_edge_px = self.max_edge_px.max(f32::from_bits(done.max_edge_bits));
        self.cuts = done.cuts();
    }

    /// The work of one replay: its invocations and its largest outputs of one invocation.
    pub fn count(&mut self, recording: &Recording, params: &SubdivideParams, after: &SubdivideCounters) {
        for (entry, n) in dispatched(recording, params, after) {
            match self.invocations.iter_mut().find(|(e, _)| *e == entry) {
                Some((_, total)) => *total += n,
                None => self.invocations.push((entry, n)),
            }
        }
        self.max_pieces = self.max_pieces.max(after.max_pieces);
        self.max_output = self.max_output.max(after.max_output);
    }

    /// The output of a read-back run: its nodes and indices, with these totals.
    pub fn output(&self, nodes: Vec<DrawVertex>, indices: Vec<u32>) -> SubdivideOutput {
        let mut out = SubdivideOutput::indexed(nodes, indices, self.pieces as u32, self.max_edge_px, self.cuts);
        (out.max_pieces, out.max_output) = (self.max_pieces, self.max_output);
        out
    }
}

/// Replays `recording` and counts its work into `totals`.
fn replay_counted<E: SubdivisionEngine>(
    engine: &mut E,
    recording: &Recording,
    params: &SubdivideParams,
    totals: &mut RunTotals,
) -> Result<SubdivideCounters> {
    let counters = engine.replay(recording, params)?;
    totals.count(recording, params, &counters);
    Ok(counters)
}

/// Runs `schedule` over the scene's `triangles` to the end, within `budget`, by the usual
/// frame's policy ([`FramePlan`], which the GPU's frames follow too): one submission with the
/// first capacities; where a buffer overflows, chunks from there (grown within the budget, or
/// halved). `Chunked` starts with chunks of the given size.
pub fn run_schedule<E: SubdivisionEngine>(
    engine: &mut E,
    settings: &RenderSettings,
    triangles: u32,
    schedule: Schedule,
    budget: Capacities,
) -> Result<RunTotals> {
    let first = FramePlan::first(triangles, None, budget);
    let (plan, chunk) = match schedule {
        Schedule::OneSubmission => (first, triangles.max(1)),
        Schedule::Chunked { triangles_per_chunk } => (first.after_overflow(budget), triangles_per_chunk.max(1)),
    };
    run_plan(engine, settings, triangles, plan, chunk)
}

/// Runs a frame's subdivision by `plan` to the end: the one overflow policy, which the GPU's
/// frames (`gpu::subdivided`), the GPU's read-back and the CPU twin all follow. One submission
/// with the plan's capacities; where a buffer overflows, chunks from there (grown within the
/// budget, or halved), the first of at most `chunk` triangles.
pub fn run_plan<E: SubdivisionEngine>(
    engine: &mut E,
    settings: &RenderSettings,
    triangles: u32,
    mut plan: FramePlan,
    chunk: u32,
) -> Result<RunTotals> {
    let budget = plan.budget();
    if let FramePlan::OneSubmission(want, _) = plan {
        let capacity = engine.ensure(want).min(budget);
        match run_one_submission(engine, settings, triangles, capacity)? {
            Ok(totals) => return Ok(totals),
            Err(_) => plan = plan.after_overflow(budget),
        }
    }
    let FramePlan::Chunked { mut want, budget } = plan else { unreachable!("a one-submission run returned") };
    run_chunked(engine, settings, triangles, &mut want, budget, chunk.max(1))
}

/// The one-submission schedule with these capacities: the totals, or (when a buffer overflowed,
/// nothing taken) the capacities it wanted.
pub fn run_one_submission<E: SubdivisionEngine>(
    engine: &mut E,
    settings: &RenderSettings,
    triangles: u32,
    capacity: Capacities,
) -> Result<std::result::Result<RunTotals, Capacities>> {
    let mut params = subdivide_params(settings, 0, triangles);
    (params.piece_capacity, params.triangle_capacity) = (capacity.pieces, capacity.triangles);
    (params.first_piece, params.piece_count) = (0, PIECES_FROM_COUNTER);
    let recording = one_submission(triangles, Passes::of_settings(settings), PassTiming::Untimed);
    let mut totals = RunTotals::default();
    let counters = engine.replay_and_take(&recording, &params)?;
    totals.count(&recording, &params, &counters);
    if counters.overflowed(capacity.pieces, capacity.triangles) {
        let wanted = Capacities {
            pieces: capacity.pieces.max(counters.piece_records()),
            triangles: capacity.triangles.max(counters.output_units()),
        };
        return Ok(Err(wanted));
    }
    totals.pieces = counters.pieces as u64;
    totals.add(&counters);
    Ok(Ok(totals))
}

/// The chunked schedule (see the module doc): `active_cuts` over the whole scene, then `plan`
/// over ranges of at most `chunk` triangles, each followed by `lattice` over ranges of its
/// pieces, each range's output taken; at least one range is taken (an empty scene's clears the
/// targets). `want` is what the buffers should hold, grown within `budget`.
pub fn run_chunked<E: SubdivisionEngine>(
    engine: &mut E,
    settings: &RenderSettings,
    triangles: u32,
    want: &mut Capacities,
    budget: Capacities,
    chunk: u32,
) -> Result<RunTotals> {
    let n = triangles;
    let mut totals = RunTotals::default();
    engine.ensure(*want);
    replay_counted(engine, &active_cuts(n), &subdivide_params(settings, 0, n), &mut totals)?;
    let (mut first, mut chunk) = (0u32, chunk.max(1));
    while first < n || totals.chunks == 0 {
        let count = chunk.min(n - first);
        let capacity = engine.ensure(*want);
        let mut params = subdivide_params(settings, first, count);
        params.piece_capacity = capacity.pieces.min(budget.pieces);
        params.triangle_capacity = capacity.triangles;
        let planned =
            replay_counted(engine, &pass_run("plan", count, Passes::of_settings(settings)), &params, &mut totals)?;
        if planned.piece_records() > params.piece_capacity {
            match on_overflow(planned.piece_records(), budget.pieces, count) {
                Overflow::Grow(p) => want.pieces = p,
                Overflow::Halve(c) => chunk = c,
                Overflow::TooBig => {
                    let why = format!(
                        "one triangle needs {} pieces; raise the edge length L or the memory budget",
                        planned.piece_records()
                    );
                    return Err(too_small(settings, why));
                }
            }
            continue;
        }
        totals.pieces += planned.pieces as u64;
        lattice_ranges(engine, settings, &mut params, planned.pieces, (want, budget), &mut totals)?;
        first += count;
    }
    Ok(totals)
}

/// The lattices of a range's `pieces` planned pieces, in ranges whose output fits (the buffer
/// grown within the budget, else the range halved), each range's output taken.
fn lattice_ranges<E: SubdivisionEngine>(
    engine: &mut E,
    settings: &RenderSettings,
    params: &mut SubdivideParams,
    pieces: u32,
    (want, budget): (&mut Capacities, Capacities),
    totals: &mut RunTotals,
) -> Result<()> {
    let (mut first, mut chunk, mut taken) = (0u32, pieces.max(1), false);
    while first < pieces || !taken {
        let count = chunk.min(pieces - first);
        let capacity = engine.ensure(*want);
        (params.first_piece, params.piece_count) = (first, count);
        params.triangle_capacity = capacity.triangles.min(budget.triangles);
        let done = replay_counted(engine, &pass_run("lattice", count, Passes::of_settings(settings)), params, totals)?;
        if done.output_units() > params.triangle_capacity {
            match on_overflow(done.output_units(), budget.triangles, count) {
                Overflow::Grow(t) => want.triangles = t,
                Overflow::Halve(c) => chunk = c,
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
        engine.take(&done)?;
        totals.add(&done);
        taken = true;
        first += count;
    }
    Ok(())
}

/// The memory budget cannot hold what one triangle or piece makes.
fn too_small(settings: &RenderSettings, why: String) -> Error {
    let memory_mb = settings.subdivision.memory_mb;
    Error::setting("subdivision.memory_mb", format!("{memory_mb} is too small: {why}"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn overflow_grows_within_the_budget_else_halves_else_fails() {
        assert_eq!(on_overflow(100, 200, 50), Overflow::Grow(100));
        assert_eq!(on_overflow(300, 200, 50), Overflow::Halve(25));
        assert_eq!(on_overflow(300, 200, 1), Overflow::TooBig);
    }

    #[test]
    fn the_first_plan_never_exceeds_the_budget() {
        let budget = Capacities::budget(8, u64::MAX);
        assert_eq!(budget.pieces as u64, 2 * (1 << 20) / PIECE_SIZE);
        match FramePlan::first(10_000_000, None, budget) {
            FramePlan::OneSubmission(c, b) => assert_eq!((c, b), (budget, budget)),
            other => panic!("{other:?}"),
        }
        let small = Capacities { pieces: 10, triangles: 20 };
        assert_eq!(FramePlan::first(5, Some(small), budget), FramePlan::OneSubmission(small, budget));
        assert_eq!(
            FramePlan::OneSubmission(small, budget).after_overflow(budget),
            FramePlan::Chunked { want: small, budget }
        );
    }
}
