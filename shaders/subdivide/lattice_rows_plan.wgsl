// The `lattice_rows_plan` pass of the `subdivide` stage (the sphere, adaptive rules), after
// `lattice_rows`: one invocation per piece `lattice` listed (in `parts`) whose rows were measured:
// its rows' widths from the measures (`rows_from_measures`), drawn in rows where they make fewer
// candidate triangles than its lattice, and planned as `lattice` plans the others: its seam
// copies, its nodes' room, written in place or as work items. (One invocation per row item, band
// 0's doing the work, left most SIMD lanes idle on lavapipe.) CPU twin:
// `CpuSubdivision::lattice_rows_plan`.

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
fn lattice_rows_plan(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    var tri: InputTriangle;
    var part: PartPlan;
    var piece_state: PieceState;
    let local = invocation_index(gid, groups);
    if (local >= pending_count()) {
        return;
    }
    let index = parts[local].triangle;
    let work = piece_work[index].work;
    load_triangle(pieces[index].triangle, &tri);
    load_work(index, work, &part, &piece_state);
    load_bends(index, &piece_state);
    let rows = rows_from_measures(&piece_state);
    let c = piece_state.corner;
    var shape = PieceShape(work.m, work.candidates, work.node_count, azimuth((c[0].position + c[1].position + c[2].position) / 3.0));
    piece_state.strip_base = LATTICE_SHAPE;
    if (rows.x < shape.candidates) {
        piece_state.strip_base = ROWS_SHAPE;
        shape.candidates = rows.x;
        shape.node_count = rows.y;
    }
    plan_work(index, shape, seam_copies(shape, &part, &piece_state), &tri, &part, &piece_state);
}
