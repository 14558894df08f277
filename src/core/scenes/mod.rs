//! Scenes: the data, the loaders (glTF, OBJ), the built-in scenes and shapes, shared edges, the BVH, animation and timelines.

pub mod animation;
pub mod builtin;
pub mod bvh;
pub mod load;
pub mod scene;
pub mod shapes;
pub mod shared_edges;
pub mod timeline;
