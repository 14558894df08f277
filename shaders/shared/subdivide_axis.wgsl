// The parts around the vertical axis: the quadrant and diamond cuts, clipping a triangle's polygon
// by them, the bands, and a triangle cut only at the crossings of its shared edges. CPU twin:
// src/cpu/subdivide/axis.rs.

#import constants
#import subdivide_bindings
#import subdivide_state
#import subdivide_edges
#import subdivide_frame_cuts

// ---- the parts around the vertical axis (src/cpu/subdivide/axis.rs) ----

// Moves a vertex within SNAP (relative to |x| + |z|) of the plane x = 0 or z = 0 onto it.
fn snap_to_cut_planes(p: vec3<f32>) -> vec3<f32> {
    let scale = SNAP * (abs(p.x) + abs(p.z));
    return vec3<f32>(select(p.x, 0.0, abs(p.x) <= scale), p.y, select(p.z, 0.0, abs(p.z) <= scale));
}

// The half-planes: CUT_X s·x ≥ 0, CUT_Z s·z ≥ 0, CUT_CHORD side·(sx·x + sz·z − c) ≥ 0 (beyond
// or within the diamond |x| + |z| = c of the quadrant).
const CUT_X: u32 = 0u;
const CUT_Z: u32 = 1u;
const CUT_CHORD: u32 = 2u;

struct Cut {
    kind: u32,
    s: vec2<f32>,
    c: f32,
    side: f32,
}

fn cut_distance(cut: Cut, p: vec3<f32>) -> f32 {
    if (cut.kind == CUT_X) {
        return cut.s.x * p.x;
    }
    if (cut.kind == CUT_Z) {
        return cut.s.y * p.z;
    }
    let d = cut.s.x * p.x + cut.s.y * p.z - cut.c;
    return select(cut.side * d, 0.0, abs(d) <= SNAP * (abs(p.x) + abs(p.z) + cut.c));
}

// The crossing of lo→hi (canonically ordered); on x = 0 or z = 0 that coordinate is set to 0.
fn cut_crossing(kind: u32, lo: Node, hi: Node, dl: f32, dh: f32) -> Node {
    let t = dl / (dl - dh);
    var n = Node(lo.position + (hi.position - lo.position) * t, lo.bary + (hi.bary - lo.bary) * t);
    let scale = SNAP * (abs(lo.position.x) + abs(lo.position.z) + abs(hi.position.x) + abs(hi.position.z));
    if (kind == CUT_X) {
        n.position.x = 0.0;
        n.position.z = select(n.position.z, 0.0, abs(n.position.z) <= scale);
    } else if (kind == CUT_Z) {
        n.position.z = 0.0;
        n.position.x = select(n.position.x, 0.0, abs(n.position.x) <= scale);
    }
    return n;
}

fn push_clipped(at: u32, n: u32, v: Node, clip: ptr<function, ClipState>) -> u32 {
    if (n > 0u && same(v.position, (*clip).pool[at + n - 1u].position)) {
        return n;
    }
    (*clip).pool[at + n] = v;
    return n + 1u;
}

// Sutherland–Hodgman clip of the current polygon against one half-plane, into a slot that is
// neither its own, the quadrant's nor `keep_at`'s, which becomes the current polygon's; crossing
// points from the canonically ordered edge.
fn clip_polygon(cut: Cut, clip: ptr<function, ClipState>) {
    var at = 0u;
    for (var slot = 0u; slot < 21u; slot += 7u) {
        if (slot != (*clip).poly_at && slot != (*clip).quadrant_at && slot != (*clip).keep_at) {
            at = slot;
        }
    }
    var n = 0u;
    for (var i = 0u; i < (*clip).poly_count; i++) {
        let cur = poly_node(i, clip);
        let next = poly_node((i + 1u) % (*clip).poly_count, clip);
        let d0 = cut_distance(cut, cur.position);
        let d1 = cut_distance(cut, next.position);
        if (d0 >= 0.0) {
            n = push_clipped(at, n, cur, clip);
        }
        if ((d0 >= 0.0) != (d1 >= 0.0) && d0 != 0.0 && d1 != 0.0) {
            // From the canonically ordered edge (one call site of cut_crossing).
            var lo = cur;
            var hi = next;
            var d = vec2<f32>(d0, d1);
            if (lex_less(next.position, cur.position)) {
                lo = next;
                hi = cur;
                d = d.yx;
            }
            n = push_clipped(at, n, cut_crossing(cut.kind, lo, hi, d.x, d.y), clip);
        }
    }
    if (n > 1u && same((*clip).pool[at + n - 1u].position, (*clip).pool[at].position)) {
        n -= 1u;
    }
    if (n < 3u) {
        n = 0u;
    }
    (*clip).poly_at = at;
    (*clip).poly_count = n;
}

