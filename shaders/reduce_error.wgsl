// The `reduce_error` stage (compute): reduces the error targets of both eyes to count, mean,
// std, max and the p50/p90/p99 percentiles. CPU twin: src/cpu/reduce_error.rs, which documents the
// histogram (bins of 1/64 px below 64 px, 1 px up to 1024 px, then one overflow bin).
//
// `accumulate`: one invocation per pixel: histogram (atomic), count, max; per-workgroup sums.
// `finish`: one workgroup: compensated sums of the partials, then the percentiles.

// FINE_BINS ([0, 64) px, 1/64 px each), COARSE_BINS ([64, 1024) px, 1 px each), BINS (+ 1
// overflow bin): from src/shader/constants.rs.
#import constants
const WG: u32 = 256u;

struct ReduceParams {
    width: u32,
    height: u32,
    row_stride: u32,   // u32s per padded row
    images: u32,
    partial_count: u32,
    partial_offset: u32, // where this dispatch's per-workgroup sums go (one dispatch per eye)
    _pad1: u32,
    _pad2: u32,
}

struct Totals {
    count: atomic<u32>,
    max_bits: atomic<u32>,
}

struct ErrorStats {
    count: u32,
    mean: f32,
    std_dev: f32,
    p50: f32,
    p90: f32,
    p99: f32,
    max: f32,
    _pad: f32,
}

@group(0) @binding(0) var<uniform> params: ReduceParams;
@group(0) @binding(1) var<storage, read> errors: array<u32>;
@group(0) @binding(2) var<storage, read_write> histogram: array<atomic<u32>, BINS>;
@group(0) @binding(3) var<storage, read_write> partials: array<vec2<f32>>;
@group(0) @binding(4) var<storage, read_write> totals: Totals;
@group(0) @binding(5) var<storage, read_write> result: ErrorStats;

var<workgroup> sums: array<vec2<f32>, WG>;

// Tree sum of every invocation's `value` over the workgroup (call from uniform control flow).
fn workgroup_sum(li: u32, value: vec2<f32>) -> vec2<f32> {
    sums[li] = value;
    workgroupBarrier();
    for (var stride = WG / 2u; stride > 0u; stride /= 2u) {
        if (li < stride) {
            sums[li] += sums[li + stride];
        }
        workgroupBarrier();
    }
    return sums[0];
}

fn bin_of(e: f32) -> u32 {
    if (e < 64.0) {
        return min(u32(floor(e * 64.0)), FINE_BINS - 1u);
    }
    if (e < 1024.0) {
        return FINE_BINS + min(u32(floor(e - 64.0)), COARSE_BINS - 1u);
    }
    return BINS - 1u;
}

fn bin_low(b: u32) -> f32 {
    if (b < FINE_BINS) {
        return f32(b) / 64.0;
    }
    return 64.0 + f32(b - FINE_BINS);
}

fn bin_width(b: u32) -> f32 {
    return select(1.0, 1.0 / 64.0, b < FINE_BINS);
}

@compute @workgroup_size(256)
fn accumulate(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(local_invocation_index) li: u32,
              @builtin(workgroup_id) wid: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    let i = gid.x + gid.y * groups.x * WG;
    let per_image = params.width * params.height;
    var s = vec2<f32>(0.0, 0.0);
    if (i < per_image * params.images) {
        let image = i / per_image;
        let k = i % per_image;
        let e = bitcast<f32>(errors[image * params.height * params.row_stride + (k / params.width) * params.row_stride + k % params.width]);
        if (e >= 0.0) {
            atomicAdd(&histogram[bin_of(e)], 1u);
            atomicAdd(&totals.count, 1u);
            atomicMax(&totals.max_bits, bitcast<u32>(e));
            s = vec2<f32>(e, e * e);
        }
    }
    let total = workgroup_sum(li, s);
    if (li == 0u) {
        partials[params.partial_offset + wid.x + wid.y * groups.x] = total;
    }
}

fn percentile(p: f32, count: u32) -> f32 {
    let rank = max(u32(ceil(p * f32(count))), 1u);
    var cumulative = 0u;
    for (var b = 0u; b < BINS; b++) {
        let n = atomicLoad(&histogram[b]);
        if (cumulative + n >= rank) {
            if (b == BINS - 1u) {
                return bitcast<f32>(atomicLoad(&totals.max_bits));
            }
            // Interpolate by rank within the bin, never beyond the largest error.
            let low = bin_low(b);
            let high = min(low + bin_width(b), bitcast<f32>(atomicLoad(&totals.max_bits)));
            return low + max(high - low, 0.0) * f32(rank - cumulative) / f32(n);
        }
        cumulative += n;
    }
    return 0.0;
}

@compute @workgroup_size(256)
fn finish(@builtin(local_invocation_index) li: u32) {
    // Each invocation sums a strided share of the partials with Kahan compensation.
    var total = vec2<f32>(0.0, 0.0);
    var compensation = vec2<f32>(0.0, 0.0);
    for (var k = li; k < params.partial_count; k += WG) {
        let y = partials[k] - compensation;
        let t = total + y;
        compensation = (t - total) - y;
        total = t;
    }
    let sum = workgroup_sum(li, total);
    if (li == 0u) {
        let count = atomicLoad(&totals.count);
        var out: ErrorStats;
        out.count = count;
        if (count > 0u) {
            let n = f32(count);
            out.mean = sum.x / n;
            out.std_dev = sqrt(max(sum.y / n - out.mean * out.mean, 0.0));
            out.p50 = percentile(0.5, count);
            out.p90 = percentile(0.9, count);
            out.p99 = percentile(0.99, count);
            out.max = bitcast<f32>(atomicLoad(&totals.max_bits));
        }
        result = out;
    }
}
