// The `subdivide` stage (compute): adaptive subdivision (seed 002 §2.3, eq. 5, Fig. 6), the
// vertical-axis split and the seam copies: its entry points; the work is in the shared modules
// subdivide_* (types, bindings, state, edges, frame_cuts, axis, quad, lattice), each mirrored by
// the twin module of the same name in src/cpu/subdivide/. CPU twin and full description there.

#import projection
#import constants
#import scene
#import subdivide_types
#import subdivide_bindings
#import subdivide_state
#import subdivide_edges
#import subdivide_frame_cuts
#import subdivide_axis
#import subdivide_quad
#import subdivide_lattice
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
    var shape: PieceShape;
    if ((piece.count2_level & QUAD_HEAD) != 0u) {
        shape = quad_shape(piece, pieces[params.first_piece + local + 1u]);
    } else {
        shape = lattice_shape(piece);
    }
    if (shape.candidates == 0u) {
        return;
    }
    // Which of the candidate triangles (the m² of the lattice, or the strip's) are drawn (one
    // bit each; m ≤ PIECE_DIVISIONS = 32).
    var drawn: array<u32, 32>;
    var count = 0u;
    var walk = vec2<u32>(0u, 0u);
    for (var t = 0u; t < shape.candidates; t++) {
        if (piece_triangle_drawn(t, shape.m, &walk)) {
            drawn[t / 32u] |= 1u << (t % 32u);
            count += 1u;
        }
    }
    if (count == 0u) {
        return;
    }
    emit_piece(shape, seam_copies(shape), &drawn, count);
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
