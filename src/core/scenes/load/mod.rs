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
mod gltf_check;
mod gltf_rig;
mod obj;

use std::path::Path;

use crate::core::panoramas::projection::Projection;
use crate::core::scenes::builtin;
use crate::core::scenes::scene::Scene;
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
    let mut scene = match ext.as_deref() {
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
    scene.mark_sides();
    // Tangents for normal maps where the file gives none (a moving scene keeps the
    // derivatives' frame: its rig poses only the file's tangents).
    if scene.rig.is_none() {
        let wants: Vec<bool> = std::iter::once(false)
            .chain(scene.materials.iter().map(|m| m.normal_texture != crate::core::shading::material::NO_TEXTURE))
            .collect();
        crate::core::scenes::scene::generate_tangents(&mut scene.vertices, &scene.indices, |m| {
            wants.get(m as usize).copied().unwrap_or(false)
        });
    }
    Ok(scene)
}

/// The largest file a scene may be or name (scene, MTL, buffer, image), bytes: memory stays
/// bounded whatever a file claims.
pub const MAX_FILE_BYTES: u64 = 1 << 30;

/// Checks that `path` is a regular file (links followed) of at most [`MAX_FILE_BYTES`]: not a
/// folder, device, pipe or socket, which could be endless.
pub(crate) fn check_file(path: &Path) -> std::result::Result<u64, String> {
    let meta = std::fs::metadata(path).map_err(|e| match e.kind() {
        std::io::ErrorKind::NotFound => "no such file".to_string(),
        _ => format!("cannot be read: {e}"),
    })?;
    if meta.is_dir() {
        return Err("is a folder, not a file".into());
    }
    if !meta.is_file() {
        return Err("is not a regular file (a device, pipe or socket?)".into());
    }
    if meta.len() > MAX_FILE_BYTES {
        return Err(format!("is {} MiB, more than the {} MiB twister reads", meta.len() >> 20, MAX_FILE_BYTES >> 20));
    }
    Ok(meta.len())
}

/// Reads a whole file after [`check_file`], never more than [`MAX_FILE_BYTES`].
pub(crate) fn read_file(path: &Path) -> std::result::Result<Vec<u8>, String> {
    use std::io::Read;
    check_file(path)?;
    let mut bytes = Vec::new();
    std::fs::File::open(path)
        .and_then(|f| f.take(MAX_FILE_BYTES + 1).read_to_end(&mut bytes))
        .map_err(|e| format!("cannot be read: {e}"))?;
    if bytes.len() as u64 > MAX_FILE_BYTES {
        return Err(format!("is more than the {} MiB twister reads", MAX_FILE_BYTES >> 20));
    }
    Ok(bytes)
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
