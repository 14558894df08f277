//! glTF 2.0 files (the gltf crate): `.gltf` with external or embedded buffers and `.glb`; the
//! default scene's node hierarchy, triangle primitives, sparse accessors, materials and cameras.

use std::path::Path;

use glam::{Mat4, Vec3};

use crate::core::scenes::scene::{compute_normals, pack_tangent, Scene, SceneVertex};
use crate::core::shading::light::{Light, LightKind};
use crate::core::shading::material::{AlphaMode, Filter, Material, Mipmap, Wrap};
use crate::core::shading::texture::Texture;

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

fn finite_or(x: f32, default: f32) -> f32 {
    if x.is_finite() {
        x
    } else {
        default
    }
}

/// Channel `c` of a material's emitted linear colour: emissive factor × emissive strength.
fn emissive(material: &gltf::Material, c: usize) -> f32 {
    let strength = finite_or(material.emissive_strength().unwrap_or(1.0), 1.0).max(0.0);
    (finite_or(material.emissive_factor()[c], 0.0).max(0.0) * strength).min(1e6)
}

/// A `KHR_lights_punctual` light placed by its node's world matrix (it shines along the node's −z).
fn gltf_light(light: &gltf::khr_lights_punctual::Light, world: Mat4) -> Light {
    use gltf::khr_lights_punctual::Kind;
    let color = Vec3::from(light.color()).max(Vec3::ZERO) * finite_or(light.intensity(), 1.0).max(0.0);
    let (kind, inner_cone, outer_cone) = match light.kind() {
        Kind::Directional => (LightKind::Directional, 0.0, 0.0),
        Kind::Point => (LightKind::Point, 0.0, 0.0),
        Kind::Spot { inner_cone_angle, outer_cone_angle } => {
            let outer =
                finite_or(outer_cone_angle, std::f32::consts::FRAC_PI_4).clamp(1e-3, std::f32::consts::FRAC_PI_2);
            (LightKind::Spot, finite_or(inner_cone_angle, 0.0).clamp(0.0, outer), outer)
        }
    };
    Light {
        kind,
        position: Vec3::ZERO,
        direction: -Vec3::Z,
        color: color.min(Vec3::splat(1e9)),
        range: light.range().filter(|r| r.is_finite() && *r > 0.0),
        inner_cone,
        outer_cone,
    }
    .transformed(world)
}

/// A glTF material as twister draws it, and the TEXCOORD set and `KHR_texture_transform`
/// (u' = offset + R(rotation)·(scale·u)) of its base colour texture.
/// The base colour texture's sampler: wrap modes, magnification, minification and mipmaps.
fn set_sampler(m: &mut Material, sampler: &gltf::texture::Sampler) {
    use gltf::texture::{MagFilter, MinFilter, WrappingMode};
    let wrap = |w: WrappingMode| match w {
        WrappingMode::ClampToEdge => Wrap::ClampToEdge,
        WrappingMode::MirroredRepeat => Wrap::MirroredRepeat,
        WrappingMode::Repeat => Wrap::Repeat,
    } as u32;
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
}

