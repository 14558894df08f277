//! The `subdivide` stage, CPU twin of `shaders/subdivide/*.wgsl` (its passes: `passes.rs`) and of
//! `shaders/shared/subdivide_edges.wgsl` (`edges.rs`; the other modules mirror `subdivide_axis`,
//! `subdivide_frame_cuts`, `subdivide_quad` and `subdivide_lattice`): adaptive subdivision (seed
//! 002 §2.3, eq. 5, Fig. 6) plus the handling of the vertical axis and the ±π seam. The
//! projection itself (eq. 1–4) is applied per vertex afterwards, in the raster stage.
//!
//! **Edges (eq. 5).** Each edge of a triangle is split into N equal parts:
//! `adaptive`: N = ceil(l / L), l the edge's projected length in pixels (the projected curve,
//! sampled at 8 points, the larger of the two eyes, wrapping at the seam; heights are clamped to
//! a screen height above and below the image so that geometry far off screen does not inflate N);
//! `fixed:N`: every edge N; `vertex`: N = 1. N depends only on the edge's two endpoints, taken in a
//! canonical (lexicographic) order, and edge nodes are computed from that ordered pair, so the two
//! triangles sharing an edge make bit-identical nodes: no cracks.
//!
//! **Pre-split (`plan`).** The paper caps N at N_max (`max_div`), so that polygons larger than
//! the screen keep large errors. Here a triangle whose largest edge count M exceeds N_max is first
//! cut into a macro-lattice of level K = ceil(M / N_max) (K² pieces); macro nodes on an original
//! edge snap to that edge's fine nodes j/N_e, so a neighbour sees the same nodes whatever its own K.
//! Each piece then needs at most about N_max per edge: N_max caps only the lattice step. Pieces
//! whose snapped corners coincide have no area and are skipped. K is at most `MAX_MACRO_LEVEL`
//! (32) and a piece's edges at most `PIECE_DIVISIONS` (32), so that no invocation's loop runs
//! long (lavapipe cuts long invocations short).
//!
//! **Lattice (`lattice`).** With counts (n0, n1, n2) on a piece's edges, the piece is cut by the
//! regular triangular lattice of level m = max(n0, n1, n2) (the paper's Fig. 6): m² triangles.
//! On an edge with fewer divisions, the lattice's boundary nodes snap to the edge's nearest
//! node; the triangles that collapse are dropped, the others stay in order along the edge.
//! ```text
//!   the level-3 lattice of a piece (lattice nodes at 0, 1/3, 2/3, 1 of each edge):
//!
//!               C
//!              / \
//!             *---*
//!            / \ / \
//!           *---*---*
//!          / \ / \ / \
//!         A---1---2---B
//!
//!   counts (3, 3, 3): all 9 triangles are kept.
//!   counts (3, 3, 2): edge AB has nodes at 0, 1/2 and 1 only. Lattice nodes 1 and 2 both
//!   snap to the edge node at 1/2, so the upward triangle (1, 2, *) above them collapses to a
//!   segment and is dropped; its two neighbours now meet at the edge node: 8 triangles.
//! ```
//! No cracks, no T-junctions (every edge node is a lattice corner), no zero-area triangles.
//!
//! **Slivers (the error split, on the cylinder).** A piece with an edge in one part and another
//! in three or more is a sliver: the regular lattice would fill it with m² − (m − 1) triangles
//! across a width that needed no split (43 for counts 1, 7, 7). If that base edge's chord error is
//! within a quarter of τ, the piece is drawn as a strip instead ([`strip_triangles`]): its two
//! long edges' own nodes joined by a zigzag, n1 + n2 − 1 triangles (13), whose rungs are no
//! longer than the base. The boundary nodes are the edges' own, so neighbours still meet without
//! cracks, and the error bound is the lattice's. Not on the sphere,
//! where a sliver reaching towards a pole bends ever more towards its apex.
//!
//! **Rows (the full sphere, adaptive rules).** A piece may instead be drawn in rows parallel to
//! its base edge (the one with the fewest parts), from the base to the apex, each row in as many
//! parts as it and its zipper's diagonals need (see [`Rows`] and `Subdivider::piece_shape`),
//! consecutive rows zipped: about rows × width triangles where the lattice makes m². Used where
//! that makes fewer candidates than the lattice; the base and sides keep their own nodes.
//!
//! **Bands (adaptive rules).** A part with K ≥ 3 whose base needs at most N_max parts is cut
//! not into K² macro cells but into bands of N_max of its rows, two pieces per band
//! ([`band_cell`], [`PartSplit`]); the pieces' corners lie on the part's edges' fine nodes.
//!
//! **The vertical axis.** No eye sees a point with r ≤ d_e, and a triangle around the axis covers
//! every azimuth. Triangles that reach near the axis, or are large next to their distance from it,
//! switch on cuts for the whole frame (`active_cuts`, a pass over the scene before `plan`) and are
//! cut into their parts in the four quadrants around the axis (planes x = 0 and z = 0; the seam
//! θ = ±π is one of the cuts, so no part crosses it in θ), minus a small square around the axis
//! whose points no eye sees, and (adaptive, or any method on the cylinder) into bands between the
//! diamonds they need; their
//! neighbours are cut only where the edges they share cross those cuts, and every other triangle
//! is its own single part (see `axis.rs`). The cut points on an edge depend on that edge and the
//! frame's cuts alone, so neighbours agree; the parts are then split as above, each part's edges
//! counting as its "original" edges. On the GPU, `plan` plans the triangles that are their own
//! single part and lists the others for `plan_cuts`, which clips them.
//!
//! **Off screen.** Triangles, parts and pieces that lie wholly above or below the image's rows
//! (see [`Subdivider::off_screen_vertically`]) make no pieces or no lattice, and sub-triangles
//! that do are not emitted: a floor or ceiling near the axis is not subdivided where no one can
//! see it (the same image with fewer pieces).
//!
//! **Output (indexed).** Each piece writes its lattice's (m + 1)(m + 2)/2 nodes once
//! ([`node_slot`] order) and its drawn triangles as indices into them, so the vertex stage
//! projects a node once per eye instead of once per triangle around it (up to six).
//!
//! **The seam.** Every node of a piece carries the azimuth of the piece's centroid, `theta_ref`;
//! the vertex stage unwraps θ by whole turns towards it (a piece spans less than π in azimuth: it
//! is part of a triangle not containing the axis). A piece whose nodes' u range (both eyes)
//! crosses ±π is also emitted with `theta_ref ∓ 2π` (its nodes again, and its triangles indexing
//! them), so it appears at both edges of the panorama. On the cylinder that range is bounded from
//! the piece's corners alone (`piece_u_range`); on the sphere from its corners too where that
//! bound keeps it clear of the seam (`sphere_u_bound`), else from every node projected.
//!
//! The GPU appends pieces and triangles with atomic counters, so its order differs from this
//! twin's; tests compare the two as sets.

