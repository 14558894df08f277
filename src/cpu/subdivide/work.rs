//! CPU twin of `shaders/shared/subdivide_work.wgsl`: a piece's work (what `lattice` planned for
//! it: its nodes once per seam copy, its candidate triangles) and its work items, each of at most
//! `LATTICE_CHUNK` outputs (seam copies included): node items of `chunk_of(copies)` node slots
//! for `lattice_nodes`, triangle items of as many candidates for `lattice_triangles`, which draws
//! those not collapsed by snapping and not off screen, reading their corners from the nodes.

use std::f32::consts::{PI, TAU};
use std::ops::Range;

use glam::Vec3;

use super::Subdivider;
use crate::core::panoramas::projection::azimuth;
use crate::encoding::constants::{LATTICE_CHUNK, SEAM_MARGIN};
use crate::encoding::types::DrawVertex;

/// `PiecePlan::reach` before a tracked head, whose u is not θ ± α: every copy of every triangle
/// drawn (1e30 in the WGSL's `piece_u_range`).
pub const NO_REACH: f32 = 1e30;

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
    /// The largest |u − θ| of its nodes (both eyes) where they were projected (the sphere near
    /// the seam), or its corners' bound's (with `SEAM_BOUND_SLACK`) where that kept them clear;
    /// on the cylinder its footprint's largest |α| (with the slack); by which
    /// [`copy_shows`](Self::copy_shows) widens a triangle's azimuths. [`NO_REACH`] with a tracked
    /// head: every copy of every triangle drawn.
    pub reach: f32,
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

    /// The drawn candidates of the triangle item at `first`, each with the seam copies of it that
    /// show ([`copy_shows`](Self::copy_shows)) as a mask (bit c: copy c), those with none left
    /// out; their corners read by node slot (copy c's slot k at c·node_count + k) from `node`.
    /// The triangles drawn are the masks' bits, candidate by candidate, copy by copy.
    pub fn shown(&self, sub: &Subdivider, first: u32, node: impl Fn(u32) -> DrawVertex) -> Vec<([u32; 3], u32)> {
        // An image narrower than a turn of longitude (VR180): every triangle is tested, copies
        // or not (the seamless images' x is no longitude).
        let narrow = sub.params.seamless == 0 && sub.image_half_span() < PI;
        self.drawn(sub, first, |k| Vec3::from(node(k).position))
            .into_iter()
            .map(|t| {
                let shows = |c: u32| {
                    (self.copies == 1 && !narrow)
                        || self.copy_shows(sub, t.map(|k| node(c * self.node_count + k)), self.reach)
                };
                (t, (0..self.copies).filter(|&c| shows(c)).fold(0, |mask, c| mask | 1 << c))
            })
            .filter(|&(_, mask)| mask != 0)
            .collect()
    }

    /// Whether a seam copy of a triangle (its corners as drawn: positions and the copy's
    /// reference azimuth) shows in the image: the corners' azimuths unwrapped towards the copy's
    /// reference as the raster stage unwraps them, widened by `reach`, reach more than
    /// `SEAM_MARGIN` into the image's columns (`copy_shows` in the WGSL). A copy wholly beyond
    /// the image's left or right edge would only be clipped, and one that reaches less far in
    /// (a part cut at the seam, touching the edge) covers no sample: the nearest lies 1/16 px in.
    fn copy_shows(&self, sub: &Subdivider, corners: [DrawVertex; 3], reach: f32) -> bool {
        let (mut lo, mut hi) = (f32::INFINITY, f32::NEG_INFINITY);
        for v in corners {
            let theta0 = azimuth(Vec3::from(v.position));
            let theta = theta0 + TAU * ((v.theta_ref - theta0) / TAU + 0.5).floor();
            lo = lo.min(theta);
            hi = hi.max(theta);
        }
        let half = sub.image_half_span();
        lo - reach < half - SEAM_MARGIN && hi + reach > -half + SEAM_MARGIN
    }

    /// The drawn candidates of the triangle item at `first`, their corners' positions read by
    /// slot (`candidate_drawn` in the WGSL).
    fn drawn(&self, sub: &Subdivider, first: u32, position: impl Fn(u32) -> Vec3) -> Vec<[u32; 3]> {
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
