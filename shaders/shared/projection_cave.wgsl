// CAVE walls (`core::panoramas::cave`): per wall and eye, where the line from a tracked head's eye through a
// point meets the wall. The frame drawn is the head's (eyes at ±d_e·x); the uniform holds the
// wall in the display's frame and the head (`head_offset`, `head_turn`), turned into the head's
// frame here. `projection` calls these; the subdivision (which never draws a CAVE) is composed
// with `projection_cave_off` in its place.

#import projection

fn is_cave(proj: Projection) -> bool {
    return (PANORAMAS & 16u) != 0u && proj.panorama == PANORAMA_CAVE;
}

// A display-frame vector in the head's frame: R_y(−γ)·v.
fn cave_to_head(proj: Projection, v: vec3<f32>) -> vec3<f32> {
    let c = cos(proj.head_turn);
    let s = sin(proj.head_turn);
    return vec3<f32>(c * v.x - s * v.z, v.y, s * v.x + c * v.z);
}

fn cave_corner(proj: Projection) -> vec3<f32> {
    return cave_to_head(proj, proj.wall_corner - proj.head_offset);
}

fn cave_normal(proj: Projection) -> vec3<f32> {
    return normalize(cross(cave_to_head(proj, proj.wall_right), cave_to_head(proj, proj.wall_up)));
}

// Image position (x, y) and the distance from the eye of head-frame point p for one eye
// (`Projection::cave_pixel`); depth −1 where p lies behind the eye's plane.
fn cave_project(proj: Projection, p: vec3<f32>, eye_sign: f32) -> vec3<f32> {
    let corner = cave_corner(proj);
    let right = cave_to_head(proj, proj.wall_right);
    let up = cave_to_head(proj, proj.wall_up);
    let n = normalize(cross(right, up));
    let e = vec3<f32>(eye_sign * proj.eye_radius, 0.0, 0.0);
    let q = p - e;
    let along = dot(q, n);
    if (!(along < 0.0)) {
        return vec3<f32>(0.0, 0.0, -1.0);
    }
    let hit = e + dot(corner - e, n) / along * q - corner;
    let a = dot(hit, right) / dot(right, right);
    let b = dot(hit, up) / dot(up, up);
    return vec3<f32>(a * proj.width, (1.0 - b) * proj.height, length(q));
}

// Whether a head-frame point lies before both eyes' planes parallel to the wall
// (`Projection::cave_sees`).
fn cave_sees(proj: Projection, p: vec3<f32>) -> bool {
    return dot(p, cave_normal(proj)) < -proj.eye_radius;
}

// The wall's point at image position xy, head frame (`Projection::cave_point`).
fn cave_point(proj: Projection, xy: vec2<f32>) -> vec3<f32> {
    return cave_corner(proj) + xy.x / proj.width * cave_to_head(proj, proj.wall_right)
        + (1.0 - xy.y / proj.height) * cave_to_head(proj, proj.wall_up);
}

// The angle a pixel spans seen from the head, at the wall's nearest point (`pixel_spread`).
fn cave_spread(proj: Projection) -> f32 {
    return length(proj.wall_right) / proj.width / abs(dot(cave_corner(proj), cave_normal(proj)));
}
