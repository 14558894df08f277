// A piece's lattice: macro cells of the pre-split, lattice and boundary nodes, the strips of
// slivers, the piece records `plan` appends, and what `lattice` emits (nodes once, triangles as
// indices). CPU twin: src/cpu/subdivide/lattice.rs.

#import constants
#import subdivide_bindings
#import subdivide_state
#import subdivide_edges

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

fn macro_location(abc: vec3<u32>, part: ptr<function, PartPlan>) -> vec3<u32> {
    let on = boundary_edge(abc);
    let e = on.x;
    if (e == 3u) {
        return vec3<u32>(INTERIOR, 0u, 0u);
    }
    return edge_location(e, snap(on.y, (*part).n[e], (*part).k), part);
}

// Fine node j (0 ≤ j ≤ n_e) of original edge e as a location: a corner at either end
// (`Location::on_edge`).
fn edge_location(e: u32, j: u32, part: ptr<function, PartPlan>) -> vec3<u32> {
    if (j == 0u) {
        return vec3<u32>(CORNER, e, 0u);
    }
    if (j == (*part).n[e]) {
        return vec3<u32>(CORNER, (e + 1u) % 3u, 0u);
    }
    return vec3<u32>(ON_EDGE, e, j);
}

// The node's fine index along original edge oe from its start, or −1 if it is not on that edge.
fn index_on(oe: u32, loc: vec3<u32>, part: ptr<function, PartPlan>) -> i32 {
    if (loc.x == CORNER && loc.y == oe) {
        return 0;
    }
    if (loc.x == CORNER && loc.y == (oe + 1u) % 3u) {
        return i32((*part).n[oe]);
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
fn node_on_edge(e: u32, m: u32, part: ptr<function, PartPlan>, piece_state: ptr<function, PieceState>) -> Node {
    let s = along_edge(e, m, part, piece_state);
    return edge_point(s.a, s.b, s.j, s.n);
}

// The same node as `edge_point`'s arguments.
fn along_edge(e: u32, m: u32, part: ptr<function, PartPlan>, piece_state: ptr<function, PieceState>) -> Along {
    let oe = (*piece_state).original[e];
    var a = (*piece_state).corner[e];
    var b = (*piece_state).corner[(e + 1u) % 3u];
    var j = m;
    var n = (*piece_state).counts[e];
    if (oe >= 0) {
        // On an original edge: the fine nodes of that edge, by their global index.
        let o = u32(oe);
        a = corner(o, part);
        b = corner((o + 1u) % 3u, part);
        n = (*part).n[o];
        j = select((*piece_state).from_index[e] + m, (*piece_state).from_index[e] - m, (*piece_state).to_index[e] < (*piece_state).from_index[e]);
    }
    return Along(a, b, j, n);
}

// The record of the current part of triangle t: its corners (position, barycentric weights),
// its edge counts and K (`record` in src/cpu/subdivide/passes.rs).
fn part_record(t: u32, part: ptr<function, PartPlan>) -> Piece {
    var record: Piece;
    record.triangle = t;
    record.counts01 = (*part).n[0] | ((*part).n[1] << 16u);
    record.count2_level = (*part).n[2] | ((*part).k << 16u) | select(0u, BANDS, (*part).bands);
    record.bend = (*part).bend;
    for (var i = 0u; i < 3u; i++) {
        record.corner[i] = vec4<f32>((*part).corner[i].position, (*part).corner[i].bary.x);
        record.bary1[i] = (*part).corner[i].bary.y;
        record.bary2[i] = (*part).corner[i].bary.z;
    }
    return record;
}

// The planned part's pieces: its K² macro cells or its bands' halves, appended; counted always,
// written only if all fit.
fn append_pieces(t: u32, part: ptr<function, PartPlan>) {
    var count = (*part).k * (*part).k;
    if ((*part).bands) {
        count = band_pieces(part);
    }
    (*part).appended += count;
    let base = atomicAdd(&counters.pieces, count);
    if (base + count > params.piece_capacity) {
        return; // counted, never written
    }
    var record = part_record(t, part);
    for (var c = 0u; c < count; c++) {
        record.cell = c;
        pieces[base + c] = record;
    }
}

// A part `plan_cuts` cut, appended for `plan_parts` to plan (its counts unset); counted always,
// written only if it fits.
fn append_part(t: u32, part: ptr<function, PartPlan>) {
    (*part).appended += 1u;
    let slot = atomicAdd(&counters.parts, 1u);
    if (slot < params.piece_capacity) {
        parts[slot] = part_record(t, part);
    }
}

// A part's corners from its record (`record_corner` in src/cpu/subdivide/passes.rs).
fn record_corners(record: Piece, part: ptr<function, PartPlan>) {
    (*part).bend = record.bend;
    for (var i = 0u; i < 3u; i++) {
        (*part).corner[i] = Node(record.corner[i].xyz, vec3<f32>(record.corner[i].w, record.bary1[i], record.bary2[i]));
    }
}

// ---- emission ----

fn draw_vertex(n: Node, theta_ref: f32, tri: ptr<function, InputTriangle>) -> DrawVertex {
    let b = n.bary;
    return DrawVertex(
        n.position,
        theta_ref,
        b.x * (*tri).normal[0] + b.y * (*tri).normal[1] + b.z * (*tri).normal[2],
        (*tri).material,
        b.x * (*tri).color[0] + b.y * (*tri).color[1] + b.z * (*tri).color[2],
        b.x * (*tri).uv[0] + b.y * (*tri).uv[1] + b.z * (*tri).uv[2],
        (*tri).object,
        pack_tangent(b.x * (*tri).tangent[0] + b.y * (*tri).tangent[1] + b.z * (*tri).tangent[2]),
        vec4<f32>(0.0),
    );
}

fn visible_edge_px(p: array<vec3<f32>, 3>) -> f32 {
    let half_h = 0.5 * params.projection.height;
    let width = params.projection.turn_px; // a full turn in pixels: x wraps at it
    var longest = 0.0;
    // Each corner projected once for both eyes, from one call site (lavapipe inlines each call).
    var both: array<array<vec2<f32>, 2>, 3>;
    for (var c = 0u; c < 3u; c++) {
        both[c] = pixels(p[c], eye_offset(params.projection, horizontal_radius(p[c]), p[c].y));
    }
    for (var s = 0u; s < 2u; s++) {
        for (var e = 0u; e < 3u; e++) {
            let a = both[e][s];
            let b = both[(e + 1u) % 3u][s];
            if (abs(a.y) <= half_h || abs(b.y) <= half_h) {
                let dx = (b.x - a.x) - width * round((b.x - a.x) / width);
                longest = max(longest, length(vec2<f32>(dx, b.y - a.y)));
            }
        }
    }
    return longest;
}

// ---- the lattice of a piece: its nodes once, its triangles as indices ----

// Slot of lattice node (i, j, l) among the piece's (m + 1)(m + 2)/2: rows l = 0..m of m + 1 − l
// nodes, by j (`node_slot` in subdivide.rs).
fn node_slot(c: vec3<u32>, m: u32) -> u32 {
    return c.z * (2u * m + 3u - c.z) / 2u + c.y;
}

// ---- the strip of a sliver piece (`strip_triangles` in subdivide.rs) ----

const LATTICE_SHAPE: u32 = 3u; // `strip_base` of a piece drawn as the regular lattice (0–2: a strip's base)

// Whether a piece may be a sliver's strip: on the cylinder only (`strip_base_of`). The sphere's
// pipelines compile their code out of the tests below, which lavapipe's lanes would otherwise all
// run whatever their piece's shape.
fn cylinder_shapes() -> bool {
    return !is_sphere(params.projection);
}

// On the cylinder, under the error split, the base edge (one part, chord error within
// STRIP_BASE_ERROR·τ by the quick profile, away from the eye circle) of a piece with another edge
// in STRIP_MIN_DIVISIONS or more parts; LATTICE_SHAPE: the regular lattice (`strip_base` in subdivide.rs).
fn strip_base_of(tri: ptr<function, InputTriangle>, piece_state: ptr<function, PieceState>) -> u32 {
    let m = max(max((*piece_state).counts[0], (*piece_state).counts[1]), (*piece_state).counts[2]);
    if (split_rule() != METHOD_ERROR || is_sphere(params.projection) || m < STRIP_MIN_DIVISIONS) {
        return LATTICE_SHAPE;
    }
    var base = LATTICE_SHAPE;
    for (var e = 0u; e < 3u; e++) {
        if (base == LATTICE_SHAPE && (*piece_state).counts[e] == 1u) {
            base = e;
        }
    }
    if (base < LATTICE_SHAPE) {
        let p = edge_profile((*piece_state).corner[base].position, (*piece_state).corner[(base + 1u) % 3u].position, 2u);
        if (!profile_straight(p, STRIP_BASE_ERROR, (*tri).max_error_px)) {
            return LATTICE_SHAPE;
        }
    }
    return base;
}

// Node `slot` of the strip: edge base + 1's nodes from its corner to the apex, then edge
// base + 2's after the apex.
fn strip_along(slot: u32, part: ptr<function, PartPlan>, piece_state: ptr<function, PieceState>) -> Along {
    let first = slot <= (*piece_state).strip_n.x;
    let e = ((*piece_state).strip_base + select(2u, 1u, first)) % 3u;
    return along_edge(e, select(slot - (*piece_state).strip_n.x, slot, first), part, piece_state);
}

// The next triangle of the strip's walk at `walk` = (i, j) (left L_i = slot n1 + n2 − i, right
// R_j = slot j), as slots; advances the walk.
fn strip_step(walk: ptr<function, vec4<u32>>, piece_state: ptr<function, PieceState>) -> vec3<u32> {
    let i = (*walk).x;
    let j = (*walk).y;
    let n1 = (*piece_state).strip_n.x;
    let n2 = (*piece_state).strip_n.y;
    if (i < n2 && (j == n1 || (i + 1u) * n1 <= (j + 1u) * n2)) {
        (*walk).x = i + 1u;
        return vec3<u32>(n1 + n2 - i, j, n1 + n2 - i - 1u);
    }
    (*walk).y = j + 1u;
    return vec3<u32>(n1 + n2 - i, j, j + 1u);
}

// ---- a piece's nodes and candidate triangles: the lattice of level m, the strip or the rows ----

// The running state `piece_node` keeps, at node slot k: the lattice's (j, l, 0, 0); the rows'
// (node, row, step, the row's first slot) (`rows_along`).
fn node_row_at(k: u32, m: u32, piece_state: ptr<function, PieceState>) -> vec4<u32> {
    var rest = k;
    var row = 0u;
    if ((*piece_state).strip_base == ROWS_SHAPE) {
        while (rest > (*piece_state).row_w[row]) {
            rest -= (*piece_state).row_w[row] + 1u;
            row += 1u;
        }
        return vec4<u32>(rest, row, select(ROW_LEFT_END, ROW_BASE, row == 0u), k - rest);
    }
    while (rest > m - row) {
        rest -= m + 1u - row;
        row += 1u;
    }
    return vec4<u32>(rest, row, 0u, 0u);
}

// The next node of a piece: the strip's and the lattice's node k in slot order (`row` the
// lattice's running (j, l, 0, 0)); the rows' in their step order (`rows_along`: the node in slot
// `rows_slot(row)`). Each shape names the node as a point along a segment (`Along`), placed by
// one call of `edge_point`; `row` is advanced here.
fn piece_node(k: u32, m: u32, row: ptr<function, vec4<u32>>, part: ptr<function, PartPlan>, piece_state: ptr<function, PieceState>) -> Node {
    var along: Along;
    var end_kept = 2u;
    (*piece_state).node_edge = 3u;
    if (cylinder_shapes() && (*piece_state).strip_base < LATTICE_SHAPE) {
        along = strip_along(k, part, piece_state);
    } else if ((*piece_state).strip_base == ROWS_SHAPE) {
        end_kept = row_end_kept(*row);
        // The base row's nodes lie on the base edge, the rows' ends on the sides.
        let base = (*piece_state).row_base;
        let step = (*row).z;
        (*piece_state).node_edge = select(select(select(3u, (base + 1u) % 3u, step == ROW_RIGHT_END), (base + 2u) % 3u, step == ROW_LEFT_END), base, step == ROW_BASE);
        along = rows_along(row, part, piece_state);
    } else {
        // Node (i, j, l) of the lattice of level m (`lattice_node`): the regular lattice, whose
        // boundary nodes on an edge with fewer divisions snap to that edge's nearest node.
        let j = (*row).x;
        let l = (*row).y;
        *row = select(vec4<u32>(j + 1u, l, 0u, 0u), vec4<u32>(0u, l + 1u, 0u, 0u), j + 1u > m - l);
        let c = vec3<u32>(m - j - l, j, l);
        let on = boundary_edge(c);
        if (on.x >= 3u) {
            return spaced_interior((*piece_state).corner, c, m);
        }
        (*piece_state).node_edge = on.x;
        along = along_edge(on.x, snap(on.y, (*piece_state).counts[on.x], m), part, piece_state);
    }
    let node = edge_point(along.a, along.b, along.j, along.n);
    keep_row_end(end_kept, node, piece_state);
    return node;
}

// Candidate triangle t's slots (the strip's in walk order, advancing `walk`).
fn piece_triangle_slots(t: u32, m: u32, walk: ptr<function, vec4<u32>>, piece_state: ptr<function, PieceState>) -> vec3<u32> {
    if ((*piece_state).strip_base == ROWS_SHAPE) {
        var at: array<vec2<u32>, 3>;
        return rows_step(walk, &at, piece_state);
    }
    if (cylinder_shapes() && (*piece_state).strip_base < LATTICE_SHAPE) {
        return strip_step(walk, piece_state);
    }
    let cell = macro_cell(m, t);
    return vec3<u32>(node_slot(cell.c[0], m), node_slot(cell.c[1], m), node_slot(cell.c[2], m));
}

// Half the image's span in longitude, radians: π on the cylinder and the sphere, π/2 for VR180
// (`Subdivider::image_half_span`; meaningless for the seamless images, whose x is no longitude).
fn image_half_span() -> f32 {
    return PI * params.projection.width / params.projection.turn_px;
}

// Whether seam copy `theta_ref` of a drawn triangle (corners p) shows in the image: its corners'
// azimuths unwrapped towards the copy's reference as the raster stage unwraps them, widened by
// the piece's `reach`, reach more than SEAM_MARGIN into the image's columns (one reaching less
// far covers no sample; `PiecePlan::copy_shows`).
fn copy_shows(p: array<vec3<f32>, 3>, theta_ref: f32, reach: f32) -> bool {
    var lo = 1e30;
    var hi = -1e30;
    for (var k = 0u; k < 3u; k++) {
        let theta0 = azimuth(p[k]);
        let theta = theta0 + TAU * floor((theta_ref - theta0) / TAU + 0.5);
        lo = min(lo, theta);
        hi = max(hi, theta);
    }
    let half = image_half_span();
    return lo - reach < half - SEAM_MARGIN && hi + reach > -half + SEAM_MARGIN;
}

// Whether a candidate triangle with these corners is drawn: not collapsed by snapping (two
// corners the same point), not off screen (`drawn` in src/cpu/subdivide/).
fn candidate_drawn(a: vec3<f32>, b: vec3<f32>, c: vec3<f32>) -> bool {
    return !(same(a, b) || same(b, c) || same(c, a) || off_screen_vertically(a, b, c));
}

// The footprint of the piece's triangle (`Footprint` in src/cpu/subdivide/): its corners'
// azimuths unwrapped towards theta_c (its footprint is convex and misses the axis, so they span
// its points'), its nearest and farthest distance from the axis: (θ min, θ max, r min, r max).
fn footprint(q: array<Node, 3>, theta_c: f32) -> vec4<f32> {
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
    return vec4<f32>(theta_min, theta_max, r_min, r_max);
}

// The u range (both eyes) of the piece's triangle on the cylinder, from its corners, and its
// reach, the largest |u − θ| (1e30 with a tracked head) (`piece_u_range` in the twin): α(r)
// grows with r, so |α| is largest at the footprint's nearest or farthest point from the axis.
// Each inverse sine and α from one call site, in a loop (lavapipe inlines every call: each
// copy of an arc function is an arctangent's worth of code to build).
fn piece_u_range(q: array<Node, 3>, theta_c: f32) -> vec3<f32> {
    let f = footprint(q, theta_c);
    let theta_min = f.x;
    let theta_max = f.y;
    let r_min = f.z;
    let r_max = f.w;
    let proj = params.projection;
    if (proj.head_on != 0.0) {
        // A tracked head: u = θ − γ, moved by the eye's offset seen from the point and by the
        // eye's distance from the display's axis seen from the screen (`core::panoramas::head`).
        let reach = length(proj.head_offset.xz) + proj.eye_radius;
        let ratios = vec2<f32>(proj.eye_radius / max(r_min, 1e-30), reach / proj.screen_radius);
        var bound = 0.0;
        for (var k = 0u; k < 2u; k++) {
            bound += precise_asin(min(ratios[k], 1.0));
        }
        return vec3<f32>(theta_min - proj.head_turn - bound, theta_max - proj.head_turn + bound, 1e30);
    }
    var alpha = 0.0;
    for (var k = 0u; k < 2u; k++) {
        alpha = max(alpha, abs(eye_shift(proj, select(r_min, r_max, k == 1u))));
    }
    return vec3<f32>(theta_min - alpha, theta_max + alpha, alpha);
}

// ---- what `lattice` does with a piece record: its shape, its seam copies, its output ----

// What `lattice` draws of a piece: its lattice level m (or its strip's), its candidate
// triangles and nodes, the reference azimuth of its seam; no candidates: nothing.
struct PieceShape {
    m: u32,
    candidates: u32,
    node_count: u32,
    theta_c: f32,
}

// A piece of the pre-split: its part's counts and K from its record, its corners (its macro
// cell's, or its band's half), as locations on the part's edges.
fn piece_corners(piece: Piece, part: ptr<function, PartPlan>, piece_state: ptr<function, PieceState>) -> array<vec3<u32>, 3> {
    (*part).n[0] = piece.counts01 & 0xffffu;
    (*part).n[1] = piece.counts01 >> 16u;
    (*part).n[2] = piece.count2_level & 0xffffu;
    (*part).k = (piece.count2_level >> 16u) & 0x1fffu;
    let cell = macro_cell((*part).k, piece.cell);
    var loc: array<vec3<u32>, 3>;
    if ((piece.count2_level & BANDS) != 0u) {
        loc = band_cell(piece.cell, part);
    }
    // Each corner (`macro_node` in src/cpu/subdivide/piece.rs) a part's corner as it is, then
    // the nodes on an edge, then the interior ones, each placed in a loop over the corners that
    // are one. A group of lavapipe's lanes runs a branch for every lane when any of them takes
    // it, and a loop's body as often as its busiest lane needs (once when none does); most pieces
    // are a whole part, whose corners are the part's own: a group of them places one edge point
    // and one interior node (four spaced points), where each corner placing both took twelve.
    var on_edge = vec3<u32>(0u);
    var edge_count = 0u;
    var inside = vec3<u32>(0u);
    var inside_count = 0u;
    for (var i = 0u; i < 3u; i++) {
        if ((piece.count2_level & BANDS) == 0u) {
            loc[i] = macro_location(cell.c[i], part);
        }
        (*piece_state).corner[i] = corner(loc[i].y, part);
        (*piece_state).corner_line[i] = select(-1, i32(loc[i].y), loc[i].x == ON_EDGE);
        if (loc[i].x == ON_EDGE) {
            on_edge[edge_count] = i;
            edge_count += 1u;
        } else if (loc[i].x != CORNER) {
            inside[inside_count] = i;
            inside_count += 1u;
        }
    }
    for (var j = 0u; j < edge_count; j++) {
        let at = loc[on_edge[j]];
        let node = edge_point(corner(at.y, part), corner((at.y + 1u) % 3u, part), at.z, (*part).n[at.y]);
        set_corner(on_edge[j], node, piece_state);
    }
    for (var j = 0u; j < inside_count; j++) {
        set_corner(inside[j], spaced_interior((*part).corner, cell.c[inside[j]], (*part).k), piece_state);
    }
    return loc;
}

// Sets the piece's corner i (a lane's own i: each slot written where it is the one).
fn set_corner(i: u32, node: Node, piece_state: ptr<function, PieceState>) {
    for (var c = 0u; c < 3u; c++) {
        if (c == i) {
            (*piece_state).corner[c] = node;
        }
    }
}

// A piece of the pre-split: its corners, each edge's count, lattice or strip, or rows to be
// measured (ROWS_PENDING: `lattice_rows`, then `lattice_rows_plan` chooses between them and the
// lattice). Nothing where its snapped corners coincide (no area) or it lies wholly off screen.
fn lattice_shape(piece: Piece, tri: ptr<function, InputTriangle>, part: ptr<function, PartPlan>, piece_state: ptr<function, PieceState>) -> PieceShape {
    let loc = piece_corners(piece, part, piece_state);
    if (same((*piece_state).corner[0].position, (*piece_state).corner[1].position) || same((*piece_state).corner[1].position, (*piece_state).corner[2].position)
        || same((*piece_state).corner[2].position, (*piece_state).corner[0].position)) {
        return PieceShape(0u, 0u, 0u, 0.0); // snapped corners coincide: no area
    }
    if (off_screen_vertically((*piece_state).corner[0].position, (*piece_state).corner[1].position, (*piece_state).corner[2].position)) {
        return PieceShape(0u, 0u, 0u, 0.0); // every sub-triangle would be culled
    }
    piece_edges(loc, part, piece_state);
    interior_counts(tri, part, piece_state);
    let m = max(max((*piece_state).counts[0], (*piece_state).counts[1]), (*piece_state).counts[2]);
    (*piece_state).strip_base = strip_base_of(tri, piece_state);
    var candidates = m * m;
    var node_count = (m + 1u) * (m + 2u) / 2u;
    if ((*piece_state).strip_base < 3u) {
        (*piece_state).strip_n = vec2<u32>((*piece_state).counts[((*piece_state).strip_base + 1u) % 3u], (*piece_state).counts[((*piece_state).strip_base + 2u) % 3u]);
        candidates = (*piece_state).strip_n.x + (*piece_state).strip_n.y - 1u;
        node_count = (*piece_state).strip_n.x + (*piece_state).strip_n.y + 1u;
    } else if (rows_possible(piece_state)) {
        (*piece_state).strip_base = ROWS_PENDING; // the lattice's figures until its rows are measured
    }
    let theta_c = azimuth(((*piece_state).corner[0].position + (*piece_state).corner[1].position + (*piece_state).corner[2].position) / 3.0);
    return PieceShape(m, candidates, node_count, theta_c);
}

// Each piece edge on an original edge: that edge and the fine indices of its ends there
// (`original`, `from_index`, `to_index`), and its count; −1 and no count inside.
fn piece_edges(loc: array<vec3<u32>, 3>, part: ptr<function, PartPlan>, piece_state: ptr<function, PieceState>) {
    for (var e = 0u; e < 3u; e++) {
        (*piece_state).original[e] = -1;
        for (var oe = 0u; oe < 3u; oe++) {
            let start = index_on(oe, loc[e], part);
            let end = index_on(oe, loc[(e + 1u) % 3u], part);
            if ((*piece_state).original[e] < 0 && start >= 0 && end >= 0) {
                (*piece_state).original[e] = i32(oe);
                (*piece_state).from_index[e] = u32(start);
                (*piece_state).to_index[e] = u32(end);
                (*piece_state).counts[e] = u32(abs(start - end));
            }
        }
    }
}

// Each piece edge inside the part: its own division (measured by `edge_counts`, so that side by
// side invocations measure their interior edges together whatever their places).
fn interior_counts(tri: ptr<function, InputTriangle>, part: ptr<function, PartPlan>, piece_state: ptr<function, PieceState>) {
    let inside = vec3<bool>((*piece_state).original[0] < 0, (*piece_state).original[1] < 0, (*piece_state).original[2] < 0);
    let c = array<vec3<f32>, 3>((*piece_state).corner[0].position, (*piece_state).corner[1].position, (*piece_state).corner[2].position);
    var bends: array<vec4<f32>, 3>;
    let n = edge_counts(c, inside, tri, &bends);
    (*piece_state).bend = bends;
    for (var e = 0u; e < 3u; e++) {
        if (inside[e]) {
            if (split_rule() == METHOD_FIXED) {
                // fixed:N pieces take N/K on interior edges (the regular N-lattice when K | N).
                (*piece_state).counts[e] = (params.fixed_n + (*part).k - 1u) / (*part).k;
            } else {
                (*piece_state).counts[e] = min(min(n[e], 2u * params.max_div), PIECE_DIVISIONS);
            }
        }
    }
}

// A bound on the u range (both eyes) of the nodes of the piece's triangle on the sphere
// (`sphere_u_bound` in src/cpu/subdivide/): u = θ − s·asin(e/r), |e/r| clamped to 1, and with
// parallel rays |e| ≤ d_e, so u lies within asin(min(d_e / r_min, 1)) (π/2 for converging rays)
// of the footprint's azimuths.
fn sphere_u_bound(q: array<Node, 3>, theta_c: f32) -> vec3<f32> {
    let f = footprint(q, theta_c);
    let proj = params.projection;
    var reach = 0.5 * PI;
    if (!CONVERGING || proj.convergence <= 0.0) {
        reach = asin(min(proj.eye_radius / max(f.z, 1e-30), 1.0));
    }
    return vec3<f32>(f.x - reach, f.y + reach, reach);
}

// Whether a bound on a piece's u range keeps it clear of the seam by SEAM_BOUND_SLACK beyond
// SEAM_MARGIN: then its nodes' own range needs no copy either.
fn clear_of_seam(bound: vec2<f32>) -> bool {
    let margin = SEAM_MARGIN + SEAM_BOUND_SLACK;
    return bound.y <= PI - margin && bound.x >= -PI + margin;
}

// The azimuths a piece is drawn at: its own, and a turn away where its nodes' u range (both
// eyes) reaches ±π. Conservative by SEAM_MARGIN: an extra copy is clipped by the rasterizer.
struct SeamCopies {
    refs: array<f32, 3>,
    copies: u32,
    // The largest |u − θ| of the piece's nodes (both eyes) where they were projected (the
    // sphere near the seam), or its corners' bound's (with SEAM_BOUND_SLACK) where it kept them
    // clear; on the cylinder its footprint's largest |α| (with the slack); by which `copy_shows`
    // widens a triangle's azimuths. 1e30 with a tracked head: every copy of every triangle drawn.
    reach: f32,
}

fn seam_copies(shape: PieceShape, part: ptr<function, PartPlan>, piece_state: ptr<function, PieceState>) -> SeamCopies {
    let theta_c = shape.theta_c;
    var u_range = vec2<f32>(1e30, -1e30);
    var reach = 1e30;
    // Nodes in slot order: (i, j, l) row by row, kept by a running (j, l) rather than searched
    // for each slot (lavapipe stops an invocation after 65,535 loop iterations in all).
    var row = node_row_at(0u, shape.m, piece_state);
    if (is_sphere(params.projection)) {
        // Every node projected, unless the corners' bound keeps the piece clear of the seam.
        let bound = sphere_u_bound((*piece_state).corner, theta_c);
        let clear = clear_of_seam(bound.xy);
        if (clear) {
            u_range = bound.xy;
            reach = bound.z + SEAM_BOUND_SLACK;
        } else {
            reach = 0.0;
        }
        for (var k = 0u; k < shape.node_count && !clear; k++) {
            let p = piece_node(k, shape.m, &row, part, piece_state).position;
            let theta = theta_c + wrap_angle(azimuth(p) - theta_c);
            let q = project_both(params.projection, p, theta);
            for (var s = 0u; s < 2u; s++) {
                u_range = vec2<f32>(min(u_range.x, q[s].x), max(u_range.y, q[s].x));
                reach = max(reach, abs(q[s].x - theta));
            }
        }
    } else {
        // The cylinder: from the corners.
        let r = piece_u_range((*piece_state).corner, theta_c);
        u_range = r.xy;
        reach = r.z + SEAM_BOUND_SLACK;
    }
    var seam = SeamCopies(array<f32, 3>(theta_c, 0.0, 0.0), 1u, reach);
    // The seamless images make none (SubdivideParams::seamless: the fisheye's, the cubemap's
    // and the CAVE walls' maps from (u, v) are no longitude: a copy would draw its piece twice
    // over the original).
    if (params.seamless != 0u) {
        return seam;
    }
    var shifts = array<f32, 3>(0.0, 0.0, 0.0);
    var n = 1u;
    if (u_range.y > PI - SEAM_MARGIN) {
        shifts[n] = -TAU;
        n += 1u;
    }
    if (u_range.x < -PI + SEAM_MARGIN) {
        shifts[n] = TAU;
        n += 1u;
    }
    // VR180: a copy whose u range lies wholly beyond the image's columns (behind the viewer) is
    // not drawn; a piece with none left draws nothing (`plan_work`).
    let half = image_half_span();
    seam.copies = 0u;
    for (var c = 0u; c < n; c++) {
        let d = shifts[c];
        if (half >= PI || (u_range.x + d < half + SEAM_MARGIN && u_range.y + d > -half - SEAM_MARGIN)) {
            seam.refs[seam.copies] = theta_c + d;
            seam.copies += 1u;
        }
    }
    return seam;
}