fn gltf_material(material: &gltf::Material) -> GltfMaterial {
    let mut m = Material {
        alpha_mode: match material.alpha_mode() {
            gltf::material::AlphaMode::Opaque => AlphaMode::Opaque,
            gltf::material::AlphaMode::Mask => AlphaMode::Mask,
            gltf::material::AlphaMode::Blend => AlphaMode::Blend,
        } as u32,
        alpha_cutoff: material.alpha_cutoff().unwrap_or(0.5),
        double_sided: material.double_sided() as u32,
        // The ray tracer's optics: a smooth metal is a mirror tinted by its base colour;
        // KHR_materials_transmission's factor refracts with KHR_materials_ior's index (1.5 by
        // default, as the extension says).
        mirror: {
            let pbr = material.pbr_metallic_roughness();
            if pbr.metallic_factor() >= 1.0 && pbr.roughness_factor() <= 0.0 {
                1.0
            } else {
                0.0
            }
        },
        transmission: material.transmission().map_or(0.0, |t| t.transmission_factor().clamp(0.0, 1.0)),
        ior: material.ior().filter(|i| i.is_finite() && *i >= 1.0).unwrap_or(1.5),
        // The glTF BRDF's factors (`--lighting pbr`); emission × KHR_materials_emissive_strength.
        metallic: finite_or(material.pbr_metallic_roughness().metallic_factor(), 1.0).clamp(0.0, 1.0),
        roughness: finite_or(material.pbr_metallic_roughness().roughness_factor(), 1.0).clamp(0.0, 1.0),
        emissive_r: emissive(material, 0),
        emissive_g: emissive(material, 1),
        emissive_b: emissive(material, 2),
        ..Default::default()
    };
    // The BRDF's maps (sampled at the base colour's coordinates; `gltf_maps_note` says where a
    // file asks otherwise).
    let pbr = material.pbr_metallic_roughness();
    if let Some(t) = pbr.metallic_roughness_texture() {
        m.mr_texture = t.texture().source().index() as u32;
    }
    if let Some(t) = material.normal_texture() {
        m.normal_texture = t.texture().source().index() as u32;
        m.normal_scale = finite_or(t.scale(), 1.0);
    }
    if let Some(t) = material.occlusion_texture() {
        m.occlusion_texture = t.texture().source().index() as u32;
        m.occlusion_strength = finite_or(t.strength(), 1.0).clamp(0.0, 1.0);
    }
    if let Some(t) = material.emissive_texture() {
        m.emissive_texture = t.texture().source().index() as u32;
    }
    let Some(info) = material.pbr_metallic_roughness().base_color_texture() else {
        return (m, 0, None);
    };
    let texture = info.texture();
    m.texture = texture.source().index() as u32;
    set_sampler(&mut m, &texture.sampler());
    let transform = info.texture_transform();
    let set = transform.as_ref().and_then(|t| t.tex_coord()).unwrap_or(info.tex_coord());
    let matrix = transform.map(|t| {
        let ([ox, oy], r, [sx, sy]) = (t.offset(), t.rotation(), t.scale());
        let (s, c) = r.sin_cos();
        [[c * sx, s * sy, ox], [-s * sx, c * sy, oy]]
    });
    (m, set, matrix)
}

/// The metallic-roughness, normal and occlusion maps hold numbers: their images become data
/// textures (`Texture::encode_data`), converted in place where no material uses the image as a
/// colour (base colour, emission), else as a copy.
fn data_maps(scene: &mut Scene) {
    use crate::core::shading::material::NO_TEXTURE;
    let n = scene.textures.len();
    let mut as_colour = vec![false; n];
    let mut as_data = vec![false; n];
    for m in &scene.materials {
        for t in [m.texture, m.emissive_texture] {
            if (t as usize) < n {
                as_colour[t as usize] = true;
            }
        }
        for t in [m.mr_texture, m.normal_texture, m.occlusion_texture] {
            if (t as usize) < n {
                as_data[t as usize] = true;
            }
        }
    }
    let mut data_index: Vec<u32> = (0..n as u32).collect();
    for k in 0..n {
        if !as_data[k] {
            continue;
        }
        let data = scene.textures[k].encode_data();
        if as_colour[k] {
            data_index[k] = scene.textures.len() as u32;
            scene.textures.push(data);
        } else {
            scene.textures[k] = data;
        }
    }
    for m in &mut scene.materials {
        for t in [&mut m.mr_texture, &mut m.normal_texture, &mut m.occlusion_texture] {
            if *t != NO_TEXTURE && (*t as usize) < n {
                *t = data_index[*t as usize];
            }
        }
    }
}

/// A note where a material's maps use other texture coordinates than its base colour (the maps
/// are sampled at the base colour's).
fn gltf_maps_note(material: &gltf::Material, set: u32, transformed: bool) -> Option<String> {
    let pbr = material.pbr_metallic_roughness();
    let maps = [
        (
            "metallic-roughness",
            pbr.metallic_roughness_texture().map(|t| (t.tex_coord(), t.texture_transform().is_some())),
        ),
        ("normal", material.normal_texture().map(|t| (t.tex_coord(), false))),
        ("occlusion", material.occlusion_texture().map(|t| (t.tex_coord(), false))),
        ("emissive", material.emissive_texture().map(|t| (t.tex_coord(), t.texture_transform().is_some()))),
    ];
    let odd: Vec<&str> = maps
        .iter()
        .filter(|(_, m)| m.is_some_and(|(s, t)| s != set || t != transformed))
        .map(|(name, _)| *name)
        .collect();
    (!odd.is_empty()).then(|| {
        format!(
            "material '{}': its {} map(s) use other texture coordinates than its base colour; drawn with the base colour's",
            material.name().unwrap_or("unnamed"),
            odd.join(", ")
        )
    })
}

