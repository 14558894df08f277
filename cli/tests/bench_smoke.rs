//! CI's smoke run of the paper's benchmarks: `twister bench all --quick` produces every output,
//! well formed (not a speed check).

use std::path::Path;

mod common;

fn run_quick(out: &Path, assets: &Path) {
    let o = common::twister()
        .env("NODEVICE_SELECT", "1")
        // One timed frame per point: this checks the outputs, not the speed.
        .args(["bench", "all", "--quick", "--reps", "1", "--out"])
        .arg(out)
        .arg("--assets")
        .arg(assets)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

fn csv_rows(path: &Path, header: &[&str]) -> Vec<csv::StringRecord> {
    let mut r = csv::Reader::from_path(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let h = r.headers().unwrap().clone();
    for col in header {
        assert!(h.iter().any(|x| x == *col), "{}: no column {col} in {h:?}", path.display());
    }
    r.records().map(|x| x.unwrap()).collect()
}

#[test]
fn quick_benchmark_writes_every_output_well_formed() {
    if !common::assets_present() {
        return;
    }
    let out = common::TempDir::new(format!("twister-bench-smoke-{}", std::process::id()));
    let assets = common::asset("");
    // Every scene of the quick run is present (CI has the assets), so every row is expected.
    for needed in [
        "stanford-bunny/bun_zipper_res2.obj",
        "stanford-bunny/bun_zipper_res4.obj",
        "sponza-dabrovic/sponza.obj",
        "cow/cow.obj",
    ] {
        common::asset(needed);
    }
    run_quick(&out, &assets);
    let cols = ["scene", "method", "parameter", "mean_px", "std_px", "p99_px", "ms_frame", "triangles_out", "timing"];
    let fig8 = csv_rows(&out.join("fig8.csv"), &cols);
    assert_eq!(fig8.len(), 3 * 4, "three distances × the quick N values");
    let fig10 = csv_rows(&out.join("fig10.csv"), &cols);
    let fig12 = csv_rows(&out.join("fig12.csv"), &cols);
    let matched = csv_rows(&out.join("fig12_matched.csv"), &["scene", "method", "adaptive_ms", "w_star", "note"]);
    let scenes = 4;
    assert_eq!(matched.len(), scenes * 2, "adaptive:length and adaptive per scene");
    assert_eq!(fig10.len(), scenes * 6, "vertex, fixed:1/4/7, adaptive:length, adaptive per scene");
    assert_eq!(fig12.len(), scenes * 5, "adaptive:length, adaptive and three slit widths per scene");
    for row in fig10.iter().chain(&fig12) {
        let ms: f64 = row[6].parse().unwrap();
        let mean: f64 = row[3].parse().unwrap();
        assert!(ms > 0.0 && ms.is_finite() && mean >= 0.0, "{row:?}");
    }
    // fig8's error falls with N at every distance (the paper's finding).
    for d in ["triangle@1", "triangle@3", "triangle@5"] {
        let means: Vec<f64> = fig8.iter().filter(|r| &r[0] == d).map(|r| r[3].parse().unwrap()).collect();
        assert!(means.windows(2).all(|w| w[1] < w[0]), "{d}: {means:?}");
    }
    for f in ["fig8.json", "fig10.json", "fig12.json"] {
        let v: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(out.join(f)).unwrap()).unwrap();
        assert!(v.is_array() || v.is_object(), "{f}");
    }
    for f in ["fig8.png", "fig10.png", "fig12.png"] {
        let (w, h) = image::image_dimensions(out.join(f)).unwrap();
        assert!(w >= 800 && h >= 500, "{f}: {w}x{h}");
    }
    let report = std::fs::read_to_string(out.join("report.md")).unwrap();
    for s in ["## Fig. 8", "## Fig. 10", "## Fig. 12", "31 px", "Timing source", "llvmpipe"] {
        if s == "llvmpipe" && !report.contains("Cpu") {
            continue; // a real GPU names itself differently
        }
        assert!(report.contains(s), "report.md lacks {s}");
    }
    check_lod(&out, &report);
    check_trace_lod(&out, &report);
    let _ = std::fs::remove_dir_all(&out);
}

/// The quick run's seed 001 outputs: per ring, two gazes × off / polygons / polygons+subdivision.
fn check_lod(out: &std::path::Path, report: &str) {
    let lod = csv_rows(
        &out.join("lod.csv"),
        &["scene", "gaze_yaw", "gaze_pitch", "config", "triangles_in", "triangles_out", "ms_frame", "central_mean_px"],
    );
    assert_eq!(lod.len(), 2 * 2 * 3, "two rings × two gazes × three configurations");
    for run in lod.chunks(3) {
        let tri = |r: &csv::StringRecord| r[4].parse::<u64>().unwrap();
        let central = |r: &csv::StringRecord| r[9].parse::<f64>().unwrap();
        assert_eq!((&run[0][3], &run[1][3], &run[2][3]), ("off", "polygons", "polygons+subdivision"));
        assert_eq!(tri(&run[0]), 12 * if run[0][0].contains("bunny") { 948 } else { 100 }, "{run:?}");
        assert!(tri(&run[1]) < tri(&run[0]) && tri(&run[2]) == tri(&run[1]), "{run:?}");
        assert!(central(&run[1]) <= central(&run[0]) * 1.05 + 1e-3, "central error grew: {run:?}");
    }
    assert!(report.contains("## Visual-field level of detail") && out.join("lod.png").exists());
    assert!(!report.contains("bunny ring of the level-of-detail benchmark did not run"));
}

/// The quick run's seed 000 Table 2 outputs: per scene A–D, plain, then LOD and LOD without
/// eq. 10 for states 1 and 2.
fn check_trace_lod(out: &std::path::Path, report: &str) {
    let trace = csv_rows(
        &out.join("trace_lod.csv"),
        &["scene", "state", "config", "s_frame", "rays_traced", "triangle_tests", "covered_pixels"],
    );
    assert_eq!(trace.len(), 4 * 5, "four scenes × (plain + two states × two LOD configurations)");
    let num = |r: &csv::StringRecord, k: usize| r[k].parse::<f64>().unwrap();
    for run in trace.chunks(5) {
        assert_eq!(
            run.iter().map(|r| (r[1].to_string(), r[2].to_string())).collect::<Vec<_>>(),
            [
                ("-", "plain"),
                ("state 1", "lod"),
                ("state 1", "lod without eq. 10"),
                ("state 2", "lod"),
                ("state 2", "lod without eq. 10")
            ]
            .map(|(a, b)| (a.to_string(), b.to_string()))
        );
        for r in run {
            assert!(num(r, 3) > 0.0 && num(r, 4) > 0.0 && num(r, 5) > 0.0, "{r:?}");
        }
        // LOD traces fewer rays than plain; eq. 10 changes the triangles met, not the rays.
        assert!(num(&run[1], 4) < num(&run[0], 4) && num(&run[3], 4) < num(&run[0], 4), "{run:?}");
        assert!((num(&run[1], 4) - num(&run[2], 4)).abs() <= 0.01 * num(&run[2], 4), "{run:?}");
    }
    // Mirror cows (A, C) spawn rays that diffuse ones (B, D) do not.
    assert!(num(&trace[0], 4) > num(&trace[5], 4) && num(&trace[10], 4) > num(&trace[15], 4));
    assert!(report.contains("## Visual-field level of detail in ray tracing") && report.contains("2.078"));
    for f in ["trace_lod.png", "trace_lod_A_state1.png", "trace_lod_A_state2.png", "trace_lod.json"] {
        assert!(out.join(f).exists(), "{f}");
    }
}

#[test]
fn absent_assets_are_skipped_with_a_clear_line() {
    let out = common::TempDir::new(format!("twister-bench-noassets-{}", std::process::id()));
    let o = common::twister()
        .env("NODEVICE_SELECT", "1")
        .args(["bench", "fig10", "--quick", "--reps", "1", "--assets", "/nonexistent/assets", "--out"])
        .arg(&out)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let report = std::fs::read_to_string(out.join("report.md")).unwrap();
    assert!(
        report.contains("Bunny skipped: /nonexistent/assets/stanford-bunny/bun_zipper_res2.obj is absent"),
        "{report}"
    );
    assert!(report.contains("Sponza skipped"), "{report}");
    let _ = std::fs::remove_dir_all(&out);
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
