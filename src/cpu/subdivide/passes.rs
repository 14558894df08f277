//! The `subdivide` stage's passes on the CPU: the twin of its pass files
//! `shaders/subdivide/*.wgsl`, one method each of the same name, over buffers named as the WGSL binds them
//! (`counters`, `cut_edges`, `cut_list`, `pieces`, `parts`, `out_nodes`, `out_indices`,
//! `lattice_dispatch`, `draw_args`), run by replaying the same recordings as the GPU: an engine
//! of `encoding::schedule`, so that the twin test runs the GPU's schedules (one submission with
//! its indirect dispatches, and the chunked one) on both sides. The work inside each pass is the
//! twin's (`Subdivider`): the passes only decide, as the WGSL does, which invocation plans which
//! triangle, lists which for `plan_cuts`, and where records and output land.
//!
//! Invocations run one after another in index order, so the output's order differs from the
//! GPU's (whose appends race); both are compared as sets.

use std::collections::HashMap;
use std::rc::Rc;

use glam::Vec3;

use super::{
    band_limit, chunk_of, edge_split_parts, fan, one_part, quadrant_polygons, triangle_cuts, FrameCuts, Node,
    PartSplit, PieceGeometry, PiecePlan, SubdivideOutput, Subdivider, Triangle,
};
use crate::core::scenes::scene::SceneVertex;
use crate::core::settings::RenderSettings;
use crate::encoding::constants::{BANDS, PIECES_FROM_COUNTER, PLAN_CUTS_SPLIT};
use crate::encoding::recording::{Command, Recording, SubdivideBuffer};
use crate::encoding::schedule::{
    run_plan, run_schedule, Capacities, FramePlan, RunTotals, Schedule, SubdivisionEngine,
};
use crate::encoding::subdivide::{
    DISPATCH_LATTICE, DISPATCH_LATTICE_NODES, DISPATCH_LATTICE_ROWS, DISPATCH_LATTICE_ROWS_PLAN,
    DISPATCH_LATTICE_TRIANGLES, DISPATCH_PLAN_CUTS, DISPATCH_PLAN_PARTS, DISPATCH_WORDS,
};
use crate::encoding::types::{DrawIndexedIndirectArgs, DrawVertex, Piece, SubdivideCounters, SubdivideParams};
use crate::error::Result;

/// Runs the whole stage on the CPU with `schedule` within `budget`, as the GPU's read-back
/// does (`gpu::subdivide::SubdivideStage::readback`), each object's L scaled by `edge_scale` (the
/// level of detail's; empty: 1): the twin side of the twin test.
pub fn run_scheduled(
    settings: &RenderSettings,
    vertices: &[SceneVertex],
    indices: &[u32],
    edge_scale: &[f32],
    schedule: Schedule,
    budget: Capacities,
) -> Result<SubdivideOutput> {
    let mut engine = CpuSubdivision::new(vertices, indices, edge_scale);
    let totals = run_schedule(&mut engine, settings, (indices.len() / 3) as u32, schedule, budget)?;
    let max_part_output = engine.part_output.values().copied().max().unwrap_or(0);
    let max_piece_output = engine.max_piece_output;
    Ok(SubdivideOutput { max_piece_output, max_part_output, ..totals.output(engine.nodes, engine.taken_indices) })
}

/// Runs the whole stage on the CPU by a frame's `plan` (a recorded frame's subdivision step,
/// `encoding::frame`), the first chunk of at most `chunk` triangles where it goes by chunks:
/// every range's output, and the run's totals.
pub fn run_planned(
    settings: &RenderSettings,
    vertices: &[SceneVertex],
    indices: &[u32],
    plan: FramePlan,
    chunk: u32,
) -> Result<(SubdivideOutput, RunTotals)> {
    let mut engine = CpuSubdivision::new(vertices, indices, &[]);
    let totals = run_plan(&mut engine, settings, (indices.len() / 3) as u32, plan, chunk)?;
    Ok((totals.output(engine.nodes, engine.taken_indices), totals))
}

