//! The pixel geometry, CPU twin of `shaders/shared/pixel_error.wgsl`: the display-position error
//! of seed 002 §4.1 (the distance in pixels, or the angle, between where a surface point was drawn
//! and where the projection puts it), a pixel's spread and the distance along its ray.

use glam::{Vec2, Vec3};

use crate::core::panoramas::panorama::ImageMap;
use crate::core::panoramas::projection::{pixel_ray, Eye, Projection};

/// The angle a pixel spans, radians (`pixel_spread` in surface.wgsl): the larger of its width
/// (2π/turn_px, on the sphere × cos latitude) and its height (on the cylinder 1/(pixels_per_v·R_T),
/// seen from the eyes about R_T away; on the sphere 1/pixels_per_v). A ray cone grows by this
/// much per metre.
pub fn pixel_spread(projection: &Projection, frag_xy: Vec2) -> f32 {
    match projection.model().image_map() {
        // The fisheye's k pixels per radian; the cubemap's a face's centre, where its pixels
        // span the most.
        ImageMap::Fisheye | ImageMap::Cubemap => 1.0 / projection.pixels_per_v(),
        ImageMap::Plane => {
            // A pixel's width at the wall's nearest point, seen from the head.
            let [corner, right, up] = projection.cave_wall();
            right.length() / projection.width as f32 / corner.dot(right.cross(up).normalize()).abs()
        }
        ImageMap::Linear => {
            let (_, v) = projection.pixel_to_screen(frag_xy.x - 0.5, frag_xy.y - 0.5);
            let across = std::f32::consts::TAU / projection.turn_px();
            if projection.panorama.is_sphere() {
                (across * v.cos()).max(1.0 / projection.pixels_per_v())
            } else {
                across.max(1.0 / (projection.pixels_per_v() * projection.screen_radius))
            }
        }
    }
}

/// The display-position error of surface point `p` drawn at pixel centre `frag_xy`: the
/// distance in pixels to where the projection puts it (wrapping around the panorama), or with
/// `angle` the angle between the two directions seen from the centre, in arcminutes; −1 where
/// no eye sees the point.
pub fn pixel_error(projection: &Projection, eye: Eye, p: Vec3, frag_xy: Vec2, angle: bool) -> f32 {
    match projection.project(p, eye) {
        None => -1.0,
        Some(q) if angle => {
            let a = projection.screen_direction(q.u, q.v);
            let (u, v) = projection.pixel_to_screen(frag_xy.x - 0.5, frag_xy.y - 0.5);
            let b = projection.screen_direction(u, v);
            a.cross(b).length().atan2(a.dot(b)).to_degrees() * 60.0
        }
        Some(q) if projection.model().image_map() == ImageMap::Cubemap => {
            // On the pixel's own face (a point drawn across a face's edge belongs beyond it there).
            let face = projection.cube_face_at(frag_xy.x, frag_xy.y);
            match projection.cube_pixel_on_face(crate::core::panoramas::cubemap::direction(q.u, q.v), face) {
                Some([x, y]) => Vec2::new(x - frag_xy.x, y - frag_xy.y).length(),
                None => 1e9,
            }
        }
        Some(q) => {
            let [x, y] = projection.to_pixel(q.u, q.v);
            Vec2::new(projection.wrapped_dx(x, frag_xy.x), y - frag_xy.y).length()
        }
    }
}

/// What `--depth` writes: the distance in metres along the ray of the pixel at `frag_xy` to the
/// plane through surface point `p` with normal `n` (the drawn triangle's plane: exact for flat
/// input triangles, however coarse the subdivision), or |p − eye point| where the ray runs
/// nearly within the plane.
pub fn pixel_distance(projection: &Projection, eye: Eye, p: Vec3, n: Vec3, frag_xy: Vec2) -> f32 {
    let (origin, dir) = pixel_ray(projection, eye, frag_xy);
    let denom = dir.dot(n);
    if denom.abs() > 1e-3 * n.length() {
        let t = (p - origin).dot(n) / denom;
        if t > 0.0 {
            return t;
        }
    }
    (p - origin).length()
}
