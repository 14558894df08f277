//! A bounding volume hierarchy over a scene's triangles, for the ray tracer (`--method trace`,
//! seed 000): built on the CPU by obvhs (its medium preset: PLOC clustering and reinsertion, then
//! leaves of up to 8 triangles collapsed by the SAH cost), stored as a flat array of 32-byte binary
//! nodes that the WGSL traversal (`shaders/trace.wgsl`) and its CPU twin (`cpu::trace`) walk.
//!
//! A node with `count` = 0 is inner: its children are `nodes[first]` and `nodes[first + 1]`.
//! Else it is a leaf of `count` triangles, `primitives[first .. first + count]` (triangle
//! indices). The root is node 0.

use bytemuck::{Pod, Zeroable};
use glam::Vec3A;

use crate::core::scene::SceneVertex;

/// `BvhNode` in shaders/trace.wgsl. 32 bytes.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct BvhNode {
    pub min: [f32; 3],
    /// First child (inner node) or first entry of `primitives` (leaf).
    pub first: u32,
    pub max: [f32; 3],
    /// Triangles in the leaf; 0 for an inner node.
    pub count: u32,
}

/// A scene's BVH, in scene coordinates.
#[derive(Clone, Debug, Default)]
pub struct SceneBvh {
    pub nodes: Vec<BvhNode>,
    /// Triangle indices, leaf by leaf.
    pub primitives: Vec<u32>,
}

impl SceneBvh {
    /// Builds the BVH of the triangles `indices` (three per triangle) over `vertices`. An empty
    /// scene gets one leaf with an empty box, which no ray enters.
    pub fn build(vertices: &[SceneVertex], indices: &[u32]) -> SceneBvh {
        let triangles: Vec<obvhs::triangle::Triangle> = indices
            .chunks_exact(3)
            .map(|t| {
                let p = |k: usize| Vec3A::from_array(vertices[t[k] as usize].position);
                obvhs::triangle::Triangle { v0: p(0), v1: p(1), v2: p(2) }
            })
            .collect();
        if triangles.is_empty() {
            let empty = BvhNode { min: [1.0; 3], max: [-1.0; 3], first: 0, count: 1 };
            return SceneBvh { nodes: vec![empty], primitives: vec![0] };
        }
        let mut build_time = std::time::Duration::ZERO;
        let bvh = obvhs::bvh2::builder::build_bvh2_from_tris(
            &triangles,
            obvhs::BvhBuildParams::medium_build(),
            &mut build_time,
        );
        let nodes = bvh
            .nodes
            .iter()
            .map(|n| BvhNode {
                min: n.aabb.min.to_array(),
                first: n.first_index,
                max: n.aabb.max.to_array(),
                count: n.prim_count,
            })
            .collect();
        SceneBvh { nodes, primitives: bvh.primitive_indices }
    }

    /// The deepest path from the root (the traversal's stack needs at most this many entries).
    pub fn depth(&self) -> u32 {
        let mut deepest = 0;
        let mut stack = vec![(0usize, 1u32)];
        while let Some((i, d)) = stack.pop() {
            deepest = deepest.max(d);
            let n = &self.nodes[i];
            if n.count == 0 {
                stack.push((n.first as usize, d + 1));
                stack.push((n.first as usize + 1, d + 1));
            }
        }
        deepest
    }
}
