//! Textures and the material table the fragment stage reads.
//!
//! A scene's textures (RGBA8, sRGB-encoded, as decoded from PNG/JPEG) get a full mip chain built
//! on the CPU (2×2 box filter in linear light, the last row/column repeated on odd sizes) and
//! are packed one after the other into one texel buffer, with a table of mip levels. One
//! storage buffer instead of a texture array keeps every texture at its own size (a texture
//! array needs equal layers, and lavapipe has no binding arrays); the fragment stage filters
//! by hand (`sample_texture` in shaders/shared/fragment.wgsl, twin in `src/cpu/fragment.rs`), which also
//! makes every glTF wrap and filter mode exact per texture.

use crate::core::shading::color::{linear_to_srgb, srgb_to_linear};
use crate::core::shading::material::{AlphaMode, Material, MipLevel, NO_TEXTURE};

/// A decoded texture image: `width × height` RGBA8 texels, rows top to bottom, colour sRGB-encoded.
#[derive(Clone, Debug, PartialEq)]
pub struct Texture {
    pub name: String,
    pub width: u32,
    pub height: u32,
    pub rgba: Vec<u8>,
}

impl Texture {
    /// A texture from an `image` crate image (any pixel format).
    pub fn from_image(name: impl Into<String>, image: image::DynamicImage) -> Texture {
        let rgba = image.into_rgba8();
        Texture { name: name.into(), width: rgba.width(), height: rgba.height(), rgba: rgba.into_raw() }
    }

    /// The texture halved (2×2 box filter in linear light; odd sizes repeat the last row/column).
    pub fn half(&self) -> Texture {
        let (w, h) = ((self.width / 2).max(1), (self.height / 2).max(1));
        let mut rgba = Vec::with_capacity((4 * w * h) as usize);
        for y in 0..h {
            for x in 0..w {
                let mut sum = [0.0f32; 4];
                for (dx, dy) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
                    let sx = (2 * x + dx).min(self.width - 1);
                    let sy = (2 * y + dy).min(self.height - 1);
                    let t = &self.rgba[(4 * (sy * self.width + sx)) as usize..][..4];
                    for c in 0..3 {
                        sum[c] += srgb_to_linear(t[c] as f32 / 255.0);
                    }
                    sum[3] += t[3] as f32 / 255.0;
                }
                let q = |x: f32| (x.clamp(0.0, 1.0) * 255.0 + 0.5).floor() as u8;
                rgba.extend([q(linear_to_srgb(sum[0] / 4.0)), q(linear_to_srgb(sum[1] / 4.0))]);
                rgba.extend([q(linear_to_srgb(sum[2] / 4.0)), q(sum[3] / 4.0)]);
            }
        }
        Texture { name: self.name.clone(), width: w, height: h, rgba }
    }

    /// The texture as data (metallic-roughness, normal, occlusion maps hold numbers, not colours):
    /// each colour channel's value v/255 stored sRGB-encoded, so that the fragment stage's sRGB
    /// decoding and the linear-light mip chain give back the numbers and their averages (alpha
    /// is linear already). Quantisation adds at most half an sRGB step (≤ 0.45 % of the range).
    pub fn encode_data(&self) -> Texture {
        let q = |x: f32| (linear_to_srgb(x) * 255.0 + 0.5).floor() as u8;
        let rgba = self
            .rgba
            .chunks_exact(4)
            .flat_map(|t| [q(t[0] as f32 / 255.0), q(t[1] as f32 / 255.0), q(t[2] as f32 / 255.0), t[3]])
            .collect();
        Texture { name: format!("{} (data)", self.name), width: self.width, height: self.height, rgba }
    }

    /// The mip chain from this level down to 1×1.
    pub fn mip_chain(&self) -> Vec<Texture> {
        let mut chain = vec![self.clone()];
        while chain.last().is_some_and(|t| t.width > 1 || t.height > 1) {
            let next = chain.last().unwrap().half();
            chain.push(next);
        }
        chain
    }
}

