//! The projection's tests: the forward map against a brute-force construction, the inverse,
//! the pixel mapping.

use super::*;
use rand::{Rng, SeedableRng};
use std::f64::consts::PI;
const PI_F32: f32 = std::f32::consts::PI;

/// The brute-force construction, in f64: for each screen azimuth φ_s, the eye of that column
/// stands on the eye circle and looks along the tangent; find the column whose ray passes
/// through `p` (bisection on the signed distance), then intersect that ray with the screen
/// cylinder. Returns (u, v) for the given eye under the `exact` vertical model, and the ray
/// parameters needed for the paper model.
fn brute_force(p: [f64; 3], eye: Eye, de: f64, rt: f64, vertical: Vertical) -> (f64, f64) {
    let dir = |phi: f64| [phi.sin(), -phi.cos()]; // (x, z) of a viewing direction
    let right = |phi: f64| [phi.cos(), phi.sin()]; // right-hand perpendicular of dir
    let side = if eye == Eye::Right { 1.0 } else { -1.0 };
    // Signed lateral offset of p from the ray of direction phi starting at the eye.
    let offset = |phi: f64| {
        let e = right(phi);
        let eye_pos = [side * de * e[0], side * de * e[1]];
        let rel = [p[0] - eye_pos[0], p[2] - eye_pos[1]];
        (rel[0] * e[0] + rel[1] * e[1], rel[0] * dir(phi)[0] + rel[1] * dir(phi)[1])
    };
    // The point's own azimuth; the ray direction is within ±π/2 of it.
    let theta = p[0].atan2(-p[2]);
    let (mut lo, mut hi) = (theta - PI / 2.0 + 1e-9, theta + PI / 2.0 - 1e-9);
    let f = |phi: f64| offset(phi).0;
    assert!(f(lo) * f(hi) < 0.0, "no tangent ray brackets the point");
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if f(lo) * f(mid) <= 0.0 {
            hi = mid
        } else {
            lo = mid
        }
    }
    let phi = 0.5 * (lo + hi);
    let forward = offset(phi).1; // distance along the ray from the eye to p
    assert!(forward > 0.0, "the point must be in front of its eye");
    // Hit of the ray with the screen cylinder: eye_pos + t·dir with |.| = rt → t = √(rt²−de²).
    let t_screen = (rt * rt - de * de).sqrt();
    let e = right(phi);
    let hit = [side * de * e[0] + t_screen * dir(phi)[0], side * de * e[1] + t_screen * dir(phi)[1]];
    let u = hit[0].atan2(-hit[1]);
    let v = match vertical {
        // Pinhole on the eye circle: similar triangles along the ray.
        Vertical::Exact => p[1] * t_screen / forward,
        // Paper: height scaled by the ratio of distances from the axis.
        Vertical::Paper => rt * p[1] / (p[0] * p[0] + p[2] * p[2]).sqrt(),
    };
    (u, v)
}

pub(crate) fn angle_diff(a: f64, b: f64) -> f64 {
    let d = (a - b).rem_euclid(2.0 * PI);
    d.min(2.0 * PI - d)
}

#[test]
fn matches_brute_force_construction_for_both_eyes_and_vertical_models() {
    let mut rng = rand::rngs::StdRng::seed_from_u64(7);
    for vertical in [Vertical::Paper, Vertical::Exact] {
        let proj = Projection { vertical, ..Projection::default() };
        for _ in 0..2000 {
            let r: f64 = rng.random_range(0.05..50.0);
            let theta: f64 = rng.random_range(-PI..PI);
            let y: f64 = rng.random_range(-5.0..5.0);
            let p = [r * theta.sin(), y, -r * theta.cos()];
            for eye in Eye::BOTH {
                let (u_ref, v_ref) = brute_force(p, eye, proj.eye_radius as f64, proj.screen_radius as f64, vertical);
                let got = proj.project(Vec3::new(p[0] as f32, p[1] as f32, p[2] as f32), eye).unwrap();
                let du_px = angle_diff(got.u as f64, u_ref) * proj.pixels_per_radian() as f64;
                let dv_px = (got.v as f64 - v_ref).abs() * proj.pixels_per_metre() as f64;
                assert!(du_px < 2e-3, "{vertical:?} {eye:?} p={p:?}: u off by {du_px} px");
                assert!(dv_px < 2e-3 * (1.0 + v_ref.abs()), "{vertical:?} {eye:?} p={p:?}: v off by {dv_px} px");
                assert!((got.depth as f64 - r).abs() < 1e-4 * r);
            }
        }
    }
}

