// The `lattice_nodes` pass of the `subdivide` stage: one invocation per node item `lattice`
// appended (the front of `lattice_work`): at most LATTICE_CHUNK / copies of its piece's nodes,
// written once per seam copy. Nothing where the run's nodes overflowed (then they are only
// counted). CPU twin: `CpuSubdivision::lattice_nodes`.

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
fn lattice_nodes(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    var tri: InputTriangle;
    var part: PartPlan;
    var piece_state: PieceState;
    let local = invocation_index(gid, groups);
    if (local >= work_items().x || atomicLoad(&counters.nodes) > params.triangle_capacity) {
        return;
    }
    let item = lattice_work[local];
    let work = piece_work[item.x].work;
    load_triangle(pieces[item.x].triangle, &tri);
    load_work(item.x, work, &part, &piece_state);
    write_nodes(item.y, item.x, work, &tri, &part, &piece_state);
}
