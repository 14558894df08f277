//! Tests of the twin running the schedules' recordings: the cut probe tells what the frame cuts.

use super::passes::CpuSubdivision;
use crate::core::builtin;
use crate::core::projection::Projection;
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