/// The stage's buffers on the CPU, and what [`SubdivisionEngine::take`] kept.
pub struct CpuSubdivision<'s> {
    /// The scene's `vertices` and `indices`.
    scene: (&'s [SceneVertex], &'s [u32]),
    /// `object_edge_scale`.
    edge_scale: &'s [f32],
    /// `cut_edges`, with the scene's shared edges (`triangle_edges`).
    frame: FrameCuts,
    counters: SubdivideCounters,
    /// Room for every triangle of the scene.
    cut_list: Vec<u32>,
    pieces: Vec<Piece>,
    /// The parts `plan_cuts` cut, for `plan_parts` (room for as many as `pieces`).
    parts: Vec<Piece>,
    out_nodes: Vec<DrawVertex>,
    out_indices: Vec<u32>,
    /// What `lattice` planned for each piece, by the piece's index: its first output node and
    /// its plan (`piece_work`).
    piece_work: HashMap<u32, Rc<(u32, PiecePlan)>>,
    /// The pieces whose rows `lattice_rows` measures, by index: their triangle, placement and
    /// each band's measures so far.
    pending_rows: HashMap<u32, PendingRows>,
    /// The bands of pieces whose rows `lattice_rows` measures: (piece << 5) | band (the GPU's
    /// share `out_indices`' room, 3 per output unit).
    row_items: Vec<u32>,
    /// `lattice`'s work items: [piece, first slot or candidate, 0, 0] (the twin needs no walk).
    lattice_work: Vec<[u32; 4]>,
    /// Each part's nodes or candidate triangles (seam copies included), by its record's bits:
    /// the most a part's output changes when one of its edges' counts flips (it is planned
    /// again whole; the twin test's slack).
    part_output: HashMap<Vec<u32>, u32>,
    /// The most one piece has (a flipped measure of its own re-triangulates it).
    max_piece_output: u32,
    lattice_dispatch: [u32; DISPATCH_WORDS],
    pub draw_args: DrawIndexedIndirectArgs,
    /// Every taken range's nodes, and its triangles' indices into them.
    pub nodes: Vec<DrawVertex>,
    pub taken_indices: Vec<u32>,
}

/// A piece whose rows `lattice_rows` measures: its triangle, its placement, each band's measures.
type PendingRows = (Triangle, PieceGeometry, Vec<(u32, u32)>);

/// A part's corner from a piece record.
/// Where row item `i` lies in its room (`row_item_slot` in the WGSL): from the back, as on the
/// GPU, where the room is the output's index buffer, filled from the front by the triangles of
/// pieces written in place.
fn row_item_slot(params: &SubdivideParams, i: u32) -> usize {
    (3 * params.triangle_capacity - 1 - i) as usize
}

fn record_corner(piece: &Piece, i: usize) -> Node {
    let c = piece.corner[i];
    Node { position: Vec3::new(c[0], c[1], c[2]), bary: Vec3::new(c[3], piece.bary1[i], piece.bary2[i]) }
}

/// A piece record of triangle t with these corners (`append_pieces` in the WGSL).
fn record(t: u32, counts01: u32, count2_level: u32, corners: [Node; 3]) -> Piece {
    let mut piece = Piece { triangle: t, counts01, count2_level, ..Default::default() };
    for (i, n) in corners.iter().enumerate() {
        piece.corner[i] = n.position.extend(n.bary.x).into();
        piece.bary1[i] = n.bary.y;
        piece.bary2[i] = n.bary.z;
    }
    piece
}

