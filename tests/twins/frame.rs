//! A whole frame as one recording (`twister::encoding::frame`): the GPU (`Renderer::render_recorded`)
//! and the CPU twins (`cpu::render::render_recorded`) run the same recording, step by step, and
//! draw the same frame — the usual one-submission frame (indirect dispatches and draw), one
//! whose buffers overflow (the one overflow policy, `encoding::schedule::run_plan`, redraws it
//! by chunks on both), and one by chunks from the start; every target compared, the chunks and
//! triangles counted alike, the error reduced alike. Then every other drawing step (slits, a
//! CAVE wall's pinholes, the ray tracer) and the shadow step, and recordings that cannot draw
//! their frame.

use twister::core::scenes::builtin;
use twister::core::settings::Method;
use twister::cpu::render::render_recorded;
use twister::encoding::frame::{FrameRecording, FrameStep};
use twister::encoding::schedule::{Capacities, FramePlan};
use twister::{GpuScene, Projection, RenderSettings};

use super::{common, compare_eyes, error_tolerance, frame_outputs};

/// `recording` with its subdivision's plan and first chunk replaced.
fn with_plan(recording: &FrameRecording, plan: FramePlan, chunk: u32) -> FrameRecording {
    let steps = recording
        .steps
        .iter()
        .map(|s| match s {
            FrameStep::Subdivided { .. } => FrameStep::Subdivided { plan, chunk },
            s => *s,
        })
        .collect();
    FrameRecording { steps }
}

#[test]
fn the_gpu_and_the_twins_run_the_same_frame_recording() {
    let r = common::renderer();
    let scene = builtin::demo();
    let gs = GpuScene::upload(&r.gpu, &scene).expect("upload");
    let projection = Projection { width: 256, height: 64, ..Projection::default() };
    let settings = RenderSettings::new(projection)
        .with_method(Method::Adaptive(Default::default()))
        .with_measure_error(true)
        .with_depth(true);
    let usual = r.record(&gs, &settings);
    assert!(matches!(usual.plan(), Some(FramePlan::OneSubmission(..))), "{usual:?}");
    assert!(usual.steps.contains(&FrameStep::ReduceError { per_eye: false }), "{usual:?}");
    // Buffers a few hundred pieces and a few thousand output units large: the one submission
    // overflows; the chunks halve until they fit.
    let small = Capacities { pieces: 300, triangles: 2500 };
    let n = scene.triangle_count() as u32;
    let cases = [
        ("one submission", usual.clone(), false),
        (
            "one submission overflowed, redrawn by chunks",
            with_plan(&usual, FramePlan::OneSubmission(small, small), n),
            true,
        ),
        (
            "by chunks of 64 triangles from the start",
            with_plan(&usual, FramePlan::first(n, None, small).after_overflow(small), 64),
            true,
        ),
    ];
    for (name, recording, chunked) in cases {
        let gpu = r.render_recorded(&gs, &settings, &recording).unwrap_or_else(|e| panic!("{name}: {e}"));
        let cpu = render_recorded(&scene, &settings, &recording).unwrap_or_else(|e| panic!("{name}: {e}"));
        let (chunks, triangles, reduced) = (cpu.chunks, cpu.triangles.len() as u64 / 3, cpu.error_stats);
        let cpu_eyes = cpu.eyes.map(|img| (img.rgba, img.error, img.object, img.distance));
        compare_eyes(&frame_outputs(&gpu), &cpu_eyes, 100, error_tolerance(&settings))
            .unwrap_or_else(|e| panic!("{name}: GPU and twins differ: {e}"));
        assert_eq!(gpu.stats.chunks, chunks, "{name}: chunks");
        assert_eq!(chunks > 1, chunked, "{name}: {chunks} chunks");
        assert_eq!(gpu.stats.triangles_out, triangles, "{name}: triangles");
        let (g, c) = (gpu.measurement.expect("measured").stats, reduced.expect("reduced"));
        let near = |a: f32, b: f32| (a - b).abs() <= 0.02 * b.abs() + 1e-3;
        assert!(
            g.count.abs_diff(c.count) * 100 <= c.count && near(g.mean, c.mean) && near(g.p90, c.p90),
            "{name}: error statistics GPU {g:?}, CPU {c:?}"
        );
    }
}

