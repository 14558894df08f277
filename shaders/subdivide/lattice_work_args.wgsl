// The `lattice_work_args` setup pass of the `subdivide` stage (one thread): the indirect
// dispatches of `lattice_nodes` and `lattice_triangles`, one invocation per work item `lattice`
// appended. CPU twin: `CpuSubdivision::lattice_work_args`.

#import constants
#import subdivide_types
#import subdivide_bindings
#import subdivide_dispatch

@compute @workgroup_size(1)
fn lattice_work_args() {
    let items = work_items();
    set_dispatch(9u, items.x);
    set_dispatch(12u, items.y);
}
