//! The `twister` binary as a user runs it: what it writes for each command and flag (its
//! refusals of bad input, a missing driver and damaged files: `cli_errors.rs`).

mod common;

use std::path::Path;

use common::{png_size, twister};

fn tmp(name: &str) -> common::TempDir {
    common::TempDir::new(format!("twister-cli-{}-{name}", std::process::id()))
}

#[test]
fn render_writes_every_layout_and_stats() {
    let out = tmp("layouts");
    let size = ["--width", "320", "--height", "60"];
    let run = |layout: &str, dir: &Path, extra: &[&str]| {
        let o = twister()
            .args(["render", "builtin:sphere100", "--layout", layout, "--out"])
            .arg(dir)
            .args(size)
            .args(extra)
            .output()
            .unwrap();
        assert!(o.status.success(), "{layout}: {}", String::from_utf8_lossy(&o.stderr));
    };
    let stats = out.join("stats.json");
    run("eyes", &out.join("eyes"), &["--stats", stats.to_str().unwrap()]);
    assert_eq!(png_size(&out.join("eyes/left.png")), (320, 60));
    assert_eq!(png_size(&out.join("eyes/right.png")), (320, 60));
    run("top-bottom", &out.join("tb"), &[]);
    assert_eq!(png_size(&out.join("tb/stereo_TB.png")), (320, 120));
    run("side-by-side", &out.join("lr"), &[]);
    assert_eq!(png_size(&out.join("lr/stereo_LR.png")), (640, 60));
    // Top-bottom: left on top; side-by-side: left on the left.
    let eyes = ["left", "right"].map(|e| image::open(out.join(format!("eyes/{e}.png"))).unwrap().to_rgba8());
    let tb = image::open(out.join("tb/stereo_TB.png")).unwrap().to_rgba8();
    let lr = image::open(out.join("lr/stereo_LR.png")).unwrap().to_rgba8();
    for (k, eye) in eyes.iter().enumerate() {
        for (x, y) in [(0, 0), (100, 30), (319, 59)] {
            assert_eq!(tb.get_pixel(x, y + 60 * k as u32), eye.get_pixel(x, y));
            assert_eq!(lr.get_pixel(x + 320 * k as u32, y), eye.get_pixel(x, y));
        }
    }
    run("twister", &out.join("tw"), &[]);
    for f in ["left_front", "left_back", "right_front", "right_back"] {
        assert_eq!(png_size(&out.join(format!("tw/{f}.png"))), (160, 60), "{f}");
    }
    // The front image is the middle half of the eye image; the back one the outer halves.
    let eye = image::open(out.join("eyes/left.png")).unwrap().to_rgba8();
    let front = image::open(out.join("tw/left_front.png")).unwrap().to_rgba8();
    let back = image::open(out.join("tw/left_back.png")).unwrap().to_rgba8();
    for y in [0, 30, 59] {
        for x in [0u32, 79, 159] {
            assert_eq!(front.get_pixel(x, y), eye.get_pixel(80 + x, y));
            assert_eq!(back.get_pixel(x, y), eye.get_pixel((240 + x) % 320, y));
        }
    }
    stats_record_a_one_submission_frame(&stats);
    let _ = std::fs::remove_dir_all(&out);
}

/// The `--stats` JSON of a one-submission frame of `builtin:sphere100` at 320×60.
fn stats_record_a_one_submission_frame(stats: &Path) {
    let json: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(stats).unwrap()).unwrap();
    for key in [
        "scene",
        "triangles_in",
        "triangles_drawn",
        "width",
        "height",
        "adapter",
        "timing",
        "ms_frame",
        "ms_subdivide",
        "ms_raster",
        "ms_total",
    ] {
        assert!(json.get(key).is_some(), "stats lack {key}: {json}");
    }
    // The times say how they were measured: apart only where they were.
    match json["timing"].as_str().unwrap() {
        "gpu-timestamps" => {
            assert!(json["ms_subdivide"].is_number() && json["ms_raster"].is_number() && json["ms_gpu"].is_number())
        }
        "wall-one-submission" => assert!(json["ms_subdivide"].is_null() && json["ms_raster"].is_null()),
        other => panic!("a one-submission frame reported timing {other}"),
    }
    assert_eq!(json["triangles_in"], 100);
    assert_eq!(json["width"], 320);
    assert!(json["triangles_drawn"].as_u64().unwrap() >= 100);
}

