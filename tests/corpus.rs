//! Hostile input: a corpus of malformed and degenerate scene files, generated here from valid
//! ones (truncations at many offsets, bit flips, wrong counts, offsets and strides, hierarchy
//! cycles, huge counts), read in-process. Every file must give either a scene or one error
//! that names the file; never a panic; memory stays bounded. A bounded property test adds
//! random mutations from a fixed seed.

mod common;

use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::{Path, PathBuf};

use rand::{Rng, SeedableRng};
use serde_json::json;
use twister::core::scenes::load::load_scene;
use twister::{GpuScene, Projection, RenderSettings};

fn dir(name: &str) -> common::TempDir {
    let d = common::TempDir::new(format!("twister-corpus-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&*d).unwrap();
    d
}

/// A valid two-triangle glTF document (positions, normals, indices) and its binary buffer.
fn valid_gltf() -> (serde_json::Value, Vec<u8>) {
    let positions: [[f32; 3]; 4] = [[0.0, 0.0, -3.0], [1.0, 0.0, -3.0], [0.0, 1.0, -3.0], [1.0, 1.0, -3.0]];
    let mut bin: Vec<u8> = positions.iter().flatten().flat_map(|f| f.to_le_bytes()).collect();
    bin.extend([0u16, 1, 2, 2, 1, 3].iter().flat_map(|i| i.to_le_bytes()));
    let doc = json!({
        "asset": { "version": "2.0" },
        "scene": 0,
        "scenes": [{ "nodes": [0] }],
        "nodes": [{ "children": [1] }, { "mesh": 0, "translation": [0.0, 0.0, -1.0] }],
        "meshes": [{ "primitives": [{ "attributes": { "POSITION": 0 }, "indices": 1 }] }],
        "accessors": [
            { "bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [0, 0, -3], "max": [1, 1, -3] },
            { "bufferView": 1, "componentType": 5123, "count": 6, "type": "SCALAR" }
        ],
        "bufferViews": [{ "buffer": 0, "byteOffset": 0, "byteLength": 48 }, { "buffer": 0, "byteOffset": 48, "byteLength": 12 }],
        "buffers": [{ "byteLength": bin.len() }]
    });
    (doc, bin)
}

fn gltf_text(doc: &serde_json::Value, bin: &[u8]) -> Vec<u8> {
    let mut d = doc.clone();
    d["buffers"][0]["uri"] = json!(format!("data:application/octet-stream;base64,{}", common::base64(bin)));
    serde_json::to_vec(&d).unwrap()
}

fn glb(doc: &serde_json::Value, bin: &[u8]) -> Vec<u8> {
    let mut json = serde_json::to_vec(doc).unwrap();
    while json.len() % 4 != 0 {
        json.push(b' ');
    }
    let mut bin = bin.to_vec();
    while bin.len() % 4 != 0 {
        bin.push(0);
    }
    let total = 12 + 8 + json.len() + 8 + bin.len();
    let mut out = b"glTF".to_vec();
    out.extend(2u32.to_le_bytes());
    out.extend((total as u32).to_le_bytes());
    out.extend((json.len() as u32).to_le_bytes());
    out.extend(b"JSON");
    out.extend(json);
    out.extend((bin.len() as u32).to_le_bytes());
    out.extend(b"BIN\0".iter().copied());
    out.extend(bin);
    out
}

const OBJ: &str = "mtllib m.mtl\no quad\nv 0 0 -3\nv 1 0 -3\nv 0 1 -3\nv 1 1 -3\nvt 0 0\nvt 1 0\nvt 0 1\nvn 0 0 1\nusemtl red\nf 1/1/1 2/2/1 3/3/1\nf 3/3/1 2/2/1 4/1/1\n";
const MTL: &str = "newmtl red\nKd 0.8 0.1 0.1\n";

/// The malformed and degenerate files: (name, bytes).
fn corpus() -> Vec<(String, Vec<u8>)> {
    let (doc, bin) = valid_gltf();
    let mut files: Vec<(String, Vec<u8>)> = Vec::new();
    let text = gltf_text(&doc, &bin);
    let binary = glb(&doc, &bin);
    files.push(("valid.gltf".into(), text.clone()));
    files.push(("valid.glb".into(), binary.clone()));
    files.push(("valid.obj".into(), OBJ.as_bytes().to_vec()));
    // Truncations at many offsets.
    for (name, bytes) in [("gltf", &text), ("glb", &binary)] {
        for k in (0..bytes.len()).step_by((bytes.len() / 40).max(1)) {
            files.push((format!("trunc{k}.{name}"), bytes[..k].to_vec()));
        }
    }
    for k in (0..OBJ.len()).step_by(7) {
        files.push((format!("trunc{k}.obj"), OBJ.as_bytes()[..k].to_vec()));
    }
    // Bit flips.
    for (name, bytes) in [("gltf", &text), ("glb", &binary), ("obj", &OBJ.as_bytes().to_vec())] {
        for k in (0..bytes.len()).step_by((bytes.len() / 30).max(1)) {
            let mut b = bytes.clone();
            b[k] ^= 1 << (k % 8);
            files.push((format!("flip{k}.{name}"), b));
        }
    }
    for (name, pointer, value) in gltf_edits() {
        let mut d = doc.clone();
        match d.pointer_mut(pointer) {
            Some(slot) => *slot = value,
            None => {
                let (parent, key) = pointer.rsplit_once('/').unwrap();
                d.pointer_mut(parent).unwrap()[key] = value;
            }
        }
        files.push((format!("{name}.gltf"), gltf_text(&d, &bin)));
        files.push((format!("{name}.glb"), glb(&d, &bin)));
    }
    // A deep chain of nodes, and one that shares children (the exponential instance bomb).
    let mut deep = doc.clone();
    deep["nodes"] = json!((0..300)
        .map(|k| if k < 299 { json!({ "children": [k + 1] }) } else { json!({ "mesh": 0 }) })
        .collect::<Vec<_>>());
    files.push(("deep.gltf".into(), gltf_text(&deep, &bin)));
    let mut bomb = doc.clone();
    bomb["nodes"] = json!((0..25)
        .map(|k| if k < 24 { json!({ "children": [k + 1, k + 1] }) } else { json!({ "mesh": 0 }) })
        .collect::<Vec<_>>());
    files.push(("bomb.gltf".into(), gltf_text(&bomb, &bin)));
    // Bad base64, bad GLB header fields.
    files.push((
        "base64.gltf".into(),
        String::from_utf8(text.clone()).unwrap().replace("base64,AAAA", "base64,A!AA").into_bytes(),
    ));
    let mut g = binary.clone();
    g[8..12].copy_from_slice(&u32::MAX.to_le_bytes());
    files.push(("length_max.glb".into(), g));
    let mut g = binary.clone();
    g[12..16].copy_from_slice(&u32::MAX.to_le_bytes());
    files.push(("chunk_max.glb".into(), g));
    let mut g = binary.clone();
    g[0] = b'x';
    files.push(("magic.glb".into(), g));
    files.extend(obj_faults());
    files
}

/// The glTF corpus's edits of the valid file: wrong counts, offsets, strides, types, indices,
/// hierarchies, numbers (a JSON pointer and the value put there).
fn gltf_edits() -> Vec<(&'static str, &'static str, serde_json::Value)> {
    vec![
        ("count_huge", "/accessors/0/count", json!(4_000_000_000u64)),
        ("count_zero", "/accessors/0/count", json!(0)),
        ("count_over", "/accessors/1/count", json!(600)),
        ("offset_huge", "/accessors/0/byteOffset", json!(18_446_744_073_709_551_000u64)),
        ("view_offset_huge", "/bufferViews/0/byteOffset", json!(18_446_744_073_709_551_000u64)),
        ("view_offset_neg", "/bufferViews/0/byteOffset", json!(-8)),
        ("stride_4", "/bufferViews/0/byteStride", json!(4)),
        ("stride_odd", "/bufferViews/0/byteStride", json!(13)),
        ("stride_huge", "/bufferViews/0/byteStride", json!(4096)),
        ("type_scalar", "/accessors/0/type", json!("SCALAR")),
        ("type_bad", "/accessors/0/type", json!("VEC7")),
        ("ct_byte", "/accessors/0/componentType", json!(5121)),
        ("ct_bad", "/accessors/0/componentType", json!(1)),
        ("index_float", "/accessors/1/componentType", json!(5126)),
        ("pos_99", "/meshes/0/primitives/0/attributes/POSITION", json!(99)),
        ("indices_99", "/meshes/0/primitives/0/indices", json!(99)),
        ("mesh_9", "/nodes/1/mesh", json!(9)),
        ("child_9", "/nodes/0/children", json!([9])),
        ("child_self", "/nodes/0/children", json!([0])),
        ("children_twice", "/nodes/0/children", json!([1, 1])),
        ("scene_9", "/scene", json!(9)),
        ("root_9", "/scenes/0/nodes", json!([9])),
        ("version_1", "/asset/version", json!("1.0")),
        ("version_3", "/asset/version", json!("3.0")),
        ("no_asset", "/asset", json!(null)),
        ("translation_nan", "/nodes/1/translation", json!([0.0, "NaN", 0.0])),
        ("translation_huge", "/nodes/1/translation", json!([1e30, 0.0, 0.0])),
        ("scale_huge", "/nodes/1/scale", json!([1e30, 1e30, 1e30])),
        ("matrix_short", "/nodes/1/matrix", json!([1, 0, 0])),
        ("buffer_short", "/buffers/0/byteLength", json!(10)),
        ("buffer_long", "/buffers/0/byteLength", json!(1_000_000)),
        ("view_buffer_9", "/bufferViews/0/buffer", json!(9)),
        ("mode_points", "/meshes/0/primitives/0/mode", json!(0)),
        ("mode_bad", "/meshes/0/primitives/0/mode", json!(99)),
        ("material_9", "/meshes/0/primitives/0/material", json!(9)),
        // Sparse accessors: a valid one is below; beyond the accessor, float indices, too many.
        (
            "sparse_beyond",
            "/accessors/0/sparse",
            json!({ "count": 1, "indices": { "bufferView": 1, "componentType": 5125, "byteOffset": 2 }, "values": { "bufferView": 0 } }),
        ),
        (
            "sparse_float",
            "/accessors/0/sparse",
            json!({ "count": 1, "indices": { "bufferView": 1, "componentType": 5126 }, "values": { "bufferView": 0 } }),
        ),
        (
            "sparse_count",
            "/accessors/0/sparse",
            json!({ "count": 9, "indices": { "bufferView": 1, "componentType": 5123 }, "values": { "bufferView": 0 } }),
        ),
        (
            "sparse_overrun",
            "/accessors/0/sparse",
            json!({ "count": 4, "indices": { "bufferView": 1, "componentType": 5125 }, "values": { "bufferView": 0 } }),
        ),
        (
            "sparse_no_values",
            "/accessors/0/sparse",
            json!({ "count": 1, "indices": { "bufferView": 1, "componentType": 5123 } }),
        ),
        (
            "sparse_ok",
            "/accessors/0/sparse",
            json!({ "count": 1, "indices": { "bufferView": 1, "componentType": 5123 }, "values": { "bufferView": 0, "byteOffset": 12 } }),
        ),
    ]
}

/// The OBJ corpus's faults: short faces, indices out of range, non-finite numbers, empty and
/// binary files.
fn obj_faults() -> Vec<(String, Vec<u8>)> {
    let mut files = Vec::new();
    for (name, text) in [
        ("face1.obj", "v 0 0 -3\nf 1\n".to_string()),
        ("face2.obj", "v 0 0 -3\nv 1 0 -3\nf 1 2\n".to_string()),
        ("face_big.obj", "v 0 0 -3\nv 1 0 -3\nv 0 1 -3\nf 1 2 99999999999999999999\n".to_string()),
        ("face_zero.obj", "v 0 0 -3\nv 1 0 -3\nv 0 1 -3\nf 0 1 2\n".to_string()),
        ("nan.obj", "v 0 NaN -3\nv 1 0 -3\nv 0 1 -3\nf 1 2 3\n".to_string()),
        ("huge.obj", "v 0 1e38 -3\nv 1 0 -3\nv 0 1 -3\nf 1 2 3\n".to_string()),
        ("inf.obj", "v 0 inf -3\nv 1 0 -3\nv 0 1 -3\nf 1 2 3\n".to_string()),
        ("degenerate.obj", "v 0 0 -3\nv 0 0 -3\nv 0 0 -3\nf 1 2 3\n".to_string()),
        ("empty.obj", String::new()),
        ("binary.obj", String::from_utf8_lossy(&[0u8, 159, 146, 150, 255, 10, 118, 32]).into_owned()),
    ] {
        files.push((name.into(), text.into_bytes()));
    }
    files
}

/// Loads a file in-process: Ok(triangles) or Err(message); a panic fails the test.
fn load(path: &Path) -> Result<usize, String> {
    let spec = path.to_str().unwrap().to_string();
    match catch_unwind(AssertUnwindSafe(|| load_scene(&spec, &Projection::default()))) {
        Ok(Ok(scene)) => Ok(scene.triangle_count()),
        Ok(Err(e)) => Err(e.to_string()),
        Err(_) => panic!("{}: the loader panicked", path.display()),
    }
}

/// Peak resident memory of this process, MiB (Linux; 0 elsewhere).
fn peak_rss_mib() -> u64 {
    std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("VmHWM:"))
                .map(|l| l.split_whitespace().nth(1).unwrap().parse::<u64>().unwrap())
        })
        .map_or(0, |kb| kb >> 10)
}

