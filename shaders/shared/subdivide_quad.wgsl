// A band quad drawn as one strip between its rails: whether a band's polygon is one, its two piece
// records, its nodes and zigzag. CPU twin: src/cpu/subdivide/quad.rs.

#import constants
#import subdivide_bindings
#import subdivide_state
#import subdivide_edges

fn plan_quad(shown: u32, tri: ptr<function, InputTriangle>, piece_state: ptr<function, PieceState>, clip: ptr<function, ClipState>) -> bool {
    if (split_rule() != METHOD_ERROR || is_sphere(params.projection) || (*clip).poly_count != 4u || shown != 6u) {
        return false;
    }
    var turn = 2u;
    for (var r = 0u; r < 2u; r++) {
        if (turn == 2u && (*clip).poly_n[r + 1u] == 1u && (*clip).poly_n[(r + 3u) % 4u] == 1u) {
            turn = r;
        }
    }
    if (turn == 2u) {
        return false;
    }
    let rails = vec2<u32>((*clip).poly_n[turn], (*clip).poly_n[turn + 2u]);
    let longest = max(rails.x, rails.y);
    if (longest < QUAD_MIN_DIVISIONS || longest > min(params.max_div, PIECE_DIVISIONS)) {
        return false;
    }
    // Every rung of the zigzag (`quad_strip_rungs` in subdivide.rs), the one-part sides among them.
    let c0 = poly_node(turn, clip);
    let c1 = poly_node(turn + 1u, clip);
    let c2 = poly_node((turn + 2u) % 4u, clip);
    let c3 = poly_node((turn + 3u) % 4u, clip);
    var walk = vec2<u32>(0u, 0u);
    for (var step = 0u; step <= rails.x + rails.y; step++) {
        let a = edge_point(c0, c1, walk.x, rails.x).position;
        let b = edge_point(c3, c2, walk.y, rails.y).position;
        let q = edge_profile(a, b, 2u);
        if (!profile_straight(q, QUAD_RUNG_ERROR, (*tri).max_error_px)) {
            return false;
        }
        if (quad_advances_on_a(walk, rails)) {
            walk.x += 1u;
        } else {
            walk.y += 1u;
        }
    }
    (*piece_state).strip_n = rails;
    (*piece_state).quad_turn = turn;
    return true;
}

// A band quad's two records: corners 0–2 and the rails' counts (QUAD_HEAD), then corner 3
// (QUAD_TAIL, whose `lattice` invocation draws nothing).
fn append_quad(t: u32, part: ptr<function, PartPlan>, piece_state: ptr<function, PieceState>, clip: ptr<function, ClipState>) {
    (*part).appended += 2u;
    let base = atomicAdd(&counters.pieces, 2u);
    if (base + 2u > params.piece_capacity) {
        return; // counted, never written
    }
    var record: Piece;
    record.triangle = t;
    record.cell = 0u;
    record.counts01 = (*piece_state).strip_n.x | ((*piece_state).strip_n.y << 16u);
    record.count2_level = QUAD_HEAD;
    for (var i = 0u; i < 3u; i++) {
        let c = poly_node(((*piece_state).quad_turn + i) % 4u, clip);
        record.corner[i] = vec4<f32>(c.position, c.bary.x);
        record.bary1[i] = c.bary.y;
        record.bary2[i] = c.bary.z;
    }
    pieces[base] = record;
    let last = poly_node(((*piece_state).quad_turn + 3u) % 4u, clip);
    record.count2_level = QUAD_TAIL;
    record.corner[0] = vec4<f32>(last.position, last.bary.x);
    record.bary1[0] = last.bary.y;
    record.bary2[0] = last.bary.z;
    pieces[base + 1u] = record;
}


// ---- a band quad drawn as a strip between its rails (`quad_strip_triangles` in subdivide.rs) ----

const QUAD_STRIP: u32 = 4u; // `strip_base` of a quad

// Node `slot`: rail a (corner 0 → 1, strip_n.x parts), then rail d (corner 3 → 2, strip_n.y).
fn quad_along(slot: u32, piece_state: ptr<function, PieceState>) -> Along {
    if (slot <= (*piece_state).strip_n.x) {
        return Along((*piece_state).corner[0], (*piece_state).corner[1], slot, (*piece_state).strip_n.x);
    }
    return Along((*piece_state).quad_last, (*piece_state).corner[2], slot - (*piece_state).strip_n.x - 1u, (*piece_state).strip_n.y);
}

// Whether the zigzag at rung (a_i, d_j) = `walk` advances on rail a (`quad_advances_on_a`).
fn quad_advances_on_a(walk: vec2<u32>, rails: vec2<u32>) -> bool {
    return walk.x < rails.x && (walk.y == rails.y || (walk.x + 1u) * rails.y <= (walk.y + 1u) * rails.x);
}

// The next triangle of the zigzag at `walk` = (i, j) (rail a's node i = slot i, rail d's node j =
// slot n1 + 1 + j), as slots; advances the walk.
fn quad_step(walk: ptr<function, vec4<u32>>, piece_state: ptr<function, PieceState>) -> vec3<u32> {
    let i = (*walk).x;
    let j = (*walk).y;
    let n1 = (*piece_state).strip_n.x;
    if (quad_advances_on_a((*walk).xy, (*piece_state).strip_n)) {
        (*walk).x = i + 1u;
        return vec3<u32>(i, i + 1u, n1 + 1u + j);
    }
    (*walk).y = j + 1u;
    return vec3<u32>(i, n1 + 2u + j, n1 + 1u + j);
}
