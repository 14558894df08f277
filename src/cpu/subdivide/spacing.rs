//! How nodes are spaced along a segment (CPU twin of `shaders/shared/subdivide_spacing.wgsl`), and the clip w the raster stage draws with
//! (`clip_w` in `shaders/shared/projection.wgsl`, twin `cpu::raster::raster_vertex`).
//!
//! **Why azimuth.** A triangle is drawn between its projected nodes with its attributes (its
//! surface point among them, whose projection the error pass measures) interpolated across the
//! screen. Drawn linearly (w = 1), the point j/n of the way along a straight edge shows j/n of the
//! way between the edge's projected ends; but the projection turns a segment near the viewer
//! through its azimuth like atan: a segment seen from distance d at angle ψ from its nearest point
//! is drawn off along itself by about (W/2π)·tan ψ·δ²/4 pixels for a part spanning δ of azimuth
//! (a floor under the viewer, whose segments sweep up to a quarter turn around the axis, needed
//! ~20 parts per quarter turn at every distance for that alone). Under the error split the raster
//! stage draws instead with w = r, the point's distance from the vertical axis (perspective-correct
//! attributes, `clip_w`): between two nodes the drawn point is the one whose horizontal direction
//! is the linear blend of the nodes' directions, whose azimuth is linear on the screen to within
//! `AZIMUTH_CHORD_RESIDUAL`·δ³ radians (a chord of the unit circle against its arc), and whose
//! y/r is linear on the screen (v = R_T·y/r on the cylinder: exact). The nodes are then spaced by
//! equal steps of azimuth along each segment ([`Spacing::param`]), and the split rules sample
//! an edge at the same points, so an edge's second differences measure the error of that
//! drawing: the curvature of its image against azimuth, not the atan of its parameter. The
//! residual of the chord is bounded apart (`EdgeProfile::residual_px`).
//!
//! The paper's methods (`vertex`, `fixed:N`, eq. 5) keep equal parts and the linear drawing, and
//! so does the cubemap, whose faces draw as pinholes (w the distance along the ray: the drawn
//! point is the ray's own, however the nodes lie; spaced by azimuth, its demo room's p99 rose
//! from 0.44 to 0.84 px, when its faces drew with w = D·n).

use glam::{Vec2, Vec3};

use super::Node;
use crate::core::panoramas::projection::horizontal_radius;
use crate::encoding::constants::{AZIMUTH_MAX_TURN, AZIMUTH_MIN_RADIUS, AZIMUTH_MIN_TURN};
use crate::encoding::types::SubdivideParams;

/// The point with weights `w` of a triangle of nodes (position and barycentric weights alike).
pub(super) fn weighted(q: &[Node; 3], w: Vec3) -> Node {
    Node {
        position: w.x * q[0].position + w.y * q[1].position + w.z * q[2].position,
        bary: w.x * q[0].bary + w.y * q[1].bary + w.z * q[2].bary,
    }
}

/// How a frame spaces nodes along a segment and draws between them.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Spacing {
    /// Equal parts in 3-D, drawn linearly on the screen (the paper's methods).
    Even,
    /// Equal steps of azimuth about the viewer's axis, drawn with w = r (the error split).
    Azimuth,
}

impl Spacing {
    /// A frame's (`SubdivideParams::by_azimuth`: the error split, but on the cubemap).
    pub fn of(params: &SubdivideParams) -> Spacing {
        if params.by_azimuth != 0 {
            Spacing::Azimuth
        } else {
            Spacing::Even
        }
    }

    /// How segment lo–hi's points are spaced ([`Spacer`]).
    pub fn spacer(self, lo: Vec3, hi: Vec3) -> Spacer {
        if self == Spacing::Even {
            return Spacer { by_radius: false, rl: 0.0, rh: 0.0, turn: None };
        }
        let (rl, rh) = (horizontal_radius(lo), horizontal_radius(hi));
        if rl < AZIMUTH_MIN_RADIUS || rh < AZIMUTH_MIN_RADIUS {
            return Spacer { by_radius: false, rl, rh, turn: None };
        }
        let (el, eh) = (Vec2::new(lo.x, lo.z) / rl, Vec2::new(hi.x, hi.z) / rh);
        let turn = el.perp_dot(eh).abs().atan2(el.dot(eh));
        Spacer { by_radius: true, rl, rh, turn: (turn > AZIMUTH_MIN_TURN && turn < AZIMUTH_MAX_TURN).then_some(turn) }
    }

    /// The 3-D parameter of the point at fraction t of the way from lo to hi ([`Spacer::param`]).
    pub fn param(self, lo: Vec3, hi: Vec3, t: f32) -> f32 {
        self.spacer(lo, hi).param(t)
    }

    /// The node at fraction t of the way from a to b ([`Spacing::param`] of their positions in
    /// this order; position and barycentric weights alike).
    pub fn mix(self, a: Node, b: Node, t: f32) -> Node {
        let s = self.param(a.position, b.position, t);
        Node { position: a.position + (b.position - a.position) * s, bary: a.bary + (b.bary - a.bary) * s }
    }

