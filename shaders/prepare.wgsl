// The `prepare` stage (compute): readies scene triangles for the projection vertex stage.
// CPU twin and full description: src/prepare.rs. Needs projection.wgsl composed in front.
//
// One invocation per input triangle: move it into the viewer frame, split it into 8 sectors
// with a chord cut around the vertical axis when its footprint contains or nears the axis (or
// spans > 90° of azimuth), and append each piece — plus a copy shifted by ∓2π where it crosses
// the ±π seam — to `out_vertices` through the atomic counter. `finalize` then writes the
// DrawIndirect arguments, clamped to the capacity (overflowing writes are never made).

struct SceneVertex {
    position: vec3<f32>,
    material: u32,
    normal: vec3<f32>,
    _pad0: u32,
    color: vec4<f32>,
    uv: vec2<f32>,
    _pad1: vec2<f32>,
}

struct DrawVertex {
    position: vec3<f32>,
    theta_ref: f32,
    normal: vec3<f32>,
    material: u32,
    color: vec4<f32>,
    uv: vec2<f32>,
    _pad: vec2<f32>,
}

struct PrepareParams {
    view: mat4x4<f32>,
    projection: Projection,
    axis_clearance: f32,
    triangle_count: u32,
    capacity: u32,        // in triangles
    first_triangle: u32,
}

struct Counter {
    requested: atomic<u32>, // triangles the stage wanted to write (may exceed capacity)
}

struct DrawIndirectArgs {
    vertex_count: u32,
    instance_count: u32,
    first_vertex: u32,
    first_instance: u32,
}

@group(0) @binding(0) var<uniform> params: PrepareParams;
@group(0) @binding(1) var<storage, read> vertices: array<SceneVertex>;
@group(0) @binding(2) var<storage, read> indices: array<u32>;
@group(0) @binding(3) var<storage, read_write> out_vertices: array<DrawVertex>;
@group(0) @binding(4) var<storage, read_write> counter: Counter;
@group(0) @binding(5) var<storage, read_write> draw_args: DrawIndirectArgs;

const SECTORS: u32 = 8u;
const MAX_SPAN: f32 = 1.6;  // rad, a little over 90°: no round angle, so meshes rarely sit on it
const MAX_POLY: u32 = 8u;
const SNAP: f32 = 1e-6;
const DUPLICATE_EPS: f32 = 1e-6; // barycentric distance below which clipped vertices coincide

// The input triangle in the viewer frame, shared by the helpers below.
var<private> tri_position: array<vec3<f32>, 3>;
var<private> tri_normal: array<vec3<f32>, 3>;
var<private> tri_color: array<vec4<f32>, 3>;
var<private> tri_uv: array<vec2<f32>, 3>;
var<private> tri_material: u32;

// The polygon being clipped, as barycentric coordinates of the input triangle: clipping is
// linear, so clipping barycentrics is exact and keeps the per-vertex state small.
var<private> poly: array<vec3<f32>, MAX_POLY>;
var<private> poly_count: u32;
var<private> scratch: array<vec3<f32>, MAX_POLY>;

fn bary_position(b: vec3<f32>) -> vec3<f32> {
    return b.x * tri_position[0] + b.y * tri_position[1] + b.z * tri_position[2];
}

// Signed distance to the half-plane a·x + b·z ≥ c, stored as (a, b, c). Points within a
// relative 1e-6 of the line count as on it, so that the CPU twin and the GPU (whose rounding
// differs in the last bits) take the same side for vertices that lie on a sector boundary.
fn plane_distance(plane: vec3<f32>, p: vec3<f32>) -> f32 {
    let d = plane.x * p.x + plane.y * p.z - plane.z;
    let scale = abs(plane.x * p.x) + abs(plane.y * p.z) + abs(plane.z);
    return select(d, 0.0, abs(d) <= SNAP * scale);
}

