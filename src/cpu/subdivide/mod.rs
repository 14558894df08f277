//! The `subdivide` stage, CPU twin of `shaders/subdivide/*.wgsl` (its passes: `passes.rs`) and of
//! `shaders/shared/subdivide_edges.wgsl` (this file; the other modules mirror `subdivide_axis`,
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
//! **Band quads (likewise).** A band of a floor or wall between two diamonds is often a polygon
//! of four corners whose fan makes two slivers along its long diagonal. When two opposite sides
//! are in one part each, the quad is drawn as one strip between the other two (its rails) instead
//! ([`quad_strip_triangles`]): n1 + n2 triangles, no diagonal. The rails' nodes are their own, the
//! diagonal was inside the polygon, so neighbours still meet without cracks; every rung of the
//! zigzag must be within τ of straight, like any edge drawn.
//!
//! **The vertical axis.** No eye sees a point with r ≤ d_e, and a triangle around the axis covers
//! every azimuth. Triangles that reach near the axis, or are large next to their distance from it,
//! switch on cuts for the whole frame (`active_cuts`, a pass over the scene before `plan`) and are
//! cut into their parts in the four quadrants around the axis (planes x = 0 and z = 0; the seam
//! θ = ±π is one of the cuts, so no part crosses it in θ), minus a small square around the axis
//! whose points no eye sees, and (adaptive) into bands between the diamonds they need; their
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
//! the piece's corners alone (`piece_u_range`); on the sphere every node is projected.
//!
//! The GPU appends pieces and triangles with atomic counters, so its order differs from this
//! twin's; tests compare the two as sets.

use glam::{Mat4, Vec2, Vec3, Vec4};
use std::f32::consts::{PI, TAU};

use crate::core::projection::{azimuth, horizontal_radius, wrap_angle, Eye, PanoramaKind, Projection, Vertical};
use crate::core::scene::{pack_tangent, unpack_tangent, SceneVertex};
use crate::core::settings::SplitRule;
use crate::encoding::constants::{
    EDGE_SAMPLES, ERROR_SPLIT_LENGTH, MAX_EDGE_DIVISIONS, MAX_MACRO_LEVEL, MAX_STRETCH, PIECE_DIVISIONS, SEAM_MARGIN,
    STRIP_BASE_ERROR, STRIP_MIN_DIVISIONS,
};
pub use crate::encoding::subdivide::{expand, subdivide_params, SubdivideOutput};
use crate::encoding::types::{DrawVertex, SubdivideParams};

mod axis;
mod frame_cuts;
mod lattice;
pub mod passes;
mod quad;

pub use axis::{
    axis_clearance, band_limit, edge_crossings, edge_split_parts, fan, one_part, polygons, quadrant_polygons,
    snap_to_cut_planes, triangle_cuts, AxisCuts,
};
pub use frame_cuts::FrameCuts;
pub use lattice::{
    boundary_edge, lattice_triangles, macro_cell, node_slot, quad_strip_node_count, quad_strip_triangles, slot_node,
    snap, strip_node_count, strip_triangles,
};
use lattice::{lattice_node, strip_node, weighted};

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

fn lex_less(a: Vec3, b: Vec3) -> bool {
    a.x < b.x || (a.x == b.x && (a.y < b.y || (a.y == b.y && a.z < b.z)))
}

/// The point j/n of the way from `a` to `b`, computed from the canonically ordered pair so that
/// both triangles sharing the edge get the same bits; the ends are exact.
fn edge_point(a: Node, b: Node, j: u32, n: u32) -> Node {
    let (lo, hi, jj) = if lex_less(b.position, a.position) { (b, a, n - j) } else { (a, b, j) };
    if jj == 0 {
        return lo;
    }
    if jj == n {
        return hi;
    }
    let t = jj as f32 / n as f32;
    Node { position: lo.position + (hi.position - lo.position) * t, bary: lo.bary + (hi.bary - lo.bary) * t }
}

