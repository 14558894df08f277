//! Materials on the GPU: textures land where the projection puts their texels, every sampler
//! mode matches the CPU twin, alpha MASK / BLEND and single-sided faces decide coverage, and a
//! real textured sample (BoxTextured) shows its texture's colours.

mod common;

use twister::encoding::params::raster_params;
use twister::encoding::subdivide::subdivide_params;

use glam::{Vec2, Vec3};
use twister::core::panoramas::projection::{Eye, Projection};
use twister::core::scenes::scene::SceneVertex;
use twister::core::settings::{Method, Split};
use twister::core::shading::material::{AlphaMode, Filter, Material, Mipmap, Wrap, NO_TEXTURE};
use twister::core::shading::texture::Texture;
use twister::cpu::raster::raster;
use twister::cpu::slit::slit;
use twister::cpu::subdivide::subdivide;
use twister::encoding::slits::{slit_params, slits};
use twister::EyeImage;
use twister::{RenderSettings, Scene};

const BG: [f32; 3] = [0.0, 0.0, 0.0];

/// A quad facing the viewer at depth `z` (x0..x1 × y0..y1), counter-clockwise as seen from the
/// viewer unless `reversed`; uv = `uv0` at the top-left corner to `uv1` at the bottom-right.
#[allow(clippy::too_many_arguments)]
fn quad(
    scene: &mut Scene,
    name: &str,
    x: [f32; 2],
    y: [f32; 2],
    z: f32,
    uv: [Vec2; 2],
    material: u32,
    color: [f32; 4],
    reversed: bool,
) {
    let corner = |i: usize, j: usize| SceneVertex {
        position: [x[i], y[j], z],
        normal: [0.0, 0.0, 1.0],
        color,
        uv: [[uv[0].x, uv[1].x][i], [uv[1].y, uv[0].y][j]],
        material,
        ..Default::default()
    };
    let v = [corner(0, 0), corner(1, 0), corner(1, 1), corner(0, 1)];
    let idx: &[u32] = if reversed { &[0, 2, 1, 0, 3, 2] } else { &[0, 1, 2, 0, 2, 3] };
    scene.add_mesh(name, &v, idx);
}

fn texture(w: u32, h: u32, f: impl Fn(u32, u32) -> [u8; 4]) -> Texture {
    let rgba = (0..h).flat_map(|y| (0..w).map(move |x| (x, y))).flat_map(|(x, y)| f(x, y)).collect();
    Texture { name: format!("{w}x{h}"), width: w, height: h, rgba }
}

/// 2×2 quadrants: top-left red, top-right blue, bottom-left green, bottom-right yellow.
const QUADRANTS: [[u8; 4]; 4] = [[255, 0, 0, 255], [0, 0, 255, 255], [0, 255, 0, 255], [255, 255, 0, 255]];

fn settings(width: u32, height: u32, method: Method) -> RenderSettings {
    let projection = Projection { width, height, ..Projection::default() };
    RenderSettings::new(projection).with_method(method).with_background(BG).with_ambient(1.0)
}

fn pixel_of(projection: &Projection, p: Vec3, eye: Eye) -> [f32; 2] {
    let q = projection.project(p, eye).unwrap();
    projection.to_pixel(q.u, q.v)
}