/// Everything the fragment stage reads about surfaces: the materials (entry 0 is the default
/// material, entry k + 1 the scene's material k), the mip table and the texels.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct MaterialTable {
    pub materials: Vec<Material>,
    pub mips: Vec<MipLevel>,
    /// RGBA8 sRGB texels, one per u32 (little-endian: r in the low byte).
    pub texels: Vec<u32>,
    /// Textures that lost their largest levels to the texel budget.
    pub warnings: Vec<String>,
    /// The frame's lights (viewer frame) and lighting, as group 1 also holds them; empty and
    /// the headlight by default ([`MaterialTable::with_lighting`]).
    pub lights: Vec<crate::core::shading::light::GpuLight>,
    pub lighting: crate::core::shading::light::LightingParams,
    /// The environment's prefiltered levels and split-sum table, as group 1's binding 5 holds
    /// them (empty without an environment; [`MaterialTable::with_environment`]).
    pub environment: Vec<u32>,
    /// The frame's shadow maps and their depths, as group 1's bindings 6 and 7 hold them
    /// (empty without; [`MaterialTable::with_shadows`]).
    pub shadow_maps: Vec<crate::core::shading::shadow::GpuShadowMap>,
    pub shadow_depths: Vec<f32>,
}

impl MaterialTable {
    /// The same table with a frame's lights (viewer frame) and lighting (the CPU twins' group 1).
    /// With an environment's texels (its places and coefficients come with the lighting).
    pub fn with_environment(
        mut self,
        environment: &crate::core::shading::environment::PreparedEnvironment,
    ) -> MaterialTable {
        self.environment = environment.texels.clone();
        self
    }

    /// With a frame's shadow maps and their depths (`cpu::shadow`).
    pub fn with_shadows(
        mut self,
        maps: Vec<crate::core::shading::shadow::GpuShadowMap>,
        depths: Vec<f32>,
    ) -> MaterialTable {
        self.shadow_maps = maps;
        self.shadow_depths = depths;
        self
    }

    pub fn with_lighting(
        mut self,
        lights: Vec<crate::core::shading::light::GpuLight>,
        lighting: crate::core::shading::light::LightingParams,
    ) -> MaterialTable {
        self.lights = lights;
        self.lighting = lighting;
        self
    }

    /// Whether any material needs the fragment stage's material code: textured, not opaque, or
    /// single-sided. (Otherwise a fragment's colour is its vertex colour.)
    pub fn needs_materials(&self) -> bool {
        self.materials.iter().any(|m| {
            m.texture != NO_TEXTURE || m.alpha_mode != AlphaMode::Opaque as u32 || m.double_sided == 0 || m.has_maps()
        })
    }

    /// Whether any material can discard a fragment: alpha-tested or blended, or single-sided.
    pub fn discards(&self) -> bool {
        self.materials.iter().any(|m| m.alpha_mode != AlphaMode::Opaque as u32 || m.double_sided == 0)
    }

    /// Whether any material mirrors or transmits light (the ray tracer's optics, which need its
    /// material code).
    pub fn has_optics(&self) -> bool {
        self.materials.iter().any(|m| m.mirror > 0.0 || m.transmission > 0.0)
    }

    /// Whether every material in `used` (indices into this table, as the vertices carry them,
    /// clamped as the fragment stage clamps them) is single-sided, and there is one: the drawing
    /// stages then cull back faces in the rasterizer, per eye, before any fragment work (the same
    /// triangles the fragment stage would discard: both go by the triangle's winding on screen).
    pub fn all_single_sided(&self, used: impl IntoIterator<Item = u32>) -> bool {
        let last = self.materials.len().saturating_sub(1);
        let mut any = false;
        for m in used {
            any = true;
            if self.materials.get((m as usize).min(last)).is_none_or(|m| m.double_sided != 0) {
                return false;
            }
        }
        any
    }

