// The `plan_parts_args` setup pass of the `subdivide` stage (one thread): the indirect dispatch of
// `plan_parts` over the parts `plan_cuts` appended. CPU twin: `CpuSubdivision::plan_parts_args`.

#import constants
#import subdivide_types
#import subdivide_bindings
#import subdivide_dispatch

@compute @workgroup_size(1)
fn plan_parts_args() {
    set_dispatch(6u, min(atomicLoad(&counters.parts), params.piece_capacity));
}
