//! Plain-old-data structs shared with the WGSL stages. Every struct here (and `SceneVertex`,
//! `Material`, `MipLevel` in `core`) has a WGSL twin of the same layout; [`LAYOUTS`] lists
//! their field offsets, which `tests/shaders.rs` checks against the WGSL reflected by naga.

use std::mem::{offset_of, size_of};

use bytemuck::{Pod, Zeroable};

pub use crate::core::frame::ErrorStats;
use crate::core::panoramas::projection::{PanoramaKind, Projection, Vertical};
pub use crate::core::scenes::bvh::{BvhLevel, BvhNode};
use crate::core::scenes::scene::SceneVertex;
pub use crate::core::shading::light::{GpuLight, LightingParams};
use crate::core::shading::material::{Material, MipLevel};
pub use crate::core::shading::shadow::GpuShadowMap;

/// A vertex of a prepared triangle (`DrawVertex` in shaders/shared/subdivide_types.wgsl, read by raster.wgsl),
/// in the viewer frame. `theta_ref` is the azimuth the vertex stage unwraps θ around; seam
/// copies carry it shifted by ±2π. 80 bytes; also the vertex-buffer layout of the raster stage.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct DrawVertex {
    pub position: [f32; 3],
    pub theta_ref: f32,
    pub normal: [f32; 3],
    pub material: u32,
    pub color: [f32; 4],
    pub uv: [f32; 2],
    pub object: u32,
    /// The interpolated glTF tangent in the viewer frame, packed (`core::scenes::scene::pack_tangent`; 0: none).
    pub tangent: u32,
    /// Where the raster stage draws the node off its projection, in image pixels (x right, y
    /// down): the left eye's (x, y), then the right eye's. Zero: at its projection.
    pub offsets: [f32; 4],
}

/// `Projection` in shaders/shared/projection.wgsl. 144 bytes.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct ProjectionUniform {
    pub screen_radius: f32,
    pub eye_radius: f32,
    pub width: f32,
    pub height: f32,
    pub acos_eye_screen: f32,
    pub vertical_exact: u32,
    /// Pixels per unit of v (metres of screen, or radians of latitude).
    pub pixels_per_v: f32,
    /// The panorama's code: its index in the registry (`core::panoramas::panorama::PANORAMAS`).
    pub panorama: u32,
    /// The sphere's convergence distance, metres; 0: parallel rays.
    pub convergence: f32,
    /// The sphere's pole merge, radians of altitude; `pole_to` 0: off (as in Cycles).
    pub pole_from: f32,
    pub pole_to: f32,
    /// Pixels per full turn of azimuth (`Projection::turn_px`): the width, or 2W for VR180.
    pub turn_px: f32,
    /// The fisheye's field of view and dome tilt, degrees (`Projection::fov`, `dome_tilt`).
    pub fov: f32,
    pub dome_tilt: f32,
    /// The cylinder's tracked head (`core::panoramas::head`): 1 on, 0 off; its turn γ (radians) and its
    /// position O in the display's frame (metres).
    pub head_on: f32,
    pub head_turn: f32,
    pub head_offset: [f32; 3],
    /// The cubemap: the face a draw projects into (`core::panoramas::cubemap::CUBE_FACES`); set per face
    /// draw by the raster stage, 0 elsewhere.
    pub face: u32,
    /// The CAVE's wall in the display's frame (`core::panoramas::cave::CaveWall`): its lower left corner,
    /// right and up edges, metres.
    pub wall_corner: [f32; 3],
    pub wall_on: f32,
    pub wall_right: [f32; 3],
    pub _pad1: f32,
    pub wall_up: [f32; 3],
    pub _pad2: f32,
    /// This draw's part of the frame: x, y, width, height in pixels (`Projection::tile`; the
    /// whole frame when not tiled).
    pub tile: [f32; 4],
}

