//! The vertical axis (see the module doc of `cpu::subdivide`): sub-triangles that contain or
//! near the axis, or span too much azimuth, are cut into the 8 sectors of 45° around it and by a
//! chord just outside the eye circle. The exact sector tables are shared with the WGSL.

use glam::{Vec2, Vec3};

use super::{lex_less, Node};
use crate::core::projection::{azimuth, wrap_angle, Projection};
use crate::shader::constants::{MAX_SPAN, SNAP};

/// Number of sectors an axis triangle is split into.
pub const SECTORS: usize = 8;

const H: f32 = std::f32::consts::FRAC_1_SQRT_2;
const C8: f32 = 0.923_879_5; // cos(π/8)
const S8: f32 = 0.382_683_43; // sin(π/8)
/// (cos, sin) of the sector boundaries −π + k·π/4, an exact table shared with the WGSL.
const BOUNDARY: [(f32, f32); 9] =
    [(-1.0, 0.0), (-H, -H), (0.0, -1.0), (H, -H), (1.0, 0.0), (H, H), (0.0, 1.0), (-H, H), (-1.0, 0.0)];
/// (cos, sin) of the sector middles −π + k·π/4 + π/8.
const MIDDLE: [(f32, f32); 8] =
    [(-C8, -S8), (-S8, -C8), (S8, -C8), (C8, -S8), (C8, S8), (S8, C8), (-S8, C8), (-C8, S8)];

/// The clearance kept around the vertical axis: just outside the eye circle (and never zero,
/// so that a mono camera with d_e = 0 still avoids the singular axis).
pub fn axis_clearance(projection: &Projection) -> f32 {
    projection.eye_radius.max(1e-3 * projection.screen_radius) * (1.0 + 1e-3)
}

/// A triangle that comes nearer the axis than this is split into sectors.
pub fn split_radius(axis_clearance: f32) -> f32 {
    axis_clearance / C8
}

/// Half-plane `a·x + b·z ≥ c` in the viewer frame's xz plane.
#[derive(Clone, Copy)]
pub(super) struct HalfPlane {
    a: f32,
    b: f32,
    c: f32,
}

impl HalfPlane {
    fn distance(&self, p: Vec3) -> f32 {
        let d = self.a * p.x + self.b * p.z - self.c;
        let scale = (self.a * p.x).abs() + (self.b * p.z).abs() + self.c.abs();
        if d.abs() <= SNAP * scale {
            0.0
        } else {
            d
        }
    }
}

/// Sutherland–Hodgman clip of a convex polygon against one half-plane. Crossing points are
/// computed from the canonically ordered edge, so neighbours get the same point; a vertex that
/// repeats the previous one (a corner on the clip line) is dropped.
pub(super) fn clip_polygon(poly: &[Node], plane: HalfPlane) -> Vec<Node> {
    let mut out: Vec<Node> = Vec::with_capacity(poly.len() + 1);
    let push = |n: Node, out: &mut Vec<Node>| {
        if out.last().is_none_or(|l| l.position != n.position) {
            out.push(n);
        }
    };
    for i in 0..poly.len() {
        let cur = poly[i];
        let next = poly[(i + 1) % poly.len()];
        let d0 = plane.distance(cur.position);
        let d1 = plane.distance(next.position);
        if d0 >= 0.0 {
            push(cur, &mut out);
        }
        if (d0 >= 0.0) != (d1 >= 0.0) {
            let (lo, hi, dl, dh) =
                if lex_less(next.position, cur.position) { (next, cur, d1, d0) } else { (cur, next, d0, d1) };
            let t = dl / (dl - dh);
            push(
                Node {
                    position: lo.position + (hi.position - lo.position) * t,
                    bary: lo.bary + (hi.bary - lo.bary) * t,
                },
                &mut out,
            );
        }
    }
    if out.len() > 1 && out[out.len() - 1].position == out[0].position {
        out.pop();
    }
    out
}

/// The three half-planes of sector s: θ ≥ boundary s, θ ≤ boundary s+1, beyond the chord.
pub(super) fn sector_planes(s: usize, clearance: f32) -> [HalfPlane; 3] {
    // With P = (X, Y) = (−z, x), θ is P's polar angle. cross(d0, P) ≥ 0 ⇔ θ ≥ φ0;
    // cross(P, d1) ≥ 0 ⇔ θ ≤ φ1; dot(P, d_mid) ≥ clearance is the chord.
    let (c0, s0) = BOUNDARY[s];
    let (c1, s1) = BOUNDARY[s + 1];
    let (cm, sm) = MIDDLE[s];
    [
        HalfPlane { a: c0, b: s0, c: 0.0 },
        HalfPlane { a: -c1, b: -s1, c: 0.0 },
        HalfPlane { a: sm, b: -cm, c: clearance },
    ]
}

fn segment_distance(a: Vec2, b: Vec2) -> f32 {
    let ab = b - a;
    let len2 = ab.dot(ab);
    let t = if len2 > 0.0 { (-a.dot(ab) / len2).clamp(0.0, 1.0) } else { 0.0 };
    (a + ab * t).length()
}

pub(super) fn cross2(a: Vec2, b: Vec2) -> f32 {
    a.x * b.y - a.y * b.x
}

/// Whether a triangle must be split into sectors (see the module doc).
pub fn needs_axis_split(p: [Vec3; 3], split_radius: f32) -> bool {
    let q = p.map(|v| Vec2::new(v.x, v.z));
    let e0 = cross2(q[1] - q[0], -q[0]);
    let e1 = cross2(q[2] - q[1], -q[1]);
    let e2 = cross2(q[0] - q[2], -q[2]);
    let contains = (e0 >= 0.0 && e1 >= 0.0 && e2 >= 0.0) || (e0 <= 0.0 && e1 <= 0.0 && e2 <= 0.0);
    let near =
        segment_distance(q[0], q[1]).min(segment_distance(q[1], q[2])).min(segment_distance(q[2], q[0])) < split_radius;
    let t = p.map(azimuth);
    let span = wrap_angle(t[0] - t[1]).abs().max(wrap_angle(t[1] - t[2]).abs()).max(wrap_angle(t[2] - t[0]).abs());
    contains || near || span > MAX_SPAN
}
