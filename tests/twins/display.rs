//! The display stage's twin check (tests/twins.rs): what the live window shows of a frame, drawn
//! by the GPU into a texture, against `cpu::display` on the same texels: the panoramas scaled
//! and at their own size, the display's halves, the look-around views on each panorama, the
//! overlay, a target that encodes sRGB itself. And the frame the window shows is the one
//! `render` reads back.

use rand::{Rng, SeedableRng};
use twister::core::display::{DisplayMode, DisplayView, Look};
use twister::core::scenes::builtin;
use twister::cpu::display::display;
use twister::gpu::display::{DisplayTarget, ShownFrame};
use twister::gpu::targets::{copy_eyes_to_buffer, unpad_eyes};
use twister::{GpuScene, Projection, RenderSettings, Renderer};

use super::{common, Twin};

pub struct Display;

pub struct Case {
    projection: Projection,
    view: DisplayView,
    texels: Vec<u32>,
    overlay: Option<Vec<u32>>,
}

fn case(projection: Projection, mode: DisplayMode, target: [u32; 2], overlay: bool, srgb: bool) -> Case {
    let mut rng = rand::rngs::StdRng::seed_from_u64(7);
    let [w, h] = [projection.width, projection.height];
    let texels = (0..2 * w * h).map(|_| rng.random::<u32>() | 0xff00_0000).collect();
    let overlay_rect = overlay.then_some([5, 3, 20, 9]);
    let overlay = overlay.then(|| (0..20 * 9).map(|_| rng.random::<u32>()).collect());
    let look = Look { yaw: 0.7, pitch: -0.3, fov_deg: 100.0 };
    let view = DisplayView {
        mode,
        look,
        image: [w, h],
        layers: 2,
        row_texels: w,
        target,
        overlay: overlay_rect,
        srgb_target: srgb,
    };
    Case { projection, view, texels, overlay }
}

