//! Rendered images against independent oracles: where the CPU projection says things are.

mod common;

use glam::Vec3;
use twister::core::scenes::builtin::{self, SEAM_SPHERE_RADIUS};
use twister::core::scenes::scene::SceneVertex;
use twister::core::settings::{Method, Split};
use twister::EyeImage;
use twister::{Eye, Projection, RenderSettings, Scene, Vertical};

fn small() -> Projection {
    Projection { width: 960, height: 180, ..Projection::default() }
}

/// Centroid (x, y) of the non-background pixels; x is unwrapped around `around_x`.
fn centroid(img: &EyeImage, bg: [f32; 3], around_x: f32) -> (f32, f32, usize) {
    let px = common::pixels_where(img, |p| !common::is_background(p, bg));
    let w = img.width as f32;
    let (mut sx, mut sy) = (0.0f64, 0.0f64);
    for &(x, y) in &px {
        let xc = x as f32 + 0.5;
        let d = (xc - around_x + w / 2.0).rem_euclid(w) - w / 2.0;
        sx += (around_x + d) as f64;
        sy += (y as f32 + 0.5) as f64;
    }
    let n = px.len().max(1) as f64;
    ((sx / n) as f32, (sy / n) as f32, px.len())
}

#[test]
fn sphere100_centroid_lies_where_the_oracle_projects_its_centre() {
    let projection = small();
    let scene = twister::core::scenes::builtin::builtin_scene("builtin:sphere100", &projection).unwrap();
    let settings = RenderSettings::new(projection);
    let frame = common::render(&scene, &settings);
    let center = Vec3::new(0.0, 0.0, -3.0);
    for eye in Eye::BOTH {
        let p = projection.project(center, eye).unwrap();
        let [ox, oy] = projection.to_pixel(p.u, p.v);
        let (cx, cy, n) = centroid(frame.eye(eye), settings.shading.background, ox);
        assert!(n > 1000, "{eye:?}: the sphere covers only {n} pixels");
        assert!(
            (cx - ox).abs() < 1.0 && (cy - oy).abs() < 1.0,
            "{eye:?}: centroid ({cx}, {cy}) vs oracle ({ox}, {oy})"
        );
    }
}

#[test]
fn disparity_has_the_right_sign_and_size() {
    // A small sphere straight ahead at several distances: the centroid difference between the
    // eyes (right − left) must be 2·α(D) in pixels: negative nearer than the screen, zero on it,
    // positive beyond.
    let projection = Projection { width: 1600, height: 200, ..Projection::default() };
    let settings = RenderSettings::new(projection);
    for distance in [0.5f32, 1.0, 5.0] {
        // Same angular size at every distance (about 40 px across).
        let radius = distance * 0.075;
        let scene = builtin::sphere_scene(1024, Vec3::new(0.0, 0.0, -distance), radius, "probe");
        let frame = common::render(&scene, &settings);
        let mid = projection.width as f32 / 2.0;
        let (l, _, nl) = centroid(&frame.left, settings.shading.background, mid);
        let (r, _, nr) = centroid(&frame.right, settings.shading.background, mid);
        assert!(nl > 200 && nr > 200);
        let expected = 2.0 * projection.eye_shift(distance) * projection.pixels_per_radian();
        let got = r - l;
        assert!((got - expected).abs() < 0.5, "at {distance} m: disparity {got} px, expected {expected} px");
        match distance {
            d if d < 1.0 => assert!(got < -5.0, "crossed disparity in front of the screen"),
            d if d > 1.0 => assert!(got > 5.0, "uncrossed disparity beyond the screen"),
            _ => assert!(got.abs() < 0.5),
        }
    }
}

fn is_seam_sphere(p: [u8; 4]) -> bool {
    // Magenta: red and blue high and alike, green low.
    let (r, g, b) = (p[0] as i32, p[1] as i32, p[2] as i32);
    r > 60 && b > 60 && (r - b).abs() < 12 && g * 3 < r
}

