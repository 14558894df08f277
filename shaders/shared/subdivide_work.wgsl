// A piece's work: what `lattice` planned for it (`PieceWork`), its work items of at most
// LATTICE_CHUNK outputs each, and what `lattice_nodes` and `lattice_triangles` do with one (issue
// 32: no invocation writes a whole piece). CPU twin: src/cpu/subdivide/work.rs.

#import constants
#import projection
#import subdivide_types
#import subdivide_bindings
#import subdivide_state
#import subdivide_edges
#import subdivide_lattice
#import subdivide_bands
#import subdivide_rows
#import subdivide_dispatch
#import subdivide_in_place

// Node slots or candidate triangles one item of a piece drawn `copies` times covers.
fn chunk_of(copies: u32) -> u32 {
    return LATTICE_CHUNK / copies;
}

// Room in `lattice_work`: as many items as output nodes (a piece's items are fewer than its nodes).
fn work_capacity() -> u32 {
    return params.triangle_capacity;
}

// The piece at `index` (its shape in `piece_state`, its seam copies): its nodes allocated; a
// piece of one item's worth (at most LATTICE_CHUNK / copies nodes and candidates: every `vertex`
// piece, most small ones) written here, as its items would be; a larger one's work written and
// its work items appended: node items from the front of `lattice_work`, triangle items from its
// back, each triangle item with the walk (strip, rows) at its first candidate. Counted
// always, written only where they fit.
fn plan_work(index: u32, shape: PieceShape, seam: SeamCopies, tri: ptr<function, InputTriangle>, part: ptr<function, PartPlan>, piece_state: ptr<function, PieceState>) {
    let copies = seam.copies;
    if (copies == 0u) {
        return; // VR180: behind the viewer
    }
    var work: PieceWork;
    work.shape = (*piece_state).strip_base;
    work.m = shape.m;
    work.node_count = shape.node_count;
    work.candidates = shape.candidates;
    work.copies = copies;
    work.counts = (*piece_state).counts[0] | ((*piece_state).counts[1] << 8u) | ((*piece_state).counts[2] << 16u) | ((*piece_state).row_base << 24u);
    work.strip_n = (*piece_state).strip_n.x | ((*piece_state).strip_n.y << 16u);
    work.refs = vec4<f32>(seam.refs[0], seam.refs[1], seam.refs[2], seam.reach);
    if (work.shape == ROWS_SHAPE) {
        work.row_w = (*piece_state).row_w;
    }
    if (params.node_offsets != 0u) {
        piece_work[index].offsets = piece_offsets(shape.node_count, part, piece_state);
    }
    work.first_node = atomicAdd(&counters.nodes, copies * shape.node_count);
    let chunk = chunk_of(copies);
    if (shape.node_count <= chunk && shape.candidates <= chunk) {
        write_in_place(index, work, tri, part, piece_state);
        return;
    }
    piece_work[index].work = work;
    let len = work_capacity();
    let node_items = (shape.node_count + chunk - 1u) / chunk;
    let at = atomicAdd(&counters.node_items, node_items);
    for (var i = 0u; i < node_items; i++) {
        if (at + i < len) {
            lattice_work[at + i] = vec4<u32>(index, i * chunk, 0u, 0u);
        }
    }
    let triangle_items = (shape.candidates + chunk - 1u) / chunk;
    let back = atomicAdd(&counters.triangle_items, triangle_items);
    // The lattice's candidates are found from their index; the others' by walking.
    let walked = work.shape != LATTICE_SHAPE;
    var walk = vec4<u32>(0u);
    for (var t = 0u; t < shape.candidates; t++) {
        if (t % chunk == 0u) {
            let slot = back + t / chunk;
            if (slot < len) {
                lattice_work[len - 1u - slot] = vec4<u32>(index, t, walk.x | (walk.y << 16u), walk.z | (walk.w << 16u));
            }
            if (!walked) {
                t += chunk - 1u;
                continue;
            }
        }
        piece_triangle_slots(t, shape.m, &walk, piece_state);
    }
}

