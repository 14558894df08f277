//! The `twister` binary's measuring commands as a user runs them: `error` (against a
//! reference, its heatmap, the error target's encodings, against the ray tracer) and `bench`
//! (options refused and honoured), and the per-pass times of a chunked frame.

mod common;

use common::{png_size, twister};

fn tmp(name: &str) -> common::TempDir {
    common::TempDir::new(format!("twister-cli-measure-{}-{name}", std::process::id()))
}

fn error_json(extra: &[&str], env: Option<(&str, &str)>) -> serde_json::Value {
    let mut cmd = twister();
    if let Some((k, v)) = env {
        cmd.env(k, v);
    }
    let o = cmd
        .args(["error", "builtin:sphere100", "--width", "320", "--height", "60", "--json"])
        .args(extra)
        .output()
        .unwrap();
    assert!(o.status.success(), "{extra:?}: {}", String::from_utf8_lossy(&o.stderr));
    serde_json::from_str(String::from_utf8_lossy(&o.stdout).trim()).unwrap()
}

#[test]
fn error_command_reports_every_field_against_a_reference_and_draws_a_heatmap() {
    let out = tmp("error");
    let heatmap = out.join("heat.png");
    let j = error_json(&["--method", "vertex", "--against", "slit:1", "--heatmap", heatmap.to_str().unwrap()], None);
    for key in [
        "method",
        "vertical",
        "mean_px",
        "std_px",
        "p50_px",
        "p90_px",
        "p99_px",
        "max_px",
        "pixels",
        "triangles_out",
        "ms_render",
        "ms_total",
        "different_surface_fraction",
        "psnr_db",
    ] {
        assert!(j.get(key).is_some(), "missing {key}: {j}");
    }
    assert_eq!(j["method"], "vertex");
    let f = j["different_surface_fraction"].as_f64().unwrap();
    assert!(f > 0.0 && f < 0.2, "{j}");
    assert!(j["psnr_db"].as_f64().unwrap() > 15.0, "{j}");
    let (w, h) = png_size(&heatmap);
    assert_eq!(w, 320);
    assert!(h > 120, "two eyes and the scale");
    let _ = std::fs::remove_dir_all(&out);
}

#[test]
fn uint_error_target_gives_the_same_numbers() {
    let float = error_json(&["--method", "vertex"], None);
    let uint = error_json(&["--method", "vertex"], Some(("TWISTER_ERROR_TARGET", "uint")));
    for key in ["mean_px", "p50_px", "p99_px", "max_px", "pixels"] {
        assert_eq!(float[key], uint[key], "{key}");
    }
}

#[test]
fn benchmark_reps_out_of_range_are_refused() {
    for args in [
        &["bench", "speed", "builtin:sphere100", "--reps", "0"][..],
        &["bench", "speed", "builtin:sphere100", "--reps", "18446744073709551615"][..],
        &["bench", "fig8", "--out", "/nonexistent/x", "--reps", "0"][..],
        &["bench", "fig8", "--out", "/nonexistent/x", "--reps", "10001"][..],
    ] {
        let o = twister().args(args).output().unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success() && err.contains("--reps") && err.lines().count() == 1, "{args:?}: {err}");
    }
}

#[test]
fn bench_speed_honours_scale_viewer_and_lod() {
    let run = |extra: &[&str]| -> serde_json::Value {
        let dir = tmp(&format!("speed{}", extra.len()));
        std::fs::create_dir_all(&dir).unwrap();
        let json = dir.join("speed.json");
        let o = twister()
            .args(["bench", "speed", "builtin:sphere100", "--methods", "vertex", "--reps", "1"])
            .args(["--width", "320", "--height", "60", "--json", json.to_str().unwrap()])
            .args(extra)
            .output()
            .unwrap();
        assert!(o.status.success(), "{extra:?}: {}", String::from_utf8_lossy(&o.stderr));
        let v: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
        let _ = std::fs::remove_dir_all(&dir);
        v["rows"][0].clone()
    };
    let plain = run(&[]);
    assert_eq!(plain["triangles_in"], 100);
    // Where timestamps time the frame: the subdivision's passes in three groups, or with
    // --pass-times each pass the frame dispatched apart (its one-thread setup pass and `finalize`
    // with a neighbour), in schedule order; each from the end of the one before, together the
    // subdivision's time.
    let each = run(&["--pass-times"]);
    for row in [&plain, &each] {
        let Some(names) = common::subdivide_pass_names(row) else { continue };
        let dispatched: Vec<&str> = row["subdivide_invocations"]
            .as_array()
            .unwrap()
            .iter()
            .map(|p| p[0].as_str().unwrap())
            .filter(|e| !e.ends_with("_args") && *e != "finalize")
            .collect();
        let groups = ["plan", "plan_cuts", "lattice"];
        assert_eq!(names, if row == &each { dispatched.as_slice() } else { groups.as_slice() }, "{row}");
    }
    // The columns that show what the subdivision multiplies.
    let out = plain["triangles_out"].as_u64().unwrap();
    assert_eq!(plain["vertices_out"].as_u64().unwrap(), 3 * out);
    assert!((plain["out_per_in"].as_f64().unwrap() - out as f64 / 100.0).abs() < 1e-9, "{plain}");
    // --lod visual-field with the sphere behind the gaze: fewer triangles than the full sphere.
    let lod = run(&["--lod", "visual-field", "--gaze", "180,0"]);
    assert!(lod["triangles_in"].as_u64().unwrap() < 100, "{lod}");
    // A viewer at the sphere's centre sees it all around: a different subdivision (pieces) than
    // from outside.
    let inside = run(&["--viewer", "0,0,-3"]);
    assert_ne!((&inside["pieces"], &inside["triangles_out"]), (&plain["pieces"], &plain["triangles_out"]), "{inside}");
    // --scale scales the scene and the viewer (given in scene units) alike: at the centre of the
    // doubled sphere the counts are those at the centre of the plain one (v = R_T·y/r does not
    // change with scale); a bench that ignored --scale would stand off-centre in the big sphere.
    let scaled = run(&["--viewer", "0,0,-3", "--scale", "2"]);
    assert_eq!((&scaled["pieces"], &scaled["triangles_out"]), (&inside["pieces"], &inside["triangles_out"]));
    let bad = twister().args(["bench", "speed", "builtin:sphere100", "--scale", "0"]).output().unwrap();
    assert!(!bad.status.success() && String::from_utf8_lossy(&bad.stderr).contains("--scale"));
}

