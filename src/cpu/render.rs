//! A whole frame of the projection methods (`vertex`, `fixed`, `adaptive`) on the CPU: the
//! twins of the GPU's stages in the frame's order — `shadow` (the lights' maps), `subdivide`,
//! `raster` (one sample at each pixel's centre: colour, error, object, distance) and, with
//! several samples, the multisampled colour and its resolve — as `Renderer::render` runs them on
//! the GPU. The oracle a test compares a GPU frame against, without assembling the stages
//! itself.

use crate::core::scenes::scene::Scene;
use crate::core::settings::RenderSettings;
use crate::core::shading::texture::MaterialTable;
use crate::cpu::multisample::raster_multisampled;
use crate::cpu::raster::{raster, RasterImage};
use crate::cpu::shadow::shadow;
use crate::cpu::subdivide::subdivide;
use crate::encoding::params::raster_params;
use crate::encoding::subdivide::subdivide_params;
use crate::encoding::types::DrawVertex;

/// A frame drawn by the CPU twins.
pub struct CpuFrame {
    /// Per eye: the colour (resolved, with several samples) and the centre sample's error,
    /// object and distance.
    pub eyes: [RasterImage; 2],
    /// The subdivision's triangles (three vertices each).
    pub triangles: Vec<DrawVertex>,
}

/// The material table a frame's drawing stages read: the scene's materials with its lights,
/// the lighting mode, and the shadow maps drawn by the shadow stage's twin.
pub fn lit_table(scene: &Scene, settings: &RenderSettings) -> MaterialTable {
    let (lights, lighting, maps) =
        settings.shadowed_lighting(&scene.lights, scene.physically_based, scene.environment.as_deref(), scene.bounds());
    let table = scene.material_table(usize::MAX);
    let depths = shadow(&scene.vertices, &scene.indices, &table, settings.view(), &maps);
    table.with_lighting(lights, lighting).with_shadows(maps, depths)
}

/// Draws `scene` with `settings` through the CPU twins (a projection method's frame; the slit
/// renderer and the tracer have their own twins, `cpu::slit` and `cpu::trace`).
pub fn render(scene: &Scene, settings: &RenderSettings) -> CpuFrame {
    let subdivision = subdivide_params(settings, 0, scene.triangle_count() as u32);
    let triangles = subdivide(&subdivision, &scene.vertices, &scene.indices).vertices;
    let table = lit_table(scene, settings);
    let (background, samples) = (settings.shading.background, settings.shading.samples);
    let params = raster_params(settings);
    let mut eyes = raster(&params, &triangles, &table, background);
    if samples > 1 {
        let resolved = raster_multisampled(&params, &triangles, &table, background, samples);
        for (eye, rgba) in eyes.iter_mut().zip(resolved) {
            eye.rgba = rgba;
        }
    }
    CpuFrame { eyes, triangles }
}
