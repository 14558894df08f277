//! Plain-old-data structs shared with the WGSL stages. Every struct here has a WGSL twin of the
//! same name and layout (the comments name the file); `tests/shaders.rs` checks the sizes.

use bytemuck::{Pod, Zeroable};

use crate::projection::{Projection, Vertical};

/// A scene vertex as the stages read it (`SceneVertex` in shaders/subdivide.wgsl). 64 bytes.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct SceneVertex {
    pub position: [f32; 3],
    pub material: u32,
    pub normal: [f32; 3],
    /// Index of the scene object the vertex belongs to.
    pub object: u32,
    pub color: [f32; 4],
    pub uv: [f32; 2],
    pub _pad1: [f32; 2],
}

/// A vertex of a prepared triangle (`DrawVertex` in shaders/subdivide.wgsl and raster.wgsl),
/// in the viewer frame. `theta_ref` is the azimuth the vertex stage unwraps θ around; seam
/// copies carry it shifted by ±2π. 64 bytes; also the vertex-buffer layout of the raster stage.
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
    pub _pad: f32,
}

/// `Projection` in shaders/projection.wgsl. 32 bytes.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct ProjectionUniform {
    pub screen_radius: f32,
    pub eye_radius: f32,
    pub width: f32,
    pub height: f32,
    pub acos_eye_screen: f32,
    pub vertical_exact: u32,
    pub pixels_per_metre: f32,
    pub _pad: f32,
}

impl From<&ProjectionUniform> for Projection {
    fn from(p: &ProjectionUniform) -> Self {
        Projection {
            screen_radius: p.screen_radius,
            eye_radius: p.eye_radius,
            width: p.width as u32,
            height: p.height as u32,
            vertical: if p.vertical_exact != 0 { Vertical::Exact } else { Vertical::Paper },
        }
    }
}

impl From<&Projection> for ProjectionUniform {
    fn from(p: &Projection) -> Self {
        ProjectionUniform {
            screen_radius: p.screen_radius,
            eye_radius: p.eye_radius,
            width: p.width as f32,
            height: p.height as f32,
            acos_eye_screen: p.acos_eye_screen(),
            vertical_exact: (p.vertical == Vertical::Exact) as u32,
            pixels_per_metre: p.pixels_per_metre(),
            _pad: 0.0,
        }
    }
}

/// `SubdivideParams` in shaders/subdivide.wgsl. 144 bytes.
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
}

impl SubdivideParams {
    pub fn with_measure_edges(self, on: bool) -> Self {
        SubdivideParams { measure_edges: on as u32, ..self }
    }
}

/// `Counters` in shaders/subdivide.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct SubdivideCounters {
    pub pieces: u32,
    pub triangles: u32,
    /// Bits of the largest visible output edge in pixels (an f32).
    pub max_edge_bits: u32,
    pub _pad: u32,
}

/// `RasterParams` in shaders/raster.wgsl. 48 bytes.
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
}

/// `DrawIndirectArgs` as the GPU reads them.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct DrawIndirectArgs {
    pub vertex_count: u32,
    pub instance_count: u32,
    pub first_vertex: u32,
    pub first_instance: u32,
}

/// No texture (`Material::texture`).
pub const NO_TEXTURE: u32 = u32::MAX;

/// A surface material as the fragment stage reads it (`Material` in shaders/fragment.wgsl),
/// indexed by a vertex's `material` (0: the default material). The base colour factor is
/// already multiplied into the vertex colours; this holds what needs the fragment. 48 bytes.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Pod, Zeroable)]
pub struct Material {
    /// Index of the base colour texture in the scene's textures, or `NO_TEXTURE`.
    pub texture: u32,
    /// Wrap modes along u and v (`Wrap as u32`).
    pub wrap_u: u32,
    pub wrap_v: u32,
    /// Filters (`Filter as u32`): magnification, minification within a level, between levels.
    pub mag_filter: u32,
    pub min_filter: u32,
    pub mipmap: u32,
    /// `AlphaMode as u32`.
    pub alpha_mode: u32,
    pub alpha_cutoff: f32,
    /// 1: both faces drawn; 0: faces seen from behind are culled.
    pub double_sided: u32,
    /// Filled in when the textures are packed: the texture's first entry in the mip table and
    /// its level count.
    pub first_mip: u32,
    pub mip_count: u32,
    pub _pad: u32,
}

impl Default for Material {
    /// The default material: untextured, opaque, double-sided.
    fn default() -> Self {
        Material {
            texture: NO_TEXTURE,
            wrap_u: Wrap::Repeat as u32,
            wrap_v: Wrap::Repeat as u32,
            mag_filter: Filter::Linear as u32,
            min_filter: Filter::Linear as u32,
            mipmap: Mipmap::Linear as u32,
            alpha_mode: AlphaMode::Opaque as u32,
            alpha_cutoff: 0.5,
            double_sided: 1,
            first_mip: 0,
            mip_count: 0,
            _pad: 0,
        }
    }
}

/// Texture wrap mode (glTF sampler `wrapS`/`wrapT`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Wrap {
    Repeat = 0,
    ClampToEdge = 1,
    MirroredRepeat = 2,
}

/// Texel filter within one mip level.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Filter {
    Nearest = 0,
    Linear = 1,
}

/// How the minification filter uses the mip levels: not at all (level 0), the nearest level,
/// or a blend of the two nearest.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Mipmap {
    None = 0,
    Nearest = 1,
    Linear = 2,
}

/// glTF alpha mode. BLEND is drawn as order-independent screen-door transparency (see
/// shaders/fragment.wgsl).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum AlphaMode {
    Opaque = 0,
    Mask = 1,
    Blend = 2,
}

/// One mip level of a packed texture (`MipLevel` in shaders/fragment.wgsl): where its texels
/// start in the texel buffer (one RGBA8 sRGB texel per u32, rows top to bottom) and its size.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct MipLevel {
    pub offset: u32,
    pub width: u32,
    pub height: u32,
    pub _pad: u32,
}