#[test]
fn seam_sphere_appears_at_both_edges_and_nowhere_between() {
    for vertical in [Vertical::Paper, Vertical::Exact] {
        let projection = Projection { vertical, ..small() };
        let frame = common::render(&builtin::demo(), &RenderSettings::new(projection));
        let w = projection.width as f32;
        for eye in Eye::BOTH {
            let px = common::pixels_where(frame.eye(eye), is_seam_sphere);
            assert!(!px.is_empty(), "{eye:?}: seam sphere not drawn");
            // Its angular half-width seen from the axis, plus the eye shift and a margin.
            let half = (SEAM_SPHERE_RADIUS / 5.0).asin() + projection.eye_shift(5.0).abs();
            let max_dx = half * projection.pixels_per_radian() + 2.0;
            let left_edge = px.iter().filter(|(x, _)| (*x as f32) < w / 2.0).count();
            let right_edge = px.len() - left_edge;
            assert!(
                left_edge > 50 && right_edge > 50,
                "{eye:?}: {left_edge} px at the left edge, {right_edge} at the right"
            );
            for &(x, y) in &px {
                let from_seam = (x as f32 + 0.5).min(w - (x as f32 + 0.5));
                assert!(from_seam <= max_dx, "{eye:?}: seam-sphere pixel at ({x}, {y}), {from_seam} px from the seam");
            }
        }
    }
}

fn flat_triangle(p: [[f32; 3]; 3], color: [f32; 4]) -> Scene {
    let v: Vec<SceneVertex> =
        p.iter().map(|&q| SceneVertex { position: q, normal: [0.0, 1.0, 0.0], color, ..Default::default() }).collect();
    let mut s = Scene::new("probe");
    s.add_mesh("probe", &v, &[0, 1, 2]);
    s
}

#[test]
fn triangle_around_the_axis_covers_every_column_below_the_horizon_without_smear() {
    // A floor triangle 1.5 m below the eyes containing the vertical axis.
    let projection = small();
    let scene = flat_triangle([[-20.0, -1.5, 15.0], [20.0, -1.5, 15.0], [0.0, -1.5, -25.0]], [0.2, 0.9, 0.3, 1.0]);
    let settings = RenderSettings::new(projection);
    let frame = common::render(&scene, &settings);
    for eye in Eye::BOTH {
        let img = frame.eye(eye);
        let px = common::pixels_where(img, |p| !common::is_background(p, settings.shading.background));
        let mid_row = projection.height as f32 / 2.0;
        // Nothing at or above the horizon (a smear would cross it).
        assert!(px.iter().all(|&(_, y)| y as f32 + 0.5 > mid_row), "{eye:?}: floor pixels above the horizon");
        // Every column has floor at the bottom row (nothing dropped, no gap at the seam).
        for x in 0..projection.width {
            assert!(
                !common::is_background(img.pixel(x, projection.height - 1), settings.shading.background),
                "{eye:?}: column {x} has no floor"
            );
        }
    }
}

#[test]
fn triangle_reaching_inside_the_eye_circle_renders_without_nan_or_smear() {
    let projection = small();
    let settings = RenderSettings::new(projection);
    // One corner 1 cm from the axis (inside the 3.2 cm eye circle), the far edge 2 m ahead.
    let scene = flat_triangle([[0.01, -0.5, 0.0], [2.0, -0.5, -2.0], [-2.0, -0.5, -2.0]], [0.9, 0.6, 0.1, 1.0]);
    let frame = common::render(&scene, &settings);
    for eye in Eye::BOTH {
        let px = common::pixels_where(frame.eye(eye), |p| !common::is_background(p, settings.shading.background));
        assert!(px.len() > 500, "{eye:?}: triangle not drawn");
        // The triangle spans azimuths of at most ±(90° + its near-axis part); it never reaches
        // straight behind (θ = ±π), so the outer quarter of columns at each edge stays empty.
        let w = projection.width;
        assert!(px.iter().all(|&(x, _)| x > w / 8 && x < w - w / 8), "{eye:?}: pixels smeared towards the seam");
        assert!(
            px.iter().all(|&(_, y)| y as f32 + 0.5 > projection.height as f32 / 2.0),
            "{eye:?}: pixels above the horizon"
        );
    }
}

