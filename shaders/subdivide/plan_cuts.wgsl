// The `plan_cuts` pass of the `subdivide` stage: one invocation per listed triangle and quadrant
// (`PLAN_CUTS_SPLIT`). A triangle not cut by all cuts is fanned at the crossings of its
// edges that cut triangles have (`plan_edge_split`); one cut by all, its parts around the
// vertical axis under the frame's cuts (quadrants minus a small square around the axis, bands
// between the active diamonds, fan-triangulated), each appended to `parts` for `plan_parts`,
// which plans it as `plan` plans a triangle (a quadrant near a pole or beside a floor has many
// bands: planning them here made the frame's longest threads). CPU twin:
// `CpuSubdivision::plan_cuts`.

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
#import subdivide_dispatch

@compute @workgroup_size(64)
fn plan_cuts(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    var tri: InputTriangle;
    var part: PartPlan;
    var clip: ClipState;
    var cuts: vec2<u32>;
    let local = invocation_index(gid, groups);
    let split = PLAN_CUTS_SPLIT;
    let listed = listed_cuts();
    if (local / split >= min(listed.x + listed.y, arrayLength(&cut_list))) {
        return;
    }
    let t = listed_cut(local / split, listed);
    cuts = vec2<u32>(atomicLoad(&counters.cuts_low), atomicLoad(&counters.cuts_high));
    load_triangle(t, &tri);
    if (local / split < listed.x) {
        // Cut only at its shared edges' crossings (one invocation of `split`).
        if (local % split == 0u) {
            plan_edge_split(t, &tri, &part, &clip, cuts);
        }
    } else {
        // Its quadrant.
        plan_quadrant(t, local % split, &tri, &part, &clip, cuts);
    }
    atomicMax(&counters.max_pieces, part.appended);
}
