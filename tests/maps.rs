//! The glTF texture maps (issue 17): the normal map's tangent frame follows glTF's convention
//! (+x along increasing u, +y up the image), mirrored texture coordinates included; the maps of
//! a Khronos sample are read as data.

mod common;

use glam::Vec3;
use twister::core::scenes::scene::pack_tangent;
use twister::core::settings::{Method, Split};
use twister::core::shading::color::srgb_to_linear;
use twister::core::shading::light::{Light, LightKind, Tonemap};
use twister::core::shading::material::{Material, NO_TEXTURE};
use twister::core::shading::texture::Texture;
use twister::{Eye, Projection, RenderSettings, Scene, Vertical};

/// A quad ahead whose normal map tilts every normal by 30° towards `tilt` (tangent space: +x
/// along u, +y up the image), lit by a directional light coming from `from`.
fn tilted(tilt: [f32; 2], mirrored: bool, from: Vec3) -> Scene {
    let mut scene = Scene::new("tilted normal map");
    let n = Vec3::new(tilt[0] * 0.5, tilt[1] * 0.5, 0.866).normalize();
    let e = |c: f32| ((c * 0.5 + 0.5) * 255.0).round() as u8;
    let map = Texture { name: "tilt".into(), width: 4, height: 4, rgba: [e(n.x), e(n.y), e(n.z), 255].repeat(16) };
    scene.textures = vec![map.encode_data()];
    scene.materials.push(Material { metallic: 0.0, roughness: 1.0, normal_texture: 0, ..Default::default() });
    common::facing_quad(&mut scene, 0.0, mirrored, 1);
    scene.lights = vec![Light {
        kind: LightKind::Directional,
        position: Vec3::ZERO,
        direction: -from.normalize(),
        color: Vec3::ONE,
        range: None,
        inner_cone: 0.0,
        outer_cone: 0.5,
    }];
    scene
}

/// Mean linear brightness of the quad's middle (the image's centre 40 × 40 pixels).
fn brightness(scene: &Scene) -> f32 {
    brightness_by(scene, Method::Adaptive(Split::Error))
}

fn brightness_by(scene: &Scene, method: Method) -> f32 {
    let projection = Projection { width: 640, height: 160, vertical: Vertical::Exact, ..Projection::default() };
    let settings = RenderSettings::new(projection).with_tonemap(Tonemap::None).with_ambient(0.0).with_method(method);
    let frame = common::render(scene, &settings);
    let img = frame.eye(Eye::Left);
    let mut sum = 0.0;
    for y in 60..100 {
        for x in 300..340 {
            sum += srgb_to_linear(img.pixel(x, y)[0] as f32 / 255.0);
        }
    }
    sum / 1600.0
}

/// The lit side is where the map tilts the normal: towards +u (right on a plain quad, left on a
/// mirrored one) and up the image (towards −v). Brightness ∝ n·l: 0.97 against 0.26 for lights
/// 45° to either side.
#[test]
fn the_normal_map_tilts_normals_along_u_and_up_the_image_mirrored_or_not() {
    let (right, left) = (Vec3::new(1.0, 0.0, 1.0), Vec3::new(-1.0, 0.0, 1.0));
    let (up, down) = (Vec3::new(0.0, 1.0, 1.0), Vec3::new(0.0, -1.0, 1.0));
    for (what, tilt, mirrored, lit, dark) in [
        ("+u, plain", [1.0, 0.0], false, right, left),
        ("+u, mirrored", [1.0, 0.0], true, left, right),
        ("+y", [0.0, 1.0], false, up, down),
        ("+y, mirrored", [0.0, 1.0], true, up, down),
    ] {
        let (b_lit, b_dark) = (brightness(&tilted(tilt, mirrored, lit)), brightness(&tilted(tilt, mirrored, dark)));
        let flat = {
            let mut s = tilted(tilt, mirrored, lit);
            s.materials[0].normal_texture = NO_TEXTURE;
            brightness(&s)
        };
        // Lambert × (1 − F) / π: the ratio of the two n·l is 3.7; flat, both sides give 0.71.
        assert!(b_lit > 2.5 * b_dark, "{what}: lit side {b_lit}, other side {b_dark}");
        assert!(b_lit > 1.2 * flat && b_dark < 0.6 * flat, "{what}: {b_lit} / {b_dark} against flat {flat}");
    }
}

