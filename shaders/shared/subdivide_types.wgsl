// The `subdivide` stage's data: its output vertex, its parameters and counters, the draw's
// indirect arguments, a piece record, a node, the edge marks' bits. Rust twins:
// src/encoding/types.rs (checked field by field by tests/shaders.rs).

#import projection
#import constants
#import scene

struct DrawVertex {
    position: vec3<f32>,
    theta_ref: f32,
    normal: vec3<f32>,
    material: u32,
    color: vec4<f32>,
    uv: vec2<f32>,
    object: u32,
    tangent: u32,   // the interpolated glTF tangent, viewer frame, packed (`pack_tangent`); 0: none
    offsets: vec4<f32>, // drawn off the projection, image pixels (x right, y down): left (x, y), right (x, y)
}

struct SubdivideParams {
    view: mat4x4<f32>,
    projection: Projection,
    axis_clearance: f32,
    triangle_count: u32,
    first_triangle: u32,
    method: u32,            // METHOD_VERTEX, METHOD_FIXED, METHOD_ADAPTIVE (length) or METHOD_ERROR
    fixed_n: u32,
    edge_px: f32,           // L
    max_div: u32,           // N_max
    piece_capacity: u32,
    triangle_capacity: u32,
    first_piece: u32,
    piece_count: u32,
    measure_edges: u32,  // 1: also track the longest visible output edge
    vertical_limit: f32, // |y| > this·r: no pixel row shows the point (`Projection::vertical_limit`)
    max_error_px: f32,   // τ of the error split
    by_azimuth: u32,     // 1: nodes spaced by azimuth, drawn with w = r (`SubdivideParams::by_azimuth`)
    seamless: u32,       // 1: the image has no seam: no seam copies (`SubdivideParams::seamless`)
    pinhole_faces: u32,  // 1: drawn as pinholes (the cubemap): `SubdivideParams::pinhole_faces`
    node_offsets: u32, // 1: nodes drawn off their projections (`SubdivideParams::node_offsets`)
    antipode_cos: f32, // cos β of the fisheye's dropped cone, 2: none (`SubdivideParams::antipode_cos`)
    _pad: u32,
}

// Whether the pipeline may measure the longest visible output edge (`measure_edges`): built
// false for the frames that do not (a render's), whose lanes would otherwise all run it on
// lavapipe (CONVERGING in projection.wgsl).
override MEASURE_EDGES: bool = true;

// Whether the pipeline may draw pinholes (`SubdivideParams::pinhole_faces`, the cubemap): built
// false for the other frames, whose lanes would otherwise all run the eye points' measure on
// lavapipe (Sponza's sphere subdivision +5 % with it merely there).
override PINHOLE_FACES: bool = true;

// The split rule the pipeline is built for (a `SubdivideParams::method` value), or ANY_SPLIT_RULE:
// the parameters' own, read as the pass runs. A variant per rule compiles the others' tests out,
// which lavapipe's lanes would otherwise all run (CONVERGING in projection.wgsl).
const ANY_SPLIT_RULE: u32 = 0xffffffffu;
override SPLIT_RULE: u32 = ANY_SPLIT_RULE;

fn split_rule() -> u32 {
    return select(params.method, SPLIT_RULE, SPLIT_RULE != ANY_SPLIT_RULE);
}

struct Counters {
    pieces: atomic<u32>,
    triangles: atomic<u32>,
    max_edge_bits: atomic<u32>, // bits of the largest visible output edge, px (f32 ≥ 0 orders as u32)
    cut_count: atomic<u32>,     // triangles `plan` listed for `plan_cuts` from the front of `cut_list`
    nodes: atomic<u32>,         // output nodes (`lattice`)
    cut_wide: atomic<u32>,      // ... and from its back: the wide ones (`asks_for_cuts`)
    max_pieces: atomic<u32>,    // the most piece records one `plan` or `plan_cuts` invocation appended
    max_output: atomic<u32>,    // the most nodes or triangles one `lattice` invocation wrote
    parts: atomic<u32>,         // part records `plan_cuts` appended for `plan_parts`
    node_items: atomic<u32>,    // work items `lattice` appended for `lattice_nodes` (front of `lattice_work`)
    triangle_items: atomic<u32>, // ... and for `lattice_triangles` (its back)
    row_items: atomic<u32>,     // bands of pieces whose rows `lattice_rows` measures (`row_items`)
    pending: atomic<u32>,       // those pieces, listed for `lattice_rows_plan` (in `parts`)
    // The frame's cuts around the axis (`AxisCuts` in axis.rs): bit 0 the quadrant cuts and the
    // square, bit k the diamond c_k; bits 0–31 and 32–63. Kept across the chunks of a frame.
    cuts_low: atomic<u32>,
    cuts_high: atomic<u32>,
    _pad: u32, // the timestamps read back after the counters start at a multiple of 8 bytes
}