impl<'s> CpuSubdivision<'s> {
    pub fn new(vertices: &'s [SceneVertex], indices: &'s [u32], edge_scale: &'s [f32]) -> Self {
        let frame = FrameCuts::unmarked(vertices, indices);
        CpuSubdivision {
            scene: (vertices, indices),
            edge_scale,
            frame,
            counters: SubdivideCounters::default(),
            cut_list: vec![0; (indices.len() / 3).max(1)],
            pieces: vec![Piece::default(); 1],
            parts: vec![Piece::default(); 1],
            out_nodes: vec![DrawVertex::default(); 1],
            out_indices: vec![0; 3],
            piece_work: HashMap::new(),
            pending_rows: HashMap::new(),
            row_items: vec![0; 3],
            lattice_work: vec![[0; 4]; 1],
            part_output: HashMap::new(),
            max_piece_output: 0,
            lattice_dispatch: [0; DISPATCH_WORDS],
            draw_args: DrawIndexedIndirectArgs::default(),
            nodes: Vec::new(),
            taken_indices: Vec::new(),
        }
    }

    fn clear(&mut self, buffer: SubdivideBuffer, bytes: Option<u64>) {
        match buffer {
            // The first `bytes` of the counters, as the GPU's clear does.
            SubdivideBuffer::Counters => {
                let all = bytemuck::bytes_of_mut(&mut self.counters);
                let n = bytes.map_or(all.len(), |n| (n as usize).min(all.len()));
                all[..n].fill(0);
            }
            SubdivideBuffer::CutEdges => self.frame.clear_marks(),
            other => unreachable!("the subdivide twin keeps no {other:?} to clear (its recordings clear none)"),
        }
    }

    /// Runs `entry` over `invocations` (whole workgroups of 64; each invocation past its pass's
    /// count returns at once, as on the GPU) or, for a one-thread setup entry, once.
    fn dispatch(&mut self, sub: &Subdivider, entry: &str, invocations: u32) {
        let all = 0..invocations.div_ceil(64) * 64;
        match entry {
            "active_cuts" => all.for_each(|i| self.active_cuts(sub, i)),
            "ring_cuts" => all.for_each(|i| self.ring_cuts(sub, i)),
            "plan" => all.for_each(|i| self.plan(sub, i)),
            "plan_cuts_args" => self.plan_cuts_args(),
            "plan_cuts" => all.for_each(|i| self.plan_cuts(sub, i)),
            "plan_parts_args" => self.plan_parts_args(sub),
            "plan_parts" => all.for_each(|i| self.plan_parts(sub, i)),
            "lattice_args" => self.lattice_args(sub),
            "lattice" => all.for_each(|i| self.lattice(sub, i)),
            "lattice_rows_args" => self.lattice_rows_args(sub),
            "lattice_rows" => all.for_each(|i| self.lattice_rows(sub, i)),
            "lattice_rows_plan" => all.for_each(|i| self.lattice_rows_plan(sub, i)),
            "lattice_work_args" => self.lattice_work_args(sub),
            "lattice_nodes" => all.for_each(|i| self.lattice_nodes(sub, i)),
            "lattice_triangles" => all.for_each(|i| self.lattice_triangles(sub, i)),
            "finalize" => self.finalize(sub),
            other => panic!("the subdivide stage has no entry point {other}"),
        }
    }

    /// An indirect dispatch's workgroup counts at byte `offset` of `lattice_dispatch`, for
    /// `invocations` in workgroups of 64 spread over two dimensions (`set_dispatch`).
    fn set_dispatch(&mut self, offset: u64, invocations: u32) {
        let groups = invocations.div_ceil(64);
        let at = offset as usize / 4;
        self.lattice_dispatch[at..at + 3].copy_from_slice(&[groups.min(65535), groups.div_ceil(65535), 1]);
    }

    // ---- the entry points ----

