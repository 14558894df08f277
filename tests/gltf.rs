//! glTF 2.0 import: the Khronos samples (when ../shared/assets is present) and files written
//! here, good and broken.

use std::path::{Path, PathBuf};
use std::process::Command;

use twister::load::load_scene;
use twister::Projection;

fn assets() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/assets/gltf")
}

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("twister-gltf-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn base64(bytes: &[u8]) -> String {
    const T: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut s = String::new();
    for c in bytes.chunks(3) {
        let n = (c[0] as u32) << 16 | (*c.get(1).unwrap_or(&0) as u32) << 8 | *c.get(2).unwrap_or(&0) as u32;
        for k in 0..4 {
            s.push(if k <= c.len() { T[(n >> (18 - 6 * k) & 63) as usize] as char } else { '=' });
        }
    }
    s
}

/// A one-primitive glTF with an embedded buffer: positions, optional u32 indices, a mode.
fn gltf_json(positions: &[[f32; 3]], indices: Option<&[u32]>, mode: u32) -> serde_json::Value {
    let mut bytes: Vec<u8> = positions.iter().flatten().flat_map(|f| f.to_le_bytes()).collect();
    let pos_len = bytes.len();
    if let Some(ix) = indices {
        bytes.extend(ix.iter().flat_map(|i| i.to_le_bytes()));
    }
    let mut prim = serde_json::json!({ "attributes": { "POSITION": 0 }, "mode": mode });
    let mut accessors = vec![serde_json::json!({
        "bufferView": 0, "componentType": 5126, "count": positions.len(), "type": "VEC3",
        "min": [-10.0, -10.0, -10.0], "max": [10.0, 10.0, 10.0]
    })];
    let mut views = vec![serde_json::json!({ "buffer": 0, "byteOffset": 0, "byteLength": pos_len })];
    if let Some(ix) = indices {
        prim["indices"] = serde_json::json!(1);
        accessors
            .push(serde_json::json!({ "bufferView": 1, "componentType": 5125, "count": ix.len(), "type": "SCALAR" }));
        views.push(serde_json::json!({ "buffer": 0, "byteOffset": pos_len, "byteLength": 4 * ix.len() }));
    }
    serde_json::json!({
        "asset": { "version": "2.0" },
        "scene": 0,
        "scenes": [{ "nodes": [0] }],
        "nodes": [{ "mesh": 0 }],
        "meshes": [{ "primitives": [prim] }],
        "accessors": accessors,
        "bufferViews": views,
        "buffers": [{ "byteLength": bytes.len(), "uri": format!("data:application/octet-stream;base64,{}", base64(&bytes)) }]
    })
}

fn write(dir: &Path, name: &str, json: &serde_json::Value) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, serde_json::to_string(json).unwrap()).unwrap();
    p
}

const QUAD: [[f32; 3]; 4] = [[0.0, 0.0, -3.0], [1.0, 0.0, -3.0], [0.0, 1.0, -3.0], [1.0, 1.0, -3.0]];

#[test]
fn strips_fans_and_lists_are_triangulated() {
    let dir = tmp("modes");
    let p = Projection::default();
    let list = write(&dir, "list.gltf", &gltf_json(&QUAD, Some(&[0, 1, 2, 2, 1, 3]), 4));
    let strip = write(&dir, "strip.gltf", &gltf_json(&QUAD, None, 5));
    let fan = write(
        &dir,
        "fan.gltf",
        &gltf_json(
            &[[0.0, 0.0, -3.0], [1.0, 0.0, -3.0], [1.0, 1.0, -3.0], [0.0, 1.0, -3.0], [-1.0, 0.5, -3.0]],
            None,
            6,
        ),
    );
    let lines = write(&dir, "lines.gltf", &gltf_json(&QUAD, None, 1));
    let area = |s: &twister::Scene| -> f32 {
        s.indices
            .chunks(3)
            .map(|t| {
                let v = |k: usize| glam::Vec3::from(s.vertices[t[k] as usize].position);
                0.5 * (v(1) - v(0)).cross(v(2) - v(0)).length()
            })
            .sum()
    };
    for (file, tris, expected_area) in [(&list, 2, 1.0), (&strip, 2, 1.0), (&fan, 3, 1.5)] {
        let s = load_scene(file.to_str().unwrap(), &p).unwrap();
        assert_eq!(s.triangle_count(), tris, "{}", file.display());
        assert!((area(&s) - expected_area).abs() < 1e-5, "{}: area {}", file.display(), area(&s));
    }
    let err = load_scene(lines.to_str().unwrap(), &p).unwrap_err();
    assert!(err.contains("no triangles"), "{err}");
}

