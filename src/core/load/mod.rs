//! Loading scenes: built-in names, OBJ files (positions, normals, UVs, vertex colours; polygons
//! triangulated; missing normals computed; MTL `Kd` colours and `map_Kd` textures) and glTF 2.0
//! (`.gltf` with external or embedded buffers, `.glb`: the default scene's node hierarchy,
//! TRIANGLES / TRIANGLE_STRIP / TRIANGLE_FAN primitives, indexed or not, sparse accessors;
//! materials: base colour factor × vertex colour × base colour texture with its sampler and
//! TEXCOORD set, `KHR_texture_transform`, alpha mode and cutoff, double-sided). Every failure is
//! one message naming the file and the problem; accessors are bounds-checked before they are read.
//!
//! Texture coordinates are stored in texture space (u right, v down from the image's top row):
//! glTF's own convention; OBJ's v (up from the bottom row) is flipped on load.

use std::path::Path;

use glam::{Mat4, Vec3};

use crate::core::builtin;
use crate::core::material::{AlphaMode, Filter, Material, Mipmap, Wrap};
use crate::core::projection::Projection;
use crate::core::scene::Scene;
use crate::core::scene::{compute_normals, SceneVertex};
use crate::core::texture::Texture;
use crate::error::{Error, Result};

/// Default colour of surfaces without a material (linear; sRGB 0.8, 0.78, 0.74).
pub const DEFAULT_COLOR: [f32; 4] = [0.604, 0.57, 0.507, 1.0];

/// Loads a scene by name (`builtin:...`) or path.
pub fn load_scene(spec: &str, projection: &Projection) -> Result<Scene> {
    if spec.starts_with("builtin:") {
        return builtin::builtin_scene(spec, projection);
    }
    let path = Path::new(spec);
    let ext = path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
    let scene = match ext.as_deref() {
        Some("obj") => load_obj(path)?,
        Some("gltf") | Some("glb") => load_gltf(path)?,
        _ => {
            return Err(Error::scene(
                spec,
                format!(
                    "unknown scene type (expected a .obj, .gltf or .glb file, or one of {})",
                    builtin::NAMES.join(", ")
                ),
            ))
        }
    };
    scene.validate()?;
    Ok(scene)
}

/// A loader's message as a scene error naming the file (once).
fn scene_error(name: &str, message: String) -> Error {
    let message = message.strip_prefix(&format!("{name}: ")).map(str::to_string).unwrap_or(message);
    Error::scene(name, message)
}

/// Loads an OBJ file: every object/group becomes one scene object.
pub fn load_obj(path: &Path) -> Result<Scene> {
    read_obj(path).map_err(|m| scene_error(&path.display().to_string(), m))
}

/// Loads a glTF 2.0 file's default scene (see the module doc for what is supported).
pub fn load_gltf(path: &Path) -> Result<Scene> {
    read_gltf(path).map_err(|m| scene_error(&path.display().to_string(), m))
}

fn read_obj(path: &Path) -> std::result::Result<Scene, String> {
    let name = path.display().to_string();
    if !path.is_file() {
        return Err(format!("{name}: no such file"));
    }
    let options = tobj::LoadOptions { triangulate: true, single_index: true, ..Default::default() };
    let (models, materials) =
        tobj::load_obj(path, &options).map_err(|e| format!("{name}: not a readable OBJ file: {e}"))?;
    let mut scene = Scene::new(name.clone());
    // A missing or broken MTL file leaves the default material, with a warning.
    let materials = materials.unwrap_or_else(|e| {
        scene.warnings.push(format!("materials not loaded ({e}); using the default colour"));
        Vec::new()
    });
    let texture_dirs = obj_texture_dirs(path);
    let mut loaded: Vec<(String, u32)> = Vec::new(); // map_Kd as written → texture index
    for mat in &materials {
        let mut material = Material::default();
        if let Some(spec) = mat.diffuse_texture.as_deref() {
            if let Some(&(_, k)) = loaded.iter().find(|(s, _)| s == spec) {
                material.texture = k;
            } else {
                match load_obj_texture(spec, &texture_dirs) {
                    Ok(texture) => {
                        material.texture = scene.textures.len() as u32;
                        scene.textures.push(texture);
                    }
                    Err(e) => scene.warnings.push(format!("material '{}': {e}; drawn without its texture", mat.name)),
                }
                loaded.push((spec.to_string(), material.texture));
            }
        }
        scene.materials.push(material);
    }
    for model in &models {
        let m = &model.mesh;
        let n = m.positions.len() / 3;
        if m.indices.iter().any(|&i| i as usize >= n) {
            return Err(format!("{name}: object '{}' has a face index beyond its {n} vertices", model.name));
        }
        let mut vertices: Vec<SceneVertex> = (0..n)
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
                uv: if m.texcoords.len() >= 2 * n {
                    [m.texcoords[2 * i], 1.0 - m.texcoords[2 * i + 1]]
                } else {
                    [0.0; 2]
                },
                ..Default::default()
            })
            .collect();
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