#[test]
fn error_against_trace_reports_surfaces_and_distances_against_the_traced_hits() {
    let run = |extra: &[&str]| {
        let o = twister()
            .args(["error", "builtin:demo", "--vertical", "exact", "--width", "320", "--height", "60", "--json"])
            .args(extra)
            .output()
            .unwrap();
        assert!(o.status.success(), "{extra:?}: {}", String::from_utf8_lossy(&o.stderr));
        serde_json::from_str::<serde_json::Value>(String::from_utf8_lossy(&o.stdout).trim()).unwrap()
    };
    // The traced image puts every surface point exactly where the projection says.
    let traced = run(&["--method", "trace"]);
    assert!(traced["p99_px"].as_f64().unwrap() < 1e-3, "{traced}");
    // The projection methods draw the same surfaces as the traced hits; their distances (along each
    // pixel's ray to the drawn triangle's plane) equal the hits' where the same triangle is drawn.
    let f = |j: &serde_json::Value, k: &str| j[k].as_f64().unwrap_or_else(|| panic!("{k}: {j}"));
    for method in ["adaptive", "vertex"] {
        let j = run(&["--method", method, "--against", "trace"]);
        assert_eq!(j["against"], "trace");
        assert!(f(&j, "different_surface_fraction") < 0.005, "{j}");
        assert!(f(&j, "depth_rel_p99") < 1e-3, "{j}");
        assert!(f(&j, "different_triangle_fraction") < 0.01, "{j}");
        // The display-position error found on the traced image is the analytic one's.
        assert!((f(&j, "traced_mean_px") - f(&j, "mean_px")).abs() <= 0.03 * f(&j, "mean_px") + 0.01, "{j}");
        assert!(f(&j, "traced_pixels") > 0.95 * f(&j, "pixels") && f(&j, "traced_unmatched") < 0.01 * f(&j, "pixels"));
    }
    // Against another method there are no traced points to measure on.
    assert!(run(&["--method", "vertex", "--against", "slit:1"]).get("traced_mean_px").is_none());
}

#[test]
fn a_chunked_frame_reports_wall_times_per_pass() {
    let out = tmp("chunked");
    let stats = out.join("s.json");
    let o = twister()
        .args([
            "render",
            "builtin:sphere1024",
            "--width",
            "320",
            "--height",
            "60",
            "--method",
            "adaptive:length",
            "--edge-px",
            "0.5",
            "--memory-mb",
            "8",
        ])
        .args(["--out", out.to_str().unwrap(), "--stats", stats.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let json: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&stats).unwrap()).unwrap();
    assert!(json["chunks"].as_u64().unwrap() > 1, "{json}");
    assert_eq!(json["timing"], "wall-per-pass");
    let (sub, ras, frame) = (
        json["ms_subdivide"].as_f64().unwrap(),
        json["ms_raster"].as_f64().unwrap(),
        json["ms_frame"].as_f64().unwrap(),
    );
    assert!(sub > 0.0 && ras > 0.0 && (sub + ras - frame).abs() < 1e-6, "{json}");
    let _ = std::fs::remove_dir_all(&out);
}

/// `bench startup` times whole `render` processes, cold, warm and warm without the pipeline
/// cache, and writes its rows; anything but a `render` case and reps out of range are refused.
#[test]
fn bench_startup_times_fresh_processes_and_refuses_bad_cases() {
    let dir = tmp("startup");
    let json = dir.join("startup.json");
    std::fs::create_dir_all(&*dir).unwrap();
    let case = "render builtin:triangle@3 --width 16 --height 8";
    let o = twister().args(["bench", "startup", "--reps", "1", "--case", case, "--json"]).arg(&json).output().unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let rows: serde_json::Value = serde_json::from_slice(&std::fs::read(&json).unwrap()).unwrap();
    let caches: Vec<&str> = rows["rows"].as_array().unwrap().iter().map(|r| r["caches"].as_str().unwrap()).collect();
    assert_eq!(caches, ["cold", "warm", "warm, no pipeline cache"]);
    for r in rows["rows"].as_array().unwrap() {
        let ms = r["ms_median"].as_f64().unwrap();
        assert!(ms > 0.0 && ms < 600_000.0 && r["command"] == case, "{r}");
    }
    for bad in [["--case", "error builtin:demo"], ["--reps", "0"], ["--case", "render --width nope"]] {
        let o = twister().args(["bench", "startup"]).args(bad).output().unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        let errors: Vec<&str> = err.lines().filter(|l| l.starts_with("error")).collect();
        assert!(!o.status.success() && errors.len() == 1 && errors[0].contains(bad[0]), "{bad:?}: {err}");
        assert!(!err.contains("panicked"), "{bad:?}: {err}");
    }
}
