// A triangle's edges (seed 002 §2.3, eq. 5, and the error split): edge nodes computed from the
// canonically ordered pair, the projected profile of an edge, its division count; loading an
// input triangle; the part's level and pre-split. CPU twin: src/cpu/subdivide/mod.rs.

#import projection
#import constants
#import subdivide_bindings
#import subdivide_state
#import subdivide_spacing

fn lex_less(a: vec3<f32>, b: vec3<f32>) -> bool {
    return a.x < b.x || (a.x == b.x && (a.y < b.y || (a.y == b.y && a.z < b.z)));
}

fn same(a: vec3<f32>, b: vec3<f32>) -> bool {
    return all(a == b);
}

// The point j/n of the way from a to b, from the canonically ordered pair; the ends are exact.
fn edge_point(a: Node, b: Node, j: u32, n: u32) -> Node {
    var lo = a;
    var hi = b;
    var jj = j;
    if (lex_less(b.position, a.position)) {
        lo = b;
        hi = a;
        jj = n - j;
    }
    if (jj == 0u) {
        return lo;
    }
    if (jj == n) {
        return hi;
    }
    return spacing_mix(lo, hi, f32(jj) / f32(n));
}

// Image positions in pixels (x not wrapped) of a viewer-frame point: both eyes' (the left's first),
// from one projection (`project_both_at`, the point's eye offset given).
fn pixels(p: vec3<f32>, offset: f32) -> array<vec2<f32>, 2> {
    let q = project_both_at(params.projection, p, azimuth(p), offset);
    var out: array<vec2<f32>, 2>;
    for (var s = 0u; s < 2u; s++) {
        out[s] = pixel_of(q[s]);
    }
    return out;
}

// The image position in pixels of a projected point (u, v, depth).
fn pixel_of(q: vec3<f32>) -> vec2<f32> {
    if (is_fisheye(params.projection)) {
        return fisheye_pixel(params.projection, q.x, q.y) - 0.5 * vec2<f32>(params.projection.width, params.projection.height);
    }
    return vec2<f32>(q.x * params.projection.turn_px / TAU, q.y * params.projection.pixels_per_v);
}

// Whether every ray to the segment ab comes from the centre (`Projection::seen_from_centre`): no
// eye offset, or both ends in one of the pole merge's cones beyond its end.
fn seen_from_centre(a: vec3<f32>, b: vec3<f32>) -> bool {
    let proj = params.projection;
    if (proj.eye_radius == 0.0) {
        return true;
    }
    if (proj.pole_to <= 0.0) {
        return false;
    }
    let merged_a = a.y != 0.0 && atan2(abs(a.y), horizontal_radius(a)) >= proj.pole_to;
    let merged_b = b.y != 0.0 && atan2(abs(b.y), horizontal_radius(b)) >= proj.pole_to;
    return merged_a && merged_b && (a.y > 0.0) == (b.y > 0.0);
}

// What the split rules read of the straight edge ab (`Subdivider::edge_profile`): sampled at
// `segments` segments, both eyes, in canonical order: the projected length by which eq. 5 splits
// it (heights clamped, segments beyond the clamp at both ends counting 0, stretch-adjusted), the
// largest second difference of the sampled points (x unwrapped, triples beyond the clamp
// skipped) by which the error split splits it, and whether it comes near the eye circle.
struct EdgeProfile {
    length_px: f32,
    bend_px: f32,
    ring: bool,
    residual_px: f32,  // the drawing's residual against the azimuth steps (`EdgeProfile`)
    // Each eye's largest second difference (the left's xy, the right's zw; y up): where nodes
    // are drawn off their projections, a line's offset (`line_offsets`).
    bend_vec: vec4<f32>,
}

