//! CPU twin of `shaders/fragment.wgsl`, the fragment work shared by the drawing stages:
//! headlight shading and the display-position error (seed 002 §4.1): the distance in pixels
//! between the pixel centre where a surface point was drawn and where the projection puts it.

use glam::{Vec2, Vec3, Vec4};

use crate::projection::{Eye, Projection};

/// Colour × (ambient + (1 − ambient)·|n·l|), the light at the viewer, two-sided; as RGBA8.
pub fn shade(ambient: f32, view_position: Vec3, normal: Vec3, color: Vec4) -> [u8; 4] {
    let lambert = if normal.length() > 1e-6 { normal.normalize().dot(-view_position.normalize()).abs() } else { 1.0 };
    let s = ambient + (1.0 - ambient) * lambert;
    let q = |x: f32| ((x * s).clamp(0.0, 1.0) * 255.0 + 0.5).floor() as u8;
    [q(color.x), q(color.y), q(color.z), 255]
}

/// The display-position error of surface point `p` drawn at pixel centre `frag_xy`; −1 where
/// no eye sees the point. The horizontal distance wraps around the panorama.
pub fn pixel_error(projection: &Projection, eye: Eye, p: Vec3, frag_xy: Vec2) -> f32 {
    match projection.project(p, eye) {
        None => -1.0,
        Some(q) => {
            let [x, y] = projection.to_pixel(q.u, q.v);
            Vec2::new(projection.wrapped_dx(x, frag_xy.x), y - frag_xy.y).length()
        }
    }
}