impl From<&ProjectionUniform> for Projection {
    fn from(p: &ProjectionUniform) -> Self {
        Projection {
            screen_radius: p.screen_radius,
            eye_radius: p.eye_radius,
            width: p.width as u32,
            height: p.height as u32,
            vertical: if p.vertical_exact != 0 { Vertical::Exact } else { Vertical::Paper },
            panorama: PanoramaKind::from_code(p.panorama).unwrap_or_default(),
            convergence: (p.convergence > 0.0).then_some(p.convergence),
            pole_merge: (p.pole_to > 0.0).then(|| (p.pole_from.to_degrees(), p.pole_to.to_degrees())),
            fov: p.fov,
            dome_tilt: p.dome_tilt,
            head: (p.head_on != 0.0)
                .then_some(crate::core::panoramas::head::Head { offset: p.head_offset, turn: p.head_turn }),
            wall: (p.wall_on != 0.0).then_some(crate::core::panoramas::cave::CaveWall {
                corner: p.wall_corner,
                right: p.wall_right,
                up: p.wall_up,
            }),
            tile: (p.tile != [0.0, 0.0, p.width, p.height]).then(|| p.tile.map(|v| v as u32)),
        }
    }
}

impl From<&Projection> for ProjectionUniform {
    fn from(p: &Projection) -> Self {
        let (pole_from, pole_to) = p.pole_merge.map_or((0.0, 0.0), |(a, b)| (a.to_radians(), b.to_radians()));
        ProjectionUniform {
            screen_radius: p.screen_radius,
            eye_radius: p.eye_radius,
            width: p.width as f32,
            height: p.height as f32,
            acos_eye_screen: p.acos_eye_screen(),
            vertical_exact: (p.vertical == Vertical::Exact) as u32,
            pixels_per_v: p.pixels_per_v(),
            panorama: p.panorama.code(),
            convergence: p.convergence.unwrap_or(0.0),
            pole_from,
            pole_to,
            turn_px: p.turn_px(),
            fov: p.fov,
            dome_tilt: p.dome_tilt,
            head_on: p.head.is_some() as u32 as f32,
            head_turn: p.head.map_or(0.0, |h| crate::core::panoramas::projection::wrap_angle(h.turn)),
            head_offset: p.head.map_or([0.0; 3], |h| h.offset),
            face: 0,
            wall_corner: p.wall.map_or([0.0; 3], |w| w.corner),
            wall_on: p.wall.is_some() as u32 as f32,
            wall_right: p.wall.map_or([0.0; 3], |w| w.right),
            _pad1: 0.0,
            wall_up: p.wall.map_or([0.0; 3], |w| w.up),
            _pad2: 0.0,
            tile: p.tile.unwrap_or([0, 0, p.width, p.height]).map(|v| v as f32),
        }
    }
}

/// `SubdivideParams` in shaders/shared/subdivide_types.wgsl. 224 bytes.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct SubdivideParams {
    /// World → viewer frame (column-major, as glam stores it).
    pub view: [[f32; 4]; 4],
    pub projection: ProjectionUniform,
    /// Every output point is at least this far from the vertical axis (see subdivide.rs).
    pub axis_clearance: f32,
    pub triangle_count: u32,
    /// Index of the first input triangle of a `plan` dispatch.
    pub first_triangle: u32,
    /// 0 vertex, 1 fixed, 2 adaptive.
    pub method: u32,
    pub fixed_n: u32,
    /// L: the longest projected edge wanted, pixels.
    pub edge_px: f32,
    /// N_max: the largest lattice step per piece.
    pub max_div: u32,
    /// Capacity of the piece buffer; `plan` counts but never writes beyond it.
    pub piece_capacity: u32,
    /// Capacity of the output buffer in triangles; `lattice` counts but never writes beyond it.
    pub triangle_capacity: u32,
    /// First piece and piece count of a `lattice` dispatch.
    pub first_piece: u32,
    pub piece_count: u32,
    /// 1: also measure the longest visible output edge (`max_sub_edge_px`, costs projections).
    pub measure_edges: u32,
    /// `Projection::vertical_limit`: beyond |y| > this·r no pixel row shows a point.
    pub vertical_limit: f32,
    /// τ: the error split's tolerance per edge, pixels.
    pub max_error_px: f32,
    /// 1: nodes are spaced by azimuth, for the raster stage's drawing with w = r (the error
    /// split, but on the cubemap, whose faces draw with their own w: `cpu::subdivide::spacing`).
    pub by_azimuth: u32,
    /// 1: the image has no seam (the fisheye; the cubemap, whose faces map (u, v) periodically
    /// in u; CAVE walls): no seam copies, which would draw their pieces twice over.
    pub seamless: u32,
    /// 1: the image is drawn as pinholes from the eye points (the cubemap's faces, w the distance
    /// along the ray): an edge is split for how far its eye point turns from the chord, and for
    /// its length (the angle it spans) — `Subdivider::pinhole_profile`.
    pub pinhole_faces: u32,
    /// 1: nodes are drawn off their projections (`DrawVertex::offsets`; `cpu::subdivide::offsets`).
    pub node_offsets: u32,
    /// The fisheye: cos β of the cone around the point opposite the dome's axis whose triangles
    /// are dropped (`Projection::dome_antipode_cone`, its margin following the chords' dip); 2
    /// where none is (no point lies in it).
    pub antipode_cos: f32,
    pub _pad: u32,
}

