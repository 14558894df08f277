// The `trace` stage (compute): ray tracing (seed 000), a primary ray per sample of each pixel
// (`--samples`; one: the pixel's centre) and eye from its eye point (`pixel_ray` of
// surface.wgsl: the cylinder's exact vertical model, or the sphere with its convergence and pole merge), the closest hit through the scene's BVH
// (src/core/scenes/bvh.rs), shaded with the rasterizer's materials and headlight (surface.wgsl), or a
// point light with shadow rays; mirror and refraction rays (the material's optics) to
// `reflect_max` bounces, depth first.
// Writes the same four outputs as the drawing stages, per eye, into buffers the host copies into
// the targets: colour (sRGB-encoded RGBA8), display-position error, object id + 1, distance.
// CPU twin: src/cpu/trace.rs.
//
// Traversal: the two-level BVH of src/core/scenes/bvh.rs (a top level over the objects, a tree per
// level of each object's chain) walked as one binary tree, nearer child first, the farther on a stack of TRACE_STACK entries
// with its entry distance (skipped when popped if the best hit is nearer; the host refuses
// deeper trees); at an object leaf the walk goes on at the root of the level the ray's visual
// level picks (seed 000 eq. 10, `pick_level`). A candidate hit closer than the best is accepted only if its
// material keeps it (a single-sided face seen from behind, alpha below a MASK cutoff or a
// BLEND screen door are passed through, as the fragment stage discards them). Textures are
// filtered by ray cones (`texture_footprint`): a ray carries the width of its pixel's cone, which
// grows by the pixel's angular size per metre; at a hit the footprint is that width over the
// incidence, in the triangle's texture units, and the sampler picks its mip level from it as the
// rasterizer does from screen derivatives.

#import projection
#import constants
#import scene
#import surface

struct TraceParams {
    // Viewer frame → scene frame (the inverse of the view: the viewer's position and yaw).
    to_scene: mat4x4<f32>,
    projection: Projection,
    // Background colour, display (sRGB) values.
    background: vec4<f32>,
    // The point light (scene frame) in xyz, w = 1; w = 0: the headlight at the viewer.
    light: vec4<f32>,
    // The visual-field LOD's gaze (viewer frame): forward (w = 1: LOD on), right, up.
    gaze_forward: vec4<f32>,
    gaze_right: vec4<f32>,
    gaze_up: vec4<f32>,
    ambient: f32,
    error_angle: u32,   // 1: the error output holds arcminutes
    row_texels: u32,    // padded row length of the outputs; an eye's rows follow the other's
    reflect_max: u32,   // bounces of mirror and refraction rays (seed 000's Reflect_max)
    lod_min_share: f32, // N_min / N_max of eq. 10
    original_root: u32, // where rays that meet every original start (SceneBvh::original_root)
    original_level: f32, // rays above this visual level do (SceneBvh::original_level)
    samples: u32,       // rays per pixel (`sample_position`)
}

// count = 0: inner (children first, first + 1); count & OBJECT_LEAF: an object, its chain's
// levels first .. first + (count & ~OBJECT_LEAF); else a leaf of triangles first .. first + count.
struct BvhNode {
    min: vec3<f32>,
    first: u32,
    max: vec3<f32>,
    count: u32,
}

// One level of an object's chain: the root of its tree and its triangles.
struct BvhLevel {
    root: u32,
    triangles: u32,
}

const OBJECT_LEAF: u32 = 0x80000000u;

@group(0) @binding(0) var<uniform> params: TraceParams;
@group(0) @binding(1) var<storage, read> vertices: array<SceneVertex>;
// The BVH's triangles (every level's, leaf by leaf), three vertex indices each.
@group(0) @binding(2) var<storage, read> indices: array<u32>;
@group(0) @binding(3) var<storage, read> bvh_nodes: array<BvhNode>;
@group(0) @binding(4) var<storage, read> bvh_levels: array<BvhLevel>;
@group(0) @binding(5) var<storage, read_write> out_color: array<u32>;
@group(0) @binding(6) var<storage, read_write> out_error: array<u32>;
@group(0) @binding(7) var<storage, read_write> out_object: array<u32>;
@group(0) @binding(8) var<storage, read_write> out_distance: array<u32>;
// Per workgroup slot (wrapping): rays traced, ray–triangle tests.
@group(0) @binding(9) var<storage, read_write> counts: array<atomic<u32>>;

