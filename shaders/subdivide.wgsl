// The `subdivide` stage (compute): adaptive subdivision (seed 002 §2.3, eq. 5, Fig. 6), the
// vertical-axis split and the seam copies. CPU twin and full description: src/cpu/subdivide/.

#import projection
#import constants
#import scene
//
// `active_cuts` one invocation per input triangle of the whole scene: the cuts around the axis
//            the frame makes (quadrant cuts and the square, the diamonds), OR-ed into `counters`;
//            a triangle that asks for cuts marks its edges in `cut_edges`.
// `ring_cuts` the same, after it: a triangle with such an edge is cut too, and marks its edges.
// `plan`     one invocation per input triangle. A triangle that is its own single part (no cuts
//            this frame; neither asks nor has an edge of one that does, nor an edge of a cut one;
//            or inside one quadrant and one band) is planned here; the others are
//            listed in `cut_list` for `plan_cuts` (the clipping code, kept out of this entry
//            point: lavapipe runs a shader that merely contains it markedly slower), the wide
//            ones cut by all of the frame's cuts apart from the rest.
// `plan_cuts_args`, `plan_cuts`  one invocation per listed triangle (on the sphere per triangle
//            and quadrant): a triangle not cut by all cuts, fanned at the crossings of its edges
//            that cut triangles have (`plan_edge_split`); one cut, its parts around the
//            vertical axis under the frame's cuts (quadrants minus a small square around the axis,
//            bands between the active diamonds, fan-triangulated; a band's quad whose two opposite
//            sides are in one part each, one piece drawn as a strip between the other two).
//            For every part, `plan` and `plan_cuts` find the edge
//            counts N (eq. 5 or the error split), the macro-lattice level K = ceil(M / N_max) of the pre-split, and
//            K² piece records (triangle, cell, counts, the part's corners).
// `lattice`  one invocation per piece: the part's corners from the piece record, the regular
//            lattice of level m = max(counts), boundary nodes snapped to each edge's nodes (or,
//            for a sliver under the error split on the cylinder, a strip along its long edges; for
//            a band quad, a strip between its rails, corner 3 read from the next record);
//            its nodes appended once and its drawn sub-triangles as indices into them, the whole
//            piece again a turn away where its nodes' u range crosses ±π.
// `finalize` the DrawIndexedIndirect arguments (none drawn if a buffer overflowed).
// Appends never write past a capacity: they are counted, and the host grows the buffer or
// processes the scene in chunks.


struct DrawVertex {
    position: vec3<f32>,
    theta_ref: f32,
    normal: vec3<f32>,
    material: u32,
    color: vec4<f32>,
    uv: vec2<f32>,
    object: u32,
    tangent: u32,   // the interpolated glTF tangent, viewer frame, packed (`pack_tangent`); 0: none
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
    _pad1: u32,
    _pad2: u32,
}

struct Counters {
    pieces: atomic<u32>,
    triangles: atomic<u32>,
    max_edge_bits: atomic<u32>, // bits of the largest visible output edge, px (f32 ≥ 0 orders as u32)
    cut_count: atomic<u32>,     // triangles `plan` listed for `plan_cuts` from the front of `cut_list`
    nodes: atomic<u32>,         // output nodes (`lattice`)
    cut_wide: atomic<u32>,      // ... and from its back: the wide ones (`asks_for_cuts`)
    // The frame's cuts around the axis (`AxisCuts` in axis.rs): bit 0 the quadrant cuts and the
    // square, bit k the diamond c_k; bits 0–31 and 32–63. Kept across the chunks of a frame.
    cuts_low: atomic<u32>,
    cuts_high: atomic<u32>,
}

struct DrawIndexedIndirectArgs {
    index_count: u32,
    instance_count: u32,
    first_index: u32,
    base_vertex: i32,
    first_instance: u32,
}

@group(0) @binding(0) var<uniform> params: SubdivideParams;
@group(0) @binding(1) var<storage, read> vertices: array<SceneVertex>;
@group(0) @binding(2) var<storage, read> indices: array<u32>;
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
}

@group(0) @binding(3) var<storage, read_write> pieces: array<Piece>;
// The output: each piece's lattice nodes once (per seam copy), and its triangles as indices
// into them (`SubdivideOutput` in src/cpu/subdivide/).
@group(0) @binding(4) var<storage, read_write> out_nodes: array<DrawVertex>;
@group(0) @binding(5) var<storage, read_write> counters: Counters;
@group(0) @binding(6) var<storage, read_write> draw_args: DrawIndexedIndirectArgs;
// Workgroup counts of the `lattice` dispatch (0–2), written by `lattice_args` from the piece
// counter, and of the `plan_cuts` dispatch (3–5), written by `plan_cuts_args`.
@group(0) @binding(7) var<storage, read_write> lattice_dispatch: array<u32, 6>;
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
const EDGE_ASKING: u32 = 1u;
const EDGE_CUT: u32 = 2u;

// `params.piece_count == PIECES_FROM_COUNTER` (from `constants`): as many pieces as `plan` made
// (read from the counter), so that plan, lattice and drawing can run in one submission.
// MAX_EDGE_DIVISIONS, EDGE_SAMPLES, BAND_LIMIT, BAND_RATIO, SNAP, SEAM_MARGIN: from src/shader/constants.rs.

struct Node {
    position: vec3<f32>,
    bary: vec3<f32>,   // weights of the input triangle's corners, for the attributes
}

// The input triangle in the viewer frame, and its plan.
var<private> tri_position: array<vec3<f32>, 3>;
var<private> tri_normal: array<vec3<f32>, 3>;
var<private> tri_color: array<vec4<f32>, 3>;
var<private> tri_uv: array<vec2<f32>, 3>;
var<private> tri_tangent: array<vec4<f32>, 3>;
var<private> tri_material: u32;
var<private> tri_object: u32;
// L for this triangle: params.edge_px × its object's factor (read once in `load_triangle`).
var<private> tri_edge_px: f32;
var<private> tri_max_error_px: f32;
// The part being split (see `triangle_part`), and its plan.
var<private> part: array<Node, 3>;
var<private> tri_n: array<u32, 3>;    // divisions of the part's edges Q0Q1, Q1Q2, Q2Q0
var<private> tri_k: u32;              // macro-lattice level

// The piece being subdivided.
var<private> piece_q: array<Node, 3>;
var<private> piece_counts: array<u32, 3>;
var<private> piece_original: array<i32, 3>; // original edge under piece edge e, or −1
var<private> piece_from: array<u32, 3>;     // fine index on that original edge at corner e
var<private> piece_to: array<u32, 3>;
var<private> strip_base: u32;               // a sliver's base edge (see `strip_base_of`); 3: the lattice; QUAD_STRIP
var<private> strip_n: vec2<u32>;            // its long edges' counts: edge base + 1, edge base + 2; a quad's rails
var<private> quad_last: Node;               // a band quad's corner 3 (its corners 0–2 in piece_q)
var<private> quad_turn: u32;                // `plan_quad`: the polygon's corner that is the quad's corner 0
var<private> poly_n: array<u32, 11>;        // edge counts of a band's polygon and its fan (`polygon_edge_ends`)

// A polygon while it is clipped (at most 7 corners), and a quadrant's polygon kept while its
// bands are cut from it. Three slots of seven nodes in one pool, named by their offsets, so that a clip writes its
// result into a free slot and no polygon is ever copied (lavapipe copies private arrays node by
// node, lane by lane).
var<private> pool: array<Node, 21>;
var<private> poly_at: u32;      // the current polygon's slot
var<private> poly_count: u32;
var<private> quadrant_at: u32;  // the quadrant's rest's slot
var<private> quadrant_count: u32;
var<private> keep_at: u32;      // a third slot a clip must not write (a band kept meanwhile)

// Corner i of the current polygon.
fn poly_node(i: u32) -> Node {
    return pool[poly_at + i];
}
// The frame's cuts (bits 0–31, 32–63), read by `plan` from the counters.
var<private> cuts: vec2<u32>;

fn corner(i: u32) -> Node {
    return part[i];
}

fn lex_less(a: vec3<f32>, b: vec3<f32>) -> bool {
    return a.x < b.x || (a.x == b.x && (a.y < b.y || (a.y == b.y && a.z < b.z)));
}

fn same(a: vec3<f32>, b: vec3<f32>) -> bool {
    return all(a == b);
}

// The point j/n of the way from a to b, from the canonically ordered pair; the ends are exact.
fn edge_point(a: Node, b: Node, j: u32, n: u32) -> Node {
    var lo = a;
    var hi = b;
    var jj = j;
    if (lex_less(b.position, a.position)) {
        lo = b;
        hi = a;
        jj = n - j;
    }
    if (jj == 0u) {
        return lo;
    }
    if (jj == n) {
        return hi;
    }
    let t = f32(jj) / f32(n);
    return Node(lo.position + (hi.position - lo.position) * t, lo.bary + (hi.bary - lo.bary) * t);
}

// Image position in pixels (x not wrapped) of a viewer-frame point for one eye sign.
fn pixel(p: vec3<f32>, eye_sign: f32) -> vec2<f32> {
    let q = project_with_azimuth(params.projection, p, azimuth(p), eye_sign);
    return vec2<f32>(q.x * params.projection.width / TAU, q.y * params.projection.pixels_per_v);
}

