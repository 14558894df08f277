//! Checks twister's full-sphere panorama against Blender Cycles' spherical stereo, the renderer
//! our users composite with (see `scripts/cycles/`).
//!
//! `cargo run --release --example cycles_reference -- export DIR` writes `DIR/demo.obj` (+ .mtl):
//! `builtin:demo` with one material per flat colour, for `scripts/cycles/render_cycles.py`.
//!
//! `cargo run --release --example cycles_reference -- compare CYCLES_PREFIX WIDTH CONVERGENCE
//! [POLE_FROM POLE_TO | off]` renders the same panorama with twister (unlit: every surface its
//! flat colour) and compares it with Cycles' `CYCLES_PREFIX_L.png` / `_R.png`: each pixel is
//! labelled with the scene colour it shows (pixels that blend two colours, at an edge, take
//! none), and every pixel whose label differs between the two must have the other renderer's
//! label within 1 pixel. Prints the counts; exits non-zero on a boundary further apart.

use std::collections::BTreeSet;
use std::path::Path;

use twister::core::builtin;
use twister::core::color::linear_to_srgb;
use twister::gpu::Gpu;
use twister::{Eye, GpuScene, Projection, RenderSettings, Renderer, Scene};

/// The scene's flat colours as display (sRGB) bytes, in a fixed order.
fn palette(scene: &Scene) -> Vec<[u8; 3]> {
    let set: BTreeSet<[u8; 3]> = scene
        .vertices
        .iter()
        .map(|v| [0, 1, 2].map(|c| (linear_to_srgb(v.color[c]) * 255.0 + 0.5).floor() as u8))
        .collect();
    set.into_iter().collect()
}

fn export(scene: &Scene, dir: &Path) -> std::io::Result<()> {
    std::fs::create_dir_all(dir)?;
    let colours: Vec<[f32; 3]> = {
        let mut seen: Vec<[f32; 3]> = Vec::new();
        for v in &scene.vertices {
            let c = [v.color[0], v.color[1], v.color[2]];
            if !seen.contains(&c) {
                seen.push(c);
            }
        }
        seen
    };
    let mut obj = String::from("mtllib demo.mtl\n");
    for v in &scene.vertices {
        obj += &format!("v {} {} {}\n", v.position[0], v.position[1], v.position[2]);
    }
    for (k, c) in colours.iter().enumerate() {
        obj += &format!("usemtl c{k}\n");
        for t in scene.indices.chunks(3) {
            let v = &scene.vertices[t[0] as usize];
            if [v.color[0], v.color[1], v.color[2]] == *c {
                obj += &format!("f {} {} {}\n", t[0] + 1, t[1] + 1, t[2] + 1);
            }
        }
    }
    let mtl: String =
        colours.iter().enumerate().map(|(k, c)| format!("newmtl c{k}\nKd {} {} {}\n", c[0], c[1], c[2])).collect();
    std::fs::write(dir.join("demo.obj"), obj)?;
    std::fs::write(dir.join("demo.mtl"), mtl)
}

/// Per pixel, the index of the palette colour it shows, or None (a blend at an edge).
fn labels(rgb: &[[u8; 3]], palette: &[[u8; 3]]) -> Vec<Option<usize>> {
    rgb.iter().map(|p| palette.iter().position(|q| (0..3).all(|c| p[c].abs_diff(q[c]) <= 3))).collect()
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let scene = builtin::demo();
    match args.first().map(String::as_str) {
        Some("export") => {
            export(&scene, Path::new(&args[1]))?;
            return Ok(());
        }
        Some("compare") => {}
        _ => {
            return Err(
                "usage: cycles_reference export DIR | compare CYCLES_PREFIX WIDTH CONVERGENCE [FROM TO | off]".into()
            )
        }
    }
    let prefix = &args[1];
    let width: u32 = args[2].parse()?;
    let convergence = if args[3] == "parallel" { None } else { Some(args[3].parse::<f32>()?) };
    let pole_merge = match args.get(4).map(String::as_str) {
        None => Some((60.0, 75.0)),
        Some("off") => None,
        Some(from) => Some((from.parse()?, args[5].parse()?)),
    };
    let projection = Projection { convergence, pole_merge, ..Projection::equirect(width) };
    let settings = RenderSettings::new(projection).with_ambient(1.0);
    let renderer = Renderer::new(Gpu::new()?)?;
    let frame = renderer.render(&GpuScene::upload(&renderer.gpu, &scene)?, &settings)?;
    let palette = palette(&scene);
    let (w, h) = (width as usize, (width / 2) as usize);
    let mut worst = 0usize;
    for (eye, suffix) in Eye::BOTH.into_iter().zip(["L", "R"]) {
        let cycles = image::open(format!("{prefix}_{suffix}.png"))?.to_rgb8();
        assert_eq!((cycles.width() as usize, cycles.height() as usize), (w, h), "Cycles image size");
        let theirs = labels(&cycles.pixels().map(|p| p.0).collect::<Vec<_>>(), &palette);
        let ours = labels(&frame.eye(eye).rgba.chunks(4).map(|p| [p[0], p[1], p[2]]).collect::<Vec<_>>(), &palette);
        // Labels within `reach` pixels (wrapping around in x) of pixel i in an image.
        let near = |img: &[Option<usize>], i: usize, label: usize, reach: i64| {
            let (x, y) = ((i % w) as i64, (i / w) as i64);
            (-reach..=reach).any(|dy| {
                (-reach..=reach).any(|dx| {
                    let (nx, ny) = ((x + dx).rem_euclid(w as i64), y + dy);
                    dx * dx + dy * dy <= reach * reach
                        && (0..h as i64).contains(&ny)
                        && img[ny as usize * w + nx as usize] == Some(label)
                })
            })
        };
        let (mut compared, mut differ, mut beyond_1px) = (0, 0, 0);
        let mut distances = [0usize; 5];
        for i in 0..w * h {
            let (Some(a), Some(b)) = (ours[i], theirs[i]) else { continue };
            compared += 1;
            if a == b {
                continue;
            }
            differ += 1;
            // How far the other renderer's label is: 1, 2, 3, 4 or more pixels.
            let d = (1..=4).find(|&r| near(&theirs, i, a, r) && near(&ours, i, b, r)).unwrap_or(5);
            distances[d - 1] += 1;
            beyond_1px += (d > 1) as usize;
        }
        println!(
            "{eye:?}: {compared} pixels compared, {differ} differ; the other label within 1 px: {}, 2: {}, 3: {}, 4: {}, further: {}",
            distances[0], distances[1], distances[2], distances[3], distances[4]
        );
        worst = worst.max(beyond_1px);
    }
    if worst > 0 {
        return Err(format!("{worst} pixels where the boundaries are more than 1 px apart").into());
    }
    Ok(())
}