fn edge_profile(a: vec3<f32>, b: vec3<f32>, segments: u32) -> EdgeProfile {
    var lo = a;
    var hi = b;
    if (lex_less(b, a)) {
        lo = b;
        hi = a;
    }
    // Drawn by pinholes (`Subdivider::edge_profile`): whose every ray to it comes from the
    // centre, exact; its length the angle it spans.
    let pinhole = PINHOLE_FACES && params.pinhole_faces != 0u;
    var angle_px = 0.0;
    if (pinhole) {
        angle_px = atan2(length(cross(lo, hi)), dot(lo, hi)) * params.projection.turn_px / TAU;
        if (seen_from_centre(lo, hi)) {
            return EdgeProfile(angle_px, 0.0, false, 0.0, vec4<f32>(0.0));
        }
    }
    let clamp_v = 1.5 * params.projection.height;
    let width = params.projection.turn_px; // a full turn in pixels: x wraps at it
    var length_px = 0.0;
    var longest = 0.0;
    var nearest = 1e30;
    var bend = 0.0;
    var bend_vec: array<vec2<f32>, 2>;
    let sp = spacer(lo, hi);
    // Each point projected once for both eyes (`pixels`), each eye's walk kept apart.
    var total = vec2<f32>(0.0);
    var prev: array<vec2<f32>, 2>;
    var q0: array<vec2<f32>, 2>;
    var q1: array<vec2<f32>, 2>;
    // The pinholes' eye points (`pinhole_profile` in edges.rs): the last two, and the distance
    // along the ray at the last.
    var e0: array<vec3<f32>, 2>;
    var e1: array<vec3<f32>, 2>;
    var depth1 = vec2<f32>(1.0);
    var eye_bend = 0.0;
    for (var k = 0u; k <= segments; k++) {
        let t = f32(k) / f32(segments);
        let p = lo + (hi - lo) * spaced(sp, t);
        // How far inside twice the eye offset at its altitude the point lies (d_e on the
        // cylinder; the sphere's pole merge fades it, and with it the ring).
        let r = horizontal_radius(p);
        let offset = eye_offset(params.projection, r, p.y);
        nearest = min(nearest, r - 2.0 * offset);
        let projected = project_both_at(params.projection, p, azimuth(p), offset);
        for (var s = 0u; s < 2u; s++) {
            let raw = pixel_of(projected[s]);
            if (pinhole) {
                // The eye point E = s·d·(cos λ, 0, sin λ) (core/panoramas/sphere.rs).
                let e = select(-offset, offset, s == 1u) * vec3<f32>(cos(projected[s].x), 0.0, sin(projected[s].x));
                if (k >= 2u) {
                    eye_bend = max(eye_bend, length(e - 2.0 * e1[s] + e0[s]) / depth1[s]);
                }
                e0[s] = e1[s];
                e1[s] = e;
                depth1[s] = projected[s].z;
            }
            var q = raw;
            q.y = clamp(q.y, -clamp_v, clamp_v);
            let dx = (q.x - prev[s].x) - width * round((q.x - prev[s].x) / width);
            if (k > 0u && !(q.y == prev[s].y && abs(q.y) == clamp_v)) {
                let segment = length(vec2<f32>(dx, q.y - prev[s].y));
                longest = max(longest, segment);
                total[s] += segment;
            }
            let unwrapped = vec2<f32>(select(raw.x, q1[s].x + dx, k > 0u), raw.y);
            if (k >= 2u && abs(unwrapped.y) < clamp_v && abs(q1[s].y) < clamp_v && abs(q0[s].y) < clamp_v) {
                let second = unwrapped - 2.0 * q1[s] + q0[s];
                bend = max(bend, length(second));
                bend_vec[s] = select(bend_vec[s], second, length(second) > length(bend_vec[s]));
            }
            q0[s] = q1[s];
            q1[s] = unwrapped;
            prev[s] = q;
        }
    }
    length_px = max(max(length_px, total[0]), total[1]);
    // Near the eye circle, which the paper model and the sphere show on screen (α and the
    // longitude ∝ √(r − d_e)), no stretch is allowed (the exact model puts it at v = ±∞).
    let shows_ring = !VERTICAL_EXACT || params.projection.vertical_exact == 0u || is_sphere(params.projection);
    let ring = shows_ring && nearest < 0.0;
    if (pinhole) {
        return EdgeProfile(angle_px, eye_bend * params.projection.turn_px / TAU, ring, 0.0, vec4<f32>(0.0));
    }
    let stretch = select(MAX_STRETCH, 1.0, ring);
    let residual = AZIMUTH_CHORD_RESIDUAL * sp.turn * sp.turn * f32(segments) * longest;
    return EdgeProfile(max(length_px, f32(segments) * longest / stretch), bend, ring, residual, vec4<f32>(bend_vec[0], bend_vec[1]));
}

