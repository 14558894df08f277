// The `raster` stage (vertex + fragment): projects each prepared vertex with the TWISTER
// projection (seed 002 eq. 1–4, projection.wgsl) for one eye and shades it.
// CPU twin: src/raster.rs (the per-vertex part, `raster_vertex`). Needs projection.wgsl.

struct RasterParams {
    projection: Projection,
    eye_sign: f32,   // +1 right eye, −1 left eye
    ambient: f32,
    _pad: vec2<f32>,
}

@group(0) @binding(0) var<uniform> params: RasterParams;

struct VertexIn {
    @location(0) position: vec3<f32>,
    @location(1) theta_ref: f32,
    @location(2) normal: vec3<f32>,
    @location(3) material: u32,
    @location(4) color: vec4<f32>,
    @location(5) uv: vec2<f32>,
}

struct VertexOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) view_position: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) color: vec4<f32>,
}

@vertex
fn vs_main(in: VertexIn) -> VertexOut {
    // Unwrap θ by whole turns towards the triangle's reference, so the triangle is never split
    // by the seam; a vertex shared by neighbours gets the same bits in both.
    let theta0 = azimuth(in.position);
    let theta = theta0 + TAU * floor((in.theta_ref - theta0) / TAU + 0.5);
    let uvd = project_with_azimuth(params.projection, in.position, theta, params.eye_sign);
    var out: VertexOut;
    out.clip = to_clip(params.projection, uvd);
    out.view_position = in.position;
    out.normal = in.normal;
    out.color = in.color;
    return out;
}

@fragment
fn fs_main(in: VertexOut) -> @location(0) vec4<f32> {
    // Headlight from the viewer: colour × (ambient + (1 − ambient)·|n·l|), two-sided.
    let n_len = length(in.normal);
    let l = -normalize(in.view_position);
    var lambert = 1.0;
    if (n_len > 1e-6) {
        lambert = abs(dot(in.normal / n_len, l));
    }
    let shade = params.ambient + (1.0 - params.ambient) * lambert;
    return vec4<f32>(in.color.rgb * shade, 1.0);
}