    /// Over every triangle of the scene: the cuts it asks for, OR-ed into the counters; its
    /// edges marked if it asks.
    fn active_cuts(&mut self, sub: &Subdivider, local: u32) {
        let params = sub.params;
        if local >= params.triangle_count {
            return;
        }
        let t = (params.first_triangle + local) as usize;
        let p = sub.positions(self.scene.0, self.scene.1, t);
        if sub.off_screen_vertically(p) {
            return;
        }
        let bits = triangle_cuts(p, params.axis_clearance, band_limit(params.method, &sub.projection));
        self.counters.cuts_low |= bits as u32;
        self.counters.cuts_high |= (bits >> 32) as u32;
        if bits != 0 {
            self.frame.mark(t, true);
        }
    }

    /// After `active_cuts`: a triangle with an edge of one that asks is cut too; its edges
    /// are marked as a cut one's.
    fn ring_cuts(&mut self, sub: &Subdivider, local: u32) {
        let params = sub.params;
        if local >= params.triangle_count {
            return;
        }
        let t = (params.first_triangle + local) as usize;
        if !self.frame.is_cut_triangle(t) || sub.off_screen_vertically(sub.positions(self.scene.0, self.scene.1, t)) {
            return;
        }
        self.frame.mark(t, false);
    }

    /// Plans a triangle that is its own single part; lists the others for `plan_cuts` (those
    /// cut by all of the frame's cuts from the back of `cut_list`).
    fn plan(&mut self, sub: &Subdivider, local: u32) {
        let params = sub.params;
        if local >= params.triangle_count {
            return;
        }
        let t = (params.first_triangle + local) as usize;
        let tri = sub.load(self.scene.0, self.scene.1, t);
        if sub.off_screen_vertically(tri.position) || sub.faces_away(self.scene.0, self.scene.1, t, tri.position) {
            return;
        }
        let cuts = self.counters.cuts();
        let rho = params.axis_clearance;
        // Whether it asks for cuts was decided once, by `active_cuts` (its marks).
        let full = cuts != 0 && self.frame.is_cut_triangle(t);
        let marked = cuts != 0 && (0..3).any(|e| self.frame.is_cut_edge(t, e));
        let single = if full { one_part(tri.position, rho, cuts) } else { !marked };
        if single {
            let corners = [0, 1, 2].map(|i| Node { position: tri.position[i], bary: Vec3::AXES[i] });
            let appended = self.plan_part(sub, &tri, t as u32, corners);
            self.counters.max_pieces = self.counters.max_pieces.max(appended);
            return;
        }
        let len = self.cut_list.len() as u32;
        if full {
            let slot = self.counters.cut_wide;
            self.counters.cut_wide += 1;
            if slot < len {
                self.cut_list[(len - 1 - slot) as usize] = t as u32;
            }
        } else {
            let slot = self.counters.cut_count;
            self.counters.cut_count += 1;
            if slot < len {
                self.cut_list[slot as usize] = t as u32;
            }
        }
    }

    /// The listed triangles: (narrow, wide), within the list.
    fn listed_cuts(&self) -> (u32, u32) {
        let len = self.cut_list.len() as u32;
        (self.counters.cut_count.min(len), self.counters.cut_wide.min(len))
    }

    fn plan_cuts_args(&mut self) {
        let (narrow, wide) = self.listed_cuts();
        let listed = (narrow + wide).min(self.cut_list.len() as u32);
        self.set_dispatch(DISPATCH_PLAN_CUTS, PLAN_CUTS_SPLIT * listed);
    }

