//! A stage's schedule as data (as vello's `Recording`): the buffers it clears, its compute passes
//! and, in each, the entry points it dispatches — over a number of invocations, or indirectly from
//! arguments a previous dispatch wrote. An engine replays a recording; the subdivision's two
//! schedules are recordings (`one_submission`, `active_cuts` and `pass_run` in the subdivide
//! stage's encoding).
//! Buffers are [`SubdivideBuffer`] handles (as vello's `BufferProxy`): each engine resolves
//! every one, by an exhaustive match, to its own storage.

/// The buffers of a subdivision frame, as a recording names them and as the stage's bindings
/// bind them (several WGSL variables may bind one buffer: [`SubdivideBuffer::bound_as`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum SubdivideBuffer {
    Params,
    Vertices,
    Indices,
    Pieces,
    Parts,
    PieceWork,
    LatticeWork,
    OutNodes,
    Counters,
    DrawArgs,
    LatticeDispatch,
    ObjectEdgeScale,
    CutList,
    /// The output indices (also bound as `row_items`, the rows' items before the lattice).
    OutIndices,
    TriangleEdges,
    /// The frame's marked edges (also bound read-only as `edge_marks_read`).
    CutEdges,
}

impl SubdivideBuffer {
    /// The buffer a WGSL variable of the subdivide stage binds (`shader::SUBDIVIDE.bindings`);
    /// None for a name the stage does not bind (`tests/shaders.rs` checks every binding has one).
    pub fn bound_as(name: &str) -> Option<SubdivideBuffer> {
        use SubdivideBuffer::*;
        Some(match name {
            "params" => Params,
            "vertices" => Vertices,
            "indices" => Indices,
            "pieces" => Pieces,
            "parts" => Parts,
            "piece_work" => PieceWork,
            "lattice_work" => LatticeWork,
            "out_nodes" => OutNodes,
            "counters" => Counters,
            "draw_args" => DrawArgs,
            "lattice_dispatch" => LatticeDispatch,
            "object_edge_scale" => ObjectEdgeScale,
            "cut_list" => CutList,
            "out_indices" | "row_items" => OutIndices,
            "triangle_edges" => TriangleEdges,
            "cut_edges" | "edge_marks_read" => CutEdges,
            _ => return None,
        })
    }
}

/// One step of a recording.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Command {
    /// Clears a buffer to zero: its first `bytes`, or all of it.
    Clear { buffer: SubdivideBuffer, bytes: Option<u64> },
    /// Begins a compute pass (ending the one before); `timestamp`: the first of its two query
    /// indices, where the frame is timed.
    Pass { label: &'static str, timestamp: Option<u32> },
    /// Dispatches `entry` over `invocations` (in workgroups of 64, spread over two dimensions
    /// where one is not enough) or, for a one-thread setup entry, 1.
    Dispatch { entry: &'static str, invocations: u32 },
    /// Dispatches `entry` with the workgroup counts at `offset` in `args`.
    DispatchIndirect { entry: &'static str, args: SubdivideBuffer, offset: u64 },
}

/// A schedule: commands in order.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Recording {
    pub commands: Vec<Command>,
}

impl Recording {
    pub fn clear(&mut self, buffer: SubdivideBuffer, bytes: Option<u64>) -> &mut Self {
        self.commands.push(Command::Clear { buffer, bytes });
        self
    }

    pub fn pass(&mut self, label: &'static str, timestamp: Option<u32>) -> &mut Self {
        self.commands.push(Command::Pass { label, timestamp });
        self
    }

    pub fn dispatch(&mut self, entry: &'static str, invocations: u32) -> &mut Self {
        self.commands.push(Command::Dispatch { entry, invocations });
        self
    }

    pub fn dispatch_indirect(&mut self, entry: &'static str, args: SubdivideBuffer, offset: u64) -> &mut Self {
        self.commands.push(Command::DispatchIndirect { entry, args, offset });
        self
    }

    /// The entry points it dispatches, in order.
    pub fn entries(&self) -> impl Iterator<Item = &'static str> + '_ {
        self.commands.iter().filter_map(|c| match *c {
            Command::Dispatch { entry, .. } | Command::DispatchIndirect { entry, .. } => Some(entry),
            _ => None,
        })
    }
}
