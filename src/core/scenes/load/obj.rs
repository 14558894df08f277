//! OBJ files (tobj): objects and groups, positions, normals (computed when missing), texture
//! coordinates (v flipped to texture space), vertex colours, MTL `Kd` colours and `map_Kd` textures.

use std::path::{Path, PathBuf};

use super::DEFAULT_COLOR;
use crate::core::scenes::scene::{compute_normals, Scene, SceneVertex};
use crate::core::shading::material::Material;
use crate::core::shading::texture::Texture;

pub(super) fn read_obj(path: &Path) -> std::result::Result<Scene, String> {
    let name = path.display().to_string();
    // Names and comments are labels: bytes that are not UTF-8 (Latin-1 names) are replaced,
    // not refused.
    let text = String::from_utf8_lossy(&super::read_file(path)?).into_owned();
    check_faces(&text)?;
    let options = tobj::LoadOptions { triangulate: true, single_index: true, ..Default::default() };
    let base = path.parent().unwrap_or(Path::new(".")).to_path_buf();
    let (models, materials) = tobj::load_obj_buf(&mut text.as_bytes(), &options, |mtl| {
        // MTL files are read like every other file a scene names: regular, bounded.
        let mtl_path = base.join(mtl);
        let bytes = super::read_file(&mtl_path).map_err(|e| {
            log_mtl_problem(&mtl_path, &e);
            tobj::LoadError::OpenFileFailed
        })?;
        tobj::load_mtl_buf(&mut String::from_utf8_lossy(&bytes).as_bytes())
    })
    .map_err(|e| format!("{name}: not a readable OBJ file: {e}"))?;
    let mut scene = Scene::new(name.clone());
    // A missing or broken MTL file leaves the default material, with a warning.
    let materials = materials.unwrap_or_else(|e| {
        let why = MTL_PROBLEM.with(|p| p.borrow_mut().take()).unwrap_or_else(|| e.to_string());
        scene.warnings.push(format!("materials not loaded ({why}); using the default colour"));
        Vec::new()
    });
    add_obj_materials(&mut scene, &materials, &obj_texture_dirs(path));
    for model in &models {
        let m = &model.mesh;
        let n = m.positions.len() / 3;
        if m.indices.iter().any(|&i| i as usize >= n) {
            return Err(format!("{name}: object '{}' has a face index beyond its {n} vertices", model.name));
        }
        let mut vertices = obj_vertices(m, &materials);
        if m.normals.len() < 3 * n {
            compute_normals(&mut vertices, &m.indices);
        }
        scene.add_mesh(model.name.clone(), &vertices, &m.indices);
    }
    if scene.triangle_count() == 0 {
        return Err(format!("{name}: no faces"));
    }
    Ok(scene)
}

/// The MTL materials as scene materials, with their textures and bump maps (each texture file
/// loaded once; one that cannot be read is a warning and the material is drawn without it).
fn add_obj_materials(scene: &mut Scene, materials: &[tobj::Material], texture_dirs: &[PathBuf]) {
    let mut loaded: Vec<(String, u32)> = Vec::new(); // map_Kd as written → texture index
    for mat in materials {
        let mut material = obj_optics(mat);
        if let Some(spec) = mat.diffuse_texture.as_deref() {
            if let Some(&(_, k)) = loaded.iter().find(|(s, _)| s == spec) {
                material.texture = k;
            } else {
                match load_obj_texture(spec, texture_dirs) {
                    Ok(texture) => {
                        material.texture = scene.textures.len() as u32;
                        scene.textures.push(texture);
                    }
                    Err(e) => scene.warnings.push(format!("material '{}': {e}; drawn without its texture", mat.name)),
                }
                loaded.push((spec.to_string(), material.texture));
            }
        }
        // `map_Bump` / `bump` (tobj's normal texture) or `norm`: a normal map, or a height map
        // turned into one (`normal_map_of`).
        let bump = mat.normal_texture.as_deref().or(mat.unknown_param.get("norm").map(String::as_str));
        if let Some(spec) = bump {
            match load_obj_texture(spec, texture_dirs) {
                Ok(texture) => {
                    let (map, note) = normal_map_of(&texture);
                    if let Some(note) = note {
                        scene.warnings.push(format!("material '{}': {note}", mat.name));
                    }
                    material.normal_texture = scene.textures.len() as u32;
                    scene.textures.push(map.encode_data());
                }
                Err(e) => scene.warnings.push(format!("material '{}': {e}; drawn without its bump map", mat.name)),
            }
        }
        scene.materials.push(material);
    }
}

