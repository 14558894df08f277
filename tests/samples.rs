//! Samples per pixel (`--samples`, issue 33): each pixel of the colour image shows the average of
//! its samples' linear colours. Checked against the closed form: an emissive wall whose vertical
//! edge (a vertical line in the panorama, on the cylinder and on the sphere alike) crosses a pixel
//! at a known fraction covers that share of it; and bad sample counts are one clear line.

mod common;

use glam::Vec3;
use twister::core::panoramas::projection::{Eye, Projection, Vertical};
use twister::core::scenes::scene::SceneVertex;
use twister::core::settings::Method;
use twister::core::shading::color::srgb_to_linear;
use twister::core::shading::material::Material;
use twister::{RenderSettings, Scene};

/// An emissive white wall 2 m ahead (black base colour, no lights: its colour is its emission),
/// from x = `left` to 4 m right of it, 2 m high, on a black background.
fn wall(left: f32) -> Scene {
    let mut scene = Scene::new("emissive wall");
    scene.materials = vec![Material { emissive_r: 1.0, emissive_g: 1.0, emissive_b: 1.0, ..Default::default() }];
    let corner = |x: f32, y: f32| SceneVertex {
        position: [x, y, -2.0],
        normal: [0.0, 0.0, 1.0],
        color: [0.0, 0.0, 0.0, 1.0],
        material: 1,
        ..Default::default()
    };
    let v = [corner(left, 1.0), corner(left + 4.0, 1.0), corner(left + 4.0, -1.0), corner(left, -1.0)];
    scene.add_mesh("wall", &v, &[0, 3, 2, 0, 2, 1]);
    scene.physically_based = true;
    scene
}

/// Over walls whose edge falls at many fractions of a pixel, both eyes, rows about the horizon:
/// (mean, worst) of |measured − exact| coverage of the edge's pixel, where measured is the
/// pixel's linear value over the wall's inside (two columns on), exact the share of the pixel
/// right of the edge.
fn coverage_error(projection: Projection, method: Method, samples: u32) -> (f64, f64) {
    let panorama = projection.panorama.name();
    let settings = RenderSettings::new(projection)
        .with_method(method)
        .with_ambient(0.0)
        .with_background([0.0; 3])
        .with_samples(samples);
    let (mut sum, mut worst, mut n) = (0.0f64, 0.0f64, 0);
    // Edges at 12 fractions of a pixel (the ray tracer: 6, every other one).
    let step = if method == Method::Trace { 2 } else { 1 };
    for k in (0..12).step_by(step) {
        let left = -0.4 + 0.0137 * k as f32;
        let frame = common::render(&wall(left), &settings);
        for (eye, image) in [(Eye::Left, &frame.left), (Eye::Right, &frame.right)] {
            let p = projection.project(Vec3::new(left, 0.0, -2.0), eye).expect("seen");
            let x = projection.to_pixel(p.u, p.v)[0];
            let column = x.floor() as u32;
            let exact = (column as f32 + 1.0 - x) as f64;
            let middle = projection.height / 2;
            for row in middle - 3..middle + 3 {
                let linear = |c: u32| srgb_to_linear(image.pixel(c, row)[0] as f32 / 255.0) as f64;
                let inside = linear(column + 2);
                assert!(inside > 0.5, "{panorama}: the wall's inside is lit ({inside})");
                assert!(linear(column - 1) < 1e-3, "{panorama}: left of the edge is background");
                let error = (linear(column) / inside - exact).abs();
                sum += error;
                worst = worst.max(error);
                n += 1;
            }
        }
    }
    (sum / n as f64, worst)
}