/// The folders an OBJ file's `map_Kd` paths are relative to: those of its MTL files (the
/// `mtllib` lines, relative to the OBJ file), then the OBJ file's own folder.
fn obj_texture_dirs(obj: &Path) -> Vec<std::path::PathBuf> {
    let base = obj.parent().unwrap_or(Path::new(".")).to_path_buf();
    let text = std::fs::read(obj).unwrap_or_default();
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
    let file = candidates.iter().find(|p| p.is_file()).ok_or_else(|| format!("texture '{spec}' not found"))?;
    let image = image::open(file).map_err(|e| format!("texture {}: {e}", file.display()))?;
    Ok(Texture::from_image(file.display().to_string(), image))
}

/// An image decoded by the glTF importer, as RGBA8 (16-bit channels keep their high byte,
/// float channels are clamped to 0..1).
fn gltf_texture(name: String, data: &gltf::image::Data) -> std::result::Result<Texture, String> {
    use gltf::image::Format;
    let (channels, bytes) = match data.format {
        Format::R8 => (1, 1),
        Format::R8G8 => (2, 1),
        Format::R8G8B8 => (3, 1),
        Format::R8G8B8A8 => (4, 1),
        Format::R16 => (1, 2),
        Format::R16G16 => (2, 2),
        Format::R16G16B16 => (3, 2),
        Format::R16G16B16A16 => (4, 2),
        Format::R32G32B32FLOAT => (3, 4),
        Format::R32G32B32A32FLOAT => (4, 4),
    };
    let texels = (data.width * data.height) as usize;
    if data.pixels.len() < texels * channels * bytes || texels == 0 {
        return Err(format!(
            "image '{name}' has {} bytes for {}×{} texels",
            data.pixels.len(),
            data.width,
            data.height
        ));
    }
    let channel = |t: usize, c: usize| -> u8 {
        let at = (t * channels + c) * bytes;
        match bytes {
            1 => data.pixels[at],
            2 => data.pixels[at + 1],
            _ => {
                let x = f32::from_le_bytes([0, 1, 2, 3].map(|k| data.pixels[at + k]));
                (x.clamp(0.0, 1.0) * 255.0 + 0.5) as u8
            }
        }
    };
    let rgba = (0..texels)
        .flat_map(|t| match channels {
            1 => [channel(t, 0); 3].into_iter().chain([255]).collect::<Vec<u8>>(),
            2 => vec![channel(t, 0), channel(t, 0), channel(t, 0), channel(t, 1)],
            3 => vec![channel(t, 0), channel(t, 1), channel(t, 2), 255],
            _ => vec![channel(t, 0), channel(t, 1), channel(t, 2), channel(t, 3)],
        })
        .collect();
    Ok(Texture { name, width: data.width, height: data.height, rgba })
}

/// A glTF material as twister draws it, its base colour texture's TEXCOORD set and texture
/// transform (rows of a 2×3 affine matrix).
type GltfMaterial = (Material, u32, Option<[[f32; 3]; 2]>);

