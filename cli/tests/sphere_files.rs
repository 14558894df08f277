//! The files a full-sphere panorama writes, as players and tools read them: the Photo Sphere
//! (GPano) metadata in PNG and JPEG, the depth files' distance along each pixel's ray, and the
//! same bytes from a frame drawn in tiles as drawn whole.

mod common;

use std::path::Path;

use glam::Vec3;
use twister::core::panoramas::projection::PanoramaKind;
use twister::{Eye, Projection};

fn tmp(name: &str) -> common::TempDir {
    common::TempDir::new(format!("twister-sphere-files-{}-{name}", std::process::id()))
}

/// Runs `render builtin:demo` into `out/dir` with `args`.
fn run_demo(out: &Path, dir: &str, args: &[&str]) {
    let o = common::twister().args(["render", "builtin:demo", "--out"]).arg(out.join(dir)).args(args).output().unwrap();
    assert!(o.status.success(), "{args:?}: {}", String::from_utf8_lossy(&o.stderr));
}

/// An image `out/dir/name`.
fn read_image(out: &Path, dir: &str, name: &str) -> image::RgbaImage {
    image::open(out.join(dir).join(name)).unwrap().to_rgba8()
}

/// Frames beyond the adapter's textures (issue 34): drawn in tiles (forced small here with
/// `--max-tile`) and written as rows arrive, the images are the frame drawn whole: the ray
/// tracer's pixel for pixel, the rasterizer's and the slits' but for the edge pixels where a
/// tile's rounding breaks a tie otherwise (at most 1 % of the pixels); the combined layouts with
/// their GPano XMP, and JPEG, stream too; the statistics count the tiles; misuses are one line.
#[test]
fn frames_drawn_in_tiles_are_the_frames_drawn_whole() {
    let out = tmp("tiles");
    let run = |dir: &str, args: &[&str]| run_demo(&out, dir, args);
    let read = |dir: &str, name: &str| read_image(&out, dir, name);
    let cases: [(&[&str], &str, f64); 5] = [
        (
            &["--panorama", "equirect", "--width", "128", "--method", "trace", "--samples", "1"],
            "stereo_360_TB.png",
            0.0,
        ),
        (&["--panorama", "equirect", "--width", "128"], "stereo_360_TB.png", 0.01),
        (&["--width", "160", "--height", "60", "--method", "slit:4"], "left.png", 0.01),
        (&["--panorama", "cubemap", "--width", "144"], "stereo_cubemap_TB.png", 0.01),
        (&["--panorama", "fisheye", "--width", "96", "--alpha"], "left.png", 0.01),
    ];
    for (k, (args, name, share)) in cases.into_iter().enumerate() {
        let (whole, tiled) = (format!("whole{k}"), format!("tiled{k}"));
        run(&whole, args);
        run(&tiled, &[args, &["--max-tile", "48"]].concat());
        let (a, b) = (read(&whole, name), read(&tiled, name));
        assert_eq!(a.dimensions(), b.dimensions(), "{args:?}");
        let differ = a.pixels().zip(b.pixels()).filter(|(p, q)| p != q).count();
        assert!(
            differ as f64 <= share * (a.width() * a.height()) as f64,
            "{args:?}: {differ} of {} pixels differ",
            a.width() * a.height()
        );
        if name.contains("360") {
            assert_eq!(xmp_of(&out.join(&tiled).join(name)), xmp_of(&out.join(&whole).join(name)), "the GPano XMP");
        }
    }
}

