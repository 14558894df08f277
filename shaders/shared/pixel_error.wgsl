// The pixel geometry: a pixel's screen point, its ray from its eye point, the display-position
// error of seed 002 §4.1 and the distance along a pixel's ray. No bindings. CPU twin:
// src/cpu/fragment/pixel_error.rs (the ray itself: src/core/panoramas/projection.rs, `pixel_ray`).

#import projection
#import constants

// The screen point (u, v) at image position (x, y) (`Projection::pixel_to_screen`).
fn from_pixel(proj: Projection, xy: vec2<f32>) -> vec2<f32> {
    if (is_fisheye(proj)) {
        return fisheye_direction(proj, xy);
    }
    if (is_cubemap(proj)) {
        return cube_direction(proj, xy);
    }
    if (is_cave(proj)) {
        return xy;
    }
    return vec2<f32>((xy.x - 0.5 * proj.width) / proj.turn_px * TAU, (0.5 * proj.height - xy.y) / proj.pixels_per_v);
}

// The unit direction, seen from the centre, of screen point (u, v): on the cylinder the screen
// point (R_T sin u, v, −R_T cos u), on the sphere longitude u, latitude v.
fn screen_direction(proj: Projection, uv: vec2<f32>) -> vec3<f32> {
    if (is_cave(proj)) {
        return normalize(cave_point(proj, uv)); // the wall's point, seen from the head
    }
    if (is_sphere(proj)) {
        return vec3<f32>(cos(uv.y) * sin(uv.x), sin(uv.y), -cos(uv.y) * cos(uv.x));
    }
    if (proj.head_on != 0.0) {
        return normalize(head_screen_point(proj, uv.x, uv.y));
    }
    return normalize(vec3<f32>(proj.screen_radius * sin(uv.x), uv.y, -proj.screen_radius * cos(uv.x)));
}

// The angle a pixel spans, radians (`pixel_spread` in fragment.rs): the larger of its width
// (2π/turn_px, on the sphere × cos latitude) and its height (on the cylinder 1/(pixels_per_v·R_T) seen
// from the eyes, about R_T away; on the sphere 1/pixels_per_v).
fn pixel_spread(proj: Projection, frag_xy: vec2<f32>) -> f32 {
    if (is_fisheye(proj)) {
        return 1.0 / fisheye_scale(proj);
    }
    if (is_cubemap(proj)) {
        return 1.0 / proj.pixels_per_v; // a face's centre, where its pixels span the most
    }
    if (is_cave(proj)) {
        return cave_spread(proj);
    }
    let uv = from_pixel(proj, frag_xy);
    if (is_sphere(proj)) {
        return max(TAU / proj.turn_px * cos(uv.y), 1.0 / proj.pixels_per_v);
    }
    return max(TAU / proj.turn_px, 1.0 / (proj.pixels_per_v * proj.screen_radius));
}

// The display-position error of surface point p drawn at pixel centre `frag_xy` for this eye: the
// distance in pixels to where the projection puts p (horizontal distance wrapping around the
// panorama), or with `angle` the angle between the two directions in arcminutes; −1 where no eye
// sees p.
fn pixel_error(proj: Projection, eye_sign: f32, p: vec3<f32>, frag_xy: vec2<f32>, angle: bool) -> f32 {
    if (!sees(proj, p)) {
        return -1.0;
    }
    let uvd = project_with_azimuth(proj, p, azimuth(p), eye_sign);
    if (is_cave(proj) && uvd.z < 0.0) {
        return -1.0; // behind this eye's plane
    }
    if (angle) {
        let a = screen_direction(proj, uvd.xy);
        let b = screen_direction(proj, from_pixel(proj, frag_xy));
        return precise_atan2(length(cross(a, b)), dot(a, b)) * (180.0 * 60.0 / PI);
    }
    if (is_cubemap(proj)) {
        // On the pixel's own face (a point drawn across a face's edge belongs beyond it there).
        let near = cube_pixel_near(proj, uvd.x, uvd.y, frag_xy);
        if (near.z <= 0.0) {
            return 1e9;
        }
        return length(near.xy - frag_xy);
    }
    let ideal = to_pixel(proj, uvd.x, uvd.y);
    var dx = abs(ideal.x - frag_xy.x);
    if (!is_fisheye(proj)) {
        dx = min(dx, proj.turn_px - dx);
    }
    return length(vec2<f32>(dx, ideal.y - frag_xy.y));
}

struct Ray {
    origin: vec3<f32>,
    dir: vec3<f32>,
}

// The ray of the pixel at `frag_xy` (`pixel_ray` in fragment.rs): on the sphere the pixel's ray
// (`Projection::sphere_ray`); on the cylinder from the eye whose tangent ray meets the screen at
// the pixel's column (viewing direction φ = u − s·asin(d_e/R_T)) through the pixel's screen point.
fn pixel_ray(proj: Projection, eye_sign: f32, frag_xy: vec2<f32>) -> Ray {
    let uv = from_pixel(proj, frag_xy);
    if (is_cave(proj)) {
        let origin = vec3<f32>(eye_sign * proj.eye_radius, 0.0, 0.0);
        return Ray(origin, normalize(cave_point(proj, uv) - origin));
    }
    if (is_sphere(proj)) {
        let d = vec3<f32>(cos(uv.y) * sin(uv.x), sin(uv.y), -cos(uv.y) * cos(uv.x));
        let origin = eye_sign * pole_fade(proj, abs(uv.y)) * proj.eye_radius * vec3<f32>(cos(uv.x), 0.0, sin(uv.x));
        if (proj.convergence > 0.0) {
            return Ray(origin, normalize(proj.convergence * d - origin));
        }
        return Ray(origin, d);
    }
    if (proj.head_on != 0.0) {
        let origin = vec3<f32>(eye_sign * proj.eye_radius, 0.0, 0.0);
        return Ray(origin, normalize(head_screen_point(proj, uv.x, uv.y) - origin));
    }
    let phi = uv.x - eye_sign * precise_asin(proj.eye_radius / proj.screen_radius);
    let origin = eye_sign * proj.eye_radius * vec3<f32>(cos(phi), 0.0, sin(phi));
    let screen = vec3<f32>(proj.screen_radius * sin(uv.x), uv.y, -proj.screen_radius * cos(uv.x));
    return Ray(origin, normalize(screen - origin));
}

// The distance along the pixel's ray to the plane through p with normal n (the drawn triangle's
// plane), or |p − eye point| where the ray runs nearly within the plane (`pixel_distance`).
fn pixel_distance(proj: Projection, eye_sign: f32, p: vec3<f32>, n: vec3<f32>, frag_xy: vec2<f32>) -> f32 {
    let ray = pixel_ray(proj, eye_sign, frag_xy);
    let denom = dot(ray.dir, n);
    if (abs(denom) > 1e-3 * length(n)) {
        let t = dot(p - ray.origin, n) / denom;
        if (t > 0.0) {
            return t;
        }
    }
    return length(p - ray.origin);
}
