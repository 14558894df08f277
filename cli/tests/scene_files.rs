//! Scene files through the command line: `info` describes them, `render` places their cameras
//! and refuses broken files with one line and no output.

use std::path::{Path, PathBuf};

mod common;
use common::gltf_files::{gltf_json, write, QUAD};

fn assets() -> PathBuf {
    common::asset("gltf")
}

fn tmp(name: &str) -> common::TempDir {
    let d = common::TempDir::new(format!("twister-files-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&*d).unwrap();
    d
}

/// The column span (first, last) of non-background pixels in a row band of a rendered PNG.
fn drawn_columns(png: &Path) -> (u32, u32, u32) {
    let img = image::open(png).unwrap().to_rgba8();
    let bg = *img.get_pixel(0, 0);
    let xs: Vec<u32> = img.enumerate_pixels().filter(|(_, _, p)| **p != bg).map(|(x, _, _)| x).collect();
    assert!(!xs.is_empty(), "{}: nothing drawn", png.display());
    (*xs.iter().min().unwrap(), *xs.iter().max().unwrap(), img.width())
}

/// Broken glTF files for `broken_files_are_one_clear_error_without_panic_or_output`: not JSON,
/// truncated, out-of-range indices, NaN, missing and undecodable buffers and images, required
/// extensions, a bad GLB, empty files, a folder, devices; with what the error must say.
fn broken_files(dir: &Path) -> Vec<(PathBuf, &'static str)> {
    let mut cases: Vec<(PathBuf, &str)> = Vec::new();
    let garbage = dir.join("garbage.gltf");
    std::fs::write(&garbage, "{ this is not json").unwrap();
    cases.push((garbage, "not a glTF file (invalid JSON"));
    let good = serde_json::to_string(&gltf_json(&QUAD, Some(&[0, 1, 2]), 4)).unwrap();
    let truncated = dir.join("truncated.gltf");
    std::fs::write(&truncated, &good[..good.len() / 2]).unwrap();
    cases.push((truncated, "not a glTF file (invalid JSON"));
    cases.push((write(dir, "index.gltf", &gltf_json(&QUAD, Some(&[0, 1, 9]), 4)), "index 9 is out of range"));
    cases.push((
        write(dir, "nan.gltf", &gltf_json(&[[0.0, f32::NAN, -3.0], [1.0, 0.0, -3.0], [0.0, 1.0, -3.0]], None, 4)),
        "NaN",
    ));
    let mut overrun = gltf_json(&QUAD, None, 4);
    overrun["accessors"][0]["count"] = serde_json::json!(400);
    cases.push((write(dir, "overrun.gltf", &overrun), "overruns"));
    let mut missing = gltf_json(&QUAD, None, 4);
    missing["buffers"][0]["uri"] = serde_json::json!("missing.bin");
    cases.push((write(dir, "missing.gltf", &missing), "buffer 0 file 'missing.bin': no such file"));
    let mut no_image = gltf_json(&QUAD, None, 4);
    no_image["images"] = serde_json::json!([{ "uri": "missing.png" }]);
    cases.push((write(dir, "no_image.gltf", &no_image), "image 0 file 'missing.png': no such file"));
    let mut bad_image = gltf_json(&QUAD, None, 4);
    bad_image["images"] = serde_json::json!([{ "uri": "data:image/png;base64,iVBORw0KGgoAAAANSUhEUgAA" }]);
    cases.push((write(dir, "bad_image.gltf", &bad_image), "image 0: cannot be decoded"));
    let mut ext = gltf_json(&QUAD, None, 4);
    ext["extensionsUsed"] = serde_json::json!(["KHR_draco_mesh_compression"]);
    ext["extensionsRequired"] = serde_json::json!(["KHR_draco_mesh_compression"]);
    cases.push((write(dir, "ext.gltf", &ext), "KHR_draco_mesh_compression"));
    let glb = dir.join("truncated.glb");
    let mut bytes = b"glTF".to_vec();
    bytes.extend(2u32.to_le_bytes());
    bytes.extend(4000u32.to_le_bytes()); // claims 4000 bytes, has 20
    bytes.extend([0u8; 8]);
    std::fs::write(&glb, bytes).unwrap();
    cases.push((glb, "not a readable GLB file"));
    for (name, text, needle) in [
        ("empty.gltf", "", "is empty"),
        ("brace.gltf", "{", "invalid JSON"),
        ("object.gltf", "{}", "asset.version is missing"),
    ] {
        std::fs::write(dir.join(name), text).unwrap();
        cases.push((dir.join(name), needle));
    }
    std::fs::create_dir_all(dir.join("folder.gltf")).unwrap();
    cases.push((dir.join("folder.gltf"), "is a folder, not a file"));
    #[cfg(unix)]
    {
        let _ = std::os::unix::fs::symlink("/dev/zero", dir.join("zero.gltf"));
        cases.push((dir.join("zero.gltf"), "not a regular file"));
        let mut dev = gltf_json(&QUAD, None, 4);
        dev["buffers"][0]["uri"] = "/dev/zero".into();
        cases.push((write(dir, "devzero.gltf", &dev), "buffer 0 file '/dev/zero': is not a regular file"));
    }
    cases
}

/// Invalid documents the gltf crate would panic on, or accept, with what the error must say.
fn broken_documents(dir: &Path) -> Vec<(PathBuf, &'static str)> {
    let mut cases: Vec<(PathBuf, &'static str)> = Vec::new();
    let doc = || gltf_json(&QUAD, None, 4);
    let mut edit = |name: &str, f: &dyn Fn(&mut serde_json::Value), needle: &'static str| {
        let mut d = doc();
        f(&mut d);
        cases.push((write(dir, name, &d), needle));
    };
    edit(
        "acc99.gltf",
        &|d| d["meshes"][0]["primitives"][0]["attributes"]["POSITION"] = 99.into(),
        "names accessors[99]",
    );
    edit("stride4.gltf", &|d| d["bufferViews"][0]["byteStride"] = 4.into(), "byteStride is only 4");
    edit("version.gltf", &|d| d["asset"]["version"] = "1.0".into(), "asset.version is \"1.0\"");
    edit("scalar.gltf", &|d| d["accessors"][0]["type"] = "SCALAR".into(), "of type SCALAR");
    edit("ubyte.gltf", &|d| d["accessors"][0]["componentType"] = 5121.into(), "componentType 5121");
    edit("bytelength.gltf", &|d| d["buffers"][0]["byteLength"] = 10.into(), "overruns buffers[0]");
    edit(
        "shared.gltf",
        &|d| {
            d["nodes"] = serde_json::json!([{ "children": [1] }, { "mesh": 0 }, { "children": [1] }]);
            d["scenes"][0]["nodes"] = serde_json::json!([0, 2]);
        },
        "a glTF node has at most one parent",
    );
    edit(
        "cycle.gltf",
        &|d| d["nodes"] = serde_json::json!([{ "children": [1], "mesh": 0 }, { "children": [0] }]),
        "cycle",
    );
    edit(
        "base64.gltf",
        &|d| d["buffers"][0]["uri"] = "data:application/octet-stream;base64,AAA!AAAA".into(),
        "buffer 0:",
    );
    cases
}

#[test]
fn broken_files_are_one_clear_error_without_panic_or_output() {
    let dir = tmp("broken");
    let mut cases = broken_files(&dir);
    cases.extend(broken_documents(&dir));
    for (file, needle) in cases {
        let out = dir.join("out");
        let o = common::twister()
            .env("NODEVICE_SELECT", "1")
            .args(["render", file.to_str().unwrap(), "--width", "64", "--height", "16", "--out"])
            .arg(&out)
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(1), "{}: {err}", file.display());
        assert!(err.contains(file.to_str().unwrap()) && err.contains(needle), "{}: {err}", file.display());
        assert!(!err.contains("panicked") && err.trim().lines().count() == 1, "{}: {err}", file.display());
        assert!(!out.exists(), "{}: output written for a broken file", file.display());
    }
}

fn twister(args: &[&str]) -> std::process::Output {
    common::twister().env("NODEVICE_SELECT", "1").args(args).output().unwrap()
}

#[test]
fn info_describes_a_file_and_its_camera_is_a_viewer() {
    if !common::assets_present() {
        return;
    }
    let duck = assets().join("Duck/glTF-Binary/Duck.glb");
    assert!(duck.exists(), "{} is missing from the assets", duck.display());
    let o = twister(&["info", duck.to_str().unwrap()]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let j: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(j["triangles"], 4212);
    assert_eq!(j["materials"].as_u64(), Some(1));
    assert_eq!((j["meshes"].as_u64(), j["primitives"].as_u64(), j["objects"].as_u64()), (Some(1), Some(1), Some(1)));
    let png = image::open(assets().join("Duck/glTF/DuckCM.png")).unwrap();
    assert_eq!(j["textures"][0]["width"].as_u64(), Some(png.width() as u64));
    assert_eq!(j["textures"][0]["height"].as_u64(), Some(png.height() as u64));
    assert_eq!(j["cameras"].as_array().unwrap().len(), 1);
    assert_eq!(j["suggested_viewer"]["where"], "in front");
    // The camera stands at (4.0, 4.6, −4.3) looking at the duck near the origin: its yaw points there.
    let cam = &j["cameras"][0];
    let (x, z, yaw) =
        (cam["position"][0].as_f64().unwrap(), cam["position"][2].as_f64().unwrap(), cam["yaw_deg"].as_f64().unwrap());
    let dir = (-(yaw.to_radians().sin()), -(yaw.to_radians().cos()));
    let to_duck = (-x / (x * x + z * z).sqrt(), -z / (x * x + z * z).sqrt());
    assert!(dir.0 * to_duck.0 + dir.1 * to_duck.1 > 0.99, "camera yaw {yaw} does not face the duck");
    let out = tmp("cam");
    let o = twister(&[
        "render",
        duck.to_str().unwrap(),
        "--viewer",
        "camera",
        "--width",
        "64",
        "--height",
        "16",
        "--out",
        out.join("a").to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let o =
        twister(&["render", duck.to_str().unwrap(), "--viewer", "camera:3", "--out", out.join("b").to_str().unwrap()]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success() && err.contains("camera:3") && err.contains("1 cameras"), "{err}");
}

#[test]
fn fit_and_scale_move_the_file_camera_with_the_scene() {
    // A camera at (2, 0, 5) looking along −z, 3 m behind a triangle centred on x = 2: the
    // triangle is straight ahead of it. `--fit` moves the scene (centring it on x = 0); the
    // camera must move with it, so the triangle stays straight ahead (centre columns).
    let dir = tmp("fitcam");
    let mut json = gltf_json(&[[1.5, -0.5, 2.0], [2.5, -0.5, 2.0], [2.0, 0.5, 2.0]], None, 4);
    json["nodes"] = serde_json::json!([{ "mesh": 0 }, { "camera": 0, "translation": [2.0, 0.0, 5.0] }]);
    json["scenes"] = serde_json::json!([{ "nodes": [0, 1] }]);
    json["cameras"] = serde_json::json!([{ "type": "perspective", "perspective": { "yfov": 1.0, "znear": 0.1 } }]);
    let file = write(&dir, "cam.gltf", &json);
    for extra in [&["--fit", "3"][..], &["--scale", "2"][..], &["--fit", "3", "--scale", "0.5"][..]] {
        let out = dir.join(format!("out{}", extra.join("_")));
        let mut args = vec!["render", file.to_str().unwrap(), "--viewer", "camera", "--width", "360", "--height", "90"];
        args.extend_from_slice(extra);
        args.extend_from_slice(&["--out", out.to_str().unwrap()]);
        let o = twister(&args);
        assert!(o.status.success(), "{extra:?}: {}", String::from_utf8_lossy(&o.stderr));
        let (lo, hi, w) = drawn_columns(&out.join("left.png"));
        let centre = (lo + hi) as f32 / 2.0;
        assert!((centre - w as f32 / 2.0).abs() < 4.0, "{extra:?}: triangle drawn at columns {lo}..{hi} of {w}");
    }
}

#[test]
fn obj_files_are_read_safely_and_faults_name_their_line() {
    let dir = tmp("objsafe");
    let tri = "v 0 0 -3\nv 1 0 -3\nv 0 1 -3\n";
    let cases: [(&str, String, Option<&str>); 5] = [
        ("two.obj", format!("{tri}f 1 2\nf 1 2 3\n"), Some("line 4: a face needs at least 3 vertices, got 2")),
        ("one.obj", format!("{tri}f 1\n"), Some("line 4: a face needs at least 3 vertices, got 1")),
        ("vt.obj", format!("{tri}f 1/5 2/5 3/5\n"), Some("face names texture coordinate 5")),
        ("vn.obj", format!("{tri}vn 0 0 1\nf 1//1 2//2 3//1\n"), Some("face names normal 2")),
        ("zero.obj", format!("mtllib /dev/zero\n{tri}f 1 2 3\n"), None),
    ];
    for (name, text, needle) in cases {
        let file = dir.join(name);
        std::fs::write(&file, text).unwrap();
        let o = twister(&["info", file.to_str().unwrap()]);
        let err = String::from_utf8_lossy(&o.stderr);
        match needle {
            Some(needle) => {
                assert_eq!(o.status.code(), Some(1), "{name}: {err}");
                assert!(err.contains(name) && err.contains(needle) && err.lines().count() == 1, "{name}: {err}");
            }
            None => {
                // An MTL that is a device is not read (it never ends): a warning, the default colour.
                assert!(o.status.success(), "{name}: {err}");
                let j: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
                let w = j["warnings"][0].as_str().unwrap();
                assert!(w.contains("/dev/zero") && w.contains("not a regular file"), "{w}");
            }
        }
    }
    // An object name in Latin-1 is a label: read, not refused.
    let latin1 = dir.join("latin1.obj");
    let mut bytes = b"o caf\xe9\n".to_vec();
    bytes.extend_from_slice(format!("{tri}f 1 2 3\n").as_bytes());
    std::fs::write(&latin1, bytes).unwrap();
    let o = twister(&["info", latin1.to_str().unwrap()]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    // A folder named like a scene.
    std::fs::create_dir_all(dir.join("folder.obj")).unwrap();
    let o = twister(&["info", dir.join("folder.obj").to_str().unwrap()]);
    assert!(String::from_utf8_lossy(&o.stderr).contains("is a folder, not a file"));
}

/// `twister info` lists a glTF file's punctual lights (KHR_lights_punctual).
#[test]
fn info_lists_a_gltf_files_punctual_lights() {
    if !common::assets_present() {
        return;
    }
    let o = common::twister()
        .args(["info", common::asset("gltf/LightsPunctualLamp/glTF/LightsPunctualLamp.gltf").to_str().unwrap()])
        .output()
        .unwrap();
    let info: serde_json::Value = serde_json::from_slice(&o.stdout).expect("info prints JSON");
    let listed = info["lights"].as_array().expect("lights listed");
    assert!(listed.len() == 5 && listed.iter().all(|l| l["kind"] == "point"), "{info}");
}

#[test]
fn loader_warnings_are_printed_by_render_and_error() {
    // An OBJ naming a missing MTL file: one warning line on stderr, the render still made.
    let dir = tmp("warn");
    let obj = dir.join("w.obj");
    std::fs::write(&obj, "mtllib missing.mtl\nv -1 0 -3\nv 1 0 -3\nv 0 1 -3\nf 1 2 3\n").unwrap();
    for cmd in ["render", "error"] {
        let out = dir.join(cmd);
        let o = twister(
            &[cmd, obj.to_str().unwrap(), "--width", "64", "--height", "16", "--out", out.to_str().unwrap()]
                [..if cmd == "render" { 8 } else { 6 }],
        );
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(o.status.success(), "{cmd}: {err}");
        assert!(
            err.contains("warning:") && err.contains("w.obj") && err.contains("materials not loaded"),
            "{cmd}: {err}"
        );
    }
}