#[test]
fn scene_too_big_for_the_memory_budget_is_drawn_in_chunks_without_loss() {
    let scene = builtin::demo();
    // Wide: no triangle asks for cuts around the axis. Square: the floor and the ceiling near the
    // axis show, and the cuts they ask for hold in every chunk.
    // And with four samples per pixel: the multisampled colour is kept across the chunks.
    for (projection, edge_px, cut, samples) in [
        (Projection { width: 960, height: 180, ..Projection::default() }, 2.0, false, 1),
        (Projection { width: 256, height: 256, ..Projection::default() }, 2.5, true, 1),
        (Projection { width: 256, height: 256, ..Projection::default() }, 2.5, true, 4),
        // The full sphere: pieces drawn in rows, whose row items share the index buffer with
        // the triangles of the pieces written in place.
        (Projection::equirect(256), 2.5, true, 1),
    ] {
        let roomy = RenderSettings::new(projection)
            .with_method(Method::Adaptive(Split::Length))
            .with_edge_px(edge_px)
            .with_samples(samples);
        let params = twister::encoding::subdivide::subdivide_params(&roomy, 0, scene.triangle_count() as u32);
        let cuts = twister::cpu::subdivide::Subdivider::new(&params).active_cuts(&scene.vertices, &scene.indices).axis;
        assert_eq!(cuts != 0, cut, "{projection:?}: cuts {cuts:#x}");
        let tight = roomy.with_memory_mb(8);
        let a = common::render(&scene, &roomy);
        let b = common::render(&scene, &tight);
        assert_eq!(a.stats.chunks, 1);
        assert!(b.stats.chunks > 1, "8 MiB should not hold {} triangles at once", b.stats.triangles_out);
        assert_eq!(a.stats.triangles_out, b.stats.triangles_out, "chunking lost or added triangles");
        for eye in Eye::BOTH {
            let differ = a.eye(eye).rgba.chunks(4).zip(b.eye(eye).rgba.chunks(4)).filter(|(p, q)| p != q).count();
            // Equal-depth fragments (seam copies, shared edges) may resolve in another order.
            assert!(
                differ * 1000 < a.eye(eye).rgba.len() / 4,
                "{eye:?}: {differ} pixels differ between one chunk and many"
            );
        }
    }
}

#[test]
fn a_triangle_far_away_is_drawn_by_every_method() {
    // 100 km to 100,000 km ahead, spanning ±20°: its depth would round to 1 (the cleared depth)
    // at some pixels without MAX_DEPTH, and the `Less` test would drop them.
    let projection = Projection { vertical: Vertical::Exact, ..small() };
    for d in [1e5f32, 1e6, 1e8] {
        let s = 0.36 * d;
        let scene = flat_triangle([[-s, -s, -d], [s, -s, -d], [0.0, s, -d]], [1.0, 1.0, 1.0, 1.0]);
        let coverage = |method: Method| {
            let settings = RenderSettings::new(projection).with_method(method);
            let frame = common::render(&scene, &settings);
            common::pixels_where(&frame.left, |p| !common::is_background(p, settings.shading.background)).len()
        };
        let (vertex, adaptive, slit) =
            (coverage(Method::Vertex), coverage(Method::Adaptive(Split::Length)), coverage(Method::Slit(1)));
        eprintln!("{d} m: vertex {vertex}, adaptive {adaptive}, slit:1 {slit} pixels");
        // The exact shape has curved edges: adaptive and slit:1 agree; vertex (straight edges)
        // differs, but draws too.
        assert!(vertex > 1000 && adaptive > 1000, "{d} m: vertex {vertex}, adaptive {adaptive}");
        assert!(
            (slit as f32 - adaptive as f32).abs() < 0.02 * adaptive as f32,
            "{d} m: slit:1 {slit}, adaptive {adaptive}"
        );
    }
}

