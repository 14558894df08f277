//! The encoding: what the CPU side and the GPU side of a frame agree on, between [`crate::core`]
//! (the scene and settings) and the two engines that run the stages, `cpu` (the twins) and
//! `gpu` (wgpu), which never import each other (as vello_encoding sits between the scene and
//! its GPU and CPU shaders).
//!
//! - [`types`]: the plain-old-data structs laid out as WGSL reads them, and their field offsets;
//! - [`constants`]: constants shared with WGSL (the generated `constants` module);
//! - [`params`], [`subdivide`], [`slits`], [`skin`]: each stage's parameters and tables built
//!   from the settings and the scene, and the outputs both engines give;
//! - [`frame`]: a whole frame's schedule as data, recorded once, run by either engine;
//! - [`recording`]: a stage's schedule as data (the subdivision's, in [`subdivide`]);
//! - [`schedule`]: the subdivision's frame schedules and its one overflow policy, run by either
//!   engine.

pub mod constants;
pub mod frame;
pub mod params;
pub mod recording;
pub mod schedule;
pub mod skin;
pub mod slits;
pub mod subdivide;
pub mod types;
