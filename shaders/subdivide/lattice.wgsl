// The `lattice` pass of the `subdivide` stage: one invocation per piece. The part's corners from
// the piece record, the regular lattice of level m = max(counts), boundary nodes snapped to each
// edge's nodes (or, for a sliver under the error split on the cylinder, a strip along its long
// edges; for a band quad, a strip between its rails, corner 3 read from the next record); its
// nodes appended once and its drawn sub-triangles as indices into them, the whole piece again a
// turn away where its nodes' u range crosses ±π. Appends never write past a capacity: they are
// counted, and the host grows the buffer or processes the scene in chunks.
// CPU twin: `CpuSubdivision::lattice`.

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
#import subdivide_bands
#import subdivide_rows
#import subdivide_dispatch

@compute @workgroup_size(64)
fn lattice(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    var tri: InputTriangle;
    var part: PartPlan;
    var piece_state: PieceState;
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
    load_triangle(piece.triangle, &tri);
    record_corners(piece, &part);
    var shape: PieceShape;
    if ((piece.count2_level & QUAD_HEAD) != 0u) {
        shape = quad_shape(piece, pieces[params.first_piece + local + 1u], &part, &piece_state);
    } else {
        shape = lattice_shape(piece, &tri, &part, &piece_state);
    }
    if (shape.candidates == 0u) {
        return;
    }
    // Which of the candidate triangles (the m² of the lattice, or the strip's) are drawn (one
    // bit each; m ≤ PIECE_DIVISIONS = 32).
    var drawn: array<u32, 32>;
    var count = 0u;
    var walk = vec4<u32>(0u);
    for (var t = 0u; t < shape.candidates; t++) {
        if (piece_triangle_drawn(t, shape.m, &walk, &part, &piece_state)) {
            drawn[t / 32u] |= 1u << (t % 32u);
            count += 1u;
        }
    }
    if (count == 0u) {
        return;
    }
    emit_piece(shape, seam_copies(shape, &part, &piece_state), &drawn, count, &tri, &part, &piece_state);
}