// Appends a clipped vertex unless it repeats the previous one (a corner lying on the clip line
// would otherwise come out twice, making a zero-area sliver).
fn push_clipped(n: u32, b: vec3<f32>) -> u32 {
    if (n > 0u && all(abs(b - scratch[n - 1u]) <= vec3<f32>(DUPLICATE_EPS))) {
        return n;
    }
    scratch[n] = b;
    return n + 1u;
}

// Sutherland–Hodgman clip of `poly` against one half-plane, in place.
fn clip_polygon(plane: vec3<f32>) {
    var n = 0u;
    for (var i = 0u; i < poly_count; i++) {
        let cur = poly[i];
        let next = poly[(i + 1u) % poly_count];
        let d0 = plane_distance(plane, bary_position(cur));
        let d1 = plane_distance(plane, bary_position(next));
        if (d0 >= 0.0) {
            n = push_clipped(n, cur);
        }
        if ((d0 >= 0.0) != (d1 >= 0.0)) {
            n = push_clipped(n, cur + (next - cur) * (d0 / (d0 - d1)));
        }
    }
    if (n > 1u && all(abs(scratch[n - 1u] - scratch[0]) <= vec3<f32>(DUPLICATE_EPS))) {
        n -= 1u;
    }
    for (var i = 0u; i < n; i++) {
        poly[i] = scratch[i];
    }
    poly_count = n;
}

// (cos, sin) of the sector boundaries −π + k·π/4 and of the sector middles, as exact tables
// shared with the CPU twin (the driver's cos/sin would differ from Rust's in the last bits).
const H: f32 = 0.707106781186548;
const C8: f32 = 0.923879532511287;
const S8: f32 = 0.382683432365090;
const BOUNDARY = array<vec2<f32>, 9>(
    vec2<f32>(-1.0, 0.0), vec2<f32>(-H, -H), vec2<f32>(0.0, -1.0), vec2<f32>(H, -H),
    vec2<f32>(1.0, 0.0), vec2<f32>(H, H), vec2<f32>(0.0, 1.0), vec2<f32>(-H, H), vec2<f32>(-1.0, 0.0),
);
const MIDDLE = array<vec2<f32>, 8>(
    vec2<f32>(-C8, -S8), vec2<f32>(-S8, -C8), vec2<f32>(S8, -C8), vec2<f32>(C8, -S8),
    vec2<f32>(C8, S8), vec2<f32>(S8, C8), vec2<f32>(-S8, C8), vec2<f32>(-C8, S8),
);

fn segment_distance(a: vec2<f32>, b: vec2<f32>) -> f32 {
    let ab = b - a;
    let len2 = dot(ab, ab);
    var t = 0.0;
    if (len2 > 0.0) {
        t = clamp(-dot(a, ab) / len2, 0.0, 1.0);
    }
    return length(a + ab * t);
}

fn cross2(a: vec2<f32>, b: vec2<f32>) -> f32 {
    return a.x * b.y - a.y * b.x;
}

fn needs_axis_split(split_radius: f32) -> bool {
    let q0 = tri_position[0].xz;
    let q1 = tri_position[1].xz;
    let q2 = tri_position[2].xz;
    let e0 = cross2(q1 - q0, -q0);
    let e1 = cross2(q2 - q1, -q1);
    let e2 = cross2(q0 - q2, -q2);
    let contains = (e0 >= 0.0 && e1 >= 0.0 && e2 >= 0.0) || (e0 <= 0.0 && e1 <= 0.0 && e2 <= 0.0);
    let near = min(min(segment_distance(q0, q1), segment_distance(q1, q2)), segment_distance(q2, q0)) < split_radius;
    let t0 = azimuth(tri_position[0]);
    let t1 = azimuth(tri_position[1]);
    let t2 = azimuth(tri_position[2]);
    let span = max(max(abs(wrap_angle(t0 - t1)), abs(wrap_angle(t1 - t2))), abs(wrap_angle(t2 - t0)));
    return contains || near || span > MAX_SPAN;
}

