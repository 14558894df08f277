//! The shadow stage's twin check (tests/twins.rs): each shadow map's depths drawn on the GPU
//! against `cpu::shadow` on the same scene and maps.

use twister::core::settings::Method;
use twister::core::shading::light::LightKind;
use twister::{GpuScene, Projection, RenderSettings, Renderer, Scene};

use super::{common, Twin};

pub struct Shadow;

/// The maps a frame of `scene` with `settings` draws.
fn maps(scene: &Scene, settings: &RenderSettings) -> Vec<twister::core::shading::shadow::GpuShadowMap> {
    settings.shadowed_lighting(&scene.lights, scene.physically_based, scene.environment.as_deref(), scene.bounds()).2
}

impl Twin for Shadow {
    type Case = (Scene, RenderSettings);
    /// The depths and each map's (offset, side).
    type Output = (Vec<f32>, Vec<(usize, usize)>);
    fn cases() -> Vec<(String, Self::Case)> {
        let settings = RenderSettings::new(Projection { width: 96, height: 32, ..Projection::default() })
            .with_shadow_map_size(256)
            .with_method(Method::Vertex);
        vec![
            // Opaque: depth only.
            ("ball over floor, directional".into(), (common::ball_over_floor(LightKind::Directional, false), settings)),
            // A perspective map; the masked screen's holes (`fs_mask`).
            ("ball and screen, spot".into(), (common::ball_over_floor(LightKind::Spot, true), settings)),
            // A point light's cube.
            ("ball and screen, point".into(), (common::ball_over_floor(LightKind::Point, true), settings)),
            // All three kinds, seen from a moved, turned viewer.
            (
                "lit spheres".into(),
                (
                    common::lit_spheres(),
                    settings.with_viewer(glam::Vec3::new(0.2, 0.1, 0.3)).with_yaw_deg(20.0).with_shadow_map_size(128),
                ),
            ),
        ]
    }
    fn gpu(r: &Renderer, (scene, settings): &Self::Case) -> Self::Output {
        let gs = GpuScene::upload(&r.gpu, scene).unwrap();
        r.render(&gs, settings).unwrap();
        let maps = maps(scene, settings);
        let texels: u64 = maps.iter().map(|m| (m.size * m.size) as u64).sum();
        (r.shadow_depths(&gs, 4 * texels).unwrap(), layout(&maps))
    }
    fn cpu((scene, settings): &Self::Case) -> Self::Output {
        let table = scene.material_table(usize::MAX);
        let maps = maps(scene, settings);
        (twister::cpu::shadow::shadow(&scene.vertices, &scene.indices, &table, settings.view(), &maps), layout(&maps))
    }
    /// The GPU snaps vertices to sub-texel steps and breaks coverage ties its own way: a GPU
    /// depth must lie within 1e-5 of the twin's there or within the range of the twin's 3×3
    /// neighbourhood (where the depth changes fast: grazing surfaces, edges); at most 0.1 % of
    /// the texels beyond, the maps' outermost texels left out.
    fn compare((gpu, maps): &Self::Output, (cpu, _): &Self::Output) -> Result<(), String> {
        if gpu.len() != cpu.len() || cpu.is_empty() {
            return Err(format!("{} GPU depths, {} CPU", gpu.len(), cpu.len()));
        }
        let covered = cpu.iter().filter(|&&d| d < 1.0).count();
        let mut differ = 0;
        for &(offset, size) in maps {
            // Not the outermost texels: the GPU clips triangles at the map's edges (the twin
            // only at the near plane), and grazing surfaces there interpolate differently; a
            // cube's faces are read only inside their central 90° anyway.
            for y in 1..size - 1 {
                for x in 1..size - 1 {
                    let (g, c) = (gpu[offset + y * size + x], cpu[offset + y * size + x]);
                    if (g - c).abs() <= 1e-5 {
                        continue;
                    }
                    let (mut lo, mut hi) = (f32::MAX, f32::MIN);
                    for (nx, ny) in (0..9).map(|k| (x as i64 + k % 3 - 1, y as i64 + k / 3 - 1)) {
                        if (0..size as i64).contains(&nx) && (0..size as i64).contains(&ny) {
                            let d = cpu[offset + ny as usize * size + nx as usize];
                            (lo, hi) = (lo.min(d), hi.max(d));
                        }
                    }
                    differ += !(lo - 1e-5..=hi + 1e-5).contains(&g) as usize;
                }
            }
        }
        if covered * 10 < cpu.len() || differ * 1000 > cpu.len() {
            return Err(format!("{differ} of {} depths differ ({covered} covered)", cpu.len()));
        }
        Ok(())
    }
}

/// Each map's first depth and side.
fn layout(maps: &[twister::core::shading::shadow::GpuShadowMap]) -> Vec<(usize, usize)> {
    maps.iter().map(|m| (m.offset as usize, m.size as usize)).collect()
}