/// `Counters` in shaders/shared/subdivide_types.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct SubdivideCounters {
    pub pieces: u32,
    pub triangles: u32,
    /// Bits of the largest visible output edge in pixels (an f32).
    pub max_edge_bits: u32,
    /// Triangles `plan` listed for `plan_cuts` (from the front of its list) ...
    pub cut_count: u32,
    /// Output nodes (`lattice`).
    pub nodes: u32,
    /// ... and the wide ones near the axis (from the back).
    pub cut_wide: u32,
    /// The most piece records one `plan` or `plan_cuts` invocation appended (the balance of the
    /// work: see `bench speed`).
    pub max_pieces: u32,
    /// The most nodes or triangles (seam copies included) one `lattice` invocation wrote.
    pub max_output: u32,
    /// Part records `plan_cuts` appended for `plan_parts`.
    pub parts: u32,
    /// Work items `lattice` appended to `lattice_work` for `lattice_nodes` (from its front) ...
    pub node_items: u32,
    /// ... and for `lattice_triangles` (from its back).
    pub triangle_items: u32,
    /// Bands of pieces whose rows `lattice_rows` measures (`row_items`).
    pub row_items: u32,
    /// Those pieces, listed for `lattice_rows_plan` (in `parts`, free after `plan_parts`).
    pub pending: u32,
    /// The frame's cuts around the axis (`AxisCuts`), bits 0–31 and 32–63.
    pub cuts_low: u32,
    pub cuts_high: u32,
    /// The timestamps read back after the counters start at a multiple of 8 bytes.
    pub _pad: u32,
}

impl SubdivideCounters {
    /// Bytes of the counters that each `plan` or `lattice` run starts from zero; the cuts after
    /// them are set once per frame by `active_cuts`.
    pub const RUN_BYTES: u64 = 52;

    /// What the output buffers must hold, in their unit (a triangle's indices and a node each):
    /// the larger of the node count and the triangle count with the row items (which lie in the
    /// index buffer from its back while pieces written in place fill it from the front).
    pub fn output_units(&self) -> u32 {
        self.triangles.saturating_add(self.row_items.div_ceil(3)).max(self.nodes)
    }

    /// What the piece buffers must hold: the piece records, and as many part records (a part
    /// that did not fit was never planned, so its pieces are not counted yet).
    pub fn piece_records(&self) -> u32 {
        self.pieces.max(self.parts)
    }

    /// Whether a run wanted more than its buffers held (then nothing it drew is complete).
    pub fn overflowed(&self, piece_capacity: u32, triangle_capacity: u32) -> bool {
        self.piece_records() > piece_capacity || self.output_units() > triangle_capacity
    }

    /// The frame's cuts as one mask.
    pub fn cuts(&self) -> u64 {
        self.cuts_low as u64 | (self.cuts_high as u64) << 32
    }
}