const NO_HIT: u32 = 0xffffffffu;
const FAR: f32 = 3.0e38;

struct Hit {
    t: f32,
    triangle: u32,
    b1: f32,
    b2: f32,
    front: bool,
    tests: u32,   // ray–triangle tests made
}

// The entry distance of the ray into a node's box (clamped at 0), or FAR if it misses the box
// or enters it beyond `limit`. `inv` is 1/dir with no zero component.
fn enter_box(n: BvhNode, origin: vec3<f32>, inv: vec3<f32>, limit: f32) -> f32 {
    let t1 = (n.min - origin) * inv;
    let t2 = (n.max - origin) * inv;
    let near = max(max(min(t1.x, t2.x), min(t1.y, t2.y)), max(min(t1.z, t2.z), 0.0));
    let far = min(min(max(t1.x, t2.x), max(t1.y, t2.y)), min(max(t1.z, t2.z), limit));
    return select(FAR, near, near <= far);
}

// The footprint of a ray cone `width` metres wide meeting `triangle` along the unit direction
// `dir`: the ellipse the cone draws on the triangle's plane, as its two axes in texture units
// (the derivatives the sampler takes, columns): along the ray's trace on the plane width / |cos
// incidence| (at most 20×), across it width; each world vector in the plane mapped to texture
// units through the triangle's corners.
fn texture_footprint(triangle: u32, dir: vec3<f32>, width: f32) -> mat2x2<f32> {
    let a = vertices[indices[3u * triangle]];
    let b = vertices[indices[3u * triangle + 1u]];
    let c = vertices[indices[3u * triangle + 2u]];
    let e1 = b.position - a.position;
    let e2 = c.position - a.position;
    let n = cross(e1, e2);
    let world = max(length(n), 1e-30);
    let normal = n / world;
    let cos_i = max(abs(dot(normal, dir)), 0.05);
    var along = dir - normal * dot(normal, dir);
    if (dot(along, along) < 1e-12) {
        along = e1;
    }
    along = normalize(along);
    let major = along * (width / cos_i);
    let minor = cross(normal, along) * width;
    // w = s·e1 + t·e2 in the plane: s = w·(e2 × n̂)/|n|, t = w·(n̂ × e1)/|n|.
    let to_s = cross(e2, normal) / world;
    let to_t = cross(normal, e1) / world;
    let d1 = b.uv - a.uv;
    let d2 = c.uv - a.uv;
    return mat2x2<f32>(dot(major, to_s) * d1 + dot(major, to_t) * d2, dot(minor, to_s) * d1 + dot(minor, to_t) * d2);
}

// Whether a candidate hit's material keeps it (the fragment stage's discard), its texture
// filtered over `footprint` (texture units).
fn keeps(triangle: u32, b1: f32, b2: f32, front: bool, frag_xy: vec2<f32>, dir: vec3<f32>, width: f32) -> bool {
    if (!MATERIALS) {
        return true;
    }
    let a = vertices[indices[3u * triangle]];
    let m = materials[min(a.material, arrayLength(&materials) - 1u)];
    if (m.alpha_mode == ALPHA_OPAQUE) {
        return front || m.double_sided != 0u;
    }
    let b = vertices[indices[3u * triangle + 1u]];
    let c = vertices[indices[3u * triangle + 2u]];
    let b0 = 1.0 - b1 - b2;
    let color = b0 * a.color + b1 * b.color + b2 * c.color;
    let uv = b0 * a.uv + b1 * b.uv + b2 * c.uv;
    let f = texture_footprint(triangle, dir, width);
    return surface_color(a.material, color, uv, f[0], f[1], frag_xy, front).a >= 0.0;
}

// The level of an object's chain (levels first .. first + count, the original first) that a ray
// of visual level `level` meets (eq. 10, `SceneBvh::pick_level`): N_j = level·(N_max − N_min) +
// N_min, and the coarsest level with at least N_j triangles.
fn pick_level(first: u32, count: u32, level: f32) -> u32 {
    let max = f32(bvh_levels[first].triangles);
    let wanted = level * (max - params.lod_min_share * max) + params.lod_min_share * max;
    // The counts fall along the chain: the last level still ≥ N_j.
    var k = 0u;
    loop {
        if (k + 1u >= count || f32(bvh_levels[first + k + 1u].triangles) < wanted) {
            break;
        }
        k += 1u;
    }
    return first + k;
}

