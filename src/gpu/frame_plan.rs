//! How one frame's subdivision and raster are scheduled, and the subdivision buffers they use.
//!
//! Memory: the piece and output buffers (nodes and triangle indices) together stay within `memory_mb` (and each within the
//! device's storage-binding limit). Both passes count what they wanted to write and never
//! write past the end. The usual frame is [`FramePlan::OneSubmission`]: `plan` → `lattice`
//! (sized on the GPU from the piece counter) → `finalize` → both eyes, then one read of the
//! counters. When that overflowed a buffer, the frame is redone [`FramePlan::Chunked`]: a
//! `plan` over a range of triangles that overflows grows the piece buffer if the budget
//! allows, else the range is halved; likewise a `lattice` over a range of pieces and the
//! output buffer. Ranges are drawn one after another into the same targets (`chunks` in the
//! stats), so nothing is dropped; a single piece that cannot fit is an error.

use crate::encoding::types::{DrawIndexedIndirectArgs, DrawVertex, Piece, SubdivideCounters};
use crate::gpu::device::Gpu;
use crate::gpu::scene::GpuScene;

pub const PIECE_SIZE: u64 = std::mem::size_of::<Piece>() as u64;
/// Bytes of one output node.
pub const NODE_SIZE: u64 = std::mem::size_of::<DrawVertex>() as u64;
/// Bytes of one output triangle's indices.
pub const INDICES_SIZE: u64 = 3 * 4;
/// Bytes of one unit of output capacity: room for a node and for a triangle's indices (the
/// lattices make about one node per output triangle or fewer: (m + 1)(m + 2)/2 for m²).
pub const OUTPUT_UNIT_SIZE: u64 = NODE_SIZE + INDICES_SIZE;

/// Capacities of the piece and output buffers: pieces, and output units (each a node and a
/// triangle's indices; `triangles` also caps the nodes).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Capacities {
    pub pieces: u32,
    pub triangles: u32,
}

impl Capacities {
    /// What a memory budget allows: a quarter for pieces, the rest for the output (nodes and
    /// indices), each buffer within the largest binding.
    pub fn budget(memory_mb: u32, max_binding: u64) -> Capacities {
        let budget = memory_mb as u64 * (1 << 20);
        let pieces = (budget / 4).min(max_binding) / PIECE_SIZE;
        let triangles = ((budget - budget / 4) / OUTPUT_UNIT_SIZE).min(max_binding / NODE_SIZE);
        Capacities { pieces: pieces.min(u32::MAX as u64) as u32, triangles: triangles.min(u32::MAX as u64) as u32 }
    }

    pub fn min(self, other: Capacities) -> Capacities {
        Capacities { pieces: self.pieces.min(other.pieces), triangles: self.triangles.min(other.triangles) }
    }

    /// A first guess for a scene of `triangles` input triangles (a triangle is a piece or more:
    /// the cuts around the axis make a few parts of some, the pre-split pieces of large ones).
    pub fn guess(triangles: u32) -> Capacities {
        Capacities {
            pieces: triangles.saturating_mul(2).saturating_add(4096),
            triangles: triangles.saturating_mul(4).saturating_add(4096),
        }
    }
}

/// How a frame runs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FramePlan {
    /// Everything in one submission, with these capacities.
    OneSubmission(Capacities),
    /// Triangle ranges and piece ranges, each drawn in turn, starting from the capacities
    /// wanted and growing within the budget.
    Chunked { want: Capacities, budget: Capacities },
}

impl FramePlan {
    /// The usual plan: one submission with the cached buffers' capacities (or a guess from the
    /// triangle count), never beyond the budget.
    pub fn first(triangles: u32, cached: Option<Capacities>, budget: Capacities) -> FramePlan {
        FramePlan::OneSubmission(cached.unwrap_or(Capacities::guess(triangles)).min(budget))
    }

    /// The plan after a one-submission frame overflowed its buffers.
    pub fn after_overflow(self, budget: Capacities) -> FramePlan {
        match self {
            FramePlan::OneSubmission(want) | FramePlan::Chunked { want, .. } => FramePlan::Chunked { want, budget },
        }
    }
}

/// What to do when a pass wanted `requested` slots of a buffer holding at most `max` within the
/// budget, after running over `count` items.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Overflow {
    /// Grow the buffer to `requested` and run the same range again.
    Grow(u32),
    /// Run half the range.
    Halve(u32),
    /// A single item does not fit.
    TooBig,
}

pub fn on_overflow(requested: u32, max: u32, count: u32) -> Overflow {
    if requested <= max {
        Overflow::Grow(requested)
    } else if count > 1 {
        Overflow::Halve(count / 2)
    } else {
        Overflow::TooBig
    }
}

/// The subdivision's GPU buffers, with their capacities; kept by the renderer across frames.
pub struct SubdivisionBuffers {
    pub pieces: wgpu::Buffer,
    /// The output: lattice nodes (the raster's vertex buffer) and triangles' indices into them.
    pub nodes: wgpu::Buffer,
    pub indices: wgpu::Buffer,
    pub counters: wgpu::Buffer,
    pub draw_args: wgpu::Buffer,
    /// Indirect dispatch arguments of `lattice` (in the one-submission frame) and `plan_cuts`.
    pub lattice_dispatch: wgpu::Buffer,
    /// The triangles `plan` leaves to `plan_cuts`: room for every triangle of the scene.
    pub cut_list: wgpu::Buffer,
    pub cut_list_capacity: u32,
    /// Two bits per shared edge of the scene, set by `active_cuts` and `ring_cuts` each frame
    /// (the frame's scratch: the uploaded scene holds only the edges' numbers), and its words.
    pub cut_edges: wgpu::Buffer,
    pub cut_edge_words: u32,
    pub capacity: Capacities,
}