/// The cubemap: top-bottom by default (stereo_cubemap_TB.png); 12x1 cuts each eye's 3×2 grid
/// into one strip of twelve faces, the left eye's six first.
#[test]
fn the_cubemap_writes_its_layouts() {
    let out = tmp("cube-layouts");
    let cube = ["--panorama", "cubemap", "--width", "96"];
    let run = |layout: &str, dir: &Path, extra: &[&str]| {
        let o = twister()
            .args(["render", "builtin:sphere100", "--layout", layout, "--out"])
            .arg(dir)
            .args(extra)
            .output()
            .unwrap();
        assert!(o.status.success(), "{layout}: {}", String::from_utf8_lossy(&o.stderr));
    };
    run("eyes", &out.join("cube-eyes"), &cube);
    let cube_eyes = ["left", "right"].map(|e| image::open(out.join(format!("cube-eyes/{e}.png"))).unwrap().to_rgba8());
    assert_eq!(cube_eyes[0].dimensions(), (96, 64));
    run("12x1", &out.join("strip"), &cube);
    let strip = image::open(out.join("strip/stereo_cubemap_12x1.png")).unwrap().to_rgba8();
    assert_eq!(strip.dimensions(), (384, 32));
    for k in 0..12u32 {
        let (eye, face) = (&cube_eyes[(k / 6) as usize], k % 6);
        for (x, y) in [(0, 0), (13, 21), (31, 31)] {
            assert_eq!(
                strip.get_pixel(32 * k + x, y),
                eye.get_pixel(32 * (face % 3) + x, 32 * (face / 3) + y),
                "face {k}"
            );
        }
    }
    let o =
        twister().args(["render", "builtin:sphere100", "--out"]).arg(out.join("cube-tb")).args(cube).output().unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(png_size(&out.join("cube-tb/stereo_cubemap_TB.png")), (96, 128));
    let _ = std::fs::remove_dir_all(&out);
}

#[test]
fn background_and_view_flags_take_effect() {
    let out = tmp("bg");
    let o = twister()
        .args([
            "render",
            "builtin:sphere100",
            "--width",
            "200",
            "--height",
            "40",
            "--background",
            "255,0,0",
            "--yaw",
            "180",
            "--out",
        ])
        .arg(&out)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let img = image::open(out.join("left.png")).unwrap().to_rgba8();
    // Turned around, the sphere is behind: the centre column is background, the edge is not.
    assert_eq!(img.get_pixel(100, 20).0, [255, 0, 0, 255]);
    assert_ne!(img.get_pixel(0, 20).0, [255, 0, 0, 255]);
    let _ = std::fs::remove_dir_all(&out);
}