// The triangles of leaf `n` the ray meets nearer than `best` (Möller–Trumbore) that `keeps`
// accepts: the nearest becomes `best`.
fn leaf_hits(n: BvhNode, origin: vec3<f32>, dir: vec3<f32>, frag_xy: vec2<f32>, cone: vec2<f32>,
             best: ptr<function, Hit>) {
    for (var k = 0u; k < n.count; k++) {
        let tri = n.first + k;
        let v0 = vertices[indices[3u * tri]].position;
        let e1 = vertices[indices[3u * tri + 1u]].position - v0;
        let e2 = vertices[indices[3u * tri + 2u]].position - v0;
        let p = cross(dir, e2);
        let det = dot(e1, p);
        if (abs(det) < 1e-12) {
            continue;
        }
        let inv_det = 1.0 / det;
        let s = origin - v0;
        let b1 = dot(s, p) * inv_det;
        let q = cross(s, e1);
        let b2 = dot(dir, q) * inv_det;
        let t = dot(e2, q) * inv_det;
        if (b1 < 0.0 || b2 < 0.0 || b1 + b2 > 1.0 || !(t > 0.0) || t >= (*best).t) {
            continue;
        }
        if (keeps(tri, b1, b2, det > 0.0, frag_xy, dir, cone.x + cone.y * t)) {
            *best = Hit(t, tri, b1, b2, det > 0.0, 0u);
        }
    }
}

// The closest kept hit along the ray (scene frame) nearer than `limit` for a ray of visual
// level `level` and cone `cone` (width at the origin, growth per metre), Möller–Trumbore per
// triangle.
fn closest_hit(origin: vec3<f32>, dir: vec3<f32>, frag_xy: vec2<f32>, limit: f32, level: f32, cone: vec2<f32>) -> Hit {
    var best = Hit(limit, NO_HIT, 0.0, 0.0, true, 0u);
    var tests = 0u;
    let tiny = vec3<f32>(1e-20);
    let safe = select(dir, select(tiny, -tiny, dir < vec3<f32>(0.0)), abs(dir) < tiny);
    let inv = 1.0 / safe;
    // Rays that meet every object's original start at the tree over all of them.
    var node = select(0u, params.original_root, level > params.original_level);
    if (enter_box(bvh_nodes[node], origin, inv, limit) == FAR) {
        return best;
    }
    // Nodes still to visit, with the distance where the ray enters their box.
    var stack_node: array<u32, TRACE_STACK>;
    var stack_t: array<f32, TRACE_STACK>;
    var depth = 0u;
    loop {
        let n = bvh_nodes[node];
        var descend = false;
        if ((n.count & OBJECT_LEAF) != 0u) {
            node = bvh_levels[pick_level(n.first, n.count & ~OBJECT_LEAF, level)].root;
            continue;
        }
        if (n.count > 0u) {
            tests += n.count;
            leaf_hits(n, origin, dir, frag_xy, cone, &best);
        } else {
            let ta = enter_box(bvh_nodes[n.first], origin, inv, best.t);
            let tb = enter_box(bvh_nodes[n.first + 1u], origin, inv, best.t);
            if (ta != FAR && tb != FAR) {
                let a_first = ta <= tb;
                node = select(n.first + 1u, n.first, a_first);
                if (depth < TRACE_STACK) {
                    stack_node[depth] = select(n.first, n.first + 1u, a_first);
                    stack_t[depth] = max(ta, tb);
                    depth += 1u;
                }
                descend = true;
            } else if (ta != FAR || tb != FAR) {
                node = select(n.first + 1u, n.first, ta != FAR);
                descend = true;
            }
        }
        if (descend) {
            continue;
        }
        // The latest pending node the ray enters before the best hit so far.
        var found = false;
        loop {
            if (depth == 0u) {
                break;
            }
            depth -= 1u;
            if (stack_t[depth] < best.t) {
                node = stack_node[depth];
                found = true;
                break;
            }
        }
        if (!found) {
            break;
        }
    }
    best.tests = tests;
    return best;
}

