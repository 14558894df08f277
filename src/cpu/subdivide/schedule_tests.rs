//! Tests of the twin running the schedules' recordings: the cut probe tells what the frame cuts.

use super::passes::CpuSubdivision;
use crate::core::panoramas::projection::Projection;
use crate::core::scenes::builtin;
use crate::core::settings::{Method, RenderSettings, Split};
use crate::encoding::constants::PIECES_FROM_COUNTER;
use crate::encoding::schedule::{Capacities, SubdivisionEngine};
use crate::encoding::subdivide::{
    cut_probe, dispatched, missed, one_submission, subdivide_params, PassTiming, Passes, CUT_PASSES,
};

#[test]
fn the_cut_probe_lists_the_triangles_the_frame_cuts() {
    // The demo room on a wide cylinder keeps its floor beyond the rows (nothing to cut); on a
    // square one and on the sphere the floor near the axis is cut.
    let scene = builtin::demo();
    let n = scene.triangle_count() as u32;
    for (projection, cuts) in [
        (Projection { width: 960, height: 180, ..Projection::default() }, false),
        (Projection { width: 256, height: 256, ..Projection::default() }, true),
        (Projection::equirect(256), true),
    ] {
        let settings = RenderSettings::new(projection).with_method(Method::Adaptive(Split::Error));
        let mut engine = CpuSubdivision::new(&scene.vertices, &scene.indices, &[]);
        let capacity = engine.ensure(Capacities::guess(n));
        let mut params = subdivide_params(&settings, 0, n);
        (params.piece_capacity, params.triangle_capacity) = (capacity.pieces, capacity.triangles);
        (params.first_piece, params.piece_count) = (0, PIECES_FROM_COUNTER);
        let frame = one_submission(n, Passes::of_settings(&settings), PassTiming::Untimed);
        let probed = engine.replay(&cut_probe(n), &params).expect("probe");
        let done = engine.replay(&frame, &params).expect("frame");
        assert_eq!((probed.cut_count, probed.cut_wide), (done.cut_count, done.cut_wide), "{projection:?}");
        let ran_cuts = dispatched(&frame, &params, &done).iter().any(|&(e, k)| e == "plan_cuts" && k > 0);
        let needs = !missed(&frame, &params, &probed, |e| !CUT_PASSES.contains(&e)).is_empty();
        assert_eq!((needs, ran_cuts), (cuts, cuts), "{projection:?}");
        // Without the cut passes, the frame misses them exactly when it cuts.
        assert_eq!(missed(&frame, &params, &done, |e| !CUT_PASSES.contains(&e)).is_empty(), !cuts);
    }
}

#[test]
fn a_frame_whose_piece_records_overflow_replays_to_the_direct_run() {
    // Fine splits (L = 4 px, N_max = 1) of a room around the viewer on the fisheye make more
    // piece records than the first guess holds: the slots counted but never written are no
    // pieces, and the frame drawn again with grown buffers gives the direct run's triangles.
    use crate::core::scenes::scene::Scene;
    use crate::core::scenes::shapes::ClosedMesh;
    use crate::encoding::schedule::Schedule;
    let mut scene = Scene::new("room");
    ClosedMesh::grid_box(3).placed(glam::Vec3::new(0.3, 0.2, -0.4), 2.0).add_to(&mut scene, [1.0; 4]);
    let projection = Projection { fov: 250.0, dome_tilt: 6.0, ..Projection::fisheye(96) };
    let settings = RenderSettings::new(projection)
        .with_method(Method::Adaptive(Split::Error))
        .with_edge_px(2.0)
        .with_max_error_px(0.1)
        .with_max_div(1);
    let n = scene.triangle_count() as u32;
    let direct = super::subdivide(&subdivide_params(&settings, 0, n), &scene.vertices, &scene.indices);
    assert!(direct.pieces > Capacities::guess(n).pieces, "{} pieces: no overflow", direct.pieces);
    let budget = Capacities::budget(256, 128 << 20);
    let passes =
        super::passes::run_scheduled(&settings, &scene.vertices, &scene.indices, &[], Schedule::OneSubmission, budget)
            .expect("replayed");
    assert_eq!(passes.vertices.len(), direct.vertices.len());
}