#[test]
fn texels_land_where_the_projection_puts_their_texture_coordinates() {
    // A 2 m quad 3 m ahead with a nearest-filtered 2×2 texture: its colour boundaries are the
    // quad's lines x = 0 (a column at u = ±α) and y = 0 (the centre row).
    let mut scene = Scene::new("quadrants");
    scene.textures.push(texture(2, 2, |x, y| QUADRANTS[(2 * y + x) as usize]));
    scene.materials.push(Material { texture: 0, mag_filter: Filter::Nearest as u32, ..Default::default() });
    quad(&mut scene, "quad", [-1.0, 1.0], [-1.0, 1.0], -3.0, [Vec2::ZERO, Vec2::ONE], 1, [1.0; 4], false);
    for method in [Method::Adaptive(Split::Length), Method::Slit(1)] {
        let s = settings(720, 180, method);
        let frame = common::render(&scene, &s);
        for eye in Eye::BOTH {
            let img = frame.eye(eye);
            let [bx, by] = pixel_of(&s.view.projection, Vec3::new(0.0, 0.0, -3.0), eye);
            let (mut checked, mut wrong) = (0, Vec::new());
            for (x, y) in common::pixels_where(img, |p| !common::is_background(p, BG)) {
                let (cx, cy) = (x as f32 + 0.5, y as f32 + 0.5);
                if (cx - bx).abs() < 1.5 || (cy - by).abs() < 1.5 {
                    continue;
                }
                let want = QUADRANTS[2 * (cy > by) as usize + (cx > bx) as usize];
                checked += 1;
                if img.pixel(x, y)[..3] != want[..3] {
                    wrong.push((x, y, img.pixel(x, y)));
                }
            }
            assert!(checked > 1000, "{method:?} {eye:?}: only {checked} pixels of the quad");
            assert!(
                wrong.is_empty(),
                "{method:?} {eye:?}: {} of {checked} wrong, e.g. {:?}",
                wrong.len(),
                &wrong[..wrong.len().min(5)]
            );
        }
    }
}

/// A scene exercising every sampler path: magnified nearest and linear, repeat / mirrored /
/// clamp outside 0..1, minified without mipmaps, nearest mip and trilinear, alpha mask.
fn sampler_scene() -> Scene {
    let mut scene = Scene::new("samplers");
    // A 16×16 pattern with gradients (so filtering shows) and a fine checker (so mip levels differ).
    scene
        .textures
        .push(texture(16, 16, |x, y| [(x * 16) as u8, (y * 16) as u8, if (x + y) % 2 == 0 { 255 } else { 0 }, 255]));
    scene.textures.push(texture(
        64,
        64,
        // 4-texel checker blocks over gradients: levels 0–2 keep the blocks, all differ.
        |x, y| if (x / 4 + y / 4) % 2 == 0 { [250, (4 * y) as u8, 30, 255] } else { [(4 * x) as u8, 40, 200, 255] },
    ));
    scene.textures.push(texture(8, 8, |x, _| [200, 90, 40, if x < 4 { 40 } else { 220 }]));
    let m = |texture: u32, wrap: Wrap, mag: Filter, min: Filter, mip: Mipmap| Material {
        texture,
        wrap_u: wrap as u32,
        wrap_v: wrap as u32,
        mag_filter: mag as u32,
        min_filter: min as u32,
        mipmap: mip as u32,
        ..Default::default()
    };
    scene.materials = vec![
        m(0, Wrap::Repeat, Filter::Nearest, Filter::Nearest, Mipmap::None),
        m(0, Wrap::MirroredRepeat, Filter::Linear, Filter::Linear, Mipmap::Linear),
        m(0, Wrap::ClampToEdge, Filter::Linear, Filter::Linear, Mipmap::Linear),
        m(1, Wrap::Repeat, Filter::Linear, Filter::Nearest, Mipmap::None),
        m(1, Wrap::Repeat, Filter::Linear, Filter::Linear, Mipmap::Nearest),
        m(1, Wrap::Repeat, Filter::Linear, Filter::Linear, Mipmap::Linear),
        Material {
            alpha_mode: AlphaMode::Mask as u32,
            alpha_cutoff: 0.5,
            ..m(2, Wrap::Repeat, Filter::Nearest, Filter::Nearest, Mipmap::None)
        },
    ];
    let wide = [Vec2::splat(-1.0), Vec2::splat(2.0)];
    let unit = [Vec2::ZERO, Vec2::ONE];
    let far = [Vec2::ZERO, Vec2::splat(8.0)];
    // Magnified quads ahead; minified (far, repeated) quads to the sides and behind.
    let rad = |deg: f32| deg.to_radians();
    let ring = |scene: &mut Scene, k: u32, deg: f32, dist: f32, half: f32, uv: [Vec2; 2]| {
        // Build the quad at −z then turn it to its azimuth.
        let first = scene.vertices.len();
        quad(scene, &format!("quad {k}"), [-half, half], [-half, half], -dist, uv, k + 1, [1.0; 4], false);
        let turn = glam::Mat3::from_rotation_y(-rad(deg));
        for v in &mut scene.vertices[first..] {
            v.position = (turn * Vec3::from(v.position)).into();
            v.normal = (turn * Vec3::from(v.normal)).into();
        }
    };
    ring(&mut scene, 0, -40.0, 2.0, 0.6, wide);
    ring(&mut scene, 1, 0.0, 2.0, 0.6, wide);
    ring(&mut scene, 2, 40.0, 2.0, 0.6, wide);
    ring(&mut scene, 3, 100.0, 4.0, 1.5, far);
    ring(&mut scene, 4, 160.0, 4.0, 1.5, far);
    ring(&mut scene, 5, -160.0, 4.0, 1.5, far);
    ring(&mut scene, 6, -100.0, 2.0, 0.6, unit);
    scene
}

