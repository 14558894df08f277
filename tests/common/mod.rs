//! Shared helpers for the integration tests: one GPU renderer per test binary.
#![allow(dead_code)]

use std::sync::OnceLock;

use twister::gpu::Gpu;
use twister::renderer::{EyeImage, Frame};
use twister::{GpuScene, RenderSettings, Renderer, Scene};

pub fn renderer() -> &'static Renderer {
    static R: OnceLock<Renderer> = OnceLock::new();
    R.get_or_init(|| {
        // Quiet Mesa's device-select layer when XDG_RUNTIME_DIR is unset.
        if std::env::var_os("XDG_RUNTIME_DIR").is_none() {
            unsafe { std::env::set_var("NODEVICE_SELECT", "1") };
        }
        Renderer::new(Gpu::new().unwrap_or_else(|e| panic!("{e}")))
    })
}

pub fn render(scene: &Scene, settings: &RenderSettings) -> Frame {
    let r = renderer();
    let gs = GpuScene::upload(&r.gpu, scene).expect("upload");
    r.render(&gs, settings).expect("render")
}

/// Pixels of an image matching a predicate, as (x, y).
pub fn pixels_where(img: &EyeImage, f: impl Fn([u8; 4]) -> bool) -> Vec<(u32, u32)> {
    let mut out = Vec::new();
    for y in 0..img.height {
        for x in 0..img.width {
            if f(img.pixel(x, y)) {
                out.push((x, y));
            }
        }
    }
    out
}

pub fn is_background(px: [u8; 4], bg: [f32; 3]) -> bool {
    (0..3).all(|c| (px[c] as f32 - bg[c] * 255.0).abs() <= 1.0)
}