fn linear_to_srgb(c: vec3<f32>) -> vec3<f32> {
    return select(1.055 * pow(c, vec3<f32>(1.0 / 2.4)) - 0.055, 12.92 * c, c <= vec3<f32>(0.0031308));
}

// sRGB bytes as the colour target holds them: round(x·255), like `cpu::fragment::shade`.
fn pack_display(c: vec3<f32>) -> u32 {
    let q = floor(clamp(c, vec3<f32>(0.0), vec3<f32>(1.0)) * 255.0 + 0.5);
    return u32(q.x) | (u32(q.y) << 8u) | (u32(q.z) << 16u) | (255u << 24u);
}

// A ray waiting to be traced (scene frame): the primary ray, a mirror or refraction ray (its
// light weighted by `weight`), or a shadow ray (`weight`: the light it brings if nothing is hit
// before `limit`). One loop traces them all through the one call of `closest_hit` (lavapipe runs
// a shader with several inlined copies of the traversal markedly slower).
struct Task {
    origin: vec3<f32>,
    kind: u32,
    dir: vec3<f32>,
    limit: f32,
    weight: vec3<f32>,
    bounces: u32,
    cone: vec2<f32>,   // the ray cone: width at the origin (m), growth per metre
}

const PRIMARY: u32 = 0u;
const SECONDARY: u32 = 1u;
const SHADOW: u32 = 2u;

// What a hit shows (`shade_hit`).
struct Shaded {
    color: vec3<f32>,      // its own light now (all of it, or the ambient part with a point light)
    direct: vec3<f32>,     // with a point light: the light it adds unless shadowed
    to_light: vec4<f32>,   // the unit direction to the light and its distance (w)
    mirror: f32,
    transmission: f32,
    ior: f32,
    front: bool,
    tint: vec3<f32>,       // the surface colour, which tints the mirrored light
    normal: vec3<f32>,     // scene frame, facing the ray
    // The glTF BRDF under the scene's lights: the first `shadowed` lights add their light only
    // where their shadow rays meet nothing (`light_term` with these inputs × own).
    shadowed: u32,
    shading_normal: vec3<f32>,  // viewer frame, as the BRDF sees it
    v: vec3<f32>,
    view_position: vec3<f32>,
    base: vec3<f32>,
    own: f32,
    maps: SurfaceMaps,
}

