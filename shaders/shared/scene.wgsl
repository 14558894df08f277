// The scene's vertices as uploaded (`SceneVertex` in src/core/scenes/scene.rs), read by the stages
// that start from the scene (subdivide, trace), and the tangent's packing (also raster, slit).

struct SceneVertex {
    position: vec3<f32>,
    material: u32,
    normal: vec3<f32>,
    object: u32,
    color: vec4<f32>,
    uv: vec2<f32>,
    tangent: u32,   // glTF's TANGENT, packed (`pack_tangent`); 0: none
    flags: u32,     // SINGLE_SIDED: its material draws no back faces (`Scene::mark_sides`)
}

// A tangent and its bitangent sign (unit xyz, w = ±1) in 32 bits: octahedral coordinates in 15
// bits each, w < 0 in bit 30, bit 31 set; 0 (none) for a zero direction (`pack_tangent` in
// src/core/scenes/scene.rs).
fn pack_tangent(t: vec4<f32>) -> u32 {
    let sum = abs(t.x) + abs(t.y) + abs(t.z);
    if (!(sum > 0.0)) {
        return 0u;
    }
    var e = t.xy / sum;
    if (t.z < 0.0) {
        let s = select(vec2<f32>(-1.0), vec2<f32>(1.0), e >= vec2<f32>(0.0));
        e = (1.0 - abs(e.yx)) * s;
    }
    let q = vec2<u32>(floor(clamp(e, vec2<f32>(-1.0), vec2<f32>(1.0)) * 16383.0 + 0.5) + 16384.0);
    return q.x | (q.y << 15u) | select(0u, 1u << 30u, t.w < 0.0) | (1u << 31u);
}

// The tangent of `pack_tangent`, or zero for none.
fn unpack_tangent(bits: u32) -> vec4<f32> {
    if ((bits & (1u << 31u)) == 0u) {
        return vec4<f32>(0.0);
    }
    let ex = f32(bits & 0x7fffu) / 16383.0 - 16384.0 / 16383.0;
    let ey = f32((bits >> 15u) & 0x7fffu) / 16383.0 - 16384.0 / 16383.0;
    var n = vec3<f32>(ex, ey, 1.0 - abs(ex) - abs(ey));
    let t = max(-n.z, 0.0);
    n.x += select(t, -t, n.x >= 0.0);
    n.y += select(t, -t, n.y >= 0.0);
    return vec4<f32>(normalize(n), select(1.0, -1.0, (bits & (1u << 30u)) != 0u));
}