/// The projection methods multisample, the ray tracer traces a ray per sample position: both
/// count the share of an edge's pixel the surface covers.
#[test]
fn a_pixel_shows_the_share_of_it_a_surface_covers() {
    // The ray tracer takes the cylinder's exact vertical model only.
    let cylinder = Projection { width: 256, height: 64, vertical: Vertical::Exact, ..Projection::default() };
    let cases = [cylinder, Projection::equirect(256)]
        .into_iter()
        .flat_map(|p| [(p, Method::Adaptive(Default::default())), (p, Method::Trace)]);
    for (projection, method) in cases {
        let panorama = projection.panorama.name();
        let (mean1, _) = coverage_error(projection, method, 1);
        let (mean4, worst4) = coverage_error(projection, method, 4);
        let (mean16, worst16) = coverage_error(projection, method, 16);
        eprintln!(
            "{panorama}, {method:?}: coverage error, 1 sample mean {mean1:.3}; 4 samples mean {mean4:.3}, worst {worst4:.3}; \
             16 mean {mean16:.3}, worst {worst16:.3}"
        );
        // One sample: the pixel is all or nothing (the mean error of an edge at a uniform
        // fraction is 1/4). Four: the standard pattern's columns at 1/8, 3/8, 5/8, 7/8 of the
        // pixel count the share to within 1/8 (mean 1/16), plus the sRGB target's rounding.
        // Sixteen (four per pixel of a 2×2 larger image where the adapter has no 16): eight
        // columns, within 1/16 (mean 1/32).
        // The ray tracer's sixteen are the standard 16 pattern: sixteen columns, within 1/32.
        let what = format!("{panorama}, {method:?}");
        assert!(mean1 > 0.15, "{what}: one sample, mean {mean1}");
        assert!(worst4 <= 0.13 && mean4 <= 0.08, "{what}: four samples, mean {mean4}, worst {worst4}");
        assert!(worst16 <= 0.07 && mean16 <= 0.05, "{what}: sixteen samples, mean {mean16}, worst {worst16}");
    }
}

/// The pixels the multisampled colour does not touch stay as one sample draws them, for the
/// projection methods and the slit mosaic alike: in rows about the horizon only the columns the
/// wall's two sides cross change.
#[test]
fn samples_change_only_the_edges() {
    let projection = Projection { width: 256, height: 64, ..Projection::default() };
    let scene = wall(-0.35);
    for method in [Method::Adaptive(Default::default()), Method::Vertex, Method::Slit(4)] {
        let settings =
            RenderSettings::new(projection).with_ambient(0.0).with_background([0.1, 0.2, 0.3]).with_method(method);
        let one = common::render(&scene, &settings);
        let four = common::render(&scene, &settings.with_samples(4));
        for (a, b) in [(&one.left, &four.left), (&one.right, &four.right)] {
            let middle = a.height / 2;
            for y in middle - 3..middle + 3 {
                let changed: Vec<u32> = (0..a.width).filter(|&x| a.pixel(x, y) != b.pixel(x, y)).collect();
                // One column a side, or two where a side lies near a column's border.
                assert!((2..=4).contains(&changed.len()), "{method:?} row {y}: columns {changed:?} changed");
            }
        }
    }
}

