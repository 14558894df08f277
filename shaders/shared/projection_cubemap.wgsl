// The stereo cubemap's image (`core::panoramas::cubemap`): the sphere's eye rays on six 90° gnomonic faces,
// one eye's image the 3×2 grid of YouTube's layout (right, left, up / down, front, back).
// `projection` calls these; the subdivision (which measures a cubemap on the sphere) is composed
// with `projection_cubemap_off` in its place.

#import projection

fn is_cubemap(proj: Projection) -> bool {
    return (PANORAMAS & 8u) != 0u && proj.panorama == PANORAMA_CUBEMAP;
}

struct CubeFace {
    normal: vec3<f32>,
    right: vec3<f32>,
    up: vec3<f32>,
    cell: vec2<f32>,
}

// `CUBE_FACES` in core/panoramas/cubemap.rs: right, left, up, down, front, back.
fn cube_face_axes(f: u32) -> CubeFace {
    switch f {
        case 0u: { return CubeFace(vec3<f32>(1.0, 0.0, 0.0), vec3<f32>(0.0, 0.0, 1.0), vec3<f32>(0.0, 1.0, 0.0), vec2<f32>(0.0, 0.0)); }
        case 1u: { return CubeFace(vec3<f32>(-1.0, 0.0, 0.0), vec3<f32>(0.0, 0.0, -1.0), vec3<f32>(0.0, 1.0, 0.0), vec2<f32>(1.0, 0.0)); }
        case 2u: { return CubeFace(vec3<f32>(0.0, 1.0, 0.0), vec3<f32>(-1.0, 0.0, 0.0), vec3<f32>(0.0, 0.0, -1.0), vec2<f32>(2.0, 0.0)); }
        case 3u: { return CubeFace(vec3<f32>(0.0, -1.0, 0.0), vec3<f32>(-1.0, 0.0, 0.0), vec3<f32>(0.0, 0.0, 1.0), vec2<f32>(0.0, 1.0)); }
        case 4u: { return CubeFace(vec3<f32>(0.0, 0.0, -1.0), vec3<f32>(1.0, 0.0, 0.0), vec3<f32>(0.0, 1.0, 0.0), vec2<f32>(1.0, 1.0)); }
        default: { return CubeFace(vec3<f32>(0.0, 0.0, 1.0), vec3<f32>(-1.0, 0.0, 0.0), vec3<f32>(0.0, 1.0, 0.0), vec2<f32>(2.0, 1.0)); }
    }
}

fn lon_lat_direction(u: f32, v: f32) -> vec3<f32> {
    return vec3<f32>(cos(v) * sin(u), sin(v), -cos(v) * cos(u));
}

// The face a direction falls on (`cube_face_of`).
fn cube_face_of(d: vec3<f32>) -> u32 {
    let a = abs(d);
    if (a.x >= a.y && a.x >= a.z) {
        return select(1u, 0u, d.x >= 0.0);
    }
    if (a.y >= a.z) {
        return select(3u, 2u, d.y >= 0.0);
    }
    return select(5u, 4u, d.z < 0.0);
}

// The image position of direction d on face f, beyond its edges where d lies outside it; the
// caller checks that d is in front of the face (`Projection::cube_pixel_on_face`).
fn cube_pixel_on_face(proj: Projection, d: vec3<f32>, f: u32) -> vec2<f32> {
    let face = cube_face_axes(f);
    let w = dot(d, face.normal);
    let s = proj.width / 3.0;
    return s * (face.cell + vec2<f32>(0.5 * (1.0 + dot(d, face.right) / w), 0.5 * (1.0 - dot(d, face.up) / w)));
}

// The image position of the ray of longitude u, latitude v (`Projection::cube_pixel`).
fn cube_pixel(proj: Projection, u: f32, v: f32) -> vec2<f32> {
    let d = lon_lat_direction(u, v);
    return cube_pixel_on_face(proj, d, cube_face_of(d));
}

// The face whose square holds image position xy (`Projection::cube_face_at`).
fn cube_face_at(proj: Projection, xy: vec2<f32>) -> u32 {
    let s = proj.width / 3.0;
    let cell = clamp(floor(xy / s), vec2<f32>(0.0), vec2<f32>(2.0, 1.0));
    return u32(3.0 * cell.y + cell.x);
}

// The longitude and latitude of the ray shown at image position xy (`Projection::cube_direction_at`).
fn cube_direction(proj: Projection, xy: vec2<f32>) -> vec2<f32> {
    let face = cube_face_axes(cube_face_at(proj, xy));
    let s = proj.width / 3.0;
    let ab = vec2<f32>(2.0 * (xy.x / s - face.cell.x) - 1.0, 1.0 - 2.0 * (xy.y / s - face.cell.y));
    let d = normalize(face.normal + ab.x * face.right + ab.y * face.up);
    return vec2<f32>(precise_atan2(d.x, -d.z), precise_atan2(d.y, sqrt(d.x * d.x + d.z * d.z)));
}

// A face's w for D·n (`horizon_w` in core/panoramas/cubemap.rs): a direction on the face's horizon plane
// (the cuts around the axis put nodes on x = 0 and z = 0) drawn just in front of it, at
// CUBE_MIN_W (an H200 drew no triangle with a vertex at w = 0).
fn horizon_w(w: f32) -> f32 {
    return select(w, CUBE_MIN_W, abs(w) < CUBE_MIN_W);
}

// The direction a vertex seen at (u, v) is drawn in (`Projection::cube_ray`): within half a
// pixel of a pole (1/F radians), the pole itself, so that the nodes around the axis meet there.
fn cube_ray(proj: Projection, u: f32, v: f32) -> vec3<f32> {
    if (abs(v) > 0.5 * PI - 3.0 / proj.width) {
        return vec3<f32>(0.0, sign(v), 0.0);
    }
    return lon_lat_direction(u, v);
}

// The clip position on the whole grid of the ray of longitude u, latitude v of a point at
// `distance` from its eye for the draw of face `proj.face`, before `clip_w` scales it by that
// distance (`Projection::cube_clip`): w = D·n; z = w − ν/distance, linear in the point after the
// scaling (ν = CUBE_NEAR·R_T, the near plane); the draw's scissor keeps the face.
fn cube_clip(proj: Projection, u: f32, v: f32, distance: f32) -> vec4<f32> {
    let d = cube_ray(proj, u, v);
    let face = cube_face_axes(proj.face);
    let w = horizon_w(dot(d, face.normal));
    let near = CUBE_NEAR * proj.screen_radius / max(distance, CUBE_MIN_DISTANCE);
    return vec4<f32>(((2.0 * face.cell.x + 1.0) / 3.0 - 1.0) * w + dot(d, face.right) / 3.0,
                     (0.5 - face.cell.y) * w + 0.5 * dot(d, face.up), min(w - near, MAX_DEPTH * w), w);
}

// Where the ray of (u, v) shows on the face of image position xy, and how far in front of that
// face it is (≤ 0: behind it): the display-position error's ideal position on the pixel's face.
fn cube_pixel_near(proj: Projection, u: f32, v: f32, xy: vec2<f32>) -> vec3<f32> {
    let d = lon_lat_direction(u, v);
    let f = cube_face_at(proj, xy);
    let w = dot(d, cube_face_axes(f).normal);
    if (w <= 0.0) {
        return vec3<f32>(0.0, 0.0, w);
    }
    return vec3<f32>(cube_pixel_on_face(proj, d, f), w);
}
