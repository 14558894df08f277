//! Nodes drawn off their projections (CPU twin of `piece_offsets` and `node_offset` in
//! shaders/shared/subdivide_rows.wgsl; docs/method.md, *Nodes drawn off their projections*).
//!
//! A drawn triangle's error rises from 0 at its nodes (which lie on the projection) to about τ
//! between them. Each node is drawn half that bowl towards the curve, so that the error swings
//! both ways and the split can take larger parts for the same largest error:
//! - a node inside an edge of its piece takes half that edge's part error as its profile
//!   estimates it: −b·(S/n)²/8 for n parts, b the largest second difference (a vector, per eye)
//!   of the edge's image at S = 8 equal steps of azimuth. The edge is the part's original edge
//!   (an input edge's sub-segment or a cut line) where the piece's edge lies on one, else the
//!   piece's own edge (a macro line), both profiled from their canonically ordered ends: every
//!   piece with the node computes the same bits;
//! - a corner of the piece none;
//! - a node inside the piece half the largest error its piece's boundary segments measure (the
//!   drawing's point at each segment's screen midpoint against its projection).

use std::collections::HashMap;

use glam::{Vec2, Vec3};

use super::piece::PieceGeometry;
use super::{Node, Subdivider};
use crate::core::panoramas::projection::horizontal_radius;
use crate::encoding::constants::{AZIMUTH_MIN_RADIUS, EDGE_SAMPLES};

/// Keeps the longer of two error vectors.
fn widen(slot: &mut Vec2, e: Vec2) {
    if e.length() > slot.length() {
        *slot = e;
    }
}