// What the split rules read of the straight edge ab (`Subdivider::edge_profile`): sampled at
// `segments` segments, both eyes, in canonical order: the projected length by which eq. 5 splits
// it (heights clamped, segments beyond the clamp at both ends counting 0, stretch-adjusted), the
// largest second difference of the sampled points (x unwrapped, triples beyond the clamp
// skipped) by which the error split splits it, and whether it comes near the eye circle.
struct EdgeProfile {
    length_px: f32,
    bend_px: f32,
    ring: bool,
}

fn edge_profile(a: vec3<f32>, b: vec3<f32>, segments: u32) -> EdgeProfile {
    var lo = a;
    var hi = b;
    if (lex_less(b, a)) {
        lo = b;
        hi = a;
    }
    let clamp_v = 1.5 * params.projection.height;
    let width = params.projection.width;
    var length_px = 0.0;
    var longest = 0.0;
    var nearest = 1e30;
    var bend = 0.0;
    for (var s = 0u; s < 2u; s++) {
        let eye_sign = select(-1.0, 1.0, s == 1u);
        var total = 0.0;
        var prev = vec2<f32>(0.0, 0.0);
        var q0 = vec2<f32>(0.0, 0.0);
        var q1 = vec2<f32>(0.0, 0.0);
        for (var k = 0u; k <= segments; k++) {
            let t = f32(k) / f32(segments);
            let p = lo + (hi - lo) * t;
            nearest = min(nearest, horizontal_radius(p));
            let raw = pixel(p, eye_sign);
            var q = raw;
            q.y = clamp(q.y, -clamp_v, clamp_v);
            let dx = (q.x - prev.x) - width * round((q.x - prev.x) / width);
            if (k > 0u && !(q.y == prev.y && abs(q.y) == clamp_v)) {
                let segment = length(vec2<f32>(dx, q.y - prev.y));
                longest = max(longest, segment);
                total += segment;
            }
            let unwrapped = vec2<f32>(select(raw.x, q1.x + dx, k > 0u), raw.y);
            if (k >= 2u && abs(unwrapped.y) < clamp_v && abs(q1.y) < clamp_v && abs(q0.y) < clamp_v) {
                bend = max(bend, length(unwrapped - 2.0 * q1 + q0));
            }
            q0 = q1;
            q1 = unwrapped;
            prev = q;
        }
        length_px = max(length_px, total);
    }
    // Near the eye circle, which the paper model and the sphere show on screen (α and the
    // longitude ∝ √(r − d_e)), no stretch is allowed (the exact model puts it at v = ±∞).
    let shows_ring = params.projection.vertical_exact == 0u || is_sphere(params.projection);
    let ring = shows_ring && nearest < 2.0 * params.projection.eye_radius;
    let stretch = select(MAX_STRETCH, 1.0, ring);
    return EdgeProfile(max(length_px, f32(segments) * longest / stretch), bend, ring);
}

// Parts for a chord error of at most τ (`parts_for_bend`).
fn parts_for_bend(bend_px: f32, segments: u32, max_error_px: f32) -> f32 {
    return ceil(f32(segments) * sqrt(bend_px / (8.0 * max_error_px)));
}

// Divisions of an edge (`Subdivider::edge_divisions`): eq. 5 for METHOD_ADAPTIVE, the error
// split for METHOD_ERROR. The quick 2-segment profile, then the 8-segment one, from one call site
// in a loop (lavapipe's compiler inlines every call, and a shader that merely contains more code
// runs slower).
fn edge_divisions(a: vec3<f32>, b: vec3<f32>) -> u32 {
    if (params.method == METHOD_VERTEX) {
        return 1u;
    }
    if (params.method == METHOD_FIXED) {
        return params.fixed_n;
    }
    let by_length = params.method == METHOD_ADAPTIVE;
    var n = 0.0;
    for (var round = 0u; round < 2u; round++) {
        let segments = select(2u, EDGE_SAMPLES, round == 1u);
        let p = edge_profile(a, b, segments);
        let by_bend = parts_for_bend(p.bend_px, segments, tri_max_error_px);
        if (round == 0u) {
            let whole = select(p.length_px <= tri_edge_px && !p.ring && by_bend <= 1.0,
                               p.length_px <= 0.5 * tri_edge_px, by_length);
            if (whole) {
                return 1u;
            }
        } else if (by_length) {
            n = ceil(p.length_px / tri_edge_px);
        } else {
            let longest = select(ERROR_SPLIT_LENGTH * tri_edge_px, tri_edge_px, p.ring);
            n = max(by_bend, ceil(p.length_px / longest));
        }
    }
    if (n >= f32(MAX_EDGE_DIVISIONS) || !(n == n)) {
        return MAX_EDGE_DIVISIONS;
    }
    return max(u32(n), 1u);
}

// Whether a triangle lies wholly above or below the image (see `off_screen_vertically` in
// src/cpu/subdivide/ for why testing the corners suffices).
fn off_screen_vertically(p0: vec3<f32>, p1: vec3<f32>, p2: vec3<f32>) -> bool {
    let k = params.vertical_limit;
    let r = vec3<f32>(horizontal_radius(p0), horizontal_radius(p1), horizontal_radius(p2));
    let y = vec3<f32>(p0.y, p1.y, p2.y);
    return all(y > k * r) || all(y < -k * r);
}

// The corners of input triangle t in the viewer frame, snapped to the cut planes.
fn load_positions(t: u32) {
    for (var k = 0u; k < 3u; k++) {
        let v = vertices[indices[3u * t + k]];
        tri_position[k] = snap_to_cut_planes((params.view * vec4<f32>(v.position, 1.0)).xyz);
    }
}

// Loads an input triangle into the viewer frame, its vertices snapped to the cut planes
// (its parts, their edge counts and K come from `visit_parts` or from the piece record).
fn load_triangle(t: u32) {
    load_positions(t);
    for (var k = 0u; k < 3u; k++) {
        let v = vertices[indices[3u * t + k]];
        tri_normal[k] = (params.view * vec4<f32>(v.normal, 0.0)).xyz;
        tri_color[k] = v.color;
        tri_uv[k] = v.uv;
        let t = unpack_tangent(v.tangent);
        tri_tangent[k] = vec4<f32>((params.view * vec4<f32>(t.xyz, 0.0)).xyz, t.w);
    }
    tri_material = vertices[indices[3u * t]].material;
    tri_object = vertices[indices[3u * t]].object;
    let scale = object_edge_scale[min(tri_object, arrayLength(&object_edge_scale) - 1u)];
    tri_edge_px = params.edge_px * scale;
    tri_max_error_px = params.max_error_px * (scale * scale);
}

// Whether the method is one of the adaptive rules (eq. 5 or the error split).
fn is_adaptive() -> bool {
    return params.method == METHOD_ADAPTIVE || params.method == METHOD_ERROR;
}

// Edge counts and macro-lattice level of the current part.
fn plan_part() {
    for (var e = 0u; e < 3u; e++) {
        tri_n[e] = edge_divisions(part[e].position, part[(e + 1u) % 3u].position);
    }
    plan_level();
}

// The macro-lattice level of the current part from its edge counts `tri_n`.
fn plan_level() {
    let m = max(max(tri_n[0], tri_n[1]), tri_n[2]);
    tri_k = 1u;
    if (is_adaptive()) {
        let step = min(params.max_div, PIECE_DIVISIONS);
        tri_k = min((m + step - 1u) / step, MAX_MACRO_LEVEL);
    } else if (params.method == METHOD_FIXED) {
        tri_k = (m + PIECE_DIVISIONS - 1u) / PIECE_DIVISIONS;
    }
}

// Where macro node (a, b, c)/K lies, as (kind, i, j): kind 0 = triangle corner i; kind 1 = fine
// node j (0 < j < n_i) of original edge i; kind 2 = interior. Nodes on an original edge snap to
// its fine nodes and may land on a corner. (`Location` in subdivide.rs.)
const CORNER: u32 = 0u;
const ON_EDGE: u32 = 1u;
const INTERIOR: u32 = 2u;

// The boundary edge a node (a, b, c) of a level-k lattice lies on, and its index along that edge
// from the edge's start: (0, b) for c = 0, (1, c) for a = 0, (2, a) for b = 0; edge 3 = interior.
// Both lattice levels (the macro pre-split and each piece) place such nodes on the edge's own
// nodes with `snap`. (`boundary_edge` and `snap` in subdivide.rs.)
fn boundary_edge(abc: vec3<u32>) -> vec2<u32> {
    if (abc.z == 0u) {
        return vec2<u32>(0u, abc.y);
    }
    if (abc.x == 0u) {
        return vec2<u32>(1u, abc.z);
    }
    if (abc.y == 0u) {
        return vec2<u32>(2u, abc.x);
    }
    return vec2<u32>(3u, 0u);
}

// The edge node nearest to lattice index idx of `level` on an edge of `count` parts.
fn snap(idx: u32, count: u32, level: u32) -> u32 {
    return (2u * idx * count + level) / (2u * level);
}

fn macro_location(abc: vec3<u32>) -> vec3<u32> {
    let on = boundary_edge(abc);
    let e = on.x;
    if (e == 3u) {
        return vec3<u32>(INTERIOR, 0u, 0u);
    }
    let j = snap(on.y, tri_n[e], tri_k);
    if (j == 0u) {
        return vec3<u32>(CORNER, e, 0u);
    }
    if (j == tri_n[e]) {
        return vec3<u32>(CORNER, (e + 1u) % 3u, 0u);
    }
    return vec3<u32>(ON_EDGE, e, j);
}

