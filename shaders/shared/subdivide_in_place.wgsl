// A piece of one work item's worth written where `plan_work` plans it, as its items would write it
// (its stand-in `subdivide_in_place_off` in the pipelines of the frames that measure rows, which
// never write in place: the code merely present cost their `lattice` pass registers). CPU twin:
// `CpuSubdivision::plan_work`.

#import subdivide_types
#import subdivide_bindings
#import subdivide_state
#import subdivide_work

fn write_in_place(index: u32, work: PieceWork, tri: ptr<function, InputTriangle>, part: ptr<function, PartPlan>, piece_state: ptr<function, PieceState>) {
    if (work.first_node + work.copies * work.node_count <= params.triangle_capacity) {
        write_nodes(0u, index, work, tri, part, piece_state);
        write_triangles(vec4<u32>(index, 0u, 0u, 0u), work, piece_state);
    }
}