// Clips the input triangle to quadrant q (signs of x and z as in `QUADRANTS` of axis.rs), beyond
// the first diamond.
fn quadrant_polygon(s: vec2<f32>, tri: ptr<function, InputTriangle>, clip: ptr<function, ClipState>) {
    (*clip).poly_at = 0u;
    (*clip).quadrant_at = 0u;
    (*clip).keep_at = 0u;
    (*clip).pool[0] = Node((*tri).position[0], vec3<f32>(1.0, 0.0, 0.0));
    (*clip).pool[1] = Node((*tri).position[1], vec3<f32>(0.0, 1.0, 0.0));
    (*clip).pool[2] = Node((*tri).position[2], vec3<f32>(0.0, 0.0, 1.0));
    (*clip).poly_count = 3u;
    // Quick tests (the clips would give the same): wholly on the far side of x = 0 or z = 0, or
    // two corners the same (no polygon); wholly inside the quadrant.
    let p = (*tri).position;
    let dx = vec3<f32>(s.x * p[0].x, s.x * p[1].x, s.x * p[2].x);
    let dz = vec3<f32>(s.y * p[0].z, s.y * p[1].z, s.y * p[2].z);
    if (all(dx < vec3<f32>(0.0)) || all(dz < vec3<f32>(0.0)) || same(p[0], p[1]) || same(p[1], p[2])
        || same(p[2], p[0])) {
        (*clip).poly_count = 0u;
        return;
    }
    // x = 0 and z = 0 (unless it lies wholly inside the quadrant), then what lies beyond the
    // first diamond (`rest` in axis.rs), from one call site of clip_polygon (lavapipe inlines
    // every call).
    let inside = all(dx >= vec3<f32>(0.0)) && all(dz >= vec3<f32>(0.0));
    for (var k = select(0u, 2u, inside); k < 3u; k++) {
        var cut = Cut(select(CUT_X, CUT_Z, k == 1u), s, 0.0, 1.0);
        if (k == 2u) {
            cut = Cut(CUT_CHORD, s, params.axis_clearance, 1.0);
        }
        clip_polygon(cut, clip);
    }
}

// c_k = ρ·√2^k, exactly as the twin (`band_bound` in axis.rs): ρ or ρ·√2, times 2^(k/2).
fn band_bound(k: u32) -> f32 {
    let base = select(params.axis_clearance, params.axis_clearance * BAND_RATIO, (k & 1u) == 1u);
    return ldexp(base, i32(k / 2u));
}

// The largest k < MAX_DIAMONDS with c_k ≤ d (0 if none): an estimate from the logarithm, then
// exact steps. `band_of` in axis.rs.
fn band_of(d: f32) -> u32 {
    var k = u32(min(2.0 * log2(max(d / params.axis_clearance, 1.0)), f32(MAX_DIAMONDS - 1u)));
    loop {
        if (k == 0u || !(band_bound(k) > d)) {
            break;
        }
        k -= 1u;
    }
    loop {
        if (!(k + 1u < MAX_DIAMONDS && band_bound(k + 1u) <= d)) {
            break;
        }
        k += 1u;
    }
    return k;
}

fn cut_active(k: u32, cuts: vec2<u32>) -> bool {
    if (k < 32u) {
        return ((cuts.x >> k) & 1u) != 0u;
    }
    return k < 64u && ((cuts.y >> (k - 32u)) & 1u) != 0u;
}