/// glTF extensions twister draws (the others are ignored with a note, or refused when required).
pub const GLTF_EXTENSIONS: &[&str] = &["KHR_texture_transform"];

/// The most triangles a scene may hold (`Scene::validate`'s limit, checked while mesh instances
/// are added so that a file cannot make memory grow past it).
const MAX_TRIANGLES: usize = crate::core::scenes::scene::MAX_TRIANGLES;

/// A glTF document with its buffers and decoded images.
type Document = (gltf::Document, Vec<gltf::buffer::Data>, Vec<gltf::image::Data>);

/// Reads a glTF file's document, buffers and images: every file checked before it is read,
/// the JSON checked before the gltf crate parses it (the crate panics on some invalid files).
fn read_document(path: &Path) -> std::result::Result<Document, String> {
    let bytes = super::read_file(path)?;
    let base = path.parent().unwrap_or(Path::new("."));
    // The JSON (of a .gltf, or the JSON chunk of a .glb) is checked before the gltf crate reads
    // it: the crate panics on some invalid files.
    let is_glb = bytes.starts_with(b"glTF");
    let named_glb = path.extension().is_some_and(|e| e.eq_ignore_ascii_case("glb"));
    if named_glb && !is_glb {
        return Err("not a GLB file: it does not start with 'glTF'".into());
    }
    if is_glb && bytes.len() >= 12 {
        let claimed = u32::from_le_bytes([bytes[8], bytes[9], bytes[10], bytes[11]]) as usize;
        if claimed != bytes.len() {
            return Err(format!(
                "not a readable GLB file: its header says {claimed} bytes, the file has {}",
                bytes.len()
            ));
        }
    }
    let json_bytes: std::borrow::Cow<[u8]> = if is_glb {
        gltf::Glb::from_slice(&bytes).map_err(|e| format!("not a readable GLB file: {e}"))?.json
    } else {
        std::borrow::Cow::Borrowed(&bytes[..])
    };
    if json_bytes.iter().all(u8::is_ascii_whitespace) {
        return Err("is empty: not a glTF file".into());
    }
    let json: serde_json::Value = serde_json::from_slice(&json_bytes).map_err(|e| {
        if is_glb {
            format!("the GLB's JSON chunk is not valid JSON: {e}")
        } else {
            format!("not a glTF file (invalid JSON: {e})")
        }
    })?;
    super::gltf_check::check(&json)?;
    check_external_files(&json, base)?;
    let gltf::Gltf { document: doc, mut blob } =
        gltf::Gltf::from_slice(&bytes).map_err(|e| format!("not a readable glTF file: {e}"))?;
    let mut buffers = Vec::new();
    for buffer in doc.buffers() {
        let data = gltf::buffer::Data::from_source_and_blob(buffer.source(), Some(base), &mut blob)
            .map_err(|e| format!("buffer {}: {e}", buffer.index()))?;
        if data.len() < buffer.length() {
            return Err(format!(
                "buffer {} holds {} bytes, fewer than its byteLength {}",
                buffer.index(),
                data.len(),
                buffer.length()
            ));
        }
        buffers.push(data);
    }
    let mut images = Vec::new();
    for image in doc.images() {
        let data = gltf::image::Data::from_source(image.source(), Some(base), &buffers).map_err(|e| {
            let named = match image.source() {
                gltf::image::Source::Uri { uri, .. } if !uri.starts_with("data:") => format!(" ('{uri}')"),
                _ => String::new(),
            };
            format!("image {}{named}: cannot be decoded: {e}", image.index())
        })?;
        images.push(data);
    }
    Ok((doc, buffers, images))
}

