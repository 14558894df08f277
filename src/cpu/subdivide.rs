//! The `subdivide` stage, CPU twin of `shaders/subdivide.wgsl`: adaptive subdivision (seed 002
//! §2.3, eq. 5, Fig. 6) plus the handling of the vertical axis and the ±π seam. The projection
//! itself (eq. 1–4) is applied per vertex afterwards, in the raster stage.
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
//! whose snapped corners coincide have no area and are skipped.
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
//! **The vertical axis.** No eye sees a point with r ≤ d_e, and a triangle around the axis covers
//! every azimuth. A sub-triangle whose footprint contains or nears the axis, or spans more than
//! `MAX_SPAN` of azimuth, is split into the 8 sectors of 45° around the axis and cut by a chord
//! just outside the eye circle (`axis_clearance`): nothing is smeared across the panorama and no
//! NaN is made. Only points no eye sees, or that project far above or below the image, are removed.
//! Clip points are computed from canonically ordered edge endpoints, so neighbours agree.
//!
//! **Off screen.** Triangles that lie wholly above or below the image (see
//! [`Subdivider::off_screen_vertically`]) make no pieces, and sub-triangles that do are not
//! emitted: a floor or ceiling near the axis is not subdivided where no one can see it.
//!
//! **The seam.** Each output triangle carries the azimuth of its centroid, `theta_ref`; the vertex
//! stage unwraps θ by whole turns towards it. A triangle whose u range (both eyes) crosses ±π is
//! also emitted with `theta_ref ∓ 2π`, so it appears at both edges of the panorama.
//!
//! The GPU appends pieces and triangles with atomic counters, so its order differs from this
//! twin's; tests compare the two as sets.

use glam::{Mat4, Vec2, Vec3, Vec4};
use std::f32::consts::{PI, TAU};

use crate::core::projection::{azimuth, horizontal_radius, wrap_angle, Projection};
use crate::core::scene::SceneVertex;
use crate::core::settings::{RenderSettings, SplitRule};
use crate::shader::constants::{EDGE_SAMPLES, FIXED_PIECE_DIVISIONS, MAX_EDGE_DIVISIONS, MAX_SPAN, SEAM_MARGIN, SNAP};
use crate::shader::types::{DrawVertex, SubdivideParams};

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

/// The `subdivide` stage's parameters for a range of input triangles (capacities and piece
/// ranges are left for the caller, 0).
pub fn subdivide_params(settings: &RenderSettings, first_triangle: u32, triangle_count: u32) -> SubdivideParams {
    let projection = settings.projection();
    let sub = &settings.subdivision;
    let (rule, fixed_n) = sub.method.split_rule();
    SubdivideParams {
        view: settings.view().to_cols_array_2d(),
        projection: projection.into(),
        axis_clearance: axis_clearance(projection),
        triangle_count,
        first_triangle,
        method: rule as u32,
        fixed_n,
        edge_px: sub.edge_px,
        max_div: sub.max_div.max(1),
        piece_capacity: 0,
        triangle_capacity: 0,
        first_piece: 0,
        piece_count: 0,
        measure_edges: (settings.measure.edges || settings.measure.error) as u32,
    }
}

/// An input triangle in the viewer frame.
#[derive(Clone, Copy, Debug)]
struct Triangle {
    position: [Vec3; 3],
    normal: [Vec3; 3],
    color: [Vec4; 3],
    uv: [Vec2; 3],
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

/// The stage's state for one dispatch: parameters and the derived projection.
pub struct Subdivider<'a> {
    params: &'a SubdivideParams,
    projection: Projection,
    /// Per object: the factor its L is multiplied by (the level of detail's relaxation; 1 where
    /// missing). `object_edge_scale` in shaders/subdivide.wgsl.
    edge_scale: &'a [f32],
}

/// Counters the GPU keeps too.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SubdivideOutput {
    pub vertices: Vec<DrawVertex>,
    pub pieces: u32,
    /// Largest projected length, in pixels, of an output edge with an end on the screen rows.
    pub max_sub_edge_px: f32,
}

impl<'a> Subdivider<'a> {
    pub fn new(params: &'a SubdivideParams) -> Self {
        Subdivider { params, projection: (&params.projection).into(), edge_scale: &[] }
    }

    /// The same with a per-object factor on L (see `edge_scale`).
    pub fn with_edge_scale(params: &'a SubdivideParams, edge_scale: &'a [f32]) -> Self {
        Subdivider { edge_scale, ..Subdivider::new(params) }
    }

