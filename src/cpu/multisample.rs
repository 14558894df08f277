//! The multisampled colour pass of the drawing stages on the CPU (`--samples N`), twin of what
//! `fs_main` and `fs_coverage` (shaders/shared/fragment.wgsl) draw into N-sample targets and of
//! the resolve after them. Each triangle covers the samples at the standard positions
//! ([`sample_position`]) that lie inside it and pass the depth test there (depth per sample,
//! interpolated at the sample); the fragment is shaded once per pixel at the pixel's centre (as
//! a GPU shades a pixel some of whose samples a triangle covers) and, with alpha to coverage,
//! covers only the samples of its mask ([`coverage_mask`]). The resolve averages each pixel's
//! samples in linear light (the target is sRGB) and encodes the mean.

use glam::{Vec2, Vec4};

use crate::core::panoramas::projection::{Eye, Projection};
use crate::core::shading::color::{linear_to_srgb, srgb_to_linear};
use crate::core::shading::sampling::sample_position;
use crate::core::shading::texture::MaterialTable;
use crate::cpu::fragment::{
    background_color, coverage_mask, mask_alpha_width, shade_surface, shows_environment, surface_rgba,
};
use crate::cpu::raster::{clip_vertices, near_clipped, ClipVertex, FragmentIn, ScreenTriangle};
use crate::encoding::types::{DrawVertex, RasterParams};

/// One eye's colour and depth targets of `samples` samples per pixel, sample s of pixel i at
/// `samples · i + s`.
pub struct MultisampledImage {
    pub width: u32,
    pub height: u32,
    pub samples: u32,
    pub rgba: Vec<[u8; 4]>,
    pub depth: Vec<f32>,
}

/// A shaded fragment's display colour and the samples it covers, or None where it covers none.
pub type CoverageFn<'a> = dyn Fn(&FragmentIn) -> Option<([u8; 4], u32)> + 'a;

impl MultisampledImage {
    /// Cleared to the background (display values) and the far depth.
    pub fn new(width: u32, height: u32, samples: u32, background: [f32; 3]) -> MultisampledImage {
        let bg = background.map(|c| (c.clamp(0.0, 1.0) * 255.0 + 0.5).floor() as u8);
        let n = (width * height * samples) as usize;
        MultisampledImage { width, height, samples, rgba: vec![[bg[0], bg[1], bg[2], 255]; n], depth: vec![1.0; n] }
    }

    /// The environment's background, one colour per pixel in all its samples.
    pub fn fill_background(&mut self, table: &MaterialTable, projection: &Projection, eye: Eye) {
        let n = self.samples as usize;
        for y in 0..self.height {
            for x in 0..self.width {
                if !projection.shows_pixel(x as f32 + 0.5, y as f32 + 0.5) {
                    continue; // outside the fisheye's circle: the background colour
                }
                let c = background_color(table, projection, eye, Vec2::new(x as f32 + 0.5, y as f32 + 0.5));
                let i = (y * self.width + x) as usize;
                self.rgba[n * i..n * (i + 1)].fill(c);
            }
        }
    }

    /// Draws one triangle into the samples it covers within `scissor` [columns start, end,
    /// rows start, end).
    pub fn rasterize(&mut self, tri: [ClipVertex; 3], scissor: [u32; 4], fragment: &CoverageFn) {
        let n = self.samples;
        for clipped in near_clipped(tri) {
            let Some(t) = ScreenTriangle::new(clipped, self.width, self.height, scissor) else { continue };
            for y in t.rows.clone() {
                for x in t.columns.clone() {
                    let first = (n * (y as u32 * self.width + x as u32)) as usize;
                    // The samples the triangle covers and wins the depth test at, with their depth.
                    let mut passed = [None::<f32>; 32];
                    for (s, slot) in passed.iter_mut().enumerate().take(n as usize) {
                        let p = sample_position(n, s as u32);
                        let depth = t.covers(t.barycentric(x as f32 + p.x, y as f32 + p.y));
                        *slot = depth.filter(|&z| z < self.depth[first + s] && z >= 0.0);
                    }
                    if passed.iter().all(Option::is_none) {
                        continue;
                    }
                    let Some((rgba, mask)) = fragment(&t.fragment_input(x, y)) else { continue };
                    for (s, z) in passed.iter().enumerate().take(n as usize) {
                        if let (Some(z), true) = (z, mask >> s & 1 == 1) {
                            self.depth[first + s] = *z;
                            self.rgba[first + s] = rgba;
                        }
                    }
                }
            }
        }
    }

    /// The resolved image (RGBA8, sRGB): each pixel the mean of its samples in linear light.
    pub fn resolve(&self) -> Vec<u8> {
        let n = self.samples as usize;
        self.rgba
            .chunks_exact(n)
            .flat_map(|samples| {
                let mean = |c: usize, linear: bool| {
                    let sum: f32 = samples
                        .iter()
                        .map(|p| if linear { srgb_to_linear(p[c] as f32 / 255.0) } else { p[c] as f32 / 255.0 })
                        .sum();
                    let m = sum / n as f32;
                    ((if linear { linear_to_srgb(m) } else { m }) * 255.0 + 0.5).floor() as u8
                };
                [mean(0, true), mean(1, true), mean(2, true), mean(3, false)]
            })
            .collect()
    }
}

/// A fragment of the multisampled colour pass (`fs_coverage`; `fs_main` draws the same where no
/// material can discard, every sample covered): shaded at the pixel's centre, covering the
/// samples its alpha gives.
pub fn coverage_fragment(
    table: &MaterialTable,
    ambient: f32,
    projection: &Projection,
    eye: Eye,
    samples: u32,
    f: &FragmentIn,
) -> Option<([u8; 4], u32)> {
    if !projection.shows_pixel(f.surface.frag_xy.x, f.surface.frag_xy.y) {
        return None; // outside the fisheye's circle
    }
    let c = surface_rgba(table, &f.surface);
    let alpha = c.map_or(-1.0, |c| c.w);
    let width = mask_alpha_width(table, &f.surface, alpha);
    let mask = coverage_mask(table, f.surface.material, alpha, width, f.surface.frag_xy, samples);
    let c = c.filter(|_| mask != 0)?;
    let color = Vec4::new(c.x, c.y, c.z, c.w.max(0.0));
    let rgba =
        shade_surface(table, ambient, projection, eye, f.view_position, f.normal, color, &f.surface, f.dp_dx, f.dp_dy);
    Some((rgba, mask))
}

/// The raster stage's multisampled colour pass on the CPU, both eyes, resolved (RGBA8 per eye).
pub fn raster_multisampled(
    params: &[RasterParams; 2],
    vertices: &[DrawVertex],
    table: &MaterialTable,
    background: [f32; 3],
    samples: u32,
) -> [Vec<u8>; 2] {
    let projection = Projection::from(&params[0].projection);
    Eye::BOTH.map(|eye| {
        let eye_params = &params[eye as usize];
        let mut img = MultisampledImage::new(projection.width, projection.height, samples, background);
        if shows_environment(table) {
            img.fill_background(table, &projection, eye);
        }
        let fragment = |f: &FragmentIn| coverage_fragment(table, eye_params.ambient, &projection, eye, samples, f);
        for tri in vertices.chunks_exact(3) {
            img.rasterize(clip_vertices(eye_params, tri), [0, projection.width, 0, projection.height], &fragment);
        }
        img.resolve()
    })
}