pub(super) fn read_gltf(path: &Path) -> std::result::Result<Scene, String> {
    let name = path.display().to_string();
    let (doc, buffers, images) = read_document(path)?;
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
        scene.textures.push(gltf_texture(image_label(&image), data).map_err(|e| format!("{name}: {e}"))?);
    }
    // glTF material k is scene material k; primitives without one share the spec's default
    // material (single-sided, opaque), appended at the end.
    let materials: Vec<GltfMaterial> = doc.materials().map(|m| gltf_material(&m)).collect();
    scene.materials = materials.iter().map(|m| m.0).collect();
    scene.physically_based = true;
    if let Some(p) = doc.meshes().flat_map(|m| m.primitives()).find(|p| p.material().index().is_none()) {
        scene.materials.push(gltf_material(&p.material()).0);
    }
    data_maps(&mut scene);
    for (material, (_, set, transform)) in doc.materials().zip(&materials) {
        if let Some(note) = gltf_maps_note(&material, *set, transform.is_some()) {
            scene.warnings.push(note);
        }
    }
    let root =
        doc.default_scene().or_else(|| doc.scenes().next()).ok_or_else(|| format!("{name}: the file has no scene"))?;
    // What moves, where the file animates, skins or morphs (`core::scenes::animation`).
    let mut rig = super::gltf_rig::needs_rig(&doc).then(|| super::gltf_rig::rig_nodes(&doc, &buffers));
    let mut stack: Vec<(gltf::Node, Mat4, usize, Option<usize>)> =
        root.nodes().map(|n| (n, Mat4::IDENTITY, 0, None)).collect();
    while let Some((node, parent, depth, parent_index)) = stack.pop() {
        if depth > 256 {
            return Err(format!("{name}: the node hierarchy is deeper than 256 levels"));
        }
        let world = parent * Mat4::from_cols_array_2d(&node.transform().matrix());
        if !world.is_finite() {
            return Err(format!("{name}: node {} has a NaN or infinite transform", node.index()));
        }
        if let Some(rig) = rig.as_mut() {
            rig.nodes[node.index()].parent = parent_index;
            rig.order.push(node.index());
        }
        add_node_light_and_camera(&mut scene, &node, world, rig.as_mut());
        if let Some(mesh) = node.mesh() {
            // One scene object per mesh instance (node), its primitives one after the other.
            let mesh_name = mesh.name().map_or_else(|| format!("mesh {}", mesh.index()), str::to_string);
            let instance = node.name().map_or_else(|| format!("node {}", node.index()), str::to_string);
            let objects_before = scene.objects.len();
            for prim in mesh.primitives() {
                let label = format!("{mesh_name} / primitive {}", prim.index());
                add_gltf_primitive(&mut scene, &prim, &buffers, (&node, world), &label, &materials, rig.as_mut())
                    .map_err(|e| format!("{name}: {label}: {e}"))?;
            }
            scene.merge_objects_from(objects_before, format!("{mesh_name} ({instance})"));
        }
        if scene.triangle_count() > MAX_TRIANGLES {
            return Err(format!(
                "{name}: its mesh instances hold more than {MAX_TRIANGLES} triangles, more than twister draws"
            ));
        }
        stack.extend(node.children().map(|c| (c, world, depth + 1, Some(node.index()))));
    }
    if scene.triangle_count() == 0 {
        return Err(format!("{name}: the default scene has no triangles"));
    }
    if let Some(mut rig) = rig {
        rig.clips = super::gltf_rig::clips(&doc, &buffers, &mut scene.warnings);
        // The rest pose: skinned meshes placed by their joints (glTF ignores their nodes'
        // transforms), morph targets at the meshes' default weights.
        scene.rig = Some(Box::new(rig));
        scene.pose(None, 0.0);
    }
    Ok(scene)
}

/// An image's name for messages: its own, else its file's, else its index.
fn image_label(image: &gltf::Image) -> String {
    match (image.name(), image.source()) {
        (Some(n), _) => n.to_string(),
        (None, gltf::image::Source::Uri { uri, .. }) if !uri.starts_with("data:") => uri.to_string(),
        _ => format!("image {}", image.index()),
    }
}

/// A node's punctual light and camera (placed by its `world` matrix; an animated file's rig
/// notes which scene light and camera the node carries).
fn add_node_light_and_camera(
    scene: &mut Scene,
    node: &gltf::Node,
    world: Mat4,
    mut rig: Option<&mut crate::core::scenes::animation::Rig>,
) {
    if let Some(light) = node.light() {
        if let Some(rig) = rig.as_mut() {
            rig.lights.push((scene.lights.len(), node.index(), gltf_light(&light, Mat4::IDENTITY)));
        }
        scene.lights.push(gltf_light(&light, world));
    }
    if let Some(camera) = node.camera() {
        if let Some(rig) = rig {
            rig.cameras.push((scene.cameras.len(), node.index()));
        }
        // The camera looks along its local −z.
        let forward = world.transform_vector3(-Vec3::Z);
        scene.cameras.push(crate::core::scenes::scene::Camera {
            name: camera
                .name()
                .or(node.name())
                .map_or_else(|| format!("camera {}", scene.cameras.len()), str::to_string),
            position: world.transform_point3(Vec3::ZERO).into(),
            yaw_deg: (-forward.x).atan2(-forward.z).to_degrees(),
        });
    }
}