/// `DisplayParams` in shaders/display.wgsl (the live window's display stage; twin
/// `cpu::display`). 224 bytes.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct DisplayParams {
    pub projection: ProjectionUniform,
    /// `core::display::DisplayMode` as a number.
    pub mode: u32,
    /// Each layer's image size.
    pub width: u32,
    pub height: u32,
    /// Texels per row in the buffer of texels (rows padded for the copy).
    pub row_texels: u32,
    /// 2: both eyes; 1: one image.
    pub layers: u32,
    /// 1: the target encodes sRGB itself (the stage writes linear values).
    pub srgb_target: u32,
    pub _pad0: u32,
    pub _pad1: u32,
    /// Where the image goes in the target: x, y, width, height (pixels).
    pub area: [f32; 4],
    /// Look-around: yaw, pitch (radians), tan of half the horizontal field of view, the far
    /// distance (metres) of the point whose pixel each direction takes.
    pub look: [f32; 4],
    /// The overlay's place: x, y, width, height (pixels; width 0: none).
    pub overlay: [f32; 4],
}

/// `RasterParams` in shaders/raster.wgsl. 112 bytes.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct RasterParams {
    pub projection: ProjectionUniform,
    /// +1 right eye, −1 left eye.
    pub eye_sign: f32,
    /// Ambient term of the shading: colour × (ambient + (1 − ambient)·|n·l|).
    pub ambient: f32,
    /// Test hook: draw shifted by this many pixels (x right, y down); the error pass still
    /// measures against the true projection.
    pub shift_px: [f32; 2],
    /// 1: the error target holds the display-position error as an angle (arcminutes) rather
    /// than in pixels.
    pub error_angle: u32,
    /// 1: draw with clip w = r, the vertex's distance from the vertical axis (perspective-correct
    /// attributes; the error split's azimuth spacing, `cpu::subdivide::spacing`), except on the
    /// cubemap, whose faces have their own w.
    pub w_by_radius: u32,
    pub _pad1: u32,
    pub _pad2: u32,
}

/// `DrawIndexedIndirectArgs` as the GPU reads them.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct DrawIndexedIndirectArgs {
    pub index_count: u32,
    pub instance_count: u32,
    pub first_index: u32,
    pub base_vertex: i32,
    pub first_instance: u32,
}

/// `ReduceParams` in shaders/reduce_error.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct ReduceParams {
    pub width: u32,
    pub height: u32,
    pub row_stride: u32,
    pub images: u32,
    pub partial_count: u32,
    /// Index of this dispatch's first per-workgroup sum (one dispatch per eye for large images).
    pub partial_offset: u32,
    pub _pad1: u32,
    pub _pad2: u32,
}

/// `SlitParams` in shaders/slit.wgsl. 160 bytes.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct SlitParams {
    pub view: [[f32; 4]; 4],
    pub projection: ProjectionUniform,
    pub eye_sign: f32,
    pub ambient: f32,
    pub near: f32,
    /// As in [`RasterParams`].
    pub error_angle: u32,
}

/// `SlitCamera` in shaders/slit.wgsl: the camera's position and axes (viewer frame), the tile
/// centre in NDC (x in `right_cx.w`, y in `up_cy.w`) and the NDC per unit of x_c/z_c
/// (`origin_sx.w`) and y_c/z_c (`forward_sy.w`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct SlitCamera {
    pub origin_sx: [f32; 4],
    pub right_cx: [f32; 4],
    pub up_cy: [f32; 4],
    pub forward_sy: [f32; 4],
}

/// `ProjectParams` in shaders/project_points.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct ProjectParams {
    pub projection: ProjectionUniform,
    pub eye_sign: f32,
    pub count: u32,
    pub _pad: [f32; 2],
}

/// `Totals` in shaders/reduce_error.wgsl (GPU-internal: cleared, then read by `finish` only).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct Totals {
    pub count: u32,
    pub max_bits: u32,
}

