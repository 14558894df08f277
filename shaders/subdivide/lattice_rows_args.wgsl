// The `lattice_rows_args` setup pass of the `subdivide` stage (one thread; the sphere, adaptive
// rules): the indirect dispatches of `lattice_rows`, one invocation per row item `lattice`
// appended, and of `lattice_rows_plan`, one per piece it listed. CPU twin: `CpuSubdivision::lattice_rows_args`.

#import constants
#import subdivide_types
#import subdivide_bindings
#import subdivide_dispatch

@compute @workgroup_size(1)
fn lattice_rows_args() {
    set_dispatch(15u, row_item_count());
    set_dispatch(18u, pending_count());
}
