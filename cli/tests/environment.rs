//! Lighting options through the command line: `--hdr`'s files and the environment's cache.

mod common;

use twister::core::shading::environment::Environment;

/// `--hdr` writes each eye's linear colour as an EXR beside display images that are the bytes
/// they are without it; the methods that cannot draw a linear frame, and an environment that
/// would do nothing, are refused with one line.
#[test]
fn render_hdr_writes_linear_exr_beside_the_same_display_images() {
    let dir = common::TempDir::new(format!("twister-hdr-{}", std::process::id()));
    let run = |extra: &[&str]| {
        common::twister()
            .args(["render", "builtin:demo", "--width", "128", "--height", "32", "--hdr", "--out"])
            .arg(&dir)
            .args(extra)
            .env("NODEVICE_SELECT", "1")
            .output()
            .unwrap()
    };
    let o = run(&[]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    // One frame draws both: the display images are the bytes they are without --hdr.
    let plain = common::TempDir::new(format!("twister-hdr-plain-{}", std::process::id()));
    let o = common::twister()
        .args(["render", "builtin:demo", "--width", "128", "--height", "32", "--out"])
        .arg(&*plain)
        .env("NODEVICE_SELECT", "1")
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    for name in ["left.png", "right.png"] {
        let read = |d: &std::path::Path| std::fs::read(d.join(name)).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert!(read(&dir) == read(&plain), "{name} differs with --hdr");
    }
    for name in ["left_hdr.exr", "right_hdr.exr"] {
        use exr::prelude::*;
        let image = read_first_rgba_layer_from_file(
            dir.join(name),
            |r, _| (r.width(), vec![0f32; r.width() * r.height()]),
            |(w, v), p, (r, _g, _b, _a): (f32, f32, f32, f32)| v[p.y() * *w + p.x()] = r,
        )
        .unwrap_or_else(|e| panic!("{name}: {e}"));
        let size = image.layer_data.size;
        assert_eq!((size.width(), size.height()), (128, 32), "{name}");
        assert!(image.layer_data.channel_data.pixels.1.iter().all(|r| r.is_finite() && *r >= 0.0), "{name}");
    }
    for method in ["slit:4", "trace"] {
        let o = run(&["--method", method, "--vertical", "exact"]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success() && err.starts_with("error: --hdr: ") && err.trim().lines().count() == 1, "{err}");
    }
    // An environment with the headlight look would do nothing: refused.
    let o = run(&["--environment", "neutral", "--lighting", "headlight"]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        !o.status.success() && err.starts_with("error: --environment: ") && err.trim().lines().count() == 1,
        "{err}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// `--environment` fills the cache folder that `TWISTER_CACHE_DIR` names.
#[test]
fn render_caches_the_prepared_environment_where_twister_cache_dir_says() {
    if !common::assets_present() {
        return;
    }
    use twister::core::caches::environment_cache::cache_file;
    let dir = common::TempDir::new(format!("twister-env-cache-cli-{}", std::process::id()));
    let env = Environment::load(&common::asset("environments/venice_sunset_1k.hdr")).unwrap();
    // The command line caches where TWISTER_CACHE_DIR says (the studio of a glTF scene too).
    let cli_dir = dir.join("cli");
    let out = dir.join("out");
    let status = common::twister()
        .env("TWISTER_CACHE_DIR", &cli_dir)
        .args(["render", "--width", "64", "--height", "32", "--environment"])
        .arg(common::asset("environments/venice_sunset_1k.hdr"))
        .arg("--lighting")
        .arg("pbr")
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    assert!(status.status.success(), "{}", String::from_utf8_lossy(&status.stderr));
    assert!(cli_dir.join(cache_file(&cli_dir, &env).file_name().unwrap()).exists());
    std::fs::remove_dir_all(&dir).unwrap();
}
