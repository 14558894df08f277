//! The scene's lights cast shadows (issue 17): shadow maps in the drawing stages (raster and
//! slit) for directional, spot and point lights (a cube), shadow rays in the ray tracer; checked against brute
//! force geometry (where a ball or a masked screen hides the light) on the floor below them.

mod common;

use common::{ball_over_floor, render};
use glam::{Vec2, Vec3};
use twister::core::settings::{Method, Split};
use twister::core::shading::light::LightKind;
use twister::cpu::fragment::pixel_ray;
use twister::{Eye, Projection, RenderSettings, Vertical};

const CENTRE: Vec3 = Vec3::new(0.3, -0.6, -2.2);
const RADIUS: f32 = 0.3;
const FLOOR_Y: f32 = -1.2;

fn exact(width: u32, height: u32) -> Projection {
    Projection { width, height, vertical: Vertical::Exact, ..Projection::default() }
}

fn mean(v: &[u8]) -> f64 {
    v.iter().map(|&x| x as f64).sum::<f64>() / v.len().max(1) as f64
}

/// Where the floor shows (object 0), the floor point each pixel of the left eye sees (from
/// the pixel's ray, so independent of how the method drew it; the viewer at `viewer`, not
/// turned) and the pixel's red value.
fn floor_pixels(frame: &twister::Frame, p: &Projection, viewer: Vec3) -> Vec<((u32, u32), Vec3, u8)> {
    let m = frame.measurement.as_ref().expect("measured");
    let img = frame.eye(Eye::Left);
    let mut out = Vec::new();
    for y in 0..p.height {
        for x in 0..p.width {
            if m.object[0][(y * p.width + x) as usize] != 1 {
                continue;
            }
            let (o, d) = pixel_ray(p, Eye::Left, Vec2::new(x as f32 + 0.5, y as f32 + 0.5));
            let o = o + viewer;
            out.push(((x, y), o + d * ((FLOOR_Y - o.y) / d.y), img.pixel(x, y)[0]));
        }
    }
    out
}

/// How far on the floor the surface point drawn at pixel (x, y) may lie from the one its ray
/// meets: its display-position error (the frame's measure, in pixels) along the floor, the
/// largest of the floor points that far from the pixel's centre left, right, up and down (a
/// pixel far away at a grazing angle spans centimetres of floor).
fn floor_reach(frame: &twister::Frame, p: &Projection, viewer: Vec3, (x, y): (u32, u32), point: Vec3) -> f32 {
    let error = frame.measurement.as_ref().expect("measured").error[0][(y * p.width + x) as usize].max(0.0);
    let at = |dx: f32, dy: f32| {
        let (o, d) = pixel_ray(p, Eye::Left, Vec2::new(x as f32 + 0.5 + dx, y as f32 + 0.5 + dy));
        let o = o + viewer;
        o + d * ((FLOOR_Y - o.y) / d.y)
    };
    [(error, 0.0), (-error, 0.0), (0.0, error), (0.0, -error)]
        .into_iter()
        .map(|(dx, dy)| (at(dx, dy) - point).length())
        .fold(0.0, f32::max)
}

/// A ball 0.6 m above a grey floor under a directional light (straight down), a spot light or a
/// point light above it darkens the floor it hides by the light's whole share there, with the exact methods
/// (the ray tracer, the adaptive subdivision, slits; the vertex method bends the floor): the
/// shadow is where the light's direction projects the ball (brute force: a floor point is
/// shadowed if the way from it towards the light meets the ball; points within 2 cm of the
/// shadow's edge are left out); `--no-shadows` lights it again.
#[test]
fn a_ball_shadows_the_floor_where_brute_force_puts_its_shadow() {
    let p = exact(480, 160);
    for method in [Method::Trace, Method::Adaptive(Split::Error), Method::Slit(4)] {
        for kind in [LightKind::Directional, LightKind::Spot, LightKind::Point] {
            let scene = ball_over_floor(kind, false);
            let light = scene.lights[0].position;
            let settings = RenderSettings::new(p)
                .with_method(method)
                .with_ambient(0.2)
                .with_measure_error(true)
                .with_depth(true)
                .with_shadow_map_size(1024);
            let frame = render(&scene, &settings);
            let (mut in_shadow, mut lit, mut shadow_pixels) = (Vec::new(), Vec::new(), Vec::new());
            for (xy, point, v) in floor_pixels(&frame, &p, Vec3::ZERO) {
                let to_light = if kind == LightKind::Directional { Vec3::Y } else { (light - point).normalize() };
                // Brute force: does the way to the light pass through the ball? The
                // discriminant b² − (|q|² − r²) ≈ 2r·(distance inside the silhouette).
                let q = point - CENTRE;
                let b = q.dot(to_light);
                let inside = b * b - (q.length_squared() - RADIUS * RADIUS);
                if inside.abs() < 2.0 * RADIUS * 0.02 {
                    continue;
                }
                if b < 0.0 && inside > 0.0 {
                    in_shadow.push(v);
                    shadow_pixels.push(xy);
                } else {
                    lit.push(v)
                }
            }
            let what = format!("{} under a {kind:?} light", method.name());
            assert!(
                in_shadow.len() > 40 && lit.len() > 1000,
                "{what}: {} shadowed, {} lit floor pixels",
                in_shadow.len(),
                lit.len()
            );
            let (s_mean, l_mean) = (mean(&in_shadow), mean(&lit));
            assert!(s_mean < 0.6 * l_mean, "{what}: shadowed floor {s_mean:.1} against lit {l_mean:.1}");
            // In the shadow only the ambient part is left, the same everywhere.
            let spread = in_shadow.iter().max().unwrap() - in_shadow.iter().min().unwrap();
            assert!(spread <= 6, "{what}: the shadow is the ambient part alone, evenly ({spread} levels)");
            // `--no-shadows`: the floor the ball hid is lit.
            let unshadowed = render(&scene, &settings.with_shadows(false));
            let freed: Vec<u8> = shadow_pixels.iter().map(|&(x, y)| unshadowed.eye(Eye::Left).pixel(x, y)[0]).collect();
            assert!(
                mean(&freed) > s_mean + 0.5 * (l_mean - s_mean),
                "{what}: without shadows the hidden floor is {:.1} (shadow {s_mean:.1}, lit {l_mean:.1})",
                mean(&freed)
            );
        }
    }
}