use glam::{Vec2, Vec3, Vec4};
use std::f32::consts::{PI, TAU};

use crate::core::panoramas::projection::Projection;
use crate::core::scenes::scene::{pack_tangent, SceneVertex};
use crate::core::settings::SplitRule;
use crate::encoding::constants::{SEAM_MARGIN, STRIP_BASE_ERROR, STRIP_MIN_DIVISIONS};
pub use crate::encoding::subdivide::{expand, subdivide_params, SubdivideOutput};
use crate::encoding::types::{DrawVertex, SubdivideParams};

mod axis;
mod edges;
mod frame_cuts;
mod lattice;
mod offsets;
pub mod passes;
mod piece;
mod rows;
mod seam;
pub mod spacing;
mod work;

pub use axis::{
    axis_clearance, band_limit, edge_crossings, edge_split_parts, fan, one_part, polygons, quadrant_polygons,
    snap_to_cut_planes, triangle_cuts, AxisCuts,
};
pub use edges::EdgeProfile;
use edges::{edge_point, lex_less, Limits};
pub use frame_cuts::FrameCuts;
pub use lattice::{
    boundary_edge, lattice_triangles, macro_cell, node_slot, slot_node, snap, strip_node_count, strip_triangles,
};
use piece::{PieceGeometry, Shape};
pub use rows::{band_cell, PartSplit, Rows};
pub use work::{chunk_of, PiecePlan};

