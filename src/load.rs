//! Loading scenes: built-in names, and OBJ files (positions, normals, UVs, vertex colours;
//! polygons triangulated; missing normals computed). Materials, textures and glTF come with the
//! scene-import work. Every failure is one message naming the file and the problem.

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
        Some("gltf") | Some("glb") => {
            return Err(format!("{spec}: glTF import is not supported yet; OBJ files and built-in scenes are"))
        }
        _ => {
            return Err(format!(
                "{spec}: unknown scene type (expected a .obj file or one of {})",
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
    let (models, _materials) =
        tobj::load_obj(path, &options).map_err(|e| format!("{name}: not a readable OBJ file: {e}"))?;
    let mut scene = Scene::new(name.clone());
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
                    DEFAULT_COLOR
                },
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
