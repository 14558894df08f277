//! Each GPU stage against its CPU twin.

mod common;

use twister::cpu::raster::raster_params;
use twister::cpu::subdivide::subdivide_params;
use glam::Vec3;
use rand::{Rng, SeedableRng};
use twister::shader::types::DrawVertex;
use twister::core::scene::SceneVertex;
use twister::cpu::raster::raster;
use twister::cpu::subdivide::subdivide;
use twister::core::settings::Method;
use twister::core::builtin;
use twister::{Eye, GpuScene, Projection, RenderSettings, Scene, Vertical};

#[test]
fn project_points_takes_no_points_and_more_than_one_dispatch_row() {
    let r = common::renderer();
    let projection = Projection { width: 800, height: 200, ..Projection::default() };
    assert!(r.project_points(&projection, Eye::Left, &[]).unwrap().is_empty());
    // 65,535 workgroups of 64 hold 4,194,240 points: beyond them the dispatch is 2-D, and
    // every point, the last ones included, must be projected.
    let n = 65_535 * 64 + 1000;
    let points: Vec<Vec3> = (0..n)
        .map(|i| {
            let a = i as f32 * 1e-4;
            Vec3::new(2.0 * a.sin(), (i % 7) as f32 * 0.1 - 0.3, -2.0 * a.cos())
        })
        .collect();
    let gpu = r.project_points(&projection, Eye::Right, &points).unwrap();
    assert_eq!(gpu.len(), n);
    let sample: Vec<usize> = (0..n).step_by(9973).chain(n - 1100..n).collect();
    let cpu = twister::cpu::project_points::project_points(
        &projection,
        Eye::Right,
        &sample.iter().map(|&i| points[i]).collect::<Vec<_>>(),
    );
    for (&i, c) in sample.iter().zip(&cpu) {
        let g = gpu[i];
        assert_eq!(g[3], 1.0, "point {i} was not projected");
        assert!(projection.wrapped_dx(g[0], c[0]) < 1e-2 && (g[1] - c[1]).abs() < 1e-2, "point {i}: {g:?} vs {c:?}");
    }
}

#[test]
fn gpu_projection_matches_cpu_within_a_thousandth_of_a_pixel() {
    let r = common::renderer();
    let mut rng = rand::rngs::StdRng::seed_from_u64(1);
    let points: Vec<Vec3> = (0..5000)
        .map(|_| {
            let radius: f32 = rng.random_range(0.05f32..40.0);
            let theta: f32 = rng.random_range(-std::f32::consts::PI..std::f32::consts::PI);
            Vec3::new(radius * theta.sin(), rng.random_range(-3.0f32..3.0), -radius * theta.cos())
        })
        .collect();
    for vertical in [Vertical::Paper, Vertical::Exact] {
        let projection = Projection { vertical, ..Projection::default() };
        for eye in Eye::BOTH {
            let gpu = r.project_points(&projection, eye, &points).unwrap();
            let cpu = twister::cpu::project_points::project_points(&projection, eye, &points);
            let mut worst = 0.0f32;
            for (i, (g, c)) in gpu.iter().zip(&cpu).enumerate() {
                assert_eq!(g[3], c[3], "point {i} {:?}: seen on one side only", points[i]);
                if c[3] == 0.0 {
                    continue;
                }
                let dx = projection.wrapped_dx(g[0], c[0]);
                let dy = (g[1] - c[1]).abs();
                // On or near the image: a thousandth of a pixel. Far off it (near the eye
                // circle, |y| up to 10⁵ px) f32 itself resolves only ~1e-7 relative.
                let near_image = c[1] > -(projection.height as f32) && c[1] < 2.0 * projection.height as f32;
                let tolerance = if near_image { 1e-3 } else { 1e-6 * c[1].abs() };
                if near_image {
                    worst = worst.max(dx.max(dy));
                }
                assert!(dx < 1e-3 && dy < tolerance, "{vertical:?} {eye:?} point {:?}: GPU {g:?} CPU {c:?}", points[i]);
            }
            assert!(cpu.iter().filter(|c| c[3] == 1.0).count() > 4500);
            eprintln!("{vertical:?} {eye:?}: worst difference {worst:e} px");
        }
    }
}