// Parts that keep the drawing's residual within AZIMUTH_RESIDUAL_ERROR·τ (`parts_for_residual`).
// The fewest n with n³ ≥ x: pow's guess corrected by products, which round as the twin's do.
fn parts_for_residual(p: EdgeProfile, max_error_px: f32) -> f32 {
    let x = p.residual_px / (AZIMUTH_RESIDUAL_ERROR * max_error_px);
    if (x <= 1.0) {
        return 1.0;
    }
    let n = ceil(pow(x, 1.0 / 3.0));
    if ((n - 1.0) * (n - 1.0) * (n - 1.0) >= x) {
        return n - 1.0;
    }
    return select(n, n + 1.0, n * n * n < x);
}

// Whether the edge drawn in one part is within `share`·τ of its bend and the residual's share of
// its azimuth steps, away from the eye circle (`EdgeProfile::straight`).
fn profile_straight(p: EdgeProfile, share: f32, max_error_px: f32) -> bool {
    return !p.ring && parts_for_bend(p.bend_px, 2u, share * max_error_px) <= 1.0 && parts_for_residual(p, max_error_px) <= 1.0;
}

// Parts for a chord error of at most τ (`parts_for_bend`).
fn parts_for_bend(bend_px: f32, segments: u32, max_error_px: f32) -> f32 {
    return ceil(f32(segments) * sqrt(bend_px / (8.0 * max_error_px)));
}

// What an adaptive rule reads of round `round` of an edge's profiles
// (`Subdivider::edge_divisions`): after the quick one, 1 where the edge needs no more, else 0;
// after the full one, its parts.
fn divisions_of(round: u32, p: EdgeProfile, segments: u32, tri: ptr<function, InputTriangle>) -> f32 {
    let by_length = split_rule() == METHOD_ADAPTIVE;
    if (round == 0u) {
        let whole = select(p.length_px <= (*tri).edge_px && profile_straight(p, 1.0, (*tri).max_error_px),
                           p.length_px <= 0.5 * (*tri).edge_px, by_length);
        return select(0.0, 1.0, whole);
    }
    if (by_length) {
        return ceil(p.length_px / (*tri).edge_px);
    }
    let longest = select(ERROR_SPLIT_LENGTH * (*tri).edge_px, (*tri).edge_px, p.ring);
    return max(max(parts_for_bend(p.bend_px, segments, (*tri).max_error_px), ceil(p.length_px / longest)), parts_for_residual(p, (*tri).max_error_px));
}

// A division count from the parts a profile asks for, within 1 and MAX_EDGE_DIVISIONS.
fn division_count(n: f32) -> u32 {
    if (n >= f32(MAX_EDGE_DIVISIONS) || !(n == n)) {
        return MAX_EDGE_DIVISIONS;
    }
    return max(u32(n), 1u);
}

// Whether a triangle lies wholly above or below the image (see `off_screen_vertically` in
// src/cpu/subdivide/ for why testing the corners suffices).
fn off_screen_vertically(p0: vec3<f32>, p1: vec3<f32>, p2: vec3<f32>) -> bool {
    let k = params.vertical_limit;
    // A tracked head's eyes are fixed, d_e beside its axis: a point r from that axis may lie
    // r + d_e from an eye, where it rises less steeply.
    let pad = select(0.0, params.projection.eye_radius, params.projection.head_on != 0.0);
    let r = vec3<f32>(horizontal_radius(p0), horizontal_radius(p1), horizontal_radius(p2)) + vec3<f32>(pad);
    let y = vec3<f32>(p0.y, p1.y, p2.y);
    return all(y > k * r) || all(y < -k * r) || around_dome_antipode(p0, p1, p2);
}

