// A piece's rows (`Rows`, `Subdivider::piece_shape`; `lattice_shape` chooses them where they
// make fewer triangles than the lattice): rows parallel to the base, each in the parts it and its
// zipper's diagonals need, consecutive rows zipped. CPU twin: src/cpu/subdivide/rows.rs.
//
// Here too: nodes drawn off their projections (the error split on the equirectangular panoramas,
// which draw rows; `cpu::subdivide::offsets`), left out with the rows where a frame draws none.
//
// Only the full sphere under an adaptive rule draws rows; the other frames' `lattice` pipeline is
// composed with `subdivide_rows_off` in its place (lavapipe ran their `lattice` ~40 % slower, and
// built it twice as long in a fresh process, with this code merely in it).

#import constants
#import subdivide_bindings
#import subdivide_state
#import subdivide_edges
#import subdivide_lattice
#import subdivide_bands

// Row k's left (edge base + 2, from the apex) or right (edge base + 1) end: the side's node at
// the row's fraction k/R of the way to the apex (`Rows::row_ends`).
fn row_end(k: u32, right: bool, part: ptr<function, PartPlan>, piece_state: ptr<function, PieceState>) -> Node {
    let at = row_end_index(k, right, (*piece_state).row_base, (*piece_state).strip_n);
    return node_on_edge(at.x, at.y, part, piece_state);
}

// The parts across (1 to cap) band b (rows b and b + 1) needs for the zipper's diagonals,
// estimated from the profiles of its two whole diagonals (`band_parts`).
fn band_parts(whole: array<EdgeProfile, 2>, cap: u32, tri: ptr<function, InputTriangle>) -> u32 {
    for (var w = 1u; w < cap; w++) {
        if (diagonal_fits(whole[0], w, tri) && diagonal_fits(whole[1], w, tri)) {
            return w;
        }
    }
    return cap;
}

// Whether the piece may be drawn in rows — on the sphere, under an adaptive rule, three rows or
// more (at most PIECE_DIVISIONS; two rows never draw fewer than the lattice of level 2) — and
// then its rows' base and sides in `row_base` and `strip_n` (`Subdivider::rows_base`).
fn rows_possible(piece_state: ptr<function, PieceState>) -> bool {
    let counts = (*piece_state).counts;
    let base = band_base(counts);
    let sides = vec2<u32>(counts[(base + 2u) % 3u], counts[(base + 1u) % 3u]);
    let r = max(sides.x, sides.y);
    if (!is_adaptive() || !is_sphere(params.projection) || r < 3u || r > PIECE_DIVISIONS) {
        return false;
    }
    (*piece_state).row_base = base;
    (*piece_state).strip_n = sides;
    return true;
}

// The widest a row may be: 2·N_max, within 1 and PIECE_DIVISIONS.
fn row_cap() -> u32 {
    return clamp(2u * params.max_div, 1u, PIECE_DIVISIONS);
}

// Band b's measures (one `lattice_rows` invocation; `Subdivider::row_measures`): the parts
// across it its zipper's diagonals need, | the parts row b needs itself << 8 (0 for the base row).
// One call site of row_end and of the profile (lavapipe inlines each, and side by side
// invocations then measure together): the ends l0, r0, l1, r1; the diagonals l0–r1 and r0–l1;
// then row b's own edge l0–r0 as `edge_divisions` measures it (quick, then full).
fn row_measures(b: u32, tri: ptr<function, InputTriangle>, part: ptr<function, PartPlan>, piece_state: ptr<function, PieceState>) -> u32 {
    var ends: array<vec3<f32>, 4>;
    for (var c = 0u; c < 4u; c++) {
        ends[c] = row_end(b + c / 2u, (c & 1u) == 1u, part, piece_state).position;
    }
    var whole: array<EdgeProfile, 2>;
    var own = 0.0;
    let profiles = select(2u, 4u, b > 0u);
    for (var k = 0u; k < profiles; k++) {
        let own_edge = k >= 2u;
        let segments = select(2u, EDGE_SAMPLES, k == 3u);
        let p = edge_profile(ends[select(k, 0u, own_edge)], ends[select(3u - k, 1u, own_edge)], segments);
        if (!own_edge) {
            whole[k] = p;
        } else {
            own = divisions_of(k - 2u, p, segments, tri);
            if (own == 1.0) {
                break; // the quick profile needs no more
            }
        }
    }
    let need = band_parts(whole, row_cap(), tri);
    if (b == 0u) {
        return need;
    }
    return need | (min(min(division_count(own), 2u * params.max_div), PIECE_DIVISIONS) << 8u);
}