fn macro_node(abc: vec3<u32>, loc: vec3<u32>) -> Node {
    if (loc.x == CORNER) {
        return corner(loc.y);
    }
    if (loc.x == ON_EDGE) {
        return edge_point(corner(loc.y), corner((loc.y + 1u) % 3u), loc.z, tri_n[loc.y]);
    }
    return weighted(part, vec3<f32>(abc) / f32(tri_k));
}

// The node's fine index along original edge oe from its start, or −1 if it is not on that edge.
fn index_on(oe: u32, loc: vec3<u32>) -> i32 {
    if (loc.x == CORNER && loc.y == oe) {
        return 0;
    }
    if (loc.x == CORNER && loc.y == (oe + 1u) % 3u) {
        return i32(tri_n[oe]);
    }
    if (loc.x == ON_EDGE && loc.y == oe) {
        return i32(loc.z);
    }
    return -1;
}

struct Cell {
    c: array<vec3<u32>, 3>,
}

// Corners of cell `cell` of a level-k lattice (row r: k − r upward cells, then k − r − 1 downward).
fn macro_cell(k: u32, cell: u32) -> Cell {
    var rest = cell;
    var row = 0u;
    while (rest >= 2u * (k - row) - 1u) {
        rest -= 2u * (k - row) - 1u;
        row += 1u;
    }
    let up = k - row;
    var out: Cell;
    if (rest < up) {
        let j = rest;
        out.c[0] = vec3<u32>(k - row - j, j, row);
        out.c[1] = vec3<u32>(k - row - j - 1u, j + 1u, row);
        out.c[2] = vec3<u32>(k - row - j - 1u, j, row + 1u);
    } else {
        let j = rest - up;
        out.c[0] = vec3<u32>(k - row - j - 1u, j + 1u, row);
        out.c[1] = vec3<u32>(k - row - j - 2u, j + 1u, row + 1u);
        out.c[2] = vec3<u32>(k - row - j - 1u, j, row + 1u);
    }
    return out;
}

// The m-th node of piece edge e, from piece corner e towards corner e + 1.
fn node_on_edge(e: u32, m: u32) -> Node {
    let oe = piece_original[e];
    var a = piece_q[e];
    var b = piece_q[(e + 1u) % 3u];
    var j = m;
    var n = piece_counts[e];
    if (oe >= 0) {
        // On an original edge: the fine nodes of that edge, by their global index.
        let o = u32(oe);
        a = corner(o);
        b = corner((o + 1u) % 3u);
        n = tri_n[o];
        j = select(piece_from[e] + m, piece_from[e] - m, piece_to[e] < piece_from[e]);
    }
    return edge_point(a, b, j, n);
}

// The point with weights w of a triangle of nodes (positions and barycentric weights alike).
fn weighted(q: array<Node, 3>, w: vec3<f32>) -> Node {
    return Node(
        w.x * q[0].position + w.y * q[1].position + w.z * q[2].position,
        w.x * q[0].bary + w.y * q[1].bary + w.z * q[2].bary,
    );
}

fn interior_node(i: u32, j: u32, l: u32, m: u32) -> Node {
    return weighted(piece_q, vec3<f32>(f32(i), f32(j), f32(l)) / f32(m));
}

// ---- the parts around the vertical axis (src/cpu/subdivide/axis.rs) ----

// Moves a vertex within SNAP (relative to |x| + |z|) of the plane x = 0 or z = 0 onto it.
fn snap_to_cut_planes(p: vec3<f32>) -> vec3<f32> {
    let scale = SNAP * (abs(p.x) + abs(p.z));
    return vec3<f32>(select(p.x, 0.0, abs(p.x) <= scale), p.y, select(p.z, 0.0, abs(p.z) <= scale));
}

// The half-planes: CUT_X s·x ≥ 0, CUT_Z s·z ≥ 0, CUT_CHORD side·(sx·x + sz·z − c) ≥ 0 (beyond
// or within the diamond |x| + |z| = c of the quadrant).
const CUT_X: u32 = 0u;
const CUT_Z: u32 = 1u;
const CUT_CHORD: u32 = 2u;

struct Cut {
    kind: u32,
    s: vec2<f32>,
    c: f32,
    side: f32,
}

fn cut_distance(cut: Cut, p: vec3<f32>) -> f32 {
    if (cut.kind == CUT_X) {
        return cut.s.x * p.x;
    }
    if (cut.kind == CUT_Z) {
        return cut.s.y * p.z;
    }
    let d = cut.s.x * p.x + cut.s.y * p.z - cut.c;
    return select(cut.side * d, 0.0, abs(d) <= SNAP * (abs(p.x) + abs(p.z) + cut.c));
}

// The crossing of lo→hi (canonically ordered); on x = 0 or z = 0 that coordinate is set to 0.
fn cut_crossing(kind: u32, lo: Node, hi: Node, dl: f32, dh: f32) -> Node {
    let t = dl / (dl - dh);
    var n = Node(lo.position + (hi.position - lo.position) * t, lo.bary + (hi.bary - lo.bary) * t);
    let scale = SNAP * (abs(lo.position.x) + abs(lo.position.z) + abs(hi.position.x) + abs(hi.position.z));
    if (kind == CUT_X) {
        n.position.x = 0.0;
        n.position.z = select(n.position.z, 0.0, abs(n.position.z) <= scale);
    } else if (kind == CUT_Z) {
        n.position.z = 0.0;
        n.position.x = select(n.position.x, 0.0, abs(n.position.x) <= scale);
    }
    return n;
}

fn push_clipped(at: u32, n: u32, v: Node) -> u32 {
    if (n > 0u && same(v.position, pool[at + n - 1u].position)) {
        return n;
    }
    pool[at + n] = v;
    return n + 1u;
}

// Sutherland–Hodgman clip of the current polygon against one half-plane, into a slot that is
// neither its own, the quadrant's nor `keep_at`'s, which becomes the current polygon's; crossing
// points from the canonically ordered edge.
fn clip_polygon(cut: Cut) {
    var at = 0u;
    for (var slot = 0u; slot < 21u; slot += 7u) {
        if (slot != poly_at && slot != quadrant_at && slot != keep_at) {
            at = slot;
        }
    }
    var n = 0u;
    for (var i = 0u; i < poly_count; i++) {
        let cur = poly_node(i);
        let next = poly_node((i + 1u) % poly_count);
        let d0 = cut_distance(cut, cur.position);
        let d1 = cut_distance(cut, next.position);
        if (d0 >= 0.0) {
            n = push_clipped(at, n, cur);
        }
        if ((d0 >= 0.0) != (d1 >= 0.0) && d0 != 0.0 && d1 != 0.0) {
            if (lex_less(next.position, cur.position)) {
                n = push_clipped(at, n, cut_crossing(cut.kind, next, cur, d1, d0));
            } else {
                n = push_clipped(at, n, cut_crossing(cut.kind, cur, next, d0, d1));
            }
        }
    }
    if (n > 1u && same(pool[at + n - 1u].position, pool[at].position)) {
        n -= 1u;
    }
    if (n < 3u) {
        n = 0u;
    }
    poly_at = at;
    poly_count = n;
}

// Clips the input triangle to quadrant q (signs of x and z as in `QUADRANTS` of axis.rs).
fn quadrant_polygon(s: vec2<f32>) {
    poly_at = 0u;
    quadrant_at = 0u;
    keep_at = 0u;
    pool[0] = Node(tri_position[0], vec3<f32>(1.0, 0.0, 0.0));
    pool[1] = Node(tri_position[1], vec3<f32>(0.0, 1.0, 0.0));
    pool[2] = Node(tri_position[2], vec3<f32>(0.0, 0.0, 1.0));
    poly_count = 3u;
    // Quick tests (the clips would give the same): wholly on the far side of x = 0 or z = 0, or
    // two corners the same (no polygon); wholly inside the quadrant.
    let p = tri_position;
    let dx = vec3<f32>(s.x * p[0].x, s.x * p[1].x, s.x * p[2].x);
    let dz = vec3<f32>(s.y * p[0].z, s.y * p[1].z, s.y * p[2].z);
    if (all(dx < vec3<f32>(0.0)) || all(dz < vec3<f32>(0.0)) || same(p[0], p[1]) || same(p[1], p[2])
        || same(p[2], p[0])) {
        poly_count = 0u;
        return;
    }
    if (all(dx >= vec3<f32>(0.0)) && all(dz >= vec3<f32>(0.0))) {
        return;
    }
    clip_polygon(Cut(CUT_X, s, 0.0, 1.0));
    clip_polygon(Cut(CUT_Z, s, 0.0, 1.0));
}

// c_k = ρ·√2^k, exactly as the twin (`band_bound` in axis.rs): ρ or ρ·√2, times 2^(k/2).
fn band_bound(k: u32) -> f32 {
    let base = select(params.axis_clearance, params.axis_clearance * BAND_RATIO, (k & 1u) == 1u);
    return ldexp(base, i32(k / 2u));
}

