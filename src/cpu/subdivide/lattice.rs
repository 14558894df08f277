//! CPU twin of `shaders/shared/subdivide_lattice.wgsl`.
//!
//! The piece's triangulation (seed 002 Fig. 6, see the module doc of `cpu::subdivide`): the
//! level-K macro cells of the pre-split, the regular lattice of level m with its boundary nodes
//! snapped to each edge's own nodes, and a sliver's strip. Shared by the twin's `plan` and
//! `lattice` and by the tests; the WGSL has the same functions under the same names.

use super::spacing::Spacing;
use super::Node;

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

/// The lattice of a piece with corners `q` and edge counts `counts` (edge e runs from corner e to
/// corner e+1; `node_on_edge(e, m)` gives its m-th node from corner e): the regular lattice of
/// level m = max(counts), whose boundary nodes on an edge with fewer divisions snap to that edge's
/// nearest node. Snapping is monotone along the edge, so no triangle folds over; triangles whose
/// snapped corners coincide have no area and are skipped. Each triangle as its corners' slots
/// ([`node_slot`]) and nodes.
pub fn lattice_triangles(
    counts: [u32; 3],
    q: &[Node; 3],
    node_on_edge: &dyn Fn(usize, u32) -> Node,
    spacing: Spacing,
) -> Vec<([u32; 3], [Node; 3])> {
    let m = counts[0].max(counts[1]).max(counts[2]);
    with_nodes(lattice_slots(m), |k| lattice_node(counts, q, node_on_edge, m, slot_node(k, m), spacing))
        .into_iter()
        .filter(|(_, t)| !collapsed(t))
        .collect()
}

/// The m² candidate triangles of a level-m lattice as their corners' slots ([`node_slot`]), in
/// cell order ([`macro_cell`]).
pub fn lattice_slots(m: u32) -> Vec<[u32; 3]> {
    (0..m * m).map(|t| macro_cell(m, t).map(|c| node_slot(c, m))).collect()
}

/// Triangles as slots, with the nodes in those slots.
pub(super) fn with_nodes(slots: Vec<[u32; 3]>, node: impl Fn(u32) -> Node) -> Vec<([u32; 3], [Node; 3])> {
    slots.into_iter().map(|t| (t, t.map(&node))).collect()
}

/// Whether two corners of a triangle are the same point (a triangle that snapping collapsed).
pub(super) fn collapsed(t: &[Node; 3]) -> bool {
    t[0].position == t[1].position || t[1].position == t[2].position || t[2].position == t[0].position
}

/// Nodes of a sliver's strip with base edge `base`: the n1 + 1 nodes of edge base + 1 (from
/// its corner towards the apex, corner base + 2), then the n2 nodes of edge base + 2 after the
/// apex (towards corner base).
pub fn strip_node_count(counts: [u32; 3], base: usize) -> u32 {
    counts[(base + 1) % 3] + counts[(base + 2) % 3] + 1
}

/// Node `slot` of a sliver's strip ([`strip_node_count`]).
pub(super) fn strip_node(counts: [u32; 3], base: usize, node_on_edge: &dyn Fn(usize, u32) -> Node, slot: u32) -> Node {
    let n1 = counts[(base + 1) % 3];
    if slot <= n1 {
        node_on_edge((base + 1) % 3, slot)
    } else {
        node_on_edge((base + 2) % 3, slot - n1)
    }
}

/// The strip of a sliver piece: its two long edges, from the base edge (one part) to the apex,
/// joined by a zigzag: each step advances along the edge whose next node lies at the smaller
/// fraction of the way to the apex (left first on a tie), making one triangle, n1 + n2 − 1 in
/// all. The regular lattice of level m = max(n1, n2) would fill the sliver with m² − (m − 1)
/// triangles (43 instead of 13 for counts 1, 7, 7), most of them far smaller across the sliver
/// than its edges' parts; the strip's rungs are shorter than the base, which needed no split.
/// Same corner order (winding) as the piece. Each triangle as its corners' slots and nodes.
pub fn strip_triangles(
    counts: [u32; 3],
    base: usize,
    node_on_edge: &dyn Fn(usize, u32) -> Node,
) -> Vec<([u32; 3], [Node; 3])> {
    with_nodes(strip_slots(counts, base), |k| strip_node(counts, base, node_on_edge, k))
}

/// The strip's n1 + n2 − 1 triangles ([`strip_triangles`]) as their corners' slots, in walk order.
pub fn strip_slots(counts: [u32; 3], base: usize) -> Vec<[u32; 3]> {
    let (n1, n2) = (counts[(base + 1) % 3], counts[(base + 2) % 3]);
    // Left side L_i (from corner `base` to the apex) is slot n1 + n2 − i; right side R_j is slot j.
    let left = |i: u32| n1 + n2 - i;
    let (mut i, mut j) = (0, 0);
    (0..n1 + n2 - 1)
        .map(|_| {
            if strip_advances_left(i, j, n1, n2) {
                i += 1;
                [left(i - 1), j, left(i)]
            } else {
                j += 1;
                [left(i), j - 1, j]
            }
        })
        .collect()
}

/// Whether the strip's walk at (i, j) advances on the left edge: its next node's fraction
/// (i + 1)/n2 is at most the right's (j + 1)/n1, or the right edge is done.
fn strip_advances_left(i: u32, j: u32, n1: u32, n2: u32) -> bool {
    i < n2 && (j == n1 || (i + 1) * n1 <= (j + 1) * n2)
}

/// Lattice node (i, j, l), i + j + l = m (weights of q0, q1, q2), of a piece with corners `q`
/// and edge counts `counts`: on a boundary edge, that edge's node nearest to it ([`snap`]).
pub(super) fn lattice_node(
    counts: [u32; 3],
    q: &[Node; 3],
    node_on_edge: &dyn Fn(usize, u32) -> Node,
    m: u32,
    c: [u32; 3],
    spacing: Spacing,
) -> Node {
    if let Some((e, idx)) = boundary_edge(c) {
        node_on_edge(e, snap(idx, counts[e], m))
    } else {
        spacing.interior(q, c, m)
    }
}

/// Slot of lattice node (i, j, l) among a level-m lattice's (m + 1)(m + 2)/2 nodes: rows
/// l = 0..m of m + 1 − l nodes each, by j. The output stores each piece's nodes in this order.
pub fn node_slot([_, j, l]: [u32; 3], m: u32) -> u32 {
    l * (2 * m + 3 - l) / 2 + j
}

/// The lattice node (i, j, l) in `slot` (the inverse of [`node_slot`]).
pub fn slot_node(slot: u32, m: u32) -> [u32; 3] {
    let (mut l, mut rest) = (0, slot);
    while rest > m - l {
        rest -= m + 1 - l;
        l += 1;
    }
    [m - l - rest, rest, l]
}
