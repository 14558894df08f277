//! The skin stage's twin check (tests/twins.rs): an animated scene posed by the GPU's skin
//! stage against `cpu::skin` on the same tables (skinned and morphed files, at a time and at
//! rest).

use glam::Vec3;
use twister::core::scenes::load::load_scene;
use twister::core::scenes::scene::{unpack_tangent, SceneVertex};
use twister::cpu::skin::{skin, SkinData, SkinFrame};
use twister::{GpuScene, Projection, Renderer, Scene};

use super::{common, Twin};

pub struct Skin;

impl Twin for Skin {
    type Case = (Scene, Option<usize>, f32);
    type Output = Vec<SceneVertex>;
    const NEEDS_ASSETS: bool = true;
    fn cases() -> Vec<(String, Self::Case)> {
        let load = |f: &str| {
            let mut s = load_scene(common::asset(f).to_str().unwrap(), &Projection::default()).unwrap();
            s.transform(glam::Mat4::from_scale(Vec3::splat(1.5)));
            s
        };
        vec![
            ("CesiumMan at 0.5 s".into(), (load("gltf/CesiumMan/glTF-Binary/CesiumMan.glb"), Some(0), 0.5)),
            ("RiggedSimple at 1 s".into(), (load("gltf/RiggedSimple/glTF-Binary/RiggedSimple.glb"), Some(0), 1.0)),
            (
                "AnimatedMorphCube at 0.7 s".into(),
                (load("gltf/AnimatedMorphCube/glTF-Binary/AnimatedMorphCube.glb"), Some(0), 0.7),
            ),
            ("CesiumMan at rest".into(), (load("gltf/CesiumMan/glTF-Binary/CesiumMan.glb"), None, 0.0)),
        ]
    }
    fn gpu(r: &Renderer, (scene, clip, t): &Self::Case) -> Self::Output {
        let mut scene = scene.clone();
        // Start from garbage positions: the stage must write every posed vertex.
        for v in &mut scene.vertices {
            v.position = [9.0; 3];
        }
        let mut gs = GpuScene::upload(&r.gpu, &scene).unwrap();
        r.pose(&mut gs, &mut scene, *clip, *t).unwrap();
        let bytes = r.gpu.download(&gs.vertices, gs.vertices.size()).unwrap();
        bytemuck::cast_slice(&bytes).to_vec()
    }
    fn cpu((scene, clip, t): &Self::Case) -> Self::Output {
        let rig = scene.rig.as_deref().unwrap();
        let mut vertices = scene.vertices.clone();
        skin(&SkinData::of(rig), &SkinFrame::of(rig, *clip, *t), &mut vertices);
        vertices
    }
    fn compare(gpu: &Self::Output, cpu: &Self::Output) -> Result<(), String> {
        if gpu.len() != cpu.len() || cpu.is_empty() {
            return Err(format!("{} GPU vertices, {} CPU", gpu.len(), cpu.len()));
        }
        let close = |a: [f32; 3], b: [f32; 3]| a.iter().zip(b).all(|(x, y)| (x - y).abs() <= 1e-4 * (1.0 + y.abs()));
        for (k, (g, c)) in gpu.iter().zip(cpu).enumerate() {
            let tangents = (unpack_tangent(g.tangent) - unpack_tangent(c.tangent)).abs().max_element() <= 1e-3;
            if !close(g.position, c.position) || !close(g.normal, c.normal) || !tangents {
                return Err(format!("vertex {k}: GPU {g:?}, CPU {c:?}"));
            }
        }
        Ok(())
    }
}
