// The drawing stages' and the ray tracer's group 1: the material table (materials, mip levels,
// texels), the lights and the frame's lighting, the environment, the shadow maps; the pipeline
// constants that compile parts of the look in or out. Bindings only, no functions: the modules
// texture, brdf, ibl and surface read them. Rust twins of the structs: src/encoding/types.rs
// (LAYOUTS), src/core/shading/material.rs, src/core/shading/light.rs, src/core/shading/shadow.rs.

#import constants

// ---- Materials and textures (layout: src/core/shading/material.rs, packing: src/core/shading/texture.rs) ----

// false: every material of the scene is untextured, opaque and double-sided, so a fragment's
// colour is its vertex colour and nothing is discarded; the renderer then compiles the material
// code out (a pipeline constant), which restores early depth testing.
override MATERIALS: bool = true;

// false: no material of the scene can discard a fragment (all opaque and double-sided), so the
// fragment entry points leave `discard` out and the rasterizer may test depth before shading.
override DISCARDS: bool = true;

// true: the fisheye, whose fragments outside its circle are discarded (fragment.wgsl); false
// compiles that test out, keeping early depth testing for the other panoramas.
override CIRCLE: bool = true;

// Parts of the glTF look a pipeline compiles in (src/gpu/draw.rs, `Lit`): the BRDF at all, the
// environment's image-based lighting, the texture maps. lavapipe runs every branch under a mask,
// so a part a frame does not use is left out rather than skipped. The ray tracer keeps all
// (the uniform `lighting` decides).
override PBR: bool = true;
override ENVIRONMENT: bool = true;
override MAPS: bool = true;

// false: the frame has no shadow maps (no directional or spot light, `--no-shadows`, the ray
// tracer, which shadows by rays); the drawing pipelines then leave the look-up out.
override SHADOW_MAPS: bool = true;

// NO_TEXTURE, WRAP_*, FILTER_*, MIPMAP_*, ALPHA_*: from `constants` (src/core/shading/material.rs).

struct Material {
    texture: u32,
    wrap_u: u32,
    wrap_v: u32,
    mag_filter: u32,
    min_filter: u32,
    mipmap: u32,
    alpha_mode: u32,
    alpha_cutoff: f32,
    double_sided: u32,
    first_mip: u32,
    mip_count: u32,
    mirror: f32,        // the ray tracer's optics (src/core/shading/material.rs)
    transmission: f32,
    ior: f32,
    metallic: f32,      // glTF metallic-roughness factors
    roughness: f32,
    emissive_r: f32,    // emitted linear colour (× KHR_materials_emissive_strength)
    emissive_g: f32,
    emissive_b: f32,
    // The glTF maps: texture (unused here), first mip level, level count (0: none).
    mr_texture: u32,
    mr_first_mip: u32,
    mr_mip_count: u32,
    normal_texture: u32,
    normal_first_mip: u32,
    normal_mip_count: u32,
    normal_scale: f32,
    occlusion_texture: u32,
    occlusion_first_mip: u32,
    occlusion_mip_count: u32,
    occlusion_strength: f32,
    emissive_texture: u32,
    emissive_first_mip: u32,
    emissive_mip_count: u32,
}

// A punctual light (KHR_lights_punctual, src/core/shading/light.rs), viewer frame: colour × intensity
// (candela; lux for directional lights), range 0 = unlimited, spot cone cosines.
struct Light {
    position: vec3<f32>,
    kind: u32,
    direction: vec3<f32>,
    range: f32,
    color: vec3<f32>,
    inner_cos: f32,
    outer_cos: f32,
    shadow_map: u32,    // its shadow map (src/core/shading/shadow.rs), or NO_SHADOW_MAP
    _pad1: u32,
    _pad2: u32,
}

// The frame's lighting (`LightingParams`): lights in use, the glTF BRDF (1) or the headlight
// (0), 2^EV, the tone mapping; the environment's image-based lighting (src/core/shading/environment.rs):
// on or off, where its split-sum table starts, the rotation
// from the viewer frame to the environment's, the irradiance's SH coefficients and the
// prefiltered levels (first texel, width, height).
struct Lighting {
    count: u32,
    pbr: u32,
    exposure: f32,
    tonemap: u32,
    environment: u32,
    env_background: u32,
    env_lut: u32,
    shadows: u32,
    anisotropy: u32,    // the most probes a texture sample takes along its footprint (`--anisotropy`)
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
    env_rotation: array<vec4<f32>, 3>,
    env_sh: array<vec4<f32>, 9>,
    env_levels: array<vec4<u32>, ENV_LEVELS>,
}

struct MipLevel {
    offset: u32,
    width: u32,
    height: u32,
    _pad: u32,
}

@group(1) @binding(0) var<storage, read> materials: array<Material>;
@group(1) @binding(1) var<storage, read> mips: array<MipLevel>;
// RGBA8 sRGB texels, one per u32, rows top to bottom, levels and textures one after the other.
@group(1) @binding(2) var<storage, read> texels: array<u32>;
@group(1) @binding(3) var<storage, read> lights: array<Light>;
@group(1) @binding(4) var<uniform> lighting: Lighting;
// The environment's prefiltered levels (RGB9E5) and split-sum table (two half floats); a single
// entry when none (src/core/shading/environment.rs).
@group(1) @binding(5) var<storage, read> environment: array<u32>;

// A light's shadow map (src/core/shading/shadow.rs): viewer frame → the light's clip space, its first
// depth, its side in texels, a texel's world size (at unit distance along the axis when
// perspective), its kind: SHADOW_ORTHOGRAPHIC, SHADOW_PERSPECTIVE, or SHADOW_CUBE (a point
// light's six faces, +x −x +y −y +z −z, this the first).
struct ShadowMap {
    clip_from_viewer: mat4x4<f32>,
    offset: u32,
    size: u32,
    texel: f32,
    projection: u32,
}

// The frame's shadow maps and their depths (rows top to bottom, maps one after the other),
// rendered by the `shadow` stage; a single entry each when none.
@group(1) @binding(6) var<storage, read> shadow_maps: array<ShadowMap>;
@group(1) @binding(7) var<storage, read> shadow_depths: array<f32>;
