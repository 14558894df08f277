//! The ray tracer's acceleration structure (`--method trace`, seed 000 §3.4): **one BVH per
//! object and per level of its level-of-detail chain, and a top level over the objects**, as the
//! seed builds per object so that eq. 10 can pick, per ray, the level of each object it meets.
//! Every tree is built on the CPU by obvhs (its medium preset: PLOC clustering and reinsertion,
//! then leaves of up to 8 triangles collapsed by the SAH cost; the top level keeps one object per
//! leaf) and all of them are stored in one flat array of 32-byte binary nodes that the WGSL
//! traversal (`shaders/trace.wgsl`) and its CPU twin (`cpu::trace`) walk as one tree:
//!
//! - `count` = 0: an inner node, children `nodes[first]` and `nodes[first + 1]`;
//! - `count` & [`OBJECT_LEAF`]: a top-level leaf, one object whose chain is
//!   `levels[first .. first + (count & !OBJECT_LEAF)]`, level 0 (the original) first, each
//!   level giving the root of its tree; the walk goes on at the root of the level the ray picks;
//! - otherwise a leaf of `count` triangles, `first .. first + count`, triangles of [`SceneBvh::indices`]
//!   (the triangles of every level, laid out leaf by leaf, so no second indirection is needed).
//!
//! The root is node 0. Objects with a single level (every object, without a level-of-detail
//! chain) share one tree: one top-level leaf over all their triangles. With chains, one more tree
//! over every object's original, not under the top level, is where rays of level 1 start
//! ([`SceneBvh::original_root`]).

use bytemuck::{Pod, Zeroable};
use glam::Vec3A;

use crate::core::scenes::scene::{Scene, SceneVertex};

/// The flag of a top-level leaf's `count` (the rest of `count` is the object's level count).
pub const OBJECT_LEAF: u32 = 0x8000_0000;

/// `BvhNode` in shaders/trace.wgsl. 32 bytes.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct BvhNode {
    pub min: [f32; 3],
    /// First child (inner node), first level (object leaf) or first triangle (leaf).
    pub first: u32,
    pub max: [f32; 3],
    /// 0 for an inner node; [`OBJECT_LEAF`] | levels for an object; else the leaf's triangles.
    pub count: u32,
}

/// `BvhLevel` in shaders/trace.wgsl: one level of an object's chain. 8 bytes.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Pod, Zeroable)]
pub struct BvhLevel {
    /// The node at the root of this level's tree.
    pub root: u32,
    /// Its triangles (eq. 10 picks the coarsest level with at least N_j).
    pub triangles: u32,
}

/// A scene's two-level BVH, in scene coordinates.
#[derive(Clone, Debug, Default)]
pub struct SceneBvh {
    pub nodes: Vec<BvhNode>,
    pub levels: Vec<BvhLevel>,
    /// Three vertex indices per triangle, every level's triangles, leaf by leaf.
    pub indices: Vec<u32>,
    /// Where rays that meet every object's original start (see [`SceneBvh::original_level`]):
    /// the root of a tree over every object's original (its level 0) when some object has a
    /// chain, else the root (node 0). The same hits as through the top level, faster.
    pub original_root: u32,
    /// The largest share of its original that an object's first simplified level keeps
    /// (0 without chains).
    pub first_step: f32,
}

/// The obvhs build of `triangles` (three indices each, over `vertices`), or None if there are none.
fn build_tree(vertices: &[SceneVertex], indices: &[u32]) -> Option<obvhs::bvh2::Bvh2> {
    let triangles: Vec<obvhs::triangle::Triangle> = indices
        .chunks_exact(3)
        .map(|t| {
            let p = |k: usize| Vec3A::from_array(vertices[t[k] as usize].position);
            obvhs::triangle::Triangle { v0: p(0), v1: p(1), v2: p(2) }
        })
        .collect();
    if triangles.is_empty() {
        return None;
    }
    let mut build_time = std::time::Duration::ZERO;
    Some(obvhs::bvh2::builder::build_bvh2_from_tris(&triangles, obvhs::BvhBuildParams::medium_build(), &mut build_time))
}

fn node(n: &obvhs::bvh2::node::Bvh2Node, first: u32, count: u32) -> BvhNode {
    BvhNode { min: n.aabb.min.to_array(), first, max: n.aabb.max.to_array(), count }
}