/// A recording that cannot draw the frame its settings record — another method's step, slits
/// of no width, a subdivision whose first chunk holds no triangle — is one error naming the
/// recording on both engines, nothing drawn.
#[test]
fn a_recording_that_cannot_draw_the_frame_is_one_error_on_both_engines() {
    let r = common::renderer();
    let scene = builtin::demo();
    let gs = GpuScene::upload(&r.gpu, &scene).expect("upload");
    let settings = RenderSettings::new(Projection { width: 64, height: 16, ..Projection::default() });
    let usual = r.record(&gs, &settings);
    let slit_settings = settings.with_method(Method::Slit(4));
    let no_width = with_step(&r.record(&gs, &slit_settings), FrameStep::Slit { width: 0 });
    let plan = usual.plan().expect("subdivided");
    let cases = [
        ("slits for a subdivided frame", settings, with_step(&usual, FrameStep::Slit { width: 4 })),
        ("slits of no width", slit_settings, no_width),
        ("a first chunk of no triangles", settings, with_plan(&usual, plan, 0)),
        ("no steps", settings, FrameRecording { steps: Vec::new() }),
    ];
    for (name, settings, recording) in cases {
        let gpu = r.render_recorded(&gs, &settings, &recording).map(|_| ()).expect_err(name).to_string();
        let cpu = render_recorded(&scene, &settings, &recording).map(|_| ()).expect_err(name).to_string();
        assert!(gpu.starts_with("recording: ") && cpu.starts_with("recording: "), "{name}: {gpu} / {cpu}");
    }
    // A sample count the adapter lacks (`render` makes it up from a larger image; a recorded
    // frame is drawn as it is): one error naming the setting.
    let counts = twister::gpu::targets::sample_counts(&r.gpu);
    if let Some(&n) = [2, 4, 8, 16, 32].iter().find(|n| !counts.contains(n)) {
        let many = settings.with_samples(n);
        let e = r.render_recorded(&gs, &many, &r.record(&gs, &many)).map(|_| ()).expect_err("samples").to_string();
        assert!(e.starts_with("shading.samples: "), "{e}");
    }
    // A plan whose budget holds nothing: the memory budget's error, the same on both.
    let none = Capacities { pieces: 0, triangles: 0 };
    let starved = with_plan(&usual, FramePlan::OneSubmission(none, none), 8);
    let gpu = r.render_recorded(&gs, &settings, &starved).map(|_| ()).expect_err("starved").to_string();
    let cpu = render_recorded(&scene, &settings, &starved).map(|_| ()).expect_err("starved").to_string();
    assert!(gpu.starts_with("subdivision.memory_mb: ") && gpu == cpu, "{gpu} / {cpu}");
}

/// `recording` with its drawing step replaced by `step`.
fn with_step(recording: &FrameRecording, step: FrameStep) -> FrameRecording {
    let drawing = |s: &FrameStep| matches!(s, FrameStep::Subdivided { .. } | FrameStep::Slit { .. } | FrameStep::Trace);
    FrameRecording { steps: recording.steps.iter().map(|s| if drawing(s) { step } else { *s }).collect() }
}

/// Every drawing step, and the shadow step before it, through one recording on both engines:
/// a spot light's shadow map under the subdivided raster, `slit:4`, a CAVE wall (one pinhole
/// per eye), the ray tracer; every target compared (as the stages' own twin tests do).
#[test]
fn every_drawing_step_runs_the_same_recording_on_both_engines() {
    use twister::core::shading::light::LightKind;
    let r = common::renderer();
    let cylinder = Projection { width: 160, height: 48, vertical: twister::Vertical::Exact, ..Projection::default() };
    let lit = common::ball_over_floor(LightKind::Spot, true);
    let cave = common::cave(1, 64, glam::Vec3::new(0.2, 0.1, 0.3), 25.0);
    let cases = [
        ("a spot light's shadow map", lit, RenderSettings::new(cylinder).with_shadow_map_size(256), 100),
        ("slit:4", builtin::demo(), RenderSettings::new(cylinder).with_method(Method::Slit(4)), 50),
        ("a CAVE wall", builtin::demo(), RenderSettings::new(cave), 50),
        ("trace", builtin::demo(), RenderSettings::new(cylinder).with_method(Method::Trace), 200),
    ];
    for (name, scene, settings, share) in cases {
        let settings = settings.with_measure_error(true).with_depth(true);
        let gs = GpuScene::upload(&r.gpu, &scene)
            .and_then(|g| g.with_built_bvh(&r.gpu, &scene.name, &twister::cpu::render::traced_bvh(&scene, &settings)))
            .expect("upload");
        let recording = r.record(&gs, &settings);
        let drawing = recording.steps.iter().find(|s| !matches!(s, FrameStep::Shadow { .. }));
        let expected = match name {
            "a spot light's shadow map" => recording.steps[0] == FrameStep::Shadow { maps: 1 },
            "slit:4" => drawing == Some(&FrameStep::Slit { width: 4 }),
            "a CAVE wall" => drawing == Some(&FrameStep::Slit { width: 64 }),
            _ => drawing == Some(&FrameStep::Trace),
        };
        assert!(expected, "{name}: recorded {recording:?}");
        let gpu = r.render_recorded(&gs, &settings, &recording).unwrap_or_else(|e| panic!("{name}: {e}"));
        let cpu = render_recorded(&scene, &settings, &recording).unwrap_or_else(|e| panic!("{name}: {e}"));
        let cpu_eyes = cpu.eyes.map(|img| (img.rgba, img.error, img.object, img.distance));
        compare_eyes(&frame_outputs(&gpu), &cpu_eyes, share, 0.01)
            .unwrap_or_else(|e| panic!("{name}: GPU and twins differ: {e}"));
    }
}