// The surface at a hit `p` (scene frame) with its optics; shaded with the headlight at the
// viewer (`view_position` in the viewer frame), with the point light (Lambert on the side the
// ray sees; the shadow ray decides the direct part), or with the glTF BRDF (the first
// `shadowed` scene lights left to the main loop's shadow rays). Its own light is weighted by
// 1 − mirror − transmission.
fn shade_hit(hit: Hit, dir: vec3<f32>, p: vec3<f32>, view_position: vec3<f32>, frag_xy: vec2<f32>,
             width: f32) -> Shaded {
    let a = vertices[indices[3u * hit.triangle]];
    let b = vertices[indices[3u * hit.triangle + 1u]];
    let c = vertices[indices[3u * hit.triangle + 2u]];
    let b0 = 1.0 - hit.b1 - hit.b2;
    let color = b0 * a.color + hit.b1 * b.color + hit.b2 * c.color;
    let uv = b0 * a.uv + hit.b1 * b.uv + hit.b2 * c.uv;
    var n = b0 * a.normal + hit.b1 * b.normal + hit.b2 * c.normal;
    if (dot(n, n) < 1e-12) {
        n = cross(b.position - a.position, c.position - a.position);
    }
    n = normalize(n);
    // The normal in the viewer frame (to_scene is a rotation and a translation: its
    // transpose rotates back).
    let rotation = mat3x3<f32>(params.to_scene[0].xyz, params.to_scene[1].xyz, params.to_scene[2].xyz);
    let f = texture_footprint(hit.triangle, dir, width);
    let surface = surface_color(a.material, color, uv, f[0], f[1], frag_xy, hit.front);
    let facing = select(n, -n, dot(n, dir) > 0.0);
    var own = 1.0;
    var out: Shaded;
    out.ior = 1.5;
    out.front = hit.front;
    out.tint = surface.rgb;
    out.normal = facing;
    if (MATERIALS) {
        let m = materials[min(a.material, arrayLength(&materials) - 1u)];
        out.mirror = m.mirror;
        out.transmission = m.transmission;
        out.ior = m.ior;
        own = max(1.0 - m.mirror - m.transmission, 0.0);
    }
    if (params.light.w > 0.0) {
        let to_light = params.light.xyz - p;
        let dist = length(to_light);
        let l = to_light / max(dist, 1e-20);
        let lambert = max(dot(facing, l), 0.0);
        let base = clamp(surface.rgb, vec3<f32>(0.0), vec3<f32>(1.0)) * own;
        out.color = base * params.ambient;
        out.direct = base * (1.0 - params.ambient) * lambert;
        out.to_light = vec4<f32>(l, dist);
    } else if (MATERIALS && lighting.pbr != 0u) {
        // The glTF BRDF under the scene's lights, seen along the ray; the first
        // MAX_SHADOWED_LIGHTS lights through shadow rays (the main loop), any others directly;
        // tone mapped once the pixel's light is summed.
        let back = transpose(rotation);
        // The tangent frame: the file's tangents interpolated, else from the triangle's edges
        // (what the drawing stages' screen derivatives give, as sub-triangles keep the
        // triangle's plane and texture mapping).
        let t = b0 * unpack_tangent(a.tangent) + hit.b1 * unpack_tangent(b.tangent) + hit.b2 * unpack_tangent(c.tangent);
        let maps = surface_maps(a.material, uv, f[0], f[1], back * (b.position - a.position),
                                back * (c.position - a.position), b.uv - a.uv, c.uv - a.uv, vec4<f32>(back * t.xyz, t.w));
        let v = -(back * dir);
        out.shadowed = select(0u, min(lighting.count, MAX_SHADOWED_LIGHTS), lighting.shadows != 0u);
        out.color = pbr_radiance(params.ambient, v, view_position, back * n, surface, maps, out.shadowed) * own;
        out.shading_normal = shading_normal(back * n, v, maps);
        out.v = v;
        out.view_position = view_position;
        out.base = max(surface.rgb, vec3<f32>(0.0));
        out.own = own;
        out.maps = maps;
    } else {
        out.color = shade(params.ambient, view_position, transpose(rotation) * n, surface).rgb * own;
    }
    return out;
}

// The refracted direction (Snell's law, unit vectors, `n` facing the incoming ray, eta = n₁/n₂),
// or the mirrored one under total internal reflection.
fn refract_or_reflect(d: vec3<f32>, n: vec3<f32>, eta: f32) -> vec3<f32> {
    let cos_i = -dot(d, n);
    let k = 1.0 - eta * eta * (1.0 - cos_i * cos_i);
    if (k < 0.0) {
        return reflect(d, n);
    }
    return normalize(eta * d + (eta * cos_i - sqrt(k)) * n);
}

// The level of detail of a direction (viewer frame) for the gaze (seed 000 eq. 1–8,
// `visual_field::Gaze::position` and `FieldPosition::level`): 1 in the central field, falling
// linearly to 0 at the visual field's elliptic boundary, 0 outside.
fn visual_level(d_in: vec3<f32>) -> f32 {
    let d = normalize(d_in);
    let df = dot(params.gaze_forward.xyz, d);
    let dr = dot(params.gaze_right.xyz, d);
    let du = dot(params.gaze_up.xyz, d);
    let horizontal = sqrt(df * df + dr * dr);
    let m_alpha = select(0.0, precise_acos(clamp(df / horizontal, -1.0, 1.0)), horizontal > 1e-9);
    let vertical = sqrt(df * df + du * du);
    var m_beta = select(0.0, precise_acos(clamp(abs(df) / vertical, -1.0, 1.0)), vertical > 1e-9);
    if (du < 0.0) {
        m_beta = -m_beta;
    }
    let l = sqrt(m_alpha * m_alpha + m_beta * m_beta);
    if (l <= CENTRAL_RADIUS) {
        return 1.0;
    }
    let b = select(FIELD_DOWN, FIELD_UP, m_beta >= 0.0);
    let c = m_alpha / l;
    let s = m_beta / l;
    let boundary = 1.0 / sqrt((c / FIELD_SIDEWAYS) * (c / FIELD_SIDEWAYS) + (s / b) * (s / b));
    if (l > boundary) {
        return 0.0;
    }
    return (boundary - l) / (boundary - CENTRAL_RADIUS);
}

