//! The subdivide stage's twin check (tests/twins.rs): the GPU's read-back and the CPU twin's
//! passes run the same schedules (one submission with its indirect dispatches, and chunked) on
//! random triangles, built-in rooms and spheres, both panoramas and every split rule.

use glam::Vec3;
use twister::core::scenes::builtin;
use twister::core::settings::{Method, Split};
use twister::cpu::subdivide::passes::run_scheduled;
use twister::cpu::subdivide::subdivide;
use twister::encoding::schedule::{Capacities, Schedule};
use twister::encoding::subdivide::subdivide_params;
use twister::{GpuScene, Projection, RenderSettings, Renderer, Scene, Vertical};

use twister::search::twin::compare_subdivided;

use super::{common, Twin};

pub struct Subdivide;

/// The subdivide twin's scenes and settings: random triangles with every split rule, rooms and
/// spheres around the viewer, tall images, both vertical models, the full sphere.
fn subdivide_cases() -> Vec<(Scene, RenderSettings)> {
    let projection = Projection { width: 640, height: 160, ..Projection::default() };
    let base = RenderSettings::new(projection).with_measure_edges(true);
    let moved = base.with_viewer(Vec3::new(1.0, 0.3, -2.0)).with_yaw_deg(37.0);
    let sphere = builtin::builtin_scene("builtin:sphere100", &projection).unwrap();
    let around = builtin::sphere_scene(1024, Vec3::ZERO, 2.5, "sphere around the viewer");
    let box_room = builtin::builtin_scene("builtin:box-room", &projection).unwrap();
    let cube = builtin::builtin_scene("builtin:cube", &projection).unwrap();
    let tall_projection = Projection { width: 192, height: 256, ..Projection::default() };
    let tall = RenderSettings::new(tall_projection);
    let small = RenderSettings::new(Projection { width: 64, height: 96, ..tall_projection });
    let tall_exact = RenderSettings::new(Projection { vertical: Vertical::Exact, ..tall_projection });
    vec![
        (common::random_triangles(3, 600), base.with_method(Method::Vertex)),
        (common::random_triangles(4, 300), base),
        // Single-sided triangles, half of them seen from behind (skipped by `plan`).
        (common::single_sided(common::random_triangles(13, 300)), base),
        (common::single_sided(common::random_triangles(14, 200)), RenderSettings::new(Projection::equirect(256))),
        // glTF tangents, interpolated and packed again.
        (common::with_tangents(common::random_triangles(8, 200)), moved),
        (common::random_triangles(5, 200), base.with_method(Method::Fixed(5))),
        (builtin::demo(), base),
        (builtin::demo(), moved.with_projection(tall_projection).with_method(Method::Vertex)),
        (builtin::demo(), moved.with_method(Method::Adaptive(Split::Length)).with_edge_px(12.0).with_max_div(4)),
        (sphere.clone(), base.with_method(Method::Adaptive(Split::Length)).with_edge_px(8.0)),
        // The error split (the default method) with a fine tolerance.
        (sphere, base.with_max_error_px(0.05)),
        (around, base.with_method(Method::Adaptive(Split::Length)).with_edge_px(16.0)),
        (builtin::sphere_scene(1024, Vec3::ZERO, 2.5, "sphere around the viewer"), base.with_max_error_px(0.2)),
        // fixed:N beyond 32 divisions: pre-split into pieces (one invocation used to stop short).
        (builtin::builtin_scene("builtin:triangle@3", &projection).unwrap(), base.with_method(Method::Fixed(64))),
        (common::random_triangles(6, 12), base.with_method(Method::Fixed(45))),
        // Surround scenes: quadrant and band cuts, the square around the axis, tall images,
        // both vertical models, a part beyond 32 × N_max divisions (K capped).
        (box_room.clone(), base),
        (box_room.clone(), tall.with_method(Method::Vertex)),
        (box_room, tall_exact.with_method(Method::Fixed(7))),
        (cube.clone(), tall.with_viewer(Vec3::new(0.0, 0.95, 0.0))),
        (
            cube.clone(),
            small
                .with_viewer(Vec3::new(0.0, 0.95, 0.0))
                .with_method(Method::Adaptive(Split::Length))
                .with_edge_px(4.0)
                .with_max_div(3),
        ),
        (cube, tall_exact.with_viewer(Vec3::new(0.1, -0.8, 0.2)).with_edge_px(12.0)),
    ]
    .into_iter()
    .chain(sphere_cases(&projection))
    .collect()
}

