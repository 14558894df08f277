// The stand-in for `projection_cubemap` in the subdivision's pipelines (which measure a cubemap
// on the sphere): its functions, with the same signatures, doing nothing (see
// `projection_sphere_off`).

#import projection

fn is_cubemap(proj: Projection) -> bool {
    return false;
}

fn cube_pixel(proj: Projection, u: f32, v: f32) -> vec2<f32> {
    return vec2<f32>(0.0);
}

fn cube_direction(proj: Projection, xy: vec2<f32>) -> vec2<f32> {
    return vec2<f32>(0.0);
}

fn cube_clip(proj: Projection, u: f32, v: f32, z: f32) -> vec4<f32> {
    return vec4<f32>(0.0);
}

fn cube_pixel_near(proj: Projection, u: f32, v: f32, xy: vec2<f32>) -> vec3<f32> {
    return vec3<f32>(0.0);
}
