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

mod gltf;
mod obj;

use std::path::Path;

use glam::Vec3;

use crate::core::builtin;
use crate::core::projection::Projection;
use crate::core::scene::Scene;
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
pub(crate) fn scene_error(name: &str, message: String) -> Error {
    let message = message.strip_prefix(&format!("{name}: ")).map(str::to_string).unwrap_or(message);
    Error::scene(name, message)
}

/// Loads an OBJ file: every object/group becomes one scene object.
pub fn load_obj(path: &Path) -> Result<Scene> {
    obj::read_obj(path).map_err(|m| scene_error(&path.display().to_string(), m))
}

/// Loads a glTF 2.0 file's default scene (see the module doc for what is supported).
pub fn load_gltf(path: &Path) -> Result<Scene> {
    gltf::read_gltf(path).map_err(|m| scene_error(&path.display().to_string(), m))
}
/// along −z at it). Returns the position and "inside" or "in front".
/// A viewer position to suggest for a scene: inside it at standing height if it surrounds a
/// person (over 4 m across on the ground), else 3 object sizes in front of it (+z side, looking
pub fn suggested_viewer(scene: &Scene) -> Option<([f32; 3], &'static str)> {
    let (lo, hi) = scene.bounds()?;
    let (size, c) = (hi - lo, (lo + hi) / 2.0);
    if size.x > 4.0 && size.z > 4.0 {
        Some(([c.x, lo.y + 1.7, c.z], "inside"))
    } else {
        Some(([c.x, c.y, hi.z + 3.0 * size.max_element()], "in front"))
    }
}
