// How nodes are spaced along a segment under the error split, and a lattice's interior points
// (CPU twin: src/cpu/subdivide/spacing.rs, which says why). Composed only into the pipelines of
// the frames that space nodes by azimuth (`SubdivideParams::by_azimuth`: the error split, but on
// the cubemap); the others' are composed with the stand-in `subdivide_spacing_off` (equal parts,
// the barycentric blend). So the parameter is not tested here: lavapipe's lanes would run both
// ways.

#import projection
#import constants
#import subdivide_bindings
#import subdivide_state

// How segment lo–hi's points are spaced (`Spacing::spacer`): by azimuth.
fn spacer(lo: vec3<f32>, hi: vec3<f32>) -> Spacer {
    let rl = horizontal_radius(lo);
    let rh = horizontal_radius(hi);
    if (rl < AZIMUTH_MIN_RADIUS || rh < AZIMUTH_MIN_RADIUS) {
        return Spacer(false, rl, rh, 0.0);
    }
    let el = vec2<f32>(lo.x, lo.z) / rl;
    let eh = vec2<f32>(hi.x, hi.z) / rh;
    let turn = precise_atan2(abs(el.x * eh.y - el.y * eh.x), dot(el, eh));
    return Spacer(true, rl, rh, select(0.0, turn, turn > AZIMUTH_MIN_TURN && turn < AZIMUTH_MAX_TURN));
}

// The 3-D parameter of the point at fraction t of the segment (`Spacer::param`): t, or under the
// error split the point at azimuth fraction t of the sweep.
fn spaced(sp: Spacer, t: f32) -> f32 {
    if (!sp.by_radius) {
        return t;
    }
    var blend = t;
    if (sp.turn > 0.0) {
        let a = precise_sin(t * sp.turn);
        blend = a / (a + precise_sin((1.0 - t) * sp.turn));
    }
    return (blend / sp.rh) / ((1.0 - blend) / sp.rl + blend / sp.rh);
}

// The node at fraction t of the way from a to b (`Spacing::mix`).
fn spacing_mix(a: Node, b: Node, t: f32) -> Node {
    let s = spaced(spacer(a.position, b.position), t);
    return Node(a.position + (b.position - a.position) * s, a.bary + (b.bary - a.bary) * s);
}

// The interior lattice point (i, j, l)/m of a triangle of nodes (`Spacing::interior`): the point
// j/(i + j) of the way along the row between the points l/m of the way from q0 and from q1
// towards q2, each spaced by azimuth.
fn spaced_interior(q: array<Node, 3>, c: vec3<u32>, m: u32) -> Node {
    // One call of spacing_mix in a loop (lavapipe inlines every call site): the row's ends,
    // then the point along the row.
    var mixed: array<Node, 3>;
    for (var s = 0u; s < 3u; s++) {
        var a = q[min(s, 1u)];
        var b = q[2];
        var t = f32(c.z) / f32(m);
        if (s == 2u) {
            a = mixed[0];
            b = mixed[1];
            t = f32(c.y) / f32(c.x + c.y);
        }
        mixed[s] = spacing_mix(a, b, t);
    }
    return mixed[2];
}
