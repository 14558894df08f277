// The `finalize` setup pass of the `subdivide` stage (one thread): the DrawIndexedIndirect
// arguments of the raster (none drawn if a buffer overflowed). CPU twin: `CpuSubdivision::finalize`.

#import constants
#import subdivide_types
#import subdivide_bindings

@compute @workgroup_size(1)
fn finalize() {
    var written = atomicLoad(&counters.triangles);
    if (written > params.triangle_capacity || atomicLoad(&counters.nodes) > params.triangle_capacity) {
        written = 0u; // an overflowed run draws nothing; the renderer grows the buffers and reruns
    }
    draw_args = DrawIndexedIndirectArgs(3u * written, 1u, 0u, 0, 0u);
}
