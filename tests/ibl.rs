//! Image-based lighting (issue 17): the white furnace on the GPU and in the CPU twin, metals
//! mirroring the environment's colours, highlights growing with roughness, and bad environment
//! files refused with one line.

mod common;

use std::sync::Arc;

use glam::Vec3;
use twister::core::scenes::builtin;
use twister::core::shading::color::srgb_to_linear;
use twister::core::shading::environment::Environment;
use twister::core::shading::light::Tonemap;
use twister::core::shading::material::Material;
use twister::{Eye, Projection, RenderSettings, Scene, Vertical};

/// Spheres of the given (metallic, roughness) and colour on a circle 1.8 m around the viewer,
/// 45° apart, centred ahead.
fn spheres(name: &str, looks: &[(f32, f32)], color: [f32; 4]) -> Scene {
    let mut scene = Scene::new(name);
    scene.materials =
        looks.iter().map(|&(metallic, roughness)| Material { metallic, roughness, ..Default::default() }).collect();
    let n = looks.len() as f32;
    for k in 0..looks.len() {
        let azimuth = (k as f32 - 0.5 * (n - 1.0)) * std::f32::consts::FRAC_PI_4;
        let s = builtin::sphere_scene(800, Vec3::new(1.8 * azimuth.sin(), 0.0, -1.8 * azimuth.cos()), 0.55, "ball");
        let first = scene.vertices.len();
        scene.add_mesh(format!("ball {k}"), &s.vertices, &s.indices);
        for v in &mut scene.vertices[first..] {
            v.material = k as u32 + 1;
            v.color = color;
        }
    }
    scene
}

fn settings(width: u32, height: u32) -> RenderSettings {
    let projection = Projection { width, height, vertical: Vertical::Exact, ..Projection::default() };
    RenderSettings::new(projection).with_tonemap(Tonemap::None).with_background([0.0, 0.0, 0.0])
}

/// Linear colours of the pixels the spheres cover, per sphere (split by image column).
fn sphere_pixels(rgba: &[u8], width: u32, columns: &[(u32, u32)]) -> Vec<Vec<Vec3>> {
    let mut out = vec![Vec::new(); columns.len()];
    for (i, px) in rgba.chunks(4).enumerate() {
        let x = i as u32 % width;
        if px[..3] == [0, 0, 0] {
            continue;
        }
        if let Some(k) = columns.iter().position(|&(a, b)| x >= a && x < b) {
            out[k].push(Vec3::new(px[0] as f32, px[1] as f32, px[2] as f32).map(|c| srgb_to_linear(c / 255.0)));
        }
    }
    out
}

/// Image columns of the spheres: contiguous runs of drawn columns in the middle rows.
fn sphere_columns(rgba: &[u8], width: u32, height: u32) -> Vec<(u32, u32)> {
    let drawn = |x: u32| (height / 3..2 * height / 3).any(|y| rgba[4 * (y * width + x) as usize..][..3] != [0, 0, 0]);
    let mut runs = Vec::new();
    let mut start = None;
    for x in 0..=width {
        match (x < width && drawn(x), start) {
            (true, None) => start = Some(x),
            (false, Some(a)) => {
                runs.push((a, x));
                start = None;
            }
            _ => {}
        }
    }
    runs
}

/// White furnace: white spheres, rough and smooth, dielectric and metal, inside a uniform
/// environment of radiance 0.5 reflect 0.5 at every pixel (± 2 %): image-based lighting neither
/// makes nor loses energy. On the GPU and in the CPU twin.
#[test]
fn white_spheres_in_a_uniform_environment_reflect_exactly_what_arrives() {
    let looks = [(0.0, 1.0), (0.0, 0.5), (0.0, 0.1), (1.0, 1.0), (1.0, 0.5)];
    let mut scene = spheres("furnace", &looks, [1.0; 4]);
    scene.environment = Some(Arc::new(Environment::uniform(Vec3::splat(0.5)).prepare()));
    let s = settings(480, 120);
    let gpu = common::render(&scene, &s);
    let cpu = twister::cpu::render::render(&scene, &s).expect("the twins' frame").eyes;
    for (what, rgba) in [("GPU", &gpu.eye(Eye::Left).rgba), ("CPU twin", &cpu[0].rgba)] {
        let columns = sphere_columns(rgba, 480, 120);
        assert_eq!(columns.len(), looks.len(), "{what}: {columns:?}");
        for (k, px) in sphere_pixels(rgba, 480, &columns).iter().enumerate() {
            assert!(px.len() > 300, "{what}: sphere {k} covers {} pixels", px.len());
            let worst = px.iter().map(|c| (*c - 0.5).abs().max_element()).fold(0.0, f32::max);
            assert!(worst <= 0.01, "{what}: sphere {k} {:?}: radiance off by up to {worst} of 0.5", looks[k]);
        }
    }
}

