//! A piece of the pre-split placed and shaped: its corners on its part's edges, its edges and
//! their counts (`piece_corners`, `piece_edges`, `interior_counts` in
//! shaders/shared/subdivide_lattice.wgsl), then how it is drawn — a sliver's strip, rows, the
//! regular lattice — and its plan (`lattice_shape`, and for rows `lattice_rows` and
//! `lattice_rows_plan`).

use glam::Vec3;

use super::edges::Limits;
use super::lattice::{lattice_node, lattice_slots, strip_node, strip_slots};
use super::seam::clear_of_seam;
use super::spacing::Spacing;
use super::{
    band_cell, boundary_edge, edge_point, macro_cell, slot_node, snap, strip_node_count, Node, PartSplit, PiecePlan,
    Rows, Subdivider, Triangle,
};
use crate::core::panoramas::projection::{azimuth, wrap_angle, Eye};
use crate::encoding::constants::SEAM_BOUND_SLACK;

/// Where a macro node lies. Original edge e runs from corner e to corner e + 1.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum Location {
    Corner(usize),
    /// Fine node j (0 < j < n_e) of original edge e, counted from its start.
    OnEdge(usize, u32),
    Interior([u32; 3]),
}

impl Location {
    /// Fine node j of original edge e (0 ≤ j ≤ n_e): a corner at either end.
    pub(super) fn on_edge(e: usize, j: u32, n: [u32; 3]) -> Location {
        if j == 0 {
            Location::Corner(e)
        } else if j == n[e] {
            Location::Corner((e + 1) % 3)
        } else {
            Location::OnEdge(e, j)
        }
    }

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

/// A piece edge: on an original edge of its part (that edge's fine nodes from `from` to `to`),
/// or inside the part (its own `count` parts).
#[derive(Clone, Copy, Debug, Default)]
struct PieceEdge {
    original: Option<usize>,
    from: u32,
    to: u32,
    count: u32,
}

/// A piece placed in its part: the part's corners and counts, the piece's corners `q`, its
/// edges, and the limits of its triangle's object.
#[derive(Clone, Debug)]
pub(super) struct PieceGeometry {
    part: [Node; 3],
    n: [u32; 3],
    pub k: u32,
    pub q: [Node; 3],
    edges: [PieceEdge; 3],
    /// Where each corner lies in its part.
    loc: [Location; 3],
    pub limits: Limits,
    pub spacing: Spacing,
}

impl PieceGeometry {
    pub fn counts(&self) -> [u32; 3] {
        self.edges.map(|e| e.count)
    }

    /// The straight line piece edge e lies on, as its nodes are placed: the part's original
    /// edge (its ends and parts) where it lies on one, else its own ends and parts.
    pub fn edge_line(&self, e: usize) -> (Vec3, Vec3, u32) {
        match self.edges[e].original {
            Some(oe) => (self.part[oe].position, self.part[(oe + 1) % 3].position, self.n[oe]),
            None => (self.q[e].position, self.q[(e + 1) % 3].position, self.edges[e].count),
        }
    }

    /// The part's original edge and its parts where corner c lies inside one.
    pub fn corner_line(&self, c: usize) -> Option<(Vec3, Vec3, u32)> {
        match self.loc[c] {
            Location::OnEdge(oe, _) => Some((self.part[oe].position, self.part[(oe + 1) % 3].position, self.n[oe])),
            _ => None,
        }
    }

    /// The m-th node of piece edge e from corner e towards corner e + 1: on an original edge,
    /// that edge's fine node by its global index (so that neighbours agree bit for bit).
    pub fn node_on_edge(&self, e: usize, m: u32) -> Node {
        let pe = self.edges[e];
        match pe.original {
            Some(oe) => {
                let j = if pe.to >= pe.from { pe.from + m } else { pe.from - m };
                edge_point(self.part[oe], self.part[(oe + 1) % 3], j, self.n[oe], self.spacing)
            }
            None => edge_point(self.q[e], self.q[(e + 1) % 3], m, pe.count, self.spacing),
        }
    }
}

/// How a piece is triangulated (`lattice_shape`).
pub(super) enum Shape {
    Lattice(u32),
    Strip(usize),
    Rows(Rows),
}

impl Shape {
    /// Its candidate triangles, as their corners' slots.
    fn slots(&self, counts: [u32; 3]) -> Vec<[u32; 3]> {
        match self {
            Shape::Lattice(m) => lattice_slots(*m),
            Shape::Strip(base) => strip_slots(counts, *base),
            Shape::Rows(rows) => rows.slots(),
        }
    }

