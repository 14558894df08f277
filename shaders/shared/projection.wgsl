// The panoramas' projections, GPU side. Imported by every stage that projects
// (`#import projection`); the CPU twin is src/core/panoramas/projection.rs, which derives both.
//
// The TWISTER cylinder (seed 002, §2.1, eq. 1–4):
//   r = √(x² + z²), θ = atan2(x, −z), α = acos(d_e/r) − acos(d_e/R_T)
//   u = θ + eye_sign·α   (eye_sign = +1 right eye, −1 left eye)
//   v = R_T·y/r (paper)   or   v = y·√(R_T²−d_e²)/√(r²−d_e²) (exact)
//   depth = r
// The full sphere (equirectangular ODS, Cycles' spherical stereo), at eye offset d:
//   e = d (parallel) or (1 − t)·d, (c² + d²)t² − 2d²t − (|P|² − d²) = 0 (converging on radius c)
//   u = λ = θ − eye_sign·asin(e/r), v = φ = atan2(y, √(r² − e²)), depth = √(r² + y² + d² − 2de)
//   with d = f(|φ|)·d_e (pole merge), solved by Newton steps.

#import constants
#import projection_sphere
#import projection_fisheye
#import projection_head
#import projection_cubemap
#import projection_cave

const PI: f32 = 3.14159265358979;
const TAU: f32 = 6.28318530717959;

// Mirrors `ProjectionUniform` in src/encoding/types.rs (144 bytes).
struct Projection {
    screen_radius: f32,    // R_T, metres
    eye_radius: f32,       // d_e, metres
    width: f32,            // image width in pixels (2π of azimuth)
    height: f32,           // image height in pixels
    acos_eye_screen: f32,  // acos(d_e / R_T)
    vertical_exact: u32,   // 0: paper model, 1: exact model
    pixels_per_v: f32,     // W / (2π·R_T) (cylinder: v in metres), H/π (sphere: v in radians)
    panorama: u32,         // PANORAMA_CYLINDER, PANORAMA_EQUIRECT or PANORAMA_VR180 (generated constants)
    convergence: f32,      // sphere: rays converge on this radius, metres; 0: parallel
    pole_from: f32,        // sphere: pole merge, radians of altitude; pole_to 0: off
    pole_to: f32,
    turn_px: f32,          // pixels per full turn of azimuth: the width, 2W for VR180 (its width spans π)
    fov: f32,              // fisheye: the field of view inscribed in the image, degrees
    dome_tilt: f32,        // fisheye: the dome's front raised by this, degrees
    head_on: f32,          // the cylinder's tracked head (`core::panoramas::head`): 1 on, 0 off
    head_turn: f32,        // γ: head frame → display frame turn, radians
    head_offset: vec3<f32>, // O: the head in the display's frame, metres
    face: u32,             // the cubemap: the face this draw projects into (0 elsewhere)
    wall_corner: vec3<f32>, // the CAVE: its wall in the display's frame (`core::panoramas::cave`), metres
    wall_on: f32,
    wall_right: vec3<f32>,
    _pad1: f32,
    wall_up: vec3<f32>,
    _pad2: f32,
    tile: vec4<f32>,       // this draw's part of the frame: x, y, width, height (pixels)
}

// The panoramas a pipeline can draw (bit 0 the cylinder, bit 1 the sphere: equirect, VR180, the
// fisheye or the cubemap, bit 2 the fisheye's image, bit 3 the cubemap's, bit 4 the CAVE). The
// subdivide stage's and the drawing stages' pipelines are built for one panorama each, so the
// others' code is compiled out: on lavapipe a
// shader that merely contains the sphere's projection (inlined at every sample of an edge) ran
// the cylinder's subdivision three times slower.
override PANORAMAS: u32 = 31u;

// Whether the sphere's rays may converge (`Projection::convergence` > 0). On lavapipe every lane
// runs the code behind a uniform's test whether or not one needs it (the converging eye model's
// root and divisions at every projection of the sphere): the subdivide stage's pipelines for
// parallel rays are built with it false, compiling that code out.
override CONVERGING: bool = true;
// Likewise whether the cylinder's exact vertical model may be drawn (`Vertical::Exact`).
override VERTICAL_EXACT: bool = true;