/// A frame in tiles as JPEG, streamed through its encoder: the same picture, its XMP, and the
/// tiles counted in the statistics.
#[test]
fn a_jpeg_drawn_in_tiles_is_the_jpeg_drawn_whole() {
    let out = tmp("tiles-jpeg");
    let run = |dir: &str, args: &[&str]| run_demo(&out, dir, args);
    let read = |dir: &str, name: &str| read_image(&out, dir, name);
    let jpeg = ["--panorama", "equirect", "--width", "128", "--format", "jpg"];
    run("jpeg-whole", &jpeg);
    let stats = out.join("stats.json");
    run("jpeg-tiled", &[&jpeg[..], &["--max-tile", "48", "--stats", stats.to_str().unwrap()]].concat());
    let (a, b) = (read("jpeg-whole", "stereo_360_TB.jpg"), read("jpeg-tiled", "stereo_360_TB.jpg"));
    assert_eq!(a.dimensions(), b.dimensions());
    let mean = a.as_raw().iter().zip(b.as_raw()).map(|(&p, &q)| (p as f64 - q as f64).abs()).sum::<f64>()
        / a.as_raw().len() as f64;
    assert!(mean < 1.5, "mean difference {mean}");
    assert!(gpano(&xmp_of(&out.join("jpeg-tiled/stereo_360_TB.jpg")))
        .get("ProjectionType")
        .is_some_and(|t| t == "equirectangular"));
    let json: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&stats).unwrap()).unwrap();
    assert_eq!(json["tiles"], 128u32.div_ceil(48) * 64u32.div_ceil(48), "{json}");
}

/// Depth and the linear colour in tiles stream too (OpenEXR, row by row): the same values (the
/// ray tracer's depth exactly; the rasterizer's linear colour but for tie-broken edge pixels).
#[test]
fn depth_and_linear_colour_drawn_in_tiles_are_the_frames_drawn_whole() {
    let out = tmp("tiles-exr");
    let run = |dir: &str, args: &[&str]| run_demo(&out, dir, args);
    let depth = ["--panorama", "equirect", "--width", "128", "--method", "trace", "--samples", "1", "--depth"];
    run("depth-whole", &depth);
    run("depth-tiled", &[&depth[..], &["--max-tile", "40"]].concat());
    let whole = common::read_exr(&out.join("depth-whole/depth_TB.exr"));
    assert_eq!(whole, common::read_exr(&out.join("depth-tiled/depth_TB.exr")), "depth");
    assert!(whole.2.iter().filter(|d| d.is_finite()).count() > 1000);
    let hdr = ["--panorama", "equirect", "--width", "128", "--samples", "1", "--hdr", "--depth"];
    run("hdr-whole", &hdr);
    run("hdr-tiled", &[&hdr[..], &["--max-tile", "40"]].concat());
    let rgb = |dir: &str| {
        exr::prelude::read_first_rgba_layer_from_file(
            out.join(dir).join("left_hdr.exr"),
            |size, _| vec![[0.0f32; 3]; size.width() * size.height()],
            |px: &mut Vec<[f32; 3]>, pos, (r, g, b, _): (f32, f32, f32, f32)| px[pos.y() * 128 + pos.x()] = [r, g, b],
        )
        .unwrap()
        .layer_data
        .channel_data
        .pixels
    };
    let (a, b) = (rgb("hdr-whole"), rgb("hdr-tiled"));
    // Off by more than f32's rounding of the pixel positions a tile adds its origin to.
    let off = |p: &[f32; 3], q: &[f32; 3]| (0..3).any(|c| (p[c] - q[c]).abs() > 1e-3 * (1.0 + p[c].abs()));
    let differ = a.iter().zip(&b).filter(|(p, q)| off(p, q)).count();
    assert!(a.len() == 128 * 64 && differ * 100 <= a.len(), "the linear colour: {differ} pixels differ");
}

