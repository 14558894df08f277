//! The `raster` stage, CPU twin of `shaders/raster.wgsl`: projects each prepared vertex for one
//! eye (seed 002 eq. 1–4, via [`crate::projection`]) and rasterizes the triangles with a depth
//! test and the same headlight shading. Clip w is 1, so attributes interpolate linearly on the
//! screen, as on the GPU. Pixel-centre sampling; coverage on exact edges may differ from the
//! GPU's tie-breaking rule, so tests compare images with a small tolerance on edge pixels.

use glam::{Vec3, Vec4};

use crate::gpu_types::{DrawVertex, RasterParams};
use crate::projection::{azimuth, horizontal_radius};

/// Clip-space position of a prepared vertex (`vs_main` in raster.wgsl).
pub fn raster_vertex(params: &RasterParams, v: &DrawVertex) -> Vec4 {
    let p = Vec3::from(v.position);
    let pr = &params.projection;
    let theta0 = azimuth(p);
    let theta = theta0 + std::f32::consts::TAU * ((v.theta_ref - theta0) / std::f32::consts::TAU + 0.5).floor();
    let r = horizontal_radius(p);
    let alpha = (pr.eye_radius / r).clamp(0.0, 1.0).acos() - pr.acos_eye_screen;
    let u = theta + params.eye_sign * alpha;
    let v_screen = if pr.vertical_exact != 0 {
        let de = pr.eye_radius;
        p.y * (pr.screen_radius * pr.screen_radius - de * de).sqrt() / (r * r - de * de).max(1e-12).sqrt()
    } else {
        pr.screen_radius * p.y / r
    };
    Vec4::new(u / std::f32::consts::PI, v_screen * pr.pixels_per_metre / (0.5 * pr.height), r / (r + 1.0), 1.0)
}

/// Shading of `fs_main`: colour × (ambient + (1 − ambient)·|n·l|), light from the viewer.
pub fn shade(params: &RasterParams, view_position: Vec3, normal: Vec3, color: Vec4) -> [u8; 4] {
    let lambert = if normal.length() > 1e-6 { normal.normalize().dot(-view_position.normalize()).abs() } else { 1.0 };
    let s = params.ambient + (1.0 - params.ambient) * lambert;
    let q = |x: f32| ((x * s).clamp(0.0, 1.0) * 255.0 + 0.5).floor() as u8;
    [q(color.x), q(color.y), q(color.z), 255]
}

pub struct RasterImage {
    pub width: u32,
    pub height: u32,
    pub rgba: Vec<u8>,
    pub depth: Vec<f32>,
}

/// The raster stage on the CPU for one eye.
pub fn raster(params: &RasterParams, vertices: &[DrawVertex], background: [f32; 3]) -> RasterImage {
    let (w, h) = (params.projection.width as u32, params.projection.height as u32);
    let bg = background.map(|c| (c.clamp(0.0, 1.0) * 255.0 + 0.5).floor() as u8);
    let mut img = RasterImage {
        width: w,
        height: h,
        rgba: (0..w * h).flat_map(|_| [bg[0], bg[1], bg[2], 255]).collect(),
        depth: vec![1.0; (w * h) as usize],
    };
    for tri in vertices.chunks_exact(3) {
        let clip: Vec<Vec4> = tri.iter().map(|v| raster_vertex(params, v)).collect();
        if clip.iter().any(|c| !c.is_finite()) {
            continue;
        }
        let s: Vec<[f32; 2]> =
            clip.iter().map(|c| [(c.x + 1.0) * 0.5 * w as f32, (1.0 - c.y) * 0.5 * h as f32]).collect();
        let area = (s[1][0] - s[0][0]) * (s[2][1] - s[0][1]) - (s[2][0] - s[0][0]) * (s[1][1] - s[0][1]);
        if area == 0.0 {
            continue;
        }
        let min_x = s.iter().map(|p| p[0]).fold(f32::MAX, f32::min).floor().max(0.0) as i64;
        let max_x = s.iter().map(|p| p[0]).fold(f32::MIN, f32::max).ceil().min(w as f32) as i64;
        let min_y = s.iter().map(|p| p[1]).fold(f32::MAX, f32::min).floor().max(0.0) as i64;
        let max_y = s.iter().map(|p| p[1]).fold(f32::MIN, f32::max).ceil().min(h as f32) as i64;
        for y in min_y..max_y {
            for x in min_x..max_x {
                let (px, py) = (x as f32 + 0.5, y as f32 + 0.5);
                let edge = |a: [f32; 2], b: [f32; 2]| (b[0] - a[0]) * (py - a[1]) - (b[1] - a[1]) * (px - a[0]);
                let b0 = edge(s[1], s[2]) / area;
                let b1 = edge(s[2], s[0]) / area;
                let b2 = edge(s[0], s[1]) / area;
                if b0 < 0.0 || b1 < 0.0 || b2 < 0.0 {
                    continue;
                }
                let z = b0 * clip[0].z + b1 * clip[1].z + b2 * clip[2].z;
                let i = (y as u32 * w + x as u32) as usize;
                if !(z < img.depth[i]) {
                    continue;
                }
                let mix3 = |f: &dyn Fn(&DrawVertex) -> Vec3| b0 * f(&tri[0]) + b1 * f(&tri[1]) + b2 * f(&tri[2]);
                let pos = mix3(&|v| Vec3::from(v.position));
                let nrm = mix3(&|v| Vec3::from(v.normal));
                let col = b0 * Vec4::from(tri[0].color) + b1 * Vec4::from(tri[1].color) + b2 * Vec4::from(tri[2].color);
                img.depth[i] = z;
                img.rgba[4 * i..4 * i + 4].copy_from_slice(&shade(params, pos, nrm, col));
            }
        }
    }
    img
}