// The next active diamond after k, or MAX_DIAMONDS. `next_cut` in axis.rs.
fn next_cut(k: u32, cuts: vec2<u32>) -> u32 {
    let j = k + 1u;
    if (j < 32u) {
        let low = cuts.x & (0xffffffffu << j);
        if (low != 0u) {
            return firstTrailingBit(low);
        }
    }
    if (j < 64u) {
        let high = cuts.y & (0xffffffffu << (max(j, 32u) - 32u));
        if (high != 0u) {
            return 32u + firstTrailingBit(high);
        }
    }
    return MAX_DIAMONDS;
}

// The largest active k with c_k ≤ d (k = 0, the square, always counts). `zone_of` in axis.rs.
fn zone_of(d: f32, cuts: vec2<u32>) -> u32 {
    var k = band_of(d);
    loop {
        if (k == 0u || cut_active(k, cuts)) {
            break;
        }
        k -= 1u;
    }
    return k;
}

// The smallest and largest |x| + |z| of the triangle's points (`diamond_range` in axis.rs).
fn diamond_range(p: array<vec3<f32>, 3>) -> vec2<f32> {
    let d = vec3<f32>(abs(p[0].x) + abs(p[0].z), abs(p[1].x) + abs(p[1].z), abs(p[2].x) + abs(p[2].z));
    let hi = max(max(d.x, d.y), d.z);
    var s: vec3<f32>;
    for (var e = 0u; e < 3u; e++) {
        let a = p[e];
        let b = p[(e + 1u) % 3u];
        s[e] = (b.z - a.z) * a.x - (b.x - a.x) * a.z;
    }
    if (all(s >= vec3<f32>(0.0)) || all(s <= vec3<f32>(0.0))) {
        return vec2<f32>(0.0, hi);
    }
    var lo = min(min(d.x, d.y), d.z);
    for (var e = 0u; e < 3u; e++) {
        let a = p[e];
        let b = p[(e + 1u) % 3u];
        if ((a.x < 0.0) != (b.x < 0.0) && a.x != 0.0 && b.x != 0.0) {
            lo = min(lo, abs(a.z + (b.z - a.z) * (a.x / (a.x - b.x))));
        }
        if ((a.z < 0.0) != (b.z < 0.0) && a.z != 0.0 && b.z != 0.0) {
            lo = min(lo, abs(a.x + (b.x - a.x) * (a.z / (a.z - b.z))));
        }
    }
    return vec2<f32>(lo, hi);
}

// The cuts the current triangle asks for (`triangle_cuts` in axis.rs), as bits 0–31, 32–63.
fn triangle_cuts(limit: f32, tri: ptr<function, InputTriangle>) -> vec2<u32> {
    let range = diamond_range((*tri).position);
    let lo = range.x;
    let hi = range.y;
    if (!asks_for_cuts(range)) {
        return vec2<u32>(0u);
    }
    var bits = vec2<u32>(1u, 0u);
    for (var k = 1u; k < MAX_DIAMONDS; k++) {
        let c = band_bound(k);
        if (c >= limit || c >= hi) {
            break;
        }
        if (lo < c) {
            if (k < 32u) {
                bits.x |= 1u << k;
            } else {
                bits.y |= 1u << (k - 32u);
            }
        }
    }
    return bits;
}

// Whether every corner of the polygon kept in `quadrant` is on the far side of the cut (x: the
// clip would be empty), or none is (y: the clip would change nothing). `Polygon::all_beyond`
// in axis.rs.
fn quadrant_beyond(cut: Cut, clip: ptr<function, ClipState>) -> vec2<bool> {
    var beyond = true;
    var within = true;
    for (var i = 0u; i < (*clip).quadrant_count; i++) {
        let d = cut_distance(cut, (*clip).pool[(*clip).quadrant_at + i].position);
        beyond = beyond && d < 0.0;
        within = within && d >= 0.0;
    }
    return vec2<bool>(beyond, within);
}