/// Matches each CPU triangle to the nearest unused GPU triangle (searched among those whose
/// centroid and reference azimuth fall in neighbouring buckets) and checks they are the same.
fn assert_same_triangle_sets(cpu: &[DrawVertex], gpu: &[DrawVertex], what: &str) {
    use std::collections::HashMap;
    assert_eq!(cpu.len(), gpu.len(), "{what}: CPU made {} triangles, GPU {}", cpu.len() / 3, gpu.len() / 3);
    let key = |t: &[DrawVertex]| {
        let c = t.iter().fold(Vec3::ZERO, |a, v| a + Vec3::from(v.position)) / 3.0;
        (c, t[0].theta_ref)
    };
    let cell = |c: Vec3, th: f32| {
        ((c.x * 1e3).floor() as i64, (c.y * 1e3).floor() as i64, (c.z * 1e3).floor() as i64, (th * 10.0).floor() as i64)
    };
    let gpu_tris: Vec<&[DrawVertex]> = gpu.chunks(3).collect();
    let mut buckets: HashMap<(i64, i64, i64, i64), Vec<usize>> = HashMap::new();
    for (j, t) in gpu_tris.iter().enumerate() {
        let (c, th) = key(t);
        buckets.entry(cell(c, th)).or_default().push(j);
    }
    let mut used = vec![false; gpu_tris.len()];
    for t in cpu.chunks(3) {
        let (c, th) = key(t);
        let k = cell(c, th);
        let mut best: Option<(f32, usize)> = None;
        for dx in -1..=1 {
            for dy in -1..=1 {
                for dz in -1..=1 {
                    for dt in -1..=1 {
                        for &j in buckets.get(&(k.0 + dx, k.1 + dy, k.2 + dz, k.3 + dt)).into_iter().flatten() {
                            if used[j] {
                                continue;
                            }
                            let (c2, th2) = key(gpu_tris[j]);
                            let d = (c2 - c).length() + (th2 - th).abs();
                            if best.is_none_or(|(bd, _)| d < bd) {
                                best = Some((d, j));
                            }
                        }
                    }
                }
            }
        }
        let (_, best) = best.unwrap_or_else(|| panic!("{what}: CPU triangle {t:?} has no GPU twin"));
        used[best] = true;
        for (a, b) in t.iter().zip(gpu_tris[best]) {
            let close = |x: &[f32], y: &[f32]| x.iter().zip(y).all(|(p, q)| (p - q).abs() <= 1e-4 * (1.0 + p.abs()));
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
            2 => Vec3::new(rng.random_range(-0.05..0.05), rng.random_range(-2.0..2.0), rng.random_range(-0.05..0.05)),
            _ => Vec3::new(rng.random_range(-8.0..8.0), rng.random_range(-3.0..3.0), rng.random_range(-8.0..8.0)),
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
fn gpu_subdivide_matches_cpu_twin() {
    let r = common::renderer();
    let projection = Projection { width: 640, height: 160, ..Projection::default() };
    let base = RenderSettings::new(projection).with_measure_edges(true);
    let moved = base.clone().with_viewer(Vec3::new(1.0, 0.3, -2.0)).with_yaw_deg(37.0);
    let sphere = builtin::builtin_scene("builtin:sphere100", &projection).unwrap();
    let cases = [
        (random_triangle_scene(3, 600), base.clone().with_method(Method::Vertex)),
        (random_triangle_scene(4, 300), base.clone()),
        (random_triangle_scene(5, 200), base.clone().with_method(Method::Fixed(5))),
        (builtin::demo(), base.clone()),
        (builtin::demo(), moved.clone().with_method(Method::Vertex)),
        (builtin::demo(), moved.clone().with_edge_px(12.0).with_max_div(4)),
        (sphere, base.clone().with_edge_px(8.0)),
        (
            builtin::sphere_scene(1024, Vec3::ZERO, 2.5, "sphere around the viewer"),
            base.clone().with_edge_px(16.0),
        ),
    ];
    for (k, (scene, settings)) in cases.iter().enumerate() {
        let gs = GpuScene::upload(&r.gpu, scene).unwrap();
        let gpu = r.subdivide_readback(&gs, settings).unwrap();
        let params = subdivide_params(&settings, 0, scene.triangle_count() as u32);
        let cpu = subdivide(&params, &scene.vertices, &scene.indices);
        let what = format!("case {k}: {} {}", scene.name, settings.subdivision.method.name());
        assert!(cpu.vertices.len() / 3 > scene.triangle_count(), "{what}: exercises splits and seam copies");
        assert_eq!(cpu.pieces, gpu.pieces, "{what}: pieces");
        assert!(
            (cpu.max_sub_edge_px - gpu.max_sub_edge_px).abs() < 1e-2 * (1.0 + cpu.max_sub_edge_px),
            "{what}: max edge"
        );
        assert_same_triangle_sets(&cpu.vertices, &gpu.vertices, &what);
    }
}

#[test]
fn gpu_raster_matches_cpu_twin() {
    let projection = Projection { width: 400, height: 100, ..Projection::default() };
    let scene = builtin::demo();
    let settings = RenderSettings::new(projection);
    let frame = common::render(&scene, &settings);
    let params = subdivide_params(&settings, 0, scene.triangle_count() as u32);
    let prepared = subdivide(&params, &scene.vertices, &scene.indices).vertices;
    for eye in Eye::BOTH {
        let cpu = raster(
            &raster_params(&settings, eye),
            &prepared,
            &scene.material_table(usize::MAX),
            settings.shading.background,
        );
        let gpu = frame.eye(eye);
        let differing = cpu
            .rgba
            .chunks(4)
            .zip(gpu.rgba.chunks(4))
            .filter(|(a, b)| a.iter().zip(b.iter()).any(|(x, y)| (*x as i32 - *y as i32).abs() > 2))
            .count();
        let total = (projection.width * projection.height) as usize;
        // Only pixels on triangle edges may differ (tie-breaking and rounding at coverage edges).
        assert!(differing * 100 < total, "{eye:?}: {differing} of {total} pixels differ");
        eprintln!("{eye:?}: {differing} of {total} pixels differ");
    }
}
