//! The `display` stage on the CPU (twin of `shaders/display.wgsl`): each target pixel's colour
//! from the frame's texels (sRGB bytes packed RGBA in words), the mode and the overlay, as the
//! fragment shader computes it.

use glam::{Vec2, Vec3};

use crate::core::panoramas::projection::{Eye, Projection};
use crate::encoding::types::DisplayParams;

const BACKGROUND: [f32; 4] = [0.05, 0.05, 0.06, 1.0];

fn unpack(word: u32) -> [f32; 4] {
    [0, 8, 16, 24].map(|s| ((word >> s) & 255) as f32 / 255.0)
}

fn linear_to_srgb(c: f32) -> f32 {
    if c <= 0.0031308 {
        c * 12.92
    } else {
        1.055 * c.powf(1.0 / 2.4) - 0.055
    }
}

fn srgb_to_linear(c: f32) -> f32 {
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

struct Source<'a> {
    params: &'a DisplayParams,
    projection: &'a Projection,
    texels: &'a [u32],
}

impl Source<'_> {
    fn texel(&self, k: u32, x: u32, y: u32) -> [f32; 4] {
        let p = self.params;
        unpack(self.texels[((k * p.height + y) * p.row_texels + x) as usize])
    }

    fn local(&self, xy: Vec2) -> Option<Vec2> {
        let a = self.params.area;
        let local = (xy - Vec2::new(a[0], a[1])) / Vec2::new(a[2], a[3]);
        (local.cmpge(Vec2::ZERO).all() && local.cmplt(Vec2::ONE).all()).then_some(local)
    }

    fn content_texel(&self, xy: Vec2) -> [f32; 4] {
        let p = self.params;
        let Some(local) = self.local(xy) else { return BACKGROUND };
        let (w, h) = (p.width, p.height * p.layers);
        let c = (local * Vec2::new(w as f32, h as f32)).floor();
        let (cx, cy) = ((c.x as u32).min(w - 1), (c.y as u32).min(h - 1));
        let x = if p.mode == 1 { (cx + w / 4) % w } else { cx };
        self.texel(cy / p.height, x, cy % p.height)
    }

    fn look_direction(&self, local: Vec2, aspect: f32) -> Vec3 {
        let [yaw, pitch, t, _] = self.params.look;
        let forward = Vec3::new(yaw.sin() * pitch.cos(), pitch.sin(), -yaw.cos() * pitch.cos());
        let right = Vec3::new(yaw.cos(), 0.0, yaw.sin());
        let up = right.cross(forward);
        let ndc = Vec2::new(2.0 * local.x - 1.0, 1.0 - 2.0 * local.y);
        (forward + ndc.x * t * right + ndc.y * t / aspect * up).normalize()
    }

    fn look_texel(&self, k: u32, d: Vec3) -> [f32; 4] {
        let p = self.params;
        let eye = if k == 1 { Eye::Right } else { Eye::Left };
        let Some(q) = self.projection.project(d * p.look[3], eye) else { return BACKGROUND };
        let [x, y] = self.projection.to_pixel(q.u, q.v).map(f32::floor);
        if x < 0.0 || y < 0.0 || x >= p.width as f32 || y >= p.height as f32 {
            return BACKGROUND;
        }
        self.texel(k, x as u32, y as u32)
    }

    fn look(&self, xy: Vec2) -> [f32; 4] {
        let a = self.params.area;
        let Some(local) = self.local(xy) else { return BACKGROUND };
        if self.params.mode == 2 {
            let k = (local.x >= 0.5) as u32;
            let half = Vec2::new((local.x * 2.0).fract(), local.y);
            return self.look_texel(k, self.look_direction(half, 0.5 * a[2] / a[3]));
        }
        let d = self.look_direction(local, a[2] / a[3]);
        let (left, right) = (self.look_texel(0, d), self.look_texel(1, d));
        [left[0], right[1], right[2], 1.0]
    }
}

/// The target's pixels (RGBA bytes packed in words, as an 8-bit target stores the fragment's
/// values: encoded again where it encodes sRGB) for a frame's `texels` (each layer `params.height` rows of
/// `params.row_texels`) and the overlay's texels.
pub fn display(
    params: &DisplayParams,
    projection: &Projection,
    texels: &[u32],
    overlay: &[u32],
    size: [u32; 2],
) -> Vec<u32> {
    let source = Source { params, projection, texels };
    let mut out = Vec::with_capacity((size[0] * size[1]) as usize);
    for y in 0..size[1] {
        for x in 0..size[0] {
            let xy = Vec2::new(x as f32 + 0.5, y as f32 + 0.5);
            let mut color = if params.mode >= 2 { source.look(xy) } else { source.content_texel(xy) };
            let o = params.overlay;
            let (ox, oy) = (xy.x - o[0], xy.y - o[1]);
            if o[2] > 0.0 && ox >= 0.0 && oy >= 0.0 && ox < o[2] && oy < o[3] {
                let c = unpack(overlay[(oy as u32 * o[2] as u32 + ox as u32) as usize]);
                for k in 0..3 {
                    color[k] += (c[k] - color[k]) * c[3];
                }
            }
            if params.srgb_target == 1 {
                // The fragment's linear values, stored encoded by the target.
                color = color.map(|c| linear_to_srgb(srgb_to_linear(c)));
                color[3] = 1.0;
            }
            let byte = |v: f32| ((v.clamp(0.0, 1.0) * 255.0).round() as u32) & 255;
            out.push(byte(color[0]) | byte(color[1]) << 8 | byte(color[2]) << 16 | 255 << 24);
        }
    }
    out
}
