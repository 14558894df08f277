//! The `twister` binary given bad input as a user gives it: malformed options, options out of
//! place, no GPU driver, outputs it cannot write, sizes beyond the device, a damaged pipeline
//! cache: one clear line naming the option or file, no panic, no half-written output.

mod common;

use std::path::Path;

use common::twister;

fn tmp(name: &str) -> common::TempDir {
    common::TempDir::new(format!("twister-cli-errors-{}-{name}", std::process::id()))
}

#[test]
fn no_gpu_driver_is_one_clear_error_without_panic_or_output() {
    let out = tmp("nogpu");
    // Only the Metal backend allowed: no adapter on Linux, as on a machine without a driver.
    let o = twister()
        .env("WGPU_BACKEND", "metal")
        .args(["render", "--width", "64", "--height", "16", "--out"])
        .arg(&out)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(err.contains("no GPU adapter found") && err.contains("mesa-vulkan-drivers"), "{err}");
    assert!(!err.contains("panicked"), "{err}");
    assert_eq!(err.lines().count(), 1, "one line: {err}");
    assert!(!out.exists(), "no output folder is made when rendering fails");
}

#[test]
fn bad_arguments_are_clear_errors() {
    let cases: &[(&[&str], &str)] = &[
        (&["render", "builtin:nope"], "unknown built-in scene"),
        (&["render", "builtin:triangle@abc"], "builtin:triangle@abc"),
        (&["render", "--eye-radius", "2"], "--eye-radius"),
        (&["render", "--width", "0"], "image size"),
        (&["render", "--viewer", "1,2"], "three finite numbers"),
        (&["render", "--background", "300,0,0"], "0–255"),
        (&["render", "scene.obj"], "scene.obj"),
        // Options of the full sphere, and of the image format.
        (&["render", "--convergence", "2"], "--convergence: needs --panorama equirect"),
        (&["render", "--pole-merge", "60,75"], "--pole-merge: needs --panorama equirect"),
        (&["render", "--panorama", "equirect", "--pole-merge", "80,70"], "FROM < TO"),
        (&["render", "--panorama", "equirect", "--convergence", "close"], "parallel or a distance"),
        (&["render", "--panorama", "equirect", "--convergence", "0.01"], "--convergence"),
        (&["render", "--preset", "vr4k", "--panorama", "cylinder"], "--preset"),
        (&["render", "--preset", "vr4k", "--width", "100"], "--width"),
        (&["render", "--quality", "50"], "--quality: needs --format jpg"),
        (&["render", "--format", "jpg", "--quality", "0"], "--quality"),
        (&["render", "--format", "gif"], "--format"),
        // VR180 and the fisheye (issue 34).
        (&["render", "--panorama", "vr180", "--layout", "twister"], "--layout: twister splits a panorama"),
        (&["render", "--panorama", "vr180", "--preset", "vr4k"], "--preset"),
        (&["render", "--fov", "200"], "--fov: needs --panorama fisheye"),
        (&["render", "--panorama", "equirect", "--dome-tilt", "10"], "--dome-tilt: needs --panorama fisheye"),
        (&["render", "--panorama", "fisheye", "--fov", "0"], "--fov: must be a field of view"),
        (&["render", "--panorama", "fisheye", "--fov", "361"], "--fov: must be a field of view"),
        (&["render", "--panorama", "fisheye", "--fov", "nan"], "--fov"),
        (&["render", "--panorama", "fisheye", "--dome-tilt", "95"], "--dome-tilt: must be degrees between -90 and 90"),
        (&["render", "--panorama", "fisheye", "--fov", "350", "--dome-tilt", "10"], "--dome-tilt: a tilted dome"),
        (&["render", "--panorama", "fisheye", "--method", "slit:4"], "--method: slit:4"),
        (&["render", "--alpha"], "--alpha: needs --panorama fisheye"),
        // A tracked head (issue 34).
        (&["render", "--head", "0.98,0,0"], "--head: the eyes reach the screen"),
        (&["render", "--head", "0,0,0", "--panorama", "equirect"], "--head: a tracked head looks at the cylinder"),
        (&["render", "--head", "0,0,0", "--viewer", "camera"], "--head: needs the display's centre"),
        (&["render", "--head", "0,0,0", "--vertical", "paper"], "--vertical: a tracked head"),
        (&["render", "--head", "0,0,0", "--method", "slit:4"], "--method: slit:4 pastes the slits of eyes"),
        (&["render", "--head", "0,0"], "--head"),
        (&["render", "--head", "0,0,nan"], "--head"),
        (&["render", "--panorama", "fisheye", "--alpha", "--format", "jpg"], "--alpha: needs --format png"),
        // The stereo cubemap (issue 34).
        (&["render", "--panorama", "cubemap", "--width", "100"], "--width/--height: a cubemap is a 3x2 grid"),
        (&["render", "--panorama", "cubemap", "--width", "300", "--height", "300"], "3x2 grid"),
        (&["render", "--panorama", "cubemap", "--method", "slit:4"], "--method: slit:4"),
        (&["render", "--panorama", "cubemap", "--preset", "vr4k"], "--preset"),
        (&["render", "--layout", "12x1"], "--layout: 12x1 lays out a cubemap's faces"),
        (&["render", "--panorama", "cubemap", "--layout", "twister"], "--layout: twister"),
    ];
    for (args, needle) in cases {
        let o = twister().args(*args).args(["--out", "/nonexistent/never"]).output().unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success(), "{args:?} succeeded");
        assert!(err.contains(needle), "{args:?}: {err}");
        assert!(!err.contains("panicked"), "{args:?}: {err}");
    }
}

