//! The core: maths and data with no GPU in them. The projection (seed 002 eq. 1–4) as a
//! [`projection::Panorama`], scenes with their loaders and materials, the visual field and level
//! of detail (seeds 000/001), render settings and the frames a renderer returns.

pub mod animation;
pub mod assets;
pub mod builtin;
pub mod bvh;
pub mod cave;
pub mod choice;
pub mod color;
pub mod compare;
pub mod cubemap;
pub mod disk_cache;
pub mod display;
pub mod environment;
pub mod environment_cache;
pub mod fisheye;
pub mod frame;
pub mod head;
pub mod light;
pub mod load;
pub mod lod;
pub mod material;
pub mod panorama;
pub mod projection;
pub mod sampling;
pub mod scene;
pub mod settings;
pub mod shadow;
pub mod shapes;
pub mod shared_edges;
pub mod simplify;
pub mod sphere;
pub mod texture;
pub mod timeline;
pub mod visual_field;
