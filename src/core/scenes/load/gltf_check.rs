//! Checks of a glTF document's JSON before the gltf crate reads it (the crate panics on some
//! invalid files, e.g. an attribute naming an accessor that does not exist, or a stride shorter
//! than its element): every index in range, the version, a node hierarchy that is a forest, and
//! accessor types, component types and strides that fit their use. Each problem is one message
//! naming where in the file it is.

use serde_json::Value;

/// The length of a top-level array (0 when absent).
fn len(root: &Value, array: &str) -> usize {
    root.get(array).and_then(Value::as_array).map_or(0, Vec::len)
}

/// Checks `value` (at `at`) as an index into the top-level `array`.
fn index(root: &Value, value: &Value, at: &str, array: &str) -> Result<usize, String> {
    let n = len(root, array);
    match value.as_u64() {
        Some(i) if (i as usize) < n => Ok(i as usize),
        Some(i) => Err(format!("{at} names {array}[{i}], but the file has {n} {array}")),
        None => Err(format!("{at} is not an index: {value}")),
    }
}

/// Every element of a top-level array, with its path.
fn items<'a>(root: &'a Value, array: &'a str) -> impl Iterator<Item = (String, &'a Value)> + 'a {
    root.get(array)
        .and_then(Value::as_array)
        .into_iter()
        .flatten()
        .enumerate()
        .map(move |(i, v)| (format!("{array}[{i}]"), v))
}

/// Checks an optional index field of an object.
fn field(root: &Value, obj: &Value, at: &str, key: &str, array: &str) -> Result<Option<usize>, String> {
    match obj.get(key) {
        None => Ok(None),
        Some(v) => index(root, v, &format!("{at}.{key}"), array).map(Some),
    }
}

/// Components per element of an accessor type.
fn components(ty: &str) -> Option<usize> {
    Some(match ty {
        "SCALAR" => 1,
        "VEC2" => 2,
        "VEC3" => 3,
        "VEC4" | "MAT2" => 4,
        "MAT3" => 9,
        "MAT4" => 16,
        _ => return None,
    })
}

/// Bytes per component of a component type.
fn component_bytes(ct: u64) -> Option<usize> {
    Some(match ct {
        5120 | 5121 => 1,
        5122 | 5123 => 2,
        5125 | 5126 => 4,
        _ => return None,
    })
}

const FLOAT: u64 = 5126;

/// What a mesh attribute may be: (allowed types, allowed component types; normalized integer
/// types are allowed where listed).
fn attribute_rule(semantic: &str) -> Option<(&'static [&'static str], &'static [u64])> {
    let base = semantic.split('_').next().unwrap_or(semantic);
    Some(match base {
        "POSITION" | "NORMAL" => (&["VEC3"], &[FLOAT]),
        "TANGENT" => (&["VEC4"], &[FLOAT]),
        "TEXCOORD" => (&["VEC2"], &[FLOAT, 5121, 5123]),
        "COLOR" => (&["VEC3", "VEC4"], &[FLOAT, 5121, 5123]),
        "JOINTS" => (&["VEC4"], &[5121, 5123]),
        "WEIGHTS" => (&["VEC4"], &[FLOAT, 5121, 5123]),
        _ => return None,
    })
}

/// Checks an accessor used as `what` against allowed types and component types.
fn accessor_use(root: &Value, k: usize, what: &str, types: &[&str], cts: &[u64]) -> Result<(), String> {
    let acc = &root["accessors"][k];
    let ty = acc.get("type").and_then(Value::as_str).unwrap_or("");
    let ct = acc.get("componentType").and_then(Value::as_u64).unwrap_or(0);
    if !types.contains(&ty) || !cts.contains(&ct) {
        return Err(format!(
            "{what} uses accessors[{k}] of type {ty} / componentType {ct}; it must be {} with componentType {}",
            types.join(" or "),
            cts.iter().map(u64::to_string).collect::<Vec<_>>().join(" or ")
        ));
    }
    Ok(())
}