// Whether the environment lights this frame's rays (the glTF BRDF, no `--light`).
fn environment_lit() -> bool {
    return MATERIALS && lighting.pbr != 0u && lighting.environment != 0u && params.light.w <= 0.0;
}

// A pixel that shows no surface: the background colour, error −1, object 0, distance +∞.
fn write_background(slot: u32) {
    out_color[slot] = pack_display(params.background.rgb);
    out_error[slot] = bitcast<u32>(-1.0);
    out_object[slot] = 0u;
    out_distance[slot] = 0x7f800000u;
}

// One pixel of one eye (gid.z): `params.samples` rays through stratified points of the pixel
// (`sample_position`; one sample: its centre), each with the mirror, refraction and shadow rays
// it leads to; the pixel shows the average of their tone-mapped colours in linear light. The
// outputs that are not averaged (error, object, distance) are those of the centre's ray.
@compute @workgroup_size(8, 8, 1)
fn trace(@builtin(global_invocation_id) gid: vec3<u32>) {
    let proj = params.projection;
    // This draw's image: a tile of the frame, or the frame.
    let size = vec2<u32>(proj.tile.zw);
    if (gid.x >= size.x || gid.y >= size.y) {
        return;
    }
    let pixel = vec2<f32>(gid.xy) + proj.tile.xy;
    let eye_sign = select(-1.0, 1.0, gid.z == 1u);
    let slot = (gid.z * size.y + gid.y) * params.row_texels + gid.x;
    let n = params.samples;
    var rays = 0u;
    var tests = 0u;
    if (n > 1u) {
        // The centre's ray for the outputs alone (one sample is the centre's itself).
        let centre = trace_sample(slot, eye_sign, pixel + 0.5, SAMPLE_OUTPUTS);
        rays += centre.rays;
        tests += centre.tests;
    }
    var sum = vec3<f32>(0.0);
    var plain = 0u;
    for (var i = 0u; i < n; i++) {
        let s = trace_sample(slot, eye_sign, pixel + sample_position(n, i),
                             select(SAMPLE_COLOUR, SAMPLE_BOTH, n == 1u));
        sum += s.color;
        plain += u32(s.plain);
        rays += s.rays;
        tests += s.tests;
    }
    // Counted per group of 64 pixels (a wrapping slot), so that no 32-bit counter overflows.
    let count_slot = (((gid.z * size.y + gid.y) * size.x + gid.x) / 64u) % TRACE_COUNT_SLOTS;
    atomicAdd(&counts[2u * count_slot], rays);
    atomicAdd(&counts[2u * count_slot + 1u], tests);
    // A pixel all background keeps the background's display value exactly.
    out_color[slot] = select(pack_display(linear_to_srgb(sum / f32(n))), pack_display(params.background.rgb), plain == n);
}

// Where sample i of n lies in its pixel (0..1 from the pixel's corner): the standard sample
// positions of Vulkan and Direct3D for 1, 2, 4, 8 and 16 samples (in 16ths of a pixel; one
// sample: the centre; `SAMPLES_N`, generated from src/core/shading/sampling.rs), 32 as the 8 pattern in
// each quarter of the pixel. `sample_position` in src/core/shading/sampling.rs.
fn sample_position(n: u32, i: u32) -> vec2<f32> {
    // The generated tables (`constants`), copied to be indexed at run time.
    var p2 = SAMPLES_2;
    var p4 = SAMPLES_4;
    var p8 = SAMPLES_8;
    var p16 = SAMPLES_16;
    switch n {
        case 2u: { return p2[i] / 16.0; }
        case 4u: { return p4[i] / 16.0; }
        case 8u: { return p8[i] / 16.0; }
        case 16u: { return p16[i] / 16.0; }
        case 32u: {
            let quarter = vec2<f32>(f32(i & 1u), f32((i >> 1u) & 1u));
            return (quarter + p8[i >> 2u] / 16.0) * 0.5;
        }
        default: { return vec2<f32>(0.5); }
    }
}