/// An environment red above the horizon and green below, plus a small bright sun ahead-up.
fn two_tone(sun: f32) -> Environment {
    let (w, h) = (256u32, 128u32);
    let sun_dir = Vec3::new(0.0, 0.5, 1.0).normalize();
    let radiance = (0..w * h)
        .map(|i| {
            let d = twister::core::shading::environment::direction_at((i % w) as f32 + 0.5, (i / w) as f32 + 0.5, w, h);
            let base = if d.y > 0.0 { Vec3::new(0.6, 0.05, 0.05) } else { Vec3::new(0.05, 0.6, 0.05) };
            base + if d.dot(sun_dir) > 0.995 { Vec3::splat(sun) } else { Vec3::ZERO }
        })
        .collect();
    Environment { name: "two-tone".into(), width: w, height: h, radiance }
}

/// A smooth white metal mirrors the environment: red in its upper half, green in its lower;
/// the sun's highlight (behind the viewer, up) covers more of a sphere the rougher it is.
#[test]
fn metals_mirror_the_environment_and_highlights_grow_with_roughness() {
    let looks = [(1.0, 0.05), (1.0, 0.3), (1.0, 0.6)];
    let mut scene = spheres("metals", &looks, [1.0; 4]);
    scene.environment = Some(Arc::new(two_tone(40.0).prepare()));
    let (w, h) = (480u32, 160u32);
    let frame = common::render(&scene, &settings(w, h));
    let rgba = &frame.eye(Eye::Left).rgba;
    let columns = sphere_columns(rgba, w, h);
    assert_eq!(columns.len(), 3, "{columns:?}");
    // The smooth sphere's top and bottom rows.
    let (a, b) = columns[0];
    let rows: Vec<u32> =
        (0..h).filter(|&y| (a..b).any(|x| rgba[4 * (y * w + x) as usize..][..3] != [0, 0, 0])).collect();
    let (top, bottom) = (rows[0] + 3, rows[rows.len() - 1] - 3);
    let at = |x: u32, y: u32| {
        Vec3::new(rgba[4 * (y * w + x) as usize] as f32, rgba[4 * (y * w + x) as usize + 1] as f32, 0.0)
    };
    let mid = (a + b) / 2;
    let (up, down) = (at(mid, top), at(mid, bottom));
    assert!(up.x > 2.0 * up.y, "the smooth metal's top shows the red sky: {up}");
    assert!(down.y > 2.0 * down.x, "its bottom shows the green ground: {down}");
    // Highlight: pixels brighter than the sky can make.
    let highlight: Vec<usize> =
        sphere_pixels(rgba, w, &columns).iter().map(|px| px.iter().filter(|c| c.min_element() > 0.5).count()).collect();
    assert!(highlight[0] >= 1, "the smooth sphere shows the sun: {highlight:?}");
    assert!(highlight[0] < highlight[1] && highlight[1] < highlight[2], "highlight pixels by roughness: {highlight:?}");
}