    /// L for a triangle of `object`.
    fn edge_px(&self, object: u32) -> f32 {
        self.params.edge_px * self.edge_scale.get(object as usize).copied().unwrap_or(1.0)
    }

    /// Image position (x, y) in pixels of a viewer-frame point for one eye sign, x not wrapped.
    fn pixel(&self, p: Vec3, eye_sign: f32) -> Vec2 {
        let r = horizontal_radius(p);
        let u = azimuth(p) + eye_sign * self.projection.eye_shift(r);
        let v = self.projection.screen_height(p.y, r);
        Vec2::new(u * self.projection.pixels_per_radian(), v * self.projection.pixels_per_metre())
    }

    /// Projected length in pixels of the straight edge ab (larger of the two eyes), measured as
    /// a polyline through `segments` + 1 points. Heights are clamped to ±1.5 image heights from
    /// the middle row, so off-screen parts count little.
    pub fn edge_length_px(&self, a: Vec3, b: Vec3, segments: u32) -> f32 {
        let (lo, hi) = if lex_less(b, a) { (b, a) } else { (a, b) };
        let clamp_v = 1.5 * self.projection.height as f32;
        let width = self.projection.width as f32;
        let mut longest = 0.0f32;
        for eye_sign in [-1.0f32, 1.0] {
            let mut total = 0.0;
            let mut prev = Vec2::ZERO;
            for k in 0..=segments {
                let t = k as f32 / segments as f32;
                let mut q = self.pixel(lo + (hi - lo) * t, eye_sign);
                q.y = q.y.clamp(-clamp_v, clamp_v);
                if k > 0 {
                    let dx = (q.x - prev.x) - width * ((q.x - prev.x) / width).round();
                    total += Vec2::new(dx, q.y - prev.y).length();
                }
                prev = q;
            }
            longest = longest.max(total);
        }
        longest
    }

    /// Divisions of an edge (eq. 5, not capped by N_max: the pre-split handles that). A quick
    /// 2-segment length first: if it is at most L/2 the edge stays whole, else the 8-segment
    /// length decides (it is never shorter, as it refines the same polyline).
    fn edge_divisions(&self, a: Vec3, b: Vec3, edge_px: f32) -> u32 {
        match self.params.method {
            0 => 1,
            1 => self.params.fixed_n,
            _ => {
                if self.edge_length_px(a, b, 2) <= 0.5 * edge_px {
                    return 1;
                }
                let n = (self.edge_length_px(a, b, EDGE_SAMPLES) / edge_px).ceil();
                if n.is_finite() {
                    (n as u32).clamp(1, MAX_EDGE_DIVISIONS)
                } else {
                    MAX_EDGE_DIVISIONS
                }
            }
        }
    }

    /// Divisions of an interior edge of the macro-lattice. Macro edges are about N_max·L long,
    /// but the projection stretches unevenly across a large triangle, so some need more: they may
    /// take up to 2·N_max (a piece then makes at most 4·N_max² triangles).
    /// `fixed:N` pieces (K per edge) take N/K (rounded up) on their interior edges: the union is the
    /// regular N-lattice when K divides N.
    fn interior_divisions(&self, a: Vec3, b: Vec3, edge_px: f32, k: u32) -> u32 {
        if self.params.method == SplitRule::Fixed as u32 {
            return self.params.fixed_n.div_ceil(k.max(1));
        }
        self.edge_divisions(a, b, edge_px).min(2 * self.params.max_div)
    }

    fn load(&self, vertices: &[SceneVertex], indices: &[u32], t: usize) -> Triangle {
        let view = Mat4::from_cols_array_2d(&self.params.view);
        let v = |k: usize| &vertices[indices[3 * t + k] as usize];
        Triangle {
            position: [0, 1, 2].map(|k| view.transform_point3(Vec3::from(v(k).position))),
            normal: [0, 1, 2].map(|k| view.transform_vector3(Vec3::from(v(k).normal))),
            color: [0, 1, 2].map(|k| Vec4::from(v(k).color)),
            uv: [0, 1, 2].map(|k| Vec2::from(v(k).uv)),
            material: v(0).material,
            object: v(0).object,
        }
    }