// The error, object and distance outputs of a primary ray's hit.
fn write_primary(slot: u32, eye_sign: f32, ray: Ray, hit: Hit, frag_xy: vec2<f32>) {
    let view_position = ray.origin + hit.t * ray.dir;
    out_error[slot] = bitcast<u32>(pixel_error(params.projection, eye_sign, view_position, frag_xy, params.error_angle != 0u));
    out_object[slot] = vertices[indices[3u * hit.triangle]].object + 1u;
    out_distance[slot] = bitcast<u32>(hit.t);
}

// What `trace_sample` makes of its ray: its colour, its colour and the pixel's outputs (one
// sample, the centre's), or the outputs alone (the centre's ray beside several samples: its
// primary hit only).
const SAMPLE_COLOUR: u32 = 0u;
const SAMPLE_BOTH: u32 = 1u;
const SAMPLE_OUTPUTS: u32 = 2u;

// A traced sample: its colour as the pixel shows it (tone mapped, linear light), whether that is
// the plain background, and the rays and ray–triangle tests it took.
struct Sample {
    color: vec3<f32>,
    plain: bool,
    rays: u32,
    tests: u32,
}

// One sample's primary ray through `frag_xy`, then the mirror, refraction and shadow rays it
// leads to, from a stack of tasks. Seed 000's level of detail: rays outside the visual field
// are not traced (background), and a ray's bounces are level × Reflect_max (eq. 9, rounded);
// its rays meet each object at the level of detail eq. 10 gives (level 1: the original). The
// primary ray writes the error, object and distance outputs unless `mode` is SAMPLE_COLOUR, and
// with SAMPLE_OUTPUTS nothing more is traced. One call of `closest_hit` traces every ray (lavapipe
// runs a shader with several inlined copies of the traversal markedly slower).
fn trace_sample(slot: u32, eye_sign: f32, frag_xy: vec2<f32>, mode: u32) -> Sample {
    let proj = params.projection;
    let ray = pixel_ray(proj, eye_sign, frag_xy);
    let background = srgb_to_linear(params.background.rgb);
    // The scene frame's origin of the viewer frame and the rotation back, for the headlight.
    let to_view = transpose(mat3x3<f32>(params.to_scene[0].xyz, params.to_scene[1].xyz, params.to_scene[2].xyz));
    let viewer = params.to_scene[3].xyz;
    let centre = mode != SAMPLE_COLOUR;
    if (centre) {
        write_background(slot);
    }
    var pending: array<Task, TRACE_PENDING>;
    var count = 0u;
    var color = vec3<f32>(0.0);
    var reflect_max = params.reflect_max;
    var level = 1.0;
    if (!shows_pixel(proj, frag_xy)) {
        return Sample(background, true, 0u, 0u); // outside the fisheye's circle
    }
    if (params.gaze_forward.w > 0.0) {
        level = visual_level(ray.dir);
        if (level <= 0.0) {
            return Sample(background, true, 0u, 0u);
        }
        reflect_max = u32(floor(level * f32(params.reflect_max) + 0.5));
    }
    // The pixel's angular size: the cone's growth per metre (`pixel_spread`).
    let spread = pixel_spread(proj, frag_xy);
    var task = Task((params.to_scene * vec4<f32>(ray.origin, 1.0)).xyz, PRIMARY,
                    (params.to_scene * vec4<f32>(ray.dir, 0.0)).xyz, FAR, vec3<f32>(1.0), 0u,
                    vec2<f32>(0.0, spread));
    var rays = 0u;
    var tests = 0u;
    loop {
        let hit = closest_hit(task.origin, task.dir, frag_xy, task.limit, level, task.cone);
        rays += 1u;
        tests += hit.tests;
        if (task.kind == SHADOW) {
            if (hit.triangle == NO_HIT) {
                color += task.weight;
            }
        } else if (hit.triangle == NO_HIT) {
            if (task.kind == PRIMARY) {
                // The background, or the environment seen where it lights the scene.
                if (environment_lit() && lighting.env_background != 0u) {
                    return Sample(tonemap(env_level(0u, env_st(env_direction(ray.dir)))), false, rays, tests);
                }
                return Sample(background, true, rays, tests);
            }
            // A mirrored or refracted ray that leaves the scene brings the environment's light.
            color += task.weight
                * select(background, env_level(0u, env_st(env_direction(to_view * task.dir))), environment_lit());
        } else {
            let p = task.origin + hit.t * task.dir;
            if (task.kind == PRIMARY && centre) {
                write_primary(slot, eye_sign, ray, hit, frag_xy);
                if (mode == SAMPLE_OUTPUTS) {
                    return Sample(vec3<f32>(0.0), false, rays, tests);
                }
            }
            // The cone's width here; mirrored and refracted rays go on growing from it, shadow
            // rays keep it (they converge on a point light).
            let width = task.cone.x + task.cone.y * hit.t;
            let s = shade_hit(hit, task.dir, p, to_view * (p - viewer), frag_xy, width);
            color += task.weight * s.color;
            let offset = 1e-4 * max(1.0, length(p));
            if (task.bounces < reflect_max) {
                push_bounces(&pending, &count, task, s, p, offset, vec2<f32>(width, spread));
            }
            push_shadow_rays(&pending, &count, task, s, p, offset, width, to_view);
        }
        if (count == 0u) {
            break;
        }
        count -= 1u;
        task = pending[count];
    }
    // Tone mapped once the pixel's light is summed.
    if (MATERIALS && lighting.pbr != 0u && params.light.w <= 0.0) {
        color = tonemap(color);
    }
    return Sample(color, false, rays, tests);
}

