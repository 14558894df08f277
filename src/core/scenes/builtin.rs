//! Built-in scenes, generated in code (no files):
//!
//! | name | what |
//! |---|---|
//! | `builtin:demo` | a 12 m room around the viewer, one closed mesh: tiled floor (one tile under the viewer, around the axis), four walls, a tiled ceiling whose middle tile's diagonal passes over the viewer, and spheres at 1 m (ahead right, red), 3 m (left, green), 5 m (straight behind, magenta, straddling the ±π seam) |
//! | `builtin:box-room` | a closed 40×10×40 m box of 12 triangles around the viewer, the floor 1.7 m below the eyes, each face its own colour |
//! | `builtin:cube` | the closed 2 m cube [−1, 1]³ of 12 triangles, each face its own colour (place the viewer inside it with `--viewer`) |
//! | `builtin:sphere100`, `builtin:sphere1024` | spheres of exactly 100 and 1024 triangles, 3 m ahead, filling the screen height (the paper's Sphere100/Sphere1024) |
//! | `builtin:triangle@D` | the paper's evaluation-1 triangle: equilateral, facing the viewer, D metres straight ahead, projected side ≈ the image height H |

use crate::core::shading::color::srgb_to_linear;
use glam::Vec3;
use std::f32::consts::{FRAC_1_SQRT_2, PI, TAU};

use crate::core::panoramas::projection::Projection;
use crate::core::scenes::scene::Scene;
use crate::core::scenes::scene::SceneVertex;
use crate::error::{Error, Result};

/// Colour of the seam sphere in `builtin:demo` (tests find it by this hue).
pub const SEAM_SPHERE_COLOR: [f32; 4] = [0.9, 0.1, 0.9, 1.0];
/// Where the demo's seam sphere stands (straight behind the viewer) and its radius.
pub const SEAM_SPHERE_CENTER: [f32; 3] = [0.0, 0.0, 5.0];
pub const SEAM_SPHERE_RADIUS: f32 = 0.8;
/// Height of the demo's floor below the eyes.
pub const DEMO_FLOOR_Y: f32 = -1.5;

pub const NAMES: &[&str] = &[
    "builtin:demo",
    "builtin:box-room",
    "builtin:cube",
    "builtin:sphere100",
    "builtin:sphere1024",
    "builtin:triangle@D",
];

/// Builds a built-in scene by name; `projection` sizes the screen-filling ones.
pub fn builtin_scene(name: &str, projection: &Projection) -> Result<Scene> {
    let spec = name.strip_prefix("builtin:").unwrap_or(name);
    match spec {
        "demo" => Ok(demo()),
        "box-room" => Ok(closed_box(name, Vec3::new(-20.0, -1.7, -20.0), Vec3::new(20.0, 8.3, 20.0))),
        "cube" => Ok(closed_box(name, Vec3::splat(-1.0), Vec3::splat(1.0))),
        "sphere100" => Ok(screen_filling_sphere(100, 3.0, projection, name)),
        "sphere1024" => Ok(screen_filling_sphere(1024, 3.0, projection, name)),
        _ => {
            if let Some(d) = spec.strip_prefix("triangle@") {
                let distance: f32 = d
                    .trim_end_matches('m')
                    .parse()
                    .ok()
                    .filter(|d: &f32| d.is_finite() && *d > projection.eye_radius)
                    .ok_or_else(|| {
                        Error::scene(name, "the distance after '@' must be a number of metres beyond the eye circle")
                    })?;
                Ok(paper_triangle(distance, projection))
            } else {
                Err(Error::scene(name, format!("unknown built-in scene; built-in scenes are {}", NAMES.join(", "))))
            }
        }
    }
}

/// A built-in vertex; `color` is given as display (sRGB-encoded) values and stored linear.
fn vertex(position: Vec3, normal: Vec3, color: [f32; 4]) -> SceneVertex {
    let [r, g, b, a] = color;
    let color = [srgb_to_linear(r), srgb_to_linear(g), srgb_to_linear(b), a];
    SceneVertex { position: position.into(), normal: normal.into(), color, ..Default::default() }
}

