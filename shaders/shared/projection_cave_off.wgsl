// The stand-in for `projection_cave` in the subdivision's pipelines (a CAVE wall is a
// perspective, drawn without subdivision): its functions, with the same signatures, doing nothing
// (see `projection_sphere_off`).

#import projection

fn is_cave(proj: Projection) -> bool {
    return false;
}

fn cave_project(proj: Projection, p: vec3<f32>, eye_sign: f32) -> vec3<f32> {
    return vec3<f32>(0.0);
}

fn cave_sees(proj: Projection, p: vec3<f32>) -> bool {
    return true;
}

fn cave_point(proj: Projection, xy: vec2<f32>) -> vec3<f32> {
    return vec3<f32>(0.0);
}

fn cave_spread(proj: Projection) -> f32 {
    return 1.0;
}