impl Subdivider<'_> {
    /// Whether the frame draws nodes off their projections (`SubdivideParams::node_offsets`).
    pub(super) fn draws_offsets(&self) -> bool {
        self.params.node_offsets != 0
    }

    /// The x difference b − a in pixels, across the seam the short way.
    fn unwrapped(&self, a: Vec2, b: Vec2) -> Vec2 {
        let width = self.projection.turn_px();
        let dx = b.x - a.x;
        Vec2::new(dx - width * (dx / width).round(), b.y - a.y)
    }

    /// Both eyes' error of the drawing (w = r) at the screen midpoint of segment a–b (y up).
    fn midpoint_errors(&self, a: Vec3, b: Vec3) -> [Vec2; 2] {
        let (wa, wb) = (horizontal_radius(a).max(AZIMUTH_MIN_RADIUS), horizontal_radius(b).max(AZIMUTH_MIN_RADIUS));
        let mid = (a / wa + b / wb) / (1.0 / wa + 1.0 / wb);
        [-1.0f32, 1.0].map(|eye_sign| {
            let (pa, pb, pm) = (self.pixel(a, eye_sign), self.pixel(b, eye_sign), self.pixel(mid, eye_sign));
            self.unwrapped(pa, pm) - 0.5 * self.unwrapped(pa, pb)
        })
    }

    /// Half the part error of line lo–hi drawn in `parts` parts, per eye (y up), from its profile.
    fn line_offsets(&self, lo: Vec3, hi: Vec3, parts: u32) -> [Vec2; 2] {
        let step = EDGE_SAMPLES as f32 / parts as f32;
        self.edge_profile(lo, hi, EDGE_SAMPLES).bend_vec.map(|b| -0.5 * b * (step * step) / 8.0)
    }

    /// Each node's offsets [left x, y, right x, y] (image pixels, y down) for a shaped piece's
    /// nodes in slot order.
    pub(super) fn node_offsets(&self, g: &PieceGeometry, nodes: &[Node]) -> Vec<[f32; 4]> {
        let mut out = vec![[0.0; 4]; nodes.len()];
        if !self.draws_offsets() {
            return out;
        }
        let key = |p: Vec3| p.to_array().map(f32::to_bits);
        // A corner inside an original edge of the part takes that edge's offset (a piece beside
        // it may have the node inside its edge); the part's corners and corners inside the part
        // none.
        let corners = g.q.map(|c| key(c.position));
        let corner_offsets: [[Vec2; 2]; 3] = std::array::from_fn(|c| {
            g.corner_line(c).map_or([Vec2::ZERO; 2], |(lo, hi, parts)| self.line_offsets(lo, hi, parts))
        });
        let flat = |o: [Vec2; 2]| [o[0].x, -o[0].y, o[1].x, -o[1].y];
        if nodes.len() <= 3 {
            for (k, node) in nodes.iter().enumerate() {
                if let Some(c) = corners.iter().position(|&q| q == key(node.position)) {
                    out[k] = flat(corner_offsets[c]);
                }
            }
            return out;
        }
        // The nodes inside the piece's edges, and each edge's offset.
        let mut on_edge = HashMap::new();
        let mut edge_offsets = [[Vec2::ZERO; 2]; 3];
        for (e, offset) in edge_offsets.iter_mut().enumerate() {
            let (lo, hi, parts) = g.edge_line(e);
            if g.counts()[e] < 2 || parts < 2 {
                continue;
            }
            *offset = self.line_offsets(lo, hi, parts);
            for m in 1..g.counts()[e] {
                on_edge.insert(key(g.node_on_edge(e, m).position), e);
            }
        }
        // Half the largest error of the piece's boundary segments, sampled: each edge's middle
        // segment.
        let mut inside = [Vec2::ZERO; 2];
        for (e, count) in g.counts().into_iter().enumerate().filter(|&(_, c)| c > 0) {
            let m = (count - 1) / 2;
            let errors = self.midpoint_errors(g.node_on_edge(e, m).position, g.node_on_edge(e, m + 1).position);
            for (slot, error) in inside.iter_mut().zip(errors) {
                widen(slot, 0.5 * error);
            }
        }
        for (k, node) in nodes.iter().enumerate() {
            let p = key(node.position);
            let o = if let Some(c) = corners.iter().position(|&q| q == p) {
                corner_offsets[c]
            } else if let Some(&e) = on_edge.get(&p) {
                edge_offsets[e]
            } else {
                inside
            };
            out[k] = flat(o);
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use std::collections::HashMap;

    use glam::Vec3;

    use crate::core::panoramas::projection::Projection;
    use crate::core::scenes::builtin;
    use crate::core::settings::{Method, RenderSettings, Split};
    use crate::cpu::subdivide::subdivide;
    use crate::encoding::subdivide::subdivide_params;

    /// Every copy of a node position (each piece has its own) is drawn at the same place: the
    /// offsets agree bit for bit, so the drawing stays watertight.
    #[test]
    fn every_copy_of_a_node_takes_the_same_offset() {
        for (name, scene, viewer) in [
            ("demo", builtin::demo(), Vec3::ZERO),
            ("box room", builtin::builtin_scene("builtin:box-room", &Projection::equirect(512)).unwrap(), Vec3::ZERO),
            ("demo off centre", builtin::demo(), Vec3::new(0.4, 0.3, -0.2)),
        ] {
            for width in [512, 2048] {
                let settings = RenderSettings::new(Projection::equirect(width))
                    .with_method(Method::Adaptive(Split::Error))
                    .with_viewer(viewer)
                    .with_max_error_px(0.7);
                let mut params = subdivide_params(&settings, 0, scene.triangle_count() as u32);
                params.node_offsets = 1;
                let out = subdivide(&params, &scene.vertices, &scene.indices);
                let mut seen: HashMap<([u32; 3], i32), [f32; 4]> = HashMap::new();
                let mut offset_nodes = 0;
                for v in &out.nodes {
                    let key = (v.position.map(f32::to_bits), (v.theta_ref / 3.0).round() as i32);
                    if v.offsets != [0.0; 4] {
                        offset_nodes += 1;
                    }
                    let first = *seen.entry(key).or_insert(v.offsets);
                    assert_eq!(first, v.offsets, "{name} at {width}: node {:?} drawn at two places", v.position);
                }
                assert!(
                    offset_nodes * 10 > out.nodes.len(),
                    "{name} at {width}: {offset_nodes} of {} nodes offset",
                    out.nodes.len()
                );
            }
        }
    }
}