fn is_sphere(proj: Projection) -> bool {
    return (PANORAMAS & 2u) != 0u && ((PANORAMAS & 1u) == 0u || proj.panorama != PANORAMA_CYLINDER);
}

// atan2 and acos accurate to about 1e-7 rad. Drivers' built-ins may be far less precise (lavapipe's
// are off by ~4e-6 rad, 2e-3 px at 3168 px): reduce to |t| ≤ tan(π/12) and sum the odd series
// (truncation error < 0.268¹³/13 ≈ 3e-9).
fn atan_reduced(t: f32) -> f32 {
    let t2 = t * t;
    return t * (1.0 + t2 * (-1.0 / 3.0 + t2 * (1.0 / 5.0 + t2 * (-1.0 / 7.0 + t2 * (1.0 / 9.0 + t2 * (-1.0 / 11.0))))));
}

// atan(t) for 0 ≤ t ≤ 1.
fn atan_unit(t: f32) -> f32 {
    let tan_pi_12 = 0.267949192431123;
    let sqrt3 = 1.73205080756888;
    // One copy of the series (lavapipe inlines every call): 0 + x is x.
    let far = t > tan_pi_12;
    let reduced = select(t, (t * sqrt3 - 1.0) / (sqrt3 + t), far);
    return select(0.0, PI / 6.0, far) + atan_reduced(reduced);
}

fn precise_atan2(y: f32, x: f32) -> f32 {
    let ax = abs(x);
    let ay = abs(y);
    if (ax == 0.0 && ay == 0.0) {
        return 0.0;
    }
    // One copy of atan_unit: min/max is ay/ax where ay ≤ ax, else ax/ay.
    let steep = ay > ax;
    let unit = atan_unit(min(ax, ay) / max(ax, ay));
    var a = select(unit, PI / 2.0 - unit, steep);
    if (x < 0.0) {
        a = PI - a;
    }
    return select(a, -a, y < 0.0);
}

// sin(x) for 0 ≤ x ≤ π, from the odd series on [0, π/2] (`precise_sin` in
// src/cpu/subdivide/spacing.rs; truncation error below 6e-8).
fn precise_sin(x: f32) -> f32 {
    let y = min(x, PI - x);
    let y2 = y * y;
    return y * (1.0 + y2 * (-1.0 / 6.0 + y2 * (1.0 / 120.0 + y2 * (-1.0 / 5040.0 + y2 * (1.0 / 362880.0 + y2 * (-1.0 / 39916800.0))))));
}

// acos(c) for c in [0, 1].
fn precise_acos(c: f32) -> f32 {
    return precise_atan2(sqrt(max((1.0 - c) * (1.0 + c), 0.0)), c);
}

// asin(q) for q in [−1, 1].
fn precise_asin(q: f32) -> f32 {
    return precise_atan2(q, sqrt(max((1.0 - q) * (1.0 + q), 0.0)));
}

// Wraps an angle into [−π, π).
fn wrap_angle(a: f32) -> f32 {
    return a - TAU * floor((a + PI) / TAU);
}

fn azimuth(p: vec3<f32>) -> f32 {
    return precise_atan2(p.x, -p.z);
}

fn horizontal_radius(p: vec3<f32>) -> f32 {
    return sqrt(p.x * p.x + p.z * p.z);
}

// α(r) (eq. 3); the ratio is clamped so that points inside the eye circle stay finite.
fn eye_shift(proj: Projection, r: f32) -> f32 {
    return precise_acos(clamp(proj.eye_radius / r, 0.0, 1.0)) - proj.acos_eye_screen;
}

fn screen_height(proj: Projection, y: f32, r: f32) -> f32 {
    if (VERTICAL_EXACT && proj.vertical_exact != 0u) {
        let de = proj.eye_radius;
        let t_screen = sqrt(proj.screen_radius * proj.screen_radius - de * de);
        let t_point = sqrt(max(r * r - de * de, 1e-12));
        return y * t_screen / t_point;
    }
    return proj.screen_radius * y / r;
}

// ---- the full sphere (`Projection::sphere_*` in projection.rs) ----

