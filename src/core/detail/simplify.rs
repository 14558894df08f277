//! The level-of-detail chain's simplification (seed 001 §2.3: the Garland–Heckbert quadric
//! simplifier, meshoptimizer's), made to keep a closed surface closed.
//!
//! A mesh's vertices are split where its attributes are (a UV seam, a hard normal): two vertices
//! at one position. meshoptimizer treats those seams as borders it must keep, so a UV sphere
//! barely simplifies, and a small torus can still collapse into a fan of edges used by many
//! triangles. So an object is simplified on its **welded** topology (every vertex replaced by the
//! first vertex at its exact position), each level is kept only if it is as closed as the
//! original (a closed original: every directed edge once, with its reverse once, no degenerate
//! triangle; [`is_closed`]), and the chain stops at the first level that is not. The kept
//! levels' corners then get back a vertex of their own position with the attributes of the side
//! they lie on ([`unweld`]).

use std::collections::HashMap;

use crate::core::scenes::scene::SceneVertex;
use crate::core::scenes::shared_edges::welded_points;

/// Each simplified level aims at this share of the triangles of the level before: close enough
/// that the coarsest level meeting a budget is at most ~1.4× the budget.
pub const LEVEL_RATIO: f32 = 0.7;

/// The vertices' welding: each vertex's representative, the first vertex at its position.
pub struct Welding {
    pub first: Vec<u32>,
}

impl Welding {
    pub fn of(vertices: &[SceneVertex]) -> Welding {
        let points = welded_points(vertices);
        let mut first_of_point: Vec<u32> = Vec::new();
        let first = points
            .iter()
            .enumerate()
            .map(|(v, &p)| {
                if p as usize == first_of_point.len() {
                    first_of_point.push(v as u32);
                }
                first_of_point[p as usize]
            })
            .collect();
        Welding { first }
    }

    /// `indices` with each vertex replaced by its representative (out of range kept as is).
    pub fn weld(&self, indices: &[u32]) -> Vec<u32> {
        indices.iter().map(|&i| self.first.get(i as usize).copied().unwrap_or(i)).collect()
    }
}

/// A closed, consistently wound surface: every directed edge used once and its reverse once, and
/// no triangle with two equal corners.
pub fn is_closed(welded: &[u32]) -> bool {
    let mut edges: HashMap<(u32, u32), u32> = HashMap::with_capacity(welded.len());
    for t in welded.chunks_exact(3) {
        if t[0] == t[1] || t[1] == t[2] || t[2] == t[0] {
            return false;
        }
        for e in 0..3 {
            *edges.entry((t[e], t[(e + 1) % 3])).or_default() += 1;
        }
    }
    !edges.is_empty() && edges.iter().all(|(&(a, b), &n)| n == 1 && edges.get(&(b, a)) == Some(&1))
}

/// Whether a triangle of `indices` has (nearly) no area: its height under 10⁻⁴ of its longest
/// edge. Its plane is then undefined, and it draws nothing while its neighbours meet it.
pub fn has_sliver(vertices: &[SceneVertex], indices: &[u32]) -> bool {
    let at = |i: u32| glam::Vec3::from(vertices[i as usize].position);
    indices.chunks_exact(3).any(|t| {
        let (a, b, c) = (at(t[0]), at(t[1]), at(t[2]));
        let longest = (b - a).length_squared().max((c - b).length_squared()).max((a - c).length_squared());
        // Twice the area is the longest edge times the height over it.
        let twice_area = (b - a).cross(c - a).length();
        twice_area <= 1e-4 * longest
    })
}

