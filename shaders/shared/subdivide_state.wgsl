// The per-invocation state of the `subdivide` stage's passes, as structs: each pass's entry point
// declares the ones it needs as function variables and passes them by pointer to the loading,
// planning and lattice functions that write and read them (no private globals). CPU twin: the
// `Triangle`, the part and piece locals and the `Polygon`s of src/cpu/subdivide/.

#import subdivide_types

// The input triangle in the viewer frame (`load_triangle`; `load_positions` fills `position`).
struct InputTriangle {
    position: array<vec3<f32>, 3>,
    normal: array<vec3<f32>, 3>,
    color: array<vec4<f32>, 3>,
    uv: array<vec2<f32>, 3>,
    tangent: array<vec4<f32>, 3>,
    material: u32,
    object: u32,
    // L for this triangle: params.edge_px × its object's factor (read once in `load_triangle`).
    edge_px: f32,
    // τ likewise (× the factor squared).
    max_error_px: f32,
}

// The part being split, and its plan (`plan_part`).
struct PartPlan {
    corner: array<Node, 3>,
    n: array<u32, 3>,   // divisions of the part's edges Q0Q1, Q1Q2, Q2Q0
    k: u32,             // macro-lattice level
    bands: bool,        // a long thin part cut in bands (`PartSplit::bands`), not K² cells
    appended: u32,      // piece records the invocation appended so far (`max_pieces`)
    bend: array<vec4<f32>, 3>, // each edge's profile's bend vectors (`EdgeProfile::bend_vec`; 0 if not fully measured)
}

// The piece being subdivided (`lattice`).
struct PieceState {
    corner: array<Node, 3>,
    counts: array<u32, 3>,
    original: array<i32, 3>, // original edge under piece edge e, or −1
    from_index: array<u32, 3>,    // fine index on that original edge at corner e
    to_index: array<u32, 3>,  // and at corner e + 1
    strip_base: u32,         // a sliver's base edge (see `strip_base_of`); 3: the lattice; ROWS_SHAPE
    strip_n: vec2<u32>,      // its long edges' counts: edge base + 1, edge base + 2; rows' sides (left, right)
    row_base: u32,           // rows: the base edge
    row_w: array<u32, 33>,   // rows: each row's parts, from the base to the apex (`Rows::widths`)
    row_ends: array<Node, 2>, // rows: the current row's ends (left, right), placed first (`rows_along`)
    corner_line: array<i32, 3>, // the original edge corner c lies inside, or −1 (`piece_offsets`)
    node_edge: u32,          // the piece edge the last node `piece_node` placed lies on; 3: inside
    bend: array<vec4<f32>, 3>, // each edge inside the part: its profile's bend vectors (`interior_counts`)
}

// A polygon while it is clipped (at most 7 corners), and a quadrant's polygon kept while its
// bands are cut from it (`plan_cuts`). Three slots of seven nodes in one pool, named by their
// offsets, so that a clip writes its result into a free slot and no polygon is ever copied
// (lavapipe copies arrays node by node, lane by lane).
struct ClipState {
    pool: array<Node, 21>,
    poly_at: u32,          // the current polygon's slot
    poly_count: u32,
    quadrant_at: u32,      // the quadrant's rest's slot
    quadrant_count: u32,
    keep_at: u32,          // a third slot a clip must not write (a band kept meanwhile)
    // The segment of an edge being clipped (`edge_crossings`), the edge's ends, and where its
    // crossings start in the pool.
    seg_p: Node,
    seg_q: Node,
    seg_live: bool,
    edge_ends: array<vec3<f32>, 2>,
    run_start: u32,
}

// Corner i of the current polygon.
fn poly_node(i: u32, clip: ptr<function, ClipState>) -> Node {
    return (*clip).pool[(*clip).poly_at + i];
}

fn corner(i: u32, part: ptr<function, PartPlan>) -> Node {
    return (*part).corner[i];
}