// Whether the input triangle lies strictly inside quadrant s and between two consecutive active
// diamonds: then it is its own single part. `single_band` in axis.rs.
fn single_band(s: vec2<f32>, tri: ptr<function, InputTriangle>, cuts: vec2<u32>) -> bool {
    let p = (*tri).position;
    let dx = vec3<f32>(s.x * p[0].x, s.x * p[1].x, s.x * p[2].x);
    let dz = vec3<f32>(s.y * p[0].z, s.y * p[1].z, s.y * p[2].z);
    if (!(all(dx > vec3<f32>(0.0)) && all(dz > vec3<f32>(0.0)))) {
        return false;
    }
    let d = dx + dz;
    let k = zone_of(min(min(d.x, d.y), d.z), cuts);
    let lower = Cut(CUT_CHORD, s, band_bound(k), 1.0);
    let next = next_cut(k, cuts);
    let upper = Cut(CUT_CHORD, s, band_bound(min(next, MAX_DIAMONDS - 1u)), -1.0);
    for (var i = 0u; i < 3u; i++) {
        if (cut_distance(lower, p[i]) <= 0.0 || (next < MAX_DIAMONDS && cut_distance(upper, p[i]) <= 0.0)) {
            return false;
        }
    }
    return true;
}

const QUADRANT_SIGNS = array<vec2<f32>, 4>(vec2<f32>(1.0, -1.0), vec2<f32>(1.0, 1.0), vec2<f32>(-1.0, 1.0), vec2<f32>(-1.0, -1.0));

// Whether the current triangle is its own single part: no cuts this frame; not cut by all of
// them (`full` false: asks for none and has no edge of one that does) and no edge of a cut
// triangle (`marks`, its edges'); or one quadrant and one band (the loop of `plan_quadrant`
// would give that part).
fn single_part(full: bool, marks: vec3<u32>, tri: ptr<function, InputTriangle>, cuts: vec2<u32>) -> bool {
    if (all(cuts == vec2<u32>(0u))) {
        return true;
    }
    if (!full) {
        return all((marks & vec3<u32>(EDGE_CUT)) == vec3<u32>(0u));
    }
    for (var q = 0u; q < 4u; q++) {
        if (single_band(QUADRANT_SIGNS[q], tri, cuts)) {
            return true;
        }
    }
    return false;
}

// Appends every part of the current triangle in quadrant q for `plan_parts` (`polygons` in
// axis.rs: band by band outwards, along each fan).
fn plan_quadrant(t: u32, q: u32, tri: ptr<function, InputTriangle>, part: ptr<function, PartPlan>, clip: ptr<function, ClipState>, cuts: vec2<u32>) {
    let signs = QUADRANT_SIGNS;
    {
        let s = signs[q];
        // What lies in the quadrant beyond the first diamond (`rest` in axis.rs); each band is
        // cut from it, and the rest beyond the next diamond from the same polygon.
        quadrant_polygon(s, tri, clip);
        if ((*clip).poly_count == 0u) {
            return;
        }
        (*clip).quadrant_at = (*clip).poly_at;
        (*clip).quadrant_count = (*clip).poly_count;
        // Start at the band of the nearest corner: the bands below are empty, and cutting them
        // away would leave the polygon as it is (the twin runs them; the parts are the same).
        var d_min = 1e30;
        for (var i = 0u; i < (*clip).quadrant_count; i++) {
            d_min = min(d_min, s.x * (*clip).pool[(*clip).quadrant_at + i].position.x + s.y * (*clip).pool[(*clip).quadrant_at + i].position.z);
        }
        var k = zone_of(d_min, cuts);
        loop {
            if ((*clip).quadrant_count == 0u) {
                break;
            }
            k = next_cut(k, cuts);
            let c = band_bound(min(k, MAX_DIAMONDS - 1u));
            if (k >= MAX_DIAMONDS) {
                (*clip).poly_at = (*clip).quadrant_at;
                (*clip).poly_count = (*clip).quadrant_count;
                (*clip).quadrant_count = 0u; // the last band: all the rest
            } else {
                let within = Cut(CUT_CHORD, s, c, -1.0);
                let test = quadrant_beyond(within, clip);
                if (test.x) {
                    continue; // all of it lies beyond this band
                }
                (*clip).poly_at = (*clip).quadrant_at;
                (*clip).poly_count = (*clip).quadrant_count;
                if (test.y) {
                    (*clip).quadrant_count = 0u;
                } else {
                    // The band within the diamond, then the rest beyond it, from one call site
                    // of clip_polygon.
                    var band_at = 0u;
                    var band_count = 0u;
                    for (var side = 0u; side < 2u; side++) {
                        clip_polygon(Cut(CUT_CHORD, s, c, select(-1.0, 1.0, side == 1u)), clip);
                        if (side == 0u) {
                            band_at = (*clip).poly_at;
                            band_count = (*clip).poly_count;
                            (*clip).keep_at = band_at;
                            (*clip).poly_at = (*clip).quadrant_at;
                            (*clip).poly_count = (*clip).quadrant_count;
                        }
                    }
                    (*clip).quadrant_at = (*clip).poly_at;
                    (*clip).quadrant_count = (*clip).poly_count;
                    (*clip).poly_at = band_at;
                    (*clip).poly_count = band_count;
                    (*clip).keep_at = (*clip).quadrant_at;
                }
            }
            plan_band(t, part, clip);
        }
    }
}

