// The stand-in for `projection_fisheye` in the subdivision's pipelines of the other panoramas:
// its functions, with the same signatures, doing nothing (lavapipe runs a pass slower with the
// fisheye's map merely inlined in it; see `projection_sphere_off`).

#import projection

fn is_fisheye(proj: Projection) -> bool {
    return false;
}

fn fisheye_scale(proj: Projection) -> f32 {
    return 1.0;
}

fn fisheye_pixel(proj: Projection, u: f32, v: f32) -> vec2<f32> {
    return vec2<f32>(0.0);
}

fn fisheye_direction(proj: Projection, xy: vec2<f32>) -> vec2<f32> {
    return vec2<f32>(0.0);
}

fn shows_pixel(proj: Projection, xy: vec2<f32>) -> bool {
    return true;
}
