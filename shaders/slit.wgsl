// The `slit` stage (vertex + fragment): the conventional slit-mosaic renderer (seed 002 §1,
// §4.3). For each slit of columns and each eye, a pinhole camera on the eye circle looks along
// the tangent, aimed so its central ray meets the screen at the slit's centre column; the scene
// is drawn into that slit only (scissor), one draw per slit with `first_instance` = the slit.
// Rows follow the exact vertical model, so slit:1 converges to the projection. The fragments
// carry the same shading and display-position error as the raster stage (fragment.wgsl).
// CPU twin: src/cpu/slit.rs.

#import projection
#import fragment

struct SlitParams {
    view: mat4x4<f32>,
    projection: Projection,
    eye_sign: f32,
    ambient: f32,
    near: f32,          // near plane distance along the camera's forward axis
    focal_y_clip: f32,  // t_S · pixels_per_metre / (H/2), t_S = √(R_T² − d_e²)
    error_angle: u32,   // 1: the error target holds arcminutes (fragment.wgsl)
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
}

// One slit's camera: eye position (viewer frame), and (sin φ, cos φ, NDC x of the slit centre).
struct SlitCamera {
    origin: vec4<f32>,
    basis: vec4<f32>,
}

@group(0) @binding(0) var<uniform> params: SlitParams;
@group(0) @binding(1) var<storage, read> cameras: array<SlitCamera>;

struct VertexIn {
    @builtin(instance_index) slit: u32,
    @location(0) position: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) color: vec4<f32>,
    @location(3) object: u32,
    @location(4) uv: vec2<f32>,
    @location(5) material: u32,
}


@vertex
fn vs_main(in: VertexIn) -> VertexOut {
    let cam = cameras[in.slit];
    let p = (params.view * vec4<f32>(in.position, 1.0)).xyz;
    let rel = p - cam.origin.xyz;
    let s = cam.basis.x;
    let c = cam.basis.y;
    let x_c = rel.x * c + rel.z * s;    // along right(φ) = (cos φ, 0, sin φ)
    let z_c = rel.x * s - rel.z * c;    // along forward(φ) = (sin φ, 0, −cos φ)
    var out: VertexOut;
    // Depth 1 − near/z_c, kept below 1 however far (MAX_DEPTH).
    out.clip = vec4<f32>(cam.basis.z * z_c + x_c / PI, rel.y * params.focal_y_clip, min(z_c - params.near, z_c * MAX_DEPTH), z_c);
    out.view_position = p;
    out.normal = (params.view * vec4<f32>(in.normal, 0.0)).xyz;
    out.color = in.color;
    out.object = in.object;
    out.uv = in.uv;
    out.material = in.material;
    return out;
}