// The piece's rows from its bands' measures in `row_w` (`lattice_rows_plan`;
// `Subdivider::rows_from_measures`): their widths in `row_w`, and (candidate triangles, nodes).
fn rows_from_measures(piece_state: ptr<function, PieceState>) -> vec2<u32> {
    let counts = (*piece_state).counts;
    let r = max((*piece_state).strip_n.x, (*piece_state).strip_n.y);
    // Row k's width from its own measure and its two bands' needs, in place: row k − 1's width
    // is written before row k is read, so the band below's need is kept aside.
    var below = (*piece_state).row_w[0] & 0xffu;
    (*piece_state).row_w[0] = counts[(*piece_state).row_base];
    for (var row = 1u; row < r; row++) {
        let measures = (*piece_state).row_w[row];
        let need = max(max(measures >> 8u, below), measures & 0xffu);
        below = measures & 0xffu;
        (*piece_state).row_w[row] = clamp(need, 1u, row_cap());
    }
    (*piece_state).row_w[r] = 0u;
    var candidates = 0u;
    var nodes = 1u;
    for (var k = 0u; k < r; k++) {
        candidates += (*piece_state).row_w[k] + (*piece_state).row_w[k + 1u];
        nodes += (*piece_state).row_w[k] + 1u;
    }
    return vec2<u32>(candidates, nodes);
}

// The rows' nodes in step order (`Rows::row_node`), one `edge_point` a step: the base row's
// nodes (the base edge's own) in turn; each other row's left end (its node 0), its right end
// (node w), kept in `row_ends`, then its nodes between, the point a/w of the way between the
// ends (placing the ends once a row, not twice a node). `row` = (node a, row k, step, the row's
// first slot): `ROW_BASE`, `ROW_LEFT_END`, `ROW_RIGHT_END` or `ROW_BETWEEN`; entered at a node
// a > 0 of a row (a work item's first slot), the ends are placed and the nodes from a on follow.
// Returns the step's node as a segment's point and advances `row`.
fn rows_along(row: ptr<function, vec4<u32>>, part: ptr<function, PartPlan>, piece_state: ptr<function, PieceState>) -> Along {
    let a = (*row).x;
    let k = (*row).y;
    let step = (*row).z;
    let start = (*row).w;
    let w = (*piece_state).row_w[k];
    // One along_edge: the base row's node a, or an end of row k (`row_end`).
    var edge = vec2<u32>((*piece_state).row_base, a);
    if (step != ROW_BASE) {
        edge = row_end_index(k, step == ROW_RIGHT_END, (*piece_state).row_base, (*piece_state).strip_n);
    }
    var along = along_edge(edge.x, edge.y, part, piece_state);
    if (step == ROW_BETWEEN) {
        along = Along((*piece_state).row_ends[0], (*piece_state).row_ends[1], a, max(w, 1u));
    }
    var next = vec4<u32>(a + 1u, k, step, start);
    if (step == ROW_LEFT_END) {
        next = vec4<u32>(max(a, 1u), k, ROW_RIGHT_END, start);
    } else if (step == ROW_RIGHT_END) {
        next = vec4<u32>(a, k, ROW_BETWEEN, start);
    }
    // The row is done after its last node: the apex's only one, the right end where no node lies
    // between, the base's node w, the last between (a = w − 1).
    let done = (step == ROW_LEFT_END && w == 0u) || (step == ROW_RIGHT_END && a >= w)
        || (step == ROW_BASE && a >= w) || (step == ROW_BETWEEN && a + 2u > w);
    if (done) {
        next = vec4<u32>(0u, k + 1u, ROW_LEFT_END, start + w + 1u);
    }
    *row = next;
    return along;
}

// The slot of the node the next step of `rows_along` places.
fn rows_slot(row: vec4<u32>, piece_state: ptr<function, PieceState>) -> u32 {
    let w = (*piece_state).row_w[row.y];
    return row.w + select(select(row.x, w, row.z == ROW_RIGHT_END), 0u, row.z == ROW_LEFT_END);
}