    /// Its nodes in slot order.
    fn nodes(&self, g: &PieceGeometry) -> Vec<Node> {
        let (counts, on_edge) = (g.counts(), |e: usize, m: u32| g.node_on_edge(e, m));
        match self {
            Shape::Lattice(m) => (0..(m + 1) * (m + 2) / 2)
                .map(|k| lattice_node(counts, &g.q, &on_edge, *m, slot_node(k, *m), g.spacing))
                .collect(),
            Shape::Strip(base) => {
                (0..strip_node_count(counts, *base)).map(|k| strip_node(counts, *base, &on_edge, k)).collect()
            }
            Shape::Rows(rows) => rows.nodes(&on_edge, g.spacing),
        }
    }
}

impl Subdivider<'_> {
    /// Where macro node (a, b, c)/K lies: nodes on an original edge snap to its fine nodes, and
    /// may land on a triangle corner.
    fn macro_location(&self, n: [u32; 3], k: u32, abc: [u32; 3]) -> Location {
        let Some((e, idx)) = boundary_edge(abc) else {
            return Location::Interior(abc);
        };
        Location::on_edge(e, snap(idx, n[e], k), n)
    }

    fn macro_node(&self, part: &[Node; 3], n: [u32; 3], k: u32, loc: Location) -> Node {
        match loc {
            Location::Corner(i) => part[i],
            Location::OnEdge(e, j) => edge_point(part[e], part[(e + 1) % 3], j, n[e], self.spacing()),
            Location::Interior(abc) => self.spacing().interior(part, abc, k),
        }
    }

    /// Piece `cell` of a part (a macro cell, or a band's half) placed: its corners, its edges
    /// (on an original edge: that edge's fine nodes, by global index; inside: their own
    /// division). None where its snapped corners coincide or it lies wholly off screen.
    pub(super) fn piece_geometry(
        &self,
        tri: &Triangle,
        part: &[Node; 3],
        split: PartSplit,
        cell: u32,
    ) -> Option<PieceGeometry> {
        let PartSplit { n, k, .. } = split;
        let loc = if split.bands {
            band_cell(n, self.params.max_div, cell).map(|(e, j)| Location::on_edge(e, j, n))
        } else {
            macro_cell(k, cell).map(|c| self.macro_location(n, k, c))
        };
        let q = loc.map(|l| self.macro_node(part, n, k, l));
        if q[0].position == q[1].position || q[1].position == q[2].position || q[2].position == q[0].position {
            return None; // snapped corners coincide: no area
        }
        if self.off_screen_vertically(q.map(|n| n.position)) {
            return None; // every sub-triangle would be culled
        }
        let limits = self.limits(tri.object);
        let edges = [0, 1, 2].map(|e| {
            let (s, t) = (loc[e], loc[(e + 1) % 3]);
            (0..3)
                .find_map(|oe| match (s.index_on(oe, n), t.index_on(oe, n)) {
                    (Some(from), Some(to)) => {
                        Some(PieceEdge { original: Some(oe), from, to, count: from.abs_diff(to) })
                    }
                    _ => None,
                })
                .unwrap_or(PieceEdge {
                    count: self.interior_divisions(q[e].position, q[(e + 1) % 3].position, limits, k),
                    ..Default::default()
                })
        });
        Some(PieceGeometry { part: *part, n, k, q, edges, loc, limits, spacing: self.spacing() })
    }

