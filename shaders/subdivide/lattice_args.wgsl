// The `lattice_args` setup pass of the `subdivide` stage (one thread): the indirect dispatch of
// `lattice`, one invocation per piece counted. CPU twin: `CpuSubdivision::lattice_args`.

#import constants
#import subdivide_types
#import subdivide_bindings

@compute @workgroup_size(1)
fn lattice_args() {
    let groups = (min(atomicLoad(&counters.pieces), params.piece_capacity) + 63u) / 64u;
    lattice_dispatch[0] = min(groups, 65535u);
    lattice_dispatch[1] = (groups + 65534u) / 65535u;
    lattice_dispatch[2] = 1u;
}
