// The stand-in for `projection_sphere` in the pipelines built for the cylinder alone (the
// subdivide stage's, `PANORAMAS` = 1, where `is_sphere` is false): its functions that
// `projection` calls, with the same signatures, doing nothing. lavapipe inlines a function at
// every call site before it drops the branches a constant leaves out: with the sphere's Newton
// steps in them the cylinder's `plan_cuts` and `lattice` took about twice as long to build.

#import projection

fn sphere_e(proj: Projection, r: f32, y: f32, d: f32) -> f32 {
    return 0.0;
}

fn sphere_at_offset(proj: Projection, r: f32, y: f32, theta: f32, eye_sign: f32, d: f32) -> vec3<f32> {
    return vec3<f32>(0.0);
}

fn sphere_offset_view(proj: Projection, r: f32, y: f32, d: f32) -> vec3<f32> {
    return vec3<f32>(0.0);
}

fn sphere_eye_offset(proj: Projection, r: f32, y: f32) -> f32 {
    return 0.0;
}
