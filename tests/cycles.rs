//! twister's full-sphere panorama against Blender Cycles' spherical stereo (the renderer our
//! users composite with), an oracle that shares no code with twister: `tests/data/cycles/`
//! holds Cycles 3.4.1 renders of `builtin:demo` (flat emissive colours, 64 samples, 512×256
//! per eye, interocular 64 mm), made by `scripts/cycles/render_cycles.py` from the scene that
//! `cargo run --example cycles_reference -- export` writes, and snapped to the scene's colours.
//! Every pixel that shows a different colour in the two renders must lie within 1 pixel of a
//! region of its own colour in the other: the boundaries agree to a pixel, for both eyes. The
//! `demo_parallel_box_*` renders (a one-pixel box filter, 1024 rays a pixel, not snapped) check
//! the anti-aliased edges' values.

mod common;

use twister::core::compare::{boundary_agreement, display_palette, palette_labels};
use twister::core::scenes::builtin;
use twister::{Eye, Projection, RenderSettings};

fn check(fixture: &str, convergence: Option<f32>, pole_merge: Option<(f32, f32)>) {
    check_projection(fixture, Projection { convergence, pole_merge, ..Projection::equirect(512) });
}

fn check_projection(fixture: &str, projection: Projection) {
    let scene = builtin::demo();
    let (w, h) = (projection.width, projection.height);
    let frame = common::render(&scene, &RenderSettings::new(projection).with_ambient(1.0));
    let palette = display_palette(&scene);
    for (eye, suffix) in Eye::BOTH.into_iter().zip(["L", "R"]) {
        let path =
            std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("tests/data/cycles/{fixture}_{suffix}.png"));
        let cycles = image::open(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display())).to_rgb8();
        assert_eq!(cycles.dimensions(), (w, h));
        let theirs = palette_labels(&cycles.pixels().map(|p| p.0).collect::<Vec<_>>(), &palette);
        let ours =
            palette_labels(&frame.eye(eye).rgba.chunks(4).map(|p| [p[0], p[1], p[2]]).collect::<Vec<_>>(), &palette);
        let a = boundary_agreement(&ours, &theirs, w as usize, h as usize);
        let shown = (0..w * h).filter(|i| projection.shows_pixel((i % w) as f32 + 0.5, (i / w) as f32 + 0.5)).count();
        assert!(a.compared * 20 > shown * 19, "{fixture} {eye:?}: only {} pixels labelled in both", a.compared);
        assert!(
            a.moved[1..].iter().all(|&n| n == 0),
            "{fixture} {eye:?}: boundaries further apart than 1 px: {:?} (e.g. (x, y, ours, Cycles) {:?})",
            a.moved,
            a.examples
        );
        // The two disagree only along boundaries (under 1 % of the pixels).
        assert!(a.differ * 100 < a.compared, "{fixture} {eye:?}: {} pixels differ", a.differ);
    }
}

#[test]
fn boundaries_agree_with_cycles_parallel_rays_and_pole_merge() {
    check("demo_parallel", None, Some((60.0, 75.0)));
}

#[test]
fn boundaries_agree_with_cycles_converging_on_2_m() {
    check("demo_converge2m", Some(2.0), Some((60.0, 75.0)));
}

#[test]
fn boundaries_agree_with_cycles_without_pole_merge() {
    check("demo_no_pole_merge", None, None);
}

/// The comparison tells the eyes apart: our left eye against Cycles' right one fails.
/// VR180 (issue 34): Cycles' equirectangular camera cut to longitudes ±90°, spherical stereo,
/// 256 × 256 per eye.
#[test]
fn vr180_boundaries_agree_with_cycles() {
    check_projection("demo_vr180", Projection::vr180(256));
}

