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
