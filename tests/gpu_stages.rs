//! Each GPU stage against its CPU twin.

mod common;

use glam::Vec3;
use rand::{Rng, SeedableRng};
use twister::gpu_types::{DrawVertex, SceneVertex};
use twister::prepare::{prepare, prepare_params};
use twister::raster::raster;
use twister::{builtin, Eye, GpuScene, Projection, RenderSettings, Scene, Vertical};

#[test]
fn gpu_projection_matches_cpu_within_a_thousandth_of_a_pixel() {
    let r = common::renderer();
    let mut rng = rand::rngs::StdRng::seed_from_u64(1);
    let points: Vec<Vec3> = (0..5000)
        .map(|_| {
            let radius: f32 = rng.random_range(0.05f32..40.0);
            let theta: f32 = rng.random_range(-3.14159f32..3.14159);
            Vec3::new(
                radius * theta.sin(),
                rng.random_range(-3.0f32..3.0),
                -radius * theta.cos(),
            )
        })
        .collect();
    for vertical in [Vertical::Paper, Vertical::Exact] {
        let projection = Projection {
            vertical,
            ..Projection::default()
        };
        for eye in Eye::BOTH {
            let gpu = r.project_points(&projection, eye, &points);
            let cpu = twister::projection::project_points(&projection, eye, &points);
            let mut worst = 0.0f32;
            for (i, (g, c)) in gpu.iter().zip(&cpu).enumerate() {
                assert_eq!(
                    g[3], c[3],
                    "point {i} {:?}: seen on one side only",
                    points[i]
                );
                if c[3] == 0.0 {
                    continue;
                }
                let dx = projection.wrapped_dx(g[0], c[0]);
                let dy = (g[1] - c[1]).abs();
                // On or near the image: a thousandth of a pixel. Far off it (near the eye
                // circle, |y| up to 10⁵ px) f32 itself resolves only ~1e-7 relative.
                let near_image =
                    c[1] > -(projection.height as f32) && c[1] < 2.0 * projection.height as f32;
                let tolerance = if near_image { 1e-3 } else { 1e-6 * c[1].abs() };
                if near_image {
                    worst = worst.max(dx.max(dy));
                }
                assert!(
                    dx < 1e-3 && dy < tolerance,
                    "{vertical:?} {eye:?} point {:?}: GPU {g:?} CPU {c:?}",
                    points[i]
                );
            }
            assert!(cpu.iter().filter(|c| c[3] == 1.0).count() > 4500);
            eprintln!("{vertical:?} {eye:?}: worst difference {worst:e} px");
        }
    }
}

/// Matches each CPU triangle to the nearest unused GPU triangle and checks they are the same.
fn assert_same_triangle_sets(cpu: &[DrawVertex], gpu: &[DrawVertex], what: &str) {
    if cpu.len() != gpu.len() {
        for t in gpu.chunks(3) {
            let c = t.iter().fold(Vec3::ZERO, |a, v| a + Vec3::from(v.position)) / 3.0;
            let found = cpu.chunks(3).any(|u| {
                let c2 = u.iter().fold(Vec3::ZERO, |a, v| a + Vec3::from(v.position)) / 3.0;
                (c2 - c).length() < 1e-4 && (u[0].theta_ref - t[0].theta_ref).abs() < 1e-3
            });
            if !found {
                eprintln!("GPU-only triangle {t:?}");
            }
        }
    }
    assert_eq!(
        cpu.len(),
        gpu.len(),
        "{what}: CPU made {} triangles, GPU {}",
        cpu.len() / 3,
        gpu.len() / 3
    );
    let key = |t: &[DrawVertex]| {
        let c = t.iter().fold(Vec3::ZERO, |a, v| a + Vec3::from(v.position)) / 3.0;
        (c, t[0].theta_ref)
    };
    let gpu_tris: Vec<&[DrawVertex]> = gpu.chunks(3).collect();
    let mut used = vec![false; gpu_tris.len()];
    for t in cpu.chunks(3) {
        let (c, th) = key(t);
        let best = (0..gpu_tris.len())
            .filter(|&j| !used[j])
            .min_by(|&a, &b| {
                let d = |j: usize| {
                    let (c2, th2) = key(gpu_tris[j]);
                    (c2 - c).length() + (th2 - th).abs()
                };
                d(a).total_cmp(&d(b))
            })
            .unwrap();
        used[best] = true;
        for (a, b) in t.iter().zip(gpu_tris[best]) {
            let close = |x: &[f32], y: &[f32]| {
                x.iter()
                    .zip(y)
                    .all(|(p, q)| (p - q).abs() <= 1e-4 * (1.0 + p.abs()))
            };
            assert!(
                close(&a.position, &b.position)
                    && close(&[a.theta_ref], &[b.theta_ref])
                    && close(&a.normal, &b.normal)
                    && close(&a.color, &b.color)
                    && close(&a.uv, &b.uv)
                    && a.material == b.material,
                "{what}: CPU vertex {a:?} differs from GPU vertex {b:?}"
            );
        }
    }
}

