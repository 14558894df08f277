//! The promises of exactness as property tests with shrinking, on the random cases of
//! `twister::search` (closed rooms of grid faces holding closed objects, random viewers, every
//! panorama and method, sizes, eye models, tracked heads and levels of detail): the cases run
//! never depend on which assets are present. `PROPTEST_CASES` raises their number; failing cases
//! are saved under `proptest-regressions/` and run first next time. `twister bench search` runs
//! the same cases for long searches.

mod common;

use proptest::prelude::*;
use twister::search::{self, SearchMethod, SearchPanorama};

/// The panoramas the GPU draws every random closed room of the search closed on (2,000 cases
/// each, docs/results.md; the others: see the ignored test below).
const EXACT_ON_THE_GPU: [SearchPanorama; 4] =
    [SearchPanorama::Cylinder, SearchPanorama::Equirect, SearchPanorama::Vr180, SearchPanorama::Cave];

proptest! {
    #![proptest_config(search::test_config(32))]

    /// The subdivision's twin is watertight (every interior edge used by exactly two triangles)
    /// and loses nothing visible, for every method, panorama, level-of-detail scale, eye model,
    /// size and viewer place.
    #[test]
    fn the_subdivision_is_watertight_and_whole_on_random_rooms(case in search::case_strategy(&[], &[], 128)) {
        if let Err(f) = search::check(None, &case) {
            prop_assert!(false, "{}: {}: {}", case.describe(), f.check.name(), f.message);
        }
    }
}

proptest! {
    #![proptest_config(search::test_config(12))]

    /// Drawn on the GPU path at one sample on a marker background, a closed room shows no
    /// background pixel in either eye, and the GPU's subdivision is its twin's: every method, on
    /// the cylinder, the sphere, VR180 and the CAVE.
    #[test]
    fn closed_rooms_show_no_background_and_the_gpu_subdivides_as_its_twin(
        case in search::case_strategy(&EXACT_ON_THE_GPU, &[], 160),
    ) {
        if let Err(f) = search::check(Some(common::renderer()), &case) {
            prop_assert!(false, "{}: {}: {}", case.describe(), f.check.name(), f.message);
        }
    }

    /// The same on the fisheye, the cubemap and the cylinder seen by a tracked head: not yet true
    /// (docs/results.md, *Exactness by search*); run with `cargo test --test search --
    /// --ignored`, or `twister bench search`.
    #[test]
    #[ignore = "the fisheye's rim, the cubemap's faces and a head's right edge still show background (docs/results.md)"]
    fn closed_rooms_show_no_background_on_the_fisheye_the_cubemap_and_a_head(
        case in search::case_strategy(&[SearchPanorama::Fisheye, SearchPanorama::Cubemap, SearchPanorama::CylinderHead], &[], 160),
    ) {
        if let Err(f) = search::check(Some(common::renderer()), &case) {
            prop_assert!(false, "{}: {}: {}", case.describe(), f.check.name(), f.message);
        }
    }

    /// The level of detail never opens a closed room around the viewer, whatever the gaze:
    /// every case here has one (the selection's own promise is `core::lod`'s property test).
    #[test]
    fn the_level_of_detail_keeps_a_room_around_the_viewer_closed_at_any_gaze(
        case in search::case_strategy(&[SearchPanorama::Cylinder, SearchPanorama::Equirect], &[SearchMethod::Adaptive, SearchMethod::Vertex], 160),
        gaze in (-180.0f32..180.0, -80.0f32..80.0),
    ) {
        let case = search::SearchCase { gaze: Some(gaze), ..case };
        if let Err(f) = search::check_gpu(common::renderer(), &case, &search::drawn_scene(&case)) {
            prop_assert!(false, "{}: {}: {}", case.describe(), f.check.name(), f.message);
        }
    }
}

/// The fisheye refuses the methods that measure no edge, naming the setting.
#[test]
fn the_fisheye_refuses_vertex_and_fixed_with_one_line() {
    for method in [twister::core::settings::Method::Vertex, twister::core::settings::Method::Fixed(8)] {
        let settings = twister::RenderSettings::new(twister::Projection::fisheye(64)).with_method(method);
        let e = settings.validate().expect_err("refused").to_string();
        assert!(e.contains("subdivision.method") && e.contains("fisheye") && !e.contains('\n'), "{e}");
    }
}

/// `twister bench search`: a short run writes its table (cases per panorama and method) and
/// exits 0; bad options are one line naming the option, exit 1, no table.
#[test]
fn bench_search_runs_cases_and_refuses_bad_options() {
    let dir = std::env::temp_dir().join(format!("twister-search-test-{}", std::process::id()));
    let o = common::twister()
        .args(["bench", "search", "--cases", "2", "--panoramas", "cylinder,equirect", "--cpu-only", "--out"])
        .arg(&dir)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let table = std::fs::read_to_string(dir.join("table.md")).unwrap();
    for row in ["| cylinder | 2 | 0 |", "| equirect | 2 | 0 |"] {
        assert!(table.contains(row), "{table}");
    }
    let _ = std::fs::remove_dir_all(&dir);
    for (args, option) in [
        (vec!["--cases", "0"], "--cases"),
        (vec!["--panoramas", "dome"], "--panoramas"),
        (vec!["--methods", "slit:4"], "--methods"),
        (vec!["--panoramas", "fisheye", "--methods", "vertex"], "--methods"),
        (vec!["--max-width", "4"], "--max-width"),
    ] {
        let o =
            common::twister().args(["bench", "search", "--cpu-only", "--out"]).arg(&dir).args(&args).output().unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(1), "{args:?}: {err}");
        assert!(err.trim().lines().count() == 1 && err.contains(option), "{args:?}: {err}");
        assert!(!dir.join("table.md").exists(), "{args:?}: a table written");
    }
}
