// The stand-in for `subdivide_spacing` in the pipelines of the split rules that space nodes
// evenly (vertex, fixed, eq. 5): equal parts, the barycentric blend. Its functions are
// `subdivide_spacing`'s that other modules call, with the same signatures (the naga test
// composes both).

#import subdivide_state

// Even spacing: nothing measured.
fn spacer(lo: vec3<f32>, hi: vec3<f32>) -> Spacer {
    return Spacer(false, 0.0, 0.0, 0.0);
}

fn spaced(sp: Spacer, t: f32) -> f32 {
    return t;
}

fn spacing_mix(a: Node, b: Node, t: f32) -> Node {
    return Node(a.position + (b.position - a.position) * t, a.bary + (b.bary - a.bary) * t);
}

fn spaced_interior(q: array<Node, 3>, c: vec3<u32>, m: u32) -> Node {
    return weighted(q, vec3<f32>(c) / f32(m));
}
