// The scene's vertices as uploaded (`SceneVertex` in src/core/scene.rs), read by the stages
// that start from the scene: subdivide and trace.

struct SceneVertex {
    position: vec3<f32>,
    material: u32,
    normal: vec3<f32>,
    object: u32,
    color: vec4<f32>,
    uv: vec2<f32>,
    _pad1: vec2<f32>,
}