#[test]
fn negative_and_malformed_numbers_are_one_line_naming_the_option() {
    for (args, needle) in [
        (&["render", "--width", "-5"][..], "--width"),
        (&["render", "--fit", "-1"][..], "--fit"),
        (&["render", "--edge-px", "-1"][..], "--edge-px"),
        (&["render", "--max-div", "-1"][..], "--max-div"),
        (&["render", "--max-error-px", "0"][..], "--max-error-px"),
        (&["render", "--max-error-px", "NaN"][..], "--max-error-px"),
        (&["render", "--split", "curvature"][..], "--split"),
        (&["render", "--reflect-max", "9"][..], "--reflect-max"),
        (&["render", "--reflect-max", "-1"][..], "--reflect-max"),
        (&["render", "--method", "trace", "--vertical", "paper"][..], "--vertical"),
        (&["render", "--light", "0,2,0"][..], "--light"),
        (
            &[
                "bench",
                "speed",
                "builtin:demo",
                "--methods",
                "vertex,trace",
                "--vertical",
                "exact",
                "--lod",
                "visual-field",
            ][..],
            "--lod",
        ),
        (&["render", "--method", "trace", "--vertical", "exact", "--light", "0,nan,0"][..], "--light"),
        (&["render", "--eye-radius", "NaN"][..], "--eye-radius"),
        (&["render", "--exposure", "NaN"][..], "--exposure"),
        (&["render", "--exposure", "100"][..], "--exposure"),
        (&["render", "--tonemap", "reinhard"][..], "--tonemap"),
        (&["render", "--lighting", "sun"][..], "--lighting"),
        (&["render", "--yaw", "abc"][..], "--yaw"),
        (&["error", "--heatmap-max", "0"][..], "--heatmap-max"),
        (&["error", "--heatmap-max", "-5"][..], "--heatmap-max"),
    ] {
        let o = twister().args(args).output().unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success(), "{args:?} accepted");
        assert!(err.contains(needle) && err.trim().lines().count() == 1 && !err.contains("'-- -"), "{args:?}: {err}");
    }
}

#[test]
fn lod_options_without_lod_are_refused_by_every_command() {
    for cmd in [&["render"][..], &["error"][..], &["bench", "speed", "builtin:sphere100"][..]] {
        for (flag, value) in [("--lod-p2", "5"), ("--lod-p3", "0.1"), ("--lod-dinf", "10"), ("--gaze", "10,0")] {
            let o = twister().args(cmd).args([flag, value]).output().unwrap();
            let err = String::from_utf8_lossy(&o.stderr);
            assert!(!o.status.success(), "{cmd:?} {flag}: accepted");
            assert!(err.contains(flag) && err.contains("needs --lod visual-field"), "{cmd:?} {flag}: {err}");
        }
    }
}

