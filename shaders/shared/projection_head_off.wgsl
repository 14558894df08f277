// The stand-in for `projection_head` in the subdivision's pipelines of frames without a tracked
// head: its functions, with the same signatures, doing nothing.

#import projection

fn head_project(proj: Projection, p: vec3<f32>, theta: f32, eye_sign: f32) -> vec3<f32> {
    return vec3<f32>(0.0);
}

fn head_screen_point(proj: Projection, u: f32, v: f32) -> vec3<f32> {
    return vec3<f32>(0.0);
}