#[test]
fn a_frame_that_first_needs_the_cut_passes_is_drawn_with_them() {
    // The cut passes (`plan_cuts`) are built when a frame first needs them: the first frame of
    // each panorama asks the GPU beforehand; a later frame that needed them unbuilt is drawn
    // again once they are. A wide cylinder keeps the demo room's floor beyond its rows (no cuts);
    // a square one shows it, and the floor near the axis is cut.
    use twister::core::settings::Method;
    let scene = builtin::demo();
    let wide = RenderSettings::new(Projection { width: 960, height: 180, ..Projection::default() });
    let square = RenderSettings::new(Projection { width: 256, height: 256, ..Projection::default() })
        .with_method(Method::Adaptive(Split::Length));
    let cut = |f: &twister::Frame| f.stats.subdivide_invocations.iter().any(|&(e, n)| e == "plan_cuts" && n > 0);
    let fresh = || twister::Renderer::new(twister::gpu::Gpu::new().expect("GPU")).expect("renderer");
    let (later, first) = (fresh(), fresh());
    let upload = |r: &twister::Renderer| twister::GpuScene::upload(&r.gpu, &scene).expect("upload");
    let (on_later, on_first) = (upload(&later), upload(&first));
    let before = later.render(&on_later, &wide.with_method(Method::Adaptive(Split::Length))).expect("render");
    assert!(!cut(&before), "the wide frame should need no cuts");
    let a = later.render(&on_later, &square).expect("render");
    let b = first.render(&on_first, &square).expect("render");
    assert!(cut(&a) && cut(&b), "the square frame should cut the floor");
    assert_eq!(a.stats.triangles_out, b.stats.triangles_out);
    for eye in Eye::BOTH {
        assert!(a.eye(eye).rgba == b.eye(eye).rgba, "{eye:?}: the frame drawn again differs from the first");
    }
}

/// Writes `texels` (both eyes, rows of `w` texels of `bytes` bytes) into a two-layer target.
fn fill_eyes(gpu: &twister::gpu::Gpu, texture: &wgpu::Texture, texels: &[u8], bytes: u32) {
    let (w, h) = (texture.width(), texture.height());
    gpu.queue.write_texture(
        wgpu::TexelCopyTextureInfo {
            texture,
            mip_level: 0,
            origin: wgpu::Origin3d::ZERO,
            aspect: wgpu::TextureAspect::All,
        },
        texels,
        wgpu::TexelCopyBufferLayout { offset: 0, bytes_per_row: Some(bytes * w), rows_per_image: Some(h) },
        wgpu::Extent3d { width: w, height: h, depth_or_array_layers: 2 },
    );
}

#[test]
fn targets_read_back_each_eyes_rows_unpadded_through_the_kept_buffer() {
    let gpu = &common::renderer().gpu;
    // Rows of 37 texels (148 bytes, padded to 256 in the copy), then a second size.
    for (w, h) in [(37u32, 5u32), (70, 9)] {
        let targets = twister::gpu::targets::Targets::new(gpu, w, h, false, false, 1);
        let n = (w * h) as usize;
        // Every texel of both eyes distinct: eye k, row y, column x.
        let word = |k: usize, i: usize| (k * 1_000_000 + i * 7 + 3) as u32;
        let words: Vec<u32> = (0..2).flat_map(|k| (0..n).map(move |i| word(k, i))).collect();
        fill_eyes(gpu, &targets.object, bytemuck::cast_slice(&words), 4);
        let colors: Vec<u8> = (0..2 * n * 4).map(|i| (i * 13 % 251) as u8).collect();
        fill_eyes(gpu, &targets.color, &colors, 4);
        // Colour, objects, colour again: the narrow targets share one kept buffer.
        for _ in 0..2 {
            let eyes = targets.read_colors(gpu).unwrap();
            for (k, eye) in eyes.iter().enumerate() {
                assert_eq!((eye.width, eye.height), (w, h));
                assert_eq!(eye.rgba, colors[k * n * 4..(k + 1) * n * 4], "{w}×{h}: eye {k}'s colour");
            }
            let objects = targets.read_objects(gpu).unwrap();
            for (k, eye) in objects.iter().enumerate() {
                assert_eq!(*eye, (0..n).map(|i| word(k, i)).collect::<Vec<_>>(), "{w}×{h}: eye {k}'s objects");
            }
        }
    }
}
