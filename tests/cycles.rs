//! twister's full-sphere panorama against Blender Cycles' spherical stereo (the renderer our
//! users composite with), an oracle that shares no code with twister: `tests/data/cycles/`
//! holds Cycles 3.4.1 renders of `builtin:demo` (flat emissive colours, 64 samples, 512×256
//! per eye, interocular 64 mm), made by `scripts/cycles/render_cycles.py` from the scene that
//! `cargo run --example cycles_reference -- export` writes, and snapped to the scene's colours.
//! Every pixel that shows a different colour in the two renders must lie within 1 pixel of a
//! region of its own colour in the other: the boundaries agree to a pixel, for both eyes.

mod common;

use twister::core::builtin;
use twister::core::compare::{boundary_agreement, display_palette, palette_labels};
use twister::{Eye, Projection, RenderSettings};

fn check(fixture: &str, convergence: Option<f32>, pole_merge: Option<(f32, f32)>) {
    let scene = builtin::demo();
    let projection = Projection { convergence, pole_merge, ..Projection::equirect(512) };
    let frame = common::render(&scene, &RenderSettings::new(projection).with_ambient(1.0));
    let palette = display_palette(&scene);
    for (eye, suffix) in Eye::BOTH.into_iter().zip(["L", "R"]) {
        let path =
            std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("tests/data/cycles/{fixture}_{suffix}.png"));
        let cycles = image::open(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display())).to_rgb8();
        assert_eq!(cycles.dimensions(), (512, 256));
        let theirs = palette_labels(&cycles.pixels().map(|p| p.0).collect::<Vec<_>>(), &palette);
        let ours =
            palette_labels(&frame.eye(eye).rgba.chunks(4).map(|p| [p[0], p[1], p[2]]).collect::<Vec<_>>(), &palette);
        let a = boundary_agreement(&ours, &theirs, 512, 256);
        assert!(a.compared > 125_000, "{fixture} {eye:?}: only {} pixels labelled in both", a.compared);
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