/// Pixels whose colour differs by more than `tol` in some channel.
fn differing(a: &[u8], b: &[u8], tol: i32) -> usize {
    a.chunks(4)
        .zip(b.chunks(4))
        .filter(|(x, y)| x.iter().zip(y.iter()).any(|(p, q)| (*p as i32 - *q as i32).abs() > tol))
        .count()
}

#[test]
fn every_sampler_mode_matches_the_cpu_twin_in_both_drawing_stages() {
    let scene = sampler_scene();
    let table = scene.material_table(usize::MAX);
    // The raster stage (after the subdivision, here on the CPU).
    let s = settings(640, 120, Method::Adaptive(Split::Length));
    let frame = common::render(&scene, &s);
    let prepared =
        subdivide(&subdivide_params(&s, 0, scene.triangle_count() as u32), &scene.vertices, &scene.indices).vertices;
    let cpu_eyes = raster(&raster_params(&s), &prepared, &table, BG);
    for (eye, cpu) in Eye::BOTH.into_iter().zip(cpu_eyes) {
        let gpu = frame.eye(eye);
        let drawn = common::pixels_where(gpu, |p| !common::is_background(p, BG)).len();
        let bad = differing(&cpu.rgba, &gpu.rgba, 3);
        assert!(drawn > 4000, "{eye:?}: {drawn}");
        // Edge pixels may differ (coverage tie-breaks); sampling differences would be whole areas.
        assert!(bad * 100 <= drawn, "raster {eye:?}: {bad} of {drawn} pixels differ from the CPU twin");
    }
    // The slit stage (perspective-correct uv; derivatives from 2×2 quads on the GPU, from the
    // next pixel on the CPU).
    let s = settings(320, 64, Method::Slit(4));
    let frame = common::render(&scene, &s);
    for eye in Eye::BOTH {
        let params = slit_params(&s.view.projection, s.view(), eye, s.shading.ambient, false);
        let cpu = slit(&params, &slits(&s.view.projection, eye, 4), &scene, &table, BG);
        let gpu = frame.eye(eye);
        let drawn = common::pixels_where(gpu, |p| !common::is_background(p, BG)).len();
        let bad = differing(&cpu.rgba, &gpu.rgba, 6);
        assert!(bad * 100 <= 3 * drawn, "slit {eye:?}: {bad} of {drawn} pixels differ from the CPU twin");
    }
}

fn covered(img: &EyeImage, projection: &Projection, eye: Eye, x: [f32; 2], y: [f32; 2], z: f32) -> (usize, usize) {
    // Pixels strictly inside the projected rectangle (1.5 px margin), and how many are drawn.
    let [x0, y0] = pixel_of(projection, Vec3::new(x[0], y[1], z), eye);
    let [x1, y1] = pixel_of(projection, Vec3::new(x[1], y[0], z), eye);
    let (mut inside, mut drawn) = (0, 0);
    for py in (y0 + 1.5) as u32..(y1 - 1.5) as u32 {
        for px in (x0 + 1.5) as u32..(x1 - 1.5) as u32 {
            inside += 1;
            drawn += !common::is_background(img.pixel(px, py), BG) as usize;
        }
    }
    (inside, drawn)
}