/// A glTF material as twister draws it, and the TEXCOORD set and `KHR_texture_transform`
/// (u' = offset + R(rotation)·(scale·u)) of its base colour texture.
fn gltf_material(material: &gltf::Material) -> GltfMaterial {
    use gltf::texture::{MagFilter, MinFilter, WrappingMode};
    let mut m = Material {
        alpha_mode: match material.alpha_mode() {
            gltf::material::AlphaMode::Opaque => AlphaMode::Opaque,
            gltf::material::AlphaMode::Mask => AlphaMode::Mask,
            gltf::material::AlphaMode::Blend => AlphaMode::Blend,
        } as u32,
        alpha_cutoff: material.alpha_cutoff().unwrap_or(0.5),
        double_sided: material.double_sided() as u32,
        ..Default::default()
    };
    let Some(info) = material.pbr_metallic_roughness().base_color_texture() else {
        return (m, 0, None);
    };
    let texture = info.texture();
    let sampler = texture.sampler();
    let wrap = |w: WrappingMode| match w {
        WrappingMode::ClampToEdge => Wrap::ClampToEdge,
        WrappingMode::MirroredRepeat => Wrap::MirroredRepeat,
        WrappingMode::Repeat => Wrap::Repeat,
    } as u32;
    m.texture = texture.source().index() as u32;
    m.wrap_u = wrap(sampler.wrap_s());
    m.wrap_v = wrap(sampler.wrap_t());
    m.mag_filter = match sampler.mag_filter() {
        Some(MagFilter::Nearest) => Filter::Nearest,
        _ => Filter::Linear,
    } as u32;
    // No minification filter given: trilinear, the renderer's choice the spec leaves open.
    let (min, mip) = match sampler.min_filter() {
        Some(MinFilter::Nearest) => (Filter::Nearest, Mipmap::None),
        Some(MinFilter::Linear) => (Filter::Linear, Mipmap::None),
        Some(MinFilter::NearestMipmapNearest) => (Filter::Nearest, Mipmap::Nearest),
        Some(MinFilter::LinearMipmapNearest) => (Filter::Linear, Mipmap::Nearest),
        Some(MinFilter::NearestMipmapLinear) => (Filter::Nearest, Mipmap::Linear),
        Some(MinFilter::LinearMipmapLinear) | None => (Filter::Linear, Mipmap::Linear),
    };
    (m.min_filter, m.mipmap) = (min as u32, mip as u32);
    let transform = info.texture_transform();
    let set = transform.as_ref().and_then(|t| t.tex_coord()).unwrap_or(info.tex_coord());
    let matrix = transform.map(|t| {
        let ([ox, oy], r, [sx, sy]) = (t.offset(), t.rotation(), t.scale());
        let (s, c) = r.sin_cos();
        [[c * sx, s * sy, ox], [-s * sx, c * sy, oy]]
    });
    (m, set, matrix)
}

/// The first external buffer or image file a glTF file names that does not exist, described.
fn missing_gltf_resource(path: &Path) -> Option<String> {
    let gltf = gltf::Gltf::open(path).ok()?;
    let base = path.parent().unwrap_or(Path::new("."));
    let exists = |uri: &str| uri.starts_with("data:") || base.join(uri.replace("%20", " ")).is_file();
    let buffers = gltf.buffers().filter_map(|b| match b.source() {
        gltf::buffer::Source::Uri(uri) if !exists(uri) => Some(format!("buffer {} file '{uri}' not found", b.index())),
        _ => None,
    });
    let images = gltf.images().filter_map(|i| match i.source() {
        gltf::image::Source::Uri { uri, .. } if !exists(uri) => {
            Some(format!("image {} file '{uri}' not found", i.index()))
        }
        _ => None,
    });
    buffers.chain(images).next()
}

/// glTF extensions twister draws (the others are ignored with a note, or refused when required).
pub const GLTF_EXTENSIONS: &[&str] = &["KHR_texture_transform"];

