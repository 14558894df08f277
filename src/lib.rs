//! twister: a GPU rasterizer for omnidirectional stereo — the pair of concentric-mosaic
//! panoramas (one per eye) that the TWISTER display shows around its viewer (seed 002).
//!
//! Layers, bottom up (a layer imports only the layers above it in this list; `cpu` and `gpu`
//! stand side by side and never import each other; only `gpu` imports wgpu):
//! - [`core`]: the projection, scenes and their loaders, materials, level of detail, settings;
//! - [`encoding`]: what both engines agree on: the plain-old-data structs and constants shared
//!   with WGSL, each stage's parameters and tables built from the settings, the stages' outputs;
//! - [`shader`]: the WGSL sources composed by `#import`, one descriptor per stage (its bindings);
//! - [`cpu`]: one CPU twin per GPU stage, named like its WGSL file (the test oracles);
//! - [`gpu`]: the wgpu device, stage pipelines, targets, the frame plan and the renderer;
//! - [`output`]: image layouts and all-or-nothing file writing.
//!
//! The command line, benchmarks, plots and reports live in the `twister` binary, the workspace's
//! `cli/` crate; the library depends on no command-line, window or plotting crate.

// Comparisons written `!(x > y)` are deliberate: they put NaN on the rejecting side.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

pub mod core;
pub mod cpu;
pub mod encoding;
pub mod error;
pub mod gpu;
pub mod output;
pub mod search;
pub mod shader;
pub mod video;

pub use crate::core::frame::{EyeImage, Frame, FrameStats};
pub use crate::core::panoramas::projection::{Eye, Projection, Vertical};
pub use crate::core::scenes::scene::Scene;
pub use crate::core::settings::RenderSettings;
pub use error::{Error, Result};
pub use gpu::{GpuScene, Renderer};
