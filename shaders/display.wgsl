// The `display` stage (vertex + fragment): what the live window (`twister view`) shows of a
// drawn frame, one fragment per window pixel, from both eyes' colour copied into a buffer
// (sRGB bytes, rows of `row_texels`). CPU twin: src/cpu/display.rs.
//
// Modes (`core::display::DisplayMode`):
//   0 panorama: the images stacked (left eye above right), scaled into `area`;
//   1 halves: the TWISTER display's four W/2×H inputs in a 2×2 grid (front, back; left eye on
//     top): each eye's image turned by a quarter of its width (the `twister` layout's halves);
//   2 look-around side by side, 3 anaglyph: a perspective view from the centre (yaw, pitch, the
//     horizontal field of view) into each eye's panorama, as a headset shows it: the pixel of a
//     direction is where the eye sees a point far along it (the projection's forward map).
// A second buffer holds the overlay (RGBA bytes, `overlay` its place), blended over the image.

#import projection

struct DisplayParams {
    projection: Projection,
    mode: u32,
    width: u32,        // the frame's image (each layer's)
    height: u32,
    row_texels: u32,   // texels per row in `texels` (rows padded for the copy)
    layers: u32,       // 2: both eyes; 1: one image (the error heatmap)
    srgb_target: u32,  // 1: the target encodes sRGB itself (write linear values)
    _pad0: u32,
    _pad1: u32,
    area: vec4<f32>,   // where the image goes in the target: x, y, width, height (pixels)
    look: vec4<f32>,   // look-around: yaw, pitch (radians), tan of half the horizontal field, far distance
    overlay: vec4<f32>, // the overlay's place: x, y, width, height (pixels; width 0: none)
}

// Whether the pipeline draws the look-around views: the others' pipeline leaves the projection
// out (on the software driver, a fragment shader that merely holds it ran ten times slower).
override LOOK: bool = true;

@group(0) @binding(0) var<uniform> params: DisplayParams;
@group(0) @binding(1) var<storage, read> texels: array<u32>;
@group(0) @binding(2) var<storage, read> overlay: array<u32>;

const BACKGROUND: vec4<f32> = vec4<f32>(0.05, 0.05, 0.06, 1.0);

@vertex
fn vs_main(@builtin(vertex_index) k: u32) -> @builtin(position) vec4<f32> {
    // One triangle over the whole target.
    let xy = vec2<f32>(f32((k << 1u) & 2u), f32(k & 2u));
    return vec4<f32>(xy * 2.0 - 1.0, 0.0, 1.0);
}

fn unpack(word: u32) -> vec4<f32> {
    return vec4<f32>(f32(word & 255u), f32((word >> 8u) & 255u), f32((word >> 16u) & 255u), f32(word >> 24u)) / 255.0;
}

// Texel (x, y) of layer k as sRGB-encoded values.
fn texel(k: u32, x: u32, y: u32) -> vec4<f32> {
    return unpack(texels[(k * params.height + y) * params.row_texels + x]);
}

// The image's texel under `xy` (pixels) of a w × h content drawn into the area, or none.
fn content_texel(xy: vec2<f32>) -> vec4<f32> {
    let local = (xy - params.area.xy) / params.area.zw;
    if (any(local < vec2<f32>(0.0)) || any(local >= vec2<f32>(1.0))) {
        return BACKGROUND;
    }
    let w = params.width;
    let h = params.height * params.layers;
    let c = min(vec2<u32>(floor(local * vec2<f32>(f32(w), f32(h)))), vec2<u32>(w - 1u, h - 1u));
    var x = c.x;
    if (params.mode == 1u) {
        x = (x + w / 4u) % w;
    }
    return texel(c.y / params.height, x, c.y % params.height);
}

// The direction of view through `local` ∈ [0, 1)² of a look-around view (x right, y down).
fn look_direction(local: vec2<f32>, aspect: f32) -> vec3<f32> {
    let yaw = params.look.x;
    let pitch = params.look.y;
    let forward = vec3<f32>(sin(yaw) * cos(pitch), sin(pitch), -cos(yaw) * cos(pitch));
    let right = vec3<f32>(cos(yaw), 0.0, sin(yaw));
    let up = cross(right, forward);
    let ndc = vec2<f32>(2.0 * local.x - 1.0, 1.0 - 2.0 * local.y);
    let t = params.look.z;
    return normalize(forward + ndc.x * t * right + ndc.y * t / aspect * up);
}

// Eye k's panorama where it sees direction d (the point `far` along it), or none.
fn look_texel(k: u32, d: vec3<f32>) -> vec4<f32> {
    let p = d * params.look.w;
    if (!sees(params.projection, p)) {
        return BACKGROUND;
    }
    let uvd = project_with_azimuth(params.projection, p, azimuth(p), select(-1.0, 1.0, k == 1u));
    let xy = floor(to_pixel(params.projection, uvd.x, uvd.y));
    if (any(xy < vec2<f32>(0.0)) || xy.x >= f32(params.width) || xy.y >= f32(params.height)) {
        return BACKGROUND;
    }
    return texel(k, u32(xy.x), u32(xy.y));
}

fn look(xy: vec2<f32>) -> vec4<f32> {
    let local = (xy - params.area.xy) / params.area.zw;
    if (any(local < vec2<f32>(0.0)) || any(local >= vec2<f32>(1.0))) {
        return BACKGROUND;
    }
    if (params.mode == 2u) {
        // Side by side: the left eye's view in the left half.
        let k = u32(local.x >= 0.5);
        let half = vec2<f32>(fract(local.x * 2.0), local.y);
        return look_texel(k, look_direction(half, 0.5 * params.area.z / params.area.w));
    }
    let d = look_direction(local, params.area.z / params.area.w);
    let left = look_texel(0u, d);
    let right = look_texel(1u, d);
    return vec4<f32>(left.r, right.g, right.b, 1.0);
}

fn srgb_to_linear(c: f32) -> f32 {
    if (c <= 0.04045) {
        return c / 12.92;
    }
    return pow((c + 0.055) / 1.055, 2.4);
}

@fragment
fn fs_main(@builtin(position) position: vec4<f32>) -> @location(0) vec4<f32> {
    let xy = position.xy;
    var color = BACKGROUND;
    if (LOOK && params.mode >= 2u) {
        color = look(xy);
    } else {
        color = content_texel(xy);
    }
    let o = (xy - params.overlay.xy);
    if (params.overlay.z > 0.0 && all(o >= vec2<f32>(0.0)) && all(o < params.overlay.zw)) {
        let ow = u32(params.overlay.z);
        let c = unpack(overlay[u32(o.y) * ow + u32(o.x)]);
        color = vec4<f32>(mix(color.rgb, c.rgb, c.a), 1.0);
    }
    if (params.srgb_target == 1u) {
        color = vec4<f32>(srgb_to_linear(color.r), srgb_to_linear(color.g), srgb_to_linear(color.b), 1.0);
    }
    return vec4<f32>(color.rgb, 1.0);
}