/// CAVE walls (issue 34): the outputs named by wall and eye at each wall's pixels, the
/// statistics one record per wall, a sequence's frames per wall along a head path; each misuse
/// one line naming the option (and the file and wall), nothing written.
#[test]
fn cave_walls_are_written_by_name_and_their_misuses_are_one_line() {
    let out = tmp("cave");
    std::fs::create_dir_all(&out).unwrap();
    let cave = out.join("cave.json");
    let wall = |name: &str, ll: &str, lr: &str, ul: &str, px: &str| {
        format!(r#"{{"name": "{name}", "lower_left": {ll}, "lower_right": {lr}, "upper_left": {ul}, "pixels": {px}}}"#)
    };
    let front = wall("front", "[-1.5,-1.5,-1.5]", "[1.5,-1.5,-1.5]", "[-1.5,1.5,-1.5]", "[64, 48]");
    let floor = wall("floor", "[-1.5,-1.5,1.5]", "[1.5,-1.5,1.5]", "[-1.5,-1.5,-1.5]", "[32, 32]");
    std::fs::write(&cave, format!(r#"{{"walls": [{front}, {floor}]}}"#)).unwrap();
    let c = cave.to_str().unwrap();
    let stats = out.join("stats.json");
    let o = twister()
        .args(["render", "builtin:demo", "--panorama", "cave", "--cave", c, "--head", "0.1,0,0.2,15", "--out"])
        .arg(out.join("still"))
        .args(["--stats", stats.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    for (name, size) in [("front", (64, 48)), ("floor", (32, 32))] {
        for eye in ["left", "right"] {
            assert_eq!(png_size(&out.join(format!("still/{name}_{eye}.png"))), size, "{name} {eye}");
        }
    }
    let json: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&stats).unwrap()).unwrap();
    let walls: Vec<(&str, u64)> =
        json.as_array().unwrap().iter().map(|r| (r["wall"].as_str().unwrap(), r["width"].as_u64().unwrap())).collect();
    assert_eq!(walls, [("front", 64), ("floor", 32)]);
    // A sequence along a head path: each frame's walls.
    let path = out.join("head.csv");
    std::fs::write(&path, "time,x,y,z,yaw\n0,0,0,0,0\n1,0.3,0.1,0.2,30\n").unwrap();
    let o = twister()
        .args(["render", "builtin:demo", "--panorama", "cave", "--cave", c, "--head-path", path.to_str().unwrap()])
        .args(["--frames", "0..1", "--out"])
        .arg(out.join("seq"))
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    for f in ["frame_000000_front_left.png", "frame_000001_floor_right.png"] {
        assert!(out.join("seq").join(f).exists(), "{f}");
    }
    let bad = out.join("bad.json");
    std::fs::write(&bad, r#"{"walls": [{"name": "front""#).unwrap();
    let b = bad.to_str().unwrap();
    let cases: &[(&[&str], &str)] = &[
        (&["--panorama", "cave", "--head", "0,0,0"], "--cave: --panorama cave draws the walls"),
        (&["--panorama", "cave", "--cave", "/nonexistent/cave.json", "--head", "0,0,0"], "cannot open"),
        (&["--panorama", "cave", "--cave", b, "--head", "0,0,0"], "--cave: "),
        (&["--cave", c], "--cave: gives the walls of --panorama cave"),
        (&["--panorama", "cave", "--cave", c], "--head: a CAVE wall is seen by a tracked head"),
        (&["--panorama", "cave", "--cave", c, "--head", "0,0,0", "--width", "64"], "--width/--height: a CAVE's walls"),
        (
            &["--panorama", "cave", "--cave", c, "--head", "0,0,0", "--method", "slit:4"],
            "--method: slit:4: a CAVE wall",
        ),
        (&["--panorama", "cave", "--cave", c, "--head", "0,0,-2"], "--cave: wall \"front\": faces away"),
        (&["--panorama", "cave", "--cave", c, "--head", "0,-1.495,0"], "--cave: wall \"floor\": the left eye is"),
        (&["--panorama", "cave", "--cave", c, "--head", "0,0,0", "--viewer", "camera"], "--viewer: a CAVE's walls"),
        (
            &["--panorama", "cave", "--cave", c, "--head", "0,0,0", "--frames", "0..1", "--video", "/tmp/x.mp4"],
            "--video",
        ),
    ];
    for (args, needle) in cases {
        let o = twister()
            .args(["render", "builtin:demo"])
            .args(*args)
            .arg("--out")
            .arg(out.join("never"))
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success(), "{args:?} succeeded");
        assert!(err.contains(needle) && err.lines().count() == 1, "{args:?}: {err}");
        assert!(err.contains("bad.json") || !args.contains(&b), "{err}");
    }
    assert!(!out.join("never").exists(), "nothing written");
    let _ = std::fs::remove_dir_all(&out);
}

#[test]
fn subdivision_flags_take_effect_and_are_reported() {
    let out = tmp("flags");
    let stats = |extra: &[&str]| -> serde_json::Value {
        let file = out.join(format!("s{}.json", extra.join("_").replace([':', '-'], "")));
        let o = twister()
            .args(["render", "builtin:sphere100", "--width", "320", "--height", "60", "--out"])
            .arg(&out)
            .args(["--stats", file.to_str().unwrap()])
            .args(extra)
            .output()
            .unwrap();
        assert!(o.status.success(), "{extra:?}: {}", String::from_utf8_lossy(&o.stderr));
        serde_json::from_str(&std::fs::read_to_string(&file).unwrap()).unwrap()
    };
    let vertex = stats(&["--method", "vertex"]);
    assert_eq!(vertex["method"], "vertex");
    // vertex: one triangle per part (the 100 triangles: nothing near the axis asks for cuts, so
    // none is cut); fixed:3: nine per part.
    let parts = vertex["triangles_out"].as_u64().unwrap();
    assert!((100..200).contains(&parts), "{parts} parts");
    let fixed = stats(&["--method", "fixed:3"]);
    assert_eq!(fixed["method"], "fixed:3");
    assert_eq!(fixed["triangles_out"].as_u64().unwrap(), 9 * parts);
    // The paper's eq. 5 (`--split length` or `--method adaptive:length`) follows L ...
    let coarse = stats(&["--split", "length", "--edge-px", "64"]);
    let fine = stats(&["--method", "adaptive:length", "--edge-px", "4"]);
    assert_eq!(fine["edge_px"], 4.0);
    assert_eq!(fine["method"], "adaptive:length");
    assert_eq!(coarse["method"], "adaptive:length");
    assert!(fine["triangles_out"].as_u64() > coarse["triangles_out"].as_u64());
    // ... the error split (the default) follows τ.
    let loose = stats(&["--max-error-px", "2"]);
    let strict = stats(&["--max-error-px", "0.0625"]);
    assert_eq!(strict["method"], "adaptive");
    assert_eq!(strict["max_error_px"], 0.0625);
    assert!(strict["triangles_out"].as_u64() > loose["triangles_out"].as_u64());
    assert!(strict["max_sub_edge_px"].as_f64() < loose["max_sub_edge_px"].as_f64());
    let tight = stats(&["--split", "length", "--edge-px", "0.25", "--memory-mb", "8"]);
    assert!(tight["chunks"].as_u64().unwrap() > 1, "{tight}");
    // The subdivision's balance: one `lattice` invocation per piece; a vertex piece writes its 3
    // nodes (twice at the seam), a fixed:3 piece its 10; a chunked frame sums its ranges.
    let invocations = |j: &serde_json::Value, pass: &str| {
        let passes = j["subdivide_invocations"].as_array().unwrap();
        passes.iter().find(|p| p[0] == pass).map_or(0, |p| p[1].as_u64().unwrap())
    };
    assert_eq!(invocations(&vertex, "lattice"), vertex["pieces"].as_u64().unwrap(), "{vertex}");
    assert!((3..=6).contains(&vertex["max_output_per_invocation"].as_u64().unwrap()), "{vertex}");
    assert!((10..=20).contains(&fixed["max_output_per_invocation"].as_u64().unwrap()), "{fixed}");
    assert!(invocations(&tight, "plan") >= tight["triangles_in"].as_u64().unwrap(), "{tight}");
    assert!(tight["max_pieces_per_invocation"].as_u64().unwrap() >= 1, "{tight}");
    // Where timestamps timed the frame: the three groups of passes, in schedule order, each from
    // the end of the one before: together the subdivision's time. (`bench speed --pass-times`
    // times each pass apart: tests/cli_measure.rs.)
    for j in [&vertex, &strict] {
        if let Some(names) = common::subdivide_pass_names(j) {
            assert_eq!(names, ["plan", "plan_cuts", "lattice"], "{j}");
        }
    }
    let _ = std::fs::remove_dir_all(&out);
}

#[test]
fn render_accepts_slit_methods() {
    let out = tmp("slit");
    let o = twister()
        .args(["render", "builtin:demo", "--method", "slit:8", "--width", "256", "--height", "48", "--out"])
        .arg(&out)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(png_size(&out.join("left.png")), (256, 48));
    let o = twister().args(["render", "--method", "slit:0"]).output().unwrap();
    assert!(!o.status.success() && String::from_utf8_lossy(&o.stderr).contains("slit:W"));
    let _ = std::fs::remove_dir_all(&out);
}

#[test]
fn trace_on_the_default_cylinder_uses_the_exact_model_and_says_so_in_one_note() {
    let out = tmp("trace-cylinder");
    let run = |dir: &str, method: &str, extra: &[&str]| {
        let o = twister()
            .args(["render", "builtin:demo", "--method", method, "--width", "128", "--height", "24", "--out"])
            .arg(out.join(dir))
            .args(extra)
            .output()
            .unwrap();
        assert!(o.status.success(), "{extra:?}: {}", String::from_utf8_lossy(&o.stderr));
        let stderr = String::from_utf8_lossy(&o.stderr).into_owned();
        (std::fs::read(out.join(dir).join("left.png")).unwrap(), stderr)
    };
    let (default, note) = run("default", "trace", &[]);
    let (exact, quiet) = run("exact", "trace", &["--vertical", "exact"]);
    assert_eq!(default, exact, "the default cylinder traced is the exact model's image");
    let notes: Vec<&str> = note.lines().collect();
    assert!(notes.len() == 1 && notes[0].starts_with("note: ") && notes[0].contains("--vertical exact"), "{note}");
    assert!(quiet.trim().is_empty(), "{quiet}");
    // Another method on the default cylinder keeps the paper's model, without a note.
    let (_, plain) = run("vertex", "vertex", &[]);
    assert!(plain.trim().is_empty(), "{plain}");
}

#[test]
fn scale_turns_scene_units_into_metres_which_sets_the_disparity() {
    // Scaling the scene and the viewer together keeps every direction; only the disparity
    // changes, since the eye circle is in metres. Sphere100 (3 m ahead) at --scale 0.2 stands
    // 0.6 m ahead, inside the display cylinder: its disparity changes sign.
    use twister::core::panoramas::projection::{Eye, Projection};
    let (w, h) = (720u32, 120u32);
    let projection = Projection { width: w, height: h, ..Projection::default() };
    let disparity = |scale: &str| {
        let out = tmp(&format!("scale{scale}"));
        let o = twister()
            .args(["render", "builtin:sphere100", "--width", &w.to_string(), "--height", &h.to_string()])
            .args(["--scale", scale, "--background", "0,0,0", "--out"])
            .arg(&out)
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let cx = |eye: &str| {
            let img = image::open(out.join(format!("{eye}.png"))).unwrap().to_rgba8();
            let xs: Vec<f32> =
                img.enumerate_pixels().filter(|(_, _, p)| p.0[..3] != [0, 0, 0]).map(|(x, _, _)| x as f32).collect();
            assert!(xs.len() > 100);
            xs.iter().sum::<f32>() / xs.len() as f32
        };
        let d = cx("right") - cx("left");
        let _ = std::fs::remove_dir_all(&out);
        d
    };
    let expected = |r: f32| {
        let x = |eye| projection.to_pixel(projection.project(glam::Vec3::new(0.0, 0.0, -r), eye).unwrap().u, 0.0)[0];
        x(Eye::Right) - x(Eye::Left)
    };
    let sphere = twister::core::scenes::builtin::builtin_scene("builtin:sphere100", &projection).unwrap();
    let (lo, hi) = sphere.bounds().unwrap();
    let (centre, front) = (-(lo.z + hi.z) / 2.0, -hi.z);
    let (d1, d02) = (disparity("1"), disparity("0.2"));
    // The drawn disk's disparity lies between those of its centre's and its front's distance.
    for (d, s) in [(d1, 1.0), (d02, 0.2)] {
        let (a, b) = (expected(s * centre), expected(s * front));
        assert!(d >= a.min(b) - 0.5 && d <= a.max(b) + 0.5, "scale {s}: disparity {d} px, expected in {a}..{b}");
    }
    assert!(d1 > 0.0 && d02 < 0.0, "{d1} {d02}");
    let o = twister().args(["render", "--scale", "0", "--out", "/nonexistent"]).output().unwrap();
    assert_eq!(o.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&o.stderr).contains("--scale"));
}

#[test]
fn lod_flags_render_an_overlay_and_report_the_selection() {
    let out = tmp("lod");
    let stats = out.join("stats.json");
    let o = twister()
        .args([
            "render",
            "builtin:demo",
            "--width",
            "400",
            "--height",
            "80",
            "--lod",
            "visual-field",
            "--gaze",
            "90,10",
        ])
        .args(["--lod-overlay", "--lod-p2", "0.4", "--lod-p3", "0.1", "--lod-dinf", "50", "--out"])
        .arg(&out)
        .arg("--stats")
        .arg(&stats)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let json: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&stats).unwrap()).unwrap();
    let lod = &json["lod"];
    let by_field: u64 =
        ["central", "peripheral", "outside"].iter().map(|f| lod[f]["triangles"].as_u64().unwrap()).sum();
    assert_eq!(by_field, lod["triangles_selected"].as_u64().unwrap());
    assert_eq!(json["triangles_in"], lod["triangles_selected"]);
    // The overlay: white pixels (the central field's boundary) around 90° left of centre.
    let img = image::open(out.join("left.png")).unwrap().to_rgba8();
    let white: Vec<u32> =
        img.enumerate_pixels().filter(|(_, _, p)| p.0 == [255, 255, 255, 255]).map(|(x, _, _)| x).collect();
    assert!(!white.is_empty());
    let (lo, hi) = (white.iter().min().unwrap(), white.iter().max().unwrap());
    // The central field spans ±30° around 90° left: columns 400·(0.5 − 120/360) .. 400·(0.5 − 60/360).
    assert!(*lo >= 60 && *hi <= 140, "central boundary at columns {lo}..{hi}");
    let _ = std::fs::remove_dir_all(&out);
    for (args, needle) in [
        (&["render", "--lod-overlay"][..], "--lod-overlay: needs --lod visual-field"),
        (&["render", "--lod", "visual-field", "--gaze", "1,2,3"][..], "YAW,PITCH"),
        (&["render", "--lod", "visual-field", "--lod-p3", "0.5", "--lod-p2", "0.3"][..], "P3"),
    ] {
        let o = twister().args(args).args(["--out", "/nonexistent/x"]).output().unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code().map(|c| c != 0), Some(true), "{args:?}");
        assert!(err.contains(needle) && !err.contains("panicked"), "{args:?}: {err}");
    }
}

