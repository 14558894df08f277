// The `shadow` stage (src/core/shading/shadow.rs): the depth of the scene seen from a light (a
// directional light's orthographic map, a spot light's perspective one, each of a point light's
// six cube faces), one map per render pass, before the drawing stages read it (`shadow_visibility`
// in surface.wgsl). A plain linear projection, so the scene's own triangles are drawn, not
// subdivided. Opaque scenes draw depth only; where a material can discard (alpha MASK, the
// BLEND screen door, here at the map's texels), `fs_mask` leaves out what it leaves out. Both
// faces cast shadows. CPU twin: src/cpu/shadow.rs.

#import constants
#import surface

struct ShadowParams {
    clip_from_scene: mat4x4<f32>,
}

@group(0) @binding(0) var<uniform> params: ShadowParams;

// The scene's vertices (`SceneVertex`), as the slit stage reads them.
struct VertexIn {
    @location(0) position: vec3<f32>,
    @location(1) color: vec4<f32>,
    @location(2) uv: vec2<f32>,
    @location(3) material: u32,
}

struct VertexOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) color: vec4<f32>,
    @location(1) uv: vec2<f32>,
    @location(2) @interpolate(flat) material: u32,
}

@vertex
fn vs_main(in: VertexIn) -> VertexOut {
    return VertexOut(params.clip_from_scene * vec4<f32>(in.position, 1.0), in.color, in.uv, in.material);
}

@fragment
fn fs_mask(in: VertexOut) {
    let c = surface_color(in.material, in.color, in.uv, dpdx(in.uv), dpdy(in.uv), in.clip.xy, true);
    if (c.a < 0.0) {
        discard;
    }
}