#[test]
fn a_scene_of_single_sided_materials_culls_back_faces_in_the_rasterizer_as_the_fragments_would() {
    // Every material single-sided: the pipelines cull back faces (GpuScene::cull_back_faces); the
    // image is the one the fragment stage's discard gives, per eye (and with the CPU twin).
    let mut scene = Scene::new("single-sided");
    scene.materials = vec![Material { double_sided: 0, ..Default::default() }];
    let (y, z) = ([-0.4, 0.4], -3.0);
    let xs = [[-1.6, -0.8], [-0.6, 0.2], [0.4, 1.2]];
    let uv = [Vec2::ZERO, Vec2::ONE];
    // Material 1: the scene's first (0 is the table's default, double-sided).
    quad(&mut scene, "facing", xs[0], y, z, uv, 1, [1.0; 4], false);
    quad(&mut scene, "from behind", xs[1], y, z, uv, 1, [1.0; 4], true);
    quad(&mut scene, "facing again", xs[2], y, z, uv, 1, [1.0; 4], false);
    let r = common::renderer();
    let gs = twister::GpuScene::upload(&r.gpu, &scene).unwrap();
    assert!(gs.cull_back_faces);
    let mut mixed = scene.clone();
    quad(&mut mixed, "default material", [2.0, 2.5], y, z, uv, 0, [1.0; 4], false);
    assert!(
        !twister::GpuScene::upload(&r.gpu, &mixed).unwrap().cull_back_faces,
        "the default material is double-sided"
    );
    for method in [Method::Adaptive(Split::Error), Method::Vertex, Method::Slit(2)] {
        let s = settings(900, 150, method);
        let frame = r.render(&gs, &s).unwrap();
        for eye in Eye::BOTH {
            let img = frame.eye(eye);
            let cov = |x: [f32; 2]| {
                let (inside, drawn) = covered(img, &s.view.projection, eye, x, y, z);
                drawn as f32 / inside as f32
            };
            assert_eq!(cov(xs[0]), 1.0, "{method:?} {eye:?}: the facing quad");
            assert_eq!(cov(xs[1]), 0.0, "{method:?} {eye:?}: the quad seen from behind");
            assert_eq!(cov(xs[2]), 1.0, "{method:?} {eye:?}: the other facing quad");
        }
    }
}