/// An input triangle in the viewer frame.
#[derive(Clone, Copy, Debug)]
struct Triangle {
    position: [Vec3; 3],
    normal: [Vec3; 3],
    color: [Vec4; 3],
    uv: [Vec2; 3],
    /// glTF tangents (viewer frame xyz, sign w), zero where none.
    tangent: [Vec4; 3],
    material: u32,
    object: u32,
}

/// A node of the subdivision: its position (computed so that neighbours agree bit for bit)
/// and its barycentric weights in the input triangle (for the attributes).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Node {
    pub position: Vec3,
    pub bary: Vec3,
}

/// The stage's state for one dispatch: parameters and the derived projection.
pub struct Subdivider<'a> {
    params: &'a SubdivideParams,
    projection: Projection,
    /// Per object: the factor its L is multiplied by (the level of detail's relaxation; 1 where
    /// missing). `object_edge_scale` in shaders/shared/subdivide_bindings.wgsl.
    edge_scale: &'a [f32],
}

impl<'a> Subdivider<'a> {
    pub fn new(params: &'a SubdivideParams) -> Self {
        Subdivider { params, projection: (&params.projection).into(), edge_scale: &[] }
    }

    /// The projection the stage's parameters describe.
    pub fn projection(&self) -> &Projection {
        &self.projection
    }

    /// ρ: the half-diagonal of the square around the axis that the cuts remove.
    pub fn axis_clearance(&self) -> f32 {
        self.params.axis_clearance
    }

    /// The same with a per-object factor on L (see `edge_scale`).
    pub fn with_edge_scale(params: &'a SubdivideParams, edge_scale: &'a [f32]) -> Self {
        Subdivider { edge_scale, ..Subdivider::new(params) }
    }

    /// The whole stage for the dispatch's triangles: `active_cuts` over the scene, then `plan`
    /// and `lattice`.
    pub fn run(&self, vertices: &[SceneVertex], indices: &[u32]) -> SubdivideOutput {
        self.run_with_cuts(vertices, indices, &self.active_cuts(vertices, indices))
    }

    /// The same with the frame's cuts already known (tests that subdivide one triangle at a time).
    pub fn run_with_cuts(&self, vertices: &[SceneVertex], indices: &[u32], frame: &FrameCuts) -> SubdivideOutput {
        let mut out = SubdivideOutput { cuts: frame.axis, ..Default::default() };
        let first = self.params.first_triangle as usize;
        for t in first..first + self.params.triangle_count as usize {
            let tri = self.load(vertices, indices, t);
            if self.faces_away(vertices, indices, t, tri.position) {
                continue; // drawn nowhere
            }
            for poly in self.triangle_polygons(&tri, t, frame, &mut out.edge_splits) {
                for part in fan(&poly) {
                    // A part (a band of a floor under the viewer) wholly beyond the image's rows
                    // makes no pieces; likewise a piece in `lattice`.
                    if self.off_screen_vertically(part.map(|n| n.position)) {
                        continue;
                    }
                    let split = self.plan(&tri, &part);
                    let mut part_output = 0;
                    for cell in 0..split.pieces(self.params.max_div) {
                        out.pieces += 1;
                        out.bands += split.bands as u32;
                        if let Some((plan, shape)) = self.lattice(&tri, &part, split, cell) {
                            out.strips += matches!(shape, Shape::Strip(_)) as u32;
                            out.rows += matches!(shape, Shape::Rows(_)) as u32;
                            part_output += plan.output();
                            out.max_piece_output = out.max_piece_output.max(plan.output());
                            self.emit(&plan, &mut out);
                        }
                    }
                    out.max_part_output = out.max_part_output.max(part_output);
                }
            }
        }
        out.vertices = expand(&out.nodes, &out.indices);
        out
    }