// The largest k < MAX_DIAMONDS with c_k ≤ d (0 if none): an estimate from the logarithm, then
// exact steps. `band_of` in axis.rs.
fn band_of(d: f32) -> u32 {
    var k = u32(min(2.0 * log2(max(d / params.axis_clearance, 1.0)), f32(MAX_DIAMONDS - 1u)));
    loop {
        if (k == 0u || !(band_bound(k) > d)) {
            break;
        }
        k -= 1u;
    }
    loop {
        if (!(k + 1u < MAX_DIAMONDS && band_bound(k + 1u) <= d)) {
            break;
        }
        k += 1u;
    }
    return k;
}

fn cut_active(k: u32) -> bool {
    if (k < 32u) {
        return ((cuts.x >> k) & 1u) != 0u;
    }
    return k < 64u && ((cuts.y >> (k - 32u)) & 1u) != 0u;
}

// The next active diamond after k, or MAX_DIAMONDS. `next_cut` in axis.rs.
fn next_cut(k: u32) -> u32 {
    let j = k + 1u;
    if (j < 32u) {
        let low = cuts.x & (0xffffffffu << j);
        if (low != 0u) {
            return firstTrailingBit(low);
        }
    }
    if (j < 64u) {
        let high = cuts.y & (0xffffffffu << (max(j, 32u) - 32u));
        if (high != 0u) {
            return 32u + firstTrailingBit(high);
        }
    }
    return MAX_DIAMONDS;
}

// The largest active k with c_k ≤ d (k = 0, the square, always counts). `zone_of` in axis.rs.
fn zone_of(d: f32) -> u32 {
    var k = band_of(d);
    loop {
        if (k == 0u || cut_active(k)) {
            break;
        }
        k -= 1u;
    }
    return k;
}

// The smallest and largest |x| + |z| of the triangle's points (`diamond_range` in axis.rs).
fn diamond_range(p: array<vec3<f32>, 3>) -> vec2<f32> {
    let d = vec3<f32>(abs(p[0].x) + abs(p[0].z), abs(p[1].x) + abs(p[1].z), abs(p[2].x) + abs(p[2].z));
    let hi = max(max(d.x, d.y), d.z);
    var s: vec3<f32>;
    for (var e = 0u; e < 3u; e++) {
        let a = p[e];
        let b = p[(e + 1u) % 3u];
        s[e] = (b.z - a.z) * a.x - (b.x - a.x) * a.z;
    }
    if (all(s >= vec3<f32>(0.0)) || all(s <= vec3<f32>(0.0))) {
        return vec2<f32>(0.0, hi);
    }
    var lo = min(min(d.x, d.y), d.z);
    for (var e = 0u; e < 3u; e++) {
        let a = p[e];
        let b = p[(e + 1u) % 3u];
        if ((a.x < 0.0) != (b.x < 0.0) && a.x != 0.0 && b.x != 0.0) {
            lo = min(lo, abs(a.z + (b.z - a.z) * (a.x / (a.x - b.x))));
        }
        if ((a.z < 0.0) != (b.z < 0.0) && a.z != 0.0 && b.z != 0.0) {
            lo = min(lo, abs(a.x + (b.x - a.x) * (a.z / (a.z - b.z))));
        }
    }
    return vec2<f32>(lo, hi);
}

// The cuts the current triangle asks for (`triangle_cuts` in axis.rs), as bits 0–31, 32–63.
fn triangle_cuts(limit: f32) -> vec2<u32> {
    let range = diamond_range(tri_position);
    let lo = range.x;
    let hi = range.y;
    if (!asks_for_cuts(range)) {
        return vec2<u32>(0u);
    }
    var bits = vec2<u32>(1u, 0u);
    for (var k = 1u; k < MAX_DIAMONDS; k++) {
        let c = band_bound(k);
        if (c >= limit || c >= hi) {
            break;
        }
        if (lo < c) {
            if (k < 32u) {
                bits.x |= 1u << k;
            } else {
                bits.y |= 1u << (k - 32u);
            }
        }
    }
    return bits;
}

// Whether every corner of the polygon kept in `quadrant` is on the far side of the cut (x: the
// clip would be empty), or none is (y: the clip would change nothing). `Polygon::all_beyond`
// in axis.rs.
fn quadrant_beyond(cut: Cut) -> vec2<bool> {
    var beyond = true;
    var within = true;
    for (var i = 0u; i < quadrant_count; i++) {
        let d = cut_distance(cut, pool[quadrant_at + i].position);
        beyond = beyond && d < 0.0;
        within = within && d >= 0.0;
    }
    return vec2<bool>(beyond, within);
}

// Whether the input triangle lies strictly inside quadrant s and between two consecutive active
// diamonds: then it is its own single part. `single_band` in axis.rs.
fn single_band(s: vec2<f32>) -> bool {
    let p = tri_position;
    let dx = vec3<f32>(s.x * p[0].x, s.x * p[1].x, s.x * p[2].x);
    let dz = vec3<f32>(s.y * p[0].z, s.y * p[1].z, s.y * p[2].z);
    if (!(all(dx > vec3<f32>(0.0)) && all(dz > vec3<f32>(0.0)))) {
        return false;
    }
    let d = dx + dz;
    let k = zone_of(min(min(d.x, d.y), d.z));
    let lower = Cut(CUT_CHORD, s, band_bound(k), 1.0);
    let next = next_cut(k);
    let upper = Cut(CUT_CHORD, s, band_bound(min(next, MAX_DIAMONDS - 1u)), -1.0);
    for (var i = 0u; i < 3u; i++) {
        if (cut_distance(lower, p[i]) <= 0.0 || (next < MAX_DIAMONDS && cut_distance(upper, p[i]) <= 0.0)) {
            return false;
        }
    }
    return true;
}

const QUADRANT_SIGNS = array<vec2<f32>, 4>(vec2<f32>(1.0, -1.0), vec2<f32>(1.0, 1.0), vec2<f32>(-1.0, 1.0), vec2<f32>(-1.0, -1.0));

// Whether the current triangle is its own single part: no cuts this frame; not cut by all of
// them (`full` false: asks for none and has no edge of one that does) and no edge of a cut
// triangle (`marks`, its edges'); or one quadrant and one band (the loop of `plan_quadrant`
// would give that part).
fn single_part(full: bool, marks: vec3<u32>) -> bool {
    if (all(cuts == vec2<u32>(0u))) {
        return true;
    }
    if (!full) {
        return all((marks & vec3<u32>(EDGE_CUT)) == vec3<u32>(0u));
    }
    for (var q = 0u; q < 4u; q++) {
        if (single_band(QUADRANT_SIGNS[q])) {
            return true;
        }
    }
    return false;
}

// Plans every part of the current triangle in quadrant q (`polygons` in axis.rs: band by band
// outwards, along each fan) and appends its pieces.
fn plan_quadrant(t: u32, q: u32) {
    let signs = QUADRANT_SIGNS;
    {
        let s = signs[q];
        quadrant_polygon(s);
        if (poly_count == 0u) {
            return;
        }
        // What lies beyond the current diamond (`rest` in axis.rs); each band is cut from it,
        // and the rest beyond the next diamond from the same polygon.
        clip_polygon(Cut(CUT_CHORD, s, params.axis_clearance, 1.0));
        quadrant_at = poly_at;
        quadrant_count = poly_count;
        // Start at the band of the nearest corner: the bands below are empty, and cutting them
        // away would leave the polygon as it is (the twin runs them; the parts are the same).
        var d_min = 1e30;
        for (var i = 0u; i < quadrant_count; i++) {
            d_min = min(d_min, s.x * pool[quadrant_at + i].position.x + s.y * pool[quadrant_at + i].position.z);
        }
        var k = zone_of(d_min);
        loop {
            if (quadrant_count == 0u) {
                break;
            }
            k = next_cut(k);
            let c = band_bound(min(k, MAX_DIAMONDS - 1u));
            if (k >= MAX_DIAMONDS) {
                poly_at = quadrant_at;
                poly_count = quadrant_count;
                quadrant_count = 0u; // the last band: all the rest
            } else {
                let within = Cut(CUT_CHORD, s, c, -1.0);
                let test = quadrant_beyond(within);
                if (test.x) {
                    continue; // all of it lies beyond this band
                }
                poly_at = quadrant_at;
                poly_count = quadrant_count;
                if (test.y) {
                    quadrant_count = 0u;
                } else {
                    clip_polygon(within);
                    let band_at = poly_at;
                    let band_count = poly_count;
                    keep_at = band_at;
                    poly_at = quadrant_at;
                    poly_count = quadrant_count;
                    clip_polygon(Cut(CUT_CHORD, s, c, 1.0));
                    quadrant_at = poly_at;
                    quadrant_count = poly_count;
                    poly_at = band_at;
                    poly_count = band_count;
                    keep_at = quadrant_at;
                }
            }
            // The fan's parts: those wholly beyond the image's rows make no pieces (`run` in
            // subdivide.rs); the others' edges, each counted once (a diagonal is two parts').
            var shown = 0u;
            var needed = 0u;
            for (var i = 1u; i + 1u < poly_count; i++) {
                if (!off_screen_vertically(poly_node(0).position, poly_node(i).position, poly_node(i + 1u).position)) {
                    shown |= 1u << i;
                    let e = fan_edges(i);
                    needed |= (1u << e.x) | (1u << e.y) | (1u << e.z);
                }
            }
            for (var e = 0u; e + 3u < 2u * poly_count; e++) {
                if ((needed & (1u << e)) != 0u) {
                    let ends = polygon_edge_ends(e);
                    poly_n[e] = edge_divisions(poly_node(ends.x).position, poly_node(ends.y).position);
                }
            }
            if (plan_quad(shown)) {
                append_quad(t);
                continue;
            }
            for (var i = 1u; i + 1u < poly_count; i++) {
                if ((shown & (1u << i)) != 0u) {
                    part[0] = poly_node(0);
                    part[1] = poly_node(i);
                    part[2] = poly_node(i + 1u);
                    let e = fan_edges(i);
                    tri_n[0] = poly_n[e.x];
                    tri_n[1] = poly_n[e.y];
                    tri_n[2] = poly_n[e.z];
                    plan_level();
                    append_pieces(t);
                }
            }
        }
    }
}

