// The `project_points` stage (compute): projects viewer-frame points to image pixels for one eye.
// CPU twin: src/cpu/project_points.rs. Used to check the GPU projection against the CPU
// oracle.

#import projection

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
fn project_points(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    // A 2-D dispatch beyond 65,535 workgroups (more than 4.19 M points).
    let i = gid.x + gid.y * groups.x * 64u;
    if (i >= params.count) {
        return;
    }
    let p = points[i].xyz;
    if (!sees(params.projection, p)) {
        pixels[i] = vec4<f32>(0.0, 0.0, 0.0, 0.0);
        return;
    }
    let uvd = project_with_azimuth(params.projection, p, azimuth(p), params.eye_sign);
    pixels[i] = vec4<f32>(to_pixel(params.projection, uvd.x, uvd.y), uvd.z, 1.0);
}
