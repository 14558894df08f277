// The `plan_parts` pass of the `subdivide` stage: one invocation per part `plan_cuts` appended
// (on the sphere, a quadrant's band's fan part): its edge counts N (eq. 5 or the error split),
// its macro-lattice level K and its piece records, as `plan` plans a triangle that is its own
// single part. So no invocation plans a whole floor's bands near a pole (the edge profiles are
// most of the planning). CPU twin: `CpuSubdivision::plan_parts`.

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
fn plan_parts(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    var tri: InputTriangle;
    var part: PartPlan;
    let local = invocation_index(gid, groups);
    if (local >= min(atomicLoad(&counters.parts), params.piece_capacity)) {
        return;
    }
    let record = parts[local];
    load_triangle(record.triangle, &tri);
    record_corners(record, &part);
    plan_part(&tri, &part);
    append_pieces(record.triangle, &part);
    atomicMax(&counters.max_pieces, part.appended);
}
