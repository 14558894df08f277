//! CPU twin of `shaders/shared/subdivide_rows.wgsl`: a long thin part's bands and a piece's rows
//! (see the module doc of `cpu::subdivide`).
//!
//! **Rows.** Rows parallel to a piece's base edge (the first edge with the fewest parts), row k
//! of R (the larger side's count) meeting each side at its node ⌊k·n/R⌋ from the base, each row
//! in as many parts as it and its zipper's diagonals need; consecutive rows zipped. About rows ×
//! width triangles where the regular lattice makes m².
//!
//! **Bands.** A long thin part (K ≥ 3, its base within N_max parts) cut into bands of N_max of
//! its rows, two pieces per band, instead of K² macro cells.

use super::edges::Limits;
use super::lattice::{collapsed, with_nodes};
use super::spacing::Spacing;
use super::{edge_point, Node, Subdivider};
use crate::core::settings::SplitRule;
use crate::encoding::constants::PIECE_DIVISIONS;

/// How `plan` cuts a part into pieces: the K² cells of its macro lattice of level K, or, for a
/// long thin part under an adaptive rule, its bands ([`band_cell`]): K ≥ 3 and its base (the
/// edge with the fewest divisions) within one piece's N_max. The macro lattice would cut such a
/// part into K² cells, most of them as wide as the part; its bands make 2 per N_max steps along it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PartSplit {
    pub n: [u32; 3],
    pub k: u32,
    /// Whether the pieces are bands (else macro cells).
    pub bands: bool,
}

impl PartSplit {
    pub fn new(n: [u32; 3], k: u32, adaptive: bool, max_div: u32) -> PartSplit {
        let base = band_base(n);
        PartSplit { n, k, bands: adaptive && k >= 3 && n[base] <= band_rows(max_div) }
    }

    /// Piece records: two per band, or the K² cells.
    pub fn pieces(self, max_div: u32) -> u32 {
        if self.bands {
            2 * band_count(self.n, max_div)
        } else {
            self.k * self.k
        }
    }
}

/// A thin part's base: the first edge with the fewest divisions (corner `base` → `base` + 1;
/// the apex is corner `base` + 2).
pub fn band_base(n: [u32; 3]) -> usize {
    (0..3).min_by_key(|&e| n[e]).unwrap_or(0)
}

/// Steps along a thin part's sides per band: N_max (at most `PIECE_DIVISIONS`).
pub fn band_rows(max_div: u32) -> u32 {
    max_div.clamp(1, PIECE_DIVISIONS)
}

/// A thin part's bands: its rows, R = the larger side's count, `band_rows` at a time.
pub fn band_count(n: [u32; 3], max_div: u32) -> u32 {
    Rows::base_of(n).1.div_ceil(band_rows(max_div))
}

/// Where row k of rows on edge `base` with sides of `sides` (left, right) parts (R = the larger,
/// parallel to the base, at the row's fraction of the way to the apex on each side's fine nodes,
/// [`row_side_index`]) meets its left side (corner `base` → apex, edge `base` + 2 reversed) and
/// its right side (corner `base` + 1 → apex, edge `base` + 1): each as (edge, fine index from that
/// edge's start). Both a thin part's bands and a piece's rows.
pub fn row_end_indices(base: usize, sides: [u32; 2], k: u32) -> [(usize, u32); 2] {
    let r = sides[0].max(sides[1]);
    [((base + 2) % 3, sides[0] - row_side_index(k, sides[0], r)), ((base + 1) % 3, row_side_index(k, sides[1], r))]
}

/// The sides' counts (left, right) of rows on edge `base`.
fn sides_of(n: [u32; 3], base: usize) -> [u32; 2] {
    [n[(base + 2) % 3], n[(base + 1) % 3]]
}

/// The node, counted from the base, where row k of R meets a side of `count` ≤ R parts: the
/// row's fraction k/R of the way rounded down, so that only the last row reaches the apex (a
/// side that reached it earlier would leave rows lying along the other side, bands of no area)
/// and each step between rows advances a side by at most one node.
pub fn row_side_index(k: u32, count: u32, r: u32) -> u32 {
    k * count / r.max(1)
}

/// Piece `cell` of a thin part split in bands: band `cell` / 2 between rows k0 = `band_rows`·band
/// and k1 (the next band's first row, or the apex), and of that band's quad (L_k0, R_k0, R_k1,
/// L_k1) the triangle (L_k0, R_k0, R_k1) (even cells) or (L_k0, R_k1, L_k1) (odd), the part's
/// winding: each corner as (edge, fine index). Every corner lies on the part's edges, so the
/// piece's sides along them keep their fine nodes and neighbours meet without cracks.
pub fn band_cell(n: [u32; 3], max_div: u32, cell: u32) -> [(usize, u32); 3] {
    let (base, r) = Rows::base_of(n);
    let k0 = (cell / 2 * band_rows(max_div)).min(r);
    let k1 = (k0 + band_rows(max_div)).min(r);
    let sides = sides_of(n, base);
    let ([l0, r0], [l1, r1]) = (row_end_indices(base, sides, k0), row_end_indices(base, sides, k1));
    if cell % 2 == 0 {
        [l0, r0, r1]
    } else {
        [l0, r1, l1]
    }
}

