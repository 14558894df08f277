//! The GPU layer (wgpu): the device, one [`stages::GpuStage`] per stage descriptor, the
//! uploaded scene, render targets, timestamps, the frame plan, and the renderer that runs them.

pub mod device;
pub mod display;
pub mod draw;
pub mod frame;
pub mod frame_plan;
pub mod pipeline_cache;
pub mod project_points;
pub mod reduce_error;
pub mod renderer;
pub mod scene;
pub mod shadow;
pub mod skin;
pub mod slit;
pub mod stages;
pub mod subdivide;
pub mod subdivided;
pub mod targets;
pub mod timestamps;
pub mod trace;

pub use device::Gpu;
pub use renderer::Renderer;
pub use scene::GpuScene;
