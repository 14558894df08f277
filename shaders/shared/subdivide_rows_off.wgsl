// The stand-in for `subdivide_rows` in the pipelines of the frames that never draw rows (the
// cylinder; the vertex and fixed rules): no piece has rows. Its functions are `subdivide_rows`'s
// that other modules call, with the same signatures (the naga test composes both).

#import subdivide_state

// No rows.
fn rows_possible(piece_state: ptr<function, PieceState>) -> bool {
    return false;
}

fn row_measures(b: u32, tri: ptr<function, InputTriangle>, part: ptr<function, PartPlan>, piece_state: ptr<function, PieceState>) -> u32 {
    return 0u;
}

fn rows_from_measures(piece_state: ptr<function, PieceState>) -> vec2<u32> {
    return vec2<u32>(0xffffffffu, 0u);
}

fn rows_along(row: ptr<function, vec4<u32>>, part: ptr<function, PartPlan>, piece_state: ptr<function, PieceState>) -> Along {
    return Along();
}

fn rows_slot(row: vec4<u32>, piece_state: ptr<function, PieceState>) -> u32 {
    return 0u;
}

fn rows_bound(row: vec4<u32>) -> u32 {
    return 0u;
}

fn row_end_kept(row: vec4<u32>) -> u32 {
    return 2u;
}

fn keep_row_end(end: u32, node: Node, piece_state: ptr<function, PieceState>) {
}

fn rows_step(walk: ptr<function, vec4<u32>>, at: ptr<function, array<vec2<u32>, 3>>, piece_state: ptr<function, PieceState>) -> vec3<u32> {
    return vec3<u32>(0u);
}

// No nodes drawn off their projections (the frames without rows draw none).
fn keep_bends(index: u32, piece_state: ptr<function, PieceState>) {}

fn load_bends(index: u32, piece_state: ptr<function, PieceState>) {}

fn piece_offsets(node_count: u32, part: ptr<function, PartPlan>, piece_state: ptr<function, PieceState>) -> array<vec4<f32>, 7> {
    return array<vec4<f32>, 7>();
}

fn corner_offset(index: u32, c: u32) -> vec4<f32> {
    return vec4<f32>(0.0);
}

fn node_offset(node: Node, index: u32, piece_state: ptr<function, PieceState>) -> vec4<f32> {
    return vec4<f32>(0.0);
}