/// Checks every external file a glTF document names (buffers, images) before anything reads
/// it: a regular file of bounded size, named in the error when it is not.
fn check_external_files(json: &serde_json::Value, base: &Path) -> std::result::Result<(), String> {
    for array in ["buffers", "images"] {
        for (i, item) in json.get(array).and_then(|a| a.as_array()).into_iter().flatten().enumerate() {
            let Some(uri) = item.get("uri").and_then(|u| u.as_str()) else { continue };
            if uri.starts_with("data:") {
                continue;
            }
            let what = if array == "buffers" { "buffer" } else { "image" };
            let decoded = percent_decode(uri);
            super::check_file(&base.join(&decoded)).map_err(|e| format!("{what} {i} file '{decoded}': {e}"))?;
        }
    }
    Ok(())
}

/// A URI's %XX escapes decoded (glTF URIs are relative references).
fn percent_decode(uri: &str) -> String {
    let bytes = uri.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        let hex = |k: usize| bytes.get(k).and_then(|b| (*b as char).to_digit(16));
        match (bytes[i], hex(i + 1), hex(i + 2)) {
            (b'%', Some(h), Some(l)) => {
                out.push((h * 16 + l) as u8);
                i += 3;
            }
            (b, _, _) => {
                out.push(b);
                i += 1;
            }
        }
    }
    String::from_utf8_lossy(&out).into_owned()
}

/// Checks that an accessor's elements lie inside its buffer view and the view inside its buffer.
fn check_accessor(acc: &gltf::Accessor, buffers: &[gltf::buffer::Data]) -> std::result::Result<(), String> {
    let count = acc.count();
    if count > (1 << 28) {
        return Err(format!("accessor {} claims {count} elements", acc.index()));
    }
    let element = acc.size();
    if let Some(view) = acc.view() {
        let bytes = view_bytes(&view, buffers)?;
        let stride = view.stride().unwrap_or(element);
        let end = stride
            .checked_mul(count.saturating_sub(1))
            .and_then(|n| n.checked_add(element))
            .and_then(|n| n.checked_add(acc.offset()));
        if end.is_none_or(|end| end > bytes.len()) {
            return Err(format!("accessor {} overruns buffer view {}", acc.index(), view.index()));
        }
    }
    if let Some(sparse) = acc.sparse() {
        // Sparse indices must lie in the accessor, values in their view.
        let n = sparse.count();
        let indices = sparse.indices();
        let size = match indices.index_type() {
            gltf::accessor::sparse::IndexType::U8 => 1,
            gltf::accessor::sparse::IndexType::U16 => 2,
            gltf::accessor::sparse::IndexType::U32 => 4,
        };
        let ib = view_bytes(&indices.view(), buffers)?;
        let ib = ib.get(indices.offset()..).and_then(|b| b.get(..n.checked_mul(size)?));
        let ib = ib.ok_or(format!(
            "accessor {}: its sparse indices overrun buffer view {}",
            acc.index(),
            sparse.indices().view().index()
        ))?;
        for k in 0..n {
            let i = match size {
                1 => ib[k] as usize,
                2 => u16::from_le_bytes([ib[2 * k], ib[2 * k + 1]]) as usize,
                _ => u32::from_le_bytes([ib[4 * k], ib[4 * k + 1], ib[4 * k + 2], ib[4 * k + 3]]) as usize,
            };
            if i >= count {
                return Err(format!("accessor {}: sparse index {i} is beyond its {count} elements", acc.index()));
            }
        }
        let values = sparse.values();
        let vb = view_bytes(&values.view(), buffers)?;
        if values.offset().checked_add(n.saturating_mul(element)).is_none_or(|end| end > vb.len()) {
            return Err(format!(
                "accessor {}: its sparse values overrun buffer view {}",
                acc.index(),
                values.view().index()
            ));
        }
    }
    Ok(())
}

/// The bytes of a buffer view, checked to lie in its buffer's data.
fn view_bytes<'a>(
    view: &gltf::buffer::View,
    buffers: &'a [gltf::buffer::Data],
) -> std::result::Result<&'a [u8], String> {
    let data = buffers.get(view.buffer().index()).map_or(&[][..], |b| &b.0[..]);
    view.offset().checked_add(view.length()).and_then(|end| data.get(view.offset()..end)).ok_or(format!(
        "buffer view {} overruns its buffer ({} bytes)",
        view.index(),
        data.len()
    ))
}