#[test]
fn single_sided_faces_seen_from_behind_and_transparent_texels_are_not_drawn() {
    let mut scene = Scene::new("coverage");
    scene.textures.push(texture(2, 1, |x, _| [255, 255, 255, if x == 0 { 0 } else { 255 }]));
    scene.materials = vec![
        Material { double_sided: 0, ..Default::default() },
        Material {
            texture: 0,
            mag_filter: Filter::Nearest as u32,
            alpha_mode: AlphaMode::Mask as u32,
            alpha_cutoff: 0.5,
            ..Default::default()
        },
        Material { alpha_mode: AlphaMode::Blend as u32, ..Default::default() },
    ];
    let (y, z) = ([-0.4, 0.4], -3.0);
    let white = [1.0; 4];
    let xs = [[-2.6, -1.8], [-1.6, -0.8], [-0.6, 0.2], [0.4, 1.2], [1.4, 2.2]];
    let uv = [Vec2::ZERO, Vec2::ONE];
    quad(&mut scene, "single-sided, facing", [xs[0][0], xs[0][1]], y, z, uv, 1, white, false);
    quad(&mut scene, "single-sided, from behind", [xs[1][0], xs[1][1]], y, z, uv, 1, white, true);
    quad(&mut scene, "double-sided, from behind", [xs[2][0], xs[2][1]], y, z, uv, 0, white, true);
    quad(&mut scene, "mask", [xs[3][0], xs[3][1]], y, z, uv, 2, white, false);
    quad(&mut scene, "blend 0.5", [xs[4][0], xs[4][1]], y, z, uv, 3, [1.0, 1.0, 1.0, 0.5], false);
    for method in [Method::Adaptive(Split::Length), Method::Vertex, Method::Slit(2)] {
        let s = settings(900, 150, method);
        let frame = common::render(&scene, &s);
        for eye in Eye::BOTH {
            let img = frame.eye(eye);
            let cov = |_quad: usize, x: [f32; 2]| {
                let (inside, drawn) = covered(img, &s.view.projection, eye, x, y, z);
                drawn as f32 / inside as f32
            };
            let what = format!("{method:?} {eye:?}");
            assert_eq!(cov(0, xs[0]), 1.0, "{what}: a single-sided face seen from the front is drawn");
            assert_eq!(cov(1, xs[1]), 0.0, "{what}: a single-sided face seen from behind is culled");
            assert_eq!(cov(2, xs[2]), 1.0, "{what}: a double-sided face seen from behind is drawn");
            let mid = (xs[3][0] + xs[3][1]) / 2.0;
            assert_eq!(cov(3, [xs[3][0], mid]), 0.0, "{what}: texels below the mask cutoff are not drawn");
            assert_eq!(cov(3, [mid, xs[3][1]]), 1.0, "{what}: texels above the mask cutoff are drawn");
            let blend = cov(4, xs[4]);
            assert!((blend - 0.5).abs() < 0.08, "{what}: opacity 0.5 covers half the pixels, not {blend}");
        }
    }
}

#[test]
fn box_textured_shows_its_logo_colours() {
    if !common::assets_present() {
        return;
    }
    let dir = common::asset("gltf/BoxTextured/glTF");
    // The texture's colours under the paper's headlight (a glTF scene is otherwise lit by the
    // BRDF, and this one has no lights of its own).
    let mut s = settings(1200, 300, Method::Adaptive(Split::Length))
        .with_lighting(twister::core::shading::light::LightingMode::Headlight);
    let mut scene =
        twister::core::scenes::load::load_scene(dir.join("BoxTextured.gltf").to_str().unwrap(), &s.view.projection)
            .unwrap();
    assert_eq!(scene.textures.len(), 1);
    assert!(scene.materials[0].texture != NO_TEXTURE);
    scene.fit(1.5, &s.view.projection).unwrap();
    // Look at it from above a little, so that two faces show.
    s.view.viewer = Vec3::new(0.0, 0.3, 0.0);
    let frame = common::render(&scene, &s);
    let logo = image::open(dir.join("CesiumLogoFlat.png")).unwrap().to_rgba8();
    // The logo's three most common colours (quantized to 32 levels).
    let q = |p: &[u8]| [p[0] / 8, p[1] / 8, p[2] / 8];
    let mut counts = std::collections::HashMap::new();
    for p in logo.pixels() {
        *counts.entry(q(&p.0)).or_insert(0usize) += 1;
    }
    let mut common_colours: Vec<([u8; 3], usize)> = counts.into_iter().collect();
    common_colours.sort_by_key(|c| std::cmp::Reverse(c.1));
    let drawn = common::pixels_where(&frame.left, |p| !common::is_background(p, BG));
    assert!(drawn.len() > 2000, "{}", drawn.len());
    let near = |a: [u8; 3], b: [u8; 3]| (0..3).all(|c| (a[c] as i32 - b[c] as i32).abs() <= 1);
    for &(colour, n) in &common_colours[..3] {
        let share = n as f32 / (logo.width() * logo.height()) as f32;
        let seen = drawn.iter().filter(|&&(x, y)| near(q(&frame.left.pixel(x, y)), colour)).count() as f32
            / drawn.len() as f32;
        // The box shows the logo on every face: each colour covers a good part of what the logo's share is.
        assert!(seen > 0.3 * share, "logo colour {colour:?} (share {share:.3}) covers {seen:.3} of the box");
    }
    // Not a flat colour: the box shows many of the logo's colours.
    let distinct: std::collections::HashSet<[u8; 3]> = drawn.iter().map(|&(x, y)| q(&frame.left.pixel(x, y))).collect();
    assert!(distinct.len() >= 20, "only {} distinct colours on the box", distinct.len());
}