/// The fulldome master (issue 34): Cycles' equidistant fisheye (200°, looking up, the front at
/// the bottom), 256 × 256, mono (Cycles turns its spherical stereo's eye circle with the
/// camera, so a camera looking up would stand it upright; twister's stays level, as the sphere's:
/// the stereo is checked against the sphere's rays in `core::panoramas::fisheye`); pixels outside the circle
/// are not compared (Cycles leaves them black).
#[test]
fn fisheye_boundaries_agree_with_cycles() {
    check_projection("demo_fisheye200", Projection { fov: 200.0, eye_radius: 0.0, ..Projection::fisheye(256) });
}

#[test]
fn swapped_eyes_do_not_agree_with_cycles() {
    let scene = builtin::demo();
    let frame = common::render(&scene, &RenderSettings::new(Projection::equirect(512)).with_ambient(1.0));
    let palette = display_palette(&scene);
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/cycles/demo_parallel_R.png");
    let cycles = image::open(&path).unwrap().to_rgb8();
    let theirs = palette_labels(&cycles.pixels().map(|p| p.0).collect::<Vec<_>>(), &palette);
    let ours = palette_labels(&frame.left.rgba.chunks(4).map(|p| [p[0], p[1], p[2]]).collect::<Vec<_>>(), &palette);
    let a = boundary_agreement(&ours, &theirs, 512, 256);
    assert!(a.moved[1..].iter().sum::<usize>() > 100, "{a:?}");
}

/// Anti-aliasing against Cycles (issue 33): `demo_parallel_box_*.png` are Cycles renders of the
/// same scene with 1024 rays spread evenly over each pixel (a one-pixel box filter, not snapped:
/// `render_cycles.py … box`), so an edge pixel holds the share of it each colour covers. Over
/// the edge pixels (those whose 3 × 3 neighbourhood in Cycles' image shows more than one colour
/// or a blend), the mean |difference| in linear light per channel: within 0.10 with 4 samples,
/// well under one sample's (all or nothing).
#[test]
fn edge_pixels_agree_with_cycles_box_filtered_renders() {
    use twister::core::shading::color::srgb_to_linear;
    let scene = builtin::demo();
    let projection = Projection { pole_merge: Some((60.0, 75.0)), ..Projection::equirect(512) };
    let palette = display_palette(&scene);
    let mut means = Vec::new();
    for samples in [1u32, 4, 16] {
        let frame = common::render(&scene, &RenderSettings::new(projection).with_ambient(1.0).with_samples(samples));
        let (mut sum, mut n) = (0.0f64, 0usize);
        for (eye, suffix) in Eye::BOTH.into_iter().zip(["L", "R"]) {
            let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
                .join(format!("tests/data/cycles/demo_parallel_box_{suffix}.png"));
            let cycles = image::open(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display())).to_rgb8();
            assert_eq!(cycles.dimensions(), (512, 256));
            let theirs: Vec<[u8; 3]> = cycles.pixels().map(|p| p.0).collect();
            let labels = palette_labels(&theirs, &palette);
            let ours: Vec<&[u8]> = frame.eye(eye).rgba.chunks(4).collect();
            for y in 1..255usize {
                for x in 0..512usize {
                    let i = y * 512 + x;
                    let mixed = (-1i64..=1).any(|dy| {
                        (-1i64..=1).any(|dx| {
                            let j = (y as i64 + dy) as usize * 512 + (x as i64 + dx).rem_euclid(512) as usize;
                            labels[j].is_none() || labels[j] != labels[i]
                        })
                    });
                    if mixed {
                        let linear = |b: u8| srgb_to_linear(b as f32 / 255.0) as f64;
                        sum += (0..3).map(|c| (linear(ours[i][c]) - linear(theirs[i][c])).abs()).sum::<f64>() / 3.0;
                        n += 1;
                    }
                }
            }
        }
        let mean = sum / n as f64;
        eprintln!(
            "{samples} samples: {n} edge pixels, mean |twister − Cycles (box filter)| {mean:.4} (linear, per channel)"
        );
        assert!(n > 5000, "{n} edge pixels");
        means.push(mean);
    }
    assert!(means[1] <= 0.10 && means[2] <= means[1], "means at 1, 4, 16 samples: {means:?}");
    assert!(means[1] < 0.6 * means[0], "4 samples against 1: {means:?}");
}
