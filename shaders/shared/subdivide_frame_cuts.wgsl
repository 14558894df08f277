// Which triangles a frame cuts: the marks on the scene's shared edges (`cut_edges`) that
// `active_cuts` and `ring_cuts` set and `plan` reads. CPU twin: src/cpu/subdivide/frame_cuts.rs.

#import subdivide_bindings

// ---- a triangle that asks for no cuts, cut at edges it shares with ones that do ----

// The marks of triangle t's three edges (EDGE_ASKING, EDGE_CUT; `FrameCuts` in subdivide.rs),
// while they are being set (`ring_cuts`), and once they are (`plan`, `plan_cuts`).
fn edge_marks_now(t: u32) -> vec3<u32> {
    var marks: vec3<u32>;
    for (var e = 0u; e < 3u; e++) {
        let id = triangle_edges[3u * t + e];
        marks[e] = mark_in(atomicLoad(&cut_edges[id / 16u]), id);
    }
    return marks;
}

fn edge_marks(t: u32) -> vec3<u32> {
    var marks: vec3<u32>;
    for (var e = 0u; e < 3u; e++) {
        let id = triangle_edges[3u * t + e];
        marks[e] = mark_in(edge_marks_read[id / 16u], id);
    }
    return marks;
}

// Edge id's two bits in its word of `cut_edges`.
fn mark_in(word: u32, id: u32) -> u32 {
    return (word >> (2u * (id % 16u))) & 3u;
}

// Sets marks on triangle t's three edges.
fn mark_edges(t: u32, marks: u32) {
    for (var e = 0u; e < 3u; e++) {
        let id = triangle_edges[3u * t + e];
        atomicOr(&cut_edges[id / 16u], marks << (2u * (id % 16u)));
    }
}

// Whether a triangle with edge marks `marks` has an edge of a triangle that asks for cuts: then
// it is cut by all of them (`FrameCuts::is_cut_triangle`).
fn cut_triangle(marks: vec3<u32>) -> bool {
    return any((marks & vec3<u32>(EDGE_ASKING)) != vec3<u32>(0u));
}

// The segment being clipped (`clip_segment` in axis.rs), the edge it is part of, and where that
// edge's crossings start in the pool.