    /// `lattice`: piece `cell` of a part planned — its shape, its nodes once per seam copy, its
    /// candidate triangles — with its rows measured in turn (the direct run; the passes measure
    /// them in `lattice_rows`). None where it draws nothing.
    pub(super) fn lattice(
        &self,
        tri: &Triangle,
        part: &[Node; 3],
        split: PartSplit,
        cell: u32,
    ) -> Option<(PiecePlan, Shape)> {
        let g = self.piece_geometry(tri, part, split, cell)?;
        let shape = match self.unmeasured_shape(&g) {
            None => {
                let measures: Vec<_> = (0..self.row_count(&g)).map(|b| self.row_measure(&g, b)).collect();
                self.rows_or_lattice(&g, &measures)
            }
            Some(shape) => shape,
        };
        Some((self.shaped_plan(tri, &g, &shape), shape))
    }

    /// A piece's shape where it needs no rows measured: a sliver's strip on the cylinder
    /// ([`Subdivider::strip_base`]), or the regular lattice of level m = max(counts) where rows
    /// cannot be drawn; None: its rows are to be measured (the sphere, an adaptive rule, three
    /// rows or more).
    pub(super) fn unmeasured_shape(&self, g: &PieceGeometry) -> Option<Shape> {
        let counts = g.counts();
        if let Some(base) = self.strip_base(counts, &g.q, g.limits) {
            return Some(Shape::Strip(base));
        }
        (self.row_count(g) == 0).then(|| Shape::Lattice(counts.into_iter().max().unwrap_or(1)))
    }

    /// The rows to measure (the bands between them): R, the larger side's count, where rows can
    /// be drawn ([`Subdivider::rows_base`]); 0 elsewhere.
    pub(super) fn row_count(&self, g: &PieceGeometry) -> u32 {
        self.rows_base(g.counts()).map_or(0, |(_, sides)| sides[0].max(sides[1]))
    }

    /// Band b's measures (`row_measure`).
    pub(super) fn row_measure(&self, g: &PieceGeometry, b: u32) -> (u32, u32) {
        self.row_measures(g.counts(), b, g.limits, g.k, &|e, m| g.node_on_edge(e, m))
    }

    /// Rows from their measures where they make fewer candidate triangles than the lattice,
    /// else the lattice.
    pub(super) fn rows_or_lattice(&self, g: &PieceGeometry, measures: &[(u32, u32)]) -> Shape {
        let counts = g.counts();
        let m = counts.into_iter().max().unwrap_or(1);
        match self.rows_from_measures(counts, measures) {
            Some(rows) if rows.candidates() < m * m => Shape::Rows(rows),
            _ => Shape::Lattice(m),
        }
    }

    /// A shaped piece's plan: its nodes, its seam copies (from its nodes' u range on the sphere,
    /// from its corners on the cylinder), its candidates.
    pub(super) fn shaped_plan(&self, tri: &Triangle, g: &PieceGeometry, shape: &Shape) -> PiecePlan {
        let q = &g.q;
        let nodes = shape.nodes(g);
        let theta_c = azimuth((q[0].position + q[1].position + q[2].position) / 3.0);
        let sphere_bound = self.projection.panorama.is_sphere().then(|| self.sphere_u_bound(q, theta_c));
        // With the range, the reach a copy's triangles are tested with (`PiecePlan::reach`).
        let (u_range, reach) = if let Some((bound, reach)) = sphere_bound.filter(|&(b, _)| clear_of_seam(b)) {
            (bound, reach + SEAM_BOUND_SLACK) // every node within it: none projected
        } else if sphere_bound.is_some() {
            let (mut u_min, mut u_max, mut reach) = (f32::INFINITY, f32::NEG_INFINITY, 0.0f32);
            for n in &nodes {
                let theta = theta_c + wrap_angle(azimuth(n.position) - theta_c);
                for eye in Eye::BOTH {
                    let u = self.projection.project_with_azimuth(n.position, theta, eye).u;
                    u_min = u_min.min(u);
                    u_max = u_max.max(u);
                    reach = reach.max((u - theta).abs());
                }
            }
            ((u_min, u_max), reach)
        } else {
            let (range, reach) = self.piece_u_range(q, theta_c);
            (range, reach + SEAM_BOUND_SLACK)
        };
        let offsets = self.node_offsets(g, &nodes);
        self.piece_plan(tri, &nodes, shape.slots(g.counts()), &offsets, theta_c, u_range, reach)
    }
}