fn check_file(path: &Path, loaded: &mut Vec<PathBuf>) {
    match load(path) {
        Ok(n) => {
            assert!(n > 0, "{}: loaded with no triangles", path.display());
            loaded.push(path.to_path_buf());
        }
        Err(e) => {
            if std::env::var("CORPUS_PRINT").is_ok() {
                eprintln!("CORPUS {e}");
            }
            assert!(e.contains(path.to_str().unwrap()), "{}: the error does not name the file: {e}", path.display());
            assert!(!e.contains('\n'), "{}: not one line: {e}", path.display());
        }
    }
}

#[test]
fn malformed_files_are_one_clear_error_or_a_scene_never_a_panic() {
    let d = dir("files");
    std::fs::write(d.join("m.mtl"), MTL).unwrap();
    let mut loaded = Vec::new();
    let files = corpus();
    for (name, bytes) in &files {
        let path = d.join(name);
        std::fs::write(&path, bytes).unwrap();
        check_file(&path, &mut loaded);
    }
    // The valid files load; the corpus is mostly refused.
    for valid in ["valid.gltf", "valid.glb", "valid.obj", "sparse_ok.gltf", "sparse_ok.glb"] {
        assert!(loaded.contains(&d.join(valid)), "{valid} did not load");
    }
    assert!(loaded.len() * 3 < files.len(), "{} of {} malformed files loaded", loaded.len(), files.len());
    // Whatever loaded renders (and measures) without a panic: a scene or one error.
    let r = common::renderer();
    let p = Projection { width: 64, height: 16, ..Projection::default() };
    for path in &loaded {
        let scene = load_scene(path.to_str().unwrap(), &p).unwrap();
        match GpuScene::upload(&r.gpu, &scene) {
            Ok(gs) => {
                for s in [RenderSettings::new(p), RenderSettings::new(p).with_measure_error(true)] {
                    let _ = r.render(&gs, &s).map_err(|e| assert!(!e.to_string().contains('\n'), "{e}"));
                }
            }
            Err(e) => assert!(e.to_string().contains(path.to_str().unwrap()), "{e}"),
        }
    }
    assert!(peak_rss_mib() < 4096, "peak memory {} MiB", peak_rss_mib());
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn random_mutations_of_valid_files_never_panic() {
    // A bounded property test (fixed seed, 400 cases): byte flips, deletions, insertions and
    // duplicated runs anywhere in a valid glTF, GLB or OBJ file.
    let d = dir("mutations");
    std::fs::write(d.join("m.mtl"), MTL).unwrap();
    let (doc, bin) = valid_gltf();
    let seeds = [("gltf", gltf_text(&doc, &bin)), ("glb", glb(&doc, &bin)), ("obj", OBJ.as_bytes().to_vec())];
    let mut rng = rand::rngs::StdRng::seed_from_u64(2026);
    let mut loaded = Vec::new();
    for case in 0..400 {
        let (ext, seed) = &seeds[case % seeds.len()];
        let mut b = seed.clone();
        for _ in 0..rng.random_range(1..6) {
            let at = rng.random_range(0..b.len().max(1));
            match rng.random_range(0..4) {
                0 if !b.is_empty() => b[at] = rng.random(),
                1 if !b.is_empty() => {
                    b.remove(at);
                }
                2 => b.insert(at.min(b.len()), rng.random()),
                _ => {
                    let end = (at + rng.random_range(1..16)).min(b.len());
                    let run = b[at.min(end)..end].to_vec();
                    b.splice(at.min(b.len())..at.min(b.len()), run);
                }
            }
        }
        let path = d.join(format!("m{case}.{ext}"));
        std::fs::write(&path, &b).unwrap();
        check_file(&path, &mut loaded);
    }
    assert!(peak_rss_mib() < 4096, "peak memory {} MiB", peak_rss_mib());
    let _ = std::fs::remove_dir_all(&d);
}