/// Supplied tangents (glTF's TANGENT) give the normal map's frame instead of the texture
/// coordinates: with the tangent pointing up the quad, a map tilting towards +x (the tangent)
/// lights the quad from above, not from the right; with the tangent along +u and w = −1 the
/// bitangent (n × t)·w points down, so a map tilting towards +y lights it from below. The
/// drawing stages (adaptive, slits) and the ray tracer alike.
#[test]
fn supplied_tangents_give_the_normal_maps_frame() {
    let (right, left) = (Vec3::new(1.0, 0.0, 1.0), Vec3::new(-1.0, 0.0, 1.0));
    let (up, down) = (Vec3::new(0.0, 1.0, 1.0), Vec3::new(0.0, -1.0, 1.0));
    let with_tangent = |tilt: [f32; 2], tangent: glam::Vec4, from: Vec3| {
        let mut s = tilted(tilt, false, from);
        for v in &mut s.vertices {
            v.tangent = pack_tangent(tangent);
        }
        s
    };
    for method in [Method::Adaptive(Split::Error), Method::Slit(4), Method::Trace] {
        for (what, tilt, tangent, lit, dark) in [
            ("tangent up, map towards +x", [1.0, 0.0], glam::Vec4::new(0.0, 1.0, 0.0, 1.0), up, down),
            ("tangent along u, w = −1, map towards +y", [0.0, 1.0], glam::Vec4::new(1.0, 0.0, 0.0, -1.0), down, up),
        ] {
            let b_lit = brightness_by(&with_tangent(tilt, tangent, lit), method);
            let b_dark = brightness_by(&with_tangent(tilt, tangent, dark), method);
            let b_side = [right, left].map(|from| brightness_by(&with_tangent(tilt, tangent, from), method));
            assert!(b_lit > 2.5 * b_dark, "{} {what}: lit side {b_lit}, other side {b_dark}", method.name());
            assert!(
                b_side.iter().all(|&b| b < 0.9 * b_lit && b > 1.1 * b_dark),
                "{} {what}: across the tilt {b_side:?}, along it {b_lit} / {b_dark}",
                method.name()
            );
        }
    }
}

/// NormalTangentMirrorTest: each material's normal map and its occlusion-roughness-metallic
/// image are read; the data images are stored as data (not as colours) once.
#[test]
fn a_khronos_samples_maps_are_read_as_data() {
    if !common::assets_present() {
        return;
    }
    let path = common::asset("gltf/NormalTangentMirrorTest/glTF-Binary/NormalTangentMirrorTest.glb");
    let p = Projection::default();
    let scene = twister::core::scenes::load::load_scene(path.to_str().unwrap(), &p).unwrap();
    let with_maps: Vec<&Material> = scene.materials.iter().filter(|m| m.normal_texture != NO_TEXTURE).collect();
    assert!(!with_maps.is_empty());
    for m in &with_maps {
        assert_ne!(m.texture, m.normal_texture, "the normal map is not the base colour");
        assert_eq!(m.mr_texture, m.occlusion_texture, "one ORM image serves both");
        for t in [m.normal_texture, m.mr_texture] {
            assert!(scene.textures[t as usize].name.ends_with("(data)"), "{}", scene.textures[t as usize].name);
        }
    }
    let data = scene.textures.iter().filter(|t| t.name.ends_with("(data)")).count();
    assert_eq!(data, 2, "normal and ORM images, each converted once");
}

