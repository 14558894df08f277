//! Loading scenes: built-in names, OBJ files (positions, normals, UVs, vertex colours; polygons
//! triangulated; missing normals computed) and glTF 2.0 geometry (`.gltf` with external or
//! embedded buffers, `.glb`: the default scene's node hierarchy, TRIANGLES / TRIANGLE_STRIP /
//! TRIANGLE_FAN primitives, indexed or not, sparse accessors, base colour factor × vertex colour;
//! textures are not sampled yet). Every failure is one message naming the file and the problem;
//! accessors are bounds-checked before they are read.

use std::path::Path;

use glam::{Mat4, Vec3};

use crate::builtin;
use crate::gpu_types::SceneVertex;
use crate::projection::Projection;
use crate::scene::Scene;

/// Default colour of surfaces without a material.
pub const DEFAULT_COLOR: [f32; 4] = [0.8, 0.78, 0.74, 1.0];

/// Loads a scene by name (`builtin:...`) or path.
pub fn load_scene(spec: &str, projection: &Projection) -> Result<Scene, String> {
    if spec.starts_with("builtin:") {
        return builtin::builtin_scene(spec, projection);
    }
    let path = Path::new(spec);
    let ext = path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
    let scene = match ext.as_deref() {
        Some("obj") => load_obj(path)?,
        Some("gltf") | Some("glb") => load_gltf(path)?,
        _ => {
            return Err(format!(
                "{spec}: unknown scene type (expected a .obj, .gltf or .glb file, or one of {})",
                builtin::NAMES.join(", ")
            ))
        }
    };
    scene.validate().map_err(|e| format!("{spec}: {e}"))?;
    Ok(scene)
}

/// Loads an OBJ file: every object/group becomes one scene object.
pub fn load_obj(path: &Path) -> Result<Scene, String> {
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
    scene.materials = materials.len();
    scene.textures = materials.iter().filter(|m| m.diffuse_texture.is_some()).count();
    if scene.textures > 0 {
        scene.warnings.push(format!("{} diffuse textures (map_Kd) are not drawn yet", scene.textures));
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
                uv: if m.texcoords.len() >= 2 * n { [m.texcoords[2 * i], m.texcoords[2 * i + 1]] } else { [0.0; 2] },
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

/// Loads a glTF 2.0 file's default scene (see the module doc for what is supported).
pub fn load_gltf(path: &Path) -> Result<Scene, String> {
    let name = path.display().to_string();
    if !path.is_file() {
        return Err(format!("{name}: no such file"));
    }
    let (doc, buffers, _images) = gltf::import(path).map_err(|e| format!("{name}: not a readable glTF file: {e}"))?;
    let required: Vec<&str> = doc.extensions_required().collect();
    if !required.is_empty() {
        return Err(format!("{name}: requires extensions twister does not support: {}", required.join(", ")));
    }
    let mut scene = Scene::new(name.clone());
    let used: Vec<&str> = doc.extensions_used().collect();
    if !used.is_empty() {
        scene.warnings.push(format!("optional extensions ignored: {}", used.join(", ")));
    }
    scene.materials = doc.materials().count();
    scene.textures = doc.textures().count();
    if scene.textures > 0 {
        scene.warnings.push(format!("{} textures are not drawn yet (base colour factors are)", scene.textures));
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
            scene.cameras.push(crate::scene::Camera {
                name: camera
                    .name()
                    .or(node.name())
                    .map_or_else(|| format!("camera {}", scene.cameras.len()), str::to_string),
                position: world.transform_point3(Vec3::ZERO).into(),
                yaw_deg: (-forward.x).atan2(-forward.z).to_degrees(),
            });
        }
        if let Some(mesh) = node.mesh() {
            for prim in mesh.primitives() {
                let mesh_name = mesh.name().map_or_else(|| format!("mesh {}", mesh.index()), str::to_string);
                let label = format!("{mesh_name} / primitive {}", prim.index());
                add_gltf_primitive(&mut scene, &prim, &buffers, world, &label)
                    .map_err(|e| format!("{name}: {label}: {e}"))?;
            }
        }
        stack.extend(node.children().map(|c| (c, world, depth + 1)));
    }
    if scene.triangle_count() == 0 {
        return Err(format!("{name}: the default scene has no triangles"));
    }
    Ok(scene)
}

/// Checks that an accessor's elements lie inside its buffer view and the view inside its buffer.
fn check_accessor(acc: &gltf::Accessor, buffers: &[gltf::buffer::Data]) -> Result<(), String> {
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
) -> Result<(), String> {
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
    let uvs: Option<Vec<[f32; 2]>> = reader.read_tex_coords(0).map(|r| r.into_f32().collect());
    let colors: Option<Vec<[f32; 4]>> = reader.read_colors(0).map(|r| r.into_rgba_f32().collect());
    let factor = prim.material().pbr_metallic_roughness().base_color_factor();
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
                material: prim.material().index().map_or(0, |m| m as u32 + 1),
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

/// Area-weighted vertex normals from the faces.
pub fn compute_normals(vertices: &mut [SceneVertex], indices: &[u32]) {
    let mut acc = vec![Vec3::ZERO; vertices.len()];
    for t in indices.chunks_exact(3) {
        let p = [0, 1, 2].map(|k| Vec3::from(vertices[t[k] as usize].position));
        let n = (p[1] - p[0]).cross(p[2] - p[0]);
        for &i in t {
            acc[i as usize] += n;
        }
    }
    for (v, n) in vertices.iter_mut().zip(acc) {
        v.normal = n.normalize_or_zero().into();
    }
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

impl Scene {
    /// Axis-aligned bounds of the vertices used by triangles.
    pub fn bounds(&self) -> Option<(Vec3, Vec3)> {
        let mut it = self.indices.iter().map(|&i| Vec3::from(self.vertices[i as usize].position));
        let first = it.next()?;
        Some(it.fold((first, first), |(lo, hi), p| (lo.min(p), hi.max(p))))
    }

    /// Applies an affine transform to positions and normals.
    pub fn transform(&mut self, m: Mat4) {
        let normal_matrix = m.inverse().transpose();
        for v in &mut self.vertices {
            v.position = m.transform_point3(Vec3::from(v.position)).into();
            v.normal = normal_matrix.transform_vector3(Vec3::from(v.normal)).normalize_or_zero().into();
        }
    }

    /// `--fit DIST`: moves and scales the scene so that its bounding box stands `distance` m
    /// straight ahead, centred on the eye height, its front face filling the screen height
    /// (v = R_T·y/r at the front).
    pub fn fit(&mut self, distance: f32, projection: &Projection) -> Result<(), String> {
        let (lo, hi) = self.bounds().ok_or("the scene has no triangles to fit")?;
        let size = hi - lo;
        if !(size.y > 0.0) || !(distance > projection.eye_radius) {
            return Err(format!("--fit {distance}: needs a scene with height and a distance beyond the eye circle"));
        }
        let half = projection.half_height_m();
        // Front face at depth distance − s·dz/2 spans v = ±R_T·(s·h/2)/(front depth) = ±half.
        let s = half * distance / (projection.screen_radius * size.y / 2.0 + half * size.z / 2.0);
        let center = (lo + hi) / 2.0;
        self.transform(
            Mat4::from_translation(Vec3::new(0.0, 0.0, -distance))
                * Mat4::from_scale(Vec3::splat(s))
                * Mat4::from_translation(-center),
        );
        Ok(())
    }
}