#[test]
fn identical_runs_give_identical_bytes() {
    let run = |dir: &Path| {
        let stats = dir.join("stats.json");
        let o = twister()
            .args(["render", "builtin:demo", "--width", "320", "--height", "80", "--layout", "top-bottom", "--out"])
            .arg(dir)
            .args(["--stats", stats.to_str().unwrap()])
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let mut json: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&stats).unwrap()).unwrap();
        // Times differ between runs; everything else must not.
        json.as_object_mut().unwrap().retain(|k, _| !k.starts_with("ms_"));
        (std::fs::read(dir.join("stereo_TB.png")).unwrap(), json)
    };
    let (a, b) = (tmp("same-a"), tmp("same-b"));
    let (ra, rb) = (run(&a), run(&b));
    assert!(ra.0 == rb.0, "two identical renders differ");
    assert_eq!(ra.1, rb.1, "their stats differ");
    let _ = (std::fs::remove_dir_all(&a), std::fs::remove_dir_all(&b));
}

#[test]
fn both_eyes_in_one_multiview_draw_match_a_pass_per_eye() {
    if !common::assets_present() {
        return;
    }
    // The raster stage can draw both eyes from one multiview draw (`TWISTER_MULTIVIEW=on`; the
    // default on hardware GPUs) or a pass per eye (`off`; the default on software adapters).
    // Both must draw the same: colours and distances (the error pass's fragment path, which
    // reads the eye's parameters). Lavapipe's multiview mixes the views up at some pixels near
    // triangle edges, differently from run to run (a pixel of the left image showing exactly the
    // right eye's distance there: a vertex shaded for one view drawn in the other), measured up
    // to 0.6 % of the pixels, and 2.0–2.8 % on AlphaBlendModeTest once the subdivision skipped
    // its back faces (0 with its default, a pass per eye); so up to 5 % may differ on lavapipe
    // and 2 % elsewhere. Mixing the eyes' parameters up in twister would change nearly every
    // pixel (the eyes are apart by the disparity, and every distance changes).
    let duck = common::asset("gltf/Duck/glTF-Binary/Duck.glb");
    let alpha = common::asset("gltf/AlphaBlendModeTest/glTF-Binary/AlphaBlendModeTest.glb");
    let cases: Vec<(String, Vec<&str>)> = vec![
        ("builtin:demo".into(), vec!["--height", "90"]),
        (
            "builtin:demo".into(),
            vec!["--method", "vertex", "--panorama", "equirect", "--height", "240", "--layout", "eyes"],
        ),
        ("builtin:sphere1024".into(), vec!["--method", "adaptive:length", "--height", "90"]),
        // Single-sided materials: culled by the rasterizer per eye.
        (duck.to_string_lossy().into(), vec!["--fit", "2", "--height", "90"]),
        // Textures, alpha mask and blend, double-sided: the material code.
        (alpha.to_string_lossy().into(), vec!["--fit", "2", "--height", "90"]),
    ];
    for (k, (scene, extra)) in cases.iter().enumerate() {
        let run = |env: Option<&str>| {
            let out = tmp(&format!("multiview{k}{}", env.is_some()));
            let mut cmd = twister();
            if let Some(v) = env {
                cmd.env("TWISTER_MULTIVIEW", v);
            }
            let o = cmd
                .args(["render", scene, "--width", "480", "--depth", "--out"])
                .arg(&out)
                .arg("--stats")
                .arg(out.join("stats.json"))
                .args(extra)
                .output()
                .unwrap();
            assert!(o.status.success(), "{scene} {extra:?}: {}", String::from_utf8_lossy(&o.stderr));
            let stats: serde_json::Value =
                serde_json::from_str(&std::fs::read_to_string(out.join("stats.json")).unwrap()).unwrap();
            let files = ["left.png", "right.png", "left_depth.exr", "right_depth.exr"].map(|f| {
                if f.ends_with(".exr") {
                    common::read_exr(&out.join(f)).2.into_iter().map(|z| [z; 4]).collect()
                } else {
                    let img = image::open(out.join(f)).unwrap_or_else(|e| panic!("{f}: {e}")).to_rgba32f();
                    img.pixels().map(|p| p.0).collect::<Vec<[f32; 4]>>()
                }
            });
            let _ = std::fs::remove_dir_all(&out);
            (stats["adapter"].as_str().unwrap().to_string(), files)
        };
        let (adapter, both) = run(Some("on"));
        let (per_eye_adapter, per_eye) = run(Some("off"));
        assert!(per_eye_adapter.contains("a pass per eye"), "{per_eye_adapter}");
        if !adapter.contains("multiview") {
            eprintln!("{adapter}: no multiview on this adapter; both runs drew a pass per eye");
        }
        let differing = |a: &[[f32; 4]], b: &[[f32; 4]]| a.iter().zip(b).filter(|(p, q)| p != q).count();
        let names = ["left.png", "right.png", "left_depth.exr", "right_depth.exr"];
        let share = if adapter.contains("llvmpipe") { 20 } else { 50 };
        for (f, (a, b)) in names.iter().zip(both.iter().zip(&per_eye)) {
            let bad = differing(a, b);
            assert!(bad * share <= a.len(), "{scene} {extra:?}: {f}: {bad} of {} pixels differ", a.len());
        }
        // The two eyes differ (each view drew its own eye) by far more than that.
        let apart = differing(&both[2], &both[3]);
        let covered = both[2].iter().zip(&both[3]).filter(|(p, q)| p[0].is_finite() || q[0].is_finite()).count();
        assert!(apart * 2 > covered, "{scene} {extra:?}: left and right differ on only {apart} of {covered} distances");
    }
}

