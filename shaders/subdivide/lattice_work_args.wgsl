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
    for (var i = 0u; i < 2u; i++) {
        let groups = (items[i] + 63u) / 64u;
        lattice_dispatch[9u + 3u * i] = min(groups, 65535u);
        lattice_dispatch[10u + 3u * i] = (groups + 65534u) / 65535u;
        lattice_dispatch[11u + 3u * i] = 1u;
    }
}