/// A screen whose alpha-masked texture is a checker of holes casts a checker shadow: under a
/// light straight down, the floor below an opaque cell is in shadow and below a hole lit (brute
/// force: the cell straight above; points within 2 cm of a cell's edge, plus the reach of the
/// pixel's display-position error along the floor, left out), in the drawing
/// stages (the shadow pass discards what the mask leaves out). The eyes are below the screen,
/// which would hide the floor under it from above.
#[test]
fn an_alpha_masked_screen_casts_the_shadow_of_its_opaque_cells() {
    let p = exact(1024, 360);
    let viewer = Vec3::new(0.0, -0.6, 0.0);
    for method in [Method::Adaptive(Split::Error), Method::Slit(4)] {
        for kind in [LightKind::Directional, LightKind::Spot, LightKind::Point] {
            let scene = ball_over_floor(kind, true);
            let light = scene.lights[0].position;
            let settings = RenderSettings::new(p)
                .with_method(method)
                .with_ambient(0.2)
                .with_measure_error(true)
                .with_viewer(viewer)
                .with_shadow_map_size(1024);
            let frame = render(&scene, &settings);
            let (mut under_cells, mut under_holes) = (Vec::new(), Vec::new());
            for (xy, point, v) in floor_pixels(&frame, &p, viewer) {
                // Where the way towards the light crosses the screen's plane (y = −0.3).
                let to_light = if kind == LightKind::Directional { Vec3::Y } else { (light - point).normalize() };
                // Well inside the spot light's cone (0.5..0.8 rad), where it lights the floor.
                if kind == LightKind::Spot && to_light.y < 0.7f32.cos() {
                    continue;
                }
                let at = point + to_light * ((-0.3 - point.y) / to_light.y);
                let (u, v_) = ((at.x + 1.6) * 8.0, (at.z + 2.8) * 8.0);
                let margin = 0.02 + floor_reach(&frame, &p, viewer, xy, point);
                let near_edge = |c: f32| (c - c.round()).abs() < margin * 8.0;
                if !(0.0..8.0).contains(&u) || !(0.0..8.0).contains(&v_) || near_edge(u) || near_edge(v_) {
                    continue;
                }
                if (u as u32 + v_ as u32) % 2 == 0 {
                    under_cells.push(v);
                } else {
                    under_holes.push(v);
                }
            }
            let what = format!("{} under a {kind:?} light", method.name());
            assert!(
                under_cells.len() > 100 && under_holes.len() > 100,
                "{what}: {} pixels under cells, {} under holes",
                under_cells.len(),
                under_holes.len()
            );
            let (cells, holes) = (mean(&under_cells), mean(&under_holes));
            assert!(cells < 0.6 * holes, "{what}: floor under the opaque cells {cells:.1}, under the holes {holes:.1}");
            // Every pixel on its side: the darkest under a hole is brighter than the brightest
            // under a cell.
            let (cell_max, hole_min) = (under_cells.iter().max().unwrap(), under_holes.iter().min().unwrap());
            assert!(cell_max < hole_min, "{what}: brightest shadowed {cell_max}, darkest lit {hole_min}");
        }
    }
}

/// The shadow maps' size takes multiples of 64 from 64 to 8192; anything else is one line naming
/// the setting (the library names fields, not command-line flags).
#[test]
fn the_shadow_map_size_is_checked() {
    for bad in [0, 100, 65, 16384] {
        let e = RenderSettings::new(exact(64, 32)).with_shadow_map_size(bad).validate().unwrap_err().to_string();
        assert!(e.contains("shading.shadow_map_size") && e.contains(&bad.to_string()) && !e.contains('\n'), "{e}");
    }
    RenderSettings::new(exact(64, 32)).with_shadow_map_size(64).validate().unwrap();
}