/// A piece record of `subdivide`: the input triangle, the macro cell (its part's edge counts and
/// K packed), and the part's corners (viewer-frame positions and barycentric weights in the
/// triangle), so that `lattice` need not cut the triangle again.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct Piece {
    pub triangle: u32,
    pub cell: u32,
    /// n0 | n1 << 16
    pub counts01: u32,
    /// n2 | K << 16
    pub count2_level: u32,
    /// Corner i: position xyz, barycentric weight of the triangle's corner 0.
    pub corner: [[f32; 4]; 3],
    /// Barycentric weights of the triangle's corners 1 and 2 at each part corner (x, y, z: the
    /// part's corners 0, 1, 2).
    pub bary1: [f32; 4],
    pub bary2: [f32; 4],
    /// Each edge's profile's bend vectors (`EdgeProfile::bend_vec`: left x, y, right x, y; 0
    /// where not fully measured), for the nodes drawn off their projections.
    pub bend: [[f32; 4]; 3],
}

/// `PieceWork` in shaders/shared/subdivide_types.wgsl: what `lattice` planned for a piece (at
/// the piece's index), which its work items read (`lattice_nodes`, `lattice_triangles`).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Pod, Zeroable)]
pub struct PieceWork {
    /// How it is drawn: a sliver's strip (its base edge 0–2), the lattice (3), rows
    /// (`ROWS_SHAPE`), or `ROWS_PENDING` while its rows are measured.
    pub shape: u32,
    /// Its lattice level (the largest edge count).
    pub m: u32,
    pub node_count: u32,
    /// Candidate triangles (the lattice's m², the strip's, the rows').
    pub candidates: u32,
    /// Seam copies (1–3); 0: nothing drawn.
    pub copies: u32,
    /// The output node of the first copy's slot 0 (copy c's at + c·node_count).
    pub first_node: u32,
    /// The piece's edge counts, 8 bits each; rows: the base edge in bits 24–31.
    pub counts: u32,
    /// A strip's or rows' sides' counts: x | y << 16.
    pub strip_n: u32,
    /// Each copy's reference azimuth (`theta_ref`; x, y, z).
    pub refs: [f32; 4],
    /// Rows: each row's parts (33 rows at most); while `lattice_rows` measures them, each
    /// band's measures (`row_measures`).
    pub row_w: [u32; 33],
    pub _pad: [u32; 3],
}

/// `StoredWork` in shaders/shared/subdivide_types.wgsl: a piece's work as `piece_work` stores it,
/// with where its nodes are drawn off their projections (`cpu::subdivide::offsets`; image
/// pixels, y down, left (x, y) and right (x, y)): inside edge 0, 1, 2; at corner 0, 1, 2; inside.
/// Apart from `PieceWork`, which the passes copy by value.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct StoredWork {
    pub work: PieceWork,
    pub offsets: [[f32; 4]; 7],
}

impl Default for PieceWork {
    fn default() -> Self {
        bytemuck::Zeroable::zeroed()
    }
}

/// A Rust struct's layout, to be checked against its WGSL twin.
#[derive(Clone, Copy, Debug)]
pub struct StructLayout {
    /// The WGSL struct's name.
    pub wgsl_name: &'static str,
    pub rust_name: &'static str,
    pub size: usize,
    /// (field name, byte offset), in declaration order.
    pub fields: &'static [(&'static str, usize)],
}

macro_rules! layout {
    ($wgsl:literal => $ty:ident { $($field:ident),* $(,)? }) => {
        StructLayout {
            wgsl_name: $wgsl,
            rust_name: stringify!($ty),
            size: size_of::<$ty>(),
            fields: &[$((stringify!($field), offset_of!($ty, $field))),*],
        }
    };
}

