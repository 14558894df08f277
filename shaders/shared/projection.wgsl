// The TWISTER projection (seed 002, §2.1, eq. 1–4), GPU side.
// Imported by every stage that projects (`#import projection`); the CPU twin is
// src/core/projection.rs, which documents the derivation of the eye sign.
//
//   r = √(x² + z²), θ = atan2(x, −z), α = acos(d_e/r) − acos(d_e/R_T)
//   u = θ + eye_sign·α   (eye_sign = +1 right eye, −1 left eye)
//   v = R_T·y/r (paper)   or   v = y·√(R_T²−d_e²)/√(r²−d_e²) (exact)
//   depth = r

#import constants

const PI: f32 = 3.14159265358979;
const TAU: f32 = 6.28318530717959;

// Mirrors `ProjectionUniform` in src/shader/types.rs (32 bytes).
struct Projection {
    screen_radius: f32,    // R_T, metres
    eye_radius: f32,       // d_e, metres
    width: f32,            // image width in pixels (2π of azimuth)
    height: f32,           // image height in pixels
    acos_eye_screen: f32,  // acos(d_e / R_T)
    vertical_exact: u32,   // 0: paper model, 1: exact model
    pixels_per_metre: f32, // W / (2π·R_T)
    _pad: f32,
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
    if (t > tan_pi_12) {
        return PI / 6.0 + atan_reduced((t * sqrt3 - 1.0) / (sqrt3 + t));
    }
    return atan_reduced(t);
}

fn precise_atan2(y: f32, x: f32) -> f32 {
    let ax = abs(x);
    let ay = abs(y);
    if (ax == 0.0 && ay == 0.0) {
        return 0.0;
    }
    var a: f32;
    if (ay <= ax) {
        a = atan_unit(ay / ax);
    } else {
        a = PI / 2.0 - atan_unit(ax / ay);
    }
    if (x < 0.0) {
        a = PI - a;
    }
    return select(a, -a, y < 0.0);
}

// acos(c) for c in [0, 1].
fn precise_acos(c: f32) -> f32 {
    return precise_atan2(sqrt(max((1.0 - c) * (1.0 + c), 0.0)), c);
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
    if (proj.vertical_exact != 0u) {
        let de = proj.eye_radius;
        let t_screen = sqrt(proj.screen_radius * proj.screen_radius - de * de);
        let t_point = sqrt(max(r * r - de * de, 1e-12));
        return y * t_screen / t_point;
    }
    return proj.screen_radius * y / r;
}

// (u, v, depth) of a viewer-frame point whose azimuth θ the caller has already unwrapped.
fn project_with_azimuth(proj: Projection, p: vec3<f32>, theta: f32, eye_sign: f32) -> vec3<f32> {
    let r = horizontal_radius(p);
    return vec3<f32>(theta + eye_sign * eye_shift(proj, r), screen_height(proj, p.y, r), r);
}

// Continuous image coordinates (x right, y down) of a screen point, u wrapped into the image.
fn to_pixel(proj: Projection, u: f32, v: f32) -> vec2<f32> {
    let x = (wrap_angle(u) / TAU + 0.5) * proj.width;
    let y = 0.5 * proj.height - v * proj.pixels_per_metre;
    return vec2<f32>(x, y);
}

// Clip-space position of a projected point. u is NOT wrapped: the pre-pass places seam copies
// at u ± 2π and the rasterizer clips them. w = 1, so attributes interpolate linearly on the
// screen as in the paper; depth r maps monotonically into (0, 1) as r / (r + 1).
fn to_clip(proj: Projection, uvd: vec3<f32>) -> vec4<f32> {
    let x = uvd.x / PI;
    let y = uvd.y * proj.pixels_per_metre / (0.5 * proj.height);
    let z = min(uvd.z / (uvd.z + 1.0), MAX_DEPTH);
    return vec4<f32>(x, y, z, 1.0);
}