/// A sequence's frames in tiles, each streamed as it is drawn: the same pixels; no spool is
/// left beside the outputs; misuses are one line and write nothing.
#[test]
fn a_sequence_drawn_in_tiles_is_the_sequence_drawn_whole() {
    let out = tmp("tiles-seq");
    let run = |dir: &str, args: &[&str]| run_demo(&out, dir, args);
    let read = |dir: &str, name: &str| read_image(&out, dir, name);
    let seq = ["--panorama", "equirect", "--width", "128", "--method", "trace", "--samples", "1", "--frames", "0..1"];
    run("seq-whole", &seq);
    run("seq-tiled", &[&seq[..], &["--max-tile", "40"]].concat());
    for f in ["frame_000000_360_TB.png", "frame_000001_360_TB.png"] {
        assert_eq!(read("seq-whole", f), read("seq-tiled", f), "{f}");
    }
    // No spool is left beside the outputs.
    let left: Vec<String> = std::fs::read_dir(out.join("seq-tiled"))
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    assert!(left.iter().all(|n| !n.ends_with(".tmp")), "{left:?}");
    for (args, needle) in [
        (&["--max-tile", "8"][..], "--max-tile: must be at least 16"),
        (&["--max-tile", "48", "--lod-overlay"], "--lod-overlay"),
        (&["--max-tile", "8", "--frames", "0..1"], "--max-tile: must be at least 16"),
    ] {
        let o = common::twister()
            .args(["render", "builtin:demo", "--out"])
            .arg(out.join("never"))
            .args(args)
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success() && err.contains(needle) && err.lines().count() == 1, "{args:?}: {err}");
    }
    assert!(!out.join("never").exists());
}

/// Reads a PNG's iTXt chunk `XML:com.adobe.xmp`, or a JPEG's XMP APP1 segment.
fn xmp_of(path: &std::path::Path) -> String {
    let bytes = std::fs::read(path).unwrap();
    if path.extension().is_some_and(|e| e == "png") {
        let decoder = png::Decoder::new(std::io::Cursor::new(bytes));
        let reader = decoder.read_info().unwrap();
        let chunk =
            reader.info().utf8_text.iter().find(|c| c.keyword == "XML:com.adobe.xmp").expect("an XMP iTXt chunk");
        return chunk.get_text().unwrap();
    }
    // JPEG: walk the segments from SOI.
    assert_eq!(&bytes[..2], &[0xFF, 0xD8]);
    let mut at = 2;
    while at + 4 <= bytes.len() && bytes[at] == 0xFF {
        let marker = bytes[at + 1];
        let len = u16::from_be_bytes([bytes[at + 2], bytes[at + 3]]) as usize;
        let body = &bytes[at + 4..at + 2 + len];
        if marker == 0xE1 && body.starts_with(twister::output::JPEG_XMP_NAMESPACE) {
            return String::from_utf8(body[twister::output::JPEG_XMP_NAMESPACE.len()..].to_vec()).unwrap();
        }
        if marker == 0xDA {
            break;
        }
        at += 2 + len;
    }
    panic!("{}: no XMP segment", path.display())
}

/// The GPano properties of an XMP packet, parsed as XML.
fn gpano(xmp: &str) -> std::collections::HashMap<String, String> {
    let doc = roxmltree::Document::parse(xmp).expect("well-formed XMP");
    doc.descendants()
        .filter(|n| n.tag_name().namespace() == Some("http://ns.google.com/photos/1.0/panorama/"))
        .map(|n| (n.tag_name().name().to_string(), n.text().unwrap_or("").to_string()))
        .collect()
}

