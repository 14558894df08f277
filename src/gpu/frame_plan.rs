//! The subdivision's GPU buffers, kept by the renderer across frames and grown as a frame's
//! schedule ([`crate::encoding::schedule`]) asks.

use crate::encoding::schedule::{Capacities, INDICES_SIZE, ITEM_SIZE, NODE_SIZE, RECORD_SIZE, WORK_SIZE};
use crate::encoding::subdivide::DISPATCH_WORDS;
use crate::encoding::types::{DrawIndexedIndirectArgs, SubdivideCounters};
use crate::gpu::device::Gpu;
use crate::gpu::scene::GpuScene;

/// The subdivision's GPU buffers, with their capacities; kept by the renderer across frames.
pub struct SubdivisionBuffers {
    pub pieces: wgpu::Buffer,
    /// The parts `plan_cuts` cuts, for `plan_parts`: as many as `pieces` (each makes a piece or more).
    pub parts: wgpu::Buffer,
    /// What `lattice` planned for each piece (as many as `pieces`).
    pub piece_work: wgpu::Buffer,
    /// `lattice`'s work items: room for one per output unit.
    pub lattice_work: wgpu::Buffer,
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

fn pieces_buffer(gpu: &Gpu, label: &str, n: u32) -> wgpu::Buffer {
    gpu.storage_buffer(label, n.max(1) as u64 * RECORD_SIZE, wgpu::BufferUsages::empty())
}

fn work_buffer(gpu: &Gpu, n: u32) -> wgpu::Buffer {
    gpu.storage_buffer("piece work", n.max(1) as u64 * WORK_SIZE, wgpu::BufferUsages::empty())
}

/// The output's nodes and indices, and the work items (one per output unit).
fn output_buffers(gpu: &Gpu, n: u32) -> (wgpu::Buffer, wgpu::Buffer, wgpu::Buffer) {
    (
        gpu.storage_buffer("subdivided nodes", n.max(1) as u64 * NODE_SIZE, wgpu::BufferUsages::VERTEX),
        gpu.storage_buffer("subdivided triangles", n.max(1) as u64 * INDICES_SIZE, wgpu::BufferUsages::INDEX),
        gpu.storage_buffer("lattice work", n.max(1) as u64 * ITEM_SIZE, wgpu::BufferUsages::empty()),
    )
}

impl SubdivisionBuffers {
    pub fn new(gpu: &Gpu, capacity: Capacities) -> SubdivisionBuffers {
        let capacity = Capacities { pieces: capacity.pieces.max(1), triangles: capacity.triangles.max(1) };
        let (nodes, indices, lattice_work) = output_buffers(gpu, capacity.triangles);
        SubdivisionBuffers {
            pieces: pieces_buffer(gpu, "pieces", capacity.pieces),
            parts: pieces_buffer(gpu, "parts", capacity.pieces),
            piece_work: work_buffer(gpu, capacity.pieces),
            lattice_work,
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
            lattice_dispatch: gpu.storage_buffer(
                "lattice dispatch",
                4 * DISPATCH_WORDS as u64,
                wgpu::BufferUsages::INDIRECT,
            ),
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
                    b.pieces = pieces_buffer(gpu, "pieces", want.pieces);
                    b.parts = pieces_buffer(gpu, "parts", want.pieces);
                    b.piece_work = work_buffer(gpu, want.pieces);
                    b.capacity.pieces = want.pieces;
                }
                if b.capacity.triangles < want.triangles {
                    (b.nodes, b.indices, b.lattice_work) = output_buffers(gpu, want.triangles);
                    b.capacity.triangles = want.triangles;
                }
            }
        }
        cache.as_ref().expect("just made")
    }
}