/// All the checks; the first problem found.
pub fn check(root: &Value) -> Result<(), String> {
    check_asset_and_scenes(root)?;
    check_buffers_and_accessors(root)?;
    check_textures_and_materials(root)?;
    check_meshes(root)?;
    check_nodes(root)?;
    check_skins_and_animations(root)
}

/// The document is glTF 2.x; the scene indices.
fn check_asset_and_scenes(root: &Value) -> Result<(), String> {
    if !root.is_object() {
        return Err("not a glTF document (the JSON is not an object)".into());
    }
    let version = root.pointer("/asset/version").and_then(Value::as_str).ok_or("asset.version is missing")?;
    if version.split('.').next() != Some("2") {
        return Err(format!("asset.version is \"{version}\": twister reads glTF 2.x"));
    }
    if let Some(s) = root.get("scene") {
        index(root, s, "scene", "scenes")?;
    }
    for (at, scene) in items(root, "scenes") {
        for (k, n) in scene.get("nodes").and_then(Value::as_array).into_iter().flatten().enumerate() {
            index(root, n, &format!("{at}.nodes[{k}]"), "nodes")?;
        }
    }
    Ok(())
}

/// Buffer views within their buffers; accessors' types, counts, strides and sparse parts.
fn check_buffers_and_accessors(root: &Value) -> Result<(), String> {
    for (at, view) in items(root, "bufferViews") {
        let b = field(root, view, &at, "buffer", "buffers")?.ok_or(format!("{at} has no buffer"))?;
        let start = view.get("byteOffset").and_then(Value::as_u64).unwrap_or(0);
        let length = view.get("byteLength").and_then(Value::as_u64).ok_or(format!("{at}.byteLength is missing"))?;
        let buffer_length = root["buffers"][b].get("byteLength").and_then(Value::as_u64).unwrap_or(0);
        if start.checked_add(length).is_none_or(|end| end > buffer_length) {
            return Err(format!(
                "{at} (byteOffset {start}, byteLength {length}) overruns buffers[{b}] (byteLength {buffer_length})"
            ));
        }
        if let Some(stride) = view.get("byteStride").and_then(Value::as_u64) {
            if !(4..=252).contains(&stride) || stride % 4 != 0 {
                return Err(format!("{at}.byteStride is {stride}: it must be a multiple of 4 in 4..=252"));
            }
        }
    }
    for (at, acc) in items(root, "accessors") {
        let ty = acc.get("type").and_then(Value::as_str).unwrap_or("");
        let n = components(ty).ok_or(format!("{at}.type \"{ty}\" is not a glTF accessor type"))?;
        let ct = acc.get("componentType").and_then(Value::as_u64).unwrap_or(0);
        let bytes = component_bytes(ct).ok_or(format!("{at}.componentType {ct} is not a glTF component type"))?;
        match acc.get("count").and_then(Value::as_u64) {
            Some(c) if c >= 1 => {}
            _ => {
                return Err(format!("{at}.count must be at least 1, got {}", acc.get("count").unwrap_or(&Value::Null)))
            }
        }
        if let Some(v) = field(root, acc, &at, "bufferView", "bufferViews")? {
            if let Some(stride) = root["bufferViews"][v].get("byteStride").and_then(Value::as_u64) {
                if (stride as usize) < n * bytes {
                    return Err(format!(
                        "{at} ({ty} of {bytes}-byte components, {} bytes) lies in bufferViews[{v}] whose byteStride is only {stride}",
                        n * bytes
                    ));
                }
            }
        }
        if let Some(sparse) = acc.get("sparse") {
            let count = acc.get("count").and_then(Value::as_u64).unwrap_or(0);
            match sparse.get("count").and_then(Value::as_u64) {
                Some(c) if c >= 1 && c <= count => {}
                other => {
                    let got = other.map_or("none".to_string(), |c| c.to_string());
                    return Err(format!("{at}.sparse.count must be 1..={count}, got {got}"));
                }
            }
            for part in ["indices", "values"] {
                let p = sparse.get(part).ok_or(format!("{at}.sparse.{part} is missing"))?;
                field(root, p, &format!("{at}.sparse.{part}"), "bufferView", "bufferViews")?
                    .ok_or(format!("{at}.sparse.{part}.bufferView is missing"))?;
            }
            let ct = sparse["indices"].get("componentType").and_then(Value::as_u64).unwrap_or(0);
            if ![5121, 5123, 5125].contains(&ct) {
                return Err(format!("{at}.sparse.indices.componentType {ct} is not 5121, 5123 or 5125"));
            }
        }
    }
    Ok(())
}

