//! twister: a GPU rasterizer for omnidirectional stereo — the pair of concentric-mosaic
//! panoramas (one per eye) that the TWISTER display shows around its viewer (seed 002).
//!
//! Stages (each a WGSL file in `shaders/` with a CPU twin of the same name here):
//! - `subdivide` ([`subdivide::subdivide`], `shaders/subdivide.wgsl`): adaptive subdivision (eq. 5),
//!   axis split, seam copies;
//! - `raster` ([`raster::raster`], `shaders/raster.wgsl`): projection per vertex (eq. 1–4), shading;
//! - `slit` ([`slit::slit`], `shaders/slit.wgsl`): the conventional slit-mosaic reference renderer;
//! - `reduce_error` ([`reduce::reduce_error`], `shaders/reduce_error.wgsl`): error statistics;
//! - `project_points` ([`projection::project_points`], `shaders/project_points.wgsl`).

// Comparisons written `!(x > y)` are deliberate: they put NaN on the rejecting side.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

pub mod bench;
pub mod bench_lod;
pub mod builtin;
pub mod compare;
pub mod figures;
pub mod fragment;
pub mod gpu;
pub mod gpu_types;
pub mod heatmap;
pub mod load;
pub mod lod;
pub mod output;
pub mod plot;
pub mod projection;
pub mod raster;
pub mod reduce;
pub mod renderer;
pub mod scene;
pub mod shaders;
pub mod slit;
pub mod subdivide;
pub mod texture;
pub mod visual_field;

pub use projection::{Eye, Projection, Vertical};
pub use renderer::{Frame, GpuScene, RenderSettings, Renderer};
pub use scene::Scene;
