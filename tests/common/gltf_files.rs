//! glTF files written by the tests: one primitive with an embedded buffer, good or broken.

use std::path::{Path, PathBuf};

/// A one-primitive glTF with an embedded buffer: positions, optional u32 indices, a mode.
pub fn gltf_json(positions: &[[f32; 3]], indices: Option<&[u32]>, mode: u32) -> serde_json::Value {
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
        "buffers": [{ "byteLength": bytes.len(), "uri": format!("data:application/octet-stream;base64,{}", super::base64(&bytes)) }]
    })
}

pub fn write(dir: &Path, name: &str, json: &serde_json::Value) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, serde_json::to_string(json).unwrap()).unwrap();
    p
}

pub const QUAD: [[f32; 3]; 4] = [[0.0, 0.0, -3.0], [1.0, 0.0, -3.0], [0.0, 1.0, -3.0], [1.0, 1.0, -3.0]];