// ---- a triangle that asks for no cuts, cut at edges it shares with ones that do ----

// The marks of triangle t's three edges (EDGE_ASKING, EDGE_CUT; `FrameCuts` in subdivide.rs),
// while they are being set (`ring_cuts`), and once they are (`plan`, `plan_cuts`).
fn edge_marks_now(t: u32) -> vec3<u32> {
    var marks: vec3<u32>;
    for (var e = 0u; e < 3u; e++) {
        let id = triangle_edges[3u * t + e];
        marks[e] = mark_in(atomicLoad(&cut_edges[id / 16u]), id);
    }
    return marks;
}

fn edge_marks(t: u32) -> vec3<u32> {
    var marks: vec3<u32>;
    for (var e = 0u; e < 3u; e++) {
        let id = triangle_edges[3u * t + e];
        marks[e] = mark_in(edge_marks_read[id / 16u], id);
    }
    return marks;
}

// Edge id's two bits in its word of `cut_edges`.
fn mark_in(word: u32, id: u32) -> u32 {
    return (word >> (2u * (id % 16u))) & 3u;
}

// Sets marks on triangle t's three edges.
fn mark_edges(t: u32, marks: u32) {
    for (var e = 0u; e < 3u; e++) {
        let id = triangle_edges[3u * t + e];
        atomicOr(&cut_edges[id / 16u], marks << (2u * (id % 16u)));
    }
}

// Whether a triangle with edge marks `marks` has an edge of a triangle that asks for cuts: then
// it is cut by all of them (`FrameCuts::is_cut_triangle`).
fn cut_triangle(marks: vec3<u32>) -> bool {
    return any((marks & vec3<u32>(EDGE_ASKING)) != vec3<u32>(0u));
}

// The segment being clipped (`clip_segment` in axis.rs), the edge it is part of, and where that
// edge's crossings start in the pool.
var<private> seg_p: Node;
var<private> seg_q: Node;
var<private> seg_live: bool;
var<private> edge_ends: array<vec3<f32>, 2>;
var<private> run_start: u32;

// Appends a crossing of the current edge to the pool, unless it is an end of the edge or there
// already (a plane's crossing is found in two or four quadrants).
fn add_crossing(n: Node) {
    if (same(n.position, edge_ends[0]) || same(n.position, edge_ends[1])) {
        return;
    }
    for (var i = run_start; i < poly_count; i++) {
        if (same(pool[i].position, n.position)) {
            return;
        }
    }
    if (poly_count < 21u) {
        pool[poly_count] = n;
        poly_count += 1u;
    }
}

// Clips the segment to the side cut ≥ 0 as `clip_polygon` clips a polygon's edge, keeping the
// crossing (`clip_segment` in axis.rs).
fn clip_segment(cut: Cut) {
    if (!seg_live) {
        return;
    }
    let dp = cut_distance(cut, seg_p.position);
    let dq = cut_distance(cut, seg_q.position);
    if ((dp >= 0.0) != (dq >= 0.0) && dp != 0.0 && dq != 0.0) {
        var x: Node;
        if (lex_less(seg_q.position, seg_p.position)) {
            x = cut_crossing(cut.kind, seg_q, seg_p, dq, dp);
        } else {
            x = cut_crossing(cut.kind, seg_p, seg_q, dp, dq);
        }
        add_crossing(x);
        if (dp >= 0.0) {
            seg_q = x;
        } else {
            seg_p = x;
        }
        return;
    }
    seg_live = dp >= 0.0 && dq >= 0.0;
}

// Appends to the pool the points where a cut triangle cuts edge a → b (ends excluded), in order
// from a (`edge_crossings` in axis.rs): the same clips in the same order, on the edge alone.
fn edge_crossings(a: Node, b: Node) {
    run_start = poly_count;
    edge_ends = array<vec3<f32>, 2>(a.position, b.position);
    for (var q = 0u; q < 4u; q++) {
        let s = QUADRANT_SIGNS[q];
        seg_p = a;
        seg_q = b;
        seg_live = true;
        clip_segment(Cut(CUT_X, s, 0.0, 1.0));
        clip_segment(Cut(CUT_Z, s, 0.0, 1.0));
        clip_segment(Cut(CUT_CHORD, s, params.axis_clearance, 1.0));
        var k = 0u;
        loop {
            k = next_cut(k);
            if (!seg_live || k >= MAX_DIAMONDS) {
                break;
            }
            clip_segment(Cut(CUT_CHORD, s, band_bound(k), 1.0));
        }
    }
    // In order along the edge (insertion sort; a few points).
    let dir = b.position - a.position;
    for (var i = run_start + 1u; i < poly_count; i++) {
        let n = pool[i];
        let key = dot(n.position - a.position, dir);
        var j = i;
        loop {
            if (j == run_start || !(dot(pool[j - 1u].position - a.position, dir) > key)) {
                break;
            }
            pool[j] = pool[j - 1u];
            j -= 1u;
        }
        pool[j] = n;
    }
}

// Plans part (apex, pool[i], pool[i + 1 mod the polygon's count]) unless it is off screen.
fn plan_apex_part(t: u32, apex: Node, i: u32) {
    part[0] = apex;
    part[1] = pool[i];
    part[2] = pool[(i + 1u) % poly_count];
    if (!off_screen_vertically(part[0].position, part[1].position, part[2].position)) {
        plan_part();
        append_pieces(t);
    }
}

// Plans the parts of triangle t, which is not cut by all cuts, at the crossings of its edges that
// cut triangles have (`edge_split_parts` in axis.rs): its boundary (corner e, then edge e's
// crossings) in the pool; with crossings on one edge the fan from the opposite corner, on more
// the fan from the centroid, on none the triangle.
fn plan_edge_split(t: u32) {
    let corners = array<Node, 3>(Node(tri_position[0], vec3<f32>(1.0, 0.0, 0.0)),
                                 Node(tri_position[1], vec3<f32>(0.0, 1.0, 0.0)),
                                 Node(tri_position[2], vec3<f32>(0.0, 0.0, 1.0)));
    poly_count = 0u;
    var crossed = 0u;
    var chain = vec3<u32>(0u); // the crossed edge, its corner's slot, its nodes before the next corner
    let marks = edge_marks(t);
    for (var e = 0u; e < 3u; e++) {
        let at = poly_count;
        pool[at] = corners[e];
        poly_count += 1u;
        if ((marks[e] & EDGE_CUT) != 0u) {
            edge_crossings(corners[e], corners[(e + 1u) % 3u]);
        }
        if (poly_count > at + 1u) {
            crossed += 1u;
            chain = vec3<u32>(e, at, poly_count - at);
        }
    }
    if (crossed == 0u) {
        part = corners;
        plan_part();
        append_pieces(t);
    } else if (crossed == 1u) {
        for (var i = 0u; i < chain.z; i++) {
            plan_apex_part(t, corners[(chain.x + 2u) % 3u], chain.y + i);
        }
    } else {
        let centre = weighted(corners, vec3<f32>(1.0 / 3.0));
        for (var i = 0u; i < poly_count; i++) {
            plan_apex_part(t, centre, i);
        }
    }
}

// The edges of the polygon in `poly` and its fan: side e (corner e → e + 1, the last back to
// corner 0) for e < poly_count, then diagonal d (corner 0 → d + 2) at poly_count + d. The ends of
// edge e, as corner indices.
fn polygon_edge_ends(e: u32) -> vec2<u32> {
    if (e < poly_count) {
        return vec2<u32>(e, (e + 1u) % poly_count);
    }
    return vec2<u32>(0u, e - poly_count + 2u);
}

// The edges of fan part i (corners 0, i, i + 1): 0 → i, i → i + 1, i + 1 → 0.
fn fan_edges(i: u32) -> vec3<u32> {
    let first = select(poly_count + i - 2u, 0u, i == 1u);
    let last = select(poly_count + i - 1u, poly_count - 1u, i + 2u == poly_count);
    return vec3<u32>(first, i, last);
}

