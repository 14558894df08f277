// The `plan_cuts_args` setup pass of the `subdivide` stage (one thread): the indirect dispatch of
// `plan_cuts` over the triangles `plan` listed. CPU twin: `CpuSubdivision::plan_cuts_args`.

#import constants
#import subdivide_types
#import subdivide_bindings
#import subdivide_dispatch

@compute @workgroup_size(1)
fn plan_cuts_args() {
    let listed = listed_cuts();
    set_dispatch(3u, PLAN_CUTS_SPLIT * min(listed.x + listed.y, arrayLength(&cut_list)));
}