fn add_gltf_primitive(
    scene: &mut Scene,
    prim: &gltf::Primitive,
    buffers: &[gltf::buffer::Data],
    (node, world): (&gltf::Node, Mat4),
    label: &str,
    materials: &[GltfMaterial],
    rig: Option<&mut crate::core::scenes::animation::Rig>,
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
    let tangents: Option<Vec<[f32; 4]>> = reader.read_tangents().map(|r| r.collect());
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
    let indices = triangle_indices(mode, &raw);
    let attributes =
        Attributes { positions: &positions, normals: normals.as_deref(), tangents: tangents.as_deref(), uvs, colors };
    let mut vertices = attributes.placed(world, factor, material_id);
    if normals.is_none() {
        compute_normals(&mut vertices, &indices);
    }
    if let Some(rig) = rig {
        // The normals in the mesh frame: the file's, or the computed ones moved back.
        let local_normals: Vec<Vec3> = match &normals {
            Some(n) => n.iter().map(|v| Vec3::from(*v)).collect(),
            None => vertices
                .iter()
                .map(|v| world.transpose().transform_vector3(Vec3::from(v.normal)).normalize_or_zero())
                .collect(),
        };
        let first = scene.vertices.len();
        let instance = super::gltf_rig::instance(node, &reader, first, &positions, &local_normals, tangents.as_deref());
        rig.instances.push(instance);
    }
    scene.add_mesh(label, &vertices, &indices);
    Ok(())
}

/// A primitive's triangles as three indices each: a list as it is, a strip with every other
/// triangle turned back to the strip's winding, a fan around its first vertex.
fn triangle_indices(mode: gltf::mesh::Mode, raw: &[u32]) -> Vec<u32> {
    use gltf::mesh::Mode;
    match mode {
        Mode::Triangles => raw.chunks_exact(3).flatten().copied().collect(),
        Mode::TriangleStrip => (0..raw.len().saturating_sub(2))
            .flat_map(|k| if k % 2 == 0 { [raw[k], raw[k + 1], raw[k + 2]] } else { [raw[k + 1], raw[k], raw[k + 2]] })
            .collect(),
        _ => (1..raw.len().saturating_sub(1)).flat_map(|k| [raw[0], raw[k], raw[k + 1]]).collect(),
    }
}

/// A primitive's vertex attributes as read (mesh frame).
struct Attributes<'p> {
    positions: &'p [[f32; 3]],
    normals: Option<&'p [[f32; 3]]>,
    tangents: Option<&'p [[f32; 4]]>,
    uvs: Option<Vec<[f32; 2]>>,
    colors: Option<Vec<[f32; 4]>>,
}

impl Attributes<'_> {
    /// The vertices placed by the node's `world` matrix (normals by its inverse transpose),
    /// coloured by the base colour `factor`, of material `material_id`.
    fn placed(&self, world: Mat4, factor: [f32; 4], material_id: u32) -> Vec<SceneVertex> {
        let normal_matrix = world.inverse().transpose();
        // A tangent moves with the surface (the matrix itself); a mirroring matrix flips the
        // bitangent's sign, as it flips the winding.
        let mirror = if glam::Mat3::from_mat4(world).determinant() < 0.0 { -1.0 } else { 1.0 };
        (0..self.positions.len())
            .map(|i| {
                let c = self.colors.as_ref().and_then(|c| c.get(i).copied()).unwrap_or([1.0; 4]);
                SceneVertex {
                    position: world.transform_point3(Vec3::from(self.positions[i])).into(),
                    normal: self
                        .normals
                        .and_then(|v| v.get(i))
                        .map_or(Vec3::ZERO, |&v| normal_matrix.transform_vector3(Vec3::from(v)).normalize_or_zero())
                        .into(),
                    color: [0, 1, 2, 3].map(|k| c[k] * factor[k]),
                    uv: self.uvs.as_ref().and_then(|v| v.get(i)).copied().unwrap_or([0.0; 2]),
                    tangent: self.tangents.and_then(|v| v.get(i)).map_or(0, |&[x, y, z, w]| {
                        pack_tangent(world.transform_vector3(Vec3::new(x, y, z)).normalize_or_zero().extend(w * mirror))
                    }),
                    material: material_id,
                    ..Default::default()
                }
            })
            .collect()
    }
}
