//! CPU twin of `shaders/shared/subdivide_work.wgsl`: a piece's work (what `lattice` planned for
//! it: its nodes once per seam copy, its candidate triangles) and its work items, each of at most
//! `LATTICE_CHUNK` outputs (seam copies included): node items of `chunk_of(copies)` node slots
//! for `lattice_nodes`, triangle items of as many candidates for `lattice_triangles`, which draws
//! those not collapsed by snapping and not off screen, reading their corners from the nodes.

use std::ops::Range;

use glam::Vec3;

use super::Subdivider;
use crate::encoding::constants::LATTICE_CHUNK;
use crate::encoding::types::DrawVertex;

/// Node slots or candidate triangles one item of a piece drawn `copies` times covers.
pub fn chunk_of(copies: u32) -> u32 {
    LATTICE_CHUNK / copies
}

/// What `lattice` planned for a piece.
#[derive(Clone, Debug, Default)]
pub struct PiecePlan {
    /// Its nodes, slot by slot, once per seam copy (copy c's slot k at c·node_count + k).
    pub nodes: Vec<DrawVertex>,
    pub node_count: u32,
    pub copies: u32,
    /// Every candidate triangle as its corners' slots (the lattice's m², the strip's, the rows').
    pub candidates: Vec<[u32; 3]>,
}

impl PiecePlan {
    fn chunk(&self) -> u32 {
        chunk_of(self.copies)
    }

    /// Its nodes or candidate triangles, seam copies included, whichever are more: what one
    /// invocation wrote before the work items (the most a piece's output changes when one of
    /// its measures flips).
    pub fn output(&self) -> u32 {
        self.copies * self.node_count.max(self.candidates.len() as u32)
    }

    /// The first node slot of each node item.
    pub fn node_items(&self) -> impl Iterator<Item = u32> {
        (0..self.node_count).step_by(self.chunk() as usize)
    }

    /// The first candidate of each triangle item.
    pub fn triangle_items(&self) -> impl Iterator<Item = u32> {
        (0..self.candidates.len() as u32).step_by(self.chunk() as usize)
    }

    /// The node slots of the node item at `first`.
    pub fn node_range(&self, first: u32) -> Range<u32> {
        first..(first + self.chunk()).min(self.node_count)
    }

    /// The drawn candidates of the triangle item at `first`, their corners' positions read by
    /// slot (`candidate_drawn` in the WGSL).
    pub fn drawn(&self, sub: &Subdivider, first: u32, position: impl Fn(u32) -> Vec3) -> Vec<[u32; 3]> {
        let end = (first + self.chunk()).min(self.candidates.len() as u32);
        self.candidates[first as usize..end as usize]
            .iter()
            .copied()
            .filter(|t| {
                let p = t.map(&position);
                !(p[0] == p[1] || p[1] == p[2] || p[2] == p[0] || sub.off_screen_vertically(p))
            })
            .collect()
    }
}