fn read_gltf(path: &Path) -> std::result::Result<Scene, String> {
    let name = path.display().to_string();
    if !path.is_file() {
        return Err(format!("{name}: no such file"));
    }
    let (doc, buffers, images) = gltf::import(path).map_err(|e| match missing_gltf_resource(path) {
        Some(missing) => format!("{name}: not a readable glTF file: {missing}"),
        None => format!("{name}: not a readable glTF file: {e}"),
    })?;
    let required: Vec<&str> = doc.extensions_required().filter(|e| !GLTF_EXTENSIONS.contains(e)).collect();
    if !required.is_empty() {
        return Err(format!("{name}: requires extensions twister does not support: {}", required.join(", ")));
    }
    let mut scene = Scene::new(name.clone());
    let used: Vec<&str> = doc.extensions_used().filter(|e| !GLTF_EXTENSIONS.contains(e)).collect();
    if !used.is_empty() {
        scene.warnings.push(format!("optional extensions ignored: {}", used.join(", ")));
    }
    for (image, data) in doc.images().zip(&images) {
        let label = match (image.name(), image.source()) {
            (Some(n), _) => n.to_string(),
            (None, gltf::image::Source::Uri { uri, .. }) if !uri.starts_with("data:") => uri.to_string(),
            _ => format!("image {}", image.index()),
        };
        scene.textures.push(gltf_texture(label, data).map_err(|e| format!("{name}: {e}"))?);
    }
    // glTF material k is scene material k; primitives without one share the spec's default
    // material (single-sided, opaque), appended at the end.
    let materials: Vec<GltfMaterial> = doc.materials().map(|m| gltf_material(&m)).collect();
    scene.materials = materials.iter().map(|m| m.0).collect();
    if let Some(p) = doc.meshes().flat_map(|m| m.primitives()).find(|p| p.material().index().is_none()) {
        scene.materials.push(gltf_material(&p.material()).0);
    }
    let root =
        doc.default_scene().or_else(|| doc.scenes().next()).ok_or_else(|| format!("{name}: the file has no scene"))?;
    let mut stack: Vec<(gltf::Node, Mat4, usize)> = root.nodes().map(|n| (n, Mat4::IDENTITY, 0)).collect();
    while let Some((node, parent, depth)) = stack.pop() {
        if depth > 256 {
            return Err(format!("{name}: the node hierarchy is deeper than 256 levels (a cycle?)"));
        }
        let world = parent * Mat4::from_cols_array_2d(&node.transform().matrix());
        if !world.is_finite() {
            return Err(format!("{name}: node {} has a NaN or infinite transform", node.index()));
        }
        if let Some(camera) = node.camera() {
            // The camera looks along its local −z.
            let forward = world.transform_vector3(-Vec3::Z);
            scene.cameras.push(crate::core::scene::Camera {
                name: camera
                    .name()
                    .or(node.name())
                    .map_or_else(|| format!("camera {}", scene.cameras.len()), str::to_string),
                position: world.transform_point3(Vec3::ZERO).into(),
                yaw_deg: (-forward.x).atan2(-forward.z).to_degrees(),
            });
        }
        if let Some(mesh) = node.mesh() {
            // One scene object per mesh instance (node), its primitives one after the other.
            let mesh_name = mesh.name().map_or_else(|| format!("mesh {}", mesh.index()), str::to_string);
            let instance = node.name().map_or_else(|| format!("node {}", node.index()), str::to_string);
            let objects_before = scene.objects.len();
            for prim in mesh.primitives() {
                let label = format!("{mesh_name} / primitive {}", prim.index());
                add_gltf_primitive(&mut scene, &prim, &buffers, world, &label, &materials)
                    .map_err(|e| format!("{name}: {label}: {e}"))?;
            }
            scene.merge_objects_from(objects_before, format!("{mesh_name} ({instance})"));
        }
        stack.extend(node.children().map(|c| (c, world, depth + 1)));
    }
    if scene.triangle_count() == 0 {
        return Err(format!("{name}: the default scene has no triangles"));
    }
    Ok(scene)
}

/// Checks that an accessor's elements lie inside its buffer view and the view inside its buffer.
fn check_accessor(acc: &gltf::Accessor, buffers: &[gltf::buffer::Data]) -> std::result::Result<(), String> {
    let count = acc.count();
    if count > (1 << 28) {
        return Err(format!("accessor {} claims {count} elements", acc.index()));
    }
    if let Some(view) = acc.view() {
        let buffer_len = buffers.get(view.buffer().index()).map_or(0, |b| b.len());
        if view.offset() + view.length() > buffer_len {
            return Err(format!(
                "buffer view {} overruns its buffer ({} > {buffer_len} bytes)",
                view.index(),
                view.offset() + view.length()
            ));
        }
        let element = acc.size();
        let stride = view.stride().unwrap_or(element);
        if count > 0 && acc.offset() + stride * (count - 1) + element > view.length() {
            return Err(format!("accessor {} overruns buffer view {}", acc.index(), view.index()));
        }
    }
    Ok(())
}