// Appends a crossing of the current edge to the pool, unless it is an end of the edge or there
// already (a plane's crossing is found in two or four quadrants).
fn add_crossing(n: Node, clip: ptr<function, ClipState>) {
    if (same(n.position, (*clip).edge_ends[0]) || same(n.position, (*clip).edge_ends[1])) {
        return;
    }
    for (var i = (*clip).run_start; i < (*clip).poly_count; i++) {
        if (same((*clip).pool[i].position, n.position)) {
            return;
        }
    }
    if ((*clip).poly_count < 21u) {
        (*clip).pool[(*clip).poly_count] = n;
        (*clip).poly_count += 1u;
    }
}

// Clips the segment to the side cut ≥ 0 as `clip_polygon` clips a polygon's edge, keeping the
// crossing (`clip_segment` in axis.rs).
fn clip_segment(cut: Cut, clip: ptr<function, ClipState>) {
    if (!(*clip).seg_live) {
        return;
    }
    let dp = cut_distance(cut, (*clip).seg_p.position);
    let dq = cut_distance(cut, (*clip).seg_q.position);
    if ((dp >= 0.0) != (dq >= 0.0) && dp != 0.0 && dq != 0.0) {
        var lo = (*clip).seg_p;
        var hi = (*clip).seg_q;
        var d = vec2<f32>(dp, dq);
        if (lex_less((*clip).seg_q.position, (*clip).seg_p.position)) {
            lo = (*clip).seg_q;
            hi = (*clip).seg_p;
            d = d.yx;
        }
        let x = cut_crossing(cut.kind, lo, hi, d.x, d.y);
        add_crossing(x, clip);
        if (dp >= 0.0) {
            (*clip).seg_q = x;
        } else {
            (*clip).seg_p = x;
        }
        return;
    }
    (*clip).seg_live = dp >= 0.0 && dq >= 0.0;
}

// Appends to the pool the points where a cut triangle cuts edge a → b (ends excluded), in order
// from a (`edge_crossings` in axis.rs): the same clips in the same order, on the edge alone.
fn edge_crossings(a: Node, b: Node, clip: ptr<function, ClipState>, cuts: vec2<u32>) {
    (*clip).run_start = (*clip).poly_count;
    (*clip).edge_ends = array<vec3<f32>, 2>(a.position, b.position);
    for (var q = 0u; q < 4u; q++) {
        let s = QUADRANT_SIGNS[q];
        (*clip).seg_p = a;
        (*clip).seg_q = b;
        (*clip).seg_live = true;
        // x = 0, z = 0, the first diamond, then each band's, from one call site of clip_segment.
        var step = 0u;
        var k = 0u;
        loop {
            var cut = Cut(select(CUT_X, CUT_Z, step == 1u), s, 0.0, 1.0);
            if (step == 2u) {
                cut = Cut(CUT_CHORD, s, params.axis_clearance, 1.0);
            } else if (step > 2u) {
                k = next_cut(k, cuts);
                if (!(*clip).seg_live || k >= MAX_DIAMONDS) {
                    break;
                }
                cut = Cut(CUT_CHORD, s, band_bound(k), 1.0);
            }
            clip_segment(cut, clip);
            step += 1u;
        }
    }
    // In order along the edge (insertion sort; a few points).
    let dir = b.position - a.position;
    for (var i = (*clip).run_start + 1u; i < (*clip).poly_count; i++) {
        let n = (*clip).pool[i];
        let key = dot(n.position - a.position, dir);
        var j = i;
        loop {
            if (j == (*clip).run_start || !(dot((*clip).pool[j - 1u].position - a.position, dir) > key)) {
                break;
            }
            (*clip).pool[j] = (*clip).pool[j - 1u];
            j -= 1u;
        }
        (*clip).pool[j] = n;
    }
}