// A piece whose rows `lattice_rows` measures: its plan so far (counts, rows' base and sides, the
// lattice's figures), a row item per band (`row_items`), and its index in the list
// `lattice_rows_plan` runs over (`parts`), counted always, written where they fit.
fn plan_pending(index: u32, shape: PieceShape, piece_state: ptr<function, PieceState>) {
    var work: PieceWork;
    work.shape = ROWS_PENDING;
    work.m = shape.m;
    work.node_count = shape.node_count;
    work.candidates = shape.candidates;
    work.counts = (*piece_state).counts[0] | ((*piece_state).counts[1] << 8u) | ((*piece_state).counts[2] << 16u) | ((*piece_state).row_base << 24u);
    work.strip_n = (*piece_state).strip_n.x | ((*piece_state).strip_n.y << 16u);
    piece_work[index].work = work;
    keep_bends(index, piece_state);
    let r = max((*piece_state).strip_n.x, (*piece_state).strip_n.y);
    let base = atomicAdd(&counters.row_items, r);
    for (var b = 0u; b < r; b++) {
        if (base + b < row_item_room()) {
            row_items[row_item_slot(base + b)] = (index << 5u) | b; // b < r ≤ PIECE_DIVISIONS = 32
        }
    }
    let slot = atomicAdd(&counters.pending, 1u);
    if (slot < params.piece_capacity) {
        parts[slot].triangle = index;
    }
}

// A work item's piece reloaded as `lattice` left it: its part, corners, edges and counts, its
// shape (and rows' widths) from its work.
fn load_work(index: u32, work: PieceWork, part: ptr<function, PartPlan>, piece_state: ptr<function, PieceState>) {
    let piece = pieces[index];
    record_corners(piece, part);
    piece_edges(piece_corners(piece, part, piece_state), part, piece_state);
    for (var e = 0u; e < 3u; e++) {
        (*piece_state).counts[e] = (work.counts >> (8u * e)) & 0xffu;
    }
    (*piece_state).strip_base = work.shape;
    (*piece_state).strip_n = vec2<u32>(work.strip_n & 0xffffu, work.strip_n >> 16u);
    (*piece_state).row_base = work.counts >> 24u;
    if (work.shape == ROWS_SHAPE || work.shape == ROWS_PENDING) {
        (*piece_state).row_w = work.row_w;
    }
}

// A node item: the piece's nodes in slots [first, first + chunk), written once per seam copy.
// A piece that is one lattice triangle (most of a scene's pieces) has its corners for nodes
// (slot k is corner k, the bits `piece_node` gives them): they come from a loop of their own, and
// the general loop runs no step for it. A group of lavapipe's lanes runs a loop's body as often
// as its busiest lane (and once when none is), a branch of the body for every lane when any
// takes it: a group of single triangles runs `piece_node` once rather than three times. Rows are stepped through
// in their own order (`rows_along`: each row's ends first, which its other nodes lie between),
// until no step is left that writes a slot of the item's (`rows_bound`); an end outside the
// item is placed and not written.
fn write_nodes(first: u32, index: u32, work: PieceWork, tri: ptr<function, InputTriangle>, part: ptr<function, PartPlan>, piece_state: ptr<function, PieceState>) {
    let end = min(first + chunk_of(work.copies), work.node_count);
    let corners_only = work.shape == LATTICE_SHAPE && work.m == 1u;
    let rows = work.shape == ROWS_SHAPE;
    var k = first;
    for (; k < select(first, end, corners_only); k++) {
        write_node((*piece_state).corner[k], k, corner_offset(index, k), work, tri);
    }
    var row = node_row_at(k, work.m, piece_state);
    var next = k;
    while (next < end) {
        let slot = select(k, rows_slot(row, piece_state), rows);
        let node = piece_node(k, work.m, &row, part, piece_state);
        if (slot >= first && slot < end) {
            write_node(node, slot, node_offset(node, index, piece_state), work, tri);
        }
        k += 1u;
        next = select(k, rows_bound(row), rows);
    }
    atomicMax(&counters.max_output, (end - first) * work.copies);
}