// Whether the band polygon in `poly` (both fan parts `shown`, edge counts in `poly_n`) is drawn as one strip between two of its sides (the rails)
// rather than as the two parts of its fan (`quad_strip` in subdivide.rs); then `strip_n` holds
// the rails' counts and `quad_turn` the polygon corner that becomes the quad's corner 0 (rails
// 0 → 1 and 3 → 2).
fn plan_quad(shown: u32) -> bool {
    if (params.method != METHOD_ERROR || is_sphere(params.projection) || poly_count != 4u || shown != 6u) {
        return false;
    }
    var turn = 2u;
    for (var r = 0u; r < 2u; r++) {
        if (turn == 2u && poly_n[r + 1u] == 1u && poly_n[(r + 3u) % 4u] == 1u) {
            turn = r;
        }
    }
    if (turn == 2u) {
        return false;
    }
    let rails = vec2<u32>(poly_n[turn], poly_n[turn + 2u]);
    let longest = max(rails.x, rails.y);
    if (longest < QUAD_MIN_DIVISIONS || longest > min(params.max_div, PIECE_DIVISIONS)) {
        return false;
    }
    // Every rung of the zigzag (`quad_strip_rungs` in subdivide.rs), the one-part sides among them.
    let c0 = poly_node(turn);
    let c1 = poly_node(turn + 1u);
    let c2 = poly_node((turn + 2u) % 4u);
    let c3 = poly_node((turn + 3u) % 4u);
    var walk = vec2<u32>(0u, 0u);
    for (var step = 0u; step <= rails.x + rails.y; step++) {
        let a = edge_point(c0, c1, walk.x, rails.x).position;
        let b = edge_point(c3, c2, walk.y, rails.y).position;
        let q = edge_profile(a, b, 2u);
        if (q.ring || parts_for_bend(q.bend_px, 2u, QUAD_RUNG_ERROR * tri_max_error_px) > 1.0) {
            return false;
        }
        if (quad_advances_on_a(walk, rails)) {
            walk.x += 1u;
        } else {
            walk.y += 1u;
        }
    }
    strip_n = rails;
    quad_turn = turn;
    return true;
}

// A band quad's two records: corners 0–2 and the rails' counts (QUAD_HEAD), then corner 3
// (QUAD_TAIL, whose `lattice` invocation draws nothing).
fn append_quad(t: u32) {
    let base = atomicAdd(&counters.pieces, 2u);
    if (base + 2u > params.piece_capacity) {
        return; // counted, never written
    }
    var record: Piece;
    record.triangle = t;
    record.cell = 0u;
    record.counts01 = strip_n.x | (strip_n.y << 16u);
    record.count2_level = QUAD_HEAD;
    for (var i = 0u; i < 3u; i++) {
        let c = poly_node((quad_turn + i) % 4u);
        record.corner[i] = vec4<f32>(c.position, c.bary.x);
        record.bary1[i] = c.bary.y;
        record.bary2[i] = c.bary.z;
    }
    pieces[base] = record;
    let last = poly_node((quad_turn + 3u) % 4u);
    record.count2_level = QUAD_TAIL;
    record.corner[0] = vec4<f32>(last.position, last.bary.x);
    record.bary1[0] = last.bary.y;
    record.bary2[0] = last.bary.z;
    pieces[base + 1u] = record;
}

fn append_pieces(t: u32) {
    let count = tri_k * tri_k;
    let base = atomicAdd(&counters.pieces, count);
    if (base + count > params.piece_capacity) {
        return; // counted, never written
    }
    var record: Piece;
    record.triangle = t;
    record.counts01 = tri_n[0] | (tri_n[1] << 16u);
    record.count2_level = tri_n[2] | (tri_k << 16u);
    for (var i = 0u; i < 3u; i++) {
        record.corner[i] = vec4<f32>(part[i].position, part[i].bary.x);
        record.bary1[i] = part[i].bary.y;
        record.bary2[i] = part[i].bary.z;
    }
    for (var c = 0u; c < count; c++) {
        record.cell = c;
        pieces[base + c] = record;
    }
}

// ---- emission ----

fn draw_vertex(n: Node, theta_ref: f32) -> DrawVertex {
    let b = n.bary;
    return DrawVertex(
        n.position,
        theta_ref,
        b.x * tri_normal[0] + b.y * tri_normal[1] + b.z * tri_normal[2],
        tri_material,
        b.x * tri_color[0] + b.y * tri_color[1] + b.z * tri_color[2],
        b.x * tri_uv[0] + b.y * tri_uv[1] + b.z * tri_uv[2],
        tri_object,
        pack_tangent(b.x * tri_tangent[0] + b.y * tri_tangent[1] + b.z * tri_tangent[2]),
    );
}

fn visible_edge_px(p: array<vec3<f32>, 3>) -> f32 {
    let half_h = 0.5 * params.projection.height;
    let width = params.projection.width;
    var longest = 0.0;
    for (var s = 0u; s < 2u; s++) {
        let eye_sign = select(-1.0, 1.0, s == 1u);
        let q = array<vec2<f32>, 3>(pixel(p[0], eye_sign), pixel(p[1], eye_sign), pixel(p[2], eye_sign));
        for (var e = 0u; e < 3u; e++) {
            let a = q[e];
            let b = q[(e + 1u) % 3u];
            if (abs(a.y) <= half_h || abs(b.y) <= half_h) {
                let dx = (b.x - a.x) - width * round((b.x - a.x) / width);
                longest = max(longest, length(vec2<f32>(dx, b.y - a.y)));
            }
        }
    }
    return longest;
}

// ---- the lattice of a piece: its nodes once, its triangles as indices ----

// Node (i, j, l) of the piece's lattice of level m: the regular lattice, whose boundary nodes on
// an edge with fewer divisions snap to that edge's nearest node (see subdivide.rs).
fn lattice_node(c: vec3<u32>, m: u32) -> Node {
    let on = boundary_edge(c);
    if (on.x < 3u) {
        return node_on_edge(on.x, snap(on.y, piece_counts[on.x], m));
    }
    return interior_node(c.x, c.y, c.z, m);
}

// Slot of lattice node (i, j, l) among the piece's (m + 1)(m + 2)/2: rows l = 0..m of m + 1 − l
// nodes, by j (`node_slot` in subdivide.rs).
fn node_slot(c: vec3<u32>, m: u32) -> u32 {
    return c.z * (2u * m + 3u - c.z) / 2u + c.y;
}

// ---- the strip of a sliver piece (`strip_triangles` in subdivide.rs) ----

// On the cylinder, under the error split, the base edge (one part, chord error within
// STRIP_BASE_ERROR·τ by the quick profile, away from the eye circle) of a piece with another edge
// in STRIP_MIN_DIVISIONS or more parts; 3: the regular lattice (`strip_base` in subdivide.rs).
fn strip_base_of() -> u32 {
    let m = max(max(piece_counts[0], piece_counts[1]), piece_counts[2]);
    if (params.method != METHOD_ERROR || is_sphere(params.projection) || m < STRIP_MIN_DIVISIONS) {
        return 3u;
    }
    var base = 3u;
    for (var e = 0u; e < 3u; e++) {
        if (base == 3u && piece_counts[e] == 1u) {
            base = e;
        }
    }
    if (base < 3u) {
        let p = edge_profile(piece_q[base].position, piece_q[(base + 1u) % 3u].position, 2u);
        if (p.ring || parts_for_bend(p.bend_px, 2u, STRIP_BASE_ERROR * tri_max_error_px) > 1.0) {
            return 3u;
        }
    }
    return base;
}

// Node `slot` of the strip: edge base + 1's nodes from its corner to the apex, then edge
// base + 2's after the apex.
fn strip_node(slot: u32) -> Node {
    if (slot <= strip_n.x) {
        return node_on_edge((strip_base + 1u) % 3u, slot);
    }
    return node_on_edge((strip_base + 2u) % 3u, slot - strip_n.x);
}

// The next triangle of the strip's walk at `walk` = (i, j) (left L_i = slot n1 + n2 − i, right
// R_j = slot j), as slots; advances the walk.
fn strip_step(walk: ptr<function, vec2<u32>>) -> vec3<u32> {
    let i = (*walk).x;
    let j = (*walk).y;
    let n1 = strip_n.x;
    let n2 = strip_n.y;
    if (i < n2 && (j == n1 || (i + 1u) * n1 <= (j + 1u) * n2)) {
        *walk = vec2<u32>(i + 1u, j);
        return vec3<u32>(n1 + n2 - i, j, n1 + n2 - i - 1u);
    }
    *walk = vec2<u32>(i, j + 1u);
    return vec3<u32>(n1 + n2 - i, j, j + 1u);
}

// ---- a band quad drawn as a strip between its rails (`quad_strip_triangles` in subdivide.rs) ----

const QUAD_STRIP: u32 = 4u; // `strip_base` of a quad

// Node `slot`: rail a (corner 0 → 1, strip_n.x parts), then rail d (corner 3 → 2, strip_n.y).
fn quad_node(slot: u32) -> Node {
    if (slot <= strip_n.x) {
        return edge_point(piece_q[0], piece_q[1], slot, strip_n.x);
    }
    return edge_point(quad_last, piece_q[2], slot - strip_n.x - 1u, strip_n.y);
}

// Whether the zigzag at rung (a_i, d_j) = `walk` advances on rail a (`quad_advances_on_a`).
fn quad_advances_on_a(walk: vec2<u32>, rails: vec2<u32>) -> bool {
    return walk.x < rails.x && (walk.y == rails.y || (walk.x + 1u) * rails.y <= (walk.y + 1u) * rails.x);
}

// The next triangle of the zigzag at `walk` = (i, j) (rail a's node i = slot i, rail d's node j =
// slot n1 + 1 + j), as slots; advances the walk.
fn quad_step(walk: ptr<function, vec2<u32>>) -> vec3<u32> {
    let i = (*walk).x;
    let j = (*walk).y;
    let n1 = strip_n.x;
    if (quad_advances_on_a(*walk, strip_n)) {
        *walk = vec2<u32>(i + 1u, j);
        return vec3<u32>(i, i + 1u, n1 + 1u + j);
    }
    *walk = vec2<u32>(i, j + 1u);
    return vec3<u32>(i, n1 + 2u + j, n1 + 1u + j);
}

