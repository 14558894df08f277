//! Shading: materials, lights, the environment (image-based lighting), textures, colour, shadow maps, sampling.

pub mod color;
pub mod environment;
pub mod light;
pub mod material;
pub mod sampling;
pub mod shadow;
pub mod texture;