/// One object's chain of levels, each about [`LEVEL_RATIO`] of the last, down to `floor`
/// triangles: level 0 is `original`; a closed original's levels are all closed. Returns the
/// levels (indices into `vertices`) and each level's error (meshoptimizer's, summed along the
/// chain).
pub fn simplify_chain(
    vertices: &[SceneVertex],
    welding: &Welding,
    original: &[u32],
    floor: usize,
) -> (Vec<Vec<u32>>, Vec<f32>) {
    let bytes: &[u8] = bytemuck::cast_slice(vertices);
    let adapter = meshopt::VertexDataAdapter::new(bytes, std::mem::size_of::<SceneVertex>(), 0).expect("vertex layout");
    let mut welded = welding.weld(original);
    // A closed object free of slivers stays so at every level (an open or sliver-holding mesh,
    // a scan such as the cow, is simplified as meshoptimizer gives it).
    let keep_closed = is_closed(&welded) && !has_sliver(vertices, original);
    let corners = Corners::of(original, welding);
    let mut chain = vec![original.to_vec()];
    let mut errors = vec![0.0f32];
    loop {
        let count = welded.len() / 3;
        if count <= floor {
            break;
        }
        // A level that would open the surface (or leave a triangle without area) is tried again
        // with a gentler step before the chain stops: meshoptimizer's collapses differ with
        // the target.
        let mut error = 0.0f32;
        let mut accepted = None;
        for ratio in [LEVEL_RATIO, 0.8, 0.9] {
            let target = ((count as f32 * ratio) as usize).max(floor);
            let next = meshopt::simplify(
                &welded,
                &adapter,
                3 * target,
                1.0,
                meshopt::SimplifyOptions::Sparse,
                Some(&mut error),
            );
            // No real progress: stop.
            if next.is_empty() || next.len() / 3 > count * 19 / 20 {
                break;
            }
            if !keep_closed || (is_closed(&next) && !has_sliver(vertices, &next)) {
                accepted = Some(next);
                break;
            }
        }
        let Some(next) = accepted else { break };
        chain.push(unweld(&next, &corners, vertices));
        errors.push(errors.last().unwrap() + error);
        welded = next;
    }
    (chain, errors)
}

/// The original vertices at each representative, and the original triangles each vertex is a
/// corner of (as representatives), for [`unweld`].
struct Corners {
    /// Representative → the object's vertices at its position.
    at: HashMap<u32, Vec<u32>>,
    /// Vertex → the representatives of the other corners of the original triangles it is in.
    neighbours: HashMap<u32, Vec<u32>>,
}

impl Corners {
    fn of(original: &[u32], welding: &Welding) -> Corners {
        let mut at: HashMap<u32, Vec<u32>> = HashMap::new();
        let mut neighbours: HashMap<u32, Vec<u32>> = HashMap::new();
        let rep = |i: u32| welding.first.get(i as usize).copied().unwrap_or(i);
        for t in original.chunks_exact(3) {
            for e in 0..3 {
                let v = t[e];
                let list = at.entry(rep(v)).or_default();
                if !list.contains(&v) {
                    list.push(v);
                }
                let others = neighbours.entry(v).or_default();
                others.extend([rep(t[(e + 1) % 3]), rep(t[(e + 2) % 3])]);
            }
        }
        Corners { at, neighbours }
    }
}