// The pole merge's factor on the eye offset for a ray of altitude a ≥ 0.
fn pole_fade(proj: Projection, a: f32) -> f32 {
    if (proj.pole_to <= 0.0 || a <= proj.pole_from) {
        return 1.0;
    }
    if (a >= proj.pole_to) {
        return 0.0;
    }
    return cos(0.5 * PI * (a - proj.pole_from) / (proj.pole_to - proj.pole_from));
}

// Whether an eye sees the point (`Projection::project` is Some): the cylinder r > d_e; the sphere
// r > |e| at the point's offset (a point on the axis only where the offset has faded to 0).
fn sees(proj: Projection, p: vec3<f32>) -> bool {
    if (is_cave(proj)) {
        return cave_sees(proj, p);
    }
    let r = horizontal_radius(p);
    if (!is_sphere(proj)) {
        return r > proj.eye_radius;
    }
    let e = sphere_e(proj, r, p.y, sphere_eye_offset(proj, r, p.y));
    return r > abs(e) || (r == 0.0 && e == 0.0 && p.y != 0.0);
}

// (u, v, depth) of a viewer-frame point whose azimuth θ the caller has already unwrapped:
// (u, v) are (θ ± α, screen height) on the cylinder, (longitude, latitude) on the sphere.
fn project_with_azimuth(proj: Projection, p: vec3<f32>, theta: f32, eye_sign: f32) -> vec3<f32> {
    if (is_cave(proj)) {
        return cave_project(proj, p, eye_sign);
    }
    let r = horizontal_radius(p);
    if (is_sphere(proj)) {
        return sphere_at_offset(proj, r, p.y, theta, eye_sign, sphere_eye_offset(proj, r, p.y));
    }
    if (proj.head_on != 0.0) {
        return head_project(proj, p, theta, eye_sign);
    }
    return vec3<f32>(theta + eye_sign * eye_shift(proj, r), screen_height(proj, p.y, r), r);
}

// The eye offset at a point's altitude: the sphere's (its pole merge fades it towards the poles),
// else d_e (`Projection::eye_offset`).
fn eye_offset(proj: Projection, r: f32, y: f32) -> f32 {
    if (is_sphere(proj)) {
        return sphere_eye_offset(proj, r, y);
    }
    return proj.eye_radius;
}

// Both eyes' (u, v, depth), the left's (eye sign −1) first: one projection where the eyes differ
// only by the sign of their offset (the sphere; the cylinder without a tracked head), else each
// eye's. The same values as `project_with_azimuth` per eye (an exact sign flip).
fn project_both(proj: Projection, p: vec3<f32>, theta: f32) -> array<vec3<f32>, 2> {
    return project_both_at(proj, p, theta, eye_offset(proj, horizontal_radius(p), p.y));
}

// `project_both` with the point's eye offset (`eye_offset`) given: a caller that reads the
// offset too computes it once.
fn project_both_at(proj: Projection, p: vec3<f32>, theta: f32, offset: f32) -> array<vec3<f32>, 2> {
    var out: array<vec3<f32>, 2>;
    let r = horizontal_radius(p);
    if (is_cave(proj) || (!is_sphere(proj) && proj.head_on != 0.0)) {
        // `project_with_azimuth`'s cave and tracked-head cases only (a copy of the sphere's or
        // the cylinder's projection here would double the pipeline's build).
        for (var s = 0u; s < 2u; s++) {
            let eye_sign = select(-1.0, 1.0, s == 1u);
            if (is_cave(proj)) {
                out[s] = cave_project(proj, p, eye_sign);
            } else {
                out[s] = head_project(proj, p, theta, eye_sign);
            }
        }
    } else if (is_sphere(proj)) {
        let view = sphere_offset_view(proj, r, p.y, offset);
        out[0] = vec3<f32>(theta + view.x, view.y, view.z);
        out[1] = vec3<f32>(theta - view.x, view.y, view.z);
    } else {
        let alpha = eye_shift(proj, r);
        let v = screen_height(proj, p.y, r);
        out[0] = vec3<f32>(theta - alpha, v, r);
        out[1] = vec3<f32>(theta + alpha, v, r);
    }
    return out;
}

