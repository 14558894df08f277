//! Shared edges: every triangle edge of a scene numbered so that edges with the same two end
//! points (by their positions' exact bits, whatever the vertex indices) get one number.
//!
//! The subdivision uses them around the vertical axis (`cpu::subdivide::axis`): a triangle that
//! asks for cuts marks its three edges, and a triangle that does not is cut only where it shares
//! a marked edge, at the points its neighbour makes there. Computed once per scene, from the
//! positions at load (a pose moves coinciding vertices alike unless their skins differ).

use std::collections::HashMap;

use crate::core::scenes::scene::SceneVertex;

/// The edge numbers of a scene's triangles.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SharedEdges {
    /// Edge e of triangle t (corner e to corner e + 1) is edge `ids[3 t + e]`.
    pub ids: Vec<u32>,
    /// How many distinct edges there are (`ids` are below it).
    pub count: u32,
}

impl SharedEdges {
    /// The 32-bit words a set of `bits` bits per edge needs (at least one).
    pub fn bit_words(&self, bits: u32) -> u32 {
        (self.count as u64 * bits as u64).div_ceil(32).max(1) as u32
    }
}

/// Numbers the edges of `indices` (three per triangle) over `vertices`. An index out of range
/// (rejected at load; here only defensively) gets an edge of its own.
pub fn shared_edges(vertices: &[SceneVertex], indices: &[u32]) -> SharedEdges {
    shared_edges_of(&welded_points(vertices), indices)
}

/// Each vertex's point: vertices at the same position (−0 and +0 alike) get the same number.
pub fn welded_points(vertices: &[SceneVertex]) -> Vec<u32> {
    let mut welded: HashMap<[u32; 3], u32> = HashMap::with_capacity(vertices.len());
    vertices
        .iter()
        .map(|v| {
            let next = welded.len() as u32;
            *welded.entry(v.position.map(|c| if c == 0.0 { 0 } else { c.to_bits() })).or_insert(next)
        })
        .collect()
}

/// [`shared_edges`] from the vertices' [`welded_points`] (a level-of-detail selection's indices
/// over the scene's vertices).
pub fn shared_edges_of(points: &[u32], indices: &[u32]) -> SharedEdges {
    let mut edges: HashMap<(u32, u32), u32> = HashMap::with_capacity(indices.len() / 2);
    let mut count = 0u32;
    let mut fresh = || {
        count += 1;
        count - 1
    };
    let ids = indices
        .chunks(3)
        .flat_map(|t| (0..t.len()).map(move |e| (t[e], t[(e + 1) % t.len()])))
        .map(|(a, b)| match (points.get(a as usize), points.get(b as usize)) {
            (Some(&a), Some(&b)) => *edges.entry((a.min(b), a.max(b))).or_insert_with(&mut fresh),
            _ => fresh(),
        })
        .collect();
    SharedEdges { ids, count }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn vertex(p: [f32; 3]) -> SceneVertex {
        SceneVertex { position: p, ..Default::default() }
    }

    #[test]
    fn edges_with_the_same_end_points_share_a_number_whatever_their_indices() {
        // Two triangles over a shared edge, the second with its own copies of the shared corners
        // (a texture seam), and −0 for +0.
        let vertices =
            [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0], [-0.0, 0.0, 0.0], [1.0, -1.0, 0.0]]
                .map(vertex);
        let edges = shared_edges(&vertices, &[0, 1, 2, 3, 4, 5]);
        assert_eq!(edges.count, 5);
        // Triangle 0's edge 0 (0 → 1) is triangle 1's edge 0 (1 → 0, reversed).
        assert_eq!(edges.ids[0], edges.ids[3]);
        let mut distinct = edges.ids.clone();
        distinct.sort();
        distinct.dedup();
        assert_eq!(distinct.len(), 5);
        assert!(edges.ids.iter().all(|&id| id < edges.count));
        assert_eq!(edges.bit_words(1), 1);
        assert_eq!(edges.bit_words(8), 2);
    }

    #[test]
    fn an_index_out_of_range_gets_an_edge_of_its_own() {
        let vertices = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]].map(vertex);
        let edges = shared_edges(&vertices, &[0, 1, 2, 0, 1, 9]);
        assert_eq!(edges.ids[0], edges.ids[3]);
        assert_eq!(edges.count, 5);
    }
}
