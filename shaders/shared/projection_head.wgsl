// The cylinder seen by a tracked head away from the display's centre (`core::panoramas::head`): the line
// from a fixed eye through a point meets the screen. `projection` calls these; the subdivision's
// pipelines of frames without a head are composed with `projection_head_off` in its place.

#import projection

// Head frame → display frame (the turn γ about y).
fn head_to_display(proj: Projection, v: vec3<f32>) -> vec3<f32> {
    let c = cos(proj.head_turn);
    let s = sin(proj.head_turn);
    return vec3<f32>(c * v.x + s * v.z, v.y, -s * v.x + c * v.z);
}

fn display_to_head(proj: Projection, v: vec3<f32>) -> vec3<f32> {
    let c = cos(proj.head_turn);
    let s = sin(proj.head_turn);
    return vec3<f32>(c * v.x - s * v.z, v.y, s * v.x + c * v.z);
}

// u (unwrapped about θ), v and depth where the line from the eye through p meets the screen.
fn head_project(proj: Projection, p: vec3<f32>, theta: f32, eye_sign: f32) -> vec3<f32> {
    let e_head = vec3<f32>(eye_sign * proj.eye_radius, 0.0, 0.0);
    let e = head_to_display(proj, e_head) + proj.head_offset;
    let d = head_to_display(proj, p - e_head);
    let a = d.x * d.x + d.z * d.z;
    let b = 2.0 * (e.x * d.x + e.z * d.z);
    let c = e.x * e.x + e.z * e.z - proj.screen_radius * proj.screen_radius;
    let t = (-b + sqrt(max(b * b - 4.0 * a * c, 0.0))) / max(2.0 * a, 1e-30);
    let hit = e + t * d;
    let u = theta - proj.head_turn + wrap_angle(azimuth(hit) - theta + proj.head_turn);
    return vec3<f32>(u, hit.y, length(p - e_head));
}

// The screen point of (u, v) in the head's frame.
fn head_screen_point(proj: Projection, u: f32, v: f32) -> vec3<f32> {
    let s = vec3<f32>(proj.screen_radius * sin(u), v, -proj.screen_radius * cos(u));
    return display_to_head(proj, s - proj.head_offset);
}