struct DrawIndexedIndirectArgs {
    index_count: u32,
    instance_count: u32,
    first_index: u32,
    base_vertex: i32,
    first_instance: u32,
}


// A piece: its triangle, macro cell, the part's edge counts and K, and the part's corners
// (position and barycentric weights), so that `lattice` need not cut the triangle again.
struct Piece {
    triangle: u32,
    cell: u32,
    counts01: u32,      // n0 | n1 << 16
    count2_level: u32,  // n2 | K << 16
    corner: array<vec4<f32>, 3>, // position, barycentric weight of the triangle's corner 0
    bary1: vec4<f32>,   // weights of corners 1 and 2 at the part's corners 0, 1, 2
    bary2: vec4<f32>,
    bend: array<vec4<f32>, 3>, // each edge's profile's bend vectors (`EdgeProfile::bend_vec`)
}

// What `lattice` planned for a piece (at the piece's index), which its work items read: its
// shape (`strip_base`: a sliver's strip base 0–2, the lattice 3, ROWS_SHAPE, or
// ROWS_PENDING while `lattice_rows` measures its rows), level m, nodes, candidate triangles, seam
// copies (0: nothing drawn) and their reference azimuths, its first output node, its edge counts
// (8 bits each; rows' base in bits 24–31), a strip's or rows' sides' counts
// (x | y << 16), rows' widths (while pending: each band's measures, `row_measures`).
struct PieceWork {
    shape: u32,
    m: u32,
    node_count: u32,
    candidates: u32,
    copies: u32,
    first_node: u32,
    counts: u32,
    strip_n: u32,
    refs: vec4<f32>,
    row_w: array<u32, 33>,
    _pad: array<u32, 3>,
}

// A piece's work as `piece_work` stores it, with where its nodes are drawn off their
// projections (image pixels, y down, left xy, right xy): inside edge 0, 1, 2; at corner 0, 1, 2;
// inside (`piece_offsets`). Apart from `PieceWork`, which the passes copy by value.
struct StoredWork {
    work: PieceWork,
    offsets: array<vec4<f32>, 7>,
}

// The steps of a piece's rows' nodes (`rows_along`): the base row's nodes, a row's left end, its
// right end, its nodes between.
const ROW_BASE: u32 = 3u;
const ROW_LEFT_END: u32 = 0u;
const ROW_RIGHT_END: u32 = 1u;
const ROW_BETWEEN: u32 = 2u;

const EDGE_ASKING: u32 = 1u;
const EDGE_CUT: u32 = 2u;

// `params.piece_count == PIECES_FROM_COUNTER` (from `constants`): as many pieces as `plan` made
// (read from the counter), so that plan, lattice and drawing can run in one submission.
// MAX_EDGE_DIVISIONS, EDGE_SAMPLES, BAND_LIMIT, BAND_RATIO, SNAP, SEAM_MARGIN: from src/shader/constants.rs.

// How a segment's points are spaced (`Spacer` in src/cpu/subdivide/spacing.rs; made by
// `spacer` in subdivide_spacing.wgsl): `by_radius` under azimuth spacing with both ends at least
// AZIMUTH_MIN_RADIUS from the axis (their distances rl, rh), and the azimuth the segment sweeps
// where it is within (AZIMUTH_MIN_TURN, AZIMUTH_MAX_TURN), else 0.
struct Spacer {
    by_radius: bool,
    rl: f32,
    rh: f32,
    turn: f32,
}

struct Node {
    position: vec3<f32>,
    bary: vec3<f32>,   // weights of the input triangle's corners, for the attributes
}

// A node as `edge_point`'s arguments: node j of the n parts of segment a–b. A piece's node is
// found as one of these by its shape, then placed by one call of `edge_point` (lavapipe inlines
// every call site: its time to build a pipeline grows with every copy of the spacing).
struct Along {
    a: Node,
    b: Node,
    j: u32,
    n: u32,
}

// The point with weights w of a triangle of nodes (positions and barycentric weights alike).
fn weighted(q: array<Node, 3>, w: vec3<f32>) -> Node {
    return Node(
        w.x * q[0].position + w.y * q[1].position + w.z * q[2].position,
        w.x * q[0].bary + w.y * q[1].bary + w.z * q[2].bary,
    );
}