/// A UV sphere with `slices` around and `stacks` from pole to pole: 2·slices·(stacks − 1)
/// triangles (the pole rows are single triangles).
pub fn uv_sphere(center: Vec3, radius: f32, slices: u32, stacks: u32, color: [f32; 4]) -> (Vec<SceneVertex>, Vec<u32>) {
    let mut v = Vec::new();
    let mut idx = Vec::new();
    for i in 0..=stacks {
        let polar = PI * i as f32 / stacks as f32;
        // The poles exactly on the axis (sin π is not 0 in f32): one point, a closed mesh.
        let ring = if i == 0 || i == stacks { 0.0 } else { polar.sin() };
        for j in 0..=slices {
            // The last column repeats the first's positions bit for bit (a closed mesh).
            let az = TAU * (j % slices) as f32 / slices as f32;
            let n = Vec3::new(ring * az.cos(), polar.cos(), ring * az.sin());
            v.push(vertex(center + radius * n, n, color));
        }
    }
    let row = slices + 1;
    for i in 0..stacks {
        for j in 0..slices {
            let (a, b, c, d) = (i * row + j, i * row + j + 1, (i + 1) * row + j, (i + 1) * row + j + 1);
            if i != 0 {
                idx.extend([a, b, c]);
            }
            if i != stacks - 1 {
                idx.extend([b, d, c]);
            }
        }
    }
    (v, idx)
}

/// Sphere of `triangles` (100 or 1024) triangles, `distance` m ahead, its silhouette filling
/// the screen height under the paper's vertical model: R_T·ρ/√(D²−ρ²) = half height.
pub fn screen_filling_sphere(triangles: u32, distance: f32, projection: &Projection, name: &str) -> Scene {
    let k = projection.fill_tan();
    let radius = distance * k / (1.0 + k * k).sqrt();
    sphere_scene(triangles, Vec3::new(0.0, 0.0, -distance), radius, name)
}

/// A scene holding one UV sphere: exactly 100 or 1024 triangles for those counts, else about `triangles`.
pub fn sphere_scene(triangles: u32, center: Vec3, radius: f32, name: &str) -> Scene {
    let (slices, stacks) = match triangles {
        100 => (10, 6),
        1024 => (32, 17),
        n => {
            let slices = ((n as f32).sqrt().round() as u32).clamp(3, 512);
            (slices, (n / (2 * slices)).max(1) + 1)
        }
    };
    let (v, i) = uv_sphere(center, radius, slices, stacks, [0.85, 0.8, 0.7, 1.0]);
    let mut scene = Scene::new(name);
    scene.add_mesh("sphere", &v, &i);
    scene
}

/// A closed, irregular mesh: an icosahedron (20 faces) with jittered radii and smooth normals.
/// Tests use it as a closed model that is not a UV sphere.
pub fn blob(center: Vec3, radius: f32) -> Scene {
    let t = (1.0 + 5f32.sqrt()) / 2.0;
    let corners = [
        (-1.0, t, 0.0),
        (1.0, t, 0.0),
        (-1.0, -t, 0.0),
        (1.0, -t, 0.0),
        (0.0, -1.0, t),
        (0.0, 1.0, t),
        (0.0, -1.0, -t),
        (0.0, 1.0, -t),
        (t, 0.0, -1.0),
        (t, 0.0, 1.0),
        (-t, 0.0, -1.0),
        (-t, 0.0, 1.0),
    ];
    let faces: [u32; 60] = [
        0, 11, 5, 0, 5, 1, 0, 1, 7, 0, 7, 10, 0, 10, 11, 1, 5, 9, 5, 11, 4, 11, 10, 2, 10, 7, 6, 7, 1, 8, 3, 9, 4, 3,
        4, 2, 3, 2, 6, 3, 6, 8, 3, 8, 9, 4, 9, 5, 2, 4, 11, 6, 2, 10, 8, 6, 7, 9, 8, 1,
    ];
    let mut v: Vec<SceneVertex> = corners
        .iter()
        .enumerate()
        .map(|(i, &(x, y, z))| {
            let d = Vec3::new(x, y, z).normalize() * (1.0 + 0.2 * (i as f32 * 2.7).sin());
            vertex(center + radius * d, Vec3::ZERO, [0.6, 0.7, 0.5, 1.0])
        })
        .collect();
    crate::core::scenes::scene::compute_normals(&mut v, &faces);
    let mut s = Scene::new("blob");
    s.add_mesh("blob", &v, &faces);
    s
}