/// An OBJ object's vertices: positions, normals (zero where the file has none: computed by the
/// caller), vertex colours or the material's diffuse colour, texture coordinates (v flipped).
fn obj_vertices(m: &tobj::Mesh, materials: &[tobj::Material]) -> Vec<SceneVertex> {
    let n = m.positions.len() / 3;
    (0..n)
        .map(|i| SceneVertex {
            position: [m.positions[3 * i], m.positions[3 * i + 1], m.positions[3 * i + 2]],
            normal: if m.normals.len() >= 3 * n {
                [m.normals[3 * i], m.normals[3 * i + 1], m.normals[3 * i + 2]]
            } else {
                [0.0; 3]
            },
            color: if m.vertex_color.len() >= 3 * n {
                [m.vertex_color[3 * i], m.vertex_color[3 * i + 1], m.vertex_color[3 * i + 2], 1.0]
            } else {
                m.material_id
                    .and_then(|k| materials.get(k))
                    .and_then(|mat| mat.diffuse)
                    .map_or(DEFAULT_COLOR, |d| [d[0], d[1], d[2], 1.0])
            },
            material: m.material_id.map_or(0, |k| k as u32 + 1),
            uv: if m.texcoords.len() >= 2 * n { [m.texcoords[2 * i], 1.0 - m.texcoords[2 * i + 1]] } else { [0.0; 2] },
            ..Default::default()
        })
        .collect()
}

thread_local! {
    /// Why the last MTL file could not be read (tobj's error type cannot carry it).
    static MTL_PROBLEM: std::cell::RefCell<Option<String>> = const { std::cell::RefCell::new(None) };
}

fn log_mtl_problem(path: &Path, problem: &str) {
    MTL_PROBLEM.with(|p| *p.borrow_mut() = Some(format!("{} {problem}", path.display())));
}

/// Checks every face line before tobj reads the file: at least 3 vertices, and each position,
/// texture-coordinate and normal index naming one defined before it (1-based, or negative:
/// relative to the end). The error names the line.
fn check_faces(text: &str) -> std::result::Result<(), String> {
    let (mut v, mut vt, mut vn) = (0i64, 0i64, 0i64);
    for (k, line) in text.lines().enumerate() {
        let mut words = line.split_whitespace();
        let keyword = words.next();
        if let Some(kind @ ("v" | "vt" | "vn")) = keyword {
            let numbers: Vec<&str> = words.clone().collect();
            let needed = if kind == "vt" { 1 } else { 3 };
            if numbers.len() < needed {
                return Err(format!("line {}: '{kind}' needs {needed} numbers, got {}", k + 1, numbers.len()));
            }
            if let Some(bad) = numbers.iter().find(|w| w.parse::<f32>().is_err()) {
                return Err(format!("line {}: '{bad}' is not a number", k + 1));
            }
        }
        match keyword {
            Some("v") => v += 1,
            Some("vt") => vt += 1,
            Some("vn") => vn += 1,
            Some("f") => {
                let corners: Vec<&str> = words.collect();
                if corners.len() < 3 {
                    return Err(format!("line {}: a face needs at least 3 vertices, got {}", k + 1, corners.len()));
                }
                for corner in corners {
                    for ((part, count), what) in
                        corner.split('/').zip([v, vt, vn]).zip(["vertex", "texture coordinate", "normal"])
                    {
                        if part.is_empty() {
                            continue;
                        }
                        let i: i64 =
                            part.parse().map_err(|_| format!("line {}: '{corner}' is not a face corner", k + 1))?;
                        if i == 0 || i > count || i < -count {
                            return Err(format!(
                                "line {}: face names {what} {i}, but {count} are defined before it",
                                k + 1
                            ));
                        }
                    }
                }
            }
            _ => {}
        }
    }
    Ok(())
}

/// The folders an OBJ file's `map_Kd` paths are relative to: those of its MTL files (the
/// `mtllib` lines, relative to the OBJ file), then the OBJ file's own folder.
fn obj_texture_dirs(obj: &Path) -> Vec<std::path::PathBuf> {
    let base = obj.parent().unwrap_or(Path::new(".")).to_path_buf();
    let text = super::read_file(obj).unwrap_or_default();
    let mut dirs: Vec<std::path::PathBuf> = String::from_utf8_lossy(&text)
        .lines()
        .filter_map(|l| l.trim().strip_prefix("mtllib "))
        .map(|m| base.join(portable_path(m.trim())).parent().map_or(base.clone(), Path::to_path_buf))
        .collect();
    dirs.push(base);
    dirs.dedup();
    dirs
}

/// A path as written in a file made on any system: `\` separators become `/`, a leading `./`
/// goes.
fn portable_path(written: &str) -> String {
    let p = written.replace('\\', "/");
    p.strip_prefix("./").map_or(p.clone(), str::to_string)
}

/// Loads an OBJ material's `map_Kd` image. The value may carry options (`-s 1 1 1 name.png`):
/// then the file name is its last word.
fn load_obj_texture(spec: &str, dirs: &[std::path::PathBuf]) -> std::result::Result<Texture, String> {
    let whole = portable_path(spec.trim());
    let last = portable_path(spec.split_whitespace().last().unwrap_or(""));
    let candidates: Vec<std::path::PathBuf> = dirs.iter().flat_map(|d| [d.join(&whole), d.join(&last)]).collect();
    let file = candidates.iter().find(|p| p.exists()).ok_or_else(|| format!("texture '{spec}' not found"))?;
    let bytes = super::read_file(file).map_err(|e| format!("texture {} {e}", file.display()))?;
    let image =
        image::load_from_memory(&bytes).map_err(|e| format!("texture {} cannot be decoded: {e}", file.display()))?;
    Ok(Texture::from_image(file.display().to_string(), image))
}