/// Absent, corrupt (a header claiming 10¹⁶ texels), truncated and wrongly typed environment
/// files: one line naming `--environment` and the file, no panic, no huge allocation.
#[test]
fn bad_environment_files_are_refused_with_one_line() {
    if !common::assets_present() {
        return;
    }
    let dir = common::TempDir::new(format!("twister-ibl-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let corrupt = dir.join("corrupt.hdr");
    std::fs::write(&corrupt, b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 99999999 +X 99999999\n\x02\x02").unwrap();
    let truncated = dir.join("truncated.hdr");
    let real = std::fs::read(common::asset("environments/venice_sunset_1k.hdr")).unwrap();
    std::fs::write(&truncated, &real[..real.len() / 3]).unwrap();
    for (file, says) in [
        (dir.join("absent.hdr"), "No such file"),
        (corrupt, "texels"),
        (truncated, ""),
        (dir.join("picture.png"), "not a .hdr or .exr file"),
    ] {
        let err = Environment::load(&file).expect_err("refused");
        let line = err.to_string();
        assert!(line.starts_with("environment: ") && line.contains(&*file.to_string_lossy()), "{line}");
        assert!(line.contains(says) && !line.contains('\n'), "{line}");
    }
    let env = Environment::load(&common::asset("environments/venice_sunset_1k.hdr")).unwrap();
    assert_eq!((env.width, env.height), (1024, 512));
}

/// An environment the user gave shows all around as the background, along each pixel's own
/// ray: red above the horizon, green below, the background's measuring values untouched; the
/// built-in studio only lights (the background colour stays).
#[test]
fn a_given_environment_is_the_background_and_the_studio_is_not() {
    let mut scene = spheres("one ball", &[(0.0, 0.5)], [0.8, 0.8, 0.8, 1.0]);
    let prepared = two_tone(0.0).prepare();
    let s = settings(256, 128).with_measure_error(true);
    for (background, what) in [(true, "given"), (false, "studio-like")] {
        scene.environment =
            Some(Arc::new(twister::core::shading::environment::PreparedEnvironment { background, ..prepared.clone() }));
        let frame = common::render(&scene, &s);
        let img = frame.eye(Eye::Right);
        let objects = &frame.measurement.as_ref().unwrap().object[1];
        let (top, bottom) = (img.pixel(10, 5), img.pixel(10, 122));
        assert_eq!((objects[(5 * 256 + 10) as usize], objects[(122 * 256 + 10) as usize]), (0, 0), "{what}");
        if background {
            assert!(top[0] > 150 && top[1] < 90, "{what}: the sky behind, {top:?}");
            assert!(bottom[1] > 150 && bottom[0] < 90, "{what}: the ground behind, {bottom:?}");
        } else {
            assert_eq!((&top[..3], &bottom[..3]), (&[0u8, 0, 0][..], &[0u8, 0, 0][..]), "{what}");
        }
    }
}

/// `--hdr`: the linear colour, not tone mapped and not clamped, from a float colour target. On
/// the GPU: lit spheres under a strong light and the sunset reach well above 1, and tone mapping
/// the linear colour on the CPU (PBR Neutral, sRGB) gives the ordinary frame's pixels. From the
/// command line: left_hdr.exr and right_hdr.exr (R, G, B), and slit/trace refused in one line.
#[test]
fn hdr_frames_hold_the_linear_colour_and_tone_map_to_the_ordinary_frame() {
    use twister::core::shading::light::{tonemap, LightingParams};
    use twister::cpu::fragment::display_bytes;
    let mut scene = common::lit_spheres();
    scene.environment = Some(common::studio(true));
    let s = RenderSettings::new(Projection { width: 320, height: 80, ..Projection::default() }).with_exposure_ev(1.0);
    let ldr = common::render(&scene, &s);
    let hdr_frame = common::render(&scene, &s.with_hdr(true));
    let hdr = hdr_frame.hdr.as_ref().expect("an HDR frame");
    // The same frame draws both: its display images are the ordinary frame's.
    assert!(hdr_frame.left.rgba == ldr.left.rgba && hdr_frame.right.rgba == ldr.right.rgba);
    let peak = hdr[0].iter().flat_map(|c| *c).fold(0.0f32, f32::max);
    assert!(peak > 2.0, "the linear colour is not clamped: peak {peak}");
    let params = LightingParams { exposure: 1.0, tonemap: Tonemap::PbrNeutral.code(), ..Default::default() };
    for (k, eye) in Eye::BOTH.into_iter().enumerate() {
        let img = ldr.eye(eye);
        let off = hdr[k]
            .iter()
            .enumerate()
            .filter(|(i, c)| {
                let want = &img.rgba[4 * i..4 * i + 3];
                let got = display_bytes(tonemap(Vec3::from(**c), &params));
                got.iter().zip(want).any(|(a, b)| a.abs_diff(*b) > 1)
            })
            .count();
        assert!(off * 1000 <= hdr[k].len(), "{eye:?}: {off} of {} pixels tone map elsewhere", hdr[k].len());
    }
}

/// Khronos MetalRoughSpheresNoTextures in the red-sky, green-ground environment with a sun: each
/// sphere (object id) mirrors the sky above and the ground below the sharper the smoother it is,
/// and more so when metallic (the highlight's growth with roughness is tested on the synthetic
/// spheres above, where the sun's image is not cut by the grid).
#[test]
fn metal_rough_spheres_mirror_the_environment_by_roughness() {
    if !common::assets_present() {
        return;
    }
    let path = common::asset("gltf/MetalRoughSpheresNoTextures/glTF-Binary/MetalRoughSpheresNoTextures.glb");
    let (w, h) = (1024u32, 256u32);
    let projection = Projection { width: w, height: h, vertical: Vertical::Exact, ..Projection::default() };
    let mut scene = twister::core::scenes::load::load_scene(path.to_str().unwrap(), &projection).unwrap();
    scene.fit(3.0, &projection).unwrap();
    scene.environment = Some(Arc::new(two_tone(40.0).prepare()));
    let frame = common::render(&scene, &settings(w, h).with_measure_error(true));
    let objects = &frame.measurement.as_ref().unwrap().object[0];
    let img = frame.eye(Eye::Left);
    // Per object: its material's factors, and its pixels' rows and colours.
    let mut spheres = Vec::new();
    for (k, o) in scene.objects.iter().enumerate() {
        let v = scene.vertices[scene.indices[3 * o.first_triangle as usize] as usize];
        let m = scene.materials.get(v.material as usize - 1).copied().unwrap_or_default();
        let px: Vec<(u32, Vec3)> = (0..w * h)
            .filter(|&i| objects[i as usize] == k as u32 + 1)
            .map(|i| {
                let p = img.pixel(i % w, i / w);
                (i / w, Vec3::new(p[0] as f32, p[1] as f32, p[2] as f32))
            })
            .collect();
        if px.len() < 200 {
            continue; // the labels, the backdrop's edges
        }
        let (top, bottom) = (px.iter().map(|p| p.0).min().unwrap(), px.iter().map(|p| p.0).max().unwrap());
        let band = |lo: u32, hi: u32| {
            let sel: Vec<Vec3> = px.iter().filter(|p| p.0 >= lo && p.0 <= hi).map(|p| p.1).collect();
            sel.iter().fold(Vec3::ZERO, |a, c| a + *c) / sel.len().max(1) as f32
        };
        let third = (bottom - top) / 3;
        let (up, down) = (band(top, top + third), band(bottom - third, bottom));
        // How much redder the top is than the bottom, and greener the bottom than the top.
        let contrast = (up.x - down.x) + (down.y - up.y);
        spheres.push((m.metallic, m.roughness, contrast));
    }
    assert!(spheres.len() >= 20, "{} spheres found", spheres.len());
    let metals: Vec<_> = spheres.iter().filter(|s| s.0 > 0.9).collect();
    let dielectrics: Vec<_> = spheres.iter().filter(|s| s.0 < 0.1).collect();
    assert!(metals.len() >= 3 && dielectrics.len() >= 3, "{spheres:?}");
    let smooth = |set: &[&(f32, f32, f32)], f: fn(f32) -> bool| {
        let sel: Vec<_> = set.iter().filter(|s| f(s.1)).collect();
        sel.iter().map(|s| s.2).sum::<f32>() / sel.len().max(1) as f32
    };
    let (metal_smooth, metal_rough) = (smooth(&metals, |r| r < 0.3), smooth(&metals, |r| r > 0.7));
    let dielectric_smooth = smooth(&dielectrics, |r| r < 0.3);
    assert!(metal_smooth > 1.8 * metal_rough.max(1.0), "metal contrast smooth {metal_smooth}, rough {metal_rough}");
    assert!(
        metal_smooth > dielectric_smooth,
        "smooth metal {metal_smooth} against smooth dielectric {dielectric_smooth}"
    );
}

/// `--environment-yaw`: an environment whose only bright part faces +x (azimuth 90°) shows it
/// ahead when turned by −90°, in the rasterizer's background and the ray tracer's alike.
#[test]
fn the_environment_turns_by_its_yaw() {
    let (w, h) = (256u32, 64u32);
    let radiance = (0..w * h)
        .map(|i| {
            let d = twister::core::shading::environment::direction_at((i % w) as f32 + 0.5, (i / w) as f32 + 0.5, w, h);
            if d.x > 0.7 {
                Vec3::new(0.9, 0.9, 0.1)
            } else {
                Vec3::splat(0.02)
            }
        })
        .collect();
    let env = Environment { name: "east".into(), width: w, height: h, radiance };
    // A ball behind the viewer (columns 0 and 255 only): the frame's BRDF and environment on.
    let mut scene = spheres("ball behind", &[(1.0, 0.0)], [1.0; 4]);
    for v in &mut scene.vertices {
        v.position[2] += 3.6;
    }
    scene.environment =
        Some(Arc::new(twister::core::shading::environment::PreparedEnvironment { background: true, ..env.prepare() }));
    let bright_columns = |frame: &twister::Frame| -> Vec<u32> {
        let img = frame.eye(Eye::Left);
        (0..img.width).filter(|&x| img.pixel(x, img.height / 2)[0] > 150).collect()
    };
    let base = settings(256, 64);
    use twister::core::settings::{Method, Split};
    for method in [Method::Adaptive(Split::Error), Method::Trace] {
        let straight = if method == Method::Trace {
            let r = common::renderer();
            let gs = twister::GpuScene::upload(&r.gpu, &scene).and_then(|g| g.with_bvh(&r.gpu, &scene)).unwrap();
            let traced = base.with_method(method);
            (r.render(&gs, &traced).unwrap(), r.render(&gs, &traced.with_environment_yaw_deg(-90.0)).unwrap())
        } else {
            (common::render(&scene, &base), common::render(&scene, &base.with_environment_yaw_deg(-90.0)))
        };
        let (east, turned) = (bright_columns(&straight.0), bright_columns(&straight.1));
        let mid = |c: &[u32]| c.iter().map(|&x| x as f32).sum::<f32>() / c.len().max(1) as f32;
        // Azimuth 90° is column 192 of 256; turned by −90°, column 128 (ahead).
        assert!((mid(&east) - 192.0).abs() < 4.0, "{method:?}: bright columns around {}", mid(&east));
        assert!((mid(&turned) - 128.0).abs() < 4.0, "{method:?}: turned, around {}", mid(&turned));
    }
}

/// The preparation is cached on disk: read back, it is exactly what preparing gives; a damaged
/// or truncated cache file is prepared again and replaced by a whole one.
#[test]
fn the_prepared_environment_is_cached_and_a_damaged_cache_is_replaced() {
    if !common::assets_present() {
        return;
    }
    use twister::core::caches::environment_cache::cache_file;
    let dir = common::TempDir::new(format!("twister-env-cache-{}", std::process::id()));
    let env = Environment::load(&common::asset("environments/venice_sunset_1k.hdr")).unwrap();
    let fresh = env.prepare();
    let first = env.prepare_cached_in(Some(&dir));
    assert_eq!(first, fresh, "written");
    let file = cache_file(&dir, &env);
    let bytes = std::fs::read(&file).unwrap();
    assert_eq!(env.prepare_cached_in(Some(&dir)), fresh, "read back");
    for damage in ["truncated", "flipped"] {
        let mut bad = bytes.clone();
        if damage == "truncated" {
            bad.truncate(bytes.len() / 2);
        } else {
            bad[bytes.len() / 3] ^= 0x40;
        }
        std::fs::write(&file, &bad).unwrap();
        assert_eq!(env.prepare_cached_in(Some(&dir)), fresh, "{damage} cache file");
        assert_eq!(std::fs::read(&file).unwrap(), bytes, "{damage} cache file replaced by a whole one");
    }
    // No temporary files are left behind.
    assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 1);
    std::fs::remove_dir_all(&dir).unwrap();
}
