//! glTF 2.0 import: the Khronos samples (when ../shared/assets is present) and files written
//! here, good and broken.

use std::path::PathBuf;

use twister::core::scenes::load::load_scene;
use twister::Projection;

mod common;
use common::gltf_files::{gltf_json, write, QUAD};

fn assets() -> PathBuf {
    common::asset("gltf")
}

fn tmp(name: &str) -> common::TempDir {
    let d = common::TempDir::new(format!("twister-gltf-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&*d).unwrap();
    d
}

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
    use twister::core::shading::material::{AlphaMode, Filter, Mipmap, Wrap};
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
    assert_eq!(
        (s.materials[k].double_sided, s.materials[k].texture),
        (0, twister::core::shading::material::NO_TEXTURE)
    );
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
    assert_eq!(s.materials[1].texture, twister::core::shading::material::NO_TEXTURE);
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