// Whether input triangle t is single-sided and every eye sees its back, so that it is drawn
// nowhere (`Subdivider::faces_away`): with n its front's normal (counter-clockwise corners) and
// p0 a corner in the viewer frame, n·(E − p0) < 0 for every eye point E, all within d_e of the
// viewer in the horizontal plane (the CAVE's and a tracked head's eyes are not: never there).
fn faces_away(t: u32, p0: vec3<f32>, p1: vec3<f32>, p2: vec3<f32>) -> bool {
    if ((vertices[indices[3u * t]].flags & SINGLE_SIDED) == 0u || is_cave(params.projection) || params.projection.head_on != 0.0) {
        return false;
    }
    let n = cross(p1 - p0, p2 - p0);
    return dot(n, p0) > params.projection.eye_radius * length(n.xz) + BACK_FACE_MARGIN * length(n) * length(p0);
}

// Whether a triangle lies wholly in the cone around the point opposite the fisheye's axis
// (`Projection::around_dome_antipode`): there the image folds onto a ring.
fn around_dome_antipode(p0: vec3<f32>, p1: vec3<f32>, p2: vec3<f32>) -> bool {
    let c = params.antipode_cos;
    if (c > 1.0) {
        return false;
    }
    let t = radians(params.projection.dome_tilt);
    let axis = vec3<f32>(0.0, cos(t), sin(t));
    return dot(p0, axis) < -c * length(p0) && dot(p1, axis) < -c * length(p1) && dot(p2, axis) < -c * length(p2);
}

// The corners of input triangle t in the viewer frame, snapped to the cut planes.
fn load_positions(t: u32, tri: ptr<function, InputTriangle>) {
    for (var k = 0u; k < 3u; k++) {
        let v = vertices[indices[3u * t + k]];
        (*tri).position[k] = snap_to_cut_planes((params.view * vec4<f32>(v.position, 1.0)).xyz);
    }
}

// Loads an input triangle into the viewer frame, its vertices snapped to the cut planes
// (its parts, their edge counts and K come from `visit_parts` or from the piece record).
fn load_triangle(t: u32, tri: ptr<function, InputTriangle>) {
    load_positions(t, tri);
    for (var k = 0u; k < 3u; k++) {
        let v = vertices[indices[3u * t + k]];
        (*tri).normal[k] = (params.view * vec4<f32>(v.normal, 0.0)).xyz;
        (*tri).color[k] = v.color;
        (*tri).uv[k] = v.uv;
        let t = unpack_tangent(v.tangent);
        (*tri).tangent[k] = vec4<f32>((params.view * vec4<f32>(t.xyz, 0.0)).xyz, t.w);
    }
    (*tri).material = vertices[indices[3u * t]].material;
    (*tri).object = vertices[indices[3u * t]].object;
    let scale = object_edge_scale[min((*tri).object, arrayLength(&object_edge_scale) - 1u)];
    (*tri).edge_px = params.edge_px * scale;
    (*tri).max_error_px = params.max_error_px * (scale * scale);
}

// Whether the method is one of the adaptive rules (eq. 5 or the error split).
fn is_adaptive() -> bool {
    return split_rule() == METHOD_ADAPTIVE || split_rule() == METHOD_ERROR;
}

// Edge counts and macro-lattice level of the current part.
fn plan_part(tri: ptr<function, InputTriangle>, part: ptr<function, PartPlan>) {
    let c = array<vec3<f32>, 3>((*part).corner[0].position, (*part).corner[1].position, (*part).corner[2].position);
    var bends: array<vec4<f32>, 3>;
    let n = edge_counts(c, vec3<bool>(true), tri, &bends);
    for (var e = 0u; e < 3u; e++) {
        (*part).n[e] = n[e];
    }
    (*part).bend = bends;
    plan_level(part);
}