fn cut_edges_buffer(gpu: &Gpu, words: u32) -> wgpu::Buffer {
    gpu.storage_buffer("cut edges", 4 * words.max(1) as u64, wgpu::BufferUsages::empty())
}

fn pieces_buffer(gpu: &Gpu, n: u32) -> wgpu::Buffer {
    gpu.storage_buffer("pieces", n.max(1) as u64 * PIECE_SIZE, wgpu::BufferUsages::empty())
}

fn output_buffers(gpu: &Gpu, n: u32) -> (wgpu::Buffer, wgpu::Buffer) {
    (
        gpu.storage_buffer("subdivided nodes", n.max(1) as u64 * NODE_SIZE, wgpu::BufferUsages::VERTEX),
        gpu.storage_buffer("subdivided triangles", n.max(1) as u64 * INDICES_SIZE, wgpu::BufferUsages::INDEX),
    )
}

impl SubdivisionBuffers {
    pub fn new(gpu: &Gpu, capacity: Capacities) -> SubdivisionBuffers {
        let capacity = Capacities { pieces: capacity.pieces.max(1), triangles: capacity.triangles.max(1) };
        let (nodes, indices) = output_buffers(gpu, capacity.triangles);
        SubdivisionBuffers {
            pieces: pieces_buffer(gpu, capacity.pieces),
            nodes,
            indices,
            counters: gpu.storage_buffer(
                "counters",
                std::mem::size_of::<SubdivideCounters>() as u64,
                wgpu::BufferUsages::empty(),
            ),
            draw_args: gpu.storage_buffer(
                "draw args",
                std::mem::size_of::<DrawIndexedIndirectArgs>() as u64,
                wgpu::BufferUsages::INDIRECT,
            ),
            lattice_dispatch: gpu.storage_buffer("lattice dispatch", 24, wgpu::BufferUsages::INDIRECT),
            cut_list: gpu.storage_buffer("cut list", 4, wgpu::BufferUsages::empty()),
            cut_list_capacity: 1,
            cut_edges: cut_edges_buffer(gpu, 1),
            cut_edge_words: 1,
            capacity,
        }
    }

    /// Makes sure the cached buffers hold at least `want`. Each buffer is replaced only if it is
    /// too small, so growing the output keeps the pieces already planned.
    /// The cut list gets room for the scene's triangles (at most what one binding holds:
    /// [`SubdivisionBuffers::cut_list_capacity`] bounds a dispatch's triangles), the edge marks
    /// for its shared edges.
    pub fn ensure<'c>(
        cache: &'c mut Option<SubdivisionBuffers>,
        gpu: &Gpu,
        want: Capacities,
        scene: &GpuScene,
    ) -> &'c SubdivisionBuffers {
        let cut_list = (scene.triangle_count as u64).min(gpu.max_binding() / 4).max(1) as u32;
        if let Some(b) = cache.as_mut() {
            if b.cut_list_capacity < cut_list {
                b.cut_list = gpu.storage_buffer("cut list", 4 * cut_list as u64, wgpu::BufferUsages::empty());
                b.cut_list_capacity = cut_list;
            }
            if b.cut_edge_words < scene.cut_edge_words {
                b.cut_edges = cut_edges_buffer(gpu, scene.cut_edge_words);
                b.cut_edge_words = scene.cut_edge_words;
            }
        }
        match cache {
            None => {
                let mut b = SubdivisionBuffers::new(gpu, want);
                b.cut_list = gpu.storage_buffer("cut list", 4 * cut_list as u64, wgpu::BufferUsages::empty());
                b.cut_list_capacity = cut_list;
                b.cut_edges = cut_edges_buffer(gpu, scene.cut_edge_words);
                b.cut_edge_words = scene.cut_edge_words;
                *cache = Some(b);
            }
            Some(b) => {
                if b.capacity.pieces < want.pieces {
                    b.pieces = pieces_buffer(gpu, want.pieces);
                    b.capacity.pieces = want.pieces;
                }
                if b.capacity.triangles < want.triangles {
                    (b.nodes, b.indices) = output_buffers(gpu, want.triangles);
                    b.capacity.triangles = want.triangles;
                }
            }
        }
        cache.as_ref().expect("just made")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn overflow_grows_within_the_budget_else_halves_else_fails() {
        assert_eq!(on_overflow(100, 200, 50), Overflow::Grow(100));
        assert_eq!(on_overflow(300, 200, 50), Overflow::Halve(25));
        assert_eq!(on_overflow(300, 200, 1), Overflow::TooBig);
    }

    #[test]
    fn the_first_plan_never_exceeds_the_budget() {
        let budget = Capacities::budget(8, u64::MAX);
        assert_eq!(budget.pieces as u64, 2 * (1 << 20) / PIECE_SIZE);
        match FramePlan::first(10_000_000, None, budget) {
            FramePlan::OneSubmission(c) => assert_eq!(c, budget),
            other => panic!("{other:?}"),
        }
        let small = Capacities { pieces: 10, triangles: 20 };
        assert_eq!(FramePlan::first(5, Some(small), budget), FramePlan::OneSubmission(small));
        assert_eq!(FramePlan::OneSubmission(small).after_overflow(budget), FramePlan::Chunked { want: small, budget });
    }
}
