//! Anti-aliasing against independent references (`--samples`, issue 33's proofs): an emissive
//! white sphere on black, on the cylinder and the full sphere. Its pixels' linear values, over
//! the inside's, are the share of each pixel the sphere covers: compared with the same scene
//! drawn 8 × 8 times larger with one sample and box-filtered (the exact coverage to 1/64 of a
//! pixel); and a quarter-pixel turn of the sphere moves its coverage-weighted centroid by a
//! quarter pixel.

mod common;

use glam::Vec3;
use twister::core::panoramas::projection::Projection;
use twister::core::scenes::builtin;
use twister::core::shading::color::srgb_to_linear;
use twister::core::shading::material::Material;
use twister::{EyeImage, RenderSettings, Scene};

/// An emissive white sphere of radius 0.66 m, 2 m away at azimuth `azimuth` (radians from −z
/// towards +x): about 27 px in radius on a 512-px-wide panorama.
fn emissive_sphere(azimuth: f32) -> Scene {
    let centre = 2.0 * Vec3::new(azimuth.sin(), 0.0, -azimuth.cos());
    let mut scene = builtin::sphere_scene(3200, centre, 0.66, "sphere");
    scene.materials = vec![Material { emissive_r: 1.0, emissive_g: 1.0, emissive_b: 1.0, ..Default::default() }];
    for v in &mut scene.vertices {
        v.material = 1;
        v.color = [0.0, 0.0, 0.0, 1.0];
    }
    scene.physically_based = true;
    scene
}

/// The panoramas measured here, at scale 1: the cylinder and the sphere.
fn panoramas() -> [Projection; 2] {
    [Projection { width: 512, height: 128, ..Projection::default() }, Projection::equirect(512)]
}

/// `p` `scale` times wider and higher.
fn projection(p: Projection, scale: u32) -> Projection {
    Projection { width: p.width * scale, height: p.height * scale, ..p }
}

fn settings(projection: Projection) -> RenderSettings {
    RenderSettings::new(projection).with_ambient(0.0).with_background([0.0; 3])
}

/// The left eye's linear values over the brightest (the inside's): each pixel's coverage.
fn coverage(image: &EyeImage) -> Vec<f64> {
    let linear: Vec<f64> = image.rgba.chunks(4).map(|p| srgb_to_linear(p[0] as f32 / 255.0) as f64).collect();
    let inside = linear.iter().copied().fold(0.0, f64::max);
    linear.iter().map(|v| v / inside).collect()
}

/// The coverage of each pixel from a one-sample frame `k` × `k` times larger, box-filtered.
fn reference(panorama: Projection, scene: &Scene, k: u32) -> Vec<f64> {
    let big = coverage(&common::render(scene, &settings(projection(panorama, k))).left);
    let p = projection(panorama, 1);
    (0..p.width * p.height)
        .map(|i| {
            let (x, y) = (i % p.width, i / p.width);
            let block = (0..k * k).map(|j| big[((k * y + j / k) * k * p.width + k * x + j % k) as usize]);
            block.sum::<f64>() / (k * k) as f64
        })
        .collect()
}

/// Over the edge pixels (reference coverage strictly between 0.02 and 0.98), the mean
/// |coverage − reference| at 1, 4 and 16 samples: one sample is all or nothing (about 0.23),
/// four within 0.10, sixteen within 0.05 (the goals).
#[test]
fn an_emissive_sphere_covers_what_an_eight_times_larger_frame_says() {
    for panorama in panoramas() {
        let name = panorama.panorama.name();
        let scene = emissive_sphere(0.3);
        let exact = reference(panorama, &scene, 8);
        let edge: Vec<usize> = (0..exact.len()).filter(|&i| exact[i] > 0.02 && exact[i] < 0.98).collect();
        assert!(edge.len() > 100, "{name}: {} edge pixels", edge.len());
        let error = |samples: u32| {
            let measured =
                coverage(&common::render(&scene, &settings(projection(panorama, 1)).with_samples(samples)).left);
            edge.iter().map(|&i| (measured[i] - exact[i]).abs()).sum::<f64>() / edge.len() as f64
        };
        let (one, four, sixteen) = (error(1), error(4), error(16));
        eprintln!(
            "{name}: {} edge pixels; mean |coverage − 8× reference| 1 sample {one:.3}, 4 {four:.3}, 16 {sixteen:.3}",
            edge.len()
        );
        assert!(one > 0.15, "{name}: one sample {one}");
        assert!(four <= 0.10, "{name}: four samples {four}");
        assert!(sixteen <= 0.05, "{name}: sixteen samples {sixteen}");
    }
}

/// The coverage-weighted centroid's column in the left eye.
fn centroid_x(image: &EyeImage) -> f64 {
    let c = coverage(image);
    let w = image.width as usize;
    let (sum, weight) = c.iter().enumerate().fold((0.0, 0.0), |(s, m), (i, v)| (s + v * ((i % w) as f64 + 0.5), m + v));
    sum / weight
}

/// Turning the sphere by a quarter pixel at a time (about the vertical axis, so its image moves
/// along the panorama's width) moves its coverage-weighted centroid by a quarter pixel each
/// time (± 0.03) with 4 and 16 samples; with one its steps are less even.
#[test]
fn a_quarter_pixel_turn_moves_the_centroid_a_quarter_pixel() {
    for panorama in panoramas() {
        let name = panorama.panorama.name();
        let p = projection(panorama, 1);
        let quarter = std::f32::consts::TAU / p.width as f32 / 4.0;
        let mut worst_of = Vec::new();
        for samples in [1u32, 4, 16] {
            let centroids: Vec<f64> = (0..5)
                .map(|k| {
                    let scene = emissive_sphere(0.3 + k as f32 * quarter);
                    centroid_x(&common::render(&scene, &settings(p).with_samples(samples)).left)
                })
                .collect();
            let steps: Vec<f64> = centroids.windows(2).map(|w| w[1] - w[0]).collect();
            let worst = steps.iter().map(|s| (s - 0.25).abs()).fold(0.0, f64::max);
            eprintln!("{name}, {samples} samples: centroid steps {steps:.3?} (worst off by {worst:.3})");
            if samples > 1 {
                assert!(worst <= 0.03, "{name}, {samples} samples: steps {steps:?}");
            }
            worst_of.push(worst);
        }
        // One sample: each edge pixel all or nothing; the disc's many edge pixels average much
        // of that out, but its steps stay the least even.
        assert!(worst_of[0] > 1.5 * worst_of[1], "{name}: worst step off by {worst_of:?} at 1, 4, 16 samples");
    }
}