// ---- a piece's nodes and candidate triangles: the lattice of level m, the strip or the quad ----

// Node k in slot order; `row` is the lattice's running (j, l), advanced here.
fn piece_node(k: u32, m: u32, row: ptr<function, vec2<u32>>) -> Node {
    if (strip_base == QUAD_STRIP) {
        return quad_node(k);
    }
    if (strip_base < 3u) {
        return strip_node(k);
    }
    let j = (*row).x;
    let l = (*row).y;
    *row = select(vec2<u32>(j + 1u, l), vec2<u32>(0u, l + 1u), j + 1u > m - l);
    return lattice_node(vec3<u32>(m - j - l, j, l), m);
}

// Candidate triangle t's slots (the strip's in walk order, advancing `walk`).
fn piece_triangle_slots(t: u32, m: u32, walk: ptr<function, vec2<u32>>) -> vec3<u32> {
    if (strip_base == QUAD_STRIP) {
        return quad_step(walk);
    }
    if (strip_base < 3u) {
        return strip_step(walk);
    }
    let cell = macro_cell(m, t);
    return vec3<u32>(node_slot(cell.c[0], m), node_slot(cell.c[1], m), node_slot(cell.c[2], m));
}

// Whether candidate triangle t is drawn: not collapsed by snapping, not off screen.
fn piece_triangle_drawn(t: u32, m: u32, walk: ptr<function, vec2<u32>>) -> bool {
    var a: vec3<f32>;
    var b: vec3<f32>;
    var c: vec3<f32>;
    if (strip_base == QUAD_STRIP) {
        let s = quad_step(walk);
        a = quad_node(s.x).position;
        b = quad_node(s.y).position;
        c = quad_node(s.z).position;
    } else if (strip_base < 3u) {
        let s = strip_step(walk);
        a = strip_node(s.x).position;
        b = strip_node(s.y).position;
        c = strip_node(s.z).position;
    } else {
        let cell = macro_cell(m, t);
        a = lattice_node(cell.c[0], m).position;
        b = lattice_node(cell.c[1], m).position;
        c = lattice_node(cell.c[2], m).position;
    }
    return !(same(a, b) || same(b, c) || same(c, a) || off_screen_vertically(a, b, c));
}

// The u range (both eyes) of the piece's triangle on the cylinder, from its corners
// (`piece_u_range` in subdivide.rs): its azimuths span those of its corners (its footprint is
// convex and misses the axis), and α(r) grows with r, so |α| is largest at the footprint's
// nearest or farthest point from the axis.
fn piece_u_range(q: array<Node, 3>, theta_c: f32) -> vec2<f32> {
    var theta_min = 1e30;
    var theta_max = -1e30;
    var r_min = 1e30;
    var r_max = 0.0;
    for (var e = 0u; e < 3u; e++) {
        let a = q[e].position.xz;
        let b = q[(e + 1u) % 3u].position.xz;
        let theta = theta_c + wrap_angle(azimuth(q[e].position) - theta_c);
        theta_min = min(theta_min, theta);
        theta_max = max(theta_max, theta);
        r_max = max(r_max, length(a));
        let ab = b - a;
        let t = clamp(-dot(a, ab) / max(dot(ab, ab), 1e-30), 0.0, 1.0);
        r_min = min(r_min, length(a + t * ab));
    }
    let alpha = max(abs(eye_shift(params.projection, r_min)), abs(eye_shift(params.projection, r_max)));
    return vec2<f32>(theta_min - alpha, theta_max + alpha);
}

// ---- entry points ----

fn invocation_index(gid: vec3<u32>, groups: vec3<u32>) -> u32 {
    return gid.x + gid.y * groups.x * 64u;
}

// Over every triangle of the scene, before `plan` (and before every chunk of a chunked frame).
@compute @workgroup_size(64)
fn active_cuts(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    let local = invocation_index(gid, groups);
    if (local >= params.triangle_count) {
        return;
    }
    load_positions(params.first_triangle + local);
    if (off_screen_vertically(tri_position[0], tri_position[1], tri_position[2])) {
        return;
    }
    // Diamonds for the adaptive method only (`band_limit` in axis.rs).
    let limit = select(0.0, BAND_LIMIT * params.projection.screen_radius, is_adaptive());
    let bits = triangle_cuts(limit);
    if (bits.x != 0u) {
        atomicOr(&counters.cuts_low, bits.x);
    }
    if (bits.y != 0u) {
        atomicOr(&counters.cuts_high, bits.y);
    }
    if (any(bits != vec2<u32>(0u))) {
        let t = params.first_triangle + local;
        mark_edges(t, EDGE_ASKING | EDGE_CUT);
    }
}

// Over every triangle of the scene, after `active_cuts`: a triangle that asks for no cuts but
// has an edge of one that does is cut too; its edges are marked as cut ones'.
@compute @workgroup_size(64)
fn ring_cuts(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    let local = invocation_index(gid, groups);
    if (local >= params.triangle_count) {
        return;
    }
    let t = params.first_triangle + local;
    // The bits first: most triangles have no such edge, and need not be loaded. (A triangle
    // that asks is marked already; marking it again changes nothing.)
    if (!cut_triangle(edge_marks_now(t))) {
        return;
    }
    load_positions(t);
    if (off_screen_vertically(tri_position[0], tri_position[1], tri_position[2])) {
        return;
    }
    mark_edges(t, EDGE_CUT);
}

@compute @workgroup_size(64)
fn plan(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    let local = invocation_index(gid, groups);
    if (local >= params.triangle_count) {
        return;
    }
    let t = params.first_triangle + local;
    cuts = vec2<u32>(atomicLoad(&counters.cuts_low), atomicLoad(&counters.cuts_high));
    load_triangle(t);
    if (off_screen_vertically(tri_position[0], tri_position[1], tri_position[2])) {
        return; // no pieces
    }
    // Cut by all of the frame's cuts (decided only when there are any; the marks first).
    var marks = vec3<u32>(0u);
    var full = false;
    if (any(cuts != vec2<u32>(0u))) {
        marks = edge_marks(t);
        full = cut_triangle(marks) || asks_for_cuts(diamond_range(tri_position));
    }
    if (single_part(full, marks)) {
        part[0] = Node(tri_position[0], vec3<f32>(1.0, 0.0, 0.0));
        part[1] = Node(tri_position[1], vec3<f32>(0.0, 1.0, 0.0));
        part[2] = Node(tri_position[2], vec3<f32>(0.0, 0.0, 1.0));
        plan_part();
        append_pieces(t);
        return;
    }
    // Triangles cut by all of the frame's cuts (a floor around the viewer and its neighbours)
    // make many parts; listed apart (at the back), they share SIMD lanes with each other rather
    // than stall lanes of the triangles listed for their shared edges.
    let len = arrayLength(&cut_list);
    if (full) {
        let slot = atomicAdd(&counters.cut_wide, 1u);
        if (slot < len) {
            cut_list[len - 1u - slot] = t;
        }
    } else {
        let slot = atomicAdd(&counters.cut_count, 1u);
        if (slot < len) {
            cut_list[slot] = t;
        }
    }
}

// Whether a triangle with diamond distances `range` (`diamond_range`) reaches the first diamond
// or spans a wide range of them: those ask for cuts (`triangle_cuts`).
fn asks_for_cuts(range: vec2<f32>) -> bool {
    return range.x < band_bound(1u) || range.y > WIDE_RATIO * range.x;
}

// The triangles `plan` listed, and the i-th of them: the narrow ones from the front of
// `cut_list`, then the wide ones from its back.
fn listed_cuts() -> vec2<u32> {
    let len = arrayLength(&cut_list);
    return vec2<u32>(min(atomicLoad(&counters.cut_count), len), min(atomicLoad(&counters.cut_wide), len));
}

fn listed_cut(i: u32, listed: vec2<u32>) -> u32 {
    if (i < listed.x) {
        return cut_list[i];
    }
    return cut_list[arrayLength(&cut_list) - 1u - (i - listed.x)];
}

// Invocations of `plan_cuts` per listed triangle: one per quadrant on the sphere, whose bands reach
// 10⁻⁵ m from the axis (many more bands: one quadrant's keep an invocation within lavapipe's loop
// budget, which stops any invocation after 65,535 loop iterations); one per triangle on the
// cylinder (its few bands fit, and lanes of a triangle's empty quadrants would idle).
fn plan_cuts_split() -> u32 {
    return select(1u, 4u, (PANORAMAS & 2u) != 0u);
}

@compute @workgroup_size(1)
fn plan_cuts_args() {
    let listed = listed_cuts();
    let groups = (plan_cuts_split() * min(listed.x + listed.y, arrayLength(&cut_list)) + 63u) / 64u;
    lattice_dispatch[3] = min(groups, 65535u);
    lattice_dispatch[4] = (groups + 65534u) / 65535u;
    lattice_dispatch[5] = 1u;
}