    /// Whether a triangle lies wholly above or wholly below the image. Along a segment with
    /// y > 0, y is linear and r convex, so y/r never falls below its smaller end value: corners all
    /// above the top mean the whole triangle is (likewise below). The exact model has
    /// v ≥ v_paper·√(1 − d_e²/R_T²), so the test k = half height / (R_T·√(1 − d_e²/R_T²)) on y/r is
    /// safe for both vertical models.
    pub fn off_screen_vertically(&self, p: [Vec3; 3]) -> bool {
        let (rt, de) = (self.projection.screen_radius, self.projection.eye_radius);
        let k = self.projection.half_height_m() / (rt * (1.0 - (de / rt) * (de / rt)).sqrt());
        let above = p.iter().all(|q| q.y > k * horizontal_radius(*q));
        let below = p.iter().all(|q| q.y < -k * horizontal_radius(*q));
        above || below
    }

    /// `plan`: the macro-lattice level K of a triangle (K² pieces, none if it is off screen
    /// vertically) and its edge counts.
    fn plan(&self, tri: &Triangle) -> (u32, [u32; 3]) {
        let p = tri.position;
        if self.off_screen_vertically(p) {
            return (0, [1; 3]);
        }
        let l = self.edge_px(tri.object);
        let n = [
            self.edge_divisions(p[0], p[1], l),
            self.edge_divisions(p[1], p[2], l),
            self.edge_divisions(p[2], p[0], l),
        ];
        let m = n[0].max(n[1]).max(n[2]);
        let k = if self.params.method == SplitRule::Adaptive as u32 {
            m.div_ceil(self.params.max_div)
        } else if self.params.method == SplitRule::Fixed as u32 {
            m.div_ceil(FIXED_PIECE_DIVISIONS)
        } else {
            1
        };
        (k, n)
    }

    /// The whole stage for the dispatch's triangles.
    pub fn run(&self, vertices: &[SceneVertex], indices: &[u32]) -> SubdivideOutput {
        let mut out = SubdivideOutput::default();
        let first = self.params.first_triangle as usize;
        for t in first..first + self.params.triangle_count as usize {
            let tri = self.load(vertices, indices, t);
            let (k, n) = self.plan(&tri);
            for cell in 0..k * k {
                out.pieces += 1;
                self.lattice(&tri, k, n, cell, &mut out);
            }
        }
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

    fn macro_node(&self, tri: &Triangle, n: [u32; 3], k: u32, loc: Location) -> Node {
        let corner = |i: usize| Node { position: tri.position[i], bary: Vec3::from(BARY[i]) };
        match loc {
            Location::Corner(i) => corner(i),
            Location::OnEdge(e, j) => edge_point(corner(e), corner((e + 1) % 3), j, n[e]),
            Location::Interior([a, b, c]) => {
                let w = Vec3::new(a as f32, b as f32, c as f32) / k as f32;
                Node { position: w.x * tri.position[0] + w.y * tri.position[1] + w.z * tri.position[2], bary: w }
            }
        }
    }

    /// `lattice`: subdivides macro cell `cell` of a triangle and emits its sub-triangles.
    fn lattice(&self, tri: &Triangle, k: u32, n: [u32; 3], cell: u32, out: &mut SubdivideOutput) {
        let loc = macro_cell(k, cell).map(|c| self.macro_location(n, k, c));
        let q = loc.map(|l| self.macro_node(tri, n, k, l));
        if q[0].position == q[1].position || q[1].position == q[2].position || q[2].position == q[0].position {
            return; // snapped corners coincide: no area
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
                    count: self.interior_divisions(q[e].position, q[(e + 1) % 3].position, self.edge_px(tri.object), k),
                });
        }
        let counts = edges.map(|e| e.count);
        let node_on_edge = |e: usize, m: u32| -> Node {
            // m-th node from piece corner e towards corner e+1.
            let pe = edges[e];
            match pe.original {
                Some(oe) => {
                    let corner = |i: usize| Node { position: tri.position[i], bary: Vec3::from(BARY[i]) };
                    let j = if pe.to >= pe.from { pe.from + m } else { pe.from - m };
                    edge_point(corner(oe), corner((oe + 1) % 3), j, n[oe])
                }
                None => edge_point(q[e], q[(e + 1) % 3], m, pe.count),
            }
        };
        let mut emit = |a: Node, b: Node, c: Node| self.finish_triangle(tri, [a, b, c], out);
        lattice_triangles(counts, &q, &node_on_edge, &mut emit);
    }

    /// Axis split (if needed), then emission with seam copies.
    fn finish_triangle(&self, tri: &Triangle, nodes: [Node; 3], out: &mut SubdivideOutput) {
        let p = nodes.map(|n| n.position);
        if p[0] == p[1] || p[1] == p[2] || p[2] == p[0] || self.off_screen_vertically(p) {
            return;
        }
        let clearance = self.params.axis_clearance;
        if !needs_axis_split(p, split_radius(clearance)) {
            self.emit(tri, nodes, out);
            return;
        }
        for s in 0..SECTORS {
            let mut poly = nodes.to_vec();
            for plane in sector_planes(s, clearance) {
                poly = clip_polygon(&poly, plane);
            }
            for i in 1..poly.len().saturating_sub(1) {
                self.emit(tri, [poly[0], poly[i], poly[i + 1]], out);
            }
        }
    }

    fn emit(&self, tri: &Triangle, nodes: [Node; 3], out: &mut SubdivideOutput) {
        let p = nodes.map(|n| n.position);
        let theta_c = azimuth((p[0] + p[1] + p[2]) / 3.0);
        let (mut u_min, mut u_max) = (f32::INFINITY, f32::NEG_INFINITY);
        for q in p {
            let theta = theta_c + wrap_angle(azimuth(q) - theta_c);
            let alpha = self.projection.eye_shift(horizontal_radius(q)).abs();
            u_min = u_min.min(theta - alpha);
            u_max = u_max.max(theta + alpha);
        }
        if self.params.measure_edges != 0 {
            out.max_sub_edge_px = out.max_sub_edge_px.max(self.visible_edge_px(p));
        }
        let mut push = |theta_ref: f32| out.vertices.extend(nodes.map(|n| draw_vertex(tri, n, theta_ref)));
        push(theta_c);
        // Conservative by SEAM_MARGIN: a vertex exactly on the seam (θ = π, r = R_T) is a tie
        // that rounding could break either way; an extra copy is clipped by the rasterizer.
        if u_max > PI - SEAM_MARGIN {
            push(theta_c - TAU);
        }
        if u_min < -PI + SEAM_MARGIN {
            push(theta_c + TAU);
        }
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

const BARY: [[f32; 3]; 3] = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];

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