/// `render --help` groups its options under headings, `-h` is the short form, and no module
/// path or internal name of the library leaks into either.
#[test]
fn render_help_is_grouped_and_speaks_no_module_paths() {
    let long = twister().args(["render", "--help"]).output().unwrap();
    let short = twister().args(["render", "-h"]).output().unwrap();
    let (long, short) = (String::from_utf8_lossy(&long.stdout), String::from_utf8_lossy(&short.stdout));
    let headings = [
        "Scene and placement:",
        "Panorama:",
        "Eyes and display:",
        "Quality:",
        "Lighting:",
        "Output:",
        "Animation and farm:",
    ];
    for text in [&long, &short] {
        let positions: Vec<usize> = headings.iter().map(|h| text.find(&format!("\n{h}\n")).expect(h)).collect();
        assert!(positions.windows(2).all(|w| w[0] < w[1]), "headings out of order");
        assert!(!text.contains("::") && !text.contains("core_") && !text.contains("encoding"), "{text}");
    }
    assert!(short.lines().count() * 3 < long.lines().count() * 2, "-h is not shorter than --help");
    // Every option sits under a heading: the untitled "Options:" group holds only help.
    let options = long.split("\nOptions:\n").nth(1).unwrap().split("\n\n").next().unwrap();
    assert!(options.trim_start().starts_with("-h, --help") && options.matches("--").count() == 1, "{options}");
}