/// MTL `map_Bump` and `norm`: a normal-map image is kept; a height map (a ramp rising to the
/// right) becomes normals tilted left (against the slope), with a note.
#[test]
fn mtl_bump_textures_become_normal_maps() {
    let dir = common::TempDir::new(format!("twister-maps-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let ramp =
        image::RgbaImage::from_fn(8, 8, |x, _| image::Rgba([(x * 32) as u8, (x * 32) as u8, (x * 32) as u8, 255]));
    ramp.save(dir.join("height.png")).unwrap();
    let flat = image::RgbaImage::from_pixel(8, 8, image::Rgba([128, 128, 255, 255]));
    flat.save(dir.join("normal.png")).unwrap();
    std::fs::write(
        dir.join("m.mtl"),
        "newmtl bumpy\nKd 1 1 1\nmap_Bump height.png\nnewmtl normal\nKd 1 1 1\nnorm normal.png\n",
    )
    .unwrap();
    std::fs::write(
        dir.join("m.obj"),
        "mtllib m.mtl\nv 0 0 -2\nv 1 0 -2\nv 0 1 -2\nvt 0 0\nvt 1 0\nvt 0 1\nusemtl bumpy\nf 1/1 2/2 3/3\nusemtl normal\nf 1/1 3/3 2/2\n",
    )
    .unwrap();
    let scene =
        twister::core::scenes::load::load_scene(dir.join("m.obj").to_str().unwrap(), &Projection::default()).unwrap();
    let (bumpy, normal) = (&scene.materials[0], &scene.materials[1]);
    assert!(bumpy.normal_texture != NO_TEXTURE && normal.normal_texture != NO_TEXTURE);
    // Tangents generated for the normal maps: along +u (+x here); on the triangle facing +z,
    // w = +1 (the bitangent up the image, +y, as v runs down it); on the one wound the other way
    // (facing −z, the image seen mirrored), w = −1.
    for v in &scene.vertices {
        let t = twister::core::scenes::scene::unpack_tangent(v.tangent);
        let w = if v.normal[2] > 0.0 { 1.0 } else { -1.0 };
        assert!((t - glam::Vec4::new(1.0, 0.0, 0.0, w)).abs().max_element() < 1e-3, "{t} at normal {:?}", v.normal);
    }
    assert_eq!(scene.warnings.iter().filter(|w| w.contains("height map")).count(), 1, "{:?}", scene.warnings);
    // Decode the middle texel of each (stored sRGB-encoded as data).
    let texel = |t: u32| {
        let tex = &scene.textures[t as usize];
        let i = 4 * (4 * tex.width + 4) as usize;
        Vec3::new(tex.rgba[i] as f32, tex.rgba[i + 1] as f32, tex.rgba[i + 2] as f32)
            .map(|c| srgb_to_linear(c / 255.0) * 2.0 - 1.0)
    };
    let (b, n) = (texel(bumpy.normal_texture), texel(normal.normal_texture));
    assert!(b.x < -0.3 && b.y.abs() < 0.02 && b.z > 0.5, "height ramp → {b}");
    assert!(n.x.abs() < 0.02 && n.y.abs() < 0.02 && n.z > 0.98, "flat normal map → {n}");
}

/// Tangents generated where a file gives none are MikkTSpace's, the frame the file's own were
/// baked with: NormalTangentMirrorTest with its tangents removed gets them back (per vertex),
/// and shades as with the file's (mean |difference| per channel over the drawn pixels, reported).
#[test]
fn generated_tangents_are_the_files_own_on_normal_tangent_mirror_test() {
    if !common::assets_present() {
        return;
    }
    let path = common::asset("gltf/NormalTangentMirrorTest/glTF-Binary/NormalTangentMirrorTest.glb");
    let p = Projection { width: 720, height: 240, ..Projection::default() };
    let mut file = twister::core::scenes::load::load_scene(path.to_str().unwrap(), &p).unwrap();
    file.fit(2.2, &p).unwrap();
    file.lights.push(Light::sun(20.0, 35.0, 3.0));
    let wants: Vec<bool> =
        std::iter::once(false).chain(file.materials.iter().map(|m| m.normal_texture != NO_TEXTURE)).collect();
    let mut generated = file.clone();
    let supplied = generated.vertices.iter().filter(|v| v.tangent != 0).count();
    assert!(supplied > 1000, "the sample gives its tangents: {supplied}");
    for v in &mut generated.vertices {
        v.tangent = 0;
    }
    twister::core::scenes::scene::generate_tangents(&mut generated.vertices, &generated.indices, |m| wants[m as usize]);
    let unpack = twister::core::scenes::scene::unpack_tangent;
    let mut off = 0;
    for (a, b) in file.vertices.iter().zip(&generated.vertices).filter(|(a, _)| a.tangent != 0) {
        let (a, b) = (unpack(a.tangent), unpack(b.tangent));
        off += (a.truncate().dot(b.truncate()) < 0.999 || a.w != b.w) as usize;
    }
    assert!(off * 100 <= supplied, "{off} of {supplied} generated tangents differ from the file's");
    let settings = RenderSettings::new(p).with_lighting(twister::core::shading::light::LightingMode::Pbr);
    let (a, b) = (common::render(&file, &settings), common::render(&generated, &settings));
    let mut sum = [0.0f64; 3];
    let mut differ = 0;
    for (pa, pb) in a.left.rgba.chunks(4).zip(b.left.rgba.chunks(4)) {
        differ += (pa != pb) as usize;
        for c in 0..3 {
            sum[c] += (pa[c] as f64 - pb[c] as f64).abs();
        }
    }
    let pixels = (a.left.width * a.left.height) as f64;
    let mean = sum.map(|s| s / pixels);
    eprintln!("generated vs file tangents: mean |difference| per channel {mean:.4?} levels over {pixels} pixels ({differ} differ); {off} of {supplied} tangents differ");
    assert!(mean.iter().all(|&m| m < 0.25), "mean |difference| per channel {mean:?}");
}
