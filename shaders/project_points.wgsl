// The `project_points` stage (compute): projects viewer-frame points to image pixels for one eye.
// CPU twin: `project_points` in src/projection.rs. Used to check the GPU projection
// against the CPU oracle. Needs projection.wgsl.

struct ProjectParams {
    projection: Projection,
    eye_sign: f32,
    count: u32,
    _pad: vec2<f32>,
}

@group(0) @binding(0) var<uniform> params: ProjectParams;
@group(0) @binding(1) var<storage, read> points: array<vec4<f32>>;
// (pixel x, pixel y, depth, 1 if seen else 0)
@group(0) @binding(2) var<storage, read_write> pixels: array<vec4<f32>>;

@compute @workgroup_size(64)
fn project_points(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    if (i >= params.count) {
        return;
    }
    let p = points[i].xyz;
    let r = horizontal_radius(p);
    if (!(r > params.projection.eye_radius)) {
        pixels[i] = vec4<f32>(0.0, 0.0, 0.0, 0.0);
        return;
    }
    let uvd = project_with_azimuth(params.projection, p, azimuth(p), params.eye_sign);
    pixels[i] = vec4<f32>(to_pixel(params.projection, uvd.x, uvd.y), uvd.z, 1.0);
}