#[test]
fn right_eye_sees_far_points_to_the_right() {
    let proj = Projection::default();
    let far = Vec3::new(0.0, 0.0, -5.0);
    let near = Vec3::new(0.0, 0.0, -0.5);
    let on_screen = Vec3::new(0.0, 0.0, -1.0);
    let disparity = |p| proj.project(p, Eye::Right).unwrap().u - proj.project(p, Eye::Left).unwrap().u;
    assert!(disparity(far) > 0.0);
    assert!(disparity(near) < 0.0);
    assert!(disparity(on_screen).abs() < 1e-6);
}

#[test]
fn points_inside_the_eye_circle_are_not_projected() {
    let proj = Projection::default();
    assert!(proj.project(Vec3::new(0.01, 0.0, -0.01), Eye::Left).is_none());
    assert!(proj.project(Vec3::new(0.0, 3.0, 0.0), Eye::Right).is_none());
    assert!(proj.project(Vec3::new(f32::NAN, 0.0, -1.0), Eye::Right).is_none());
}

#[test]
fn pixel_mapping_round_trips() {
    let proj = Projection { width: 320, height: 80, ..Projection::default() };
    for (c, r) in [(0.0, 0.0), (159.0, 39.0), (319.0, 79.0), (17.0, 60.0)] {
        let (u, v) = proj.pixel_to_screen(c, r);
        let [x, y] = proj.to_pixel(u, v);
        assert!((x - (c + 0.5)).abs() < 1e-3 && (y - (r + 0.5)).abs() < 1e-3, "{c},{r} -> {x},{y}");
    }
    // θ = 0 lies on the boundary between the two centre columns; straight up is row 0.
    assert!((proj.to_pixel(0.0, 0.0)[0] - 160.0).abs() < 1e-4);
    assert!(proj.to_pixel(0.0, proj.half_height_m())[1].abs() < 1e-4);
}

#[test]
fn the_inverse_takes_pixels_back_to_points_for_both_eyes_and_models() {
    let mut rng = rand::rngs::StdRng::seed_from_u64(11);
    for vertical in [Vertical::Paper, Vertical::Exact] {
        let proj = Projection { width: 1600, height: 400, vertical, ..Projection::default() };
        assert_eq!((proj.kind().name(), proj.size()), ("cylinder", [1600, 400]));
        for _ in 0..2000 {
            let r: f32 = rng.random_range(0.05..30.0);
            let theta: f32 = rng.random_range(-3.1..3.1);
            let p = Vec3::new(r * theta.sin(), rng.random_range(-3.0..3.0), -r * theta.cos());
            for eye in Eye::BOTH {
                let (pixel, depth) = proj.project_pixel(p, eye).unwrap();
                let back = proj.unproject_pixel(pixel, depth, eye);
                assert!(
                    (back - p).length() < 1e-4 * (1.0 + p.length()),
                    "{vertical:?} {eye:?}: {p} → {pixel:?} → {back}"
                );
                // And pixel → point → the same pixel, at another depth.
                let q = proj.unproject_pixel([pixel[0], 200.0], 2.5, eye);
                let (again, d) = proj.project_pixel(q, eye).unwrap();
                assert!(proj.wrapped_dx(again[0], pixel[0]) < 1e-2 && (again[1] - 200.0).abs() < 1e-2, "{again:?}");
                assert!((d - 2.5).abs() < 1e-5);
            }
        }
    }
}

#[test]
fn wrap_angle_is_half_open() {
    assert!((wrap_angle(PI_F32) + PI_F32).abs() < 1e-6);
    assert!((wrap_angle(-PI_F32) + PI_F32).abs() < 1e-6);
    assert!((wrap_angle(3.0 * PI_F32 / 2.0) + PI_F32 / 2.0).abs() < 1e-5);
    assert!((wrap_angle(0.25) - 0.25).abs() < 1e-7);
}

/// A random point around the viewer: a direction uniform on the sphere, at a distance from
/// 10^−0.5 to 10^1.5 m (log-uniform), for the panoramas' forward-map tests.
pub(crate) fn random_point(rng: &mut impl Rng) -> Vec3 {
    let (a, b): (f32, f32) = (rng.random_range(-1.0..1.0), rng.random_range(-PI_F32..PI_F32));
    let dist = 10f32.powf(rng.random_range(-0.5..1.5));
    let h = (1.0 - a * a).sqrt();
    dist * Vec3::new(h * b.sin(), a, -h * b.cos())
}