/// What must not be averaged stays one sample at each pixel's centre whatever `--samples`: the
/// depth, the error pass's error and objects, the linear HDR colour, bit for bit as with one
/// sample; and the display colour drawn beside them is the multisampled one, as without them
/// (4 samples: the adapter's own; 16: a larger image where the adapter has no 16).
#[test]
fn depth_error_and_hdr_stay_at_the_pixels_centre() {
    let projection = Projection { width: 256, height: 64, ..Projection::default() };
    let base = RenderSettings::new(projection).with_ambient(0.0).with_background([0.0; 3]);
    let measured = base.with_depth(true).with_measure_error(true).with_hdr(true);
    let scene = wall(-0.35);
    let one = common::render(&scene, &measured);
    let bits = |v: &[Vec<f32>; 2]| -> Vec<u32> { v.iter().flatten().map(|x| x.to_bits()).collect() };
    let hdr = |f: &twister::Frame| -> Vec<u32> {
        f.hdr.as_ref().unwrap().iter().flatten().flatten().map(|x| x.to_bits()).collect()
    };
    for samples in [4, 16] {
        let many = common::render(&scene, &measured.with_samples(samples));
        let plain = common::render(&scene, &base.with_samples(samples));
        assert_eq!(bits(one.depth.as_ref().unwrap()), bits(many.depth.as_ref().unwrap()), "{samples}: depth");
        let (m1, m) = (one.measurement.as_ref().unwrap(), many.measurement.as_ref().unwrap());
        assert_eq!(bits(&m1.error), bits(&m.error), "{samples}: error");
        assert_eq!(m1.object, m.object, "{samples}: objects");
        assert_eq!(hdr(&one), hdr(&many), "{samples}: linear colour");
        assert!(many.left.rgba == plain.left.rgba && many.right.rgba == plain.right.rgba, "{samples}: colour");
        assert!(one.left.rgba != many.left.rgba, "{samples}: the colour is multisampled");
        assert_eq!(many.stats.samples, samples);
    }
}

/// Samples the adapter lacks are made up by a larger image; one beyond the adapter's largest
/// image is refused with one error naming the setting, not drawn.
#[test]
fn samples_beyond_the_adapter_need_an_image_it_can_draw() {
    let max = common::renderer().gpu.limits.max_texture_dimension_2d;
    let counts = twister::gpu::targets::sample_counts(&common::renderer().gpu);
    if counts.contains(&16) {
        eprintln!("the adapter draws 16 samples itself: nothing made up to refuse");
        return;
    }
    if max > twister::core::panoramas::projection::MAX_IMAGE_SIDE {
        eprintln!("the adapter's images are larger than a frame may be: no made-up image to refuse");
        return;
    }
    let projection = Projection { width: max, height: 16, ..Projection::default() };
    let settings = RenderSettings::new(projection).with_samples(16);
    let gs = twister::GpuScene::upload(&common::renderer().gpu, &wall(-0.35)).unwrap();
    let err = common::renderer().render(&gs, &settings).err().expect("refused").to_string();
    assert!(err.contains("shading.samples") && err.contains("larger image"), "{err}");
}

/// `wall(left)` with its alpha: BLEND with the vertex colours' alpha `alpha`, or MASK (cutoff
/// 1/2) with a texture of two texels, alpha 0 then 1, filtered linearly across the wall: the
/// cutoff's line runs down the wall's middle, 2 m right of `left`.
fn alpha_wall(left: f32, mode: twister::core::shading::material::AlphaMode, alpha: f32) -> Scene {
    use twister::core::shading::material::{AlphaMode, Filter, Wrap};
    let mut scene = wall(left);
    scene.vertices.iter_mut().for_each(|v| v.color[3] = alpha);
    let m = &mut scene.materials[0];
    m.alpha_mode = mode as u32;
    if mode == AlphaMode::Mask {
        m.alpha_cutoff = 0.5;
        scene.textures.push(twister::core::shading::texture::Texture {
            name: "alpha edge".into(),
            width: 2,
            height: 1,
            rgba: vec![255, 255, 255, 0, 255, 255, 255, 255],
        });
        m.texture = 0;
        (m.mag_filter, m.min_filter) = (Filter::Linear as u32, Filter::Linear as u32);
        (m.wrap_u, m.wrap_v) = (Wrap::ClampToEdge as u32, Wrap::ClampToEdge as u32);
        for v in &mut scene.vertices {
            v.uv = [(v.position[0] - left) / 4.0, 0.5];
        }
    }
    scene
}

/// Alpha to coverage: with several samples a BLEND surface covers the share of each pixel its
/// alpha gives (not a dither of whole pixels), and a MASK texture's cutoff line is an edge that
/// covers its share of the pixels it crosses, as a triangle's edge does; with one sample both
/// stay all or nothing per pixel.
#[test]
fn alpha_covers_its_share_of_each_pixel() {
    alpha_coverage(Method::Adaptive(Default::default()));
    alpha_coverage(Method::Trace);
}