    /// A piece's plan: its nodes once per seam copy, every node unwrapped towards the piece's
    /// reference azimuth `theta_c`, again a turn away where the nodes' u range (both eyes)
    /// reaches ±π; its candidate triangles (`plan_work` in the WGSL).
    #[allow(clippy::too_many_arguments)] // the piece as `shaped_plan` measured it
    fn piece_plan(
        &self,
        tri: &Triangle,
        nodes: &[Node],
        candidates: Vec<[u32; 3]>,
        offsets: &[[f32; 4]],
        theta_c: f32,
        (u_min, u_max): (f32, f32),
        reach: f32,
    ) -> PiecePlan {
        // Conservative by SEAM_MARGIN: a vertex exactly on the seam (θ = π, r = R_T) is a tie
        // that rounding could break either way; an extra copy is clipped by the rasterizer (and
        // its triangles wholly beyond the image are not drawn: `PiecePlan::shown`). The
        // seamless images make none (`SubdivideParams::seamless`: the fisheye's, the cubemap's
        // and the CAVE walls' maps from (u, v) are no longitude: a copy would draw its piece
        // twice over the original).
        let seam = self.params.seamless == 0;
        let mut shifts = vec![0.0];
        if seam && u_max > PI - SEAM_MARGIN {
            shifts.push(-TAU);
        }
        if seam && u_min < -PI + SEAM_MARGIN {
            shifts.push(TAU);
        }
        // VR180: a copy whose u range lies wholly beyond the image's columns (behind the viewer)
        // is not drawn; a piece with none left draws nothing.
        let half = self.image_half_span();
        let refs: Vec<f32> = shifts
            .into_iter()
            .filter(|&d| !seam || half >= PI || (u_min + d < half + SEAM_MARGIN && u_max + d > -half - SEAM_MARGIN))
            .map(|d| theta_c + d)
            .collect();
        let nodes: Vec<DrawVertex> = refs
            .iter()
            .flat_map(|&theta_ref| {
                nodes
                    .iter()
                    .zip(offsets)
                    .map(move |(&n, &o)| DrawVertex { offsets: o, ..draw_vertex(tri, n, theta_ref) })
            })
            .collect();
        let node_count = if refs.is_empty() { 0 } else { (nodes.len() / refs.len()) as u32 };
        PiecePlan { node_count, nodes, copies: refs.len() as u32, candidates, reach }
    }

    /// Appends a piece's nodes and its drawn triangles (indices into them), work item by work
    /// item as `lattice_nodes` and `lattice_triangles` do; the largest item's output into
    /// `max_output`.
    fn emit(&self, plan: &PiecePlan, out: &mut SubdivideOutput) {
        if plan.copies == 0 {
            return; // VR180: behind the viewer
        }
        let first = out.nodes.len() as u32;
        out.nodes.extend_from_slice(&plan.nodes);
        for start in plan.node_items() {
            out.max_output = out.max_output.max(plan.node_range(start).len() as u32 * plan.copies);
        }
        for start in plan.triangle_items() {
            let shown = plan.shown(self, start, |k| plan.nodes[k as usize]);
            out.max_output = out.max_output.max(shown.iter().map(|(_, mask)| mask.count_ones()).sum());
            for (local, mask) in shown {
                if self.params.measure_edges != 0 {
                    let p = local.map(|i| plan.nodes[i as usize].position.into());
                    out.max_sub_edge_px = out.max_sub_edge_px.max(self.visible_edge_px(p));
                }
                for c in (0..plan.copies).filter(|c| mask & 1 << c != 0) {
                    out.indices.extend(local.map(|i| first + c * plan.node_count + i));
                }
            }
        }
    }