@compute @workgroup_size(64)
fn plan_cuts(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    let local = invocation_index(gid, groups);
    let split = plan_cuts_split();
    let listed = listed_cuts();
    if (local / split >= min(listed.x + listed.y, arrayLength(&cut_list))) {
        return;
    }
    let t = listed_cut(local / split, listed);
    cuts = vec2<u32>(atomicLoad(&counters.cuts_low), atomicLoad(&counters.cuts_high));
    load_triangle(t);
    if (local / split < listed.x) {
        // Cut only at its shared edges' crossings (one invocation of `split`).
        if (local % split == 0u) {
            plan_edge_split(t);
        }
        return;
    }
    if (split == 4u) {
        plan_quadrant(t, local % 4u);
    } else {
        for (var q = 0u; q < 4u; q++) {
            plan_quadrant(t, q);
        }
    }
}

@compute @workgroup_size(64)
fn lattice(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    let local = invocation_index(gid, groups);
    var piece_count = params.piece_count;
    if (piece_count == PIECES_FROM_COUNTER) {
        piece_count = min(atomicLoad(&counters.pieces), params.piece_capacity);
    }
    if (local >= piece_count) {
        return;
    }
    let piece = pieces[params.first_piece + local];
    if ((piece.count2_level & QUAD_TAIL) != 0u) {
        return; // drawn by the quad's first record
    }
    load_triangle(piece.triangle);
    for (var i = 0u; i < 3u; i++) {
        part[i] = Node(piece.corner[i].xyz, vec3<f32>(piece.corner[i].w, piece.bary1[i], piece.bary2[i]));
    }
    var m = 0u;
    var candidates = 0u;
    var node_count = 0u;
    var theta_c = 0.0;
    if ((piece.count2_level & QUAD_HEAD) != 0u) {
        // A band quad: corners 0–2 here, corner 3 in the next record; its rails' counts.
        piece_q = part;
        let tail = pieces[params.first_piece + local + 1u];
        quad_last = Node(tail.corner[0].xyz, vec3<f32>(tail.corner[0].w, tail.bary1[0], tail.bary2[0]));
        strip_base = QUAD_STRIP;
        strip_n = vec2<u32>(piece.counts01 & 0xffffu, piece.counts01 >> 16u);
        m = max(strip_n.x, strip_n.y);
        candidates = strip_n.x + strip_n.y;
        node_count = candidates + 2u;
        theta_c = azimuth((piece_q[0].position + piece_q[1].position + piece_q[2].position + quad_last.position) / 4.0);
    } else {
        tri_n[0] = piece.counts01 & 0xffffu;
        tri_n[1] = piece.counts01 >> 16u;
        tri_n[2] = piece.count2_level & 0xffffu;
        tri_k = piece.count2_level >> 16u;
        let cell = macro_cell(tri_k, piece.cell);
        var loc: array<vec3<u32>, 3>;
        for (var i = 0u; i < 3u; i++) {
            loc[i] = macro_location(cell.c[i]);
            piece_q[i] = macro_node(cell.c[i], loc[i]);
        }
        if (same(piece_q[0].position, piece_q[1].position) || same(piece_q[1].position, piece_q[2].position)
            || same(piece_q[2].position, piece_q[0].position)) {
            return; // snapped corners coincide: no area
        }
        if (off_screen_vertically(piece_q[0].position, piece_q[1].position, piece_q[2].position)) {
            return; // every sub-triangle would be culled
        }
        // Each piece edge: on an original edge (that edge's fine nodes, by global index) or interior.
        for (var e = 0u; e < 3u; e++) {
            piece_original[e] = -1;
            for (var oe = 0u; oe < 3u; oe++) {
                let start = index_on(oe, loc[e]);
                let end = index_on(oe, loc[(e + 1u) % 3u]);
                if (piece_original[e] < 0 && start >= 0 && end >= 0) {
                    piece_original[e] = i32(oe);
                    piece_from[e] = u32(start);
                    piece_to[e] = u32(end);
                    piece_counts[e] = u32(abs(start - end));
                }
            }
            if (piece_original[e] < 0) {
                if (params.method == METHOD_FIXED) {
                    // fixed:N pieces take N/K on interior edges (the regular N-lattice when K | N).
                    piece_counts[e] = (params.fixed_n + tri_k - 1u) / tri_k;
                } else {
                    piece_counts[e] = min(min(edge_divisions(piece_q[e].position, piece_q[(e + 1u) % 3u].position), 2u * params.max_div), PIECE_DIVISIONS);
                }
            }
        }
        m = max(max(piece_counts[0], piece_counts[1]), piece_counts[2]);
        strip_base = strip_base_of();
        candidates = m * m;
        node_count = (m + 1u) * (m + 2u) / 2u;
        if (strip_base < 3u) {
            strip_n = vec2<u32>(piece_counts[(strip_base + 1u) % 3u], piece_counts[(strip_base + 2u) % 3u]);
            candidates = strip_n.x + strip_n.y - 1u;
            node_count = strip_n.x + strip_n.y + 1u;
        }
        theta_c = azimuth((piece_q[0].position + piece_q[1].position + piece_q[2].position) / 3.0);
    }
    // Which of the candidate triangles (the m² of the lattice, or the strip's) are drawn (one
    // bit each; m ≤ PIECE_DIVISIONS = 32).
    var drawn: array<u32, 32>;
    var count = 0u;
    var walk = vec2<u32>(0u, 0u);
    for (var t = 0u; t < candidates; t++) {
        if (piece_triangle_drawn(t, m, &walk)) {
            drawn[t / 32u] |= 1u << (t % 32u);
            count += 1u;
        }
    }
    if (count == 0u) {
        return;
    }
    // The seam: every node is unwrapped towards the piece's reference azimuth; where the nodes'
    // u range (both eyes) reaches ±π, the piece is drawn again a turn away. Conservative by
    // SEAM_MARGIN: an extra copy is clipped by the rasterizer.
    var u_range = vec2<f32>(1e30, -1e30);
    // Nodes in slot order: (i, j, l) row by row, kept by a running (j, l) rather than searched
    // for each slot (lavapipe stops an invocation after 65,535 loop iterations in all).
    var row = vec2<u32>(0u, 0u);
    if (is_sphere(params.projection)) {
        for (var k = 0u; k < node_count; k++) {
            let p = piece_node(k, m, &row).position;
            let theta = theta_c + wrap_angle(azimuth(p) - theta_c);
            for (var s = 0u; s < 2u; s++) {
                let u = project_with_azimuth(params.projection, p, theta, select(-1.0, 1.0, s == 1u)).x;
                u_range = vec2<f32>(min(u_range.x, u), max(u_range.y, u));
            }
        }
    } else if (strip_base == QUAD_STRIP) {
        // The quad's range: that of its fan's two triangles, which cover it.
        let ra = piece_u_range(piece_q, theta_c);
        let rb = piece_u_range(array<Node, 3>(piece_q[0], piece_q[2], quad_last), theta_c);
        u_range = vec2<f32>(min(ra.x, rb.x), max(ra.y, rb.y));
    } else {
        u_range = piece_u_range(piece_q, theta_c);
    }
    var refs = array<f32, 3>(theta_c, 0.0, 0.0);
    var copies = 1u;
    if (u_range.y > PI - SEAM_MARGIN) {
        refs[copies] = theta_c - TAU;
        copies += 1u;
    }
    if (u_range.x < -PI + SEAM_MARGIN) {
        refs[copies] = theta_c + TAU;
        copies += 1u;
    }
    let first_node = atomicAdd(&counters.nodes, copies * node_count);
    let first_triangle = atomicAdd(&counters.triangles, copies * count);
    if (first_node + copies * node_count > params.triangle_capacity
        || first_triangle + copies * count > params.triangle_capacity) {
        return; // counted, never written
    }
    row = vec2<u32>(0u, 0u);
    for (var k = 0u; k < node_count; k++) {
        let node = piece_node(k, m, &row);
        for (var c = 0u; c < copies; c++) {
            out_nodes[first_node + c * node_count + k] = draw_vertex(node, refs[c]);
        }
    }
    var slot = 3u * first_triangle;
    walk = vec2<u32>(0u, 0u);
    for (var t = 0u; t < candidates; t++) {
        let local = piece_triangle_slots(t, m, &walk);
        if ((drawn[t / 32u] & (1u << (t % 32u))) == 0u) {
            continue;
        }
        if (params.measure_edges != 0u) {
            let ps = array<vec3<f32>, 3>(out_nodes[first_node + local.x].position,
                                         out_nodes[first_node + local.y].position,
                                         out_nodes[first_node + local.z].position);
            atomicMax(&counters.max_edge_bits, bitcast<u32>(visible_edge_px(ps)));
        }
        for (var c = 0u; c < copies; c++) {
            let base = first_node + c * node_count;
            out_indices[slot] = base + local.x;
            out_indices[slot + 1u] = base + local.y;
            out_indices[slot + 2u] = base + local.z;
            slot += 3u;
        }
    }
}

@compute @workgroup_size(1)
fn lattice_args() {
    let groups = (min(atomicLoad(&counters.pieces), params.piece_capacity) + 63u) / 64u;
    lattice_dispatch[0] = min(groups, 65535u);
    lattice_dispatch[1] = (groups + 65534u) / 65535u;
    lattice_dispatch[2] = 1u;
}

@compute @workgroup_size(1)
fn finalize() {
    var written = atomicLoad(&counters.triangles);
    if (written > params.triangle_capacity || atomicLoad(&counters.nodes) > params.triangle_capacity) {
        written = 0u; // an overflowed run draws nothing; the renderer grows the buffers and reruns
    }
    draw_args = DrawIndexedIndirectArgs(3u * written, 1u, 0u, 0, 0u);
}