/// `TraceParams` in shaders/trace.wgsl. 256 bytes.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct TraceParams {
    /// Viewer frame → scene frame, columns (the inverse of `RenderSettings::view`).
    pub to_scene: [[f32; 4]; 4],
    pub projection: ProjectionUniform,
    /// Background colour, display (sRGB) values, alpha 1.
    pub background: [f32; 4],
    /// The point light (scene frame) in xyz, w = 1; w = 0: the headlight at the viewer.
    pub light: [f32; 4],
    /// The visual-field LOD's gaze (viewer frame): forward (w = 1: LOD on), right, up.
    pub gaze_forward: [f32; 4],
    pub gaze_right: [f32; 4],
    pub gaze_up: [f32; 4],
    pub ambient: f32,
    /// As in [`RasterParams`].
    pub error_angle: u32,
    /// Padded row length of the outputs, texels (rows of 256 bytes, as texture copies need).
    pub row_texels: u32,
    /// Bounces of mirror and refraction rays (`ShadingSettings::reflect_max`).
    pub reflect_max: u32,
    /// N_min / N_max of eq. 10 (`ShadingSettings::trace_min_share`).
    pub lod_min_share: f32,
    /// Where rays that meet every object's original start (`SceneBvh::original_root`), and
    /// the visual level above which they do (`SceneBvh::original_level`).
    pub original_root: u32,
    pub original_level: f32,
    /// Rays per pixel, through `core::shading::sampling::sample_position` (`ShadingSettings::samples`).
    pub samples: u32,
}

/// `ShadowParams` in shaders/shadow.wgsl: one shadow map's projection, scene frame → the
/// light's clip space (`GpuShadowMap::clip_from_viewer` × the view).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct ShadowParams {
    pub clip_from_scene: [[f32; 4]; 4],
}

/// `SkinSource` in shaders/skin.wgsl: a posed vertex's data in its mesh frame (`cpu::skin`):
/// position and instance, normal and the scene vertex it poses, tangent (w = 0: none), four
/// joints (16 bits each), its first morph offset (`NO_SKIN`: none), four weights. 80 bytes.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct SkinSource {
    pub position: [f32; 3],
    pub instance: u32,
    pub normal: [f32; 3],
    pub vertex: u32,
    pub tangent: [f32; 4],
    pub joints: [u32; 2],
    pub first_delta: u32,
    pub _pad: u32,
    pub weights: [f32; 4],
}

/// `SkinInstance` in shaders/skin.wgsl: an instance's matrix for a frame (placement × its
/// node's, or the placement alone when skinned), its inverse transpose, its skin's joints
/// (`NO_SKIN`: none) and morph weights in the frame's tables, −1 where the matrix mirrors.
/// 160 bytes.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct SkinInstance {
    pub matrix: [[f32; 4]; 4],
    pub normal_matrix: [[f32; 4]; 4],
    pub first_joint: u32,
    pub joint_count: u32,
    pub first_weight: u32,
    pub weight_count: u32,
    pub mirror: f32,
    pub _pad0: u32,
    pub _pad1: u32,
    pub _pad2: u32,
}

/// `SkinParams` in shaders/skin.wgsl: how many sources.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct SkinParams {
    pub count: u32,
    pub _pad0: u32,
    pub _pad1: u32,
    pub _pad2: u32,
}

/// No skin / no morph offsets (`NO_SKIN` in the WGSL `constants` module).
pub const NO_SKIN: u32 = u32::MAX;

