// The `lattice_args` setup pass of the `subdivide` stage (one thread): the indirect dispatch of
// `lattice`, one invocation per piece counted. CPU twin: `CpuSubdivision::lattice_args`.

#import constants
#import subdivide_types
#import subdivide_bindings
#import subdivide_dispatch

@compute @workgroup_size(1)
fn lattice_args() {
    set_dispatch(0u, min(atomicLoad(&counters.pieces), params.piece_capacity));
}