    /// A listed triangle: a narrow one cut at its marked edges' crossings, a wide one's parts
    /// in one quadrant (`PLAN_CUTS_SPLIT` invocations a triangle).
    fn plan_cuts(&mut self, sub: &Subdivider, local: u32) {
        let split = PLAN_CUTS_SPLIT;
        let (narrow, wide) = self.listed_cuts();
        let len = self.cut_list.len() as u32;
        let i = local / split;
        if i >= (narrow + wide).min(len) {
            return;
        }
        let t = if i < narrow { self.cut_list[i as usize] } else { self.cut_list[(len - 1 - (i - narrow)) as usize] };
        let tri = sub.load(self.scene.0, self.scene.1, t as usize);
        let (cuts, rho) = (self.counters.cuts(), sub.params.axis_clearance);
        let before = self.counters.pieces + self.counters.parts;
        if i < narrow {
            if local % split == 0 {
                let shared = [0, 1, 2].map(|e| self.frame.is_cut_edge(t as usize, e));
                for part in edge_split_parts(tri.position, shared, rho, cuts) {
                    self.plan_polygon(sub, t, &part);
                }
            }
        } else {
            for poly in quadrant_polygons(tri.position, rho, cuts, (local % split) as usize) {
                self.plan_polygon(sub, t, &poly);
            }
        }
        let appended = self.counters.pieces + self.counters.parts - before;
        self.counters.max_pieces = self.counters.max_pieces.max(appended);
    }

    fn plan_parts_args(&mut self, sub: &Subdivider) {
        self.set_dispatch(DISPATCH_PLAN_PARTS, self.counters.parts.min(sub.params.piece_capacity));
    }

    /// A part `plan_cuts` cut: planned, its pieces appended.
    fn plan_parts(&mut self, sub: &Subdivider, local: u32) {
        if local >= self.counters.parts.min(sub.params.piece_capacity) {
            return;
        }
        let record = self.parts[local as usize];
        let tri = sub.load(self.scene.0, self.scene.1, record.triangle as usize);
        let appended = self.plan_part(sub, &tri, record.triangle, [0, 1, 2].map(|i| record_corner(&record, i)));
        self.counters.max_pieces = self.counters.max_pieces.max(appended);
    }

    fn lattice_args(&mut self, sub: &Subdivider) {
        self.set_dispatch(DISPATCH_LATTICE, self.counters.pieces.min(sub.params.piece_capacity));
    }

    /// The pieces `lattice` runs over: a range's, or as many as were counted.
    fn pieces_planned(&self, params: &SubdivideParams) -> u32 {
        match params.piece_count {
            PIECES_FROM_COUNTER => self.counters.pieces.min(params.piece_capacity),
            count => count,
        }
    }

    /// One piece record: its lattice planned, its nodes allocated, its work items appended
    /// (`plan_work`) — or, where its rows are to be measured, left to `lattice_rows` and
    /// `lattice_rows_plan`.
    fn lattice(&mut self, sub: &Subdivider, local: u32) {
        let params = sub.params;
        if local >= self.pieces_planned(params) {
            return;
        }
        let index = params.first_piece + local;
        let piece = self.pieces[index as usize];
        let tri = sub.load(self.scene.0, self.scene.1, piece.triangle as usize);
        let corners = [0, 1, 2].map(|i| record_corner(&piece, i));
        let (n0, n1) = (piece.counts01 & 0xffff, piece.counts01 >> 16);
        let n = [n0, n1, piece.count2_level & 0xffff];
        let k = (piece.count2_level >> 16) & 0x1fff;
        let bands = piece.count2_level & BANDS != 0;
        if k == 0 && !bands {
            // A slot never written: its part's records overflowed the buffer (`append`), and
            // the frame is drawn again once it has grown. No piece (the GPU's output from such
            // slots is discarded with the frame's).
            return;
        }
        let Some(g) = sub.piece_geometry(&tri, &corners, PartSplit { n, k, bands }, piece.cell) else { return };
        match sub.unmeasured_shape(&g) {
            Some(shape) => {
                let plan = sub.shaped_plan(&tri, &g, &shape);
                self.plan_work(sub, index, plan);
            }
            None => {
                // A row item per band, counted always, written where they fit (`plan_pending`).
                let r = sub.row_count(&g);
                for b in 0..r {
                    let slot = self.counters.row_items;
                    self.counters.row_items += 1;
                    if slot < 3 * params.triangle_capacity {
                        self.row_items[row_item_slot(params, slot)] = index << 5 | b;
                    }
                }
                self.pending_rows.insert(index, (tri, g, vec![(0, 0); r as usize]));
                // Listed for `lattice_rows_plan` in `parts` (free after `plan_parts`).
                let slot = self.counters.pending;
                self.counters.pending += 1;
                if slot < params.piece_capacity {
                    self.parts[slot as usize].triangle = index;
                }
            }
        }
    }

