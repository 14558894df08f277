// The per-invocation state of the `subdivide` stage's passes: the input triangle being planned,
// its part and its pieces, the polygon pool of the cuts around the axis, the frame's cuts. Private
// variables, written by the pass's loading and planning functions and read by those after them
// (CPU twin: the fields of `Subdivider` and its locals in src/cpu/subdivide/).

#import subdivide_types

// The input triangle in the viewer frame, and its plan.
var<private> tri_position: array<vec3<f32>, 3>;
var<private> tri_normal: array<vec3<f32>, 3>;
var<private> tri_color: array<vec4<f32>, 3>;
var<private> tri_uv: array<vec2<f32>, 3>;
var<private> tri_tangent: array<vec4<f32>, 3>;
var<private> tri_material: u32;
var<private> tri_object: u32;
// L for this triangle: params.edge_px × its object's factor (read once in `load_triangle`).
var<private> tri_edge_px: f32;
var<private> tri_max_error_px: f32;
// The part being split (see `triangle_part`), and its plan.
var<private> part: array<Node, 3>;
var<private> tri_n: array<u32, 3>;    // divisions of the part's edges Q0Q1, Q1Q2, Q2Q0
var<private> tri_k: u32;              // macro-lattice level

// The piece being subdivided.
var<private> piece_q: array<Node, 3>;
var<private> piece_counts: array<u32, 3>;
var<private> piece_original: array<i32, 3>; // original edge under piece edge e, or −1
var<private> piece_from: array<u32, 3>;     // fine index on that original edge at corner e
var<private> piece_to: array<u32, 3>;
var<private> strip_base: u32;               // a sliver's base edge (see `strip_base_of`); 3: the lattice; QUAD_STRIP
var<private> strip_n: vec2<u32>;            // its long edges' counts: edge base + 1, edge base + 2; a quad's rails
var<private> quad_last: Node;               // a band quad's corner 3 (its corners 0–2 in piece_q)
var<private> quad_turn: u32;                // `plan_quad`: the polygon's corner that is the quad's corner 0
var<private> poly_n: array<u32, 11>;        // edge counts of a band's polygon and its fan (`polygon_edge_ends`)

// A polygon while it is clipped (at most 7 corners), and a quadrant's polygon kept while its
// bands are cut from it. Three slots of seven nodes in one pool, named by their offsets, so that a clip writes its
// result into a free slot and no polygon is ever copied (lavapipe copies private arrays node by
// node, lane by lane).
var<private> pool: array<Node, 21>;
var<private> poly_at: u32;      // the current polygon's slot
var<private> poly_count: u32;
var<private> quadrant_at: u32;  // the quadrant's rest's slot
var<private> quadrant_count: u32;
var<private> keep_at: u32;      // a third slot a clip must not write (a band kept meanwhile)

// Corner i of the current polygon.
fn poly_node(i: u32) -> Node {
    return pool[poly_at + i];
}
// The frame's cuts (bits 0–31, 32–63), read by `plan` from the counters.
var<private> cuts: vec2<u32>;

fn corner(i: u32) -> Node {
    return part[i];
}