    /// The base edge of a sliver piece drawn as a strip ([`strip_triangles`]): on the cylinder,
    /// under the error split, a piece with an edge in one part, whose chord error is within
    /// `STRIP_BASE_ERROR`·τ (the quick 2-segment profile, away from the eye circle), and another
    /// edge in `STRIP_MIN_DIVISIONS` or more parts. None: the regular lattice. Not on the sphere:
    /// a sliver reaching towards a pole bends ever more towards its apex, which its base does not
    /// tell (random slivers around the axis reached p99 1.9 px at τ = 1 px, 1.3 with the lattice).
    fn strip_base(&self, counts: [u32; 3], q: &[Node; 3], limits: Limits) -> Option<usize> {
        if self.params.method != SplitRule::AdaptiveError as u32
            || self.projection.panorama.is_sphere()
            || counts.iter().max() < Some(&STRIP_MIN_DIVISIONS)
        {
            return None;
        }
        let base = counts.iter().position(|&n| n == 1)?;
        let p = self.edge_profile(q[base].position, q[(base + 1) % 3].position, 2);
        p.straight(STRIP_BASE_ERROR, limits.max_error_px).then_some(base)
    }

    /// Half the image's span in longitude, radians: π on the cylinder and the sphere, π/2 for
    /// VR180 (`image_half_span` in the WGSL; meaningless for the seamless images, whose x is no
    /// longitude).
    pub fn image_half_span(&self) -> f32 {
        PI * self.projection.width as f32 / self.projection.turn_px()
    }

    /// Longest chord, in pixels, of a triangle's edges with an end on the screen rows.
    fn visible_edge_px(&self, p: [Vec3; 3]) -> f32 {
        let half_h = 0.5 * self.projection.height as f32;
        let width = self.projection.turn_px(); // a full turn in pixels: x wraps at it
        let mut longest = 0.0f32;
        for eye_sign in [-1.0f32, 1.0] {
            let q = p.map(|x| self.pixel(x, eye_sign));
            for e in 0..3 {
                let (a, b) = (q[e], q[(e + 1) % 3]);
                if a.y.abs() <= half_h || b.y.abs() <= half_h {
                    let dx = (b.x - a.x) - width * ((b.x - a.x) / width).round();
                    longest = longest.max(Vec2::new(dx, b.y - a.y).length());
                }
            }
        }
        longest
    }
}

fn draw_vertex(tri: &Triangle, n: Node, theta_ref: f32) -> DrawVertex {
    let b = n.bary;
    DrawVertex {
        position: n.position.into(),
        theta_ref,
        normal: (b.x * tri.normal[0] + b.y * tri.normal[1] + b.z * tri.normal[2]).into(),
        material: tri.material,
        color: (b.x * tri.color[0] + b.y * tri.color[1] + b.z * tri.color[2]).into(),
        uv: (b.x * tri.uv[0] + b.y * tri.uv[1] + b.z * tri.uv[2]).into(),
        object: tri.object,
        tangent: pack_tangent(b.x * tri.tangent[0] + b.y * tri.tangent[1] + b.z * tri.tangent[2]),
        offsets: [0.0; 4],
    }
}

/// The `subdivide` stage on the CPU: the output nodes, the triangles' indices, and every output
/// triangle as three [`DrawVertex`]es.
pub fn subdivide(params: &SubdivideParams, vertices: &[SceneVertex], indices: &[u32]) -> SubdivideOutput {
    Subdivider::new(params).run(vertices, indices)
}

#[cfg(test)]
mod schedule_tests;
#[cfg(test)]
mod seam_tests;
#[cfg(test)]
mod tests;
