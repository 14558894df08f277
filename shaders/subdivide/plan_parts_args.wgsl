// The `plan_parts_args` setup pass of the `subdivide` stage (one thread): the indirect dispatch of
// `plan_parts` over the parts `plan_cuts` appended. CPU twin: `CpuSubdivision::plan_parts_args`.

#import constants
#import subdivide_types
#import subdivide_bindings

@compute @workgroup_size(1)
fn plan_parts_args() {
    let groups = (min(atomicLoad(&counters.parts), params.piece_capacity) + 63u) / 64u;
    lattice_dispatch[6] = min(groups, 65535u);
    lattice_dispatch[7] = (groups + 65534u) / 65535u;
    lattice_dispatch[8] = 1u;
}
