//! Ports a glTF (or OBJ) scene to the TWISTER display's images with the library API: the file's
//! first camera is the viewer if it has one, else the suggested viewer; the four 1584×600 images
//! (front and back half of each eye) are written as the paper fed the display.
//!
//! `cargo run --release --example port_gltf -- ../shared/assets/gltf/Duck/glTF-Binary/Duck.glb out/duck`

use glam::Vec3;
use twister::core::scenes::load::{load_scene, suggested_viewer};
use twister::gpu::Gpu;
use twister::output::{layout_images, write_images, Layout};
use twister::{GpuScene, RenderSettings, Renderer};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let file = args.next().ok_or("usage: port_gltf SCENE.gltf|.glb|.obj [OUT_DIR]")?;
    let out = args.next().unwrap_or_else(|| "out/port".into());
    let mut settings = RenderSettings::default(); // 3168×600 per eye, R_T = 1 m, d_e = 0.032 m, adaptive
    let scene = load_scene(&file, &settings.view.projection)?;
    for w in &scene.warnings {
        eprintln!("note: {w}");
    }
    if let Some(cam) = scene.cameras.first() {
        settings.view.viewer = Vec3::from(cam.position);
        settings.view.yaw_deg = cam.yaw_deg;
    } else if let Some((position, _)) = suggested_viewer(&scene) {
        settings.view.viewer = Vec3::from(position);
    }
    let renderer = Renderer::new(Gpu::new()?)?;
    let gpu_scene = GpuScene::upload(&renderer.gpu, &scene)?;
    let frame = renderer.render(&gpu_scene, &settings)?;
    for path in write_images(
        out.as_ref(),
        &layout_images(&frame, Layout::Twister, twister::output::ImageFormat::Png, settings.projection().panorama),
    )? {
        println!("{}", path.display());
    }
    Ok(())
}