// Appends for `plan_parts` the parts of triangle t, which is not cut by all cuts, at the
// crossings of its edges that cut triangles have (`edge_split_parts` in axis.rs): its boundary
// (corner e, then edge e's crossings) in the pool; with crossings on one edge the fan from the
// opposite corner, on more the fan from the centroid, on none the triangle.
fn plan_edge_split(t: u32, tri: ptr<function, InputTriangle>, part: ptr<function, PartPlan>, clip: ptr<function, ClipState>, cuts: vec2<u32>) {
    let corners = array<Node, 3>(Node((*tri).position[0], vec3<f32>(1.0, 0.0, 0.0)),
                                 Node((*tri).position[1], vec3<f32>(0.0, 1.0, 0.0)),
                                 Node((*tri).position[2], vec3<f32>(0.0, 0.0, 1.0)));
    (*clip).poly_count = 0u;
    var crossed = 0u;
    var chain = vec3<u32>(0u); // the crossed edge, its corner's slot, its nodes before the next corner
    let marks = edge_marks(t);
    for (var e = 0u; e < 3u; e++) {
        let at = (*clip).poly_count;
        (*clip).pool[at] = corners[e];
        (*clip).poly_count += 1u;
        if ((marks[e] & EDGE_CUT) != 0u) {
            edge_crossings(corners[e], corners[(e + 1u) % 3u], clip, cuts);
        }
        if ((*clip).poly_count > at + 1u) {
            crossed += 1u;
            chain = vec3<u32>(e, at, (*clip).poly_count - at);
        }
    }
    // The parts: the triangle, or the fan (apex, pool[i], pool[i + 1 mod the polygon's count])
    // of those not off screen, appended for `plan_parts`.
    var apex = weighted(corners, vec3<f32>(1.0 / 3.0));
    var first = 0u;
    var count = (*clip).poly_count;
    if (crossed == 0u) {
        count = 1u;
    } else if (crossed == 1u) {
        apex = corners[(chain.x + 2u) % 3u];
        first = chain.y;
        count = chain.z;
    }
    for (var k = 0u; k < count; k++) {
        if (crossed == 0u) {
            (*part).corner = corners;
        } else {
            let i = first + k;
            (*part).corner[0] = apex;
            (*part).corner[1] = (*clip).pool[i];
            (*part).corner[2] = (*clip).pool[(i + 1u) % (*clip).poly_count];
            if (off_screen_vertically((*part).corner[0].position, (*part).corner[1].position, (*part).corner[2].position)) {
                continue;
            }
        }
        append_part(t, part);
    }
}

// The band polygon in `poly` (of triangle `t`): its fan's parts appended for `plan_parts` (a
// quadrant near a pole or beside a floor has many bands: planning them all here made the longest
// threads of the frame). Parts wholly beyond the image's rows left out.
fn plan_band(t: u32, part: ptr<function, PartPlan>, clip: ptr<function, ClipState>) {
    for (var i = 1u; i + 1u < (*clip).poly_count; i++) {
        (*part).corner[0] = poly_node(0, clip);
        (*part).corner[1] = poly_node(i, clip);
        (*part).corner[2] = poly_node(i + 1u, clip);
        if (!off_screen_vertically((*part).corner[0].position, (*part).corner[1].position, (*part).corner[2].position)) {
            append_part(t, part); // its counts are left to `plan_parts`
        }
    }
}

// Whether a triangle with diamond distances `range` (`diamond_range`) reaches the first diamond
// or spans a wide range of them: those ask for cuts (`triangle_cuts`).
fn asks_for_cuts(range: vec2<f32>) -> bool {
    return range.x < band_bound(1u) || range.y > WIDE_RATIO * range.x;
}