// The lowest slot a step from `row` on places: the rows' nodes are written until it reaches the
// work item's end.
fn rows_bound(row: vec4<u32>) -> u32 {
    return row.w + select(row.x, 0u, row.z == ROW_LEFT_END);
}

// Which end of its row the node of a step from `row` is (0 left, 1 right; 2 none).
fn row_end_kept(row: vec4<u32>) -> u32 {
    return select(select(2u, 1u, row.z == ROW_RIGHT_END), 0u, row.z == ROW_LEFT_END);
}

// Keeps a row's end (`end`: 0 left, 1 right; 2 none) for the nodes between.
fn keep_row_end(end: u32, node: Node, piece_state: ptr<function, PieceState>) {
    for (var c = 0u; c < 2u; c++) {
        let keep = end == c;
        (*piece_state).row_ends[c] = Node(select((*piece_state).row_ends[c].position, node.position, keep), select((*piece_state).row_ends[c].bary, node.bary, keep));
    }
}

// The next triangle of the rows' zipper (`Rows::triangles`) at `walk` = (i on row k, j on row
// k + 1, k, row k's first slot): its slots, and its corners as (row, node) in `at`; advances the
// walk, to the next band when this one is done.
fn rows_step(walk: ptr<function, vec4<u32>>, at: ptr<function, array<vec2<u32>, 3>>, piece_state: ptr<function, PieceState>) -> vec3<u32> {
    var k = (*walk).z;
    var start = (*walk).w;
    if ((*walk).x + (*walk).y == (*piece_state).row_w[k] + (*piece_state).row_w[k + 1u]) {
        start += (*piece_state).row_w[k] + 1u;
        k += 1u;
        *walk = vec4<u32>(0u, 0u, k, start);
    }
    let w = (*piece_state).row_w[k];
    let w2 = (*piece_state).row_w[k + 1u];
    let i = (*walk).x;
    let j = (*walk).y;
    let next = start + w + 1u;
    // `rows_advance_lower`: at a shared left end one step along the lower row, then the upper.
    let sides = (*piece_state).strip_n;
    let r = max(sides.x, sides.y);
    let shared_left = row_side_index(k, sides.x, r) == row_side_index(k + 1u, sides.x, r);
    var lower = (i + 1u) * w2 <= (j + 1u) * w;
    if (shared_left && j == 0u) {
        lower = i == 0u;
    }
    if (i < w && (j >= w2 || lower)) {
        (*walk).x = i + 1u;
        *at = array<vec2<u32>, 3>(vec2<u32>(k, i), vec2<u32>(k, i + 1u), vec2<u32>(k + 1u, j));
        return vec3<u32>(start + i, start + i + 1u, next + j);
    }
    (*walk).y = j + 1u;
    *at = array<vec2<u32>, 3>(vec2<u32>(k, i), vec2<u32>(k + 1u, j + 1u), vec2<u32>(k + 1u, j));
    return vec3<u32>(start + i, next + j + 1u, next + j);
}

// ---- Nodes drawn off their projections (`cpu::subdivide::offsets`, which says why) ----

// b − a in pixels, x across the seam the short way.
fn unwrapped_px(a: vec2<f32>, b: vec2<f32>) -> vec2<f32> {
    let width = params.projection.turn_px;
    let dx = b.x - a.x;
    return vec2<f32>(dx - width * round(dx / width), b.y - a.y);
}

// Keeps the longer of two error vectors.
fn widened(slot: vec2<f32>, e: vec2<f32>) -> vec2<f32> {
    return select(slot, e, length(e) > length(slot));
}

// Half the part error of a line drawn in `parts` parts, both eyes (image pixels, y down: left
// x, y, right x, y), from its profile's bend vectors (`EdgeProfile::bend_vec`, y up: the
// largest second differences at EDGE_SAMPLES steps) (`line_offsets`).
fn line_offsets(bend: vec4<f32>, parts: u32) -> vec4<f32> {
    let step = f32(EDGE_SAMPLES) / f32(parts);
    let o0 = -0.5 * bend.xy * (step * step) / 8.0;
    let o1 = -0.5 * bend.zw * (step * step) / 8.0;
    return vec4<f32>(o0.x, -o0.y, o1.x, -o1.y);
}