/// The paper's evaluation-1 triangle: equilateral, in the plane z = −D facing the viewer,
/// centred on the middle row; its side projects to about H pixels (R_T·s/D metres of screen).
pub fn paper_triangle(distance: f32, projection: &Projection) -> Scene {
    let side = 2.0 * projection.fill_tan() * distance;
    let h = side * 3f32.sqrt() / 2.0;
    let z = -distance;
    let n = Vec3::Z;
    let c = [0.9, 0.9, 0.9, 1.0];
    let v = [
        vertex(Vec3::new(-side / 2.0, -h / 2.0, z), n, c),
        vertex(Vec3::new(side / 2.0, -h / 2.0, z), n, c),
        vertex(Vec3::new(0.0, h / 2.0, z), n, c),
    ];
    let mut scene = Scene::new(format!("builtin:triangle@{distance}"));
    scene.add_mesh("triangle", &v, &[0, 1, 2]);
    scene
}

/// A closed box from `lo` to `hi` seen from inside (one object, 12 triangles on 8 shared corner
/// positions), each face its own colour: −z, +x, +z, −x, floor, ceiling.
pub fn closed_box(name: &str, lo: Vec3, hi: Vec3) -> Scene {
    let colours = [
        [0.3, 0.4, 0.8, 1.0],
        [0.8, 0.7, 0.25, 1.0],
        [0.55, 0.55, 0.55, 1.0],
        [0.25, 0.6, 0.55, 1.0],
        [0.6, 0.45, 0.35, 1.0],
        [0.6, 0.65, 0.75, 1.0],
    ];
    let c = |x: usize, y: usize, z: usize| Vec3::new([lo.x, hi.x][x], [lo.y, hi.y][y], [lo.z, hi.z][z]);
    // Each face's corners counter-clockwise seen from inside the box.
    let faces = [
        [c(0, 0, 0), c(1, 0, 0), c(1, 1, 0), c(0, 1, 0)],
        [c(1, 0, 0), c(1, 0, 1), c(1, 1, 1), c(1, 1, 0)],
        [c(1, 0, 1), c(0, 0, 1), c(0, 1, 1), c(1, 1, 1)],
        [c(0, 0, 1), c(0, 0, 0), c(0, 1, 0), c(0, 1, 1)],
        [c(0, 0, 1), c(1, 0, 1), c(1, 0, 0), c(0, 0, 0)],
        [c(0, 1, 0), c(1, 1, 0), c(1, 1, 1), c(0, 1, 1)],
    ];
    let (mut v, mut idx) = (Vec::new(), Vec::new());
    for (p, colour) in faces.iter().zip(colours) {
        let n = (p[1] - p[0]).cross(p[3] - p[0]).normalize();
        let base = v.len() as u32;
        v.extend(p.iter().map(|&q| vertex(q, n, colour)));
        idx.extend([0, 1, 2, 0, 2, 3].map(|i| base + i));
    }
    let mut scene = Scene::new(name);
    scene.add_mesh("box", &v, &idx);
    scene
}

