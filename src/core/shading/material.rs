//! Surface materials as the fragment stage reads them (`Material`, `MipLevel` in
//! shaders/shared/fragment.wgsl; the layout test checks every field offset).

use bytemuck::{Pod, Zeroable};

/// No texture (`Material::texture`).
pub const NO_TEXTURE: u32 = u32::MAX;

/// A surface material as the fragment stage reads it (`Material` in shaders/shared/fragment.wgsl),
/// indexed by a vertex's `material` (0: the default material). The base colour factor is
/// already multiplied into the vertex colours; this holds what needs the fragment. 76 bytes.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Pod, Zeroable)]
pub struct Material {
    /// Index of the base colour texture in the scene's textures, or `NO_TEXTURE`.
    pub texture: u32,
    /// Wrap modes along u and v (`Wrap as u32`).
    pub wrap_u: u32,
    pub wrap_v: u32,
    /// Filters (`Filter as u32`): magnification, minification within a level, between levels.
    pub mag_filter: u32,
    pub min_filter: u32,
    pub mipmap: u32,
    /// `AlphaMode as u32`.
    pub alpha_mode: u32,
    pub alpha_cutoff: f32,
    /// 1: both faces drawn; 0: faces seen from behind are culled.
    pub double_sided: u32,
    /// Filled in when the textures are packed: the texture's first entry in the mip table and
    /// its level count.
    pub first_mip: u32,
    pub mip_count: u32,
    /// The ray tracer's optics (the rasterizer ignores them): the share of light mirrored
    /// (tinted by the surface colour), the share transmitted and refracted, and the index of
    /// refraction (glTF metallic 1 / roughness 0 → mirror 1; `KHR_materials_transmission`,
    /// `KHR_materials_ior`; OBJ `illum` 3–7 with `Ks`, `d`/`Tr`, `Ni`).
    pub mirror: f32,
    pub transmission: f32,
    pub ior: f32,
    /// The glTF metallic-roughness factors (`--lighting pbr`; the headlight ignores them).
    pub metallic: f32,
    pub roughness: f32,
    /// Emitted linear colour (glTF emissive factor × `KHR_materials_emissive_strength`).
    pub emissive_r: f32,
    pub emissive_g: f32,
    pub emissive_b: f32,
    /// The glTF texture maps (`*_texture`: a scene texture, or NO_TEXTURE; `*_first_mip`,
    /// `*_mip_count`: where the material table put its levels), sampled at the base colour's
    /// texture coordinates with its sampler: metallic-roughness (blue × metallic, green ×
    /// roughness), the tangent-space normal map (× `normal_scale` in x and y), occlusion (red,
    /// blended by `occlusion_strength`), emission (× the emissive factor). The data maps are
    /// stored sRGB-encoded like colour (see `Texture::encode_data`).
    pub mr_texture: u32,
    pub mr_first_mip: u32,
    pub mr_mip_count: u32,
    pub normal_texture: u32,
    pub normal_first_mip: u32,
    pub normal_mip_count: u32,
    pub normal_scale: f32,
    pub occlusion_texture: u32,
    pub occlusion_first_mip: u32,
    pub occlusion_mip_count: u32,
    pub occlusion_strength: f32,
    pub emissive_texture: u32,
    pub emissive_first_mip: u32,
    pub emissive_mip_count: u32,
}

impl Material {
    /// Whether it has any of the glTF BRDF's texture maps.
    pub fn has_maps(&self) -> bool {
        [self.mr_texture, self.normal_texture, self.occlusion_texture, self.emissive_texture]
            .iter()
            .any(|&t| t != NO_TEXTURE)
    }
}

impl Default for Material {
    /// The default material: untextured, opaque, double-sided.
    fn default() -> Self {
        Material {
            texture: NO_TEXTURE,
            wrap_u: Wrap::Repeat as u32,
            wrap_v: Wrap::Repeat as u32,
            mag_filter: Filter::Linear as u32,
            min_filter: Filter::Linear as u32,
            mipmap: Mipmap::Linear as u32,
            alpha_mode: AlphaMode::Opaque as u32,
            alpha_cutoff: 0.5,
            double_sided: 1,
            first_mip: 0,
            mip_count: 0,
            mirror: 0.0,
            transmission: 0.0,
            ior: 1.5,
            metallic: 0.0,
            roughness: 1.0,
            emissive_r: 0.0,
            emissive_g: 0.0,
            emissive_b: 0.0,
            mr_texture: NO_TEXTURE,
            mr_first_mip: 0,
            mr_mip_count: 0,
            normal_texture: NO_TEXTURE,
            normal_first_mip: 0,
            normal_mip_count: 0,
            normal_scale: 1.0,
            occlusion_texture: NO_TEXTURE,
            occlusion_first_mip: 0,
            occlusion_mip_count: 0,
            occlusion_strength: 1.0,
            emissive_texture: NO_TEXTURE,
            emissive_first_mip: 0,
            emissive_mip_count: 0,
        }
    }
}

/// Texture wrap mode (glTF sampler `wrapS`/`wrapT`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Wrap {
    Repeat = 0,
    ClampToEdge = 1,
    MirroredRepeat = 2,
}

/// Texel filter within one mip level.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Filter {
    Nearest = 0,
    Linear = 1,
}

/// How the minification filter uses the mip levels: not at all (level 0), the nearest level,
/// or a blend of the two nearest.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Mipmap {
    None = 0,
    Nearest = 1,
    Linear = 2,
}

/// glTF alpha mode. BLEND is drawn as order-independent screen-door transparency (see
/// shaders/shared/fragment.wgsl).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum AlphaMode {
    Opaque = 0,
    Mask = 1,
    Blend = 2,
}

/// One mip level of a packed texture (`MipLevel` in shaders/shared/fragment.wgsl): where its texels
/// start in the texel buffer (one RGBA8 sRGB texel per u32, rows top to bottom) and its size.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct MipLevel {
    pub offset: u32,
    pub width: u32,
    pub height: u32,
    pub _pad: u32,
}
