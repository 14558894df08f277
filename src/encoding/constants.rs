//! Constants shared by the Rust and WGSL sides, defined once here. The WGSL module
//! `constants` (composed by `#import constants`) is generated from this list by [`wgsl`], so
//! the two sides cannot drift apart.

use crate::core::detail::visual_field::{CENTRAL_RADIUS, FIELD_DOWN, FIELD_SIDEWAYS, FIELD_UP};
use crate::core::panoramas::cubemap::{CUBE_MIN_DISTANCE, CUBE_MIN_W, CUBE_NEAR};
use crate::core::panoramas::registry::PANORAMAS;
use crate::core::panoramas::sphere::{SPHERE_NEWTON_STEPS, SPHERE_NEWTON_TOLERANCE};
use crate::core::settings::SplitRule;
use crate::core::shading::light::{LightKind, Tonemap};
use crate::core::shading::material::{AlphaMode, Filter, Mipmap, Wrap, NO_TEXTURE};

/// Largest edge count the adaptive method asks for (edges longer than this many L are capped).
pub const MAX_EDGE_DIVISIONS: u32 = 1024;
/// Segments of the polyline that measures a long edge's projected length.
pub const EDGE_SAMPLES: u32 = 8;
/// The square cut around the vertical axis has half-diagonal ρ = d_e clamped to
/// [`AXIS_CLEARANCE_MIN`, `AXIS_CLEARANCE_MAX`]·R_T (see `cpu::subdivide::axis`).
pub const AXIS_CLEARANCE_MIN: f32 = 1e-5;
pub const AXIS_CLEARANCE_MAX: f32 = 1e-3;
/// For the adaptive method, parts are also cut into bands by the diamonds |x| + |z| = ρ·√2^k
/// below this many R_T (see `cpu::subdivide::axis::band_bound`).
pub const BAND_LIMIT: f32 = 1000.0;
/// A triangle whose diamond distances |x| + |z| span more than this ratio switches on the cuts
/// around the axis for the frame (see `cpu::subdivide::axis::triangle_cuts`).
pub const WIDE_RATIO: f32 = 2.0;
/// Invocations of `plan_cuts` per triangle it cuts around the axis: one per quadrant. On the
/// sphere a quadrant's bands reach 10⁻⁵ m from the axis (one quadrant's keep an invocation
/// within lavapipe's loop budget); on the cylinder a triangle planned whole in one invocation was
/// the frame's longest thread on a GPU (an H200: Sponza's `plan_cuts` 4.80 → 1.54 ms).
pub const PLAN_CUTS_SPLIT: u32 = 4;
/// Diamonds are numbered below this: the frame's active cuts are a 64-bit mask.
pub const MAX_DIAMONDS: u32 = 64;
/// The ratio of consecutive band diamonds.
pub const BAND_RATIO: f32 = std::f32::consts::SQRT_2;
/// Signed distances within this fraction of their terms' magnitude count as on the clip line,
/// so that the CPU and the GPU (whose rounding differs in the last bits) take the same side.
pub const SNAP: f32 = 1e-6;
/// A single-sided triangle is skipped when every eye sees its back by more than this fraction
/// of |n|·|P| (n its normal, P a corner), so that the CPU and the GPU agree.
pub const BACK_FACE_MARGIN: f32 = 1e-4;
/// An edge is split by the larger of its projected length and `EDGE_SAMPLES` × its longest
/// sampled segment / this (1 within 2·d_e of the axis in the paper model): equal parts stay short enough where the
/// projection stretches an edge unevenly, e.g. v ∝ 1/r (see `Subdivider::edge_profile`).
pub const MAX_STRETCH: f32 = 2.0;
/// The error split leaves no edge longer than this many L (so that depth and attributes, which
/// interpolate linearly on the screen, do so over bounded spans).
pub const ERROR_SPLIT_LENGTH: f32 = 8.0;
/// The ray tracer's traversal stack (entries): the host refuses a BVH deeper than this.
pub const TRACE_STACK: u32 = 64;
/// The scene lights whose shadows the ray tracer traces at each hit (the first ones of the
/// scene's list); any further ones light without shadows.
pub const MAX_SHADOWED_LIGHTS: u32 = 8;
/// The ray tracer's pending rays per pixel, traced depth first: per bounce level one mirror or
/// refraction ray waiting, plus the two a hit spawns and its shadow rays (one per shadowed light).
pub const TRACE_PENDING: u32 = crate::core::settings::MAX_REFLECT + 2 + MAX_SHADOWED_LIGHTS;
/// The ray tracer counts rays and triangle tests per workgroup into this many slots (two 32-bit
/// counters each, summed on the host in 64 bits, so that no slot overflows).
pub const TRACE_COUNT_SLOTS: u32 = 4096;
/// Seam copies are made for triangles reaching within this many radians of ±π; a copy's
/// triangle is drawn where it reaches more than this into the image.
pub const SEAM_MARGIN: f32 = 1e-5;
/// On the sphere, a piece whose bound from its corners (`sphere_u_bound`) keeps this many
/// radians more than `SEAM_MARGIN` from ±π is known to need no seam copy without projecting its
/// nodes (the bound's rounding is ~10⁻⁶ rad).
pub const SEAM_BOUND_SLACK: f32 = 1e-3;
/// The most divisions of a piece's edge: `fixed:N` above it is pre-split into a macro-lattice of
/// K = ceil(N / this) pieces (N = 64: 4 pieces of 32²), and `adaptive` takes N_max as at most
/// this, so that one `lattice` invocation never makes more than this² triangles (lavapipe cut
/// invocations short beyond about 1,900).
pub const PIECE_DIVISIONS: u32 = 32;
/// Under the error split, a piece with an edge in one part and another in at least this many is
/// drawn as a strip instead of the regular lattice (`strip_triangles` in src/cpu/subdivide/);
/// below it the two make the same number of triangles.
pub const STRIP_MIN_DIVISIONS: u32 = 3;
/// ... if that edge's chord error is within this share of τ: the strip's rungs, as long as the
/// edge or shorter, are then drawn straight with little error (with the whole τ, random slivers
/// across the seam reached p99 1.7 px at τ = 1 px, against 1.3 with the lattice).
pub const STRIP_BASE_ERROR: f32 = 0.25;
/// `Piece::count2_level` flag: a piece of a thin part split in bands (`PartSplit` and `band_cell` in
/// src/cpu/subdivide/; `cell` is the piece's index among the bands' halves).
pub const BANDS: u32 = 1 << 29;
/// Under an adaptive rule a piece drawn in rows (`Rows` in src/cpu/subdivide/) gives each band
/// between two rows the parts w its zipper's diagonals need: its whole diagonals' middles within
/// w × this many τ of their chords (each zipper diagonal bends about 1/w as much).
pub const ROW_DIAGONAL_ERROR: f32 = 1.5;
/// The largest macro-lattice level K: a part makes at most this² pieces, so that one `plan`
/// invocation's loop stays short (lavapipe cuts long invocations short and loses pieces). An
/// adaptive part whose longest edge needs more than this × N_max divisions (an edge over
/// 224·L long at N_max = 7) gets pieces of up to `PIECE_DIVISIONS` per edge instead of N_max.
pub const MAX_MACRO_LEVEL: u32 = MAX_EDGE_DIVISIONS / PIECE_DIVISIONS;
/// The most nodes or triangles (seam copies included) one work item of `lattice_nodes` or
/// `lattice_triangles` writes: an item of a piece drawn c times (the seam) covers
/// LATTICE_CHUNK / c node slots or candidate triangles (issue 32: no long threads).
pub const LATTICE_CHUNK: u32 = 64;
/// `SubdivideParams::piece_count` meaning "as many pieces as `plan` made" (read on the GPU).
pub const PIECES_FROM_COUNTER: u32 = u32::MAX;

