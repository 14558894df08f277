//! CPU twin of `shaders/shared/subdivide_quad.wgsl`.
//!
//! Band quads drawn as one strip between their rails (see the module doc of `cpu::subdivide`):
//! which band polygons qualify (`plan_quad` in the WGSL) and their `lattice`. The quad's nodes
//! and triangles are in `lattice.rs` ([`quad_strip_triangles`]).

use glam::Vec3;

use super::lattice::{quad_strip_node, quad_strip_node_count, quad_strip_rungs, quad_strip_slots};
use super::{Node, PiecePlan, Subdivider, Triangle};
use crate::core::projection::azimuth;
use crate::core::settings::SplitRule;
use crate::encoding::constants::{PIECE_DIVISIONS, QUAD_MIN_DIVISIONS, QUAD_RUNG_ERROR, SEAM_BOUND_SLACK};

impl Subdivider<'_> {
    /// Whether a band's polygon is drawn as one strip between two of its sides (the rails)
    /// rather than as the two parts of its fan: under the error split, on the cylinder, a polygon
    /// of four corners, both fan parts on screen, two opposite sides in one part each, rails in
    /// at most N_max (as a part needing no pre-split), the longer in at least
    /// `QUAD_MIN_DIVISIONS`, and every rung of the zigzag (the sides of its triangles that cross
    /// between the rails, both one-part sides among them) within `QUAD_RUNG_ERROR`·τ of straight
    /// by the quick profile, away from the eye circle, as every other edge drawn (a rung is an
    /// edge drawn: checking fewer lets the long slanted rungs of narrow bands up a wall exceed τ).
    /// The corners come back turned so that the rails run 0 → 1 and 3 → 2 (`plan_quad` in
    /// the WGSL).
    pub(super) fn quad_strip(&self, tri: &Triangle, poly: &[Node]) -> Option<([Node; 4], [u32; 2])> {
        if self.params.method != SplitRule::AdaptiveError as u32
            || self.projection.panorama.is_sphere()
            || poly.len() != 4
        {
            return None;
        }
        let p: Vec<Vec3> = poly.iter().map(|n| n.position).collect();
        if self.off_screen_vertically([p[0], p[1], p[2]]) || self.off_screen_vertically([p[0], p[2], p[3]]) {
            return None;
        }
        let limits = self.limits(tri.object);
        let n: Vec<u32> = (0..4).map(|e| self.edge_divisions(p[e], p[(e + 1) % 4], limits)).collect();
        let turn = (0..2).find(|&r| n[r + 1] == 1 && n[(r + 3) % 4] == 1)?;
        let corners = [0, 1, 2, 3].map(|i| poly[(turn + i) % 4]);
        let rails = [n[turn], n[turn + 2]];
        let longest = rails[0].max(rails[1]);
        if longest < QUAD_MIN_DIVISIONS || longest > self.params.max_div.min(PIECE_DIVISIONS) {
            return None;
        }
        let straight = |[a, b]: [u32; 2]| {
            let q = self.edge_profile(
                quad_strip_node(&corners, rails, a, self.spacing()).position,
                quad_strip_node(&corners, rails, b, self.spacing()).position,
                2,
            );
            q.straight(QUAD_RUNG_ERROR, limits.max_error_px)
        };
        quad_strip_rungs(rails).all(straight).then_some((corners, rails))
    }

    /// `lattice` for a band's quad drawn as a strip between its rails ([`quad_strip_triangles`]):
    /// its plan.
    pub(super) fn quad_lattice(&self, tri: &Triangle, corners: &[Node; 4], rails: [u32; 2]) -> Option<PiecePlan> {
        let nodes: Vec<Node> =
            (0..quad_strip_node_count(rails)).map(|k| quad_strip_node(corners, rails, k, self.spacing())).collect();
        let c = corners.map(|n| n.position);
        let theta_c = azimuth((c[0] + c[1] + c[2] + c[3]) / 4.0);
        // The quad's u range: that of its fan's two triangles, which cover it.
        let (a, b) = ([corners[0], corners[1], corners[2]], [corners[0], corners[2], corners[3]]);
        let ((ra, reach_a), (rb, reach_b)) = (self.piece_u_range(&a, theta_c), self.piece_u_range(&b, theta_c));
        let reach = reach_a.max(reach_b) + SEAM_BOUND_SLACK;
        let candidates = quad_strip_slots(rails);
        (!candidates.is_empty())
            .then(|| self.piece_plan(tri, &nodes, candidates, theta_c, (ra.0.min(rb.0), ra.1.max(rb.1)), reach))
    }
}