    /// The interior lattice point (i, j, l)/m of a triangle of nodes (i + j + l = m, l < m):
    /// `Even`, the barycentric blend; `Azimuth`, the point j/(i + j) of the way along the row
    /// between the points l/m of the way from q0 and from q1 towards q2, each by [`Spacing::mix`]
    /// (rows parallel to q0–q1, spaced by azimuth along and across).
    pub fn interior(self, q: &[Node; 3], [i, j, l]: [u32; 3], m: u32) -> Node {
        if self == Spacing::Even {
            return weighted(q, Vec3::new(i as f32, j as f32, l as f32) / m as f32);
        }
        let up = l as f32 / m as f32;
        let (left, right) = (self.mix(q[0], q[2], up), self.mix(q[1], q[2], up));
        self.mix(left, right, j as f32 / (i + j) as f32)
    }
}

/// How a segment's points are spaced (`Spacer` in subdivide_edges.wgsl): `by_radius` under
/// azimuth spacing with both ends at least `AZIMUTH_MIN_RADIUS` from the axis (at `rl`, `rh`),
/// and the azimuth the segment sweeps where it is within (`AZIMUTH_MIN_TURN`,
/// `AZIMUTH_MAX_TURN`) (else None: equal parts of the linear blend of P/r, which the drawing
/// with w = r follows between the ends).
#[derive(Clone, Copy, Debug)]
pub struct Spacer {
    pub by_radius: bool,
    pub rl: f32,
    pub rh: f32,
    pub turn: Option<f32>,
}

impl Spacer {
    /// The 3-D parameter (0 at lo, 1 at hi) of the point at fraction t of the way from lo to hi:
    /// t itself unless `by_radius`; else the point of the segment at azimuth fraction t of its
    /// sweep D: the blend T = sin(tD) / (sin(tD) + sin((1 − t)D)) of the ends' horizontal
    /// directions points there, and the point of the segment whose P/r is that blend of the
    /// ends' lies (T/r_hi) / ((1 − T)/r_lo + T/r_hi) of the way (where the sweep is not
    /// measured, T = t).
    pub fn param(&self, t: f32) -> f32 {
        if !self.by_radius {
            return t;
        }
        let blend = match self.turn {
            Some(d) => {
                let a = precise_sin(t * d);
                a / (a + precise_sin((1.0 - t) * d))
            }
            None => t,
        };
        (blend / self.rh) / ((1.0 - blend) / self.rl + blend / self.rh)
    }
}

/// sin x for 0 ≤ x ≤ π, from the odd series on [0, π/2] (`precise_sin` in projection.wgsl,
/// whose drivers' built-in may be far less precise; truncation error below 6·10⁻⁸).
pub fn precise_sin(x: f32) -> f32 {
    let y = x.min(std::f32::consts::PI - x);
    let y2 = y * y;
    y * (1.0
        + y2 * (-1.0 / 6.0
            + y2 * (1.0 / 120.0 + y2 * (-1.0 / 5040.0 + y2 * (1.0 / 362_880.0 + y2 * (-1.0 / 39_916_800.0))))))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::core::panoramas::projection::azimuth;

    #[test]
    fn azimuth_spacing_takes_equal_steps_of_azimuth_along_the_segment() {
        // A floor segment 2 mm from the axis sweeping from −60° to +80° about it, and a wall
        // segment across the seam, both ways round.
        for (a, b) in [
            (Vec3::new(-0.002 * 3f32.sqrt(), -1.6, -0.002), Vec3::new(0.002 * 5.67, -1.6, -0.002)),
            (Vec3::new(-1.0, 0.3, 2.0), Vec3::new(1.5, -0.4, 1.0)),
        ] {
            for (lo, hi) in [(a, b), (b, a)] {
                let d = Spacing::Azimuth.spacer(lo, hi).turn.expect("a measured sweep");
                let sweep = (azimuth(hi) - azimuth(lo) + std::f32::consts::PI).rem_euclid(std::f32::consts::TAU)
                    - std::f32::consts::PI;
                assert!((sweep.abs() - d).abs() < 1e-4, "sweep {sweep} against {d}");
                for k in 0..=16 {
                    let t = k as f32 / 16.0;
                    let p = lo + (hi - lo) * Spacing::Azimuth.param(lo, hi, t);
                    let want = azimuth(lo) + t * sweep;
                    let got = azimuth(p);
                    let off =
                        (got - want + std::f32::consts::PI).rem_euclid(std::f32::consts::TAU) - std::f32::consts::PI;
                    assert!(off.abs() < 2e-5, "t = {t}: azimuth {got}, want {want}");
                }
            }
        }
        // Even spacing, a radial segment and one on the axis keep equal parts of t or of P/r.
        let (lo, hi) = (Vec3::new(0.0, -1.0, -1.0), Vec3::new(0.0, -1.0, -3.0));
        assert_eq!(Spacing::Even.param(lo, hi, 0.25), 0.25);
        let s = Spacing::Azimuth.param(lo, hi, 0.5);
        assert!((s - 0.25).abs() < 1e-6, "the blend of 1/r halfway lies a quarter of the way: {s}");
        assert_eq!(Spacing::Azimuth.param(Vec3::new(0.0, 1.0, 0.0), hi, 0.3), 0.3);
    }

    #[test]
    fn precise_sin_matches_the_library() {
        for k in 0..=1000 {
            let x = k as f32 * std::f32::consts::PI / 1000.0;
            assert!((precise_sin(x) - x.sin()).abs() < 2e-7, "sin {x}: {} against {}", precise_sin(x), x.sin());
        }
    }
}