    /// Packs a scene's materials and textures, keeping at most `max_texels` texels: while over,
    /// the texture with the largest top level loses that level (with a warning).
    pub fn build(materials: &[Material], textures: &[Texture], max_texels: usize) -> MaterialTable {
        let mut chains: Vec<Vec<Texture>> = textures.iter().map(Texture::mip_chain).collect();
        let texel_count = |c: &Vec<Texture>| c.iter().map(|t| (t.width * t.height) as usize).sum::<usize>();
        let mut dropped = vec![0u32; chains.len()];
        while chains.iter().map(texel_count).sum::<usize>() > max_texels {
            let Some(k) = (0..chains.len())
                .filter(|&k| chains[k].len() > 1)
                .max_by_key(|&k| chains[k][0].width * chains[k][0].height)
            else {
                break;
            };
            chains[k].remove(0);
            dropped[k] += 1;
        }
        let mut table = MaterialTable::default();
        let mut first_mip = Vec::with_capacity(chains.len());
        for (k, chain) in chains.iter().enumerate() {
            first_mip.push(table.mips.len() as u32);
            if dropped[k] > 0 {
                table.warnings.push(format!(
                    "texture '{}' drawn at {}×{} instead of {}×{} (texture memory budget)",
                    textures[k].name, chain[0].width, chain[0].height, textures[k].width, textures[k].height
                ));
            }
            for level in chain {
                table.mips.push(MipLevel {
                    offset: table.texels.len() as u32,
                    width: level.width,
                    height: level.height,
                    _pad: 0,
                });
                table.texels.extend(level.rgba.chunks_exact(4).map(|t| u32::from_le_bytes([t[0], t[1], t[2], t[3]])));
            }
        }
        // A texture's place: (index, first level, level count), or none for a missing index.
        let place = |t: u32| match chains.get(t as usize) {
            Some(chain) => (t, first_mip[t as usize], chain.len() as u32),
            None => (NO_TEXTURE, 0, 0),
        };
        table.materials = std::iter::once(Material::default())
            .chain(materials.iter().map(|m| {
                let mut m = *m;
                (m.texture, m.first_mip, m.mip_count) = place(m.texture);
                (m.mr_texture, m.mr_first_mip, m.mr_mip_count) = place(m.mr_texture);
                (m.normal_texture, m.normal_first_mip, m.normal_mip_count) = place(m.normal_texture);
                (m.occlusion_texture, m.occlusion_first_mip, m.occlusion_mip_count) = place(m.occlusion_texture);
                (m.emissive_texture, m.emissive_first_mip, m.emissive_mip_count) = place(m.emissive_texture);
                m
            }))
            .collect();
        table
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn texture(w: u32, h: u32, f: impl Fn(u32, u32) -> [u8; 4]) -> Texture {
        let rgba = (0..h).flat_map(|y| (0..w).map(move |x| (x, y))).flat_map(|(x, y)| f(x, y)).collect();
        Texture { name: "t".into(), width: w, height: h, rgba }
    }

    #[test]
    fn mip_chain_halves_down_to_one_texel_and_averages_in_linear_light() {
        // Black and white columns: every level below the top is the linear-light mean, which
        // is sRGB 188, not the sRGB mean 128.
        let t = texture(8, 3, |x, _| if x % 2 == 0 { [0, 0, 0, 255] } else { [255, 255, 255, 0] });
        let chain = t.mip_chain();
        let sizes: Vec<(u32, u32)> = chain.iter().map(|t| (t.width, t.height)).collect();
        assert_eq!(sizes, [(8, 3), (4, 1), (2, 1), (1, 1)]);
        for level in &chain[1..] {
            for px in level.rgba.chunks_exact(4) {
                assert_eq!(px, [188, 188, 188, 128], "{}×{}", level.width, level.height);
            }
        }
    }

    #[test]
    fn packing_fills_the_tables_and_respects_the_budget() {
        let a = texture(4, 4, |x, y| [x as u8, y as u8, 0, 255]);
        let b = texture(16, 2, |x, _| [0, 0, x as u8, 255]);
        let materials = [Material { texture: 1, ..Default::default() }, Material { texture: 7, ..Default::default() }];
        let table = MaterialTable::build(&materials, &[a.clone(), b.clone()], usize::MAX);
        assert_eq!(table.materials.len(), 3);
        assert_eq!(table.materials[0], Material::default());
        assert_eq!(table.materials[2].texture, NO_TEXTURE, "an index past the textures means no texture");
        let m = table.materials[1];
        assert_eq!((m.first_mip, m.mip_count), (3, 5)); // a: 4, 2, 1; b: 16×2, 8×1, 4, 2, 1
        let top = table.mips[m.first_mip as usize];
        assert_eq!((top.width, top.height), (16, 2));
        let texel = table.texels[(top.offset + 5) as usize].to_le_bytes();
        assert_eq!(texel, [0, 0, 5, 255]);
        assert_eq!(table.texels.len(), 16 + 4 + 1 + 32 + 8 + 4 + 2 + 1);
        // A budget of 40 texels: b loses its 16×2 level (the largest), then fits.
        let small = MaterialTable::build(&materials, &[a, b], 40);
        assert_eq!(small.texels.len(), 21 + 15);
        assert_eq!(small.materials[1].mip_count, 4);
        assert_eq!(small.warnings.len(), 1, "{:?}", small.warnings);
    }
}
