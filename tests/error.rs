//! The error pass and the slit renderer against independent oracles: a known shift, the CPU
//! twins, and the paper's findings.

mod common;

use twister::cpu::raster::raster_params;
use twister::cpu::subdivide::subdivide_params;
use twister::cpu::raster::raster;
use twister::cpu::reduce_error::reduce_error;
use twister::Frame;
use twister::cpu::slit::{slit, slit_params, slits};
use twister::cpu::subdivide::subdivide;
use twister::core::settings::Method;
use twister::core::builtin;
use twister::{Eye, Projection, RenderSettings, Vertical};

fn measured(scene: &twister::Scene, settings: &RenderSettings) -> Frame {
    common::render(scene, &settings.clone().with_measure_error(true))
}

#[test]
fn a_known_shift_is_measured_as_that_shift() {
    let projection = Projection { width: 960, height: 180, ..Projection::default() };
    let scene = builtin::builtin_scene("builtin:triangle@3", &projection).unwrap();
    for (shift, expected) in [([3.0f32, 4.0], 5.0f32), ([-7.0, 0.0], 7.0), ([0.0, 0.0], 0.0)] {
        let settings = RenderSettings::new(projection).with_method(Method::Fixed(24)).with_shift_px(shift);
        let frame = measured(&scene, &settings);
        let e = frame.measurement.unwrap().stats;
        assert!(e.count > 10_000);
        // The unshifted subdivided triangle is exact to ~0.005 px; the shift adds to it.
        assert!((e.mean - expected).abs() < 0.02, "shift {shift:?}: mean {} vs {expected}", e.mean);
        assert!((e.p50 - expected).abs() < 0.03 && (e.max - expected).abs() < 0.05, "shift {shift:?}: {e:?}");
    }
}

#[test]
fn gpu_error_pass_and_reduction_match_their_cpu_twins() {
    let projection = Projection { width: 480, height: 90, ..Projection::default() };
    for vertical in [Vertical::Paper, Vertical::Exact] {
        let projection = Projection { vertical, ..projection };
        let scene = builtin::builtin_scene("builtin:triangle@3", &projection).unwrap();
        let settings = RenderSettings::new(projection).with_method(Method::Vertex);
        let frame = measured(&scene, &settings);
        let m = frame.measurement.as_ref().unwrap();
        let params = subdivide_params(&settings, 0, 1);
        let tris = subdivide(&params, &scene.vertices, &scene.indices).vertices;
        for (k, eye) in Eye::BOTH.into_iter().enumerate() {
            let cpu = raster(
                &raster_params(&settings, eye),
                &tris,
                &scene.material_table(usize::MAX),
                settings.shading.background,
            );
            let (mut both, mut worst) = (0, 0.0f32);
            for (g, c) in m.error[k].iter().zip(&cpu.error) {
                if *g >= 0.0 && *c >= 0.0 {
                    both += 1;
                    worst = worst.max((g - c).abs());
                }
            }
            assert!(both > 2000, "{vertical:?} {eye:?}: {both} pixels");
            assert!(worst < 0.01, "{vertical:?} {eye:?}: GPU and CPU errors differ by {worst} px");
        }
        // The GPU reduction equals the CPU twin on the same per-pixel errors.
        let cpu = reduce_error(m.error.iter().map(|v| v.as_slice()));
        let gpu = m.stats;
        assert_eq!(gpu.count, cpu.count);
        assert_eq!(gpu.max, cpu.max);
        assert!(
            (gpu.mean - cpu.mean).abs() <= 1e-4 * cpu.mean && (gpu.std_dev - cpu.std_dev).abs() <= 1e-3 * cpu.std_dev,
            "{gpu:?} {cpu:?}"
        );
        for (g, c) in [(gpu.p50, cpu.p50), (gpu.p90, cpu.p90), (gpu.p99, cpu.p99)] {
            assert!((g - c).abs() <= 1e-4 * c.max(1.0), "percentiles {gpu:?} vs {cpu:?}");
        }
    }
}

