//! The shadow stage's twin check (tests/twins.rs): each shadow map's depths drawn on the GPU
//! against `cpu::shadow` on the same scene and maps.

use twister::core::light::LightKind;
use twister::core::settings::Method;
use twister::{GpuScene, Projection, RenderSettings, Renderer, Scene};

use super::{common, Twin};

pub struct Shadow;

/// The maps a frame of `scene` with `settings` draws.
fn maps(scene: &Scene, settings: &RenderSettings) -> Vec<twister::core::shadow::GpuShadowMap> {
    settings.shadowed_lighting(&scene.lights, scene.environment.as_deref(), scene.bounds()).2
}

impl Twin for Shadow {
    type Case = (Scene, RenderSettings);
    type Output = Vec<f32>;
    fn cases() -> Vec<(String, Self::Case)> {
        let settings = RenderSettings::new(Projection { width: 96, height: 32, ..Projection::default() })
            .with_shadow_map_size(256)
            .with_method(Method::Vertex);
        vec![
            // Opaque: depth only.
            ("ball over floor, directional".into(), (common::ball_over_floor(LightKind::Directional, false), settings)),
            // A perspective map; the masked screen's holes (`fs_mask`).
            ("ball and screen, spot".into(), (common::ball_over_floor(LightKind::Spot, true), settings)),
            // A spot and a directional light of three, seen from a moved, turned viewer.
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
        r.shadow_depths(&gs, 4 * texels).unwrap()
    }
    fn cpu((scene, settings): &Self::Case) -> Self::Output {
        let table = scene.material_table(usize::MAX);
        twister::cpu::shadow::shadow(&scene.vertices, &scene.indices, &table, settings.view(), &maps(scene, settings))
    }
    /// Texels on triangle edges may differ (coverage tie-breaking): at most 1 %; elsewhere the
    /// depths agree within 1e-5.
    fn compare(gpu: &Self::Output, cpu: &Self::Output) -> Result<(), String> {
        if gpu.len() != cpu.len() || cpu.is_empty() {
            return Err(format!("{} GPU depths, {} CPU", gpu.len(), cpu.len()));
        }
        let covered = cpu.iter().filter(|&&d| d < 1.0).count();
        let differ = gpu.iter().zip(cpu).filter(|(g, c)| (*g - *c).abs() > 1e-5).count();
        if covered * 10 < cpu.len() || differ * 100 > cpu.len() {
            return Err(format!("{differ} of {} depths differ ({covered} covered)", cpu.len()));
        }
        Ok(())
    }
}
