//! A piece's seam copies: the bounds on its u range (both eyes) that tell, from its corners alone,
//! where it may reach ±π (`footprint`, `piece_u_range`, `sphere_u_bound`, `clear_of_seam` in
//! shaders/shared/subdivide_lattice.wgsl). On the cylinder the bound decides; on the sphere a
//! piece the bound keeps clear of the seam needs no copy, and any other has its nodes projected.

use glam::Vec2;
use std::f32::consts::PI;

use super::work::NO_REACH;
use super::{Node, Subdivider};
use crate::core::panoramas::projection::{azimuth, wrap_angle};
use crate::encoding::constants::{SEAM_BOUND_SLACK, SEAM_MARGIN};

impl Subdivider<'_> {
    /// The u range (both eyes, unwrapped towards `theta_c`) of a piece's triangle on the
    /// cylinder, from its corners alone: the triangle's footprint is convex and misses the axis,
    /// so its azimuths span those of its corners, and α(r) (eq. 3) grows with r, so |α| is
    /// largest at the footprint's nearest or farthest point from the axis (the nearest: a corner
    /// or the foot of the perpendicular on an edge). It holds every node of the piece, so seam
    /// copies are made where the nodes need them (and, rarely, one more, which the rasterizer
    /// clips). Also its reach: the largest |u − θ| it allows (the largest |α|; `NO_REACH` with a
    /// tracked head, whose u is not θ ± α). `piece_u_range` in the WGSL.
    pub(super) fn piece_u_range(&self, q: &[Node; 3], theta_c: f32) -> ((f32, f32), f32) {
        let Footprint { theta_min, theta_max, r_min, r_max } = Footprint::of(q, theta_c);
        let proj = &self.projection;
        if let Some(head) = &proj.head {
            // A tracked head: u = θ − γ, moved by the eye's offset seen from the point and by
            // the eye's distance from the display's axis seen from the screen (`core::panoramas::head`).
            let reach = Vec2::new(head.offset[0], head.offset[2]).length() + proj.eye_radius;
            let bound =
                (proj.eye_radius / r_min.max(1e-30)).min(1.0).asin() + (reach / proj.screen_radius).min(1.0).asin();
            return ((theta_min - head.turn - bound, theta_max - head.turn + bound), NO_REACH);
        }
        let alpha = proj.eye_shift(r_min).abs().max(proj.eye_shift(r_max).abs());
        ((theta_min - alpha, theta_max + alpha), alpha)
    }

    /// A bound on the u range (both eyes) of the nodes of a piece's triangle on the sphere, from
    /// its corners (`sphere_u_bound` in the WGSL): u = θ − s·asin(e/r) with |e/r| clamped to 1,
    /// and with parallel rays |e| ≤ d_e, so u lies within asin(min(d_e / r_min, 1)) (π/2 for
    /// converging rays) of the footprint's azimuths.
    /// Also the bound's reach beyond the azimuths: the largest |u − θ| it allows.
    pub(super) fn sphere_u_bound(&self, q: &[Node; 3], theta_c: f32) -> ((f32, f32), f32) {
        let f = Footprint::of(q, theta_c);
        let proj = &self.projection;
        let reach =
            if proj.convergence.is_some() { PI / 2.0 } else { (proj.eye_radius / f.r_min.max(1e-30)).min(1.0).asin() };
        ((f.theta_min - reach, f.theta_max + reach), reach)
    }
}

/// The footprint of a piece's triangle (`footprint` in the WGSL): its corners' azimuths unwrapped
/// towards `theta_c` (the footprint is convex and misses the axis, so they span its points'), its
/// nearest and farthest distance from the axis (the nearest: a corner or the foot of the
/// perpendicular on an edge).
struct Footprint {
    theta_min: f32,
    theta_max: f32,
    r_min: f32,
    r_max: f32,
}

impl Footprint {
    fn of(q: &[Node; 3], theta_c: f32) -> Footprint {
        let mut f =
            Footprint { theta_min: f32::INFINITY, theta_max: f32::NEG_INFINITY, r_min: f32::INFINITY, r_max: 0.0 };
        for e in 0..3 {
            let a = Vec2::new(q[e].position.x, q[e].position.z);
            let b = Vec2::new(q[(e + 1) % 3].position.x, q[(e + 1) % 3].position.z);
            let theta = theta_c + wrap_angle(azimuth(q[e].position) - theta_c);
            f.theta_min = f.theta_min.min(theta);
            f.theta_max = f.theta_max.max(theta);
            f.r_max = f.r_max.max(a.length());
            let ab = b - a;
            let t = (-a.dot(ab) / ab.dot(ab).max(1e-30)).clamp(0.0, 1.0);
            f.r_min = f.r_min.min((a + t * ab).length());
        }
        f
    }
}