/// What [`Subdivider::edge_profile`] measures of an edge.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EdgeProfile {
    pub length_px: f32,
    pub bend_px: f32,
    pub ring: bool,
}

/// A triangle's L and τ (see [`Subdivider::limits`]).
#[derive(Clone, Copy, Debug)]
struct Limits {
    edge_px: f32,
    max_error_px: f32,
}

/// Parts an edge needs so that its chord error, about bend·S²/(8n²) for n parts (see
/// [`Subdivider::edge_profile`]), is at most τ: ceil(S·√(bend / 8τ)) (not rounded to an integer
/// count yet; NaN stays NaN).
fn parts_for_bend(bend_px: f32, segments: u32, max_error_px: f32) -> f32 {
    (segments as f32 * (bend_px / (8.0 * max_error_px)).sqrt()).ceil()
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

    /// The same with a per-object factor on L (see `edge_scale`).
    pub fn with_edge_scale(params: &'a SubdivideParams, edge_scale: &'a [f32]) -> Self {
        Subdivider { edge_scale, ..Subdivider::new(params) }
    }

    /// L and τ for a triangle of `object`: the level of detail scales L by its factor s, and τ by
    /// s² (an edge's error grows as the square of its parts' length).
    fn limits(&self, object: u32) -> Limits {
        let s = self.edge_scale.get(object as usize).copied().unwrap_or(1.0);
        Limits { edge_px: self.params.edge_px * s, max_error_px: self.params.max_error_px * (s * s) }
    }

    /// Image position (x, y) in pixels of a viewer-frame point for one eye sign, x not wrapped.
    fn pixel(&self, p: Vec3, eye_sign: f32) -> Vec2 {
        let eye = if eye_sign > 0.0 { Eye::Right } else { Eye::Left };
        let q = self.projection.project_with_azimuth(p, azimuth(p), eye);
        Vec2::new(q.u * self.projection.pixels_per_radian(), q.v * self.projection.pixels_per_v())
    }

    /// What the split rules read of the straight edge ab, projected and sampled as a polyline
    /// through `segments` + 1 points (both eyes, x unwrapped across the seam), in the edge's
    /// canonical order:
    /// - `length_px`, by which eq. 5 splits it: the polyline's length l (the larger of the two
    ///   eyes) or, if larger, `segments` × its longest segment / `MAX_STRETCH` (/ 1 in the paper
    ///   model where the edge comes within 2·d_e of the axis: α ∝ √(r − d_e) bends it sharply):
    ///   an edge the projection stretches unevenly gets equal parts short enough where it is
    ///   stretched most. Heights are clamped to ±1.5 image heights from the middle row, so
    ///   off-screen parts count little, and segments beyond the clamp at both ends (on one side)
    ///   count nothing.
    /// - `bend_px`, by which the error split splits it: the largest second difference
    ///   |q(k+1) − 2 q(k) + q(k−1)| of the sampled points (both eyes; triples with a point beyond the
    ///   height clamp are skipped). A straight edge drawn with its nodes at the projected places
    ///   is wrong between the nodes by about |q''|·(t/n)²/8 for n parts (q'' the second derivative
    ///   along the edge's parameter t, whose sampled estimate is bend·S²): the chord's error,
    ///   across and along the curve (the drawn point j/n of the way is not where the point j/n
    ///   of the way along the 3-D edge projects).
    /// - `ring`: the edge comes within 2·d_e of the axis where the panorama shows the eye circle.
    pub fn edge_profile(&self, a: Vec3, b: Vec3, segments: u32) -> EdgeProfile {
        let (lo, hi) = if lex_less(b, a) { (b, a) } else { (a, b) };
        let clamp_v = 1.5 * self.projection.height as f32;
        let width = self.projection.width as f32;
        let (mut length, mut longest, mut nearest, mut bend) = (0.0f32, 0.0f32, f32::INFINITY, 0.0f32);
        for eye_sign in [-1.0f32, 1.0] {
            let mut total = 0.0;
            let mut prev = Vec2::ZERO;
            // The last two points, x unwrapped, y unclamped.
            let (mut q0, mut q1) = (Vec2::ZERO, Vec2::ZERO);
            for k in 0..=segments {
                let t = k as f32 / segments as f32;
                let p = lo + (hi - lo) * t;
                nearest = nearest.min(horizontal_radius(p));
                let raw = self.pixel(p, eye_sign);
                let mut q = raw;
                q.y = q.y.clamp(-clamp_v, clamp_v);
                let dx = (q.x - prev.x) - width * ((q.x - prev.x) / width).round();
                if k > 0 && !(q.y == prev.y && q.y.abs() == clamp_v) {
                    let segment = Vec2::new(dx, q.y - prev.y).length();
                    longest = longest.max(segment);
                    total += segment;
                }
                let unwrapped = Vec2::new(if k > 0 { q1.x + dx } else { raw.x }, raw.y);
                if k >= 2 && unwrapped.y.abs() < clamp_v && q1.y.abs() < clamp_v && q0.y.abs() < clamp_v {
                    bend = bend.max((unwrapped - 2.0 * q1 + q0).length());
                }
                q0 = q1;
                q1 = unwrapped;
                prev = q;
            }
            length = length.max(total);
        }
        // Near the eye circle, which the paper model and the sphere show on screen (α and the
        // longitude ∝ √(r − d_e)), no stretch is allowed (the exact model puts it at v = ±∞).
        let shows_ring =
            self.projection.vertical == Vertical::Paper || self.projection.panorama == PanoramaKind::Equirect;
        let ring = shows_ring && nearest < 2.0 * self.projection.eye_radius;
        let stretch = if ring { 1.0 } else { MAX_STRETCH };
        EdgeProfile { length_px: length.max(segments as f32 * longest / stretch), bend_px: bend, ring }
    }

    /// Divisions of an edge (not capped by N_max: the pre-split handles that), `edge_px` L and
    /// `max_error_px` τ being the triangle's (scaled by its object's level of detail).
    /// `adaptive:length` (eq. 5): a quick 2-segment length first: if it is at most L/2 the edge
    /// stays whole, else N = ceil(l/L) from the 8-segment length (never shorter, as it refines
    /// the same polyline). `adaptive` (the error split): an edge whose 2-segment polyline is at
    /// most L long, away from the eye circle, and whose midpoint bend asks for one part stays
    /// whole; else N = ceil(S·√(bend / 8τ)) from the 8-segment profile, at least l / (8·L)
    /// (no edge longer than 8·L: depth and attributes interpolate over bounded spans), and near
    /// the eye circle at least l / L, as eq. 5 (the second differences miss the ring's √ bend).
    fn edge_divisions(&self, a: Vec3, b: Vec3, limits: Limits) -> u32 {
        let Limits { edge_px, max_error_px } = limits;
        let n = match self.params.method {
            0 => return 1,
            1 => return self.params.fixed_n,
            2 => {
                if self.edge_profile(a, b, 2).length_px <= 0.5 * edge_px {
                    return 1;
                }
                (self.edge_profile(a, b, EDGE_SAMPLES).length_px / edge_px).ceil()
            }
            _ => {
                let quick = self.edge_profile(a, b, 2);
                if quick.length_px <= edge_px && !quick.ring && parts_for_bend(quick.bend_px, 2, max_error_px) <= 1.0 {
                    return 1;
                }
                let p = self.edge_profile(a, b, EDGE_SAMPLES);
                let longest = if p.ring { edge_px } else { ERROR_SPLIT_LENGTH * edge_px };
                parts_for_bend(p.bend_px, EDGE_SAMPLES, max_error_px).max((p.length_px / longest).ceil())
            }
        };
        if n.is_finite() {
            (n as u32).clamp(1, MAX_EDGE_DIVISIONS)
        } else {
            MAX_EDGE_DIVISIONS
        }
    }

    /// Divisions of an interior edge of the macro-lattice. Macro edges are about N_max·L long,
    /// but the projection stretches unevenly across a large triangle, so some need more: they may
    /// take up to 2·N_max, and at most `PIECE_DIVISIONS` (a piece then makes at most 32² triangles).
    /// `fixed:N` pieces (K per edge) take N/K (rounded up) on their interior edges: the union is the
    /// regular N-lattice when K divides N.
    fn interior_divisions(&self, a: Vec3, b: Vec3, limits: Limits, k: u32) -> u32 {
        if self.params.method == SplitRule::Fixed as u32 {
            return self.params.fixed_n.div_ceil(k.max(1));
        }
        self.edge_divisions(a, b, limits).min(2 * self.params.max_div).min(PIECE_DIVISIONS)
    }

    /// The corners of input triangle t in the viewer frame, snapped to the cut planes.
    fn positions(&self, vertices: &[SceneVertex], indices: &[u32], t: usize) -> [Vec3; 3] {
        let view = Mat4::from_cols_array_2d(&self.params.view);
        [0, 1, 2].map(|k| {
            snap_to_cut_planes(view.transform_point3(Vec3::from(vertices[indices[3 * t + k] as usize].position)))
        })
    }

    fn load(&self, vertices: &[SceneVertex], indices: &[u32], t: usize) -> Triangle {
        let view = Mat4::from_cols_array_2d(&self.params.view);
        let v = |k: usize| &vertices[indices[3 * t + k] as usize];
        Triangle {
            position: self.positions(vertices, indices, t),
            normal: [0, 1, 2].map(|k| view.transform_vector3(Vec3::from(v(k).normal))),
            color: [0, 1, 2].map(|k| Vec4::from(v(k).color)),
            uv: [0, 1, 2].map(|k| Vec2::from(v(k).uv)),
            tangent: [0, 1, 2].map(|k| {
                let t = unpack_tangent(v(k).tangent);
                view.transform_vector3(t.truncate()).extend(t.w)
            }),
            material: v(0).material,
            object: v(0).object,
        }
    }

    /// The slope k such that a point with |y| > k·r shows in no pixel row
    /// ([`Projection::vertical_limit`], passed to the GPU in `SubdivideParams`).
    pub fn vertical_limit(&self) -> f32 {
        self.params.vertical_limit
    }

    /// Whether a triangle shows in no pixel row: wholly above or wholly below the image's rows
    /// ([`Subdivider::vertical_limit`]). Along a segment with y > 0, y is linear and r convex, so
    /// y/r never falls below its smaller end value (the set y ≥ k·r is convex): corners all
    /// beyond mean the whole triangle is.
    pub fn off_screen_vertically(&self, p: [Vec3; 3]) -> bool {
        let k = self.vertical_limit();
        let above = p.iter().all(|q| q.y > k * horizontal_radius(*q));
        let below = p.iter().all(|q| q.y < -k * horizontal_radius(*q));
        above || below
    }

    /// `plan`: the macro-lattice level K of a part (K² pieces) and its edge counts.
    fn plan(&self, tri: &Triangle, part: &[Node; 3]) -> (u32, [u32; 3]) {
        let p = part.map(|n| n.position);
        let l = self.limits(tri.object);
        let n = [
            self.edge_divisions(p[0], p[1], l),
            self.edge_divisions(p[1], p[2], l),
            self.edge_divisions(p[2], p[0], l),
        ];
        let m = n[0].max(n[1]).max(n[2]);
        let k = if SplitRule::is_adaptive(self.params.method) {
            m.div_ceil(self.params.max_div.min(PIECE_DIVISIONS)).min(MAX_MACRO_LEVEL)
        } else if self.params.method == SplitRule::Fixed as u32 {
            m.div_ceil(PIECE_DIVISIONS)
        } else {
            1
        };
        (k, n)
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
            for poly in self.triangle_polygons(&tri, t, frame, &mut out.edge_splits) {
                if let Some((corners, rails)) = self.quad_strip(&tri, &poly) {
                    out.pieces += 2; // the GPU's two records of a quad
                    let before = (out.nodes.len(), out.indices.len() / 3);
                    self.quad_lattice(&tri, &corners, rails, &mut out);
                    out.note_output(before);
                    continue;
                }
                for part in fan(&poly) {
                    // A part (a band of a floor under the viewer) wholly beyond the image's rows
                    // makes no pieces; likewise a piece in `lattice`.
                    if self.off_screen_vertically(part.map(|n| n.position)) {
                        continue;
                    }
                    let (k, n) = self.plan(&tri, &part);
                    for cell in 0..k * k {
                        out.pieces += 1;
                        let before = (out.nodes.len(), out.indices.len() / 3);
                        self.lattice(&tri, &part, k, n, cell, &mut out);
                        out.note_output(before);
                    }
                }
            }
        }
        out.vertices = expand(&out.nodes, &out.indices);
        out
    }

    /// Where macro node (a, b, c)/K lies: nodes on an original edge snap to its fine nodes, and
    /// may land on a triangle corner.
    fn macro_location(&self, n: [u32; 3], k: u32, abc: [u32; 3]) -> Location {
        let Some((e, idx)) = boundary_edge(abc) else {
            return Location::Interior(abc);
        };
        let j = snap(idx, n[e], k);
        if j == 0 {
            Location::Corner(e)
        } else if j == n[e] {
            Location::Corner((e + 1) % 3)
        } else {
            Location::OnEdge(e, j)
        }
    }

    fn macro_node(&self, part: &[Node; 3], n: [u32; 3], k: u32, loc: Location) -> Node {
        match loc {
            Location::Corner(i) => part[i],
            Location::OnEdge(e, j) => edge_point(part[e], part[(e + 1) % 3], j, n[e]),
            Location::Interior([a, b, c]) => {
                let w = Vec3::new(a as f32, b as f32, c as f32) / k as f32;
                weighted(part, w)
            }
        }
    }

    /// `lattice`: subdivides macro cell `cell` of a part and emits its sub-triangles.
    fn lattice(&self, tri: &Triangle, part: &[Node; 3], k: u32, n: [u32; 3], cell: u32, out: &mut SubdivideOutput) {
        let loc = macro_cell(k, cell).map(|c| self.macro_location(n, k, c));
        let q = loc.map(|l| self.macro_node(part, n, k, l));
        if q[0].position == q[1].position || q[1].position == q[2].position || q[2].position == q[0].position {
            return; // snapped corners coincide: no area
        }
        if self.off_screen_vertically(q.map(|n| n.position)) {
            return; // every sub-triangle would be culled
        }
        // Each piece edge: on an original edge (that edge's fine nodes, by global index) or interior.
        let mut edges = [PieceEdge::default(); 3];
        for e in 0..3 {
            let (s, t) = (loc[e], loc[(e + 1) % 3]);
            edges[e] = (0..3)
                .find_map(|oe| match (s.index_on(oe, n), t.index_on(oe, n)) {
                    (Some(from), Some(to)) => {
                        Some(PieceEdge { original: Some(oe), from, to, count: from.abs_diff(to) })
                    }
                    _ => None,
                })
                .unwrap_or(PieceEdge {
                    original: None,
                    from: 0,
                    to: 0,
                    count: self.interior_divisions(q[e].position, q[(e + 1) % 3].position, self.limits(tri.object), k),
                });
        }
        let counts = edges.map(|e| e.count);
        let node_on_edge = |e: usize, m: u32| -> Node {
            // m-th node from piece corner e towards corner e+1.
            let pe = edges[e];
            match pe.original {
                Some(oe) => {
                    let j = if pe.to >= pe.from { pe.from + m } else { pe.from - m };
                    edge_point(part[oe], part[(oe + 1) % 3], j, n[oe])
                }
                None => edge_point(q[e], q[(e + 1) % 3], m, pe.count),
            }
        };
        // The lattice of level m, or a sliver's strip: which of its triangles are drawn (not
        // collapsed by snapping, not off screen), then its nodes once, then the drawn triangles
        // as indices into them.
        let m = counts[0].max(counts[1]).max(counts[2]);
        let strip = self.strip_base(counts, &q, self.limits(tri.object));
        let candidates = match strip {
            Some(base) => strip_triangles(counts, base, &node_on_edge),
            None => lattice_triangles(counts, &q, &node_on_edge),
        };
        let drawn = self.drawn(candidates);
        if drawn.is_empty() {
            return;
        }
        out.strips += strip.is_some() as u32;
        let nodes: Vec<Node> = match strip {
            Some(base) => {
                (0..strip_node_count(counts, base)).map(|k| strip_node(counts, base, &node_on_edge, k)).collect()
            }
            None => (0..(m + 1) * (m + 2) / 2)
                .map(|k| lattice_node(counts, &q, &node_on_edge, m, slot_node(k, m)))
                .collect(),
        };
        let theta_c = azimuth((q[0].position + q[1].position + q[2].position) / 3.0);
        let u_range = if self.projection.panorama == PanoramaKind::Equirect {
            let (mut u_min, mut u_max) = (f32::INFINITY, f32::NEG_INFINITY);
            for n in &nodes {
                let theta = theta_c + wrap_angle(azimuth(n.position) - theta_c);
                for eye in Eye::BOTH {
                    let u = self.projection.project_with_azimuth(n.position, theta, eye).u;
                    u_min = u_min.min(u);
                    u_max = u_max.max(u);
                }
            }
            (u_min, u_max)
        } else {
            self.piece_u_range(&q, theta_c)
        };
        self.emit(tri, &nodes, drawn, theta_c, u_range, out);
    }

    /// The candidate triangles (slots and nodes) a piece draws: those not wholly above or below
    /// the image's rows, as slots.
    fn drawn(&self, candidates: Vec<([u32; 3], [Node; 3])>) -> Vec<[u32; 3]> {
        candidates
            .into_iter()
            .filter(|(_, t)| !self.off_screen_vertically(t.map(|n| n.position)))
            .map(|(slots, _)| slots)
            .collect()
    }

    /// Appends a piece's nodes and its drawn triangles (slots into `nodes`). The seam: every
    /// node is unwrapped towards the piece's reference azimuth `theta_c`; where the nodes' u
    /// range (both eyes) reaches ±π, the piece is drawn again a turn away.
    fn emit(
        &self,
        tri: &Triangle,
        nodes: &[Node],
        drawn: Vec<[u32; 3]>,
        theta_c: f32,
        (u_min, u_max): (f32, f32),
        out: &mut SubdivideOutput,
    ) {
        let mut refs = vec![theta_c];
        // Conservative by SEAM_MARGIN: a vertex exactly on the seam (θ = π, r = R_T) is a tie
        // that rounding could break either way; an extra copy is clipped by the rasterizer.
        if u_max > PI - SEAM_MARGIN {
            refs.push(theta_c - TAU);
        }
        if u_min < -PI + SEAM_MARGIN {
            refs.push(theta_c + TAU);
        }
        let first = out.nodes.len() as u32;
        let node_count = nodes.len() as u32;
        for &theta_ref in &refs {
            out.nodes.extend(nodes.iter().map(|&n| draw_vertex(tri, n, theta_ref)));
        }
        for local in drawn {
            if self.params.measure_edges != 0 {
                out.max_sub_edge_px =
                    out.max_sub_edge_px.max(self.visible_edge_px(local.map(|i| nodes[i as usize].position)));
            }
            for c in 0..refs.len() as u32 {
                out.indices.extend(local.map(|i| first + c * node_count + i));
            }
        }
    }

    /// The u range (both eyes, unwrapped towards `theta_c`) of a piece's triangle on the
    /// cylinder, from its corners alone: the triangle's footprint is convex and misses the axis,
    /// so its azimuths span those of its corners, and α(r) (eq. 3) grows with r, so |α| is
    /// largest at the footprint's nearest or farthest point from the axis (the nearest: a corner
    /// or the foot of the perpendicular on an edge). It holds every node of the piece, so seam
    /// copies are made where the nodes need them (and, rarely, one more, which the rasterizer
    /// clips). `piece_u_range` in the WGSL.
    fn piece_u_range(&self, q: &[Node; 3], theta_c: f32) -> (f32, f32) {
        let (mut theta_min, mut theta_max) = (f32::INFINITY, f32::NEG_INFINITY);
        let (mut r_min, mut r_max) = (f32::INFINITY, 0.0f32);
        for e in 0..3 {
            let a = Vec2::new(q[e].position.x, q[e].position.z);
            let b = Vec2::new(q[(e + 1) % 3].position.x, q[(e + 1) % 3].position.z);
            let theta = theta_c + wrap_angle(azimuth(q[e].position) - theta_c);
            theta_min = theta_min.min(theta);
            theta_max = theta_max.max(theta);
            r_max = r_max.max(a.length());
            let ab = b - a;
            let t = (-a.dot(ab) / ab.dot(ab).max(1e-30)).clamp(0.0, 1.0);
            r_min = r_min.min((a + t * ab).length());
        }
        let alpha = self.projection.eye_shift(r_min).abs().max(self.projection.eye_shift(r_max).abs());
        (theta_min - alpha, theta_max + alpha)
    }

    /// The base edge of a sliver piece drawn as a strip ([`strip_triangles`]): on the cylinder,
    /// under the error split, a piece with an edge in one part, whose chord error is within
    /// `STRIP_BASE_ERROR`·τ (the quick 2-segment profile, away from the eye circle), and another
    /// edge in `STRIP_MIN_DIVISIONS` or more parts. None: the regular lattice. Not on the sphere:
    /// a sliver reaching towards a pole bends ever more towards its apex, which its base does not
    /// tell (random slivers around the axis reached p99 1.9 px at τ = 1 px, 1.3 with the lattice).
    fn strip_base(&self, counts: [u32; 3], q: &[Node; 3], limits: Limits) -> Option<usize> {
        if self.params.method != SplitRule::AdaptiveError as u32
            || self.projection.panorama == PanoramaKind::Equirect
            || counts.iter().max() < Some(&STRIP_MIN_DIVISIONS)
        {
            return None;
        }
        let base = counts.iter().position(|&n| n == 1)?;
        let p = self.edge_profile(q[base].position, q[(base + 1) % 3].position, 2);
        (!p.ring && parts_for_bend(p.bend_px, 2, STRIP_BASE_ERROR * limits.max_error_px) <= 1.0).then_some(base)
    }

    /// Longest chord, in pixels, of a triangle's edges with an end on the screen rows.
    fn visible_edge_px(&self, p: [Vec3; 3]) -> f32 {
        let half_h = 0.5 * self.projection.height as f32;
        let width = self.projection.width as f32;
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

/// Where a macro node lies. Original edge e runs from corner e to corner e + 1.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Location {
    Corner(usize),
    /// Fine node j (0 < j < n_e) of original edge e, counted from its start.
    OnEdge(usize, u32),
    Interior([u32; 3]),
}

impl Location {
    /// The node's fine index along original edge `oe` from its start, if it lies on that edge.
    fn index_on(self, oe: usize, n: [u32; 3]) -> Option<u32> {
        match self {
            Location::Corner(c) if c == oe => Some(0),
            Location::Corner(c) if c == (oe + 1) % 3 => Some(n[oe]),
            Location::OnEdge(e, j) if e == oe => Some(j),
            _ => None,
        }
    }
}

#[derive(Clone, Copy, Debug, Default)]
struct PieceEdge {
    original: Option<usize>,
    from: u32,
    to: u32,
    count: u32,
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
    }
}

/// The `subdivide` stage on the CPU: the output nodes, the triangles' indices, and every output
/// triangle as three [`DrawVertex`]es.
pub fn subdivide(params: &SubdivideParams, vertices: &[SceneVertex], indices: &[u32]) -> SubdivideOutput {
    Subdivider::new(params).run(vertices, indices)
}

#[cfg(test)]
mod tests;
#[cfg(test)]
mod watertight_tests;