// Continuous image coordinates (x right, y down) of a screen point, u wrapped into [−π, π)
// (VR180: |u| > π/2 falls outside the image; the fisheye: its own map).
fn to_pixel(proj: Projection, u: f32, v: f32) -> vec2<f32> {
    if (is_fisheye(proj)) {
        return fisheye_pixel(proj, u, v);
    }
    if (is_cubemap(proj)) {
        return cube_pixel(proj, u, v);
    }
    if (is_cave(proj)) {
        return vec2<f32>(u, v); // the CAVE's (u, v) are its image position
    }
    let x = wrap_angle(u) / TAU * proj.turn_px + 0.5 * proj.width;
    let y = 0.5 * proj.height - v * proj.pixels_per_v;
    return vec2<f32>(x, y);
}

// A clip position on the whole frame as this draw's tile has it (`Projection::tile_clip`).
fn tile_clip(proj: Projection, clip: vec4<f32>) -> vec4<f32> {
    let frame = vec2<f32>(proj.width, proj.height);
    let scale = frame / proj.tile.zw;
    let shift = vec2<f32>((frame.x - 2.0 * proj.tile.x) / proj.tile.z - 1.0, 1.0 - (frame.y - 2.0 * proj.tile.y) / proj.tile.w);
    return vec4<f32>(clip.xy * scale + clip.w * shift, clip.zw);
}

// The frame's pixel position of a position in this draw's image (a tile's, or the frame's).
fn frame_xy(proj: Projection, xy: vec2<f32>) -> vec2<f32> {
    return xy + proj.tile.xy;
}

// What the raster stage multiplies a vertex's clip position by (`raster_vertex` in
// src/cpu/raster.rs): under the error split (`by_radius` 1) r, the vertex's distance from the
// vertical axis, so that attributes are interpolated as P/r is, linearly on the screen: between
// two nodes the drawn point's azimuth then follows the screen, as the subdivision's azimuth
// spacing assumes (src/cpu/subdivide/spacing.rs). On the cubemap `depth`, the distance along the
// ray from the eye point: each face draws as a pinhole from the eye points.
fn clip_w(proj: Projection, p: vec3<f32>, depth: f32, by_radius: u32) -> f32 {
    if (is_cubemap(proj)) {
        return max(depth, CUBE_MIN_DISTANCE);
    }
    if (by_radius == 0u) {
        return 1.0;
    }
    return max(horizontal_radius(p), AZIMUTH_MIN_RADIUS);
}

// The clip position of a projected point on the whole frame (`tile_clip` then gives the tile's).
// u is NOT wrapped: the pre-pass places seam copies at u ± 2π and the rasterizer clips them (and
// VR180's |u| > π/2). w = 1 (`clip_w` scales it), so attributes interpolate linearly on the
// screen as in the paper; depth r maps monotonically into (0, 1) as r / (r + 1). y is kept
// within GUARD_BAND_PX of the image (constants.rs says why).
fn frame_clip(proj: Projection, uvd: vec3<f32>) -> vec4<f32> {
    let z = min(uvd.z / (uvd.z + 1.0), MAX_DEPTH);
    if (is_fisheye(proj)) {
        let xy = fisheye_pixel(proj, uvd.x, uvd.y);
        return vec4<f32>(2.0 * xy.x / proj.width - 1.0, 1.0 - 2.0 * xy.y / proj.height, z, 1.0);
    }
    if (is_cubemap(proj)) {
        return cube_clip(proj, uvd.x, uvd.y, uvd.z);
    }
    let x = uvd.x * proj.turn_px / (PI * proj.width);
    let y_limit = 1.0 + GUARD_BAND_PX / (0.5 * proj.height);
    var y = clamp(uvd.y * proj.pixels_per_v / (0.5 * proj.height), -y_limit, y_limit);
    // The sphere: a vertex beyond the centre of the first (last) row, where every longitude
    // meets within half a row of the pole, is put on the image's edge (the pole), so that the
    // triangles drawn there reach it and the subdivision's culling beyond that centre leaves no
    // sample of a multisampled pixel uncovered (`raster_vertex` in cpu/raster.rs).
    if (is_sphere(proj) && abs(y) > 1.0 - 1.0 / proj.height) {
        y = sign(y);
    }
    return vec4<f32>(x, y, z, 1.0);
}
