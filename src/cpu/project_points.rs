//! The `project_points` stage on the CPU (twin of `shaders/project_points.wgsl`): seed 002
//! eq. 1–4 applied to a list of viewer-frame points.

use glam::Vec3;

use crate::core::panoramas::projection::{Eye, Projection};

/// For each viewer-frame point, `[pixel x, pixel y, depth, 1]`, or all zeros where no eye sees it.
pub fn project_points(projection: &Projection, eye: Eye, points: &[Vec3]) -> Vec<[f32; 4]> {
    points
        .iter()
        .map(|&p| match projection.project(p, eye) {
            Some(q) => {
                let [x, y] = projection.to_pixel(q.u, q.v);
                [x, y, q.depth, 1.0]
            }
            None => [0.0; 4],
        })
        .collect()
}