/// Image, texture and material references.
fn check_textures_and_materials(root: &Value) -> Result<(), String> {
    for (at, image) in items(root, "images") {
        field(root, image, &at, "bufferView", "bufferViews")?;
    }
    for (at, tex) in items(root, "textures") {
        field(root, tex, &at, "source", "images")?;
        field(root, tex, &at, "sampler", "samplers")?;
    }
    for (at, mat) in items(root, "materials") {
        let refs = [
            ("pbrMetallicRoughness.baseColorTexture", mat.pointer("/pbrMetallicRoughness/baseColorTexture")),
            (
                "pbrMetallicRoughness.metallicRoughnessTexture",
                mat.pointer("/pbrMetallicRoughness/metallicRoughnessTexture"),
            ),
            ("normalTexture", mat.get("normalTexture")),
            ("occlusionTexture", mat.get("occlusionTexture")),
            ("emissiveTexture", mat.get("emissiveTexture")),
        ];
        for (name, r) in refs {
            if let Some(r) = r {
                field(root, r, &format!("{at}.{name}"), "index", "textures")?;
            }
        }
    }
    Ok(())
}

/// Primitive attributes, indices, materials and morph targets: indices in range, accessor types fit.
fn check_meshes(root: &Value) -> Result<(), String> {
    for (at, mesh) in items(root, "meshes") {
        for (p, prim) in mesh.get("primitives").and_then(Value::as_array).into_iter().flatten().enumerate() {
            let pat = format!("{at}.primitives[{p}]");
            for (semantic, acc) in prim.get("attributes").and_then(Value::as_object).into_iter().flatten() {
                let what = format!("{pat}.attributes.{semantic}");
                let k = index(root, acc, &what, "accessors")?;
                if let Some((types, cts)) = attribute_rule(semantic) {
                    accessor_use(root, k, &what, types, cts)?;
                }
            }
            if let Some(i) = field(root, prim, &pat, "indices", "accessors")? {
                accessor_use(root, i, &format!("{pat}.indices"), &["SCALAR"], &[5121, 5123, 5125])?;
            }
            field(root, prim, &pat, "material", "materials")?;
            for (t, target) in prim.get("targets").and_then(Value::as_array).into_iter().flatten().enumerate() {
                for (semantic, acc) in target.as_object().into_iter().flatten() {
                    index(root, acc, &format!("{pat}.targets[{t}].{semantic}"), "accessors")?;
                }
            }
        }
    }
    Ok(())
}

/// Node references; the hierarchy must be a forest (one parent at most, no cycle).
fn check_nodes(root: &Value) -> Result<(), String> {
    let node_count = len(root, "nodes");
    let mut parent: Vec<Option<usize>> = vec![None; node_count];
    for (at, node) in items(root, "nodes") {
        field(root, node, &at, "mesh", "meshes")?;
        field(root, node, &at, "camera", "cameras")?;
        field(root, node, &at, "skin", "skins")?;
        let me: usize = at["nodes[".len()..at.len() - 1].parse().expect("our own label");
        for (k, c) in node.get("children").and_then(Value::as_array).into_iter().flatten().enumerate() {
            let child = index(root, c, &format!("{at}.children[{k}]"), "nodes")?;
            if parent[child] == Some(me) {
                return Err(format!("{at}.children lists nodes[{child}] twice"));
            }
            if let Some(other) = parent[child] {
                return Err(format!(
                    "nodes[{child}] is a child of both nodes[{other}] and nodes[{me}]: a glTF node has at most one parent"
                ));
            }
            parent[child] = Some(me);
        }
    }
    for start in 0..node_count {
        let (mut n, mut steps) = (start, 0);
        while let Some(p) = parent[n] {
            n = p;
            steps += 1;
            if steps > node_count {
                return Err(format!("the node hierarchy has a cycle through nodes[{start}]"));
            }
        }
    }
    Ok(())
}

