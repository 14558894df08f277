//! Visual-field level of detail on the GPU: the subdivision follows each object's level exactly
//! as its CPU twin does, a frame draws fewer triangles, and the error inside the central field
//! does not grow.

mod common;

use glam::Vec3;
use twister::core::detail::lod::{LodChain, LodParams, NO_SPLIT};
use twister::core::detail::visual_field::{Field, Gaze};
use twister::core::panoramas::projection::Projection;
use twister::core::scenes::builtin::sphere_scene;
use twister::core::settings::Method;
use twister::cpu::subdivide::Subdivider;
use twister::encoding::schedule::Schedule;
use twister::encoding::subdivide::subdivide_params;
use twister::{GpuScene, RenderSettings, Scene};

/// Twelve 1024-triangle spheres 3 m around the viewer every 30°.
fn ring() -> Scene {
    let mut scene = Scene::new("ring");
    for k in 0..12 {
        let a = (30.0 * k as f32).to_radians();
        let one = sphere_scene(1024, Vec3::new(-3.0 * a.sin(), 0.0, -3.0 * a.cos()), 0.4, "sphere");
        scene.add_mesh(format!("sphere {k}"), &one.vertices, &one.indices);
    }
    scene
}

fn settings() -> RenderSettings {
    RenderSettings::new(Projection { width: 960, height: 180, ..Projection::default() })
}

#[test]
fn the_subdivision_follows_each_objects_level_as_the_cpu_twin_does() {
    let scene = ring();
    let s = settings();
    let chain = LodChain::build(&scene, 0.05);
    let sel = chain.select(&scene, s.view(), &Gaze::new(30.0, 0.0), &LodParams::default());
    let fields: Vec<Field> = sel.chosen.iter().map(|c| c.field).collect();
    assert!(
        fields.contains(&Field::Central) && fields.contains(&Field::Peripheral) && fields.contains(&Field::Outside)
    );
    let r = common::renderer();
    let base = GpuScene::upload(&r.gpu, &scene).unwrap();
    let gpu = r.subdivide_readback(&base.with_lod(&r.gpu, &sel), &s, Schedule::OneSubmission).unwrap();
    let drawn = sel.scene(&scene);
    let params = subdivide_params(&s, 0, drawn.triangle_count() as u32);
    let scales = sel.edge_scales();
    let cpu = Subdivider::with_edge_scale(&params, &scales).run(&drawn.vertices, &drawn.indices);
    assert_eq!(gpu.vertices.len(), cpu.vertices.len(), "triangles out");
    assert_eq!(gpu.pieces, cpu.pieces);
    // Per object: outside the field nothing is split (vertex method); central objects are split
    // as without the level of detail.
    let count = |out: &[twister::encoding::types::DrawVertex], o: u32| out.iter().filter(|v| v.object == o).count() / 3;
    let full = Subdivider::new(&params).run(&drawn.vertices, &drawn.indices);
    let vertex = Subdivider::new(&subdivide_params(&s.with_method(Method::Vertex), 0, params.triangle_count))
        .run(&drawn.vertices, &drawn.indices);
    for (o, c) in sel.chosen.iter().enumerate() {
        let o = o as u32;
        assert_eq!(count(&gpu.vertices, o), count(&cpu.vertices, o), "object {o}");
        match c.field {
            Field::Outside => {
                assert_eq!(c.edge_scale, NO_SPLIT);
                assert_eq!(count(&cpu.vertices, o), count(&vertex.vertices, o), "object {o} outside: not split");
            }
            Field::Central => assert_eq!(count(&cpu.vertices, o), count(&full.vertices, o), "object {o} central: full"),
            Field::Peripheral => assert!(count(&cpu.vertices, o) <= count(&full.vertices, o), "object {o}"),
        }
    }
}

#[test]
fn fewer_triangles_and_no_worse_error_in_the_central_field() {
    let scene = ring();
    let s = settings().with_measure_error(true);
    let r = common::renderer();
    let base = GpuScene::upload(&r.gpu, &scene).unwrap();
    let chain = LodChain::build(&scene, 0.05);
    for (yaw, pitch) in [(0.0, 0.0), (75.0, 10.0), (-150.0, -20.0)] {
        let gaze = Gaze::new(yaw, pitch);
        let sel = chain.select(&scene, s.view(), &gaze, &LodParams::default());
        let full = r.render(&base, &s).unwrap();
        let lod = r.render(&base.with_lod(&r.gpu, &sel), &s).unwrap();
        assert!(
            10 * lod.stats.triangles_in < 7 * full.stats.triangles_in,
            "{yaw},{pitch}: {} of {}",
            lod.stats.triangles_in,
            full.stats.triangles_in
        );
        // Mean error over the pixels in the central field, both eyes.
        let central_mean = |f: &twister::Frame| {
            let m = f.measurement.as_ref().unwrap();
            let p = &s.view.projection;
            let e: Vec<f32> = m
                .error
                .iter()
                .flat_map(|eye| eye.iter().enumerate())
                .filter(|(i, e)| {
                    let (x, y) = ((*i as u32 % p.width) as f32 + 0.5, (*i as u32 / p.width) as f32 + 0.5);
                    **e >= 0.0 && twister::core::detail::lod::pixel_field(p, &gaze, x, y) == Field::Central
                })
                .map(|(_, e)| *e)
                .collect();
            (e.iter().sum::<f32>() / e.len() as f32, e.len())
        };
        let ((e_full, n_full), (e_lod, n_lod)) = (central_mean(&full), central_mean(&lod));
        assert!(n_full > 500 && n_lod > 500, "{yaw},{pitch}: {n_full} {n_lod} central pixels");
        assert!(e_lod <= e_full * 1.05 + 1e-3, "{yaw},{pitch}: central error {e_lod} with LOD vs {e_full}");
    }
}
