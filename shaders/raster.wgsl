// The `raster` stage (vertex + fragment): projects each subdivided vertex with the TWISTER
// projection (seed 002 eq. 1–4, projection.wgsl) for the eye drawn; the fragments are shaded and
// carry their display-position error (fragment.wgsl). Both eyes come from one draw where the
// adapter has multiview (the eye is the view index, each eye a layer of the targets), else from
// one pass per eye (the `eyes` module, src/shader/mod.rs). CPU twin: src/cpu/raster.rs.

#import projection
#import scene
#import fragment
#import eyes

struct RasterParams {
    projection: Projection,
    eye_sign: f32,   // +1 right eye, −1 left eye
    ambient: f32,
    // Test hook: draws everything shifted by this many pixels (x right, y down) while the
    // error is still measured against the true projection.
    shift_px: vec2<f32>,
    error_angle: u32,  // 1: the error target holds arcminutes (fragment.wgsl)
    w_by_radius: u32,  // 1: clip w = r (the error split's azimuth spacing; see clip_w)
    _pad1: u32,
    _pad2: u32,
}

// Left eye, right eye.
@group(0) @binding(0) var<uniform> params: array<RasterParams, 2>;

// What the fragments of eye `eye` (0 left, 1 right) need of its parameters.
fn fragment_view(eye: u32) -> FragmentView {
    let p = params[eye];
    return FragmentView(p.projection, p.eye_sign, p.ambient, p.error_angle);
}

struct VertexIn {
    @location(0) position: vec3<f32>,
    @location(1) theta_ref: f32,
    @location(2) normal: vec3<f32>,
    @location(3) material: u32,
    @location(4) color: vec4<f32>,
    @location(5) uv: vec2<f32>,
    @location(6) object: u32,
    @location(7) tangent: u32,
    // Where the node is drawn off its projection, image pixels (x right, y down): left eye's
    // (x, y), right eye's (x, y).
    @location(8) offsets: vec4<f32>,
}


@vertex
fn vs_main(in: VertexIn, eye_in: EyeIn) -> VertexOut {
    let eye = eye_index(eye_in);
    let params = params[eye];
    // Unwrap θ by whole turns towards the triangle's reference, so the triangle is never split
    // by the seam; a vertex shared by neighbours gets the same bits in both.
    let theta0 = azimuth(in.position);
    let theta = theta0 + TAU * floor((in.theta_ref - theta0) / TAU + 0.5);
    let uvd = project_with_azimuth(params.projection, in.position, theta, params.eye_sign);
    var out: VertexOut;
    out.clip = frame_clip(params.projection, uvd) * clip_w(params.projection, in.position, uvd.z, params.w_by_radius);
    // The node's offset for this eye and the test hook's shift, in pixels of the frame.
    let shift = params.shift_px + select(in.offsets.xy, in.offsets.zw, eye == 1u);
    out.clip.x += 2.0 * shift.x / params.projection.width * out.clip.w;
    out.clip.y -= 2.0 * shift.y / params.projection.height * out.clip.w;
    out.clip = tile_clip(params.projection, out.clip);
    out.view_position = in.position;
    out.normal = in.normal;
    out.tangent = unpack_tangent(in.tangent);
    out.color = in.color;
    out.object = in.object;
    out.uv = in.uv;
    out.material = in.material;
    out.eye = eye;
    return out;
}

// The background triangle (fragment.wgsl), for the eye drawn.
@vertex
fn vs_background(@builtin(vertex_index) i: u32, eye_in: EyeIn) -> BackgroundOut {
    return background_vertex(i, eye_index(eye_in));
}

// ---- The fragment entry points (what they compute: fragment.wgsl) ----

@fragment
fn fs_main(in: VertexOut, @builtin(front_facing) front_facing: bool) -> FragmentColor {
    return fragment_color(in, front_facing, fragment_view(in.eye));
}

@fragment
fn fs_coverage(in: VertexOut, @builtin(front_facing) front_facing: bool) -> FragmentCoverage {
    return fragment_coverage(in, front_facing, fragment_view(in.eye));
}

@fragment
fn fs_error(in: VertexOut, @builtin(front_facing) front_facing: bool) -> FragmentOut {
    return measured(in, front_facing, fragment_view(in.eye));
}

@fragment
fn fs_position(in: VertexOut, @builtin(front_facing) front_facing: bool) -> FragmentOutPosition {
    return measured_position(in, front_facing, fragment_view(in.eye));
}

@fragment
fn fs_background(in: BackgroundOut) -> FragmentColor {
    return background_color(fragment_view(in.eye), in.clip.xy);
}