fn random_triangle_scene(seed: u64, n: usize) -> Scene {
    let mut rng = rand::rngs::StdRng::seed_from_u64(seed);
    let mut scene = Scene::new("random");
    for k in 0..n {
        // Mix of small triangles anywhere, big ones around the viewer, and ones near the axis.
        let scale = [0.3f32, 6.0, 1.0][k % 3];
        let center = match k % 3 {
            2 => Vec3::new(
                rng.random_range(-0.05..0.05),
                rng.random_range(-2.0..2.0),
                rng.random_range(-0.05..0.05),
            ),
            _ => Vec3::new(
                rng.random_range(-8.0..8.0),
                rng.random_range(-3.0..3.0),
                rng.random_range(-8.0..8.0),
            ),
        };
        let v: Vec<SceneVertex> = (0..3)
            .map(|i| SceneVertex {
                position: (center
                    + scale
                        * Vec3::new(
                            rng.random_range(-1.0..1.0),
                            rng.random_range(-1.0..1.0),
                            rng.random_range(-1.0..1.0),
                        ))
                .into(),
                normal: [rng.random_range(-1.0..1.0), 1.0, 0.0],
                color: [rng.random(), rng.random(), rng.random(), 1.0],
                uv: [i as f32, rng.random()],
                material: k as u32,
                ..Default::default()
            })
            .collect();
        scene.add_mesh("t", &v, &[0, 1, 2]);
    }
    scene
}

#[test]
fn gpu_prepare_matches_cpu_twin() {
    let r = common::renderer();
    let projection = Projection {
        width: 640,
        height: 160,
        ..Projection::default()
    };
    let cases = [
        (
            random_triangle_scene(3, 600),
            RenderSettings {
                projection,
                ..Default::default()
            },
        ),
        (
            builtin::demo(),
            RenderSettings {
                projection,
                ..Default::default()
            },
        ),
        (
            builtin::demo(),
            RenderSettings {
                projection,
                viewer: Vec3::new(1.0, 0.3, -2.0),
                yaw_deg: 37.0,
                ..Default::default()
            },
        ),
    ];
    for (scene, settings) in cases {
        let gs = GpuScene::upload(&r.gpu, &scene).unwrap();
        let gpu = r.prepare_readback(&gs, &settings);
        let params = prepare_params(
            &settings.projection,
            settings.view(),
            scene.triangle_count() as u32,
            0,
            u32::MAX,
        );
        let cpu = prepare(&params, &scene.vertices, &scene.indices);
        assert!(
            cpu.len() / 3 > scene.triangle_count(),
            "the scene exercises splits and seam copies"
        );
        assert_same_triangle_sets(&cpu, &gpu, &scene.name);
    }
}

#[test]
fn gpu_raster_matches_cpu_twin() {
    let projection = Projection {
        width: 400,
        height: 100,
        ..Projection::default()
    };
    let scene = builtin::demo();
    let settings = RenderSettings {
        projection,
        ..Default::default()
    };
    let frame = common::render(&scene, &settings);
    let params = prepare_params(
        &projection,
        settings.view(),
        scene.triangle_count() as u32,
        0,
        u32::MAX,
    );
    let prepared = prepare(&params, &scene.vertices, &scene.indices);
    for eye in Eye::BOTH {
        let cpu = raster(&settings.raster_params(eye), &prepared, settings.background);
        let gpu = frame.eye(eye);
        let differing = cpu
            .rgba
            .chunks(4)
            .zip(gpu.rgba.chunks(4))
            .filter(|(a, b)| {
                a.iter()
                    .zip(b.iter())
                    .any(|(x, y)| (*x as i32 - *y as i32).abs() > 2)
            })
            .count();
        let total = (projection.width * projection.height) as usize;
        // Only pixels on triangle edges may differ (tie-breaking and rounding at coverage edges).
        assert!(
            differing * 100 < total,
            "{eye:?}: {differing} of {total} pixels differ"
        );
        eprintln!("{eye:?}: {differing} of {total} pixels differ");
    }
}
