//! Samples per pixel (`--samples`, issue 33): each pixel of the colour image shows the average of
//! its samples' linear colours. Checked against the closed form: an emissive wall whose vertical
//! edge (a vertical line in the panorama, on the cylinder and on the sphere alike) crosses a pixel
//! at a known fraction covers that share of it; and bad sample counts are one clear line.

mod common;

use glam::Vec3;
use twister::core::color::srgb_to_linear;
use twister::core::material::Material;
use twister::core::projection::{Eye, PanoramaKind, Projection};
use twister::core::scene::SceneVertex;
use twister::core::settings::Method;
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
fn coverage_error(panorama: PanoramaKind, samples: u32) -> (f64, f64) {
    let projection = match panorama {
        PanoramaKind::Cylinder => Projection { width: 256, height: 64, ..Projection::default() },
        PanoramaKind::Equirect => Projection::equirect(256),
    };
    let settings = RenderSettings::new(projection).with_ambient(0.0).with_background([0.0; 3]).with_samples(samples);
    let (mut sum, mut worst, mut n) = (0.0f64, 0.0f64, 0);
    for k in 0..12 {
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
                assert!(inside > 0.5, "{panorama:?}: the wall's inside is lit ({inside})");
                assert!(linear(column - 1) < 1e-3, "{panorama:?}: left of the edge is background");
                let error = (linear(column) / inside - exact).abs();
                sum += error;
                worst = worst.max(error);
                n += 1;
            }
        }
    }
    (sum / n as f64, worst)
}

#[test]
fn a_pixel_shows_the_share_of_it_a_surface_covers() {
    for panorama in [PanoramaKind::Cylinder, PanoramaKind::Equirect] {
        let (mean1, _) = coverage_error(panorama, 1);
        let (mean4, worst4) = coverage_error(panorama, 4);
        let (mean16, worst16) = coverage_error(panorama, 16);
        eprintln!(
            "{panorama:?}: coverage error, 1 sample mean {mean1:.3}; 4 samples mean {mean4:.3}, worst {worst4:.3}; \
             16 mean {mean16:.3}, worst {worst16:.3}"
        );
        // One sample: the pixel is all or nothing (the mean error of an edge at a uniform
        // fraction is 1/4). Four: the standard pattern's columns at 1/8, 3/8, 5/8, 7/8 of the
        // pixel count the share to within 1/8 (mean 1/16), plus the sRGB target's rounding.
        // Sixteen (four per pixel of a 2×2 larger image where the adapter has no 16): eight
        // columns, within 1/16 (mean 1/32).
        assert!(mean1 > 0.15, "{panorama:?}: one sample, mean {mean1}");
        assert!(worst4 <= 0.13 && mean4 <= 0.08, "{panorama:?}: four samples, mean {mean4}, worst {worst4}");
        assert!(worst16 <= 0.07 && mean16 <= 0.05, "{panorama:?}: sixteen samples, mean {mean16}, worst {worst16}");
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
    if max > twister::core::projection::MAX_IMAGE_SIDE {
        eprintln!("the adapter's images are larger than a frame may be: no made-up image to refuse");
        return;
    }
    let projection = Projection { width: max, height: 16, ..Projection::default() };
    let settings = RenderSettings::new(projection).with_samples(16);
    let gs = twister::GpuScene::upload(&common::renderer().gpu, &wall(-0.35)).unwrap();
    let err = common::renderer().render(&gs, &settings).err().expect("refused").to_string();
    assert!(err.contains("shading.samples") && err.contains("larger image"), "{err}");
}

#[test]
fn bad_sample_counts_are_one_clear_line() {
    for (args, says) in [
        (&["--samples", "3"][..], "must be 1, 2, 4, 8, 16 or 32"),
        (&["--samples", "4", "--method", "trace"][..], "one ray per pixel"),
        (&["--samples", "99999999999"][..], "--samples"),
    ] {
        let dir = common::TempDir::new(format!("twister-samples-{}", std::process::id()));
        let o = common::twister()
            .args(["render", "builtin:triangle@3", "--width", "64", "--height", "16", "--out"])
            .arg(&*dir)
            .args(args)
            .output()
            .expect("runs");
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success(), "{args:?} succeeded");
        assert!(err.contains("--samples") && err.contains(says), "{args:?}: {err}");
        assert_eq!(err.lines().filter(|l| l.starts_with("error")).count(), 1, "{args:?}: one error line: {err}");
        assert!(std::fs::read_dir(&*dir).map_or(true, |mut d| d.next().is_none()), "{args:?} wrote output");
    }
}