#[test]
fn a_plain_run_without_a_desktop_session_prints_no_driver_noise() {
    // No NODEVICE_SELECT and no XDG_RUNTIME_DIR, as on a fresh server: the program quiets
    // Mesa's device-select layer itself.
    let out = tmp("quiet");
    let o = common::twister()
        .env_remove("NODEVICE_SELECT")
        .env_remove("XDG_RUNTIME_DIR")
        .args(["render", "--width", "64", "--height", "16", "--out", out.to_str().unwrap()])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{err}");
    assert!(err.trim().is_empty(), "a plain render printed to stderr: {err}");
    let _ = std::fs::remove_dir_all(&out);
}

#[test]
fn outputs_are_all_or_nothing_and_checked_before_rendering() {
    let out = tmp("atomic");
    std::fs::create_dir_all(out.join("right.png")).unwrap();
    std::fs::write(out.join("left.png"), b"older render").unwrap();
    let o =
        twister().args(["render", "--width", "64", "--height", "16", "--out", out.to_str().unwrap()]).output().unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success() && err.contains("right.png") && err.lines().count() == 1, "{err}");
    assert_eq!(std::fs::read(out.join("left.png")).unwrap(), b"older render", "left.png was replaced");
    // A stats path that cannot be written: nothing at all is written.
    let fresh = tmp("atomic-stats");
    std::fs::create_dir_all(fresh.join("stats.json")).unwrap();
    let o = twister()
        .args(["render", "--width", "64", "--height", "16", "--out", fresh.join("imgs").to_str().unwrap()])
        .args(["--stats", fresh.join("stats.json").to_str().unwrap()])
        .output()
        .unwrap();
    assert!(!o.status.success() && String::from_utf8_lossy(&o.stderr).contains("stats.json"));
    assert!(!fresh.join("imgs").exists(), "images written although the stats could not be");
    // A stats file where nothing can be written (/proc): refused before rendering, no images.
    if Path::new("/proc/self").exists() {
        let o = twister()
            .args(["render", "--width", "64", "--height", "16", "--out", fresh.join("imgs").to_str().unwrap()])
            .args(["--stats", "/proc/stats.json"])
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success() && err.contains("/proc/stats.json") && err.lines().count() == 1, "{err}");
        assert!(!fresh.join("imgs").exists(), "images written although the stats could not be");
    }
    // --out naming a file.
    let file = fresh.join("a-file");
    std::fs::write(&file, b"x").unwrap();
    let o = twister()
        .args(["render", "--width", "64", "--height", "16", "--out", file.to_str().unwrap()])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success() && err.contains("is not a folder"), "{err}");
    // Temporaries of a killed run are cleaned up by the next one in that folder.
    std::fs::remove_dir_all(out.join("right.png")).unwrap();
    let stale = out.join(".left.png.4194303.tmp");
    std::fs::write(&stale, b"half").unwrap();
    let o =
        twister().args(["render", "--width", "64", "--height", "16", "--out", out.to_str().unwrap()]).output().unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(!stale.exists(), "stale temporary kept");
    let _ = (std::fs::remove_dir_all(&out), std::fs::remove_dir_all(&fresh));
}

#[test]
fn an_image_too_large_for_the_device_is_refused_up_front() {
    let out = tmp("huge");
    let start = std::time::Instant::now();
    let o = twister()
        .args(["render", "--width", "16384", "--height", "16384", "--out", out.to_str().unwrap()])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    // lavapipe: a 2 GiB read-back exceeds its buffer limit; a real GPU may take it.
    if !o.status.success() {
        assert!(err.contains("--width/--height") && err.lines().count() == 1, "{err}");
        assert!(start.elapsed().as_secs() < 20, "refused only after {:?}", start.elapsed());
        assert!(!out.exists());
    }
    let _ = std::fs::remove_dir_all(&out);
}

