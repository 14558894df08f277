//! The core: maths and data with no GPU in them. The projection (seed 002 eq. 1–4) as a
//! [`panoramas::panorama::Panorama`], scenes with their loaders and materials, the visual field and level
//! of detail (seeds 000/001), render settings and the frames a renderer returns.

pub mod assets;
pub mod caches;
pub mod choice;
pub mod compare;
pub mod detail;
pub mod display;
pub mod frame;
pub mod panoramas;
pub mod scenes;
pub mod settings;
pub mod shading;
