// The fulldome master's image (`core::panoramas::fisheye`): the sphere's eye rays in an equidistant
// azimuthal image, the dome's axis at the centre. `projection` calls these; the pipelines of the
// other panoramas' subdivision are composed with `projection_fisheye_off` in its place.

#import projection

fn is_fisheye(proj: Projection) -> bool {
    return (PANORAMAS & 4u) != 0u && proj.panorama == PANORAMA_FISHEYE;
}

// k: pixels per radian from the dome's axis.
fn fisheye_scale(proj: Projection) -> f32 {
    return proj.width / radians(proj.fov);
}

// The image position of the ray of longitude u, latitude v (`Projection::fisheye_pixel`).
fn fisheye_pixel(proj: Projection, u: f32, v: f32) -> vec2<f32> {
    let d = vec3<f32>(cos(v) * sin(u), sin(v), -cos(v) * cos(u));
    let t = radians(proj.dome_tilt);
    let a = d.x;
    let b = d.y * sin(t) - d.z * cos(t);
    let c = d.y * cos(t) + d.z * sin(t);
    let h = sqrt(a * a + b * b);
    var ratio = 1.0;
    if (h > 0.0) {
        ratio = precise_atan2(h, c) / h;
    }
    let k = fisheye_scale(proj);
    return vec2<f32>(0.5 * proj.width + k * ratio * a, 0.5 * proj.height + k * ratio * b);
}

// The longitude and latitude of the ray shown at image position xy
// (`Projection::fisheye_direction_at`).
fn fisheye_direction(proj: Projection, xy: vec2<f32>) -> vec2<f32> {
    let dxy = xy - 0.5 * vec2<f32>(proj.width, proj.height);
    let k = fisheye_scale(proj);
    let rho = length(dxy);
    let psi = rho / k;
    var s = 1.0 / k;
    if (rho > 0.0) {
        s = sin(psi) / rho;
    }
    let t = radians(proj.dome_tilt);
    let axis = vec3<f32>(0.0, cos(t), sin(t));
    let front = vec3<f32>(0.0, sin(t), -cos(t));
    let d = vec3<f32>(s * dxy.x, 0.0, 0.0) + s * dxy.y * front + cos(psi) * axis;
    return vec2<f32>(precise_atan2(d.x, -d.z), precise_atan2(d.y, sqrt(d.x * d.x + d.z * d.z)));
}

// Whether image position xy shows the scene: inside the fisheye's circle; everywhere elsewhere
// (`Projection::shows_pixel`).
fn shows_pixel(proj: Projection, xy: vec2<f32>) -> bool {
    if (!is_fisheye(proj)) {
        return true;
    }
    let d = xy - 0.5 * vec2<f32>(proj.width, proj.height);
    return dot(d, d) <= 0.25 * proj.width * proj.width;
}
