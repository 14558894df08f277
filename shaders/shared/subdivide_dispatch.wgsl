// The `subdivide` stage's dispatch helpers: an invocation's index in a dispatch spread over two
// dimensions, and the triangles `plan` listed for `plan_cuts` (CPU twin: `listed_cuts` in
// src/cpu/subdivide/passes.rs).

#import constants
#import projection
#import subdivide_types
#import subdivide_bindings

fn invocation_index(gid: vec3<u32>, groups: vec3<u32>) -> u32 {
    return gid.x + gid.y * groups.x * 64u;
}

// An indirect dispatch's workgroup counts at word `at` of `lattice_dispatch`, for `invocations`
// in workgroups of 64 spread over two dimensions (`set_dispatch` in src/cpu/subdivide/passes.rs).
fn set_dispatch(at: u32, invocations: u32) {
    let groups = (invocations + 63u) / 64u;
    lattice_dispatch[at] = min(groups, 65535u);
    lattice_dispatch[at + 1u] = (groups + 65534u) / 65535u;
    lattice_dispatch[at + 2u] = 1u;
}

// The triangles `plan` listed, and the i-th of them: the narrow ones from the front of
// `cut_list`, then the wide ones from its back.
fn listed_cuts() -> vec2<u32> {
    let len = arrayLength(&cut_list);
    return vec2<u32>(min(atomicLoad(&counters.cut_count), len), min(atomicLoad(&counters.cut_wide), len));
}

fn listed_cut(i: u32, listed: vec2<u32>) -> u32 {
    if (i < listed.x) {
        return cut_list[i];
    }
    return cut_list[arrayLength(&cut_list) - 1u - (i - listed.x)];
}

// The pieces `lattice` and its rows' passes run over: a range's, or as many as were counted.
fn pieces_planned() -> u32 {
    if (params.piece_count == PIECES_FROM_COUNTER) {
        return min(atomicLoad(&counters.pieces), params.piece_capacity);
    }
    return params.piece_count;
}

// The work items `lattice` appended: (node items, triangle items), within `lattice_work`'s room
// (`work_items` in src/cpu/subdivide/passes.rs).
fn work_items() -> vec2<u32> {
    let len = params.triangle_capacity;
    return vec2<u32>(min(atomicLoad(&counters.node_items), len), min(atomicLoad(&counters.triangle_items), len));
}

// Room for `lattice`'s row items: the output's indices, 3 per output unit.
fn row_item_room() -> u32 {
    return 3u * params.triangle_capacity;
}

// Where row item i lies: the output's index buffer from its back, so that the triangles of
// pieces written in place (from its front) meet them only when the output overflows
// (`SubdivideCounters::output_units` counts both).
fn row_item_slot(i: u32) -> u32 {
    return row_item_room() - 1u - i;
}

// The pieces `lattice` listed for `lattice_rows_plan` (in `parts`), within its room.
fn pending_count() -> u32 {
    return min(atomicLoad(&counters.pending), params.piece_capacity);
}

// The row items `lattice` appended, within their room.
fn row_item_count() -> u32 {
    return min(atomicLoad(&counters.row_items), row_item_room());
}