/// The boundary edge a node (a, b, c) of a lattice lies on, with its index along that edge from
/// the edge's start: edge 0 (corner 0 → 1) where c = 0, index b; edge 1 (1 → 2) where a = 0,
/// index c; edge 2 (2 → 0) where b = 0, index a. None inside. Both lattice levels (the macro
/// pre-split and each piece) place such nodes on the edge's own nodes with [`snap`].
pub fn boundary_edge([a, b, c]: [u32; 3]) -> Option<(usize, u32)> {
    if c == 0 {
        Some((0, b))
    } else if a == 0 {
        Some((1, c))
    } else if b == 0 {
        Some((2, a))
    } else {
        None
    }
}

/// The node, of an edge in `count` parts, nearest to lattice index `idx` of `level` along it.
pub fn snap(idx: u32, count: u32, level: u32) -> u32 {
    (2 * idx * count + level) / (2 * level)
}

/// Corners (macro indices a, b, c with a + b + c = K) of cell `cell` of a level-K lattice.
/// Row r (c from r to r + 1) holds K − r upward cells, then K − r − 1 downward ones.
pub fn macro_cell(k: u32, cell: u32) -> [[u32; 3]; 3] {
    let mut rest = cell;
    let mut row = 0;
    while rest >= 2 * (k - row) - 1 {
        rest -= 2 * (k - row) - 1;
        row += 1;
    }
    let up = k - row;
    if rest < up {
        let j = rest;
        [[k - row - j, j, row], [k - row - j - 1, j + 1, row], [k - row - j - 1, j, row + 1]]
    } else {
        let j = rest - up;
        [[k - row - j - 1, j + 1, row], [k - row - j - 2, j + 1, row + 1], [k - row - j - 1, j, row + 1]]
    }
}

/// Generates the lattice of a piece with corners `q` and edge counts `counts` (edge e runs from
/// corner e to corner e+1; `node_on_edge(e, m)` gives its m-th node from corner e): the regular
/// lattice of level m = max(counts), whose boundary nodes on an edge with fewer divisions snap
/// to that edge's nearest node. Snapping is monotone along the edge, so no triangle folds over;
/// triangles whose snapped corners coincide have no area and are skipped.
pub fn lattice_triangles(
    counts: [u32; 3],
    q: &[Node; 3],
    node_on_edge: &dyn Fn(usize, u32) -> Node,
    emit: &mut dyn FnMut(Node, Node, Node),
) {
    let m = counts[0].max(counts[1]).max(counts[2]);
    // A lattice node by local indices (i, j, l) with i + j + l = m (weights of q0, q1, q2).
    let node = |[i, j, l]: [u32; 3]| -> Node {
        if let Some((e, idx)) = boundary_edge([i, j, l]) {
            node_on_edge(e, snap(idx, counts[e], m))
        } else {
            let w = Vec3::new(i as f32, j as f32, l as f32) / m as f32;
            Node {
                position: w.x * q[0].position + w.y * q[1].position + w.z * q[2].position,
                bary: w.x * q[0].bary + w.y * q[1].bary + w.z * q[2].bary,
            }
        }
    };
    for t in 0..m * m {
        let [a, b, c] = macro_cell(m, t).map(node);
        if a.position != b.position && b.position != c.position && c.position != a.position {
            emit(a, b, c);
        }
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
        _pad: 0.0,
    }
}