#[test]
fn sphere_images_carry_photo_sphere_metadata_in_png_and_jpeg_and_players_names() {
    let out = tmp("metadata");
    // (panorama, format, layout, file, its size, the eye's crop and left edge in the full panorama)
    for (panorama, format, layout, file, size, crop, full, left) in [
        ("equirect", "png", None, "stereo_360_TB.png", (256, 256), ("256", "128"), ("256", "128"), "0"),
        ("equirect", "jpg", Some("side-by-side"), "stereo_360_LR.jpg", (512, 128), ("256", "128"), ("256", "128"), "0"),
        ("equirect", "png", Some("eyes"), "left.png", (256, 128), ("256", "128"), ("256", "128"), "0"),
        // VR180: the front half of a sphere twice as wide, side by side by default.
        ("vr180", "png", None, "stereo_180_LR.png", (512, 256), ("256", "256"), ("512", "256"), "128"),
        ("vr180", "jpg", Some("top-bottom"), "stereo_180_TB.jpg", (256, 512), ("256", "256"), ("512", "256"), "128"),
    ] {
        let mut cmd = common::twister();
        cmd.args(["render", "builtin:demo", "--panorama", panorama, "--width", "256", "--method", "vertex"]);
        cmd.args(["--format", format, "--out"]).arg(&out);
        if let Some(l) = layout {
            cmd.args(["--layout", l]);
        }
        let o = cmd.output().unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let path = out.join(file);
        assert_eq!(image::image_dimensions(&path).unwrap(), size, "{file}");
        let g = gpano(&xmp_of(&path));
        assert_eq!(g["ProjectionType"], "equirectangular", "{file}: {g:?}");
        assert_eq!(g["UsePanoramaViewer"], "True");
        assert_eq!((g["FullPanoWidthPixels"].as_str(), g["FullPanoHeightPixels"].as_str()), full, "{file}");
        assert_eq!(
            (g["CroppedAreaImageWidthPixels"].as_str(), g["CroppedAreaImageHeightPixels"].as_str()),
            crop,
            "{file}"
        );
        assert_eq!((g["CroppedAreaLeftPixels"].as_str(), g["CroppedAreaTopPixels"].as_str()), (left, "0"), "{file}");
    }
    // The cylinder is no photo sphere: no GPano.
    let o = common::twister()
        .args(["render", "builtin:demo", "--width", "320", "--height", "80", "--out"])
        .arg(&out)
        .output()
        .unwrap();
    assert!(o.status.success());
    let decoder = png::Decoder::new(std::io::Cursor::new(std::fs::read(out.join("left.png")).unwrap()));
    assert!(decoder.read_info().unwrap().info().utf8_text.is_empty());
    // Nor is the fisheye (GPano has no fisheye type); its combined layouts carry `_fisheye`.
    let o = common::twister()
        .args(["render", "builtin:demo", "--panorama", "fisheye", "--width", "64"])
        .args(["--layout", "side-by-side", "--out"])
        .arg(&out)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let file = out.join("stereo_fisheye_LR.png");
    assert_eq!(image::image_dimensions(&file).unwrap(), (128, 64));
    let decoder = png::Decoder::new(std::io::Cursor::new(std::fs::read(&file).unwrap()));
    assert!(decoder.read_info().unwrap().info().utf8_text.is_empty());
    let opaque = image::open(&file).unwrap().to_rgba8();
    // --alpha: the circle's outside transparent, its inside as before.
    let o = common::twister()
        .args(["render", "builtin:demo", "--panorama", "fisheye", "--width", "64"])
        .args(["--layout", "side-by-side", "--alpha", "--out"])
        .arg(&out)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let clear = image::open(&file).unwrap().to_rgba8();
    let dome = Projection::fisheye(64);
    for (x, y, p) in clear.enumerate_pixels() {
        let inside = dome.shows_pixel((x % 64) as f32 + 0.5, y as f32 + 0.5);
        assert_eq!(p.0, if inside { opaque.get_pixel(x, y).0 } else { [0; 4] }, "({x}, {y})");
    }
    let _ = std::fs::remove_dir_all(&out);
}

/// The depth files hold the distance from each pixel's eye point along its ray: checked against
/// the ray (built here from the pixel: Cycles' construction) meeting the box room's walls, for
/// both panoramas' eyes (pixels beside an edge between walls left out), and +∞ where no surface is.
/// A pixel's ray for an eye 0.032 m off the axis (independently of `Projection::pixel_ray`):
/// the sphere's from Cycles' construction; the cylinder's the tangent ray of the eye whose view
/// meets the screen at this column, through the screen point (exact model).
fn pixel_eye_ray(projection: &Projection, eye: Eye, x: usize, y: usize) -> (Vec3, Vec3) {
    let (u, v) = projection.pixel_to_screen(x as f32, y as f32);
    let s = eye.sign();
    if projection.panorama.is_sphere() {
        let d = Vec3::new(v.cos() * u.sin(), v.sin(), -v.cos() * u.cos());
        let side = d.cross(Vec3::Y).normalize();
        let fade = projection.pole_fade(v.abs());
        (s * 0.032 * fade * side, d)
    } else {
        let phi = u - s * (0.032f32).asin();
        let origin = s * 0.032 * Vec3::new(phi.cos(), 0.0, phi.sin());
        let screen = Vec3::new(u.sin(), v, -u.cos());
        (origin, (screen - origin).normalize())
    }
}

