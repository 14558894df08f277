// A long thin part's bands (pieces of `band_rows` of its rows each, `append_pieces` and
// `lattice_shape`), and where rows meet a part's or a piece's sides (`subdivide_rows` draws a
// piece in rows). CPU twin: src/cpu/subdivide/rows.rs.

#import constants
#import subdivide_bindings
#import subdivide_state
#import subdivide_edges
#import subdivide_lattice

// The first edge with the fewest divisions: a thin part's (or a piece's rows') base.
fn band_base(n: array<u32, 3>) -> u32 {
    var base = 0u;
    for (var e = 1u; e < 3u; e++) {
        if (n[e] < n[base]) {
            base = e;
        }
    }
    return base;
}

// Steps along a thin part's sides per band: N_max (at most PIECE_DIVISIONS).
fn band_rows() -> u32 {
    return clamp(params.max_div, 1u, PIECE_DIVISIONS);
}

// The node, counted from the base, where row k of r meets a side of `count` ≤ r parts: the
// fraction k/r of the way rounded down (only the last row reaches the apex).
fn row_side_index(k: u32, count: u32, r: u32) -> u32 {
    return k * count / max(r, 1u);
}

// Where row k of rows on `base` with sides of `sides` (left, right) parts meets its left side
// (edge base + 2, from the apex) or its right side (edge base + 1): (edge, fine index from that
// edge's start) (`row_end_indices`).
fn row_end_index(k: u32, right: bool, base: u32, sides: vec2<u32>) -> vec2<u32> {
    let r = max(sides.x, sides.y);
    if (right) {
        return vec2<u32>((base + 1u) % 3u, row_side_index(k, sides.y, r));
    }
    return vec2<u32>((base + 2u) % 3u, sides.x - row_side_index(k, sides.x, r));
}

// Where row `row` of a thin part meets its left or right side, as a location (`band_cell`).
fn band_row_end(row: u32, right: bool, part: ptr<function, PartPlan>) -> vec3<u32> {
    let base = band_base((*part).n);
    let sides = vec2<u32>((*part).n[(base + 2u) % 3u], (*part).n[(base + 1u) % 3u]);
    let at = row_end_index(row, right, base, sides);
    return edge_location(at.x, at.y, part);
}

// Pieces of a thin part: two per band of `band_rows` rows.
fn band_pieces(part: ptr<function, PartPlan>) -> u32 {
    let base = band_base((*part).n);
    let r = max((*part).n[(base + 1u) % 3u], (*part).n[(base + 2u) % 3u]);
    let step = band_rows();
    return 2u * ((r + step - 1u) / step);
}

// Piece `cell` of a thin part: of band cell / 2's quad (L_k0, R_k0, R_k1, L_k1), the triangle
// (L_k0, R_k0, R_k1) (even cells) or (L_k0, R_k1, L_k1) (odd), as locations.
fn band_cell(cell: u32, part: ptr<function, PartPlan>) -> array<vec3<u32>, 3> {
    let base = band_base((*part).n);
    let r = max((*part).n[(base + 1u) % 3u], (*part).n[(base + 2u) % 3u]);
    let k0 = min(cell / 2u * band_rows(), r);
    let k1 = min(k0 + band_rows(), r);
    if (cell % 2u == 0u) {
        return array<vec3<u32>, 3>(band_row_end(k0, false, part), band_row_end(k0, true, part), band_row_end(k1, true, part));
    }
    return array<vec3<u32>, 3>(band_row_end(k0, false, part), band_row_end(k1, true, part), band_row_end(k1, false, part));
}

const ROWS_SHAPE: u32 = 5u; // `strip_base` of a piece drawn in rows (`subdivide_rows`)
const ROWS_PENDING: u32 = 6u; // ... of one whose rows `lattice_rows` measures