/// The farthest depth a drawing stage writes, 1 − 2⁻²¹: a surface however far (its depth would
/// round to 1, or reach it when interpolated across the triangle) still passes the `Less` test
/// against the cleared 1. Depths tie beyond it: beyond ~2,000 km for the projection methods
/// (r/(r+1)), beyond ~20 km for the slit cameras (1 − near/z).
pub const MAX_DEPTH: f32 = 1.0 - 1.0 / (1 << 21) as f32;

/// How far beyond the image's top or bottom edge, in pixels, the raster stage places a vertex
/// at most: one further out is pulled in vertically to this distance. Points between the square
/// around the axis and the eye circle (see `cpu::subdivide::axis`) project to millions of pixels
/// in the exact vertical model; a real GPU clips such triangles outside its guard band, and two
/// neighbours clipped apart can leave a pixel between them (seen on an H100: one background
/// pixel at the tips of a fan of such needles). 8,192 px lies within every guard band, and moves
/// the needles' in-image part by under 1 % of their width.
pub const GUARD_BAND_PX: f32 = 8192.0;

/// Error histogram of `reduce_error`: bins of 1/64 px in [0, 64) px ...
pub const FINE_BINS: u32 = 4096;
/// ... bins of 1 px in [64, 1024) px ...
pub const COARSE_BINS: u32 = 960;
/// ... and one overflow bin.
pub const BINS: u32 = FINE_BINS + COARSE_BINS + 1;