/// Every struct the stages bind (as a uniform or in a storage buffer), by its WGSL name.
pub const LAYOUTS: &[StructLayout] = &[
    layout!("SceneVertex" => SceneVertex { position, material, normal, object, color, uv, tangent, flags }),
    layout!("DrawVertex" => DrawVertex { position, theta_ref, normal, material, color, uv, object, tangent, offsets }),
    layout!("Projection" => ProjectionUniform {
        screen_radius, eye_radius, width, height, acos_eye_screen, vertical_exact, pixels_per_v, panorama,
        convergence, pole_from, pole_to, turn_px, fov, dome_tilt, head_on, head_turn, head_offset, face, wall_corner, wall_on, wall_right, _pad1, wall_up, _pad2, tile
    }),
    layout!("SubdivideParams" => SubdivideParams {
        view, projection, axis_clearance, triangle_count, first_triangle, method, fixed_n, edge_px, max_div,
        piece_capacity, triangle_capacity, first_piece, piece_count, measure_edges, vertical_limit, max_error_px, by_azimuth, seamless, pinhole_faces, node_offsets, antipode_cos, _pad
    }),
    layout!("Counters" => SubdivideCounters { pieces, triangles, max_edge_bits, cut_count, nodes, cut_wide, max_pieces, max_output, parts, node_items, triangle_items, row_items, pending, cuts_low, cuts_high, _pad }),
    layout!("Piece" => Piece { triangle, cell, counts01, count2_level, corner, bary1, bary2, bend }),
    layout!("PieceWork" => PieceWork { shape, m, node_count, candidates, copies, first_node, counts, strip_n, refs, row_w, _pad }),
    layout!("StoredWork" => StoredWork { work, offsets }),
    layout!("DrawIndexedIndirectArgs" => DrawIndexedIndirectArgs { index_count, instance_count, first_index, base_vertex, first_instance }),
    layout!("RasterParams" => RasterParams { projection, eye_sign, ambient, shift_px, error_angle, w_by_radius, _pad1, _pad2 }),
    layout!("DisplayParams" => DisplayParams { projection, mode, width, height, row_texels, layers, srgb_target, _pad0, _pad1, area, look, overlay }),
    layout!("SlitParams" => SlitParams { view, projection, eye_sign, ambient, near, error_angle }),
    layout!("SlitCamera" => SlitCamera { origin_sx, right_cx, up_cy, forward_sy }),
    layout!("TraceParams" => TraceParams { to_scene, projection, background, light, gaze_forward, gaze_right, gaze_up, ambient, error_angle, row_texels, reflect_max, lod_min_share, original_root, original_level, samples }),
    layout!("BvhNode" => BvhNode { min, first, max, count }),
    layout!("BvhLevel" => BvhLevel { root, triangles }),
    layout!("Light" => GpuLight { position, kind, direction, range, color, inner_cos, outer_cos, shadow_map, _pad1, _pad2 }),
    layout!("ShadowMap" => GpuShadowMap { clip_from_viewer, offset, size, texel, projection }),
    layout!("ShadowParams" => ShadowParams { clip_from_scene }),
    layout!("SkinSource" => SkinSource { position, instance, normal, vertex, tangent, joints, first_delta, _pad, weights }),
    layout!("SkinInstance" => SkinInstance { matrix, normal_matrix, first_joint, joint_count, first_weight, weight_count, mirror, _pad0, _pad1, _pad2 }),
    layout!("SkinParams" => SkinParams { count, _pad0, _pad1, _pad2 }),
    layout!("Lighting" => LightingParams {
        count, pbr, exposure, tonemap, environment, env_background, env_lut, shadows, anisotropy, _pad0, _pad1, _pad2, env_rotation, env_sh, env_levels
    }),
    layout!("ProjectParams" => ProjectParams { projection, eye_sign, count, _pad }),
    layout!("Material" => Material {
        texture, wrap_u, wrap_v, mag_filter, min_filter, mipmap, alpha_mode, alpha_cutoff, double_sided,
        first_mip, mip_count, mirror, transmission, ior, metallic, roughness, emissive_r, emissive_g, emissive_b,
        mr_texture, mr_first_mip, mr_mip_count, normal_texture, normal_first_mip, normal_mip_count, normal_scale,
        occlusion_texture, occlusion_first_mip, occlusion_mip_count, occlusion_strength,
        emissive_texture, emissive_first_mip, emissive_mip_count
    }),
    layout!("MipLevel" => MipLevel { offset, width, height, _pad }),
    layout!("ReduceParams" => ReduceParams { width, height, row_stride, images, partial_count, partial_offset, _pad1, _pad2 }),
    layout!("Totals" => Totals { count, max_bits }),
    layout!("ErrorStats" => ErrorStats { count, mean, std_dev, p50, p90, p99, max, _pad }),
];