#[test]
fn gpu_slit_renderer_matches_its_cpu_twin() {
    let projection = Projection { width: 192, height: 48, vertical: Vertical::Exact, ..Projection::default() };
    let scene = builtin::demo();
    let settings = RenderSettings::new(projection).with_method(Method::Slit(4));
    let frame = measured(&scene, &settings);
    let m = frame.measurement.as_ref().unwrap();
    for (k, eye) in Eye::BOTH.into_iter().enumerate() {
        let params = slit_params(&projection, settings.view(), eye, settings.shading.ambient);
        let cpu = slit(
            &params,
            &slits(&projection, eye, 4),
            &scene,
            &scene.material_table(usize::MAX),
            settings.shading.background,
        );
        let gpu = frame.eye(eye);
        let total = (projection.width * projection.height) as usize;
        let colour_differs = cpu
            .rgba
            .chunks(4)
            .zip(gpu.rgba.chunks(4))
            .filter(|(a, b)| a.iter().zip(b.iter()).any(|(x, y)| x.abs_diff(*y) > 2))
            .count();
        assert!(colour_differs * 50 < total, "{eye:?}: {colour_differs} of {total} pixels differ");
        let object_differs = cpu.object.iter().zip(&m.object[k]).filter(|(a, b)| a != b).count();
        assert!(object_differs * 50 < total, "{eye:?}: {object_differs} pixels show another object");
        let error_differs = cpu
            .error
            .iter()
            .zip(&m.error[k])
            .filter(|(a, b)| **a >= 0.0 && **b >= 0.0 && (*a - *b).abs() > 0.01)
            .count();
        assert!(error_differs * 50 < total, "{eye:?}: {error_differs} pixels' errors differ");
    }
}

#[test]
fn slit_1_is_exact_and_the_slit_error_grows_with_the_width() {
    let projection = Projection { width: 640, height: 120, vertical: Vertical::Exact, ..Projection::default() };
    let scene = builtin::builtin_scene("builtin:sphere1024", &projection).unwrap();
    let mut previous = -1.0;
    for w in [1, 4, 16, 64] {
        let frame = measured(&scene, &RenderSettings::new(projection).with_method(Method::Slit(w)));
        let e = frame.measurement.unwrap().stats;
        assert!(e.count > 5000);
        if w == 1 {
            assert!(e.mean < 0.5, "slit:1 mean error {} px", e.mean);
        }
        assert!(e.mean > previous, "slit:{w}: mean {} px not above the narrower slit's {previous}", e.mean);
        previous = e.mean;
    }
}

#[test]
fn paper_evaluation_1_without_and_with_subdivision() {
    // Seed 002 §4.1 at the paper's resolution: about 31 px mean without subdivision (tens of
    // pixels), under 1 px with every edge split in 7.
    let projection = Projection::default();
    let scene = builtin::builtin_scene("builtin:triangle@3", &projection).unwrap();
    let vertex = measured(&scene, &RenderSettings::new(projection).with_method(Method::Vertex));
    let fixed7 = measured(&scene, &RenderSettings::new(projection).with_method(Method::Fixed(7)));
    let (v, f) = (vertex.measurement.unwrap().stats, fixed7.measurement.unwrap().stats);
    assert!(v.mean > 10.0 && v.mean < 60.0, "vertex: mean {} px", v.mean);
    assert!(f.mean < 1.0, "fixed:7: mean {} px", f.mean);
    // The adaptive default is finer still.
    let adaptive = measured(&scene, &RenderSettings::new(projection));
    assert!(adaptive.measurement.unwrap().stats.mean < f.mean);
}

#[test]
fn error_pass_off_by_default_and_draws_the_same_image() {
    let projection = Projection { width: 320, height: 60, ..Projection::default() };
    let scene = builtin::demo();
    let plain = common::render(&scene, &RenderSettings::new(projection));
    let with = measured(&scene, &RenderSettings::new(projection));
    assert!(plain.measurement.is_none() && with.measurement.is_some());
    assert_eq!(plain.left.rgba, with.left.rgba);
    assert_eq!(plain.right.rgba, with.right.rgba);
}