/// The top level over the objects' boxes, one object per leaf: a leaf's `first` is the
/// object's first level in `levels`, its count `OBJECT_LEAF` | the object's levels.
fn top_level(boxes: &[obvhs::aabb::Aabb], object_levels: &[(u32, u32)]) -> Vec<BvhNode> {
    let params = obvhs::BvhBuildParams { max_prims_per_leaf: 1, ..obvhs::BvhBuildParams::medium_build() };
    let mut build_time = std::time::Duration::ZERO;
    let top = obvhs::bvh2::builder::build_bvh2(boxes, params, &mut build_time);
    top.nodes
        .iter()
        .map(|n| {
            if n.prim_count == 0 {
                node(n, n.first_index, 0)
            } else {
                assert_eq!(n.prim_count, 1, "one object per top-level leaf");
                let (first_level, count) = object_levels[top.primitive_indices[n.first_index as usize] as usize];
                node(n, first_level, OBJECT_LEAF | count)
            }
        })
        .collect()
}

impl SceneBvh {
    /// The BVH of a scene drawn as it is: one level per object.
    pub fn of_scene(scene: &Scene) -> SceneBvh {
        let chains: Vec<Vec<Vec<u32>>> = scene
            .objects
            .iter()
            .map(|o| {
                let first = 3 * o.first_triangle as usize;
                vec![scene.indices[first..first + 3 * o.triangle_count as usize].to_vec()]
            })
            .collect();
        SceneBvh::build(&scene.vertices, &chains)
    }

    /// Builds the BVH of objects given as chains of levels (`chains[object][level]`: three
    /// indices into `vertices` per triangle, level 0 the original, each level coarser than the
    /// one before, as `LodChain::levels`). The objects with one level only share one tree (a
    /// top level over objects whose boxes overlap, as in an atrium, costs rays up to twice the
    /// time of one tree over all their triangles); each object with a chain
    /// gets a tree per level, and then one more tree over every object's original serves the
    /// rays that meet the originals everywhere (level 1: the central field), at plain tracing's
    /// speed ([`SceneBvh::original_root`]). Objects without triangles are left out; an empty
    /// scene gets one leaf with an empty box, which no ray enters.
    pub fn build(vertices: &[SceneVertex], chains: &[Vec<Vec<u32>>]) -> SceneBvh {
        let mut out = SceneBvh::default();
        let pooled: Vec<u32> = chains.iter().filter(|c| c.len() == 1).flat_map(|c| c[0].iter().copied()).collect();
        let groups: Vec<Vec<&[u32]>> = chains
            .iter()
            .filter(|c| c.len() > 1)
            .map(|c| c.iter().map(|l| l.as_slice()).collect())
            .chain((!pooled.is_empty()).then(|| vec![pooled.as_slice()]))
            .collect();
        let mut subtrees: Vec<BvhNode> = Vec::new();
        // Appends the tree of `level`'s triangles to the subtrees and its triangles (leaf by
        // leaf) to the indices; its root (in the subtrees) and box.
        let mut add_tree = |level: &[u32], out: &mut SceneBvh| {
            let tree = build_tree(vertices, level)?;
            let (base, triangle_base) = (subtrees.len() as u32, (out.indices.len() / 3) as u32);
            for n in &tree.nodes {
                subtrees.push(if n.prim_count == 0 {
                    node(n, base + n.first_index, 0)
                } else {
                    node(n, triangle_base + n.first_index, n.prim_count)
                });
            }
            for &p in &tree.primitive_indices {
                out.indices.extend_from_slice(&level[3 * p as usize..3 * p as usize + 3]);
            }
            Some((base, tree.nodes[0].aabb))
        };
        // The top level over the groups' boxes (their level 0's root box), one group per leaf.
        let mut boxes = Vec::new();
        let mut object_levels = Vec::new();
        for chain in &groups {
            let first_level = out.levels.len() as u32;
            let mut object_box = None;
            for level in chain {
                let Some((root, b)) = add_tree(level, &mut out) else { continue };
                object_box.get_or_insert(b);
                out.levels.push(BvhLevel { root, triangles: (level.len() / 3) as u32 });
            }
            if let Some(b) = object_box {
                boxes.push(b);
                object_levels.push((first_level, out.levels.len() as u32 - first_level));
            }
        }
        if boxes.is_empty() {
            out.nodes = vec![BvhNode { min: [1.0; 3], max: [-1.0; 3], first: 0, count: 1 }];
            out.indices = vec![0; 3];
            return out;
        }
        let original = if chains.iter().any(|c| c.len() > 1) {
            let all: Vec<u32> = chains.iter().filter_map(|c| c.first()).flat_map(|l| l.iter().copied()).collect();
            add_tree(&all, &mut out).map(|(root, _)| root)
        } else {
            None
        };
        out.nodes = top_level(&boxes, &object_levels);
        let top_len = out.nodes.len() as u32;
        // The subtrees follow the top level: shift their inner nodes' child indices and roots.
        out.nodes.extend(subtrees.into_iter().map(|n| {
            if n.count == 0 {
                BvhNode { first: n.first + top_len, ..n }
            } else {
                n
            }
        }));
        for l in &mut out.levels {
            l.root += top_len;
        }
        out.original_root = original.map_or(0, |r| r + top_len);
        out.first_step =
            chains.iter().filter(|c| c.len() > 1).map(|c| c[1].len() as f32 / c[0].len() as f32).fold(0.0, f32::max);
        out
    }