/// Under the error split, nodes are spaced by equal steps of azimuth (`cpu::subdivide::spacing`)
/// along a segment whose ends lie at least this far from the axis (metres; w = r draws them)...
pub const AZIMUTH_MIN_RADIUS: f32 = 1e-6;
/// ... and whose azimuth sweep lies between these (radians: below, equal parts of P/r, which is the
/// same; above, near half a turn, the steps crowd where the segment passes the axis).
pub const AZIMUTH_MIN_TURN: f32 = 1e-4;
pub const AZIMUTH_MAX_TURN: f32 = 3.0;
/// The drawn point between two nodes δ of azimuth apart is off its step of azimuth by at most
/// this × δ³ radians (the chord of the unit circle against its arc: (2/(9√3))·(δ/2)³); the
/// error split keeps that within `AZIMUTH_RESIDUAL_ERROR`·τ on screen.
pub const AZIMUTH_CHORD_RESIDUAL: f32 = 0.016_04;
pub const AZIMUTH_RESIDUAL_ERROR: f32 = 0.25;
/// Where nodes are drawn off their projections (the error split on the equirectangular
/// panoramas: `cpu::subdivide::offsets`), the split's tolerance is this × τ: a triangle's error
/// then swings both ways, and its largest and mean are about what τ gives without offsets
/// (docs/results.md, *Nodes drawn off their projections*).
pub const OFFSET_SPLIT_FACTOR: f32 = 1.75;

/// A constant's value as WGSL writes it.
#[derive(Clone, Copy, Debug)]
pub enum Value {
    U32(u32),
    F32(f32),
}

/// Every shared constant: (WGSL name, value).
pub fn all() -> Vec<(&'static str, Value)> {
    let mut out = numbers();
    out.extend(codes());
    out.extend(SplitRule::ALL.map(|m| (m.wgsl_name(), Value::U32(m as u32))));
    out
}

