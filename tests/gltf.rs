//! glTF 2.0 import: the Khronos samples (when ../shared/assets is present) and files written
//! here, good and broken.

use std::path::{Path, PathBuf};
use std::process::Command;

use twister::core::load::load_scene;
use twister::Projection;

mod common;

fn assets() -> PathBuf {
    common::asset("gltf")
}

fn tmp(name: &str) -> common::TempDir {
    let d = common::TempDir::new(format!("twister-gltf-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&*d).unwrap();
    d
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
        "buffers": [{ "byteLength": bytes.len(), "uri": format!("data:application/octet-stream;base64,{}", common::base64(&bytes)) }]
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
    let err = load_scene(lines.to_str().unwrap(), &p).unwrap_err().to_string();
    assert!(err.contains("no triangles"), "{err}");
}

#[test]
fn khronos_samples_load_with_their_hierarchy() {
    if !common::assets_present() {
        return;
    }
    let a = assets();
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

fn png_bytes(w: u32, h: u32, f: impl Fn(u32, u32) -> [u8; 4]) -> Vec<u8> {
    let img = image::RgbaImage::from_fn(w, h, |x, y| image::Rgba(f(x, y)));
    let mut bytes = Vec::new();
    img.write_to(&mut std::io::Cursor::new(&mut bytes), image::ImageFormat::Png).unwrap();
    bytes
}

#[test]
fn gltf_materials_keep_sampler_alpha_sides_texcoord_set_and_texture_transform() {
    use twister::core::material::{AlphaMode, Filter, Mipmap, Wrap};
    let dir = tmp("material");
    let uv0: [[f32; 2]; 4] = [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0], [1.0, 1.0]];
    let uv1: [[f32; 2]; 4] = [[0.1, 0.2], [0.3, 0.4], [0.5, 0.6], [0.7, 0.8]];
    let mut json = gltf_json(&QUAD, Some(&[0, 1, 2, 2, 1, 3]), 4);
    // Append both UV sets to the buffer.
    let mut bytes: Vec<u8> = QUAD.iter().flatten().flat_map(|f| f.to_le_bytes()).collect();
    bytes.extend([0u32, 1, 2, 2, 1, 3].iter().flat_map(|i| i.to_le_bytes()));
    let at = bytes.len();
    bytes.extend(uv0.iter().chain(&uv1).flatten().flat_map(|f| f.to_le_bytes()));
    json["buffers"][0] = serde_json::json!({
        "byteLength": bytes.len(),
        "uri": format!("data:application/octet-stream;base64,{}", common::base64(&bytes))
    });
    let views = json["bufferViews"].as_array_mut().unwrap();
    views.push(serde_json::json!({ "buffer": 0, "byteOffset": at, "byteLength": 32 }));
    views.push(serde_json::json!({ "buffer": 0, "byteOffset": at + 32, "byteLength": 32 }));
    let accessors = json["accessors"].as_array_mut().unwrap();
    for view in [2, 3] {
        accessors.push(serde_json::json!({ "bufferView": view, "componentType": 5126, "count": 4, "type": "VEC2" }));
    }
    json["meshes"][0]["primitives"][0]["attributes"]["TEXCOORD_0"] = serde_json::json!(2);
    json["meshes"][0]["primitives"][0]["attributes"]["TEXCOORD_1"] = serde_json::json!(3);
    json["meshes"][0]["primitives"][0]["material"] = serde_json::json!(0);
    let png = png_bytes(4, 2, |x, y| [60 * x as u8, 100 * y as u8, 7, 255]);
    json["images"] = serde_json::json!([{ "uri": format!("data:image/png;base64,{}", common::base64(&png)) }]);
    // MIRRORED_REPEAT / CLAMP_TO_EDGE, NEAREST magnification, NEAREST_MIPMAP_NEAREST.
    json["samplers"] = serde_json::json!([{ "wrapS": 33648, "wrapT": 33071, "magFilter": 9728, "minFilter": 9984 }]);
    json["textures"] = serde_json::json!([{ "source": 0, "sampler": 0 }]);
    let (offset, rotation, scale) = ([0.5f32, 0.25f32], std::f32::consts::FRAC_PI_2, [2.0f32, 3.0f32]);
    json["materials"] = serde_json::json!([{
        "pbrMetallicRoughness": {
            "baseColorFactor": [1.0, 0.5, 1.0, 1.0],
            "baseColorTexture": { "index": 0, "texCoord": 0, "extensions": { "KHR_texture_transform": {
                "offset": offset, "rotation": rotation, "scale": scale, "texCoord": 1
            } } }
        },
        "alphaMode": "MASK", "alphaCutoff": 0.3, "doubleSided": true
    }]);
    json["extensionsUsed"] = serde_json::json!(["KHR_texture_transform", "EXT_made_up"]);
    json["extensionsRequired"] = serde_json::json!(["KHR_texture_transform"]);
    let path = write(&dir, "material.gltf", &json);
    let s = load_scene(path.to_str().unwrap(), &Projection::default()).unwrap();
    assert_eq!(s.textures.len(), 1);
    assert_eq!((s.textures[0].width, s.textures[0].height), (4, 2));
    assert_eq!(&s.textures[0].rgba[4 * 5..4 * 6], &[60, 100, 7, 255], "texel (1, 1)");
    let m = s.materials[0];
    assert_eq!((m.texture, m.wrap_u, m.wrap_v), (0, Wrap::MirroredRepeat as u32, Wrap::ClampToEdge as u32));
    assert_eq!(
        (m.mag_filter, m.min_filter, m.mipmap),
        (Filter::Nearest as u32, Filter::Nearest as u32, Mipmap::Nearest as u32)
    );
    assert_eq!((m.alpha_mode, m.alpha_cutoff, m.double_sided), (AlphaMode::Mask as u32, 0.3, 1));
    // The transform's texCoord picks TEXCOORD_1; uv' = offset + R·(scale·uv) with
    // R = [[cos, sin], [−sin, cos]] (the extension's rotation).
    let (sin, cos) = rotation.sin_cos();
    for (v, t) in s.vertices.iter().zip(uv1) {
        let (u, w) = (scale[0] * t[0], scale[1] * t[1]);
        let want = [offset[0] + cos * u + sin * w, offset[1] - sin * u + cos * w];
        assert!((v.uv[0] - want[0]).abs() < 1e-5 && (v.uv[1] - want[1]).abs() < 1e-5, "{:?} vs {want:?}", v.uv);
        assert_eq!(v.material, 1);
        assert_eq!(v.color, [1.0, 0.5, 1.0, 1.0], "base colour factor × vertex colour");
    }
    let ignored: Vec<&String> = s.warnings.iter().filter(|w| w.contains("ignored")).collect();
    assert!(
        ignored.len() == 1 && ignored[0].contains("EXT_made_up") && !ignored[0].contains("KHR_texture_transform"),
        "{:?}",
        s.warnings
    );
    // A primitive without a material gets the spec's default one: single-sided.
    json["meshes"][0]["primitives"][0].as_object_mut().unwrap().remove("material");
    let s = load_scene(write(&dir, "default.gltf", &json).to_str().unwrap(), &Projection::default()).unwrap();
    let k = s.vertices[0].material as usize - 1;
    assert_eq!((s.materials[k].double_sided, s.materials[k].texture), (0, twister::core::material::NO_TEXTURE));
}

#[test]
fn obj_map_kd_is_relative_to_the_mtl_file_and_a_missing_texture_is_a_warning() {
    let dir = tmp("mapkd");
    std::fs::create_dir_all(dir.join("mats/tex")).unwrap();
    std::fs::write(dir.join("mats/tex/quadrants.png"), png_bytes(2, 2, |x, y| [200 * x as u8, 200 * y as u8, 9, 255]))
        .unwrap();
    // Windows-style path as exporters on Windows write it; a texture that does not exist.
    let mtl =
        "newmtl painted\nKd 1 1 1\nmap_Kd .\\tex\\quadrants.png\nnewmtl lost\nKd 0 1 0\nmap_Kd -s 1 1 1 missing.png\n";
    std::fs::write(dir.join("mats/scene.mtl"), mtl).unwrap();
    let obj = "mtllib mats/scene.mtl\nv 0 0 -3\nv 1 0 -3\nv 0 1 -3\nv 1 1 -3\nvt 0 0\nvt 1 0\nvt 0 1\nvt 1 1\n\
               usemtl painted\nf 1/1 2/2 3/3\nusemtl lost\nf 2/2 4/4 3/3\n";
    std::fs::write(dir.join("scene.obj"), obj).unwrap();
    let s = load_scene(dir.join("scene.obj").to_str().unwrap(), &Projection::default()).unwrap();
    assert_eq!(s.textures.len(), 1, "{:?}", s.warnings);
    assert_eq!(&s.textures[0].rgba[12..16], &[200, 200, 9, 255], "texel (1, 1) of the PNG");
    assert_eq!(s.materials[0].texture, 0);
    assert_eq!(s.materials[1].texture, twister::core::material::NO_TEXTURE);
    assert!(s.warnings.iter().any(|w| w.contains("lost") && w.contains("missing.png")), "{:?}", s.warnings);
    // OBJ's v runs up from the bottom row; texture space runs down from the top row.
    let top_left = s.vertices.iter().find(|v| v.position == [0.0, 1.0, -3.0]).unwrap();
    assert_eq!(top_left.uv, [0.0, 0.0]);
    let bottom_right = s.vertices.iter().find(|v| v.position == [1.0, 0.0, -3.0]).unwrap();
    assert_eq!(bottom_right.uv, [1.0, 1.0]);
}

#[test]
fn a_mesh_instance_is_one_object_whatever_its_primitive_count() {
    // One mesh of two primitives drawn by two nodes: two objects (mesh instances), four primitives.
    let mut json = gltf_json(&QUAD, Some(&[0, 1, 2, 2, 1, 3]), 4);
    let prim = json["meshes"][0]["primitives"][0].clone();
    json["meshes"][0]["primitives"] = serde_json::json!([prim.clone(), prim]);
    json["nodes"] =
        serde_json::json!([{ "children": [1, 2] }, { "mesh": 0 }, { "mesh": 0, "translation": [5.0, 0.0, 0.0] }]);
    let s = load_scene(write(&tmp("instances"), "i.gltf", &json).to_str().unwrap(), &Projection::default()).unwrap();
    assert_eq!((s.objects.len(), s.meshes, s.primitives, s.triangle_count()), (2, 2, 4, 8));
    for (k, o) in s.objects.iter().enumerate() {
        assert_eq!(o.triangle_count, 4);
        for t in o.first_triangle..o.first_triangle + o.triangle_count {
            for c in 0..3 {
                assert_eq!(s.vertices[s.indices[3 * t as usize + c] as usize].object, k as u32, "{}", o.name);
            }
        }
    }
}

/// The column span (first, last) of non-background pixels in a row band of a rendered PNG.
fn drawn_columns(png: &Path) -> (u32, u32, u32) {
    let img = image::open(png).unwrap().to_rgba8();
    let bg = *img.get_pixel(0, 0);
    let xs: Vec<u32> = img.enumerate_pixels().filter(|(_, _, p)| **p != bg).map(|(x, _, _)| x).collect();
    assert!(!xs.is_empty(), "{}: nothing drawn", png.display());
    (*xs.iter().min().unwrap(), *xs.iter().max().unwrap(), img.width())
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

#[test]
fn optics_are_read_from_gltf_and_mtl_for_the_ray_tracer() {
    // glTF: a smooth metal is a mirror; a rough one and a plain dielectric are not; transmission
    // and ior come from their extensions (ior 1.5 when absent).
    let dir = tmp("optics");
    let mut json = gltf_json(&QUAD[..3], None, 4);
    json["materials"] = serde_json::json!([
        { "pbrMetallicRoughness": { "metallicFactor": 1.0, "roughnessFactor": 0.0 } },
        { "pbrMetallicRoughness": { "metallicFactor": 1.0, "roughnessFactor": 0.4 } },
        { "extensions": { "KHR_materials_transmission": { "transmissionFactor": 0.8 }, "KHR_materials_ior": { "ior": 1.33 } } },
        { "extensions": { "KHR_materials_transmission": { "transmissionFactor": 1.0 } } }
    ]);
    json["extensionsUsed"] = serde_json::json!(["KHR_materials_transmission", "KHR_materials_ior"]);
    json["meshes"][0]["primitives"][0]["material"] = serde_json::json!(0);
    let path = write(&dir, "optics.gltf", &json);
    let scene = load_scene(path.to_str().unwrap(), &Projection::default()).unwrap();
    let m = &scene.materials;
    assert_eq!(m.len(), 4, "{m:?}");
    assert_eq!((m[0].mirror, m[1].mirror, m[2].mirror), (1.0, 0.0, 0.0));
    assert_eq!((m[2].transmission, m[2].ior), (0.8, 1.33));
    assert_eq!((m[3].transmission, m[3].ior, m[0].transmission), (1.0, 1.5, 0.0));
    // MTL: illum 3 mirrors Ks; illum 7 also transmits 1 − d with index Ni; illum 6 reads Tr;
    // illum 2 has no optics.
    std::fs::write(
        dir.join("optics.mtl"),
        "newmtl chrome\nillum 3\nKs 0.8 0.9 0.7\nnewmtl glass\nillum 7\nKs 0.1 0.1 0.1\nd 0.3\nNi 1.33\n\
         newmtl tinted\nillum 6\nTr 0.6\nnewmtl matte\nillum 2\nKs 1 1 1\nNs 98\nKe 0.5 0.25 0\n\
         newmtl pbr\nPr 0.3\nPm 0.9\nNs 10\n",
    )
    .unwrap();
    std::fs::write(
        dir.join("optics.obj"),
        "mtllib optics.mtl\nv 0 0 -3\nv 1 0 -3\nv 0 1 -3\nusemtl chrome\nf 1 2 3\nusemtl glass\nf 1 2 3\n\
         usemtl tinted\nf 1 2 3\nusemtl matte\nf 1 2 3\nusemtl pbr\nf 1 2 3\n",
    )
    .unwrap();
    let scene = load_scene(dir.join("optics.obj").to_str().unwrap(), &Projection::default()).unwrap();
    let m = &scene.materials;
    assert_eq!(m.len(), 5, "{m:?}");
    // The glTF BRDF's parameters: Ns 98 → roughness (2/100)^¼; Ke emits; Pr/Pm win over Ns.
    assert!((m[3].roughness - 0.02f32.powf(0.25)).abs() < 1e-5 && m[3].metallic == 0.0, "{:?}", m[3]);
    assert_eq!((m[3].emissive_r, m[3].emissive_g, m[3].emissive_b), (0.5, 0.25, 0.0));
    assert_eq!((m[4].roughness, m[4].metallic), (0.3, 0.9));
    assert_eq!((m[0].roughness, m[0].emissive_r), (1.0, 0.0));
    assert_eq!((m[0].mirror, m[0].transmission), (0.9, 0.0));
    assert!(
        (m[1].mirror - 0.1).abs() < 1e-6 && (m[1].transmission - 0.7).abs() < 1e-6 && m[1].ior == 1.33,
        "{:?}",
        m[1]
    );
    assert!((m[2].transmission - 0.6).abs() < 1e-6 && m[2].ior == 1.5, "{:?}", m[2]);
    assert_eq!((m[3].mirror, m[3].transmission), (0.0, 0.0));
    let _ = std::fs::remove_dir_all(&dir);
}