/// The full sphere's, VR180's, the cubemap's, a tracked head's and the fisheye's cases.
fn sphere_cases(projection: &Projection) -> Vec<(Scene, RenderSettings)> {
    vec![
        // The full sphere: the poles (pole merge on and off), converging rays, the seam (τ small
        // enough at these sizes that the demo room is split, its nodes drawn off their projections).
        (builtin::demo(), RenderSettings::new(Projection::equirect(256)).with_max_error_px(0.25)),
        (
            builtin::demo(),
            RenderSettings::new(Projection { convergence: Some(2.0), pole_merge: None, ..Projection::equirect(192) })
                .with_method(Method::Vertex),
        ),
        // Converging rays under the error split, measured: the pipelines keep the converging
        // eye model and the edge measure, which those of a render's frame leave out.
        (
            builtin::demo(),
            RenderSettings::new(Projection { convergence: Some(2.0), ..Projection::equirect(192) })
                .with_measure_edges(true)
                .with_max_error_px(0.25),
        ),
        (
            common::random_triangles(7, 200),
            RenderSettings::new(Projection::equirect(256)).with_method(Method::Fixed(3)),
        ),
        // VR180: the sphere's front half (the back's pieces, beyond the image's sides, are not
        // drawn; nor the triangles of the pieces reaching round them).
        (builtin::demo(), RenderSettings::new(Projection::vr180(256)).with_max_error_px(0.25)),
        // The cubemap: measured on the sphere at its faces' resolution, nothing culled at the poles.
        (builtin::demo(), RenderSettings::new(Projection::cubemap(96))),
        // A tracked head off the display's centre: its seam copies, its vertical limit.
        (
            builtin::demo(),
            RenderSettings::new(Projection {
                width: 256,
                height: 64,
                vertical: Vertical::Exact,
                head: Some(twister::core::panoramas::head::Head { offset: [-0.5, -0.2, 0.4], turn: -1.0 }),
                ..Projection::default()
            }),
        ),
        // The fisheye: its own image's edge lengths, the cone around the tilted dome's antipode.
        (builtin::demo(), RenderSettings::new(Projection { fov: 240.0, dome_tilt: 20.0, ..Projection::fisheye(128) })),
        // Rows (the sphere, adaptive rules): random triangles, the box room (long thin parts in
        // bands), eq. 5, a viewer off the axis.
        (common::random_triangles(9, 200), RenderSettings::new(Projection::equirect(320))),
        // Rows pieces larger than a node item, near the seam (two copies: items of 32 nodes):
        // seed 9's items start at rows' right ends, seed 12's between a row's nodes
        // (`rows_along` places the row's ends first and writes only the item's slots).
        (common::random_triangles(12, 200), RenderSettings::new(Projection::equirect(256))),
        (
            builtin::builtin_scene("builtin:box-room", projection).unwrap(),
            RenderSettings::new(Projection::equirect(256)),
        ),
        (
            builtin::demo(),
            RenderSettings::new(Projection::equirect(256))
                .with_viewer(Vec3::new(0.7, 0.2, -0.4))
                .with_method(Method::Adaptive(Split::Length))
                .with_edge_px(12.0),
        ),
    ]
}

impl Twin for Subdivide {
    type Case = (Scene, RenderSettings);
    /// The GPU's outputs with the usual frame's schedule (one submission, indirect) and with the
    /// chunked one (ranges of triangles); the twin's, once.
    type Output = Vec<twister::cpu::subdivide::SubdivideOutput>;
    fn cases() -> Vec<(String, Self::Case)> {
        let cases = subdivide_cases();
        let (mut cut_frames, mut strip_frames, mut edge_split_frames) = (0, 0, 0);
        let (mut row_frames, mut band_frames) = (0, 0);
        let cases: Vec<_> = cases
            .into_iter()
            .enumerate()
            .map(|(k, (scene, s))| {
                let name = format!("case {k}: {} {}", scene.name, s.subdivision.method.name());
                let cpu =
                    subdivide(&subdivide_params(&s, 0, scene.triangle_count() as u32), &scene.vertices, &scene.indices);
                assert!(cpu.vertices.len() / 3 > scene.triangle_count(), "{name}: exercises splits and seam copies");
                cut_frames += (cpu.cuts != 0) as usize;
                strip_frames += (cpu.strips > 0) as usize;
                edge_split_frames += (cpu.edge_splits > 0) as usize;
                row_frames += (cpu.rows > 0) as usize;
                band_frames += (cpu.bands > 0) as usize;
                (name, (scene, s))
            })
            .collect();
        // Frames with and without cuts around the axis.
        assert!(cut_frames >= 8 && cut_frames < cases.len(), "{cut_frames} of {} cases cut", cases.len());
        // Slivers drawn as strips (the error split on the cylinder).
        assert!(strip_frames >= 3, "only {strip_frames} cases draw strips");
        // Triangles that ask for no cuts, cut only at the edges they share with ones that do.
        assert!(edge_split_frames >= 3, "only {edge_split_frames} cases cut triangles at shared edges alone");
        // Pieces drawn in rows, and long thin parts cut in bands (adaptive rules).
        assert!(row_frames >= 4, "only {row_frames} cases draw pieces in rows");
        assert!(band_frames >= 2, "only {band_frames} cases cut long thin parts in bands");
        cases
    }
    fn gpu(r: &Renderer, (scene, settings): &Self::Case) -> Self::Output {
        let gs = GpuScene::upload(&r.gpu, scene).unwrap();
        subdivide_schedules(scene).map(|schedule| r.subdivide_readback(&gs, settings, schedule).unwrap()).into()
    }
    /// The twin's passes replaying the same schedules (the same recordings, parameters and
    /// capacities as the GPU's read-back).
    fn cpu((scene, settings): &Self::Case) -> Self::Output {
        let budget = Capacities::budget(settings.subdivision.memory_mb, common::renderer().gpu.max_binding());
        subdivide_schedules(scene)
            .map(|schedule| run_scheduled(settings, &scene.vertices, &scene.indices, &[], schedule, budget).unwrap())
            .into()
    }
    fn compare(gpu: &Self::Output, cpu: &Self::Output) -> Result<(), String> {
        let schedules = ["one submission", "chunked"];
        for ((g, c), schedule) in gpu.iter().zip(cpu).zip(schedules) {
            let software = common::renderer().gpu.info.device_type == wgpu::DeviceType::Cpu;
            compare_subdivided(g, c, software).map_err(|e| format!("{schedule} schedule: {e}"))?;
        }
        Ok(())
    }
}

/// The schedules the twin check runs: the usual frame's (one submission, indirect), and the
/// chunked one over three ranges or more where the scene has the triangles.
fn subdivide_schedules(scene: &Scene) -> [Schedule; 2] {
    [Schedule::OneSubmission, Schedule::Chunked { triangles_per_chunk: (scene.triangle_count() as u32 / 3).max(1) }]
}
