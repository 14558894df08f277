// The `subdivide` stage's bindings (group 0; descriptor `SUBDIVIDE` in src/shader/mod.rs).

#import subdivide_types

// The parameters in a storage buffer, not a uniform one: lavapipe (Mesa 22) inlines the values of
// uniforms that branches test, and where that shrinks a pass it optimises and compiles it again
// each time the pass is bound, every frame (a `lattice_triangles` with no work to do took 6 ms of
// each frame of a 100-triangle model). What is worth compiling per frame kind is compiled once,
// as a variant's overrides (`SubdivideStage::variant` in src/gpu/subdivide.rs).
@group(0) @binding(0) var<storage, read> params: SubdivideParams;
@group(0) @binding(1) var<storage, read> vertices: array<SceneVertex>;
@group(0) @binding(2) var<storage, read> indices: array<u32>;

@group(0) @binding(3) var<storage, read_write> pieces: array<Piece>;
// The output: each piece's lattice nodes once (per seam copy), and its triangles as indices
// into them (`SubdivideOutput` in src/cpu/subdivide/).
@group(0) @binding(4) var<storage, read_write> out_nodes: array<DrawVertex>;
@group(0) @binding(5) var<storage, read_write> counters: Counters;
@group(0) @binding(6) var<storage, read_write> draw_args: DrawIndexedIndirectArgs;
// Workgroup counts of the `lattice` dispatch (0–2), written by `lattice_args` from the piece
// counter, of the `plan_cuts` dispatch (3–5), written by `plan_cuts_args`, of the `plan_parts`
// dispatch (6–8), written by `plan_parts_args`, of `lattice_nodes` (9–11) and
// `lattice_triangles` (12–14), written by `lattice_work_args`, and of `lattice_rows` (15–17)
// and `lattice_rows_plan` (18–20), written by `lattice_rows_args` (`DISPATCH_*` in
// src/encoding/subdivide.rs: their byte offsets).
@group(0) @binding(7) var<storage, read_write> lattice_dispatch: array<u32, 21>;
// Per object: the factor its L is multiplied by (the visual-field level of detail relaxes the
// subdivision away from the gaze; 1 without it). CPU twin: `Subdivider::edge_px`.
@group(0) @binding(8) var<storage, read> object_edge_scale: array<f32>;
// The triangles `plan` left for `plan_cuts` (room for every triangle of a dispatch).
@group(0) @binding(9) var<storage, read_write> cut_list: array<u32>;
@group(0) @binding(10) var<storage, read_write> out_indices: array<u32>;
// Edge e of triangle t is the scene's shared edge triangle_edges[3t + e] (`SharedEdges`).
// `cut_edges`: two bits per shared edge (`FrameCuts`), edge i's at bits 2(i mod 16) of word i / 16
// (one load reads both): EDGE_ASKING, the edge is a triangle's that asks for cuts (set by
// `active_cuts`); EDGE_CUT, a cut triangle's (those and their neighbours across those edges; set
// by `active_cuts` and `ring_cuts`).
@group(0) @binding(11) var<storage, read> triangle_edges: array<u32>;
@group(0) @binding(12) var<storage, read_write> cut_edges: array<atomic<u32>>;
// The same buffer, read only, for the passes after the marking (`plan`, `plan_cuts`): plain
// loads rather than atomic ones.
@group(0) @binding(13) var<storage, read> edge_marks_read: array<u32>;
// The parts `plan_cuts` cut (records as pieces', their counts unset), planned by `plan_parts`
// (room for as many as `pieces`: each part makes at least one piece). Free after `plan_parts`:
// then `lattice` lists in it (in each record's `triangle`) the pieces whose rows
// `lattice_rows` measures, for `lattice_rows_plan`.
@group(0) @binding(14) var<storage, read_write> parts: array<Piece>;
// What `lattice` planned for each piece (at the piece's index), and its work items: vec4(piece,
// first node slot or candidate, the walk at that candidate (two u16 pairs)), for
// `lattice_nodes` from the front and for `lattice_triangles` from the back (room for as many as
// the output's nodes: each item has at least one node's worth, see `work_items` in lattice.rs).
@group(0) @binding(15) var<storage, read_write> piece_work: array<StoredWork>;
@group(0) @binding(16) var<storage, read_write> lattice_work: array<vec4<u32>>;
// The bands of the pieces whose rows `lattice_rows` measures, (piece << 5) | band, in the
// output's index buffer (`out_indices`) from its back (`row_item_slot`): a piece of R rows has
// at least R + 1 nodes, so where the output fits, so do they, and the triangles written in
// place before `lattice_rows_plan` (from the front) reach them only where the output, counted
// with them, overflows.
@group(0) @binding(17) var<storage, read_write> row_items: array<u32>;
