// The full sphere's projection at a point (`Projection::sphere_*` in src/core/panoramas/projection.rs):
// the eye offset it is seen at (the pole merge, by Newton steps) and its longitude, latitude and
// depth there; the equations are in `projection`, which calls these. The subdivide stage's
// cylinder pipelines are composed with `projection_sphere_off` in its place.

#import projection

// e and de/dd: the eye ray's distance from P's vertical line along `side`, for eye offset d ≥ 0.
fn sphere_e_slope(proj: Projection, r: f32, y: f32, d: f32) -> vec2<f32> {
    if (!CONVERGING || proj.convergence <= 0.0) {
        return vec2<f32>(d, 1.0);
    }
    let d2 = d * d;
    let c2 = proj.convergence * proj.convergence;
    let p2 = r * r + y * y;
    let s = sqrt(max(d2 * d2 + (d2 + c2) * (p2 - d2), 0.0));
    let t = (d2 + s) / (d2 + c2);
    var ds = 0.0;
    if (s > 0.0) {
        ds = d * (p2 - c2) / s;
    }
    let dt = ((2.0 * d + ds) * (d2 + c2) - 2.0 * d * (d2 + s)) / ((d2 + c2) * (d2 + c2));
    return vec2<f32>((1.0 - t) * d, 1.0 - t - d * dt);
}

fn sphere_e(proj: Projection, r: f32, y: f32, d: f32) -> f32 {
    return sphere_e_slope(proj, r, y, d).x;
}

// Longitude, latitude and depth |P − E| at a fixed eye offset d.
fn sphere_at_offset(proj: Projection, r: f32, y: f32, theta: f32, eye_sign: f32, d: f32) -> vec3<f32> {
    let view = sphere_offset_view(proj, r, y, d);
    return vec3<f32>(theta - eye_sign * view.x, view.y, view.z);
}

// What both eyes share at eye offset d: the longitude's shift asin(e/r) (the eye's sign sets its
// side), the latitude and the depth.
fn sphere_offset_view(proj: Projection, r: f32, y: f32, d: f32) -> vec3<f32> {
    let e = sphere_e(proj, r, y, d);
    var q = 0.0;
    if (r > 0.0) {
        q = clamp(e / r, -1.0, 1.0);
    }
    let lat = precise_atan2(y, sqrt(max(r * r - e * e, 0.0)));
    let depth = sqrt(max(r * r + y * y + d * d - 2.0 * d * e, 0.0));
    return vec3<f32>(precise_asin(q), lat, depth);
}

// The altitude at which a point is seen at eye offset d, and its slope d(altitude)/dd.
fn sphere_altitude(proj: Projection, r: f32, y: f32, d: f32) -> vec2<f32> {
    let e = sphere_e_slope(proj, r, y, d);
    let h = sqrt(max(r * r - e.x * e.x, 1e-30));
    return vec2<f32>(precise_atan2(abs(y), h), abs(y) * e.x * e.y / (h * (h * h + y * y)));
}

// The eye offset f(|φ|)·d_e at which a point is seen: the root of φ = φ(f(φ)·d_e), by Newton
// steps on g(a) = altitude(f(a)·d_e) − a from the altitude at full offset (below the merge: d_e),
// at most SPHERE_NEWTON_STEPS, until one moves a by at most SPHERE_NEWTON_TOLERANCE
// (`sphere_eye_offset` in sphere.rs). One loop, one call site of the altitude (lavapipe inlines
// every call site, and this runs at every projection): step 0 the altitude at the full offset,
// then the Newton steps. The loop ends for a group of lanes once all of theirs have converged
// (most often after two steps): lavapipe runs every step's code for every lane of the group.
fn sphere_eye_offset(proj: Projection, r: f32, y: f32) -> f32 {
    let de = proj.eye_radius;
    if (proj.pole_to <= 0.0) {
        return de;
    }
    let k = 0.5 * PI / (proj.pole_to - proj.pole_from);
    var a = 0.0;
    for (var step = 0u; step <= SPHERE_NEWTON_STEPS; step++) {
        var d = de;
        if (step > 0u) {
            d = pole_fade(proj, a) * de;
        }
        let altitude = sphere_altitude(proj, r, y, d);
        if (step == 0u) {
            if (altitude.x <= proj.pole_from) {
                return de;
            }
            a = clamp(altitude.x, proj.pole_from, proj.pole_to);
        } else {
            let g = altitude.x - a;
            let dg = altitude.y * de * (-k * sin(k * (a - proj.pole_from))) - 1.0;
            let next = clamp(a - g / dg, proj.pole_from, proj.pole_to);
            let converged = abs(next - a) <= SPHERE_NEWTON_TOLERANCE;
            a = next;
            if (converged) {
                break;
            }
        }
    }
    return pole_fade(proj, a) * de;
}