/// Anisotropic filtering (`--anisotropy`) against the exact pixel average: on a floor striped
/// along x seen at grazing angles (a footprint long along the view, narrow across it), each
/// pixel's value is compared with the mean of the level-0 texture over the pixel (16 rays per
/// pixel through `pixel_ray`, met with the floor's plane). Sixteen probes along the footprint's
/// longer axis keep the stripes that isotropic filtering (the longest axis picks the level)
/// blurs to grey, in the drawing stages and the ray tracer alike; one probe is the isotropic
/// filter. (The subdivision's τ at 0.05 px: a texture lands where the geometry puts it, and at
/// the default 0.25 px the stripes, 2–3 px wide here, shift enough to leave 0.11 instead of
/// 0.04 with 16 probes.)
#[test]
fn anisotropic_filtering_keeps_the_stripes_that_isotropic_filtering_blurs() {
    use twister::core::panoramas::projection::pixel_ray;
    use twister::core::shading::color::srgb_to_linear;
    let projection =
        Projection { vertical: twister::core::panoramas::projection::Vertical::Exact, ..Projection::equirect(192) };
    let scene = common::striped_floor();
    // The exact mean over each pixel of the eye's image, where the pixel sees the floor 2 to 10 m
    // away, looking mostly along z (across the stripes).
    let reference = |eye: Eye| -> Vec<Option<f64>> {
        (0..projection.width * projection.height)
            .map(|i| {
                let (x, y) = (i % projection.width, i / projection.width);
                let mut sum = 0.0;
                for k in 0..16 {
                    let frag =
                        Vec2::new(x as f32 + (k % 4) as f32 / 4.0 + 0.125, y as f32 + (k / 4) as f32 / 4.0 + 0.125);
                    let (o, d) = pixel_ray(&projection, eye, frag);
                    let t = (-1.0 - o.y) / d.y;
                    let p = o + t * d;
                    let r = Vec2::new(p.x, p.z).length();
                    if d.y >= 0.0 || !(2.0..=10.0).contains(&r) || d.x.abs() > 0.5 * d.z.abs() {
                        return None;
                    }
                    let column = ((p.x / common::STRIPE_REPEAT_M).rem_euclid(1.0) * 64.0) as u32;
                    sum += common::stripe_is_white(column.min(63)) as u32 as f64;
                }
                Some(sum / 16.0)
            })
            .collect()
    };
    let references = Eye::BOTH.map(reference);
    for method in [Method::Adaptive(Split::Error), Method::Slit(4), Method::Trace] {
        let error = |anisotropy: u32| {
            let settings = RenderSettings::new(projection)
                .with_method(method)
                .with_background(BG)
                .with_ambient(1.0)
                .with_anisotropy(anisotropy)
                .with_max_error_px(0.05);
            let frame = common::render(&scene, &settings);
            let (mut sum, mut n) = (0.0, 0);
            for (eye, reference) in Eye::BOTH.into_iter().zip(&references) {
                let image = frame.eye(eye);
                for (i, r) in reference.iter().enumerate() {
                    if let Some(r) = r {
                        let (x, y) = (i as u32 % projection.width, i as u32 / projection.width);
                        let value = srgb_to_linear(image.pixel(x, y)[0] as f32 / 255.0) as f64;
                        sum += (value - r).abs();
                        n += 1;
                    }
                }
            }
            assert!(n > 500, "{method:?}: {n} floor pixels");
            sum / n as f64
        };
        let (isotropic, anisotropic) = (error(1), error(16));
        eprintln!("{method:?}: mean |pixel − exact mean| isotropic {isotropic:.4}, 16 probes {anisotropic:.4}");
        assert!(anisotropic < 0.3 * isotropic, "{method:?}: isotropic {isotropic:.4}, 16 probes {anisotropic:.4}");
    }
}