    /// The row items `lattice` appended, within their room.
    fn row_item_count(&self, params: &SubdivideParams) -> u32 {
        self.counters.row_items.min(3 * params.triangle_capacity)
    }

    /// The pieces `lattice` listed for `lattice_rows_plan`, within their room.
    fn pending_count(&self, params: &SubdivideParams) -> u32 {
        self.counters.pending.min(params.piece_capacity)
    }

    fn lattice_rows_args(&mut self, sub: &Subdivider) {
        self.set_dispatch(DISPATCH_LATTICE_ROWS, self.row_item_count(sub.params));
        self.set_dispatch(DISPATCH_LATTICE_ROWS_PLAN, self.pending_count(sub.params));
    }

    /// A row item: band b of a piece whose rows are to be measured, measured.
    fn lattice_rows(&mut self, sub: &Subdivider, local: u32) {
        if local >= self.row_item_count(sub.params) {
            return;
        }
        let item = self.row_items[row_item_slot(sub.params, local)];
        let (index, b) = (item >> 5, item & 31);
        if let Some((_, g, measures)) = self.pending_rows.get_mut(&index) {
            measures[b as usize] = sub.row_measure(g, b);
        }
    }

    /// A listed piece whose rows were measured: rows or the lattice, planned as `lattice` plans
    /// the others.
    fn lattice_rows_plan(&mut self, sub: &Subdivider, local: u32) {
        if local >= self.pending_count(sub.params) {
            return;
        }
        let index = self.parts[local as usize].triangle;
        if let Some((tri, g, measures)) = self.pending_rows.remove(&index) {
            let plan = sub.shaped_plan(&tri, &g, &sub.rows_or_lattice(&g, &measures));
            self.plan_work(sub, index, plan);
        }
    }

    /// A planned piece's work: its nodes allocated; a piece of one item's worth written here,
    /// as its items would be; a larger one's work items appended (`plan_work`).
    fn plan_work(&mut self, sub: &Subdivider, index: u32, plan: PiecePlan) {
        if plan.copies == 0 {
            return; // VR180: behind the viewer
        }
        let params = sub.params;
        let first_node = self.counters.nodes;
        self.counters.nodes += plan.copies * plan.node_count;
        self.max_piece_output = self.max_piece_output.max(plan.output());
        // The part's record: the piece's without its cell.
        let part = Piece { cell: 0, ..self.pieces[index as usize] };
        *self.part_output.entry(bytemuck::cast_slice(&[part]).to_vec()).or_default() += plan.output();
        let work = Rc::new((first_node, plan));
        let plan = &work.1;
        let chunk = chunk_of(plan.copies);
        if plan.node_count <= chunk && plan.candidates.len() as u32 <= chunk {
            if first_node + plan.copies * plan.node_count <= params.triangle_capacity {
                self.write_nodes(&work, 0);
                self.write_triangles(sub, &work, 0);
            }
            return;
        }
        let len = params.triangle_capacity;
        for start in plan.node_items() {
            let slot = self.counters.node_items;
            self.counters.node_items += 1;
            if slot < len {
                self.lattice_work[slot as usize] = [index, start, 0, 0];
            }
        }
        for start in plan.triangle_items() {
            let slot = self.counters.triangle_items;
            self.counters.triangle_items += 1;
            if slot < len {
                self.lattice_work[(len - 1 - slot) as usize] = [index, start, 0, 0];
            }
        }
        self.piece_work.insert(index, work);
    }

