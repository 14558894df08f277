// The `plan` pass of the `subdivide` stage: one invocation per input triangle. A triangle that is
// its own single part (no cuts this frame; neither asks nor has an edge of one that does, nor an
// edge of a cut one; or inside one quadrant and one band) is planned here: its edge counts N
// (eq. 5 or the error split), the macro-lattice level K = ceil(M / N_max) and K² piece records.
// The others are listed in `cut_list` for `plan_cuts` (the clipping code, kept out of this pass:
// lavapipe runs a shader that merely contains it markedly slower), the wide ones cut by all of
// the frame's cuts at the back. CPU twin: `CpuSubdivision::plan`.

#import projection
#import constants
#import scene
#import subdivide_types
#import subdivide_bindings
#import subdivide_state
#import subdivide_edges
#import subdivide_frame_cuts
#import subdivide_axis
#import subdivide_quad
#import subdivide_lattice
#import subdivide_dispatch

@compute @workgroup_size(64)
fn plan(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    let local = invocation_index(gid, groups);
    if (local >= params.triangle_count) {
        return;
    }
    let t = params.first_triangle + local;
    cuts = vec2<u32>(atomicLoad(&counters.cuts_low), atomicLoad(&counters.cuts_high));
    load_triangle(t);
    if (off_screen_vertically(tri_position[0], tri_position[1], tri_position[2])) {
        return; // no pieces
    }
    // Cut by all of the frame's cuts (decided only when there are any; the marks first).
    var marks = vec3<u32>(0u);
    var full = false;
    if (any(cuts != vec2<u32>(0u))) {
        marks = edge_marks(t);
        full = cut_triangle(marks) || asks_for_cuts(diamond_range(tri_position));
    }
    if (single_part(full, marks)) {
        part[0] = Node(tri_position[0], vec3<f32>(1.0, 0.0, 0.0));
        part[1] = Node(tri_position[1], vec3<f32>(0.0, 1.0, 0.0));
        part[2] = Node(tri_position[2], vec3<f32>(0.0, 0.0, 1.0));
        plan_part();
        append_pieces(t);
        return;
    }
    // Triangles cut by all of the frame's cuts (a floor around the viewer and its neighbours)
    // make many parts; listed apart (at the back), they share SIMD lanes with each other rather
    // than stall lanes of the triangles listed for their shared edges.
    let len = arrayLength(&cut_list);
    if (full) {
        let slot = atomicAdd(&counters.cut_wide, 1u);
        if (slot < len) {
            cut_list[len - 1u - slot] = t;
        }
    } else {
        let slot = atomicAdd(&counters.cut_count, 1u);
        if (slot < len) {
            cut_list[slot] = t;
        }
    }
}
