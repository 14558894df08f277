// Shared fragment work of the drawing stages (raster, slit), composed in after projection.wgsl:
// their varyings, headlight shading, the display-position error of seed 002 §4.1, the output
// targets and the fragment entry points. CPU twin: src/fragment.rs.
//
// Contract: a stage composing this module declares a uniform `params` with the fields
// `projection: Projection`, `eye_sign: f32` (+1 right eye) and `ambient: f32`, and its vertex
// stage returns `VertexOut`.

// The error target's type. R32Float where the adapter can render to it; otherwise the loader
// replaces the two marked lines so that the same bits go to an R32Uint target.
alias ErrorTarget = f32; // ERROR_TARGET
fn encode_error(e: f32) -> ErrorTarget { return e; } // ERROR_ENCODE

struct FragmentOut {
    @location(0) color: vec4<f32>,
    // Display-position error in pixels; −1 where no eye sees the point (r ≤ d_e).
    @location(1) error: ErrorTarget,
    // Object id + 1 (0 is the background).
    @location(2) object: u32,
}

// Colour × (ambient + (1 − ambient)·|n·l|), the light at the viewer, two-sided.
fn shade(ambient: f32, view_position: vec3<f32>, normal: vec3<f32>, color: vec4<f32>) -> vec4<f32> {
    let n_len = length(normal);
    var lambert = 1.0;
    if (n_len > 1e-6) {
        lambert = abs(dot(normal / n_len, -normalize(view_position)));
    }
    return vec4<f32>(color.rgb * (ambient + (1.0 - ambient) * lambert), 1.0);
}

// Distance in pixels between the pixel centre `frag_xy` where surface point p was drawn and
// where the projection puts p for this eye (horizontal distance wrapping around the panorama).
fn pixel_error(proj: Projection, eye_sign: f32, p: vec3<f32>, frag_xy: vec2<f32>) -> f32 {
    if (!(horizontal_radius(p) > proj.eye_radius)) {
        return -1.0;
    }
    let uvd = project_with_azimuth(proj, p, azimuth(p), eye_sign);
    let ideal = to_pixel(proj, uvd.x, uvd.y);
    var dx = abs(ideal.x - frag_xy.x);
    dx = min(dx, proj.width - dx);
    return length(vec2<f32>(dx, ideal.y - frag_xy.y));
}

fn fragment_out(proj: Projection, eye_sign: f32, ambient: f32, frag_xy: vec2<f32>, view_position: vec3<f32>,
                normal: vec3<f32>, color: vec4<f32>, object: u32) -> FragmentOut {
    var out: FragmentOut;
    out.color = shade(ambient, view_position, normal, color);
    out.error = encode_error(pixel_error(proj, eye_sign, view_position, frag_xy));
    out.object = object + 1u;
    return out;
}

// The varyings of the drawing stages. view_position is the surface point drawn: interpolated
// linearly on the screen by the raster stage (clip w = 1, where the projection methods put a
// triangle's inside), perspective-correctly by the slit stage (clip w = depth along the camera).
struct VertexOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) view_position: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) color: vec4<f32>,
    @location(3) @interpolate(flat) object: u32,
}

@fragment
fn fs_main(in: VertexOut) -> @location(0) vec4<f32> {
    return shade(params.ambient, in.view_position, in.normal, in.color);
}

// The same, plus the display-position error and the object id (when the error is measured).
@fragment
fn fs_error(in: VertexOut) -> FragmentOut {
    return fragment_out(params.projection, params.eye_sign, params.ambient, in.clip.xy, in.view_position, in.normal,
                        in.color, in.object);
}