/// The shared numbers: the subdivision's, the tracer's, the visual field's, the raster's.
fn numbers() -> Vec<(&'static str, Value)> {
    use Value::{F32, U32};
    vec![
        ("MAX_EDGE_DIVISIONS", U32(MAX_EDGE_DIVISIONS)),
        ("EDGE_SAMPLES", U32(EDGE_SAMPLES)),
        ("PIECE_DIVISIONS", U32(PIECE_DIVISIONS)),
        ("BANDS", U32(BANDS)),
        ("ROW_DIAGONAL_ERROR", F32(ROW_DIAGONAL_ERROR)),
        ("STRIP_MIN_DIVISIONS", U32(STRIP_MIN_DIVISIONS)),
        ("STRIP_BASE_ERROR", F32(STRIP_BASE_ERROR)),
        ("MAX_MACRO_LEVEL", U32(MAX_MACRO_LEVEL)),
        ("AXIS_CLEARANCE_MIN", F32(AXIS_CLEARANCE_MIN)),
        ("AXIS_CLEARANCE_MAX", F32(AXIS_CLEARANCE_MAX)),
        ("BAND_LIMIT", F32(BAND_LIMIT)),
        ("WIDE_RATIO", F32(WIDE_RATIO)),
        ("MAX_DIAMONDS", U32(MAX_DIAMONDS)),
        ("PLAN_CUTS_SPLIT", U32(PLAN_CUTS_SPLIT)),
        ("BAND_RATIO", F32(BAND_RATIO)),
        ("SNAP", F32(SNAP)),
        ("BACK_FACE_MARGIN", F32(BACK_FACE_MARGIN)),
        ("SINGLE_SIDED", U32(crate::core::scenes::scene::SINGLE_SIDED)),
        ("MAX_STRETCH", F32(MAX_STRETCH)),
        ("AZIMUTH_MIN_RADIUS", F32(AZIMUTH_MIN_RADIUS)),
        ("CUBE_MIN_W", F32(CUBE_MIN_W)),
        ("CUBE_MIN_DISTANCE", F32(CUBE_MIN_DISTANCE)),
        ("CUBE_NEAR", F32(CUBE_NEAR)),
        ("AZIMUTH_MIN_TURN", F32(AZIMUTH_MIN_TURN)),
        ("AZIMUTH_MAX_TURN", F32(AZIMUTH_MAX_TURN)),
        ("AZIMUTH_CHORD_RESIDUAL", F32(AZIMUTH_CHORD_RESIDUAL)),
        ("AZIMUTH_RESIDUAL_ERROR", F32(AZIMUTH_RESIDUAL_ERROR)),
        ("ERROR_SPLIT_LENGTH", F32(ERROR_SPLIT_LENGTH)),
        ("SEAM_MARGIN", F32(SEAM_MARGIN)),
        ("SEAM_BOUND_SLACK", F32(SEAM_BOUND_SLACK)),
        ("TRACE_STACK", U32(TRACE_STACK)),
        ("TRACE_PENDING", U32(TRACE_PENDING)),
        ("MAX_SHADOWED_LIGHTS", U32(MAX_SHADOWED_LIGHTS)),
        ("TRACE_COUNT_SLOTS", U32(TRACE_COUNT_SLOTS)),
        ("CENTRAL_RADIUS", F32(CENTRAL_RADIUS)),
        ("FIELD_SIDEWAYS", F32(FIELD_SIDEWAYS)),
        ("FIELD_UP", F32(FIELD_UP)),
        ("FIELD_DOWN", F32(FIELD_DOWN)),
        ("PIECES_FROM_COUNTER", U32(PIECES_FROM_COUNTER)),
        ("LATTICE_CHUNK", U32(LATTICE_CHUNK)),
        ("SPHERE_NEWTON_STEPS", U32(SPHERE_NEWTON_STEPS)),
        ("SPHERE_NEWTON_TOLERANCE", F32(SPHERE_NEWTON_TOLERANCE)),
        ("MAX_DEPTH", F32(MAX_DEPTH)),
        ("GUARD_BAND_PX", F32(GUARD_BAND_PX)),
        ("FINE_BINS", U32(FINE_BINS)),
        ("COARSE_BINS", U32(COARSE_BINS)),
        ("BINS", U32(BINS)),
        ("NORMAL_OFFSET_TEXELS", F32(crate::core::shading::shadow::NORMAL_OFFSET_TEXELS)),
        ("LIGHT_OFFSET_TEXELS", F32(crate::core::shading::shadow::LIGHT_OFFSET_TEXELS)),
    ]
}