// The divisions of the edges e (corner e → e + 1) of a triangle that `wanted` names (0 for the
// others; `Subdivider::edge_divisions` of each), their rounds interleaved: the quick profiles, then the full ones of the edges that
// need them, listed, from one call site of the profile, so that side by side invocations
// measure together (one measuring an edge fully while another waited, three times over).
fn edge_counts(c: array<vec3<f32>, 3>, wanted: vec3<bool>, tri: ptr<function, InputTriangle>, bends: ptr<function, array<vec4<f32>, 3>>) -> vec3<u32> {
    var n = vec3<u32>(0u);
    var list: array<u32, 6>;
    var count = 0u;
    for (var e = 0u; e < 3u; e++) {
        if (wanted[e]) {
            n[e] = select(params.fixed_n, 1u, split_rule() == METHOD_VERTEX);
            list[count] = e;
            count += 1u;
        }
    }
    if (!is_adaptive()) {
        return n; // the vertex and fixed rules measure nothing
    }
    let quick = count;
    for (var k = 0u; k < count; k++) {
        let e = list[k];
        let full = k >= quick;
        let segments = select(2u, EDGE_SAMPLES, full);
        let profile = edge_profile(c[e], c[(e + 1u) % 3u], segments);
        let parts = divisions_of(select(0u, 1u, full), profile, segments, tri);
        if (full || parts == 1.0) {
            n[e] = division_count(parts);
            (*bends)[e] = select(vec4<f32>(0.0), profile.bend_vec, full);
        } else {
            list[count] = e;
            count += 1u;
        }
    }
    return n;
}

// The macro-lattice level of the current part from its edge counts `tri_n`, and whether it is
// cut in bands instead (`PartSplit::new` in src/cpu/subdivide/lattice.rs).
fn plan_level(part: ptr<function, PartPlan>) {
    let m = max(max((*part).n[0], (*part).n[1]), (*part).n[2]);
    (*part).k = 1u;
    if (is_adaptive()) {
        let step = min(params.max_div, PIECE_DIVISIONS);
        (*part).k = min((m + step - 1u) / step, MAX_MACRO_LEVEL);
    } else if (split_rule() == METHOD_FIXED) {
        (*part).k = (m + PIECE_DIVISIONS - 1u) / PIECE_DIVISIONS;
    }
    (*part).bands = is_adaptive() && (*part).k >= 3u && (*part).n[band_base((*part).n)] <= band_rows();
}

// Whether `parts` parts across a band of a piece's rows are enough for the zipper's diagonals,
// judged on one of the band's whole diagonals (its quick profile): `adaptive:length`, the
// length within parts × L/2; the error split, the bend within parts × ROW_DIAGONAL_ERROR·τ and
// the length within parts × ERROR_SPLIT_LENGTH·L (`diagonal_fits` in src/cpu/subdivide/edges.rs;
// products, not quotients, which round alike on both sides).
fn diagonal_fits(whole: EdgeProfile, parts: u32, tri: ptr<function, InputTriangle>) -> bool {
    let w = f32(parts);
    if (split_rule() == METHOD_ADAPTIVE) {
        return 2.0 * whole.length_px <= w * (*tri).edge_px;
    }
    return whole.bend_px <= w * (2.0 * ROW_DIAGONAL_ERROR * (*tri).max_error_px)
        && whole.length_px <= w * (ERROR_SPLIT_LENGTH * (*tri).edge_px)
        && whole.residual_px <= w * w * w * (AZIMUTH_RESIDUAL_ERROR * (*tri).max_error_px);
}

// Where macro node (a, b, c)/K lies, as (kind, i, j): kind 0 = triangle corner i; kind 1 = fine
// node j (0 < j < n_i) of original edge i; kind 2 = interior. Nodes on an original edge snap to
// its fine nodes and may land on a corner. (`Location` in subdivide.rs.)