// The mirrored and refracted rays a hit sends on (its bounces left), onto the task stack.
fn push_bounces(pending: ptr<function, array<Task, TRACE_PENDING>>, count: ptr<function, u32>, task: Task,
                s: Shaded, p: vec3<f32>, offset: f32, cone: vec2<f32>) {
    if (s.mirror > 0.0 && *count < TRACE_PENDING) {
        let d = reflect(task.dir, s.normal);
        (*pending)[*count] = Task(p + offset * s.normal, SECONDARY, d, FAR, task.weight * s.mirror * s.tint,
                                  task.bounces + 1u, cone);
        *count += 1u;
    }
    if (s.transmission > 0.0 && *count < TRACE_PENDING) {
        // Entering through the front face: n₁/n₂ = 1/ior; leaving: ior.
        let eta = select(s.ior, 1.0 / s.ior, s.front);
        let d = refract_or_reflect(task.dir, s.normal, eta);
        let side = select(s.normal, -s.normal, dot(d, s.normal) < 0.0);
        (*pending)[*count] = Task(p + offset * side, SECONDARY, d, FAR, task.weight * s.transmission,
                                  task.bounces + 1u, cone);
        *count += 1u;
    }
}

// The shadow rays of a hit, onto the task stack: the scene's lights, each behind its shadow
// ray (the light it brings if nothing blocks it), or `--light`'s direct light.
fn push_shadow_rays(pending: ptr<function, array<Task, TRACE_PENDING>>, count: ptr<function, u32>, task: Task,
                    s: Shaded, p: vec3<f32>, offset: f32, width: f32, to_view: mat3x3<f32>) {
    for (var i = 0u; i < s.shadowed; i++) {
        let term = light_term(i, s.shading_normal, s.v, s.view_position, s.base, s.maps) * s.own;
        if (any(term > vec3<f32>(0.0)) && *count < TRACE_PENDING) {
            let light = lights[i];
            var limit = FAR;
            if (light.kind != LIGHT_DIRECTIONAL) {
                limit = length(light.position - s.view_position) - offset;
            }
            let l = light_at(light, s.view_position).xyz;
            (*pending)[*count] = Task(p + offset * s.normal, SHADOW, transpose(to_view) * l, limit, task.weight * term,
                                      0u, vec2<f32>(width, 0.0));
            *count += 1u;
        }
    }
    if (any(s.direct > vec3<f32>(0.0)) && *count < TRACE_PENDING) {
        (*pending)[*count] = Task(p + offset * s.normal, SHADOW, s.to_light.xyz, s.to_light.w - offset,
                                  task.weight * s.direct, 0u, vec2<f32>(width, 0.0));
        *count += 1u;
    }
}
