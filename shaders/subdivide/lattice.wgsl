// The `lattice` pass of the `subdivide` stage: one invocation per piece record. The part's
// corners from the record; the piece's shape: the regular lattice of level m = max(counts),
// boundary nodes snapped to each edge's nodes, or a sliver's strip along its long edges (the
// error split on the cylinder), or rows (the sphere: their measures are left to `lattice_rows`, the choice to
// `lattice_rows_plan`); its seam copies (again a turn away where its nodes' u range crosses ±π).
// A piece of one work item's worth it writes itself; for a larger one it writes its plan
// (`piece_work`), its nodes' room and its work items (`plan_work`), which `lattice_nodes` and
// `lattice_triangles` then run, at most LATTICE_CHUNK outputs each. CPU twin:
// `CpuSubdivision::lattice`.

#import projection
#import constants
#import scene
#import subdivide_types
#import subdivide_bindings
#import subdivide_state
#import subdivide_edges
#import subdivide_frame_cuts
#import subdivide_axis
#import subdivide_lattice
#import subdivide_bands
#import subdivide_rows
#import subdivide_work
#import subdivide_dispatch

@compute @workgroup_size(64)
fn lattice(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    var tri: InputTriangle;
    var part: PartPlan;
    var piece_state: PieceState;
    let local = invocation_index(gid, groups);
    if (local >= pieces_planned()) {
        return;
    }
    let index = params.first_piece + local;
    let piece = pieces[index];
    load_triangle(piece.triangle, &tri);
    record_corners(piece, &part);
    let shape = lattice_shape(piece, &tri, &part, &piece_state);
    if (shape.candidates == 0u) {
        return;
    }
    if (piece_state.strip_base == ROWS_PENDING) {
        plan_pending(index, shape, &piece_state); // planned by `lattice_rows_plan`
        return;
    }
    plan_work(index, shape, seam_copies(shape, &part, &piece_state), &tri, &part, &piece_state);
}
