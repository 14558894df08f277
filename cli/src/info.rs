//! `twister info`: a scene file described as JSON.

use clap::Args;

use twister::core::scenes::load::{load_scene, suggested_viewer};
use twister::error::{Error, Result};
use twister::Projection;

#[derive(Args)]
pub struct InfoArgs {
    /// Scene: a .obj, .gltf or .glb file, or a built-in scene.
    pub scene: String,
}

pub fn info(args: &InfoArgs) -> Result<()> {
    let scene = load_scene(&args.scene, &Projection::default())?;
    let (lo, hi) = scene.bounds().ok_or_else(|| Error::scene(&args.scene, "no triangles"))?;
    let suggestion = suggested_viewer(&scene);
    let json = serde_json::json!({
        "scene": args.scene,
        "triangles": scene.triangle_count(),
        "vertices": scene.vertices.len(),
        "objects": scene.objects.len(),
        "meshes": scene.meshes,
        "primitives": scene.primitives,
        "materials": scene.materials.len(),
        "textures": scene.textures.iter().map(|t| serde_json::json!({ "name": t.name, "width": t.width, "height": t.height })).collect::<Vec<_>>(),
        "bbox": { "min": lo.to_array(), "max": hi.to_array() },
        "cameras": scene.cameras,
        "lights": scene.lights.iter().map(|l| serde_json::json!({
            "kind": l.kind,
            "position": l.position.to_array(),
            "direction": l.direction.to_array(),
            "color_intensity": l.color.to_array(),
            "range": l.range,
        })).collect::<Vec<_>>(),
        "warnings": scene.warnings,
        "suggested_viewer": suggestion.map(|(p, where_)| serde_json::json!({ "position": p, "where": where_ })),
    });
    println!("{}", serde_json::to_string_pretty(&json).unwrap());
    Ok(())
}
