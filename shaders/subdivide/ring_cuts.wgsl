// The `ring_cuts` pass of the `subdivide` stage, after `active_cuts`: a triangle with an edge of
// one that asks for cuts is cut too, and marks its edges. CPU twin: `CpuSubdivision::ring_cuts`.

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

// Over every triangle of the scene, after `active_cuts`: a triangle that asks for no cuts but
// has an edge of one that does is cut too; its edges are marked as cut ones'.
@compute @workgroup_size(64)
fn ring_cuts(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    var tri: InputTriangle;
    let local = invocation_index(gid, groups);
    if (local >= params.triangle_count) {
        return;
    }
    let t = params.first_triangle + local;
    // The bits first: most triangles have no such edge, and need not be loaded. (A triangle
    // that asks is marked already; marking it again changes nothing.)
    if (!cut_triangle(edge_marks_now(t))) {
        return;
    }
    load_positions(t, &tri);
    if (off_screen_vertically(tri.position[0], tri.position[1], tri.position[2])) {
        return;
    }
    mark_edges(t, EDGE_CUT);
}
