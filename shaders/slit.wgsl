// The `slit` stage (vertex + fragment): the conventional slit-mosaic renderer (seed 002 §1,
// §4.3). The cylinder: for each slit of columns and each eye, a pinhole camera on the eye circle
// looks along the tangent, aimed so its central ray meets the screen at the slit's centre
// column; rows follow the exact vertical model, so slit:1 converges to the projection. The
// sphere: each slit is cut into W × W tiles, each a pinhole camera at its centre pixel's eye
// point looking along that pixel's ray. The scene is drawn into each slit or tile only
// (scissor), one draw per slit with `first_instance` = the slit. The fragments carry the same
// shading and display-position error as the raster stage (fragment.wgsl).
// CPU twin: src/cpu/slit.rs, which derives the camera form.

#import projection
#import scene
#import fragment

struct SlitParams {
    view: mat4x4<f32>,
    projection: Projection,
    eye_sign: f32,
    ambient: f32,
    near: f32,          // near plane distance along the camera's forward axis
    error_angle: u32,   // 1: the error target holds arcminutes (fragment.wgsl)
}

// One slit's (or tile's) camera: position and axes (viewer frame); the slit centre in NDC in
// right_cx.w and up_cy.w; NDC per unit of x_c/z_c in origin_sx.w, of y_c/z_c in forward_sy.w.
struct SlitCamera {
    origin_sx: vec4<f32>,
    right_cx: vec4<f32>,
    up_cy: vec4<f32>,
    forward_sy: vec4<f32>,
}

@group(0) @binding(0) var<uniform> params: SlitParams;

// The slit stage draws one eye per pass, with that eye's `params`.
fn fragment_view(eye: u32) -> FragmentView {
    return FragmentView(params.projection, params.eye_sign, params.ambient, params.error_angle);
}
@group(0) @binding(1) var<storage, read> cameras: array<SlitCamera>;

struct VertexIn {
    @builtin(instance_index) slit: u32,
    @location(0) position: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) color: vec4<f32>,
    @location(3) object: u32,
    @location(4) uv: vec2<f32>,
    @location(5) material: u32,
    @location(6) tangent: u32,
}


@vertex
fn vs_main(in: VertexIn) -> VertexOut {
    let cam = cameras[in.slit];
    let p = (params.view * vec4<f32>(in.position, 1.0)).xyz;
    let rel = p - cam.origin_sx.xyz;
    let x_c = dot(rel, cam.right_cx.xyz);
    let y_c = dot(rel, cam.up_cy.xyz);
    let z_c = dot(rel, cam.forward_sy.xyz);
    var out: VertexOut;
    // Depth 1 − near/z_c, kept below 1 however far (MAX_DEPTH).
    out.clip = tile_clip(params.projection, vec4<f32>(cam.right_cx.w * z_c + x_c * cam.origin_sx.w,
                         cam.up_cy.w * z_c + y_c * cam.forward_sy.w, min(z_c - params.near, z_c * MAX_DEPTH), z_c));
    out.view_position = p;
    out.normal = (params.view * vec4<f32>(in.normal, 0.0)).xyz;
    let t = unpack_tangent(in.tangent);
    out.tangent = vec4<f32>((params.view * vec4<f32>(t.xyz, 0.0)).xyz, t.w);
    out.color = in.color;
    out.object = in.object;
    out.uv = in.uv;
    out.material = in.material;
    out.eye = 0u;
    return out;
}

// The background triangle (fragment.wgsl), drawn once per eye's pass.
@vertex
fn vs_background(@builtin(vertex_index) i: u32) -> BackgroundOut {
    return background_vertex(i, 0u);
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