    /// The visual level above which eq. 10 picks every object's original (N_j above each
    /// object's first simplified level), so that rays start at [`SceneBvh::original_root`]
    /// (`original_level` in trace.wgsl's parameters); −1 without chains (every ray does).
    pub fn original_level(&self, min_share: f32) -> f32 {
        SceneBvh::original_level_of(self.first_step, min_share)
    }

    /// [`SceneBvh::original_level`] from [`SceneBvh::first_step`].
    pub fn original_level_of(first_step: f32, min_share: f32) -> f32 {
        if first_step <= 0.0 {
            -1.0
        } else {
            ((first_step - min_share) / (1.0 - min_share)).min(1.0)
        }
    }

    /// The deepest path from the root through any level's tree (the traversal's stack needs at
    /// most this many entries).
    pub fn depth(&self) -> u32 {
        let mut deepest = 0;
        let mut stack = vec![(0usize, 1u32), (self.original_root as usize, 1u32)];
        while let Some((i, d)) = stack.pop() {
            deepest = deepest.max(d);
            let n = &self.nodes[i];
            if n.count == 0 {
                stack.push((n.first as usize, d + 1));
                stack.push((n.first as usize + 1, d + 1));
            } else if n.count & OBJECT_LEAF != 0 {
                let levels = n.first as usize..(n.first + (n.count & !OBJECT_LEAF)) as usize;
                stack.extend(self.levels[levels].iter().map(|l| (l.root as usize, d)));
            }
        }
        deepest
    }