/// Whether a bound on a piece's u range keeps it clear of the seam by `SEAM_BOUND_SLACK` beyond
/// `SEAM_MARGIN` (`clear_of_seam` in the WGSL): then its nodes' own range needs no copy either.
pub(super) fn clear_of_seam((u_min, u_max): (f32, f32)) -> bool {
    let margin = SEAM_MARGIN + SEAM_BOUND_SLACK;
    u_max <= PI - margin && u_min >= -PI + margin
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::core::panoramas::projection::{Eye, Projection};
    use crate::core::settings::{Method, Split, DEFAULT_EDGE_PX, DEFAULT_MAX_DIV};
    use crate::cpu::subdivide::tests::params_for;
    use glam::Vec3;
    use rand::{Rng, SeedableRng};

    /// Random triangles near and far, around and across the seam, close to the axis and to the
    /// eye circle: every point of each (its corners and 64 random points inside, as a lattice's
    /// nodes lie) is projected by the sphere's own map, both eyes, and lies within the bound
    /// from its corners; and a triangle the bound calls clear of the seam has no point within
    /// `SEAM_MARGIN` of it. Parallel and converging rays, with and without pole merge.
    #[test]
    fn the_spheres_bound_from_the_corners_holds_every_point_of_a_piece() {
        let mut rng = rand::rngs::StdRng::seed_from_u64(32);
        let mut clear = 0;
        for convergence in [None, Some(2.0)] {
            for pole_merge in [Some((60.0, 75.0)), None] {
                let projection = Projection { convergence, pole_merge, ..Projection::equirect(512) };
                let params =
                    params_for(&projection, Method::Adaptive(Split::Error), DEFAULT_EDGE_PX, DEFAULT_MAX_DIV, 1);
                let sub = Subdivider::new(&params);
                for _ in 0..400 {
                    let scale = 10f32.powf(rng.random_range(-1.5..1.5));
                    let centre = Vec3::new(
                        rng.random_range(-1.0..1.0),
                        rng.random_range(-1.0..1.0),
                        rng.random_range(-1.0..1.0),
                    );
                    let q = [0; 3].map(|_| {
                        let p = (centre
                            + Vec3::new(
                                rng.random_range(-0.5..0.5),
                                rng.random_range(-0.5..0.5),
                                rng.random_range(-0.5..0.5),
                            ))
                            * scale;
                        Node { position: p, bary: Vec3::ZERO }
                    });
                    let c = (q[0].position + q[1].position + q[2].position) / 3.0;
                    // Pieces never hold the axis (it is cut out around them).
                    let contains_axis = {
                        let s = |a: Vec3, b: Vec3| (b.x - a.x) * (-a.z) - (b.z - a.z) * (-a.x);
                        let d = [
                            s(q[0].position, q[1].position),
                            s(q[1].position, q[2].position),
                            s(q[2].position, q[0].position),
                        ];
                        d.iter().all(|&v| v >= 0.0) || d.iter().all(|&v| v <= 0.0)
                    };
                    if contains_axis {
                        continue;
                    }
                    let theta_c = azimuth(c);
                    let ((lo, hi), _) = sub.sphere_u_bound(&q, theta_c);
                    let is_clear = clear_of_seam((lo, hi));
                    clear += is_clear as u32;
                    for k in 0..67 {
                        let w = match k {
                            0..=2 => Vec3::from([0, 1, 2].map(|i| (i == k) as u32 as f32)),
                            _ => {
                                let (a, b): (f32, f32) = (rng.random(), rng.random());
                                let (a, b) = if a + b > 1.0 { (1.0 - a, 1.0 - b) } else { (a, b) };
                                Vec3::new(1.0 - a - b, a, b)
                            }
                        };
                        let p = w.x * q[0].position + w.y * q[1].position + w.z * q[2].position;
                        let theta = theta_c + wrap_angle(azimuth(p) - theta_c);
                        for eye in Eye::BOTH {
                            let u = sub.projection.project_with_azimuth(p, theta, eye).u;
                            assert!(
                                u >= lo - 1e-5 && u <= hi + 1e-5,
                                "{projection:?} {q:?}: u {u} outside [{lo}, {hi}]"
                            );
                            if is_clear {
                                assert!(u.abs() < PI - SEAM_MARGIN, "{q:?}: u {u} called clear of the seam");
                            }
                        }
                    }
                }
            }
        }
        assert!(clear > 400, "too few triangles clear of the seam to test ({clear})");
    }
}