/// Whether the zipper between rows of `w` and `w2` parts at (i, j) advances on the lower row:
/// its next node lies at the smaller fraction of the way (the lower first on a tie), or the upper
/// row is done. Where the rows share their left end (the left side did not advance between
/// them), one step along the lower row (a triangle of no area, dropped), then one along the
/// upper: every other triangle with that end and two nodes of one row would lie on that row.
/// (The right ends need no such rule: the lower row reaches its end only from the upper's last
/// part, whose triangle is the one at that end.)
pub(super) fn rows_advance_lower(i: u32, j: u32, [w, w2]: [u32; 2], shared_left: bool) -> bool {
    if i >= w {
        return false;
    }
    if j >= w2 {
        return true;
    }
    if shared_left && j == 0 {
        return i == 0;
    }
    (i + 1) * w2 <= (j + 1) * w
}

/// A piece drawn in rows ([`Rows::triangles`]): rows parallel to its base edge (the first edge
/// with the fewest divisions), from the base to the apex (the opposite corner), each row in as
/// many parts as it and its zipper's diagonals need; consecutive rows zipped into a strip. A thin
/// piece (a band near a pole, a strip along a wall) then makes about (rows × its width in parts)
/// triangles instead of the regular lattice's m². The base and the two sides keep their own
/// nodes, so neighbours still meet without cracks; the rows are interior.
#[derive(Clone, Debug, PartialEq)]
pub struct Rows {
    /// The base edge (corner `base` → `base` + 1); the apex is corner `base` + 2.
    pub base: usize,
    /// The sides' counts: left (corner `base` → apex, edge `base` + 2 reversed) and right
    /// (corner `base` + 1 → apex, edge `base` + 1).
    pub sides: [u32; 2],
    /// Each row's parts, from the base (its count) to the apex (0): max(sides) + 1 rows.
    pub widths: Vec<u32>,
}

impl Rows {
    /// The base edge of a piece's rows and the rows' count (the larger side's count).
    pub fn base_of(counts: [u32; 3]) -> (usize, u32) {
        let base = band_base(counts);
        (base, counts[(base + 1) % 3].max(counts[(base + 2) % 3]))
    }

    /// Row k's ends (left, right): the sides' nodes at the row's fraction k/R of the way to the
    /// apex ([`row_side_index`]); `node_on_edge(e, j)` is edge e's j-th node from corner e.
    pub fn row_ends(base: usize, sides: [u32; 2], k: u32, node_on_edge: &dyn Fn(usize, u32) -> Node) -> [Node; 2] {
        row_end_indices(base, sides, k).map(|(e, j)| node_on_edge(e, j))
    }

    /// Nodes: each row's w + 1, the apex's one.
    pub fn node_count(&self) -> u32 {
        self.widths.iter().map(|w| w + 1).sum()
    }

    /// Candidate triangles: between rows k and k + 1, w_k + w_(k+1).
    pub fn candidates(&self) -> u32 {
        self.widths.windows(2).map(|w| w[0] + w[1]).sum()
    }

    /// Node a of row k: on the base row the base edge's own nodes, else the point a/w of the
    /// way between the row's ends ([`edge_point`], exact at the ends).
    pub fn row_node(&self, k: u32, a: u32, node_on_edge: &dyn Fn(usize, u32) -> Node, spacing: Spacing) -> Node {
        if k == 0 {
            return node_on_edge(self.base, a);
        }
        let [left, right] = Self::row_ends(self.base, self.sides, k, node_on_edge);
        edge_point(left, right, a, self.widths[k as usize].max(1), spacing)
    }

    /// Every node, row by row (the output's slot order).
    pub fn nodes(&self, node_on_edge: &dyn Fn(usize, u32) -> Node, spacing: Spacing) -> Vec<Node> {
        self.widths
            .iter()
            .zip(0..)
            .flat_map(|(&w, k)| (0..=w).map(move |a| (k, a)))
            .map(|(k, a)| self.row_node(k, a, node_on_edge, spacing))
            .collect()
    }

    /// The triangles: rows k (nodes A_0..A_w from left to right) and k + 1 (B_0..B_w') zipped
    /// ([`rows_advance_lower`]), making (A_i, A_i+1, B_j) or (A_i, B_j+1, B_j), the piece's
    /// winding. Where a side did not advance between the rows, a triangle at that end has two
    /// coincident corners and is dropped. Each triangle as its corners' slots and nodes.
    pub fn triangles(&self, node_on_edge: &dyn Fn(usize, u32) -> Node, spacing: Spacing) -> Vec<([u32; 3], [Node; 3])> {
        let nodes = self.nodes(node_on_edge, spacing);
        with_nodes(self.slots(), |k| nodes[k as usize]).into_iter().filter(|(_, t)| !collapsed(t)).collect()
    }

