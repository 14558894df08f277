//! CPU twin of `shaders/shared/subdivide_frame_cuts.wgsl`.
//!
//! Which triangles a frame cuts around the vertical axis (see `axis.rs`): `active_cuts` and
//! `ring_cuts` mark the scene's shared edges (`FrameCuts`), and each triangle's polygons follow
//! from its marks (`triangle_polygons`).

use glam::Vec3;

use super::{band_limit, edge_split_parts, polygons, triangle_cuts, AxisCuts, Node, Subdivider, Triangle};
use crate::core::scenes::scene::SceneVertex;
use crate::core::scenes::shared_edges::{shared_edges, SharedEdges};

/// The frame's cuts around the axis (`active_cuts`): which cuts, and which of the scene's
/// shared edges are a triangle's that asks for cuts, or a cut triangle's (`cut_edges` in the
/// WGSL: those two bits of each edge side by side).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct FrameCuts {
    pub axis: AxisCuts,
    pub edges: SharedEdges,
    /// Bit i: shared edge i is a triangle's that asks for cuts.
    pub asking_edges: Vec<u32>,
    /// Bit i: shared edge i is a cut triangle's (one that asks, or one with an edge of such).
    pub cut_edges: Vec<u32>,
}

fn bit(set: &[u32], id: u32) -> bool {
    set[id as usize / 32] & (1 << (id % 32)) != 0
}

fn set_bit(set: &mut [u32], id: u32) {
    set[id as usize / 32] |= 1 << (id % 32);
}

impl FrameCuts {
    /// Whether triangle t has an edge of a triangle that asks for cuts: then it is cut too.
    pub fn is_cut_triangle(&self, t: usize) -> bool {
        (0..3).any(|e| bit(&self.asking_edges, self.edges.ids[3 * t + e]))
    }

    /// Whether edge e of triangle t is a cut triangle's.
    pub fn is_cut_edge(&self, t: usize, e: usize) -> bool {
        bit(&self.cut_edges, self.edges.ids[3 * t + e])
    }

    /// Marks the three edges of triangle t as a cut triangle's and, if `asking`, as one's that
    /// asks for cuts (`mark_edges` in the WGSL).
    pub fn mark(&mut self, t: usize, asking: bool) {
        for e in 0..3 {
            let id = self.edges.ids[3 * t + e];
            set_bit(&mut self.cut_edges, id);
            if asking {
                set_bit(&mut self.asking_edges, id);
            }
        }
    }

    /// No edge marked (the `cut_edges` buffer cleared).
    pub fn clear_marks(&mut self) {
        self.asking_edges.fill(0);
        self.cut_edges.fill(0);
    }

    /// Cuts `axis` with every edge counted as a cut triangle's, none as one that asks (tests of
    /// one triangle whose neighbours, not given, are cut).
    pub fn every_edge(axis: AxisCuts, vertices: &[SceneVertex], indices: &[u32]) -> FrameCuts {
        let mut frame = FrameCuts::unmarked(vertices, indices);
        frame.axis = axis;
        frame.cut_edges.fill(u32::MAX);
        frame
    }

    /// No cuts, no edge marked, over the scene's shared edges (the `cut_edges` buffer cleared).
    pub fn unmarked(vertices: &[SceneVertex], indices: &[u32]) -> FrameCuts {
        let edges = shared_edges(vertices, indices);
        let words = edges.bit_words(1) as usize;
        FrameCuts { axis: 0, asking_edges: vec![0; words], cut_edges: vec![0; words], edges }
    }
}

impl Subdivider<'_> {
    /// The polygons of input triangle t's parts (none if it lies wholly above or below the
    /// image): a triangle that asks for cuts, or shares an edge with one, is cut by all of the
    /// frame's (`polygons`); any other only at its edges that a cut triangle has
    /// (`edge_split_parts`), each part its own polygon.
    pub(super) fn triangle_polygons(
        &self,
        tri: &Triangle,
        t: usize,
        frame: &FrameCuts,
        edge_splits: &mut u32,
    ) -> Vec<Vec<Node>> {
        if self.off_screen_vertically(tri.position) {
            return Vec::new();
        }
        let rho = self.params.axis_clearance;
        // Whether it asks for cuts was decided once, by `active_cuts`, which marked its edges:
        // deciding again here could differ in the last bit (the GPU's passes are compiled apart)
        // and leave its neighbours uncut where it is cut.
        if frame.axis == 0 || frame.is_cut_triangle(t) {
            return polygons(tri.position, rho, frame.axis);
        }
        let shared = [0, 1, 2].map(|e| frame.is_cut_edge(t, e));
        let parts = if shared.contains(&true) {
            edge_split_parts(tri.position, shared, rho, frame.axis)
        } else {
            vec![[0, 1, 2].map(|i| Node { position: tri.position[i], bary: Vec3::AXES[i] })]
        };
        *edge_splits += (parts.len() > 1) as u32;
        parts.into_iter().map(|part| part.to_vec()).collect()
    }

    /// [`FrameCuts::every_edge`] with the edges of the triangles that ask for cuts marked as
    /// `active_cuts` marks them (tests of triangles whose neighbours, not given, are cut).
    pub fn every_edge_cuts(&self, axis: AxisCuts, vertices: &[SceneVertex], indices: &[u32]) -> FrameCuts {
        let limit = band_limit(self.params.method, &self.projection);
        let mut frame = FrameCuts::every_edge(axis, vertices, indices);
        for t in 0..indices.len() / 3 {
            if triangle_cuts(self.positions(vertices, indices, t), self.params.axis_clearance, limit) != 0 {
                frame.mark(t, true);
            }
        }
        frame
    }

    /// `active_cuts` and `ring_cuts`: the cuts around the axis the frame makes, the edges of the
    /// triangles that ask for them, and the edges of the triangles cut (those and their
    /// neighbours across those edges; see `axis.rs`), from every on-screen triangle of the scene:
    /// all of `indices`, whatever range the dispatch plans.
    pub fn active_cuts(&self, vertices: &[SceneVertex], indices: &[u32]) -> FrameCuts {
        let limit = band_limit(self.params.method, &self.projection);
        let mut frame = FrameCuts::unmarked(vertices, indices);
        let on_screen: Vec<(usize, AxisCuts)> = (0..indices.len() / 3)
            .map(|t| (t, self.positions(vertices, indices, t)))
            .filter(|&(_, p)| !self.off_screen_vertically(p))
            .map(|(t, p)| (t, triangle_cuts(p, self.params.axis_clearance, limit)))
            .collect();
        for &(t, asks) in on_screen.iter().filter(|(_, asks)| *asks != 0) {
            frame.axis |= asks;
            frame.mark(t, true);
        }
        for &(t, _) in on_screen.iter().filter(|(_, asks)| *asks == 0) {
            if frame.is_cut_triangle(t) {
                frame.mark(t, false);
            }
        }
        frame
    }
}