/// Half-plane `a·x + b·z ≥ c` in the viewer frame's xz plane.
#[derive(Clone, Copy)]
struct HalfPlane {
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
fn clip_polygon(poly: &[Node], plane: HalfPlane) -> Vec<Node> {
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
fn sector_planes(s: usize, clearance: f32) -> [HalfPlane; 3] {
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

fn cross2(a: Vec2, b: Vec2) -> f32 {
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

/// The `subdivide` stage on the CPU: every output triangle as three [`DrawVertex`]es.
pub fn subdivide(params: &SubdivideParams, vertices: &[SceneVertex], indices: &[u32]) -> SubdivideOutput {
    Subdivider::new(params).run(vertices, indices)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::core::projection::{Eye, Vertical};
    use crate::core::settings::{Method, DEFAULT_EDGE_PX, DEFAULT_MAX_DIV};
    use std::collections::HashMap;
    use std::f32::consts::{FRAC_PI_4, FRAC_PI_8};

    fn vertex(p: [f32; 3]) -> SceneVertex {
        SceneVertex { position: p, normal: [0.0, 1.0, 0.0], color: [1.0; 4], ..Default::default() }
    }

    pub(super) fn params_for(
        projection: &Projection,
        method: Method,
        edge_px: f32,
        max_div: u32,
        n: u32,
    ) -> SubdivideParams {
        let settings = RenderSettings::new(*projection)
            .with_method(method)
            .with_edge_px(edge_px)
            .with_max_div(max_div)
            .with_measure_edges(true);
        subdivide_params(&settings, 0, n)
    }

    fn run_method(tri: [[f32; 3]; 3], method: Method) -> (Projection, Vec<DrawVertex>) {
        let projection = Projection::default();
        let params = params_for(&projection, method, DEFAULT_EDGE_PX, DEFAULT_MAX_DIV, 1);
        let v: Vec<SceneVertex> = tri.iter().map(|&p| vertex(p)).collect();
        (projection, subdivide(&params, &v, &[0, 1, 2]).vertices)
    }

    fn area3(t: &[DrawVertex]) -> f32 {
        let p: Vec<Vec3> = t.iter().map(|d| Vec3::from(d.position)).collect();
        0.5 * (p[1] - p[0]).cross(p[2] - p[0]).length()
    }

    /// Area of the footprint of a triangle list on the xz plane.
    fn footprint_area(v: &[DrawVertex]) -> f32 {
        v.chunks(3)
            .map(|t| {
                let q: Vec<Vec2> = t.iter().map(|d| Vec2::new(d.position[0], d.position[2])).collect();
                0.5 * cross2(q[1] - q[0], q[2] - q[0]).abs()
            })
            .sum()
    }

    #[test]
    fn ordinary_triangle_passes_through_the_vertex_method_unchanged() {
        let (_, out) = run_method([[-0.5, 0.0, -3.0], [0.5, 0.0, -3.0], [0.0, 0.5, -3.0]], Method::Vertex);
        assert_eq!(out.len(), 3);
        assert!(out[0].theta_ref.abs() < 1e-6);
    }

    #[test]
    fn floor_around_the_axis_is_split_and_keeps_its_area_outside_the_clearance() {
        let tri = [[-4.0, -1.5, 3.0], [4.0, -1.5, 3.0], [0.0, -1.5, -5.0]];
        let (projection, out) = run_method(tri, Method::Vertex);
        assert!(out.len() >= 3 * 8, "expected sector pieces, got {} vertices", out.len());
        let clearance = axis_clearance(&projection);
        for d in &out {
            let r = horizontal_radius(Vec3::from(d.position));
            assert!(r >= clearance * (1.0 - 1e-4), "point at r={r} inside the clearance");
            for eye in Eye::BOTH {
                let p = projection.project(Vec3::from(d.position), eye).expect("projectable");
                assert!(p.u.is_finite() && p.v.is_finite());
            }
        }
        // The pieces tile the triangle minus the octagon around the axis (area 8·c²·tan(π/8)).
        let full = 0.5 * 8.0 * 8.0;
        let octagon = 8.0 * clearance * clearance * FRAC_PI_8.tan();
        let originals: Vec<DrawVertex> =
            out.chunks(3).filter(|t| t[0].theta_ref.abs() <= PI).flatten().copied().collect();
        let got = footprint_area(&originals);
        assert!((got - (full - octagon)).abs() < 1e-3 * full, "area {got} vs {}", full - octagon);
        for t in out.chunks(3) {
            let th: Vec<f32> = t
                .iter()
                .map(|d| azimuth(Vec3::from(d.position)))
                .map(|a| t[0].theta_ref + wrap_angle(a - t[0].theta_ref))
                .collect();
            let span = th.iter().cloned().fold(f32::MIN, f32::max) - th.iter().cloned().fold(f32::MAX, f32::min);
            assert!(span <= FRAC_PI_4 + 1e-4, "piece spans {span}");
        }
    }

    #[test]
    fn triangle_with_a_vertex_inside_the_eye_circle_is_clipped_without_nan() {
        for method in [Method::Vertex, Method::Adaptive, Method::Fixed(4)] {
            let (projection, out) = run_method([[0.01, -0.5, 0.0], [2.0, -0.5, -2.0], [-2.0, -0.5, -2.0]], method);
            assert!(!out.is_empty());
            for d in &out {
                assert!(horizontal_radius(Vec3::from(d.position)) > projection.eye_radius);
                assert!(d.position.iter().chain(d.normal.iter()).all(|x| x.is_finite()));
            }
        }
    }

    #[test]
    fn seam_triangle_gets_a_copy_on_the_other_side() {
        let (_, out) = run_method([[-0.5, 0.0, 3.0], [0.5, 0.0, 3.0], [0.0, 0.5, 3.0]], Method::Vertex);
        assert_eq!(out.len(), 6, "one triangle and its seam copy");
        let refs: Vec<f32> = out.chunks(3).map(|t| t[0].theta_ref).collect();
        assert!((refs[0].abs() - PI).abs() < 1e-3 && (refs[1].abs() - PI).abs() < 1e-3);
        assert!((refs[0] - refs[1]).abs() > 6.0);
    }

    #[test]
    fn fixed_n_makes_exactly_n_squared_triangles_of_positive_area_tiling_the_triangle() {
        let tri = [[-0.6, -0.3, -3.0], [0.7, -0.2, -3.2], [0.1, 0.6, -2.8]];
        let whole = {
            let p = tri.map(Vec3::from);
            0.5 * (p[1] - p[0]).cross(p[2] - p[0]).length()
        };
        for n in 1..=8 {
            let (_, out) = run_method(tri, Method::Fixed(n));
            assert_eq!(out.len() / 3, (n * n) as usize, "fixed:{n}");
            assert!(out.chunks(3).all(|t| area3(t) > 0.0), "fixed:{n}: a zero-area triangle");
            let total: f32 = out.chunks(3).map(area3).sum();
            assert!((total - whole).abs() < 1e-4 * whole, "fixed:{n}: area {total} vs {whole}");
        }
    }

    /// Checks a triangulation of the triangle q with `counts` nodes per edge is conforming:
    /// every edge is shared by two triangles or lies on the boundary, the boundary edges are
    /// exactly the consecutive edge nodes, and the areas add up.
    fn check_conforming(counts: [u32; 3]) {
        let q = [
            Node { position: Vec3::new(0.0, 0.0, -3.0), bary: Vec3::X },
            Node { position: Vec3::new(1.3, 0.1, -3.0), bary: Vec3::Y },
            Node { position: Vec3::new(0.4, 1.1, -3.2), bary: Vec3::Z },
        ];
        let node_on_edge = |e: usize, m: u32| edge_point(q[e], q[(e + 1) % 3], m, counts[e]);
        let mut tris = Vec::new();
        lattice_triangles(counts, &q, &node_on_edge, &mut |a, b, c| tris.push([a.position, b.position, c.position]));
        let key = |p: Vec3| [p.x.to_bits(), p.y.to_bits(), p.z.to_bits()];
        let mut edges: HashMap<([u32; 3], [u32; 3]), u32> = HashMap::new();
        let mut total = 0.0;
        for t in &tris {
            let a = 0.5 * (t[1] - t[0]).cross(t[2] - t[0]).length();
            assert!(a > 1e-9, "{counts:?}: zero-area triangle {t:?}");
            total += a;
            for e in 0..3 {
                let (u, v) = (key(t[e]), key(t[(e + 1) % 3]));
                *edges.entry(if u < v { (u, v) } else { (v, u) }).or_default() += 1;
            }
        }
        let whole = 0.5 * (q[1].position - q[0].position).cross(q[2].position - q[0].position).length();
        assert!((total - whole).abs() < 1e-4 * whole, "{counts:?}: area {total} vs {whole}");
        let mut boundary = Vec::new();
        for (e, &count) in counts.iter().enumerate() {
            for m in 0..count {
                let (u, v) = (key(node_on_edge(e, m).position), key(node_on_edge(e, m + 1).position));
                boundary.push(if u < v { (u, v) } else { (v, u) });
            }
        }
        for (edge, n) in &edges {
            let on_boundary = boundary.contains(edge);
            assert_eq!(
                *n,
                if on_boundary { 1 } else { 2 },
                "{counts:?}: edge {edge:?} used {n} times (boundary: {on_boundary})"
            );
        }
        assert!(
            boundary.iter().all(|b| edges.contains_key(b)),
            "{counts:?}: a boundary segment is missing (T-junction)"
        );
    }

    #[test]
    fn lattice_is_conforming_for_equal_and_unequal_edge_counts() {
        for a in 1..=9 {
            for b in 1..=9 {
                for c in [1, 2, 3, 5, 9] {
                    check_conforming([a, b, c]);
                }
            }
        }
    }

    #[test]
    fn vertically_culled_triangles_project_wholly_off_the_image() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand::rngs::StdRng::seed_from_u64(11);
        let mut culled = 0;
        for vertical in [Vertical::Paper, Vertical::Exact] {
            let projection = Projection { width: 800, height: 200, vertical, ..Projection::default() };
            let params = params_for(&projection, Method::Adaptive, 32.0, 7, 0);
            let sd = Subdivider::new(&params);
            for _ in 0..3000 {
                let p: [Vec3; 3] = std::array::from_fn(|_| {
                    Vec3::new(rng.random_range(-2.0..2.0), rng.random_range(-1.0..3.0), rng.random_range(-2.0..2.0))
                });
                if !sd.off_screen_vertically(p) {
                    continue;
                }
                culled += 1;
                for _ in 0..200 {
                    let (a, b): (f32, f32) = (rng.random(), rng.random());
                    let (a, b) = if a + b > 1.0 { (1.0 - a, 1.0 - b) } else { (a, b) };
                    let q = p[0] + a * (p[1] - p[0]) + b * (p[2] - p[0]);
                    for eye in Eye::BOTH {
                        if let Some(pr) = projection.project(q, eye) {
                            assert!(
                                pr.v.abs() > projection.half_height_m(),
                                "{vertical:?}: culled triangle {p:?} shows point {q:?}"
                            );
                        }
                    }
                }
            }
        }
        assert!(culled > 100, "the test exercised only {culled} culled triangles");
    }

    #[test]
    fn macro_cells_tile_the_lattice() {
        for k in 1..=6 {
            let mut seen = std::collections::HashSet::new();
            for cell in 0..k * k {
                let c = macro_cell(k, cell);
                for v in c {
                    assert_eq!(v[0] + v[1] + v[2], k);
                }
                assert!(seen.insert(c), "cell repeated");
            }
        }
    }

    #[test]
    fn subdivided_closed_mesh_stays_closed() {
        let projection = Projection { width: 1200, height: 240, ..Projection::default() };
        let blob = crate::core::builtin::blob(Vec3::new(0.3, 0.1, -3.0), 1.2);
        let (v, i) = (blob.vertices, blob.indices);
        for (method, edge_px, max_div) in [
            (Method::Adaptive, 32.0f32, 7),
            (Method::Adaptive, 6.0, 3),
            (Method::Adaptive, 3.0, 7),
            (Method::Fixed(5), 0.0, 7),
        ] {
            let params = params_for(&projection, method, edge_px.max(1.0), max_div, (i.len() / 3) as u32);
            let out = subdivide(&params, &v, &i);
            assert!(out.vertices.len() / 3 > i.len() / 3);
            if method == Method::Adaptive && edge_px <= 6.0 {
                assert!(out.pieces > (i.len() / 3) as u32, "L = {edge_px}: pre-split expected");
            }
            let key = |p: [f32; 3]| p.map(f32::to_bits);
            let mut edges: HashMap<([u32; 3], [u32; 3]), u32> = HashMap::new();
            for t in out.vertices.chunks(3) {
                for e in 0..3 {
                    let (a, b) = (key(t[e].position), key(t[(e + 1) % 3].position));
                    *edges.entry(if a < b { (a, b) } else { (b, a) }).or_default() += 1;
                }
            }
            let open = edges.values().filter(|&&n| n != 2).count();
            assert_eq!(
                open,
                0,
                "{} L={edge_px} N_max={max_div}: {open} edges not shared by exactly two triangles",
                method.name()
            );
            if method == Method::Adaptive {
                // Eq. 5 bounds each original edge's parts by L; lattice lines inside a large face
                // nearer the viewer than its edges project longer, by up to the depth ratio
                // across the face (here ~1.7).
                assert!(out.max_sub_edge_px <= 2.0 * edge_px, "L={edge_px}: longest edge {} px", out.max_sub_edge_px);
            }
        }
    }
}

#[cfg(test)]
mod real_mesh_tests {
    use super::tests::params_for;
    use super::*;
    use crate::core::settings::Method;
    use std::collections::{BTreeSet, HashMap};

    /// Seed 002 §2.3's crack-freeness, literally: on a real mesh, the two triangles sharing an
    /// edge put bit-identical nodes on it. Each triangle is subdivided alone; the nodes each
    /// one leaves on a shared edge are compared.
    #[test]
    fn shared_edges_get_bit_identical_nodes_on_a_real_mesh() {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/assets/cow/cow.obj");
        assert!(path.exists(), "test asset {} is missing: this test needs ../shared/assets", path.display());
        let projection = Projection { width: 1600, height: 300, ..Projection::default() };
        let mut scene = crate::core::load::load_obj(&path).unwrap();
        scene.fit(3.0, &projection).unwrap();
        let key = |p: Vec3| [p.x.to_bits(), p.y.to_bits(), p.z.to_bits()];
        // Edges by their two corner positions (unordered), with the triangles that have them.
        let mut edges: HashMap<([u32; 3], [u32; 3]), Vec<usize>> = HashMap::new();
        for t in 0..scene.triangle_count() {
            for e in 0..3 {
                let a = Vec3::from(scene.vertices[scene.indices[3 * t + e] as usize].position);
                let b = Vec3::from(scene.vertices[scene.indices[3 * t + (e + 1) % 3] as usize].position);
                let (ka, kb) = (key(a), key(b));
                edges.entry(if ka < kb { (ka, kb) } else { (kb, ka) }).or_default().push(t);
            }
        }
        let params = params_for(&projection, Method::Adaptive, 6.0, 4, 1);
        let outputs: Vec<Vec<DrawVertex>> = (0..scene.triangle_count())
            .map(|t| {
                subdivide(&SubdivideParams { first_triangle: t as u32, ..params }, &scene.vertices, &scene.indices)
                    .vertices
            })
            .collect();
        let (mut compared, mut split) = (0, 0);
        for ((ka, kb), tris) in edges.iter().filter(|(_, t)| t.len() == 2) {
            let (a, b) = (
                Vec3::new(f32::from_bits(ka[0]), f32::from_bits(ka[1]), f32::from_bits(ka[2])),
                Vec3::new(f32::from_bits(kb[0]), f32::from_bits(kb[1]), f32::from_bits(kb[2])),
            );
            let on_edge = |v: &DrawVertex| {
                let p = Vec3::from(v.position);
                (p - a).cross(b - a).length() <= 1e-5 * (b - a).length_squared()
                    && (p - a).dot(b - a) >= 0.0
                    && (p - b).dot(a - b) >= 0.0
            };
            let nodes = |t: usize| -> BTreeSet<[u32; 3]> {
                outputs[t].iter().filter(|v| on_edge(v)).map(|v| key(Vec3::from(v.position))).collect()
            };
            let (n0, n1) = (nodes(tris[0]), nodes(tris[1]));
            if n0.is_empty() || n1.is_empty() {
                continue; // culled off screen on one side
            }
            assert_eq!(n0, n1, "edge {a} – {b}: the two triangles put different nodes on it");
            compared += 1;
            split += (n0.len() > 2) as usize;
        }
        assert!(compared > 1000 && split > 100, "{compared} shared edges compared, {split} of them split");
    }
}
