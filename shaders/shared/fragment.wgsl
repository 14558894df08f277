// Shared fragment work of the drawing stages (raster, slit), imported by raster.wgsl and slit.wgsl:
// their varyings, the output targets and what each fragment entry point computes, taking the
// surface colour, shading and display-position error from surface.wgsl (the sRGB colour target
// encodes the linear colour). No bindings and no entry points: each stage declares its
// `fs_main`, `fs_coverage`, `fs_error`, `fs_position` and `fs_background`, passing the drawn eye's
// `FragmentView`. CPU twins: src/cpu/fragment/ (sampling, shading, error).

#import projection
#import constants
// `ErrorTarget` and `encode_error`: R32Float where the adapter can render to it, else the same
// bits to an R32Uint target (generated: src/shader/mod.rs, `ErrorTarget::wgsl`).
#import error_target
#import surface

// What a fragment needs of the stage drawing it, for the eye drawn.
struct FragmentView {
    projection: Projection,
    eye_sign: f32,      // +1 right eye, −1 left eye
    ambient: f32,
    error_angle: u32,   // 1: the error target holds arcminutes
}

// The colour outputs: the display colour, and at location 5 the linear colour × 2^EV, which
// only a pipeline with the HDR target (`--hdr`) keeps (an output without a target is dropped).
struct FragmentColor {
    @location(0) color: vec4<f32>,
    @location(5) hdr: vec4<f32>,
}

struct FragmentOut {
    @location(0) color: vec4<f32>,
    // Display-position error in pixels (or arcminutes with `error_angle`); −1 where no eye
    // sees the point.
    @location(1) error: ErrorTarget,
    // Object id + 1 (0 is the background).
    @location(2) object: u32,
    // Distance in metres from the pixel's eye point to the surface point (cleared to +∞).
    @location(3) distance: ErrorTarget,
    @location(5) hdr: vec4<f32>,
}

fn fragment_out(params: FragmentView, frag_xy: vec2<f32>, view_position: vec3<f32>, dp_dx: vec3<f32>,
                dp_dy: vec3<f32>, normal: vec3<f32>, tangent: vec4<f32>, color: vec4<f32>, object: u32,
                material: u32, uv: vec2<f32>, duv_dx: vec2<f32>, duv_dy: vec2<f32>) -> FragmentOut {
    let plane_normal = cross(dp_dx, dp_dy);
    var out: FragmentOut;
    let shaded = shade_surface(material, params.ambient, params.projection, params.eye_sign, frag_xy, view_position,
                               normal, tangent, color, uv, duv_dx, duv_dy, dp_dx, dp_dy);
    out.color = shaded.display;
    out.hdr = shaded.linear;
    out.error = encode_error(pixel_error(params.projection, params.eye_sign, view_position, frag_xy,
                                         params.error_angle != 0u));
    out.object = object + 1u;
    out.distance = encode_error(pixel_distance(params.projection, params.eye_sign, view_position, plane_normal, frag_xy));
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
    @location(4) uv: vec2<f32>,
    @location(5) @interpolate(flat) material: u32,
    // The eye drawn: 0 left, 1 right.
    @location(6) @interpolate(flat) eye: u32,
    // glTF's tangent (viewer frame xyz, bitangent sign w), zero where none.
    @location(7) tangent: vec4<f32>,
}

// Samples per pixel of the multisampled colour's pipelines that take alpha to coverage
// (`fs_coverage`).
override SAMPLES: u32 = 1u;

// The colour outputs and the samples of the pixel the fragment covers (`fs_coverage`).
struct FragmentCoverage {
    @location(0) color: vec4<f32>,
    @location(5) hdr: vec4<f32>,
    @builtin(sample_mask) mask: u32,
}

// The shaded colour with alpha to coverage (`fs_coverage`, the multisampled colour of scenes
// whose materials may discard): a MASK or BLEND fragment covers the share of its pixel's samples
// its alpha gives (`coverage_mask`) instead of all or none.
fn fragment_coverage(in: VertexOut, front_facing: bool, params: FragmentView) -> FragmentCoverage {
    // Derivatives first, in uniform control flow.
    let duv_dx = dpdx(in.uv);
    let duv_dy = dpdy(in.uv);
    let dp_dx = dpdxFine(in.view_position);
    let dp_dy = dpdyFine(in.view_position);
    if (CIRCLE && !shows_pixel(params.projection, frame_xy(params.projection, in.clip.xy))) {
        discard; // outside the fisheye's circle
    }
    let c = surface_rgba(in.material, in.color, in.uv, duv_dx, duv_dy, front_facing);
    let alpha_width = mask_alpha_width(in.material, in.color.a, c.a, in.uv, duv_dx, duv_dy);
    let mask = coverage_mask(in.material, c.a, alpha_width, frame_xy(params.projection, in.clip.xy), SAMPLES);
    if (mask == 0u) {
        discard;
    }
    let shaded = shade_surface(in.material, params.ambient, params.projection, params.eye_sign, frame_xy(params.projection, in.clip.xy),
                               in.view_position, in.normal, in.tangent, vec4<f32>(c.rgb, max(c.a, 0.0)), in.uv,
                               duv_dx, duv_dy, dp_dx, dp_dy);
    return FragmentCoverage(shaded.display, shaded.linear, mask);
}

