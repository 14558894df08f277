// The `active_cuts` pass of the `subdivide` stage: over every triangle of the scene, the cuts
// around the axis the frame makes (quadrant cuts and the square, the diamonds), OR-ed into
// `counters`; a triangle that asks for cuts marks its edges in `cut_edges`. CPU twin:
// `CpuSubdivision::active_cuts` (src/cpu/subdivide/passes.rs).

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

// Over every triangle of the scene, before `plan` (and before every chunk of a chunked frame).
@compute @workgroup_size(64)
fn active_cuts(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    var tri: InputTriangle;
    let local = invocation_index(gid, groups);
    if (local >= params.triangle_count) {
        return;
    }
    load_positions(params.first_triangle + local, &tri);
    if (off_screen_vertically(tri.position[0], tri.position[1], tri.position[2])) {
        return;
    }
    // Diamonds for the adaptive rules, and on the cylinder for every method (`band_limit` in
    // axis.rs).
    let banded = is_adaptive() || !is_sphere(params.projection);
    let limit = select(0.0, BAND_LIMIT * params.projection.screen_radius, banded);
    let bits = triangle_cuts(limit, &tri);
    if (bits.x != 0u) {
        atomicOr(&counters.cuts_low, bits.x);
    }
    if (bits.y != 0u) {
        atomicOr(&counters.cuts_high, bits.y);
    }
    if (any(bits != vec2<u32>(0u))) {
        let t = params.first_triangle + local;
        mark_edges(t, EDGE_ASKING | EDGE_CUT);
    }
}
