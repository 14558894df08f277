//! CPU twins of the GPU stages, one module per WGSL file of the same name (as vello's
//! `cpu/` stages): straightforward Rust versions that the tests compare the GPU against.
//!
//! | twin | WGSL |
//! |---|---|
//! | [`subdivide`] | `shaders/subdivide/*.wgsl`, one file per pass (`active_cuts`, `ring_cuts`, `plan`, `plan_cuts_args`, `plan_cuts`, `lattice_args`, `lattice`, `finalize`: `subdivide::passes`), and `shaders/shared/subdivide_*.wgsl` |
//! | [`raster`] | `shaders/raster.wgsl` |
//! | [`multisample`] | the drawing stages' multisampled colour (`fs_main`, `fs_coverage`) and its resolve |
//! | [`slit`] | `shaders/slit.wgsl` |
//! | [`trace`] | `shaders/trace.wgsl` |
//! | [`shadow`] | `shaders/shadow.wgsl` |
//! | [`skin`] | `shaders/skin.wgsl` |
//! | [`fragment`] | `shaders/shared/fragment.wgsl` and `surface.wgsl` (composed into raster, slit and trace) |
//! | [`reduce_error`] | `shaders/reduce_error.wgsl` |
//! | [`project_points`] | `shaders/project_points.wgsl` |
//!
//! [`render`] runs a whole frame's recording (`encoding::frame`) through the twins.

pub mod display;
pub mod fragment;
pub mod multisample;
pub mod project_points;
pub mod raster;
pub mod reduce_error;
pub mod render;
pub mod shadow;
pub mod skin;
pub mod slit;
pub mod subdivide;
pub mod trace;
