//! Renders a built-in scene with the library API and writes the top-bottom stereo image.
//!
//! `cargo run --release --example render_builtin -- builtin:demo out/example`

use twister::core::scenes::builtin;
use twister::gpu::Gpu;
use twister::output::{layout_images, write_images, Layout};
use twister::{GpuScene, RenderSettings, Renderer};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let scene_name = args.next().unwrap_or_else(|| "builtin:demo".into());
    let out = args.next().unwrap_or_else(|| "out/example".into());
    let settings = RenderSettings::default(); // 3168×600 per eye, R_T = 1 m, d_e = 0.032 m
    let scene = builtin::builtin_scene(&scene_name, &settings.view.projection)?;
    let renderer = Renderer::new(Gpu::new()?)?;
    let gpu_scene = GpuScene::upload(&renderer.gpu, &scene)?;
    let frame = renderer.render(&gpu_scene, &settings)?;
    let panorama = settings.view.projection.panorama;
    let images = layout_images(&frame, Layout::TopBottom, twister::output::ImageFormat::Png, panorama);
    for path in write_images(out.as_ref(), &images)? {
        println!("{}", path.display());
    }
    eprintln!(
        "{} triangles in, {} drawn, {:.1} ms",
        frame.stats.triangles_in, frame.stats.triangles_out, frame.stats.ms_total
    );
    Ok(())
}
