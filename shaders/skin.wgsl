// The `skin` stage (compute, issue 18): an animated scene's vertices posed on the GPU before
// `subdivide` reads them. Uploaded once: a source per posed vertex (its mesh-frame position,
// normal, tangent, four joints and weights, its morph offsets); per frame only the instances'
// matrices, the joint matrices and the morph weights. Each invocation poses one vertex: the
// morph offsets × weights, then Σ wⱼ·Jⱼ for a skinned vertex, then the instance's matrix (the
// normal by its inverse transpose, the tangent's sign flipped by a mirroring one), and writes
// position, normal and tangent into the scene's vertex buffer. CPU twin: src/cpu/skin.rs.

#import constants
#import scene

struct SkinParams {
    count: u32,
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
}

struct SkinSource {
    position: vec3<f32>,
    instance: u32,
    normal: vec3<f32>,
    vertex: u32,             // the scene vertex it poses
    tangent: vec4<f32>,
    joints: vec2<u32>,       // four 16-bit joint indices
    first_delta: u32,        // NO_SKIN: no morph targets
    _pad: u32,
    weights: vec4<f32>,
}

struct SkinInstance {
    matrix: mat4x4<f32>,
    normal_matrix: mat4x4<f32>,
    first_joint: u32,        // NO_SKIN: not skinned
    joint_count: u32,
    first_weight: u32,
    weight_count: u32,
    mirror: f32,
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
}

@group(0) @binding(0) var<uniform> params: SkinParams;
@group(0) @binding(1) var<storage, read> sources: array<SkinSource>;
// Per vertex with morph targets: a position offset and a normal offset per target.
@group(0) @binding(2) var<storage, read> deltas: array<vec4<f32>>;
@group(0) @binding(3) var<storage, read> instances: array<SkinInstance>;
@group(0) @binding(4) var<storage, read> joints: array<mat4x4<f32>>;
@group(0) @binding(5) var<storage, read> morph_weights: array<f32>;
@group(0) @binding(6) var<storage, read_write> vertices: array<SceneVertex>;

@compute @workgroup_size(64)
fn skin(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    let i = gid.x + gid.y * groups.x * 64u;
    if (i >= params.count) {
        return;
    }
    let s = sources[i];
    let inst = instances[s.instance];
    var p = s.position;
    var n = s.normal;
    if (s.first_delta != NO_SKIN) {
        for (var k = 0u; k < inst.weight_count; k++) {
            let w = morph_weights[inst.first_weight + k];
            if (w != 0.0) {
                p += w * deltas[s.first_delta + 2u * k].xyz;
                n += w * deltas[s.first_delta + 2u * k + 1u].xyz;
            }
        }
    }
    var t = s.tangent.xyz;
    if (inst.first_joint != NO_SKIN) {
        let j = array<u32, 4>(s.joints.x & 0xffffu, s.joints.x >> 16u, s.joints.y & 0xffffu, s.joints.y >> 16u);
        let w = array<f32, 4>(s.weights.x, s.weights.y, s.weights.z, s.weights.w);
        var m = mat4x4<f32>(vec4<f32>(0.0), vec4<f32>(0.0), vec4<f32>(0.0), vec4<f32>(0.0));
        for (var k = 0u; k < 4u; k++) {
            if (w[k] != 0.0) {
                // A joint beyond the skin's list counts as the identity.
                var joint = mat4x4<f32>(vec4<f32>(1.0, 0.0, 0.0, 0.0), vec4<f32>(0.0, 1.0, 0.0, 0.0),
                                        vec4<f32>(0.0, 0.0, 1.0, 0.0), vec4<f32>(0.0, 0.0, 0.0, 1.0));
                if (j[k] < inst.joint_count) {
                    joint = joints[inst.first_joint + j[k]];
                }
                m += joint * w[k];
            }
        }
        p = (m * vec4<f32>(p, 1.0)).xyz;
        n = (m * vec4<f32>(n, 0.0)).xyz;
        t = (m * vec4<f32>(t, 0.0)).xyz;
    }
    vertices[s.vertex].position = (inst.matrix * vec4<f32>(p, 1.0)).xyz;
    let nn = (inst.normal_matrix * vec4<f32>(n, 0.0)).xyz;
    vertices[s.vertex].normal = select(vec3<f32>(0.0), normalize(nn), dot(nn, nn) > 0.0);
    if (s.tangent.w != 0.0) {
        let tt = (inst.matrix * vec4<f32>(t, 0.0)).xyz;
        let unit = select(vec3<f32>(0.0), normalize(tt), dot(tt, tt) > 0.0);
        vertices[s.vertex].tangent = pack_tangent(vec4<f32>(unit, s.tangent.w * inst.mirror));
    }
}
