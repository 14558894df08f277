//! Checks twister's full-sphere panorama against Blender Cycles' spherical stereo, the renderer
//! our users composite with (see `scripts/cycles/`).
//!
//! `cargo run --release --example cycles_reference -- export DIR` writes `DIR/demo.obj` (+ .mtl):
//! `builtin:demo` with one material per flat colour, for `scripts/cycles/render_cycles.py`.
//!
//! `... -- snap CYCLES_PREFIX OUT_PREFIX` sets every pixel of a Cycles render within 3 levels of a
//! scene colour to that colour (the test fixtures in `tests/data/cycles/`).
//!
//! `cargo run --release --example cycles_reference -- compare CYCLES_PREFIX WIDTH CONVERGENCE
//! [POLE_FROM POLE_TO | off]` renders the same panorama with twister (unlit: every surface its
//! flat colour) and compares it with Cycles' `CYCLES_PREFIX_L.png` / `_R.png`: each pixel is
//! labelled with the scene colour it shows (pixels that blend two colours, at an edge, take
//! none), and every pixel whose label differs between the two must lie within 1 pixel of a region
//! of its own label in the other render (the boundary between the two moved by at most 1 pixel).
//! Prints the counts; exits non-zero on a boundary further apart.

use std::path::Path;

use twister::core::compare::{boundary_agreement, display_palette, palette_labels};
use twister::core::scenes::builtin;
use twister::gpu::Gpu;
use twister::{Eye, GpuScene, Projection, RenderSettings, Renderer, Scene};

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

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let scene = builtin::demo();
    match args.first().map(String::as_str) {
        Some("export") => {
            export(&scene, Path::new(&args[1]))?;
            return Ok(());
        }
        Some("snap") => {
            // A Cycles render with every pixel within 3 levels of a scene colour set to it (the
            // test fixtures: the sampling noise removed, edges kept).
            let palette = display_palette(&scene);
            for suffix in ["L", "R"] {
                let mut img = image::open(format!("{}_{suffix}.png", args[1]))?.to_rgb8();
                for p in img.pixels_mut() {
                    if let Some(k) = palette_labels(&[p.0], &palette)[0] {
                        p.0 = palette[k];
                    }
                }
                img.save(format!("{}_{suffix}.png", args[2]))?;
            }
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
    let palette = display_palette(&scene);
    let (w, h) = (width as usize, (width / 2) as usize);
    let mut worst = 0usize;
    for (eye, suffix) in Eye::BOTH.into_iter().zip(["L", "R"]) {
        let cycles = image::open(format!("{prefix}_{suffix}.png"))?.to_rgb8();
        assert_eq!((cycles.width() as usize, cycles.height() as usize), (w, h), "Cycles image size");
        let theirs = palette_labels(&cycles.pixels().map(|p| p.0).collect::<Vec<_>>(), &palette);
        let ours =
            palette_labels(&frame.eye(eye).rgba.chunks(4).map(|p| [p[0], p[1], p[2]]).collect::<Vec<_>>(), &palette);
        let a = boundary_agreement(&ours, &theirs, w, h);
        for (x, y, la, lb) in &a.examples {
            println!("  pixel ({x}, {y}): twister shows colour {la}, Cycles {lb}");
        }
        let m = a.moved;
        println!(
            "{eye:?}: {} pixels compared, {} differ; boundary moved within 1 px: {}, 2: {}, 3: {}, 4: {}, further: {}",
            a.compared, a.differ, m[0], m[1], m[2], m[3], m[4]
        );
        worst = worst.max(m[1] + m[2] + m[3] + m[4]);
    }
    if worst > 0 {
        return Err(format!("{worst} pixels where the boundaries are more than 1 px apart").into());
    }
    Ok(())
}
