// The `lattice_triangles` pass of the `subdivide` stage, after `lattice_nodes`: one invocation
// per triangle item `lattice` appended (the back of `lattice_work`): at most LATTICE_CHUNK /
// copies of its piece's candidate triangles, those drawn (not collapsed by snapping, not off
// screen: read from the nodes written) appended as indices into its nodes, once per seam copy.
// Nothing where the run's nodes overflowed. CPU twin: `CpuSubdivision::lattice_triangles`.

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
fn lattice_triangles(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    var part: PartPlan;
    var piece_state: PieceState;
    let local = invocation_index(gid, groups);
    if (local >= work_items().y || atomicLoad(&counters.nodes) > params.triangle_capacity) {
        return;
    }
    let item = lattice_work[work_capacity() - 1u - local];
    let work = piece_work[item.x].work;
    load_work(item.x, work, &part, &piece_state);
    write_triangles(item, work, &piece_state);
}