    /// The work items `lattice` appended: (node items, triangle items) within `lattice_work`.
    fn work_items(&self, params: &SubdivideParams) -> (u32, u32) {
        let len = params.triangle_capacity;
        (self.counters.node_items.min(len), self.counters.triangle_items.min(len))
    }

    fn lattice_work_args(&mut self, sub: &Subdivider) {
        let (nodes, triangles) = self.work_items(sub.params);
        self.set_dispatch(DISPATCH_LATTICE_NODES, nodes);
        self.set_dispatch(DISPATCH_LATTICE_TRIANGLES, triangles);
    }

    /// A node item: its piece's nodes in its slots, once per seam copy.
    fn lattice_nodes(&mut self, sub: &Subdivider, local: u32) {
        let params = sub.params;
        if local >= self.work_items(params).0 || self.counters.nodes > params.triangle_capacity {
            return;
        }
        let [index, start, ..] = self.lattice_work[local as usize];
        let work = Rc::clone(&self.piece_work[&index]);
        self.write_nodes(&work, start);
    }

    /// A triangle item: its piece's candidates in it that are drawn (their corners read from the
    /// nodes written), appended once per seam copy.
    fn lattice_triangles(&mut self, sub: &Subdivider, local: u32) {
        let params = sub.params;
        let len = params.triangle_capacity;
        if local >= self.work_items(params).1 || self.counters.nodes > len {
            return;
        }
        let [index, start, ..] = self.lattice_work[(len - 1 - local) as usize];
        let work = Rc::clone(&self.piece_work[&index]);
        self.write_triangles(sub, &work, start);
    }

    /// The nodes of a piece's node item at slot `start`, once per seam copy (`write_nodes`).
    fn write_nodes(&mut self, (first_node, plan): &(u32, PiecePlan), start: u32) {
        let range = plan.node_range(start);
        for c in 0..plan.copies {
            for k in range.clone() {
                let (to, from) = (first_node + c * plan.node_count + k, c * plan.node_count + k);
                self.out_nodes[to as usize] = plan.nodes[from as usize];
            }
        }
        self.counters.max_output = self.counters.max_output.max(range.len() as u32 * plan.copies);
    }

    /// The drawn triangles of a piece's triangle item at candidate `start`, their corners read
    /// from the nodes written, appended once per seam copy (`write_triangles`).
    fn write_triangles(&mut self, sub: &Subdivider, (first_node, plan): &(u32, PiecePlan), start: u32) {
        let len = sub.params.triangle_capacity;
        let node = |k: u32| Vec3::from(self.out_nodes[(first_node + k) as usize].position);
        let shown = plan.shown(sub, start, |k| self.out_nodes[(first_node + k) as usize]);
        if shown.is_empty() {
            return;
        }
        let total = shown.iter().map(|(_, mask)| mask.count_ones()).sum::<u32>();
        let first_triangle = self.counters.triangles;
        self.counters.triangles += total;
        self.counters.max_output = self.counters.max_output.max(total);
        if first_triangle + total > len {
            return; // counted, never written
        }
        if sub.params.measure_edges != 0 {
            for (t, _) in &shown {
                let edge = sub.visible_edge_px(t.map(node));
                self.counters.max_edge_bits = f32::from_bits(self.counters.max_edge_bits).max(edge).to_bits();
            }
        }
        let mut slot = 3 * first_triangle as usize;
        for (t, mask) in shown {
            for c in (0..plan.copies).filter(|c| mask & 1 << c != 0) {
                for k in t {
                    self.out_indices[slot] = first_node + c * plan.node_count + k;
                    slot += 1;
                }
            }
        }
    }

    /// The draw's arguments: none drawn if a buffer overflowed.
    fn finalize(&mut self, sub: &Subdivider) {
        let c = &self.counters;
        let capacity = sub.params.triangle_capacity;
        let written = if c.triangles > capacity || c.nodes > capacity { 0 } else { c.triangles };
        self.draw_args = DrawIndexedIndirectArgs { index_count: 3 * written, instance_count: 1, ..Default::default() };
    }