/// `builtin:demo`: a room around the viewer (see the module doc).
pub fn demo() -> Scene {
    let mut s = Scene::new("builtin:demo");
    let half = 6.0f32; // room half-size, metres
    let (floor, ceiling) = (DEMO_FLOOR_Y, 2.5f32);
    // Tile lines every metre, offset by half a tile so that one tile holds the axis: −6, −5.5,
    // −4.5, …, 5.5, 6. Floor, walls and ceiling share them, so the room is one closed mesh
    // (every edge shared by exactly two triangles, no T-junctions).
    let mut lines = vec![-half];
    lines.extend((0..12).map(|i| -half + 0.5 + i as f32));
    lines.push(half);
    let (mut v, mut idx) = (Vec::new(), Vec::new());
    let mut quad = |p: [Vec3; 4], color: [f32; 4]| {
        let n = (p[1] - p[0]).cross(p[3] - p[0]).normalize();
        let base = v.len() as u32;
        v.extend(p.iter().map(|&q| vertex(q, n, color)));
        idx.extend([0, 1, 2, 0, 2, 3].map(|i| base + i));
    };
    for (i, x) in lines.windows(2).enumerate() {
        for (j, z) in lines.windows(2).enumerate() {
            let light = (i + j) % 2 == 1;
            let c = if light { [0.75, 0.72, 0.65, 1.0] } else { [0.35, 0.33, 0.3, 1.0] };
            let at = |a: f32, b: f32, y: f32| Vec3::new(a, y, b);
            quad([at(x[0], z[1], floor), at(x[1], z[1], floor), at(x[1], z[0], floor), at(x[0], z[0], floor)], c);
            // Ceiling tiles, each two triangles; the middle tile's diagonal passes over the viewer.
            let c = [0.6, 0.65, 0.75, 1.0];
            quad(
                [at(x[0], z[0], ceiling), at(x[1], z[0], ceiling), at(x[1], z[1], ceiling), at(x[0], z[1], ceiling)],
                c,
            );
        }
    }
    // Walls, each its own colour: ahead (−z) blue, right (+x) yellow, behind (+z) grey, left teal;
    // one column per tile line, so their bottom and top edges are the floor's and the ceiling's.
    let colours = [[0.3, 0.4, 0.8, 1.0], [0.8, 0.7, 0.25, 1.0], [0.55, 0.55, 0.55, 1.0], [0.25, 0.6, 0.55, 1.0]];
    for (w, colour) in colours.into_iter().enumerate() {
        for t in lines.windows(2) {
            // Along the wall, counter-clockwise seen from inside.
            let at = |a: f32| match w {
                0 => Vec3::new(a, 0.0, -half),
                1 => Vec3::new(half, 0.0, a),
                2 => Vec3::new(-a, 0.0, half),
                _ => Vec3::new(-half, 0.0, -a),
            };
            let (a, b) = (at(t[0]), at(t[1]));
            let y = |p: Vec3, y: f32| Vec3::new(p.x, y, p.z);
            quad([y(a, floor), y(b, floor), y(b, ceiling), y(a, ceiling)], colour);
        }
    }
    s.add_mesh("room", &v, &idx);
    // Spheres at 1 m (ahead right), 3 m (left), 5 m (straight behind, across the seam).
    let spheres = [
        (Vec3::new(FRAC_1_SQRT_2, -0.2, -FRAC_1_SQRT_2), 0.2, [0.85, 0.15, 0.1, 1.0], "sphere 1 m"),
        (Vec3::new(-3.0, 0.3, 0.0), 0.6, [0.2, 0.75, 0.25, 1.0], "sphere 3 m"),
        (Vec3::from(SEAM_SPHERE_CENTER), SEAM_SPHERE_RADIUS, SEAM_SPHERE_COLOR, "sphere 5 m (seam)"),
    ];
    for (center, radius, color, name) in spheres {
        let (v, i) = uv_sphere(center, radius, 32, 17, color);
        s.add_mesh(name, &v, &i);
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn paper_spheres_have_exact_triangle_counts() {
        let p = Projection::default();
        assert_eq!(builtin_scene("builtin:sphere100", &p).unwrap().triangle_count(), 100);
        assert_eq!(builtin_scene("builtin:sphere1024", &p).unwrap().triangle_count(), 1024);
    }

    #[test]
    fn screen_filling_sphere_touches_top_and_bottom_rows() {
        let p = Projection::default();
        let s = builtin_scene("builtin:sphere1024", &p).unwrap();
        // The highest v over the sphere's vertices is close to (below) the half height.
        let top = s
            .vertices
            .iter()
            .map(|v| {
                let q = Vec3::from(v.position);
                p.screen_height(q.y, (q.x * q.x + q.z * q.z).sqrt())
            })
            .fold(f32::MIN, f32::max);
        let half = p.half_height_m();
        assert!(top <= half * 1.001 && top > 0.95 * half, "top {top} vs half height {half}");
    }

    #[test]
    fn paper_triangle_side_projects_to_image_height() {
        let p = Projection { width: 3168, height: 600, ..Default::default() };
        for d in [1.0, 3.0, 5.0] {
            let s = builtin_scene(&format!("builtin:triangle@{d}"), &p).unwrap();
            let a =
                p.project(Vec3::from(s.vertices[0].position), crate::core::panoramas::projection::Eye::Left).unwrap();
            let b =
                p.project(Vec3::from(s.vertices[1].position), crate::core::panoramas::projection::Eye::Left).unwrap();
            let side_px = (b.u - a.u) * p.pixels_per_radian();
            assert!((side_px - 600.0).abs() < 0.12 * 600.0, "side {side_px} px at {d} m");
        }
    }

    #[test]
    fn demo_is_valid_and_unknown_names_are_errors() {
        let p = Projection::default();
        builtin_scene("builtin:demo", &p).unwrap().validate().unwrap();
        assert!(builtin_scene("builtin:nope", &p).unwrap_err().to_string().contains("builtin:demo"));
        assert!(builtin_scene("builtin:triangle@x", &p).is_err());
        assert!(builtin_scene("builtin:triangle@0.01", &p).is_err());
    }
}