/// `alpha_covers_its_share_of_each_pixel` drawn by `method` (the ray tracer: a ray per sample,
/// each with its own alpha test and screen-door threshold).
fn alpha_coverage(method: Method) {
    use twister::core::shading::material::AlphaMode;
    let projection = Projection { width: 256, height: 64, vertical: Vertical::Exact, ..Projection::default() };
    let settings = RenderSettings::new(projection).with_method(method).with_ambient(0.0).with_background([0.0; 3]);
    let linear = |image: &twister::EyeImage, x: u32, y: u32| srgb_to_linear(image.pixel(x, y)[0] as f32 / 255.0) as f64;
    // BLEND: every pixel inside the wall, rows about the horizon, over the opaque wall's value.
    let opaque = linear(&common::render(&wall(-0.35), &settings).left, projection.width / 2, projection.height / 2);
    for alpha in [0.3f32, 0.5, 0.8] {
        let scene = alpha_wall(-0.35, AlphaMode::Blend, alpha);
        for samples in [1u32, 4, 16] {
            let frame = common::render(&scene, &settings.with_samples(samples));
            let (a, b) = (
                projection.project(Vec3::new(0.0, 0.0, -2.0), Eye::Left).unwrap(),
                projection.project(Vec3::new(3.0, 0.0, -2.0), Eye::Left).unwrap(),
            );
            let (x0, x1) = (projection.to_pixel(a.u, a.v)[0] as u32, projection.to_pixel(b.u, b.v)[0] as u32);
            let middle = projection.height / 2;
            let values: Vec<f64> = (middle - 4..middle + 4)
                .flat_map(|y| (x0..x1).map(move |x| (x, y)))
                .map(|(x, y)| linear(&frame.left, x, y) / opaque)
                .collect();
            let mean = values.iter().sum::<f64>() / values.len() as f64;
            let worst = values.iter().map(|v| (v - alpha as f64).abs()).fold(0.0, f64::max);
            eprintln!(
                "{method:?}: BLEND alpha {alpha}, {samples} samples: mean {mean:.3}, worst pixel off by {worst:.3}"
            );
            // One sample: the screen door's 4×4 thresholds (k + 1/2)/16 over rows 8 high.
            let within = if samples == 1 { 1.0 / 16.0 } else { 0.03 };
            assert!((mean - alpha as f64).abs() < within, "alpha {alpha}, {samples} samples: mean {mean}");
            if samples == 1 {
                assert!(worst > 0.19, "alpha {alpha}, one sample: a dither of whole pixels ({worst})");
            } else {
                assert!(
                    worst <= 1.0 / samples as f64 + 0.01,
                    "alpha {alpha}, {samples} samples: a pixel off by {worst}"
                );
            }
        }
    }
    // MASK: the cutoff's line at 12 fractions of a pixel, both eyes, six rows. The texture lies
    // where the subdivision puts it (within τ), so τ is small here.
    let mask_settings = settings.with_max_error_px(0.02);
    for samples in [1u32, 4] {
        let (mut sum, mut n) = (0.0, 0);
        for k in 0..12 {
            let left = -2.4 + 0.0137 * k as f32;
            let frame = common::render(&alpha_wall(left, AlphaMode::Mask, 1.0), &mask_settings.with_samples(samples));
            for (eye, image) in [(Eye::Left, &frame.left), (Eye::Right, &frame.right)] {
                let p = projection.project(Vec3::new(left + 2.0, 0.0, -2.0), eye).expect("seen");
                let x = projection.to_pixel(p.u, p.v)[0];
                let column = x.floor() as u32;
                let exact = (column as f32 + 1.0 - x) as f64;
                let middle = projection.height / 2;
                for row in middle - 3..middle + 3 {
                    let inside = linear(image, column + 2, row);
                    let row_values: Vec<f64> =
                        (column - 4..column + 5).map(|c| (linear(image, c, row) * 100.0).round()).collect();
                    assert!(
                        inside > 0.5 && linear(image, column - 2, row) < 1e-3,
                        "the mask's two sides {x} {row_values:?}"
                    );
                    sum += (linear(image, column, row) / inside - exact).abs();
                    n += 1;
                }
            }
        }
        let mean = sum / n as f64;
        eprintln!("{method:?}: MASK edge, {samples} samples: mean |coverage − exact share| {mean:.3}");
        if samples == 1 {
            assert!(mean > 0.15, "one sample: all or nothing ({mean})");
        } else {
            assert!(mean < 0.13, "{samples} samples: mean {mean}");
        }
    }
}