/// The codes the settings and the scene's enums are passed as, and the tables' sizes.
fn codes() -> Vec<(&'static str, Value)> {
    use Value::U32;
    // Each panorama's code, from the registry.
    let panoramas = PANORAMAS.iter().map(|m| (m.wgsl_name(), U32(m.kind().code())));
    panoramas
        .chain([
            ("NO_TEXTURE", U32(NO_TEXTURE)),
            ("WRAP_REPEAT", U32(Wrap::Repeat as u32)),
            ("WRAP_CLAMP", U32(Wrap::ClampToEdge as u32)),
            ("WRAP_MIRROR", U32(Wrap::MirroredRepeat as u32)),
            ("FILTER_NEAREST", U32(Filter::Nearest as u32)),
            ("FILTER_LINEAR", U32(Filter::Linear as u32)),
            ("MIPMAP_NONE", U32(Mipmap::None as u32)),
            ("MIPMAP_NEAREST", U32(Mipmap::Nearest as u32)),
            ("MIPMAP_LINEAR", U32(Mipmap::Linear as u32)),
            ("ALPHA_OPAQUE", U32(AlphaMode::Opaque as u32)),
            ("ALPHA_MASK", U32(AlphaMode::Mask as u32)),
            ("ALPHA_BLEND", U32(AlphaMode::Blend as u32)),
            ("LIGHT_DIRECTIONAL", U32(LightKind::Directional as u32)),
            ("LIGHT_POINT", U32(LightKind::Point as u32)),
            ("LIGHT_SPOT", U32(LightKind::Spot as u32)),
            ("ENV_LEVELS", U32(crate::core::shading::environment::ENV_LEVELS as u32)),
            ("LUT_SIZE", U32(crate::core::shading::environment::LUT_SIZE as u32)),
            ("MAX_SHADOW_MAPS", U32(crate::core::shading::shadow::MAX_SHADOW_MAPS as u32)),
            ("SHADOW_ORTHOGRAPHIC", U32(crate::core::shading::shadow::SHADOW_ORTHOGRAPHIC)),
            ("SHADOW_PERSPECTIVE", U32(crate::core::shading::shadow::SHADOW_PERSPECTIVE)),
            ("SHADOW_CUBE", U32(crate::core::shading::shadow::SHADOW_CUBE)),
            ("NO_SKIN", U32(crate::encoding::types::NO_SKIN)),
            ("NO_SHADOW_MAP", U32(crate::core::shading::light::NO_SHADOW_MAP)),
            ("TONEMAP_NONE", U32(Tonemap::None.code())),
            ("TONEMAP_PBR_NEUTRAL", U32(Tonemap::PbrNeutral.code())),
            ("TONEMAP_ACES", U32(Tonemap::Aces.code())),
            ("TONEMAP_LINEAR", U32(Tonemap::Linear.code())),
        ])
        .collect()
}

/// The generated WGSL module `constants`.
pub fn wgsl() -> String {
    let mut s = String::from("// Generated from src/encoding/constants.rs: edit the Rust side.\n");
    for (name, value) in all() {
        match value {
            // `{:?}` prints the shortest decimal that reads back as the same f32 (e.g. 1e-6).
            Value::F32(x) => s += &format!("const {name}: f32 = {x:?};\n"),
            Value::U32(x) => s += &format!("const {name}: u32 = {x}u;\n"),
        }
    }
    // The standard sample positions (16ths of a pixel), for the ray tracer's samples.
    for (n, table) in crate::core::shading::sampling::STANDARD_POSITIONS {
        let items: Vec<String> = table.iter().map(|[x, y]| format!("vec2<f32>({x:?}, {y:?})")).collect();
        s += &format!("const SAMPLES_{n}: array<vec2<f32>, {n}> = array<vec2<f32>, {n}>({});\n", items.join(", "));
    }
    s
}