/// A welded level back on the object's own vertices: each corner takes, of the vertices at its
/// position, the one whose original triangles most often reach the level triangle's other
/// corners (the side of a seam the triangle lies on), then the one whose normal is nearest the
/// triangle's, then the first.
fn unweld(welded: &[u32], corners: &Corners, vertices: &[SceneVertex]) -> Vec<u32> {
    let position = |i: u32| glam::Vec3::from(vertices[i as usize].position);
    welded
        .chunks_exact(3)
        .flat_map(|t| {
            let normal = (position(t[1]) - position(t[0])).cross(position(t[2]) - position(t[0])).normalize_or_zero();
            (0..3).map(move |e| {
                let others = [t[(e + 1) % 3], t[(e + 2) % 3]];
                let Some(candidates) = corners.at.get(&t[e]) else { return t[e] };
                if candidates.len() == 1 {
                    return candidates[0];
                }
                let score = |v: u32| {
                    let reach =
                        corners.neighbours.get(&v).map_or(0, |n| n.iter().filter(|r| others.contains(r)).count());
                    (reach, glam::Vec3::from(vertices[v as usize].normal).dot(normal))
                };
                // The best score; on equal scores the first candidate.
                let mut best = candidates[0];
                let mut best_score = score(best);
                for &v in &candidates[1..] {
                    let s = score(v);
                    if s.0 > best_score.0 || (s.0 == best_score.0 && s.1 > best_score.1 + 1e-6) {
                        (best, best_score) = (v, s);
                    }
                }
                best
            })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::core::scenes::builtin::uv_sphere;
    use crate::core::scenes::shapes::ClosedMesh;
    use glam::Vec3;

    fn chain_of(vertices: &[SceneVertex], indices: &[u32], floor: usize) -> Vec<Vec<u32>> {
        simplify_chain(vertices, &Welding::of(vertices), indices, floor).0
    }

    #[test]
    fn closed_means_every_directed_edge_once_with_its_reverse() {
        let tetra = [0, 1, 2, 0, 3, 1, 1, 3, 2, 2, 3, 0];
        assert!(is_closed(&tetra));
        assert!(!is_closed(&tetra[..9]), "a face missing");
        let mut flipped = tetra;
        flipped.swap(0, 1);
        assert!(!is_closed(&flipped), "a face wound the other way");
        assert!(!is_closed(&[0, 1, 1]), "degenerate");
        let doubled: Vec<u32> = tetra.iter().chain(&tetra).copied().collect();
        assert!(!is_closed(&doubled), "every edge used four times");
    }

    /// A UV sphere (seam vertices at one position, per-triangle poles) simplifies far, as a
    /// welded surface, and every level is closed; its levels' corners keep their side's UV.
    #[test]
    fn a_uv_sphere_with_seams_simplifies_far_and_stays_closed() {
        let (vertices, indices) = uv_sphere(Vec3::ZERO, 1.0, 32, 16, [1.0; 4]);
        let welding = Welding::of(&vertices);
        assert!(is_closed(&welding.weld(&indices)));
        assert!(!is_closed(&indices), "the sphere's seam splits its vertices");
        let chain = chain_of(&vertices, &indices, indices.len() / 3 / 20);
        assert!(chain.len() >= 6, "{} levels", chain.len());
        assert!(
            chain.last().unwrap().len() * 5 < indices.len(),
            "{} of {}",
            chain.last().unwrap().len(),
            indices.len()
        );
        for level in &chain {
            assert!(is_closed(&welding.weld(level)));
            // No triangle spans the seam's two UV sides (u near 0 and near 1 in one triangle).
            for t in level.chunks_exact(3) {
                let u: Vec<f32> = t.iter().map(|&i| vertices[i as usize].uv[0]).collect();
                let spread = u.iter().fold(0f32, |m, &a| m.max(u.iter().fold(0f32, |n, &b| n.max((a - b).abs()))));
                assert!(spread < 0.5, "a triangle across the seam: u {u:?}");
            }
        }
    }

    /// Grid boxes (flat faces, where collapses can leave three corners on a line): no level has
    /// a triangle without area, and each is closed.
    #[test]
    fn grid_boxes_simplify_without_slivers() {
        for n in [3, 4, 6] {
            let mut scene = crate::core::scenes::scene::Scene::new("box");
            ClosedMesh::grid_box(n).placed(Vec3::new(0.4, 0.05, -0.4), 0.21).add_to(&mut scene, [1.0; 4]);
            let welding = Welding::of(&scene.vertices);
            for (k, level) in chain_of(&scene.vertices, &scene.indices, 1).iter().enumerate() {
                assert!(!has_sliver(&scene.vertices, level), "box {n}, level {k}");
                assert!(is_closed(&welding.weld(level)), "box {n}, level {k}");
            }
        }
    }

    /// Small tori of every proportion: each level of the chain is closed (meshoptimizer alone
    /// collapsed an 8×6 torus into edges used by seven triangles).
    #[test]
    fn small_tori_stay_closed_at_every_level() {
        for (n, m) in [(8, 6), (6, 3), (12, 8), (16, 4), (24, 12)] {
            let mut scene = crate::core::scenes::scene::Scene::new("torus");
            ClosedMesh::torus(n, m).placed(Vec3::new(0.3, -0.2, -2.0), 0.3).add_to(&mut scene, [1.0; 4]);
            let welding = Welding::of(&scene.vertices);
            assert!(is_closed(&welding.weld(&scene.indices)), "torus {n}×{m}");
            for (k, level) in chain_of(&scene.vertices, &scene.indices, 1).iter().enumerate() {
                assert!(is_closed(&welding.weld(level)), "torus {n}×{m}, level {k}");
            }
        }
    }
}