fn draw_vertex(b: vec3<f32>, theta_ref: f32) -> DrawVertex {
    return DrawVertex(
        bary_position(b),
        theta_ref,
        b.x * tri_normal[0] + b.y * tri_normal[1] + b.z * tri_normal[2],
        tri_material,
        b.x * tri_color[0] + b.y * tri_color[1] + b.z * tri_color[2],
        b.x * tri_uv[0] + b.y * tri_uv[1] + b.z * tri_uv[2],
        vec2<f32>(0.0, 0.0),
    );
}

fn write_triangle(slot: u32, b0: vec3<f32>, b1: vec3<f32>, b2: vec3<f32>, theta_ref: f32) {
    out_vertices[3u * slot] = draw_vertex(b0, theta_ref);
    out_vertices[3u * slot + 1u] = draw_vertex(b1, theta_ref);
    out_vertices[3u * slot + 2u] = draw_vertex(b2, theta_ref);
}

// Appends one triangle (barycentric corners) and, where it crosses the seam, its copy on the
// other side.
fn emit(b0: vec3<f32>, b1: vec3<f32>, b2: vec3<f32>) {
    let ps = array<vec3<f32>, 3>(bary_position(b0), bary_position(b1), bary_position(b2));
    let theta_c = azimuth((ps[0] + ps[1] + ps[2]) / 3.0);
    var u_min = 1e30;
    var u_max = -1e30;
    for (var i = 0u; i < 3u; i++) {
        let theta = theta_c + wrap_angle(azimuth(ps[i]) - theta_c);
        let alpha = abs(eye_shift(params.projection, horizontal_radius(ps[i])));
        u_min = min(u_min, theta - alpha);
        u_max = max(u_max, theta + alpha);
    }
    let copy_left = u_max > PI;
    let copy_right = u_min < -PI;
    let count = 1u + u32(copy_left) + u32(copy_right);
    var slot = atomicAdd(&counter.requested, count);
    if (slot + count > params.capacity) {
        return; // counted, never written: the host grows the buffer or chunks the scene
    }
    write_triangle(slot, b0, b1, b2, theta_c);
    slot += 1u;
    if (copy_left) {
        write_triangle(slot, b0, b1, b2, theta_c - TAU);
        slot += 1u;
    }
    if (copy_right) {
        write_triangle(slot, b0, b1, b2, theta_c + TAU);
    }
}

@compute @workgroup_size(64)
fn prepare(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    let local = gid.x + gid.y * groups.x * 64u;
    if (local >= params.triangle_count) {
        return;
    }
    let t = params.first_triangle + local;
    for (var k = 0u; k < 3u; k++) {
        let v = vertices[indices[3u * t + k]];
        tri_position[k] = (params.view * vec4<f32>(v.position, 1.0)).xyz;
        tri_normal[k] = (params.view * vec4<f32>(v.normal, 0.0)).xyz;
        tri_color[k] = v.color;
        tri_uv[k] = v.uv;
    }
    tri_material = vertices[indices[3u * t]].material;
    let e0 = vec3<f32>(1.0, 0.0, 0.0);
    let e1 = vec3<f32>(0.0, 1.0, 0.0);
    let e2 = vec3<f32>(0.0, 0.0, 1.0);
    let clearance = params.axis_clearance;
    if (!needs_axis_split(clearance / C8)) {
        emit(e0, e1, e2);
        return;
    }
    for (var s = 0u; s < SECTORS; s++) {
        poly[0] = e0;
        poly[1] = e1;
        poly[2] = e2;
        poly_count = 3u;
        let d0 = BOUNDARY[s];
        let d1 = BOUNDARY[s + 1u];
        let mid = MIDDLE[s];
        clip_polygon(vec3<f32>(d0.x, d0.y, 0.0));
        clip_polygon(vec3<f32>(-d1.x, -d1.y, 0.0));
        clip_polygon(vec3<f32>(mid.y, -mid.x, clearance));
        for (var i = 1u; i + 1u < poly_count; i++) {
            emit(poly[0], poly[i], poly[i + 1u]);
        }
    }
}

@compute @workgroup_size(1)
fn finalize() {
    let written = min(atomicLoad(&counter.requested), params.capacity);
    draw_args = DrawIndirectArgs(3u * written, 1u, 0u, 0u);
}