// The shaded colour (`fs_main`).
fn fragment_color(in: VertexOut, front_facing: bool, params: FragmentView) -> FragmentColor {
    // Derivatives first, in uniform control flow.
    let duv_dx = dpdx(in.uv);
    let duv_dy = dpdy(in.uv);
    let dp_dx = dpdxFine(in.view_position);
    let dp_dy = dpdyFine(in.view_position);
    if (CIRCLE && !shows_pixel(params.projection, frame_xy(params.projection, in.clip.xy))) {
        discard; // outside the fisheye's circle
    }
    let c = surface_color(in.material, in.color, in.uv, duv_dx, duv_dy, frame_xy(params.projection, in.clip.xy), front_facing);
    if (MATERIALS && DISCARDS && c.a < 0.0) {
        discard;
    }
    let shaded = shade_surface(in.material, params.ambient, params.projection, params.eye_sign, frame_xy(params.projection, in.clip.xy),
                               in.view_position, in.normal, in.tangent, c, in.uv, duv_dx, duv_dy, dp_dx, dp_dy);
    return FragmentColor(shaded.display, shaded.linear);
}

struct FragmentOutPosition {
    @location(0) color: vec4<f32>,
    @location(1) error: ErrorTarget,
    @location(2) object: u32,
    @location(3) distance: ErrorTarget,
    // The surface point drawn (viewer frame), w = 1 (cleared to 0: background).
    @location(4) position: vec4<f32>,
    @location(5) hdr: vec4<f32>,
}

// What `fs_position` writes: `measured`, plus the surface point drawn (for the display-position
// error against the ray tracer).
fn measured_position(in: VertexOut, front_facing: bool, params: FragmentView) -> FragmentOutPosition {
    let m = measured(in, front_facing, params);
    return FragmentOutPosition(m.color, m.error, m.object, m.distance, vec4<f32>(in.view_position, 1.0), m.hdr);
}

// What `fs_error` writes: the colour, plus the display-position error, the object id and the
// distance (when the error or the depth is measured); a discarded fragment writes nothing.
fn measured(in: VertexOut, front_facing: bool, params: FragmentView) -> FragmentOut {
    let duv_dx = dpdx(in.uv);
    let duv_dy = dpdy(in.uv);
    // Two vectors in the drawn triangle's plane (for the exact distance along the pixel's ray,
    // and the normal map's tangent frame).
    let dp_dx = dpdxFine(in.view_position);
    let dp_dy = dpdyFine(in.view_position);
    if (CIRCLE && !shows_pixel(params.projection, frame_xy(params.projection, in.clip.xy))) {
        discard; // outside the fisheye's circle
    }
    let c = surface_color(in.material, in.color, in.uv, duv_dx, duv_dy, frame_xy(params.projection, in.clip.xy), front_facing);
    if (MATERIALS && DISCARDS && c.a < 0.0) {
        discard;
    }
    return fragment_out(params, frame_xy(params.projection, in.clip.xy), in.view_position, dp_dx, dp_dy, in.normal, in.tangent, c, in.object,
                        in.material, in.uv, duv_dx, duv_dy);
}

// ---- The background: an environment the user gave, seen all around ----

// A triangle covering the image, drawn first in a pass where the environment shows as the
// background; only the colour targets are written (`background_color` in fragment.rs).
struct BackgroundOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) @interpolate(flat) eye: u32,
}

// Corner i of the triangle (−1, −1), (3, −1), (−1, 3), for eye `eye`.
fn background_vertex(i: u32, eye: u32) -> BackgroundOut {
    let xy = vec2<f32>(f32((i << 1u) & 2u), f32(i & 2u)) * 2.0 - 1.0;
    return BackgroundOut(vec4<f32>(xy, 0.5, 1.0), eye);
}

// The environment's radiance along the pixel's own ray, tone mapped, and linear
// (`fs_background`).
fn background_color(params: FragmentView, image_xy: vec2<f32>) -> FragmentColor {
    let frag_xy = frame_xy(params.projection, image_xy);
    if (CIRCLE && !shows_pixel(params.projection, frag_xy)) {
        discard; // outside the fisheye's circle: the background colour
    }
    let ray = pixel_ray(params.projection, params.eye_sign, frag_xy);
    let linear = exposed(env_level(0u, env_st(env_direction(ray.dir))));
    return FragmentColor(vec4<f32>(tone(linear), 1.0), vec4<f32>(linear, 1.0));
}