impl Twin for Display {
    type Case = Case;
    type Output = Vec<u32>;
    fn cases() -> Vec<(String, Case)> {
        let cylinder = Projection { width: 64, height: 24, ..Projection::default() };
        let sphere = Projection { height: 32, ..Projection::equirect(64) };
        let cube = Projection::cubemap(48);
        let fisheye = Projection::fisheye(40);
        use DisplayMode::*;
        vec![
            ("panorama at its size".into(), case(cylinder, Panorama, [64, 48], false, false)),
            ("panorama scaled, overlay".into(), case(cylinder, Panorama, [101, 77], true, false)),
            ("halves".into(), case(cylinder, Halves, [64, 48], false, false)),
            ("look-around, cylinder".into(), case(cylinder, LookSideBySide, [96, 40], false, false)),
            ("anaglyph, sphere, sRGB target".into(), case(sphere, LookAnaglyph, [80, 60], true, true)),
            ("look-around, sphere".into(), case(sphere, LookSideBySide, [96, 40], false, false)),
            ("look-around, cubemap".into(), case(cube, LookSideBySide, [96, 40], false, false)),
            ("look-around, fisheye".into(), case(fisheye, LookSideBySide, [96, 40], false, false)),
        ]
    }
    fn gpu(r: &Renderer, c: &Case) -> Vec<u32> {
        let gpu = &r.gpu;
        let texels = gpu.init_buffer("texels", bytemuck::cast_slice(&c.texels), wgpu::BufferUsages::STORAGE);
        let [w, h] = c.view.image;
        let frame = ShownFrame { texels, width: w, height: h, row_texels: w, layers: 2 };
        let overlay = c
            .overlay
            .as_ref()
            .map(|o| gpu.init_buffer("overlay", bytemuck::cast_slice(o), wgpu::BufferUsages::STORAGE));
        let format =
            if c.view.srgb_target { wgpu::TextureFormat::Rgba8UnormSrgb } else { wgpu::TextureFormat::Rgba8Unorm };
        let [tw, th] = c.view.target;
        let texture = gpu.device.create_texture(&wgpu::TextureDescriptor {
            label: Some("display target"),
            size: wgpu::Extent3d { width: tw, height: th, depth_or_array_layers: 2 },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
            view_formats: &[],
        });
        let view = texture.create_view(&wgpu::TextureViewDescriptor {
            dimension: Some(wgpu::TextureViewDimension::D2),
            array_layer_count: Some(1),
            ..Default::default()
        });
        let mut enc = gpu.device.create_command_encoder(&Default::default());
        r.display().draw(
            gpu,
            &mut enc,
            DisplayTarget { view: &view, format },
            &twister::encoding::params::display_params(&c.view, &c.projection),
            &frame,
            overlay.as_ref(),
        );
        gpu.queue.submit([enc.finish()]);
        let (buffer, stride) = copy_eyes_to_buffer(gpu, &texture, wgpu::BufferUsages::COPY_SRC);
        let [first, _] = unpad_eyes(&gpu.download(&buffer, buffer.size()).unwrap(), tw, th, stride);
        first
    }
    fn cpu(c: &Case) -> Vec<u32> {
        let overlay = c.overlay.clone().unwrap_or_default();
        display(
            &twister::encoding::params::display_params(&c.view, &c.projection),
            &c.projection,
            &c.texels,
            &overlay,
            c.view.target,
        )
    }
    fn compare(gpu: &Vec<u32>, cpu: &Vec<u32>) -> Result<(), String> {
        if gpu.len() != cpu.len() {
            return Err(format!("{} GPU pixels, {} CPU", gpu.len(), cpu.len()));
        }
        // A channel within 1 (sRGB encoding's rounding); a look-around pixel whose direction
        // falls on a texel's edge may take its neighbour (the WGSL's and Rust's arithmetic).
        let near = |a: u32, b: u32| (0..4).all(|k| ((a >> (8 * k)) & 255).abs_diff((b >> (8 * k)) & 255) <= 1);
        let differ = gpu.iter().zip(cpu).filter(|(g, c)| !near(**g, **c)).count();
        if differ * 200 > gpu.len() {
            return Err(format!("{differ} of {} pixels differ", gpu.len()));
        }
        let background = cpu.iter().filter(|&&c| c == cpu[0]).count();
        if background == cpu.len() {
            return Err("the twin shows nothing but one colour".into());
        }
        Ok(())
    }
}

/// The window's frame (`render_shown`: the colour left on the GPU) is the image `render` reads
/// back, texel for texel, for the raster and for the ray tracer, and for a sample count the
/// adapter lacks.
#[test]
fn the_shown_frame_is_the_rendered_frame() {
    let r = common::renderer();
    let scene = builtin::demo();
    let gs = GpuScene::upload(&r.gpu, &scene).unwrap().with_bvh(&r.gpu, &scene).unwrap();
    let adaptive = RenderSettings::default().subdivision.method;
    // 16 samples: beyond lavapipe's counts, box-filtered on the CPU and uploaded.
    for (method, samples) in [(adaptive, 4), (twister::core::settings::Method::Trace, 4), (adaptive, 16)] {
        let settings = RenderSettings::default()
            .with_projection(Projection {
                width: 96,
                height: 24,
                vertical: twister::Vertical::Exact,
                ..Projection::default()
            })
            .with_method(method)
            .with_samples(samples);
        let rendered = r.render(&gs, &settings).unwrap();
        let (frame, shown) = r.render_shown(&gs, &settings).unwrap();
        let counts = twister::gpu::targets::sample_counts(&r.gpu);
        if counts.contains(&samples) {
            assert!(frame.left.rgba.is_empty(), "{method:?}: the shown frame is not read back");
        }
        let bytes = r.gpu.download(&shown.texels, shown.texels.size()).unwrap();
        let [left, right] = unpad_eyes(&bytes, shown.width, shown.height, shown.row_texels);
        assert_eq!(bytemuck::cast_slice::<u32, u8>(&left), rendered.left.rgba.as_slice(), "{method:?}: left eye");
        assert_eq!(bytemuck::cast_slice::<u32, u8>(&right), rendered.right.rgba.as_slice(), "{method:?}: right eye");
    }
}