/// Height-map bump strength: the slope of a full-range step over one texel, as a normal map's
/// x or y (the texture's own scale is unknown to MTL; `-bm` is not read).
const BUMP_SLOPE: f32 = 4.0;

/// A bump texture as a tangent-space normal map: kept where it looks like one (mean blue above
/// 0.6, mean red and green within 0.35–0.65: the colours of normals near (0, 0, 1)); else read
/// as a height map (its luminance) and differentiated (central differences, wrapping, slope
/// `BUMP_SLOPE`), with a note.
pub fn normal_map_of(texture: &Texture) -> (Texture, Option<String>) {
    let n = (texture.width * texture.height) as f32;
    let mean = |c: usize| texture.rgba.chunks_exact(4).map(|t| t[c] as f32 / 255.0).sum::<f32>() / n.max(1.0);
    let (r, g, b) = (mean(0), mean(1), mean(2));
    if b > 0.6 && (0.35..=0.65).contains(&r) && (0.35..=0.65).contains(&g) {
        return (texture.clone(), None);
    }
    let (w, h) = (texture.width as i64, texture.height as i64);
    let height = |x: i64, y: i64| {
        let t = &texture.rgba[(4 * (y.rem_euclid(h) * w + x.rem_euclid(w))) as usize..][..3];
        (0.2126 * t[0] as f32 + 0.7152 * t[1] as f32 + 0.0722 * t[2] as f32) / 255.0
    };
    let e = |c: f32| ((c * 0.5 + 0.5) * 255.0).round() as u8;
    let rgba = (0..w * h)
        .flat_map(|i| {
            let (x, y) = (i % w, i / w);
            // +x along u; +y up the image (against v, whose rows run down).
            let dx = 0.5 * (height(x + 1, y) - height(x - 1, y)) * BUMP_SLOPE;
            let dy = 0.5 * (height(x, y - 1) - height(x, y + 1)) * BUMP_SLOPE;
            let n = glam::Vec3::new(-dx, -dy, 1.0).normalize();
            [e(n.x), e(n.y), e(n.z), 255]
        })
        .collect();
    let note = format!("bump texture {} read as a height map and turned into a normal map", texture.name);
    (Texture { name: texture.name.clone(), width: texture.width, height: texture.height, rgba }, Some(note))
}

/// The ray tracer's optics of an MTL material, by its illumination model: `illum` 3 and 5
/// (ray-traced reflection) mirror the share `Ks` (its largest channel; the reflection is tinted by
/// the surface colour); 4, 6 and 7 (ray-traced refraction) also transmit 1 − `d` (or `Tr`) with
/// index `Ni` (1.5 when absent or below 1). Other models: no optics. Also the glTF BRDF's
/// roughness, metallic and emission (see the body).
pub fn obj_optics(mat: &tobj::Material) -> Material {
    let illum = mat.illumination_model.unwrap_or(2);
    let ks = mat.specular.map_or(0.0, |s| s.iter().fold(0.0f32, |a, b| a.max(*b))).clamp(0.0, 1.0);
    let opacity = mat
        .dissolve
        .or_else(|| mat.unknown_param.get("Tr").and_then(|t| t.trim().parse::<f32>().ok()).map(|t| 1.0 - t))
        .unwrap_or(1.0);
    let mut m = Material::default();
    // The glTF BRDF's parameters (`--lighting pbr`): the PBR extension of MTL (`Pr` roughness,
    // `Pm` metallic) where given; else roughness from the Phong exponent `Ns` by the
    // Blinn-Phong–Beckmann correspondence α = √(2/(Ns + 2)), roughness = √α, and no metal;
    // `Ke` is the emitted colour.
    let param = |key: &str| -> Option<Vec<f32>> {
        let v: Vec<f32> = mat.unknown_param.get(key)?.split_whitespace().filter_map(|x| x.parse().ok()).collect();
        (!v.is_empty() && v.iter().all(|x| x.is_finite())).then_some(v)
    };
    m.roughness = match (param("Pr"), mat.shininess.filter(|n| n.is_finite() && *n >= 0.0)) {
        (Some(r), _) => r[0].clamp(0.0, 1.0),
        (None, Some(ns)) => (2.0 / (ns + 2.0)).sqrt().sqrt(),
        (None, None) => 1.0,
    };
    m.metallic = param("Pm").map_or(0.0, |p| p[0].clamp(0.0, 1.0));
    if let Some(ke) = mat.emissive.filter(|k| k.iter().all(|x| x.is_finite())) {
        let k = |i: usize| ke[i].clamp(0.0, 1e6);
        (m.emissive_r, m.emissive_g, m.emissive_b) = (k(0), k(1), k(2));
    }
    if (3..=7).contains(&illum) {
        m.mirror = ks;
    }
    if matches!(illum, 4 | 6 | 7) {
        m.transmission = (1.0 - opacity).clamp(0.0, 1.0 - m.mirror);
        m.ior = mat.optical_density.filter(|n| n.is_finite() && *n >= 1.0).unwrap_or(1.5);
    }
    m
}