    /// The level of an object's chain (`levels`, level 0 first) that a ray of visual level
    /// `level` meets (seed 000 eq. 10): N_j = level·(N_max − N_min) + N_min with N_max the
    /// original's triangles and N_min = `min_share`·N_max, and the coarsest level with at least
    /// N_j triangles (`pick_level` in trace.wgsl).
    pub fn pick_level(levels: &[BvhLevel], level: f32, min_share: f32) -> usize {
        let max = levels[0].triangles as f32;
        let wanted = level * (max - min_share * max) + min_share * max;
        // The levels' counts fall along the chain: the last one still ≥ N_j (rays near the
        // central field stop at the first step).
        (1..levels.len()).take_while(|&k| levels[k].triangles as f32 >= wanted).last().unwrap_or(0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::core::detail::lod::LodChain;
    use crate::core::scenes::builtin::sphere_scene;
    use glam::Vec3;

    fn levels(counts: &[u32]) -> Vec<BvhLevel> {
        counts.iter().map(|&triangles| BvhLevel { root: 0, triangles }).collect()
    }

    #[test]
    fn eq_10_picks_the_coarsest_level_with_enough_triangles() {
        let chain = levels(&[1000, 700, 490, 343, 240, 168, 118, 100]);
        // N_min = 0.1 · 1000 = 100: level 1 wants all 1000, level 0 wants 100.
        assert_eq!(SceneBvh::pick_level(&chain, 1.0, 0.1), 0);
        assert_eq!(SceneBvh::pick_level(&chain, 0.0, 0.1), 7);
        // Level 0.5: N_j = 0.5 · 900 + 100 = 550 → 700 is the coarsest with ≥ 550.
        assert_eq!(SceneBvh::pick_level(&chain, 0.5, 0.1), 1);
        // Level 0.2: N_j = 280 → 343.
        assert_eq!(SceneBvh::pick_level(&chain, 0.2, 0.1), 3);
        // N_j exactly a level's count takes that level.
        assert_eq!(SceneBvh::pick_level(&levels(&[1000, 550, 300]), 0.5, 0.1), 1);
        // A chain that stops above N_min: its coarsest level serves every ray below it.
        assert_eq!(SceneBvh::pick_level(&levels(&[1000, 700]), 0.0, 0.05), 1);
        assert_eq!(SceneBvh::pick_level(&levels(&[50]), 0.0, 0.05), 0);
    }

    /// Every level's triangles lie exactly once in the leaves under its root, inside every box
    /// on their way; each object is one top-level leaf listing its chain.
    #[test]
    fn each_level_tree_holds_its_triangles_once_inside_its_boxes() {
        let mut scene = Scene::new("three");
        for (k, x) in [-2.0f32, 0.0, 2.0].into_iter().enumerate() {
            let s = sphere_scene(1500 + 500 * k as u32, Vec3::new(x, 0.0, -3.0), 0.5, "s");
            scene.add_mesh(format!("s{k}"), &s.vertices, &s.indices);
        }
        let chain = LodChain::build(&scene, 0.1);
        let bvh = SceneBvh::build(&scene.vertices, &chain.levels);
        let mut objects = Vec::new();
        let mut stack = vec![0usize];
        while let Some(i) = stack.pop() {
            let n = bvh.nodes[i];
            if n.count == 0 {
                stack.extend([n.first as usize, n.first as usize + 1]);
            } else {
                assert!(n.count & OBJECT_LEAF != 0, "the top level holds objects only");
                objects.push((n.first, n.count & !OBJECT_LEAF));
            }
        }
        objects.sort();
        assert_eq!(objects.len(), 3);
        let mut seen = vec![0u32; bvh.indices.len() / 3];
        // The triangles under a root, every box holding its children and triangles.
        let walk = |root: u32, seen: &mut Vec<u32>| {
            let mut found: Vec<[u32; 3]> = Vec::new();
            let mut stack = vec![root as usize];
            while let Some(i) = stack.pop() {
                let n = bvh.nodes[i];
                let inside = |p: [f32; 3]| (0..3).all(|a| n.min[a] <= p[a] && p[a] <= n.max[a]);
                if n.count == 0 {
                    stack.extend([n.first as usize, n.first as usize + 1]);
                    for c in [bvh.nodes[n.first as usize], bvh.nodes[n.first as usize + 1]] {
                        assert!(inside(c.min) && inside(c.max), "child box outside its parent");
                    }
                } else {
                    assert!(n.count & OBJECT_LEAF == 0);
                    for t in n.first..n.first + n.count {
                        seen[t as usize] += 1;
                        let tri = [0, 1, 2].map(|k| bvh.indices[3 * t as usize + k]);
                        assert!(tri.iter().all(|&v| inside(scene.vertices[v as usize].position)));
                        found.push(tri);
                    }
                }
            }
            found.sort();
            found
        };
        let sorted = |l: &[u32]| {
            let mut v: Vec<[u32; 3]> = l.chunks_exact(3).map(|t| [t[0], t[1], t[2]]).collect();
            v.sort();
            v
        };
        for ((first, count), levels) in objects.iter().zip(&chain.levels) {
            assert_eq!(*count as usize, levels.len());
            for (level, expected) in bvh.levels[*first as usize..(*first + *count) as usize].iter().zip(levels) {
                assert_eq!(level.triangles as usize, expected.len() / 3);
                assert_eq!(walk(level.root, &mut seen), sorted(expected));
            }
        }
        // Rays of level 1 start at one tree over every original.
        assert_ne!(bvh.original_root, 0);
        let originals: Vec<u32> = chain.levels.iter().flat_map(|l| l[0].iter().copied()).collect();
        assert_eq!(walk(bvh.original_root, &mut seen), sorted(&originals));
        assert!(seen.iter().all(|&s| s == 1), "every triangle in exactly one leaf");
        assert!(bvh.depth() > 3);
        // Without chains, the objects share one tree under one top-level leaf.
        let flat = SceneBvh::of_scene(&scene);
        assert_eq!((flat.nodes[0].first, flat.nodes[0].count), (0, OBJECT_LEAF | 1));
        assert_eq!(flat.levels, [BvhLevel { root: 1, triangles: scene.triangle_count() as u32 }]);
        assert_eq!(flat.indices.len(), scene.indices.len());
        assert_eq!(flat.original_root, 0);
    }

    #[test]
    fn an_empty_scene_has_one_empty_leaf() {
        let bvh = SceneBvh::of_scene(&Scene::new("empty"));
        assert_eq!(bvh.nodes.len(), 1);
        assert!(bvh.nodes[0].min[0] > bvh.nodes[0].max[0]);
    }
}
