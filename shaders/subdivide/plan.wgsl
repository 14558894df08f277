// The `plan` pass of the `subdivide` stage: one invocation per input triangle. A triangle above
// or below the image, or single-sided and seen from behind by every eye, makes nothing. One that is
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
#import subdivide_lattice
#import subdivide_bands
#import subdivide_rows
#import subdivide_dispatch

@compute @workgroup_size(64)
fn plan(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    var tri: InputTriangle;
    var part: PartPlan;
    var cuts: vec2<u32>;
    let local = invocation_index(gid, groups);
    if (local >= params.triangle_count) {
        return;
    }
    let t = params.first_triangle + local;
    cuts = vec2<u32>(atomicLoad(&counters.cuts_low), atomicLoad(&counters.cuts_high));
    load_triangle(t, &tri);
    if (off_screen_vertically(tri.position[0], tri.position[1], tri.position[2])
        || faces_away(t, tri.position[0], tri.position[1], tri.position[2])) {
        return; // no pieces
    }
    // Cut by all of the frame's cuts (decided only when there are any; the marks first).
    var marks = vec3<u32>(0u);
    var full = false;
    if (any(cuts != vec2<u32>(0u))) {
        marks = edge_marks(t);
        // Whether it asks for cuts was decided once, by `active_cuts` (its marks): deciding
        // again in this pipeline could round otherwise and leave its neighbours uncut.
        full = cut_triangle(marks);
    }
    if (single_part(full, marks, &tri, cuts)) {
        part.corner[0] = Node(tri.position[0], vec3<f32>(1.0, 0.0, 0.0));
        part.corner[1] = Node(tri.position[1], vec3<f32>(0.0, 1.0, 0.0));
        part.corner[2] = Node(tri.position[2], vec3<f32>(0.0, 0.0, 1.0));
        plan_part(&tri, &part);
        append_pieces(t, &part);
        atomicMax(&counters.max_pieces, part.appended);
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
