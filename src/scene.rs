//! A scene: indexed triangles with per-vertex attributes, in world units (metres after
//! `scale`), plus the named objects they belong to.

use crate::gpu_types::{Material, SceneVertex};
use crate::texture::Texture;

/// A named range of triangles (a glTF mesh instance, an OBJ object, a built-in shape).
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Object {
    pub name: String,
    pub first_triangle: u32,
    pub triangle_count: u32,
}

#[derive(Clone, Debug, Default)]
pub struct Scene {
    pub name: String,
    pub vertices: Vec<SceneVertex>,
    /// Three indices per triangle.
    pub indices: Vec<u32>,
    pub objects: Vec<Object>,
    /// Things the loader skipped or guessed, for the user to read.
    pub warnings: Vec<String>,
    /// The file's materials; a vertex's `material` is an index here + 1 (0: the default
    /// material). Base colour factors are already in the vertex colours.
    pub materials: Vec<Material>,
    /// Decoded textures that `materials` refer to.
    pub textures: Vec<Texture>,
    /// Cameras placed in the file (glTF camera nodes), usable as the viewer.
    pub cameras: Vec<Camera>,
    /// Meshes drawn (glTF mesh instances, OBJ objects/groups, built-in shapes: one per object)
    /// and their primitives.
    pub meshes: usize,
    pub primitives: usize,
}

/// A camera placed in a scene file: where it stands and which way it looks (yaw only: the
/// panorama is level).
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Camera {
    pub name: String,
    pub position: [f32; 3],
    /// Turn about +y from looking along −z, degrees, positive to the left (as `--yaw`).
    pub yaw_deg: f32,
}

impl Scene {
    pub fn new(name: impl Into<String>) -> Self {
        Scene { name: name.into(), ..Default::default() }
    }

    pub fn triangle_count(&self) -> usize {
        self.indices.len() / 3
    }

    /// Appends a mesh as one object; `indices` refer to `vertices`.
    pub fn add_mesh(&mut self, name: impl Into<String>, vertices: &[SceneVertex], indices: &[u32]) {
        let base = self.vertices.len() as u32;
        let first = self.triangle_count() as u32;
        let object = self.objects.len() as u32;
        self.vertices.extend(vertices.iter().map(|v| SceneVertex { object, ..*v }));
        self.indices.extend(indices.iter().map(|i| i + base));
        self.objects.push(Object {
            name: name.into(),
            first_triangle: first,
            triangle_count: (indices.len() / 3) as u32,
        });
        self.meshes += 1;
        self.primitives += 1;
    }

    /// Merges the objects from index `first` on (consecutive triangle ranges) into one named
    /// object; nothing happens when there are none.
    pub fn merge_objects_from(&mut self, first: usize, name: String) {
        if first >= self.objects.len() {
            return;
        }
        let first_triangle = self.objects[first].first_triangle;
        let triangle_count = self.objects[first..].iter().map(|o| o.triangle_count).sum();
        self.meshes -= self.objects.len() - first - 1;
        self.objects.truncate(first);
        let object = first as u32;
        let range = 3 * first_triangle as usize..3 * (first_triangle + triangle_count) as usize;
        for &i in &self.indices[range] {
            self.vertices[i as usize].object = object;
        }
        self.objects.push(Object { name, first_triangle, triangle_count });
    }

    /// Checks what the GPU stages rely on: whole triangles, indices in range, finite values.
    /// The error names the problem; callers add the file name.
    pub fn validate(&self) -> Result<(), String> {
        if self.indices.len() % 3 != 0 {
            return Err(format!("index count {} is not a multiple of 3", self.indices.len()));
        }
        let n = self.vertices.len();
        if let Some((k, i)) = self.indices.iter().enumerate().find(|(_, &i)| i as usize >= n) {
            return Err(format!("triangle {} uses vertex index {i}, but there are only {n} vertices", k / 3));
        }
        for (k, v) in self.vertices.iter().enumerate() {
            if !v.position.iter().chain(&v.normal).chain(&v.color).chain(&v.uv).all(|x| x.is_finite()) {
                return Err(format!("vertex {k} has a NaN or infinite coordinate {:?}", v.position));
            }
        }
        if self.indices.len() / 3 > u32::MAX as usize / 64 {
            return Err(format!("{} triangles is more than twister can index", self.indices.len() / 3));
        }
        Ok(())
    }
}