    /// Every candidate triangle of the zipper ([`Rows::triangles`], the collapsed ones too) as
    /// its corners' slots, band by band.
    pub fn slots(&self) -> Vec<[u32; 3]> {
        let mut out = Vec::new();
        let mut start = 0;
        let r = self.sides[0].max(self.sides[1]);
        for k in 0..self.widths.len() - 1 {
            let (w, w2) = (self.widths[k], self.widths[k + 1]);
            let next = start + w + 1;
            let shared = row_side_index(k as u32, self.sides[0], r) == row_side_index(k as u32 + 1, self.sides[0], r);
            let (mut i, mut j) = (0, 0);
            for _ in 0..w + w2 {
                out.push(if rows_advance_lower(i, j, [w, w2], shared) {
                    i += 1;
                    [start + i - 1, start + i, next + j]
                } else {
                    j += 1;
                    [start + i, next + j, next + j - 1]
                });
            }
            start = next;
        }
        out
    }
}

impl Subdivider<'_> {
    /// Where a piece may be drawn in rows — on the sphere, under an adaptive rule, with three
    /// rows or more — its base edge and its sides' counts (left, right); None elsewhere
    /// (`rows_possible` in the WGSL). Two rows are never fewer triangles than the lattice of
    /// level 2 draws: with an edge of one part, its snapped middle collapses a corner triangle
    /// and three are drawn, the fewest two rows make (with two such edges, two).
    pub(super) fn rows_base(&self, counts: [u32; 3]) -> Option<(usize, [u32; 2])> {
        let (base, r) = Rows::base_of(counts);
        let possible = SplitRule::is_adaptive(self.params.method)
            && self.projection.panorama.is_sphere()
            && (3..=PIECE_DIVISIONS).contains(&r);
        possible.then(|| (base, sides_of(counts, base)))
    }

    /// The widest a row may be: 2·N_max, within 1 and `PIECE_DIVISIONS`.
    fn row_cap(&self) -> u32 {
        self.params.max_div.saturating_mul(2).clamp(1, PIECE_DIVISIONS)
    }

    /// Band b's measures (`row_measures` in the WGSL, one `lattice_rows` invocation): the parts
    /// across band b (rows b and b + 1) its zipper's diagonals need ([`Subdivider::band_parts`]),
    /// and the parts row b needs itself (the interior rule; 0 for the base row, whose parts are
    /// its edge's).
    pub(super) fn row_measures(
        &self,
        counts: [u32; 3],
        b: u32,
        limits: Limits,
        k: u32,
        node_on_edge: &dyn Fn(usize, u32) -> Node,
    ) -> (u32, u32) {
        let (base, sides) = self.rows_base(counts).expect("a piece with rows");
        let need = self.band_parts(base, sides, b, limits, self.row_cap(), node_on_edge);
        if b == 0 {
            return (need, 0);
        }
        let [left, right] = Rows::row_ends(base, sides, b, node_on_edge);
        (need, self.interior_divisions(left.position, right.position, limits, k))
    }

    /// A piece's rows from its bands' measures (`rows_from_measures` in the WGSL): the base row
    /// in its edge's parts, the apex's none, each other row in as many as it needs itself and
    /// as its two bands' diagonals need, at least one and at most 2·N_max. None where the piece
    /// has no rows ([`Subdivider::rows_base`]).
    pub(super) fn rows_from_measures(&self, counts: [u32; 3], measures: &[(u32, u32)]) -> Option<Rows> {
        let (base, sides) = self.rows_base(counts)?;
        let r = sides[0].max(sides[1]) as usize;
        let mut widths = vec![counts[base]];
        for row in 1..r {
            let need = measures[row].1.max(measures[row - 1].0).max(measures[row].0);
            widths.push(need.clamp(1, self.row_cap()));
        }
        widths.push(0);
        Some(Rows { base, sides, widths })
    }

    /// The parts across (1 to `cap`) that band b of a piece's rows (rows b and b + 1) needs for
    /// the zipper's diagonals: each spans a side's step along and a row's part across, and the
    /// projection's mixed term bends it in proportion to the part across, which neither the
    /// row's nor the side's own bend shows (a vertical row on a wall is straight on the sphere, a
    /// slanted line is not). Estimated from the band's two whole diagonals
    /// ([`Subdivider::diagonal_fits`]): split across in w parts, each diagonal of the zipper
    /// bends about 1/w as much.
    fn band_parts(
        &self,
        base: usize,
        sides: [u32; 2],
        b: u32,
        limits: Limits,
        cap: u32,
        node_on_edge: &dyn Fn(usize, u32) -> Node,
    ) -> u32 {
        let [l0, r0] = Rows::row_ends(base, sides, b, node_on_edge).map(|n| n.position);
        let [l1, r1] = Rows::row_ends(base, sides, b + 1, node_on_edge).map(|n| n.position);
        let (p, q) = (self.edge_profile(l0, r1, 2), self.edge_profile(r0, l1, 2));
        (1..cap).find(|&w| self.diagonal_fits(p, w, limits) && self.diagonal_fits(q, w, limits)).unwrap_or(cap)
    }
}