fn add_gltf_primitive(
    scene: &mut Scene,
    prim: &gltf::Primitive,
    buffers: &[gltf::buffer::Data],
    world: Mat4,
    label: &str,
    materials: &[GltfMaterial],
) -> std::result::Result<(), String> {
    use gltf::mesh::Mode;
    let mode = prim.mode();
    if !matches!(mode, Mode::Triangles | Mode::TriangleStrip | Mode::TriangleFan) {
        scene.warnings.push(format!("{label}: {mode:?} primitive skipped (only triangles are drawn)"));
        return Ok(());
    }
    for (_, acc) in prim.attributes() {
        check_accessor(&acc, buffers)?;
    }
    if let Some(acc) = prim.indices() {
        check_accessor(&acc, buffers)?;
    }
    let reader = prim.reader(|b| buffers.get(b.index()).map(|d| &d.0[..]));
    let positions: Vec<[f32; 3]> = reader.read_positions().ok_or("no POSITION attribute")?.collect();
    let n = positions.len();
    let normals: Option<Vec<[f32; 3]>> = reader.read_normals().map(|r| r.collect());
    let material = prim.material();
    let (set, transform) = material.index().map_or((0, None), |k| (materials[k].1, materials[k].2));
    let uvs: Option<Vec<[f32; 2]>> = reader.read_tex_coords(set).map(|r| {
        r.into_f32()
            .map(|[u, v]| match transform {
                Some([a, b]) => [a[0] * u + a[1] * v + a[2], b[0] * u + b[1] * v + b[2]],
                None => [u, v],
            })
            .collect()
    });
    if uvs.is_none() && material.pbr_metallic_roughness().base_color_texture().is_some() {
        scene.warnings.push(format!("{label}: its material's texture uses TEXCOORD_{set}, which it lacks"));
    }
    let colors: Option<Vec<[f32; 4]>> = reader.read_colors(0).map(|r| r.into_rgba_f32().collect());
    let factor = material.pbr_metallic_roughness().base_color_factor();
    let material_id = material.index().map_or(materials.len() as u32, |m| m as u32) + 1;
    let raw: Vec<u32> = match reader.read_indices() {
        Some(r) => r.into_u32().collect(),
        None => (0..n as u32).collect(),
    };
    if let Some(&bad) = raw.iter().find(|&&i| i as usize >= n) {
        return Err(format!("index {bad} is out of range ({n} vertices)"));
    }
    let indices: Vec<u32> = match mode {
        Mode::Triangles => raw.chunks_exact(3).flatten().copied().collect(),
        Mode::TriangleStrip => (0..raw.len().saturating_sub(2))
            .flat_map(|k| if k % 2 == 0 { [raw[k], raw[k + 1], raw[k + 2]] } else { [raw[k + 1], raw[k], raw[k + 2]] })
            .collect(),
        _ => (1..raw.len().saturating_sub(1)).flat_map(|k| [raw[0], raw[k], raw[k + 1]]).collect(),
    };
    let normal_matrix = world.inverse().transpose();
    let mut vertices: Vec<SceneVertex> = (0..n)
        .map(|i| {
            let c = colors.as_ref().and_then(|c| c.get(i).copied()).unwrap_or([1.0; 4]);
            SceneVertex {
                position: world.transform_point3(Vec3::from(positions[i])).into(),
                normal: normals
                    .as_ref()
                    .and_then(|v| v.get(i))
                    .map_or(Vec3::ZERO, |&v| normal_matrix.transform_vector3(Vec3::from(v)).normalize_or_zero())
                    .into(),
                color: [0, 1, 2, 3].map(|k| c[k] * factor[k]),
                uv: uvs.as_ref().and_then(|v| v.get(i)).copied().unwrap_or([0.0; 2]),
                material: material_id,
                ..Default::default()
            }
        })
        .collect();
    if normals.is_none() {
        compute_normals(&mut vertices, &indices);
    }
    scene.add_mesh(label, &vertices, &indices);
    Ok(())
}

/// A viewer position to suggest for a scene: inside it at standing height if it surrounds a
/// person (over 4 m across on the ground), else 3 object sizes in front of it (+z side, looking
/// along −z at it). Returns the position and "inside" or "in front".
pub fn suggested_viewer(scene: &Scene) -> Option<([f32; 3], &'static str)> {
    let (lo, hi) = scene.bounds()?;
    let (size, c) = (hi - lo, (lo + hi) / 2.0);
    if size.x > 4.0 && size.z > 4.0 {
        Some(([c.x, lo.y + 1.7, c.z], "inside"))
    } else {
        Some(([c.x, c.y, hi.z + 3.0 * size.max_element()], "in front"))
    }
}