/// Skin and animation references.
fn check_skins_and_animations(root: &Value) -> Result<(), String> {
    for (at, skin) in items(root, "skins") {
        field(root, skin, &at, "inverseBindMatrices", "accessors")?;
        field(root, skin, &at, "skeleton", "nodes")?;
        for (k, j) in skin.get("joints").and_then(Value::as_array).into_iter().flatten().enumerate() {
            index(root, j, &format!("{at}.joints[{k}]"), "nodes")?;
        }
    }
    for (at, anim) in items(root, "animations") {
        let samplers = anim.get("samplers").and_then(Value::as_array).map_or(0, Vec::len);
        for (k, s) in anim.get("samplers").and_then(Value::as_array).into_iter().flatten().enumerate() {
            field(root, s, &format!("{at}.samplers[{k}]"), "input", "accessors")?;
            field(root, s, &format!("{at}.samplers[{k}]"), "output", "accessors")?;
        }
        for (k, c) in anim.get("channels").and_then(Value::as_array).into_iter().flatten().enumerate() {
            let cat = format!("{at}.channels[{k}]");
            match c.get("sampler").and_then(Value::as_u64) {
                Some(s) if (s as usize) < samplers => {}
                other => {
                    let got = other.map_or("missing".to_string(), |s| s.to_string());
                    return Err(format!("{cat}.sampler is {got}, but the animation has {samplers} samplers"));
                }
            }
            if let Some(target) = c.get("target") {
                field(root, target, &format!("{cat}.target"), "node", "nodes")?;
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    fn doc() -> Value {
        json!({
            "asset": { "version": "2.0" },
            "scene": 0,
            "scenes": [{ "nodes": [0] }],
            "nodes": [{ "mesh": 0 }],
            "meshes": [{ "primitives": [{ "attributes": { "POSITION": 0 } }] }],
            "accessors": [{ "bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3" }],
            "bufferViews": [{ "buffer": 0, "byteLength": 36 }],
            "buffers": [{ "byteLength": 36 }]
        })
    }

    fn with(path: &str, value: Value) -> Value {
        let mut d = doc();
        *d.pointer_mut(path).unwrap_or_else(|| panic!("{path}")) = value;
        d
    }

    #[test]
    fn a_valid_document_passes_and_each_fault_is_named() {
        check(&doc()).unwrap();
        let cases = [
            (with("/meshes/0/primitives/0/attributes/POSITION", json!(99)), "accessors[99]"),
            (with("/asset/version", json!("1.0")), "asset.version"),
            (with("/accessors/0/type", json!("SCALAR")), "POSITION uses accessors[0] of type SCALAR"),
            (with("/accessors/0/componentType", json!(5121)), "componentType 5121"),
            (with("/bufferViews/0/buffer", json!(3)), "buffers[3]"),
            (with("/nodes/0/mesh", json!(1)), "meshes[1]"),
            (with("/scene", json!(2)), "scenes[2]"),
        ];
        for (d, needle) in cases {
            let e = check(&d).unwrap_err();
            assert!(e.contains(needle), "{needle}: {e}");
        }
        let mut d = doc();
        d["bufferViews"][0]["byteStride"] = json!(4);
        assert!(check(&d).unwrap_err().contains("byteStride is only 4"));
        let mut d = doc();
        d["nodes"] = json!([{ "children": [1, 1] }, { "mesh": 0 }]);
        assert!(check(&d).unwrap_err().contains("lists nodes[1] twice"));
        d["nodes"] = json!([{ "children": [1] }, { "mesh": 0 }, { "children": [1] }]);
        assert!(check(&d).unwrap_err().contains("child of both"));
        let mut d = doc();
        d["nodes"] = json!([{ "children": [1], "mesh": 0 }, { "children": [0] }]);
        assert!(check(&d).unwrap_err().contains("cycle"));
    }
}