/// Bright edges: each sample is tone-mapped before the samples are averaged. An emissive wall 8×
/// brighter than white (its inside saturates) keeps its edge pixels at the share of them it
/// covers; averaging the linear light first and tone-mapping the mean (measured here on a
/// one-sample frame 4 × 4 times the size, its linear colour box-filtered, then tone-mapped)
/// makes a pixel a quarter covered nearly as bright as the inside: the edge swells by most of a
/// pixel.
#[test]
fn bright_edges_keep_their_share_when_samples_are_tone_mapped_first() {
    let projection = Projection { width: 256, height: 64, ..Projection::default() };
    let settings = RenderSettings::new(projection).with_ambient(0.0).with_background([0.0; 3]);
    let larger = Projection { width: 4 * projection.width, height: 4 * projection.height, ..projection };
    let hdr_settings = RenderSettings::new(larger).with_ambient(0.0).with_background([0.0; 3]).with_hdr(true);
    let lighting = settings
        .lighting_params(twister::core::shading::light::SceneLighting { lights: 0, physically_based: true }, None);
    let (mut first, mut after, mut n) = (0.0f64, 0.0f64, 0);
    for k in 0..6 {
        let left = -0.4 + 0.023 * k as f32;
        let mut scene = wall(left);
        let m = &mut scene.materials[0];
        (m.emissive_r, m.emissive_g, m.emissive_b) = (8.0, 8.0, 8.0);
        let frame = common::render(&scene, &settings.with_samples(16));
        let big = common::render(&scene, &hdr_settings);
        let hdr = &big.hdr.as_ref().expect("asked for")[0];
        let p = projection.project(Vec3::new(left, 0.0, -2.0), Eye::Left).expect("seen");
        let x = projection.to_pixel(p.u, p.v)[0];
        let column = x.floor() as u32;
        let exact = (column as f32 + 1.0 - x) as f64;
        let middle = projection.height / 2;
        for row in middle - 2..middle + 2 {
            let linear = |c: u32| srgb_to_linear(frame.left.pixel(c, row)[0] as f32 / 255.0) as f64;
            first += (linear(column) / linear(column + 2) - exact).abs();
            // The linear light averaged over the pixel, then tone-mapped.
            let mean = |c: u32| {
                let block = (0..16).map(|i| hdr[((4 * row + i / 4) * larger.width + 4 * c + i % 4) as usize][0]);
                block.sum::<f32>() / 16.0
            };
            let toned = |c: u32| twister::core::shading::light::tonemap(Vec3::splat(mean(c)), &lighting).x as f64;
            after += (toned(column) / toned(column + 2) - exact).abs();
            n += 1;
        }
    }
    let (first, after) = (first / n as f64, after / n as f64);
    eprintln!(
        "bright edge, mean |coverage − exact share|: tone-mapped per sample {first:.3}, averaged first {after:.3}"
    );
    assert!(first < 0.06, "tone-mapped per sample: {first}");
    assert!(after > 0.2, "averaged first: {after}");
}