    // ---- what the passes share ----

    /// A polygon `plan_cuts` cut from triangle t: its fan's parts on screen appended for
    /// `plan_parts` (`plan_band` and `plan_edge_split` in the WGSL).
    fn plan_polygon(&mut self, sub: &Subdivider, t: u32, poly: &[Node]) {
        for part in fan(poly) {
            if sub.off_screen_vertically(part.map(|n| n.position)) {
                continue;
            }
            let slot = self.counters.parts;
            self.counters.parts += 1;
            if slot < sub.params.piece_capacity {
                self.parts[slot as usize] = record(t, 0, 0, part);
            }
        }
    }

    /// Part `corners` of triangle t planned (`plan_part`, then `append_pieces` in the WGSL): its
    /// pieces appended; how many.
    fn plan_part(&mut self, sub: &Subdivider, tri: &Triangle, t: u32, corners: [Node; 3]) -> u32 {
        let split = sub.plan(tri, &corners);
        let [n0, n1, n2] = split.n;
        let flags = if split.bands { BANDS } else { 0 };
        let first = record(t, n0 | n1 << 16, n2 | split.k << 16 | flags, corners);
        let cells: Vec<Piece> = (0..split.pieces(sub.params.max_div)).map(|cell| Piece { cell, ..first }).collect();
        self.append(sub.params, &cells);
        cells.len() as u32
    }

    /// Appends records: counted always, written only if all fit.
    fn append(&mut self, params: &SubdivideParams, records: &[Piece]) {
        let base = self.counters.pieces;
        self.counters.pieces += records.len() as u32;
        if base + records.len() as u32 > params.piece_capacity {
            return; // counted, never written
        }
        self.pieces[base as usize..base as usize + records.len()].copy_from_slice(records);
    }
}

impl SubdivisionEngine for CpuSubdivision<'_> {
    fn ensure(&mut self, want: Capacities) -> Capacities {
        if self.pieces.len() < want.pieces as usize {
            self.pieces.resize(want.pieces as usize, Piece::default());
            self.parts.resize(want.pieces as usize, Piece::default());
        }
        if self.out_nodes.len() < want.triangles as usize {
            self.out_nodes.resize(want.triangles as usize, DrawVertex::default());
            self.out_indices.resize(3 * want.triangles as usize, 0);
            self.lattice_work.resize(want.triangles as usize, [0; 4]);
            self.row_items.resize(3 * want.triangles as usize, 0);
        }
        Capacities { pieces: self.pieces.len() as u32, triangles: self.out_nodes.len() as u32 }
    }

    fn replay(&mut self, recording: &Recording, params: &SubdivideParams) -> Result<SubdivideCounters> {
        let sub = Subdivider::with_edge_scale(params, self.edge_scale);
        for command in &recording.commands {
            match *command {
                Command::Clear { buffer, bytes } => self.clear(buffer, bytes),
                Command::Pass { .. } => {}
                Command::Dispatch { entry, invocations } => self.dispatch(&sub, entry, invocations),
                Command::DispatchIndirect { entry, args, offset } => {
                    assert_eq!(args, SubdivideBuffer::LatticeDispatch, "the subdivide stage's indirect arguments");
                    let at = offset as usize / 4;
                    let groups = &self.lattice_dispatch[at..at + 3];
                    let invocations = groups[0] * groups[1] * groups[2] * 64;
                    self.dispatch(&sub, entry, invocations);
                }
            }
        }
        Ok(self.counters)
    }

    fn take(&mut self, counters: &SubdivideCounters) -> Result<()> {
        let offset = self.nodes.len() as u32;
        self.nodes.extend_from_slice(&self.out_nodes[..counters.nodes as usize]);
        self.taken_indices.extend(self.out_indices[..3 * counters.triangles as usize].iter().map(|i| i + offset));
        Ok(())
    }
}
