//! Shared helpers for the integration tests: one GPU renderer per test binary.
#![allow(dead_code)]

use std::sync::OnceLock;

use twister::gpu::Gpu;
use twister::{EyeImage, Frame};
use twister::{GpuScene, RenderSettings, Renderer, Scene};

pub mod gltf_files;

/// The assets folder: `TWISTER_ASSETS` where that is set, else `../shared/assets` beside the
/// workspace (cargo runs each member's tests in that member's folder, so not the working
/// directory's).
pub fn assets_root() -> std::path::PathBuf {
    use twister::core::assets::{ASSETS_VAR, DEFAULT_ASSETS};
    let here = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let workspace = here.ancestors().find(|d| d.join("shaders").is_dir()).unwrap_or(here);
    std::env::var_os(ASSETS_VAR).map_or_else(|| workspace.join(DEFAULT_ASSETS), std::path::PathBuf::from)
}

/// A PNG file's width and height.
pub fn png_size(p: &std::path::Path) -> (u32, u32) {
    image::image_dimensions(p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

pub fn renderer() -> &'static Renderer {
    static R: OnceLock<Renderer> = OnceLock::new();
    R.get_or_init(|| Renderer::new(Gpu::new().unwrap_or_else(|e| panic!("{e}"))).unwrap_or_else(|e| panic!("{e}")))
}

/// A frame of `scene` (uploaded with its BVH for the ray tracer).
pub fn render(scene: &Scene, settings: &RenderSettings) -> Frame {
    let r = renderer();
    let mut gs = GpuScene::upload(&r.gpu, scene).expect("upload");
    if settings.subdivision.method == twister::core::settings::Method::Trace {
        gs = gs.with_bvh(&r.gpu, scene).expect("BVH");
    }
    r.render(&gs, settings).expect("render")
}

/// Pixels of an image matching a predicate, as (x, y).
pub fn pixels_where(img: &EyeImage, f: impl Fn([u8; 4]) -> bool) -> Vec<(u32, u32)> {
    let mut out = Vec::new();
    for y in 0..img.height {
        for x in 0..img.width {
            if f(img.pixel(x, y)) {
                out.push((x, y));
            }
        }
    }
    out
}

pub fn is_background(px: [u8; 4], bg: [f32; 3]) -> bool {
    (0..3).all(|c| (px[c] as f32 - bg[c] * 255.0).abs() <= 1.0)
}

/// A file or folder of the third-party assets (`TWISTER_ASSETS`, default `../shared/assets`).
/// Call [`assets_present`] first: where the folder is here, a missing file fails the test, naming it.
pub fn asset(relative: &str) -> std::path::PathBuf {
    let path = assets_root().join(relative);
    assert!(path.exists(), "test asset {} is missing (see the assets' README)", path.display());
    path
}

/// Whether this test can use the third-party assets; where they are absent it is recorded as
/// not run (the test script counts it) and should return. Under CI a missing folder fails it.
pub fn assets_present() -> bool {
    let thread = std::thread::current();
    present_for_test(&assets_root(), thread.name().unwrap_or("a test"))
}

/// The environment variable naming a folder where tests that did not run for want of the assets
/// leave one file each (`scripts/test.sh` counts them).
pub const SKIPPED_VAR: &str = "TWISTER_ASSET_SKIPS";

/// For a test that needs the assets: whether they are here (at `root`). Where they are not, the
/// test is recorded as not run (one line on stderr, one file under [`SKIPPED_VAR`]) and the
/// caller returns; under CI (`CI=true`) they must be here, so a missing folder panics, naming it:
/// CI can never turn green without them.
fn present_for_test(root: &std::path::Path, test: &str) -> bool {
    use twister::core::assets::ASSETS_VAR;
    if root.is_dir() {
        return true;
    }
    if std::env::var("CI").is_ok_and(|v| v == "true" || v == "1") {
        panic!(
            "{test}: the third-party assets are missing ({} not found; set {ASSETS_VAR}), and CI must run every test",
            root.display()
        );
    }
    eprintln!("{test}: not run ({} not found; set {ASSETS_VAR})", root.display());
    if let Some(dir) = std::env::var_os(SKIPPED_VAR) {
        use std::sync::atomic::{AtomicU32, Ordering};
        static N: AtomicU32 = AtomicU32::new(0);
        let n = N.fetch_add(1, Ordering::Relaxed);
        let file = std::path::PathBuf::from(dir).join(format!("{}-{n}", std::process::id()));
        // Best effort: the count is a report, not a result.
        let _ = std::fs::create_dir_all(file.parent().unwrap()).and_then(|_| std::fs::write(&file, test));
    }
    false
}

/// Standard base64 (for data: URIs in generated glTF files).
pub fn base64(bytes: &[u8]) -> String {
    const T: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut s = String::new();
    for c in bytes.chunks(3) {
        let n = (c[0] as u32) << 16 | (*c.get(1).unwrap_or(&0) as u32) << 8 | *c.get(2).unwrap_or(&0) as u32;
        for k in 0..4 {
            s.push(if k <= c.len() { T[(n >> (18 - 6 * k) & 63) as usize] as char } else { '=' });
        }
    }
    s
}

/// Reads the channel Z of an OpenEXR file: (width, height, values).
pub fn read_exr(path: &std::path::Path) -> (usize, usize, Vec<f32>) {
    use exr::prelude::*;
    let image = read()
        .no_deep_data()
        .largest_resolution_level()
        .specific_channels()
        .required("Z")
        .collect_pixels(
            |size, _| (size.width(), size.height(), vec![0.0f32; size.width() * size.height()]),
            |(w, _, v), pos, (z,): (f32,)| v[pos.y() * *w + pos.x()] = z,
        )
        .first_valid_layer()
        .all_attributes()
        .from_file(path)
        .unwrap();
    image.layer_data.channel_data.pixels
}

/// A floor 1 m below the eyes, 40 m wide and deep, with a one-texel black-and-white checker
/// (64×64, trilinear) repeated 20 times: level 0 aliases towards the horizon, the mip levels
/// average it to grey.
#[allow(dead_code)]
pub fn checker_floor() -> twister::Scene {
    let rgba =
        (0..64u32 * 64).flat_map(|i| if (i % 64 + i / 64) % 2 == 0 { [255; 4] } else { [0, 0, 0, 255] }).collect();
    let corners =
        [[-20.0, 0.5, 0.0, 0.0], [20.0, 0.5, 20.0, 0.0], [20.0, -40.0, 20.0, 20.0], [-20.0, -40.0, 0.0, 20.0]];
    textured_floor("checker", rgba, corners)
}

/// A floor 1 m below the viewer, 60 m square, striped along x: a 64×64 texture of white and
/// black columns 2 texels wide (period 4), one repeat per `STRIPE_REPEAT_M` metres, filtered
/// linearly between linear mip levels. Seen at grazing angles the texture's footprint is long
/// along the view and narrow across it: what anisotropic filtering is for.
pub fn striped_floor() -> twister::Scene {
    let rgba = (0..64u32 * 64).flat_map(|i| if stripe_is_white(i % 64) { [255; 4] } else { [0, 0, 0, 255] }).collect();
    let corners = [[-30.0, 30.0], [30.0, 30.0], [30.0, -30.0], [-30.0, -30.0]]
        .map(|[x, z]| [x, z, x / STRIPE_REPEAT_M, z / STRIPE_REPEAT_M]);
    textured_floor("stripes", rgba, corners)
}

/// A floor quad 1 m below the viewer, white, its corners (x, z, u, v) in order, with a 64×64
/// texture (`rgba`) filtered linearly between linear mip levels.
fn textured_floor(name: &str, rgba: Vec<u8>, corners: [[f32; 4]; 4]) -> twister::Scene {
    use twister::core::scenes::scene::SceneVertex;
    use twister::core::shading::material::{Filter, Material, Mipmap};
    use twister::core::shading::texture::Texture;
    let mut scene = twister::Scene::new(format!("{name} floor"));
    scene.textures.push(Texture { name: name.into(), width: 64, height: 64, rgba });
    scene.materials.push(Material {
        texture: 0,
        min_filter: Filter::Linear as u32,
        mag_filter: Filter::Linear as u32,
        mipmap: Mipmap::Linear as u32,
        ..Default::default()
    });
    let v = corners.map(|[x, z, u, v]| SceneVertex {
        position: [x, -1.0, z],
        normal: [0.0, 1.0, 0.0],
        color: [1.0; 4],
        uv: [u, v],
        material: 1,
        ..Default::default()
    });
    scene.add_mesh("floor", &v, &[0, 1, 2, 0, 2, 3]);
    scene
}

/// Metres per repeat of `striped_floor`'s texture.
pub const STRIPE_REPEAT_M: f32 = 5.0;

/// Whether texel column `x` of `striped_floor`'s texture is white.
pub fn stripe_is_white(x: u32) -> bool {
    (x / 2) % 2 == 0
}

/// Three spheres ahead — a rough white dielectric, a gold metal, an emissive one — under a point
/// light with a range, a spot light and a directional light (`KHR_lights_punctual`): the glTF BRDF.
pub fn lit_spheres() -> twister::Scene {
    use glam::Vec3;
    use twister::core::shading::light::{Light, LightKind};
    use twister::core::shading::material::Material;
    let mut scene = twister::Scene::new("lit spheres");
    scene.materials = vec![
        Material { metallic: 0.0, roughness: 0.5, ..Default::default() },
        Material { metallic: 1.0, roughness: 0.3, ..Default::default() },
        Material {
            metallic: 0.0,
            roughness: 0.8,
            emissive_r: 0.6,
            emissive_g: 0.3,
            emissive_b: 0.1,
            ..Default::default()
        },
    ];
    let colours = [[0.9, 0.9, 0.9, 1.0], [1.0, 0.78, 0.34, 1.0], [0.2, 0.2, 0.2, 1.0]];
    for (k, x) in [-1.3f32, 0.0, 1.3].into_iter().enumerate() {
        let s = twister::core::scenes::builtin::sphere_scene(800, Vec3::new(x, 0.0, -1.6), 0.6, "ball");
        let first = scene.vertices.len();
        scene.add_mesh(format!("ball {k}"), &s.vertices, &s.indices);
        for v in &mut scene.vertices[first..] {
            v.material = k as u32 + 1;
            v.color = colours[k];
        }
    }
    let light = |kind, position: Vec3, direction: Vec3, color: Vec3| Light {
        kind,
        position,
        direction: direction.normalize(),
        color,
        range: None,
        inner_cone: 0.2,
        outer_cone: 0.5,
    };
    scene.lights = vec![
        Light {
            range: Some(6.0),
            ..light(LightKind::Point, Vec3::new(-1.5, 1.5, -1.0), Vec3::NEG_Z, Vec3::splat(4.0))
        },
        light(LightKind::Spot, Vec3::new(1.0, 2.0, -2.5), Vec3::new(0.0, -1.0, 0.0), Vec3::new(6.0, 5.0, 4.0)),
        light(LightKind::Directional, Vec3::ZERO, Vec3::new(0.3, -0.5, -1.0), Vec3::new(0.5, 0.5, 0.6)),
    ];
    scene
}

/// A textured quad facing the viewer, 2 m away at `azimuth_deg`, 1.2 m wide, its u running
/// left to right (right to left when `mirrored`) and v top to bottom, material `material`.
pub fn facing_quad(scene: &mut twister::Scene, azimuth_deg: f32, mirrored: bool, material: u32) {
    use glam::Vec3;
    use twister::core::scenes::scene::SceneVertex;
    let a = azimuth_deg.to_radians();
    let centre = Vec3::new(2.0 * a.sin(), 0.0, -2.0 * a.cos());
    let right = Vec3::new(a.cos(), 0.0, a.sin());
    let normal = -centre.normalize();
    let corner = |sx: f32, sy: f32| {
        let p = centre + right * (0.6 * sx) + Vec3::Y * (0.6 * sy);
        let u = if mirrored { 0.5 - 0.5 * sx } else { 0.5 + 0.5 * sx };
        SceneVertex {
            position: p.into(),
            normal: normal.into(),
            color: [1.0; 4],
            uv: [u, 0.5 - 0.5 * sy],
            material,
            ..Default::default()
        }
    };
    let v = [corner(-1.0, 1.0), corner(1.0, 1.0), corner(1.0, -1.0), corner(-1.0, -1.0)];
    // Counter-clockwise seen from the viewer.
    scene.add_mesh(format!("quad {azimuth_deg}"), &v, &[0, 3, 2, 0, 2, 1]);
}

/// Quads with every glTF map — metallic-roughness (stripes), normal (bumps), occlusion
/// (checker), emission (a warm spot) — the middle one with mirrored u, under a directional
/// light from the upper right.
pub fn mapped_panels() -> twister::Scene {
    use glam::Vec3;
    use twister::core::shading::light::{Light, LightKind};
    use twister::core::shading::material::Material;
    use twister::core::shading::texture::Texture;
    let mut scene = twister::Scene::new("mapped panels");
    let image = |name: &str, f: &dyn Fn(u32, u32) -> [u8; 4]| Texture {
        name: name.into(),
        width: 16,
        height: 16,
        rgba: (0..256u32).flat_map(|i| f(i % 16, i / 16)).collect(),
    };
    let mr = image("mr", &|x, _| [0, 64 + 12 * x as u8, if x < 8 { 255 } else { 0 }, 255]);
    let normal = image("normal", &|x, y| {
        let (dx, dy) = ((x as f32 - 7.5) / 8.0, (y as f32 - 7.5) / 8.0);
        let n = Vec3::new(dx * 0.8, -dy * 0.8, 1.0).normalize();
        let e = |c: f32| ((c * 0.5 + 0.5) * 255.0).round() as u8;
        [e(n.x), e(n.y), e(n.z), 255]
    });
    let occlusion = image("occlusion", &|x, y| if (x / 4 + y / 4) % 2 == 0 { [255; 4] } else { [90, 90, 90, 255] });
    let emissive = image("emissive", &|x, y| {
        let d = (x as f32 - 5.0).hypot(y as f32 - 10.0);
        if d < 3.0 {
            [255, 160, 60, 255]
        } else {
            [0, 0, 0, 255]
        }
    });
    scene.textures = vec![mr.encode_data(), normal.encode_data(), occlusion.encode_data(), emissive];
    scene.materials.push(Material {
        metallic: 1.0,
        roughness: 1.0,
        emissive_r: 1.5,
        emissive_g: 1.0,
        emissive_b: 1.0,
        mr_texture: 0,
        normal_texture: 1,
        normal_scale: 1.0,
        occlusion_texture: 2,
        occlusion_strength: 0.8,
        emissive_texture: 3,
        ..Default::default()
    });
    for (k, azimuth) in [-40.0f32, 0.0, 40.0].into_iter().enumerate() {
        facing_quad(&mut scene, azimuth, k == 1, 1);
    }
    scene.lights = vec![Light {
        kind: LightKind::Directional,
        position: Vec3::ZERO,
        direction: Vec3::new(-0.6, -0.5, -0.6).normalize(),
        color: Vec3::splat(3.0),
        range: None,
        inner_cone: 0.0,
        outer_cone: 0.5,
    }];
    scene
}

/// The scene with a tangent on every vertex (glTF's TANGENT): in the vertex's tangent plane,
/// turning 0.3 rad from one vertex to the next, the bitangent's sign +1 on object 0 and −1 on the
/// others.
pub fn with_tangents(mut scene: twister::Scene) -> twister::Scene {
    use glam::{Quat, Vec3};
    for (i, v) in scene.vertices.iter_mut().enumerate() {
        let n = Vec3::from(v.normal).normalize_or(Vec3::Z);
        let side = if n.y.abs() < 0.9 { Vec3::Y } else { Vec3::X };
        let t = Quat::from_axis_angle(n, 0.3 * i as f32) * n.cross(side).normalize();
        v.tangent = twister::core::scenes::scene::pack_tangent(t.extend(if v.object == 0 { 1.0 } else { -1.0 }));
    }
    scene
}

/// The neutral studio, prepared, shown as the background if `background`.
pub fn studio(background: bool) -> std::sync::Arc<twister::core::shading::environment::PreparedEnvironment> {
    let prepared = twister::core::shading::environment::Environment::neutral().prepare();
    std::sync::Arc::new(twister::core::shading::environment::PreparedEnvironment { background, ..prepared })
}

/// A grey rough floor (y = −1.2) with a ball of radius 0.3 at (0.3, −0.6, −2.2) above it, under
/// one light shining straight down: a directional light, or a spot light 2.1 m above the ball
/// (cone 0.5/0.8 rad), or a point light there. With `screen`, also a 1 m square screen at y = −0.3 over x −1.6..−0.6,
/// z −2.8..−1.8, whose alpha-masked 8×8 texture is a checker of holes (texel (i, j) opaque
/// where i + j is even; u along +x, v along +z).
pub fn ball_over_floor(kind: twister::core::shading::light::LightKind, screen: bool) -> twister::Scene {
    use glam::Vec3;
    use twister::core::scenes::scene::SceneVertex;
    use twister::core::shading::light::{Light, LightKind};
    use twister::core::shading::material::{AlphaMode, Filter, Material};
    use twister::core::shading::texture::Texture;
    let mut scene = twister::Scene::new("ball over floor");
    scene.materials.push(Material { metallic: 0.0, roughness: 1.0, ..Default::default() });
    let corner = |x: f32, y: f32, z: f32, material: u32| SceneVertex {
        position: [x, y, z],
        normal: [0.0, 1.0, 0.0],
        color: [0.6, 0.6, 0.6, 1.0],
        uv: [(x + 1.6) / 1.0, (z + 2.8) / 1.0],
        material,
        ..Default::default()
    };
    let floor = [
        corner(-3.0, -1.2, 0.5, 1),
        corner(3.0, -1.2, 0.5, 1),
        corner(3.0, -1.2, -5.0, 1),
        corner(-3.0, -1.2, -5.0, 1),
    ];
    scene.add_mesh("floor", &floor, &[0, 1, 2, 0, 2, 3]);
    let ball = twister::core::scenes::builtin::sphere_scene(800, Vec3::new(0.3, -0.6, -2.2), 0.3, "ball");
    scene.add_mesh("ball", &ball.vertices, &ball.indices);
    if screen {
        let rgba = (0..64u32).flat_map(|i| [200, 200, 200, if (i % 8 + i / 8) % 2 == 0 { 255 } else { 0 }]).collect();
        scene.textures.push(Texture { name: "holes".into(), width: 8, height: 8, rgba });
        scene.materials.push(Material {
            texture: 0,
            alpha_mode: AlphaMode::Mask as u32,
            alpha_cutoff: 0.5,
            min_filter: Filter::Nearest as u32,
            mag_filter: Filter::Nearest as u32,
            ..scene.materials[0]
        });
        let q = [
            corner(-1.6, -0.3, -1.8, 2),
            corner(-0.6, -0.3, -1.8, 2),
            corner(-0.6, -0.3, -2.8, 2),
            corner(-1.6, -0.3, -2.8, 2),
        ];
        scene.add_mesh("screen", &q, &[0, 1, 2, 0, 2, 3]);
    }
    let placed = kind != LightKind::Directional;
    scene.lights = vec![Light {
        kind,
        position: if placed { Vec3::new(0.3, 1.5, -2.2) } else { Vec3::ZERO },
        direction: Vec3::NEG_Y,
        color: Vec3::splat(if placed { 40.0 } else { 3.0 }),
        range: None,
        inner_cone: 0.5,
        outer_cone: 0.8,
    }];
    scene
}

/// A test's temporary folder under the system's, emptied when made and removed with everything
/// in it when dropped (also when the test fails), so that test runs leave nothing behind.
pub struct TempDir(std::path::PathBuf);

impl TempDir {
    /// `name` (made unique by the caller: the process id, the test) under the temporary folder.
    pub fn new(name: impl AsRef<str>) -> TempDir {
        let path = std::env::temp_dir().join(name.as_ref());
        let _ = std::fs::remove_dir_all(&path);
        TempDir(path)
    }
}

impl std::ops::Deref for TempDir {
    type Target = std::path::PathBuf;
    fn deref(&self) -> &std::path::PathBuf {
        &self.0
    }
}

impl AsRef<std::path::Path> for TempDir {
    fn as_ref(&self) -> &std::path::Path {
        &self.0
    }
}

impl AsRef<std::ffi::OsStr> for TempDir {
    fn as_ref(&self) -> &std::ffi::OsStr {
        self.0.as_os_str()
    }
}

impl Drop for TempDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// The walls of a CAVE, a 3 m cube about the origin (floor at y = −1.5): the front, the left
/// and the floor, `pixels` square each.
pub fn cave_walls(pixels: u32) -> Vec<twister::core::panoramas::cave::NamedWall> {
    let wall = |name: &str, lower_left: [f32; 3], lower_right: [f32; 3], upper_left: [f32; 3]| {
        twister::core::panoramas::cave::NamedWall {
            name: name.into(),
            lower_left,
            lower_right,
            upper_left,
            pixels: [pixels; 2],
        }
    };
    vec![
        wall("front", [-1.5, -1.5, -1.5], [1.5, -1.5, -1.5], [-1.5, 1.5, -1.5]),
        wall("left", [-1.5, -1.5, 1.5], [-1.5, -1.5, -1.5], [-1.5, 1.5, 1.5]),
        wall("floor", [-1.5, -1.5, 1.5], [1.5, -1.5, 1.5], [-1.5, -1.5, -1.5]),
    ]
}

/// CAVE wall `k` of [`cave_walls`] seen by a head at `head` (scene = display frame) facing
/// `yaw` degrees: its projection.
pub fn cave(k: usize, pixels: u32, head: glam::Vec3, yaw: f32) -> twister::Projection {
    use twister::core::panoramas::panorama::Panorama;
    let wall = &cave_walls(pixels)[k];
    twister::Projection {
        panorama: twister::core::panoramas::cave::Cave.kind(),
        width: pixels,
        height: pixels,
        wall: Some(wall.in_display(1.0, glam::Vec3::ZERO, 0.0)),
        head: Some(twister::core::panoramas::head::Head::relative(head, yaw, glam::Vec3::ZERO, 0.0)),
        vertical: twister::Vertical::Exact,
        ..twister::Projection::default()
    }
}

/// The subdivision's pass times a `render --stats` record or a `bench speed` row carries
/// (`ms_subdivide_passes`): where timestamps timed its frame, checked to be each from the end of
/// the one before (none negative, together `ms_subdivide`) and their names returned in order;
/// elsewhere checked absent, and None.
pub fn subdivide_pass_names(row: &serde_json::Value) -> Option<Vec<String>> {
    if row["timing"] != "gpu-timestamps" {
        assert!(row["ms_subdivide_passes"].is_null(), "{row}");
        return None;
    }
    let timed = row["ms_subdivide_passes"].as_array().unwrap();
    let ms: Vec<f64> = timed.iter().map(|p| p[1].as_f64().unwrap()).collect();
    let total = row["ms_subdivide"].as_f64().unwrap();
    assert!(ms.iter().all(|&t| t >= 0.0), "{row}");
    assert!((ms.iter().sum::<f64>() - total).abs() <= 1e-6 * total.max(1.0), "{row}");
    Some(timed.iter().map(|p| p[0].as_str().unwrap().to_string()).collect())
}

/// Random triangles: a mix of small ones anywhere, big ones around the viewer, and ones near the
/// axis, each its own object and material index (past the scene's materials: the default).
pub fn random_triangles(seed: u64, n: usize) -> Scene {
    use glam::Vec3;
    use rand::{Rng, SeedableRng};
    let mut rng = rand::rngs::StdRng::seed_from_u64(seed);
    let mut scene = Scene::new("random");
    for k in 0..n {
        // Mix of small triangles anywhere, big ones around the viewer, and ones near the axis.
        let scale = [0.3f32, 6.0, 1.0][k % 3];
        let center = match k % 3 {
            2 => Vec3::new(rng.random_range(-0.05..0.05), rng.random_range(-2.0..2.0), rng.random_range(-0.05..0.05)),
            _ => Vec3::new(rng.random_range(-8.0..8.0), rng.random_range(-3.0..3.0), rng.random_range(-8.0..8.0)),
        };
        let v: Vec<twister::core::scenes::scene::SceneVertex> = (0..3)
            .map(|i| twister::core::scenes::scene::SceneVertex {
                position: (center
                    + scale
                        * Vec3::new(
                            rng.random_range(-1.0..1.0),
                            rng.random_range(-1.0..1.0),
                            rng.random_range(-1.0..1.0),
                        ))
                .into(),
                normal: [rng.random_range(-1.0..1.0), 1.0, 0.0],
                color: [rng.random(), rng.random(), rng.random(), 1.0],
                uv: [i as f32, rng.random()],
                material: k as u32,
                ..Default::default()
            })
            .collect();
        scene.add_mesh("t", &v, &[0, 1, 2]);
    }
    scene
}

/// The same triangles, every one single-sided: those every eye sees from behind are skipped.
pub fn single_sided(mut scene: Scene) -> Scene {
    scene.materials.push(twister::core::shading::material::Material { double_sided: 0, ..Default::default() });
    for v in &mut scene.vertices {
        v.material = 1;
    }
    scene.mark_sides();
    scene
}
