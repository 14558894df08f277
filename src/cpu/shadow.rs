//! The `shadow` stage, CPU twin of `shaders/shadow.wgsl`: each shadow map's depths, the scene's
//! triangles drawn from the light with the drawing twins' rasterizer (depth test "less", cleared
//! to 1; fragments a material leaves out by its alpha cast no shadow; both faces cast).

use glam::{Mat4, Vec2, Vec3, Vec4};

use crate::core::scenes::scene::SceneVertex;
use crate::core::shading::shadow::GpuShadowMap;
use crate::core::shading::texture::MaterialTable;
use crate::cpu::fragment::{surface_color, Surface};
use crate::cpu::raster::{rasterize, ClipVertex, FragmentIn, FragmentOut, RasterImage};

/// The depths of every map (rows top to bottom, maps one after the other, as
/// `GpuShadowMap::offset` places them) of the scene `vertices`/`indices` (scene frame) seen
/// through `view` (scene → viewer frame, whose maps these are).
pub fn shadow(
    vertices: &[SceneVertex],
    indices: &[u32],
    table: &MaterialTable,
    view: Mat4,
    maps: &[GpuShadowMap],
) -> Vec<f32> {
    let mut depths = Vec::new();
    for map in maps {
        let clip_from_scene = map.matrix() * view;
        let mut img = RasterImage::new(map.size, map.size, [0.0; 3]);
        let fragment = |f: &FragmentIn| {
            let surface = Surface { front_facing: true, ..f.surface };
            surface_color(table, &surface).map(|_| FragmentOut { rgba: [0; 4], error: 0.0, distance: 0.0 })
        };
        for tri in indices.chunks_exact(3) {
            let corners = [0, 1, 2].map(|k| {
                let v = &vertices[tri[k] as usize];
                ClipVertex {
                    clip: clip_from_scene * Vec3::from(v.position).extend(1.0),
                    view_position: Vec3::ZERO,
                    normal: Vec3::ZERO,
                    tangent: Vec4::ZERO,
                    color: Vec4::from(v.color),
                    uv: Vec2::from(v.uv),
                    object: 0,
                    material: v.material,
                }
            });
            rasterize(&mut img, corners, [0, map.size, 0, map.size], &fragment);
        }
        depths.extend(img.depth);
    }
    depths
}
