// The `lattice_rows` pass of the `subdivide` stage (the sphere, adaptive rules), after `lattice`:
// one invocation per row item, band b of a piece whose rows are to be measured (ROWS_PENDING): the
// parts its zipper's diagonals need, and those row b needs itself (`row_measures`), into its
// work's `row_w[b]`, so that no invocation measures all of a piece's rows (their edge profiles
// were most of `lattice`'s time). CPU twin: `CpuSubdivision::lattice_rows`.

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
fn lattice_rows(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    var tri: InputTriangle;
    var part: PartPlan;
    var piece_state: PieceState;
    let local = invocation_index(gid, groups);
    if (local >= row_item_count()) {
        return;
    }
    let item = row_items[row_item_slot(local)];
    let index = item >> 5u;
    let b = item & 31u;
    let work = piece_work[index].work;
    load_triangle(pieces[index].triangle, &tri);
    load_work(index, work, &part, &piece_state);
    piece_work[index].work.row_w[b] = row_measures(b, &tri, &part, &piece_state);
}