// Where a piece's nodes are drawn off their projections (`StoredWork::offsets`): inside each
// edge, half its line's part error (the part's original edge where it lies on one); at each
// corner inside an original edge, that edge's; inside, half the largest error its boundary
// segments measure (the drawing's screen midpoint against its projection). Called where the
// frame draws offsets (`plan_work`).
fn piece_offsets(node_count: u32, part: ptr<function, PartPlan>, piece_state: ptr<function, PieceState>) -> array<vec4<f32>, 7> {
    var out: array<vec4<f32>, 7>;
    for (var i = 0u; i < 6u; i++) {
        var bend = vec4<f32>(0.0);
        var parts = 0u;
        if (i < 3u) {
            if ((*piece_state).counts[i] >= 2u && node_count > 3u) {
                let oe = (*piece_state).original[i];
                bend = select((*piece_state).bend[i], (*part).bend[max(oe, 0)], oe >= 0);
                parts = select((*piece_state).counts[i], (*part).n[max(oe, 0)], oe >= 0);
            }
        } else if ((*piece_state).corner_line[i - 3u] >= 0) {
            let oe = u32((*piece_state).corner_line[i - 3u]);
            bend = (*part).bend[oe];
            parts = (*part).n[oe];
        }
        if (parts >= 2u) {
            out[i] = line_offsets(bend, parts);
        }
    }
    if (node_count <= 3u) {
        return out;
    }
    // Sampled: each edge's middle segment.
    var inside: array<vec2<f32>, 2>;
    for (var e = 0u; e < 3u; e++) {
        let count = (*piece_state).counts[e];
        if (count > 0u) {
            let m = (count - 1u) / 2u;
            let pa = node_on_edge(e, m, part, piece_state).position;
            let pb = node_on_edge(e, m + 1u, part, piece_state).position;
            let wa = max(horizontal_radius(pa), AZIMUTH_MIN_RADIUS);
            let wb = max(horizontal_radius(pb), AZIMUTH_MIN_RADIUS);
            let ends = array<vec3<f32>, 3>(pa, pb, (pa / wa + pb / wb) / (1.0 / wa + 1.0 / wb));
            var q: array<array<vec2<f32>, 2>, 3>;
            for (var j = 0u; j < 3u; j++) {
                q[j] = pixels(ends[j], eye_offset(params.projection, horizontal_radius(ends[j]), ends[j].y));
            }
            for (var s = 0u; s < 2u; s++) {
                let err = unwrapped_px(q[0][s], q[2][s]) - 0.5 * unwrapped_px(q[0][s], q[1][s]);
                inside[s] = widened(inside[s], 0.5 * err);
            }
        }
    }
    out[6] = vec4<f32>(inside[0].x, -inside[0].y, inside[1].x, -inside[1].y);
    return out;
}

// A pending piece's edges' bend vectors, for `lattice_rows_plan` (which does not measure them
// again), kept where its offsets will be (`load_bends`).
fn keep_bends(index: u32, piece_state: ptr<function, PieceState>) {
    if (params.node_offsets != 0u) {
        for (var e = 0u; e < 3u; e++) {
            piece_work[index].offsets[e] = (*piece_state).bend[e];
        }
    }
}

// A pending piece's edges' bend vectors, kept by `plan_pending`.
fn load_bends(index: u32, piece_state: ptr<function, PieceState>) {
    if (params.node_offsets != 0u) {
        for (var e = 0u; e < 3u; e++) {
            (*piece_state).bend[e] = piece_work[index].offsets[e];
        }
    }
}

// Where piece `index`'s corner c is drawn off its projection.
fn corner_offset(index: u32, c: u32) -> vec4<f32> {
    if (params.node_offsets == 0u) {
        return vec4<f32>(0.0);
    }
    return piece_work[index].offsets[3u + c];
}

// Where a node of piece `index` just placed by `piece_node` is drawn off its projection: a
// corner's, an edge's (`node_edge`), or the inside's.
fn node_offset(node: Node, index: u32, piece_state: ptr<function, PieceState>) -> vec4<f32> {
    if (params.node_offsets == 0u) {
        return vec4<f32>(0.0);
    }
    var i = select(6u, (*piece_state).node_edge, (*piece_state).node_edge < 3u); // an edge's slot, or the inside's
    for (var c = 0u; c < 3u; c++) {
        if (same(node.position, (*piece_state).corner[c].position)) {
            i = 3u + c;
        }
    }
    return piece_work[index].offsets[i];
}