#[test]
fn khronos_samples_load_with_their_hierarchy() {
    let a = assets();
    if !a.exists() {
        eprintln!("NOTE: {} is absent; the Khronos sample tests did not run", a.display());
        return;
    }
    let p = Projection::default();
    let load = |rel: &str| load_scene(a.join(rel).to_str().unwrap(), &p).unwrap();
    // Box: a parent node turns Z-up into Y-up; all three containers give the same triangles.
    let variants = ["Box/glTF/Box.gltf", "Box/glTF-Binary/Box.glb", "Box/glTF-Embedded/Box.gltf"].map(load);
    for s in &variants {
        assert_eq!(s.triangle_count(), 12);
        let (lo, hi) = s.bounds().unwrap();
        assert!((lo + 0.5).abs().max_element() < 1e-5 && (hi - 0.5).abs().max_element() < 1e-5, "{lo} {hi}");
        assert_eq!(
            s.vertices.iter().map(|v| v.position).collect::<Vec<_>>(),
            variants[0].vertices.iter().map(|v| v.position).collect::<Vec<_>>()
        );
    }
    // Duck: a scaled node; world bounds as listed in the assets README.
    let duck = load("Duck/glTF-Binary/Duck.glb");
    assert_eq!(duck.triangle_count(), 4212);
    let (lo, hi) = duck.bounds().unwrap();
    for (got, want) in [(lo, [-0.693, 0.099, -0.613]), (hi, [0.962, 1.640, 0.539])] {
        assert!((0..3).all(|k| (got[k] - want[k]).abs() < 2e-3), "{got} vs {want:?}");
    }
    // SimpleMeshes: one mesh drawn by two nodes, the second translated by (1, 0, 0).
    let simple = load("SimpleMeshes/glTF/SimpleMeshes.gltf");
    assert_eq!((simple.triangle_count(), simple.objects.len()), (2, 2));
    let (lo, hi) = simple.bounds().unwrap();
    assert_eq!((lo.to_array(), hi.to_array()), ([0.0, 0.0, 0.0], [2.0, 1.0, 0.0]));
}

#[test]
fn broken_files_are_one_clear_error_without_panic_or_output() {
    let dir = tmp("broken");
    let mut cases: Vec<(PathBuf, &str)> = Vec::new();
    let garbage = dir.join("garbage.gltf");
    std::fs::write(&garbage, "{ this is not json").unwrap();
    cases.push((garbage, "not a readable glTF file"));
    let good = serde_json::to_string(&gltf_json(&QUAD, Some(&[0, 1, 2]), 4)).unwrap();
    let truncated = dir.join("truncated.gltf");
    std::fs::write(&truncated, &good[..good.len() / 2]).unwrap();
    cases.push((truncated, "not a readable glTF file"));
    cases.push((write(&dir, "index.gltf", &gltf_json(&QUAD, Some(&[0, 1, 9]), 4)), "index 9 is out of range"));
    cases.push((
        write(&dir, "nan.gltf", &gltf_json(&[[0.0, f32::NAN, -3.0], [1.0, 0.0, -3.0], [0.0, 1.0, -3.0]], None, 4)),
        "NaN",
    ));
    let mut overrun = gltf_json(&QUAD, None, 4);
    overrun["accessors"][0]["count"] = serde_json::json!(400);
    cases.push((write(&dir, "overrun.gltf", &overrun), "overruns"));
    let mut missing = gltf_json(&QUAD, None, 4);
    missing["buffers"][0]["uri"] = serde_json::json!("missing.bin");
    cases.push((write(&dir, "missing.gltf", &missing), "not a readable glTF file"));
    let mut ext = gltf_json(&QUAD, None, 4);
    ext["extensionsUsed"] = serde_json::json!(["KHR_draco_mesh_compression"]);
    ext["extensionsRequired"] = serde_json::json!(["KHR_draco_mesh_compression"]);
    cases.push((write(&dir, "ext.gltf", &ext), "KHR_draco_mesh_compression"));
    let glb = dir.join("truncated.glb");
    let mut bytes = b"glTF".to_vec();
    bytes.extend(2u32.to_le_bytes());
    bytes.extend(4000u32.to_le_bytes()); // claims 4000 bytes, has 20
    bytes.extend([0u8; 8]);
    std::fs::write(&glb, bytes).unwrap();
    cases.push((glb, "not a readable glTF file"));
    for (file, needle) in cases {
        let out = dir.join("out");
        let o = Command::new(env!("CARGO_BIN_EXE_twister"))
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
    Command::new(env!("CARGO_BIN_EXE_twister")).env("NODEVICE_SELECT", "1").args(args).output().unwrap()
}

#[test]
fn info_describes_a_file_and_its_camera_is_a_viewer() {
    let duck = assets().join("Duck/glTF-Binary/Duck.glb");
    if !duck.exists() {
        eprintln!("NOTE: {} is absent; the info test did not run", duck.display());
        return;
    }
    let o = twister(&["info", duck.to_str().unwrap()]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let j: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(j["triangles"], 4212);
    assert_eq!(j["materials"].as_u64(), Some(1));
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
fn obj_materials_give_colours_and_a_missing_mtl_is_a_warning() {
    let dir = tmp("obj");
    let obj = "mtllib colours.mtl\nv 0 0 -3\nv 1 0 -3\nv 0 1 -3\nv 1 1 -3\nusemtl red\nf 1 2 3\nusemtl blue\nf 2 4 3\n";
    std::fs::write(dir.join("quad.obj"), obj).unwrap();
    std::fs::write(dir.join("colours.mtl"), "newmtl red\nKd 1 0 0\nnewmtl blue\nKd 0 0 1\n").unwrap();
    let p = Projection::default();
    let s = load_scene(dir.join("quad.obj").to_str().unwrap(), &p).unwrap();
    let colours: std::collections::BTreeSet<[u32; 3]> =
        s.vertices.iter().map(|v| [v.color[0], v.color[1], v.color[2]].map(|c| (c * 255.0) as u32)).collect();
    assert!(colours.contains(&[255, 0, 0]) && colours.contains(&[0, 0, 255]), "{colours:?}");
    assert_eq!(s.materials.len(), 2);
    std::fs::remove_file(dir.join("colours.mtl")).unwrap();
    let s = load_scene(dir.join("quad.obj").to_str().unwrap(), &p).unwrap();
    assert_eq!(s.triangle_count(), 2);
    assert!(s.warnings.iter().any(|w| w.contains("materials not loaded")), "{:?}", s.warnings);
}