// Node slot k of a piece, once per seam copy, drawn `offsets` off its projection.
fn write_node(node: Node, k: u32, offsets: vec4<f32>, work: PieceWork, tri: ptr<function, InputTriangle>) {
    for (var c = 0u; c < work.copies; c++) {
        var v = draw_vertex(node, work.refs[c], tri);
        v.offsets = offsets;
        out_nodes[work.first_node + c * work.node_count + k] = v;
    }
}

// A triangle item: the piece's candidates [item.y, item.y + chunk) from the walk in item.zw,
// those drawn (their corners read from the nodes written) appended as indices, once per seam copy
// that shows (`copy_shows`; the piece's reach in refs.w).
fn write_triangles(item: vec4<u32>, work: PieceWork, piece_state: ptr<function, PieceState>) {
    let first = item.y;
    let end = min(first + chunk_of(work.copies), work.candidates);
    let start = vec4<u32>(item.z & 0xffffu, item.z >> 16u, item.w & 0xffffu, item.w >> 16u);
    var walk = start;
    // Bit (t − first)·copies + c: copy c of candidate t is drawn (at most LATTICE_CHUNK bits).
    var drawn = vec2<u32>(0u);
    var count = 0u;
    // An image narrower than a turn of longitude (VR180): every triangle is tested, copies or
    // not (the seamless images' x is no longitude).
    let narrow = params.seamless == 0u && image_half_span() < PI;
    for (var t = first; t < end; t++) {
        let s = piece_triangle_slots(t, work.m, &walk, piece_state) + vec3<u32>(work.first_node);
        let p = array<vec3<f32>, 3>(out_nodes[s.x].position, out_nodes[s.y].position, out_nodes[s.z].position);
        if (candidate_drawn(p[0], p[1], p[2])) {
            for (var c = 0u; c < work.copies; c++) {
                if ((work.copies == 1u && !narrow) || copy_shows(p, work.refs[c], work.refs.w)) {
                    let bit = (t - first) * work.copies + c;
                    drawn[bit / 32u] |= 1u << (bit % 32u);
                    count += 1u;
                }
            }
        }
    }
    if (count == 0u) {
        return;
    }
    let first_triangle = atomicAdd(&counters.triangles, count);
    atomicMax(&counters.max_output, count);
    if (first_triangle + count > params.triangle_capacity) {
        return; // counted, never written
    }
    walk = start;
    var slot = 3u * first_triangle;
    for (var t = first; t < end; t++) {
        let local = piece_triangle_slots(t, work.m, &walk, piece_state);
        let bits = (t - first) * work.copies;
        var any = false;
        for (var c = 0u; c < work.copies; c++) {
            let bit = bits + c;
            any = any || (drawn[bit / 32u] & (1u << (bit % 32u))) != 0u;
        }
        if (!any) {
            continue;
        }
        let s = local + vec3<u32>(work.first_node);
        if (MEASURE_EDGES && params.measure_edges != 0u) {
            let ps = array<vec3<f32>, 3>(out_nodes[s.x].position, out_nodes[s.y].position, out_nodes[s.z].position);
            atomicMax(&counters.max_edge_bits, bitcast<u32>(visible_edge_px(ps)));
        }
        for (var c = 0u; c < work.copies; c++) {
            let bit = bits + c;
            if ((drawn[bit / 32u] & (1u << (bit % 32u))) == 0u) {
                continue;
            }
            let base = c * work.node_count;
            out_indices[slot] = s.x + base;
            out_indices[slot + 1u] = s.y + base;
            out_indices[slot + 2u] = s.z + base;
            slot += 3u;
        }
    }
}