#[test]
fn depth_files_hold_the_distance_along_each_pixels_ray() {
    let out = tmp("depth");
    let (lo, hi) = (Vec3::new(-20.0, -1.7, -20.0), Vec3::new(20.0, 8.3, 20.0));
    // Distance along a ray from inside the box to its walls, and which wall (axis, side).
    let to_wall = |o: Vec3, d: Vec3| {
        (0..3)
            .map(|k| {
                let t1 = (lo[k] - o[k]) / d[k];
                let t2 = (hi[k] - o[k]) / d[k];
                (t1.max(t2), 2 * k + (t2 > t1) as usize)
            })
            .fold((f32::INFINITY, 0), |a, b| if b.0 < a.0 { b } else { a })
    };
    for panorama in ["equirect", "cylinder"] {
        let size: &[&str] =
            if panorama == "equirect" { &["--width", "256"] } else { &["--width", "256", "--height", "64"] };
        let o = common::twister()
            .args([
                "render",
                "builtin:box-room",
                "--panorama",
                panorama,
                "--vertical",
                "exact",
                "--depth",
                "--layout",
                "eyes",
            ])
            .args(size)
            .args(["--edge-px", "8", "--out"])
            .arg(&out)
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let projection = if panorama == "equirect" {
            Projection::equirect(256)
        } else {
            Projection { width: 256, height: 64, vertical: twister::Vertical::Exact, ..Projection::default() }
        };
        assert_eq!(projection.panorama == PanoramaKind::Equirect, panorama == "equirect");
        for eye in Eye::BOTH {
            let (w, h, z) = common::read_exr(&out.join(format!("{}_depth.exr", eye.name())));
            assert_eq!((w, h), (256, projection.height as usize));
            let mut checked = 0;
            for y in (2..h - 2).step_by(5) {
                for x in (0..w).step_by(7) {
                    let (origin, dir) = pixel_eye_ray(&projection, eye, x, y);
                    let (want, wall) = to_wall(origin, dir);
                    // A pixel beside an edge between walls may show the other wall (the edge
                    // is drawn within the subdivision's tolerance of where it belongs).
                    let beside = [(x.saturating_sub(1), y), ((x + 1).min(w - 1), y), (x, y - 1), (x, y + 1)]
                        .iter()
                        .any(|&(nx, ny)| {
                            let (o, d) = pixel_eye_ray(&projection, eye, nx, ny);
                            to_wall(o, d).1 != wall
                        });
                    if beside {
                        continue;
                    }
                    let got = z[y * w + x];
                    assert!(
                        (got - want).abs() <= 1e-3 * want,
                        "{panorama} {eye:?} pixel ({x}, {y}): depth {got} m, the ray meets the wall at {want} m"
                    );
                    checked += 1;
                }
            }
            assert!(checked > 300);
        }
    }
    let _ = std::fs::remove_dir_all(&out);
}

/// Where a depth file's pixel shows no surface, its distance is +∞.
#[test]
fn depth_files_hold_infinity_where_no_surface_is() {
    let out = tmp("depth-background");
    let o = common::twister()
        .args(["render", "builtin:sphere100", "--panorama", "equirect", "--width", "128", "--depth", "--out"])
        .arg(&out)
        .output()
        .unwrap();
    assert!(o.status.success());
    let (w, h, z) = common::read_exr(&out.join("depth_TB.exr"));
    assert_eq!((w, h), (128, 128));
    assert!(z[0].is_infinite() && z[0] > 0.0, "the top-left corner shows no surface: {}", z[0]);
    assert!(z.iter().any(|d| d.is_finite() && *d > 1.0), "the sphere is in the depth");
    let _ = std::fs::remove_dir_all(&out);
}