/// The pipeline cache on disk (`gpu::pipeline_cache`): written after a run; a damaged file
/// (empty, foreign bytes, truncated) is ignored and replaced, with the same image and no word on
/// stderr; a cache that cannot be written (its folder is a file) or is switched off changes
/// nothing either.
#[test]
fn a_damaged_or_unwritable_pipeline_cache_is_never_an_error() {
    let dir = tmp("pipeline-cache");
    let cache = dir.join("cache");
    let run = |cache_dir: &Path| {
        let o = twister()
            .args(["render", "builtin:triangle@3", "--width", "64", "--height", "16", "--out"])
            .arg(dir.join("out"))
            .env("TWISTER_CACHE_DIR", cache_dir)
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        assert!(o.stderr.is_empty(), "a plain run says nothing: {}", String::from_utf8_lossy(&o.stderr));
        std::fs::read(dir.join("out/left.png")).unwrap()
    };
    let image = run(&cache);
    let files: Vec<std::path::PathBuf> =
        std::fs::read_dir(&cache).map(|d| d.flatten().map(|e| e.path()).collect()).unwrap_or_default();
    if files.is_empty() {
        eprintln!("this adapter has no pipeline cache: only the runs without one were checked");
    }
    for file in &files {
        let whole = std::fs::read(file).unwrap();
        for damaged in
            [Vec::new(), b"not a pipeline cache".to_vec(), vec![0xa5; 4096], whole[..whole.len() / 2].to_vec()]
        {
            std::fs::write(file, &damaged).unwrap();
            assert_eq!(run(&cache), image, "the image with a damaged cache");
            assert_ne!(std::fs::read(file).unwrap(), damaged, "the damaged cache is replaced");
        }
    }
    let not_a_folder = dir.join("a-file");
    std::fs::write(&not_a_folder, b"x").unwrap();
    assert_eq!(run(&not_a_folder.join("cache")), image, "with a cache that cannot be written");
    assert_eq!(run(Path::new("off")), image, "with the cache switched off");
    // Relative cache homes are ignored: nothing lands in the working folder.
    let work = dir.join("work");
    std::fs::create_dir_all(&work).unwrap();
    let o = twister()
        .args(["render", "builtin:triangle@3", "--width", "64", "--height", "16", "--out"])
        .arg(dir.join("out"))
        .current_dir(&work)
        .env_remove("TWISTER_CACHE_DIR")
        .env("XDG_CACHE_HOME", "relative-cache")
        .env("HOME", "relative-home")
        .env("MESA_SHADER_CACHE_DIR", dir.join("mesa"))
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let left: Vec<_> = std::fs::read_dir(&work).unwrap().flatten().map(|e| e.file_name()).collect();
    assert!(left.is_empty(), "the working folder got {left:?}");
}

/// Bad sample counts and anisotropies: one error line naming the option, nothing written.
#[test]
fn bad_sample_counts_are_one_clear_line() {
    for (args, says) in [
        (&["--samples", "3"][..], "must be 1, 2, 4, 8, 16 or 32"),
        (&["--samples", "99999999999"][..], "--samples"),
        (&["--anisotropy", "0"][..], "must be 1 to 16"),
        (&["--anisotropy", "17"][..], "must be 1 to 16"),
        (&["--anisotropy", "-1"][..], "--anisotropy"),
    ] {
        let dir = common::TempDir::new(format!("twister-samples-{}", std::process::id()));
        let o = common::twister()
            .args(["render", "builtin:triangle@3", "--width", "64", "--height", "16", "--out"])
            .arg(&*dir)
            .args(args)
            .output()
            .expect("runs");
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success(), "{args:?} succeeded");
        assert!(err.contains(args[0]) && err.contains(says), "{args:?}: {err}");
        assert_eq!(err.lines().filter(|l| l.starts_with("error")).count(), 1, "{args:?}: one error line: {err}");
        assert!(std::fs::read_dir(&*dir).map_or(true, |mut d| d.next().is_none()), "{args:?} wrote output");
    }
}
