//! The `prepare` stage, CPU twin of `shaders/prepare.wgsl`: readies scene triangles for the
//! projection vertex stage (seed 002 §2.1 eq. 1–4 is applied later, per vertex, in raster.wgsl).
//!
//! For each input triangle:
//! 1. **Viewer frame.** Positions and normals are moved into the viewer frame (viewer at the
//!    origin, +y up, −z ahead) by the rigid `view` transform.
//! 2. **The vertical axis.** No eye sees a point with r ≤ d_e (every eye ray is tangent to the
//!    eye circle), and a triangle whose footprint (its shadow on the xz plane) contains or comes
//!    near the axis covers all azimuths: drawn as one triangle it would be smeared across the
//!    whole panorama. Such a triangle — footprint containing the axis, passing within
//!    `split_radius` of it, or spanning more than 90° of azimuth — is **split** into the 8 sectors
//!    of 45° around the axis, and each sector piece is also clipped by the chord
//!    `dot(P, mid) ≥ axis_clearance` (mid: the sector's middle direction). Every output point
//!    is then at r ≥ `axis_clearance` > d_e, so nothing is culled with a NaN, and every piece spans
//!    ≤ 45°. What is removed is the disc of radius `axis_clearance` (≈ d_e) around the axis and the
//!    small chord caps up to `axis_clearance / cos 22.5°`: points no eye sees, or that project
//!    far off the top or bottom of the screen.
//!
//!    ```text
//!            \  |  /        8 sectors of 45°; each piece keeps the part of the
//!          `. \ | / .´      triangle in its wedge beyond the chord (the short
//!       ------ [ ] ------   segment near the centre), so the disc around the axis,
//!          .´ / | \ `.      where no eye sees, is cut out.
//!            /  |  \
//!    ```
//! 3. **The seam.** u = ±π is the left/right edge of the panorama. Each output triangle carries a
//!    reference azimuth `theta_ref` (that of its centroid); the vertex stage unwraps θ to within
//!    π of it, so the triangle is drawn whole, never across the image. If the triangle's u range
//!    (both eyes) passes +π a copy with `theta_ref − 2π` is emitted too (and + 2π for −π): the
//!    triangle then appears at both edges of the panorama and the rasterizer clips each copy.
//!
//! The GPU appends output triangles with an atomic counter, so its order differs from this
//! twin's; tests compare the two as sets.

use glam::{Mat4, Vec2, Vec3, Vec4};

use crate::gpu_types::{DrawVertex, PrepareParams, SceneVertex};
use crate::projection::{azimuth, horizontal_radius, wrap_angle, Projection};
use std::f32::consts::{PI, TAU};

/// Number of sectors an axis triangle is split into.
pub const SECTORS: u32 = 8;
/// Triangles spanning more azimuth than this (a little over 90°) are split into sectors too. Not
/// a round angle, so that structured meshes rarely sit exactly on the threshold.
pub const MAX_SPAN: f32 = 1.6;
/// Signed distances within this fraction of their terms' magnitude count as on the clip line,
/// so that the CPU and the GPU (whose rounding differs in the last bits) agree for vertices
/// lying on a sector boundary.
const SNAP: f32 = 1e-6;

const H: f32 = std::f32::consts::FRAC_1_SQRT_2;
const C8: f32 = 0.923_879_5; // cos(π/8)
const S8: f32 = 0.382_683_43; // sin(π/8)
/// (cos, sin) of the sector boundaries −π + k·π/4, an exact table shared with the WGSL.
const BOUNDARY: [(f32, f32); 9] = [
    (-1.0, 0.0),
    (-H, -H),
    (0.0, -1.0),
    (H, -H),
    (1.0, 0.0),
    (H, H),
    (0.0, 1.0),
    (-H, H),
    (-1.0, 0.0),
];
/// (cos, sin) of the sector middles −π + k·π/4 + π/8.
const MIDDLE: [(f32, f32); 8] = [
    (-C8, -S8),
    (-S8, -C8),
    (S8, -C8),
    (C8, -S8),
    (C8, S8),
    (S8, C8),
    (-S8, C8),
    (-C8, S8),
];
/// Upper bound of output triangles per input triangle: 8 sectors × 4 fan triangles × 2 copies.
pub const MAX_OUT_PER_TRIANGLE: u32 = SECTORS * 4 * 2;

/// The clearance kept around the vertical axis: just outside the eye circle (and never zero,
/// so that a mono camera with d_e = 0 still avoids the singular axis).
pub fn axis_clearance(projection: &Projection) -> f32 {
    projection.eye_radius.max(1e-3 * projection.screen_radius) * (1.0 + 1e-3)
}

/// A triangle that comes nearer the axis than this is split into sectors.
pub fn split_radius(axis_clearance: f32) -> f32 {
    axis_clearance / C8
}

pub fn prepare_params(
    projection: &Projection,
    view: Mat4,
    triangle_count: u32,
    first_triangle: u32,
    capacity: u32,
) -> PrepareParams {
    PrepareParams {
        view: view.to_cols_array_2d(),
        projection: projection.into(),
        axis_clearance: axis_clearance(projection),
        triangle_count,
        capacity,
        first_triangle,
    }
}

/// The input triangle in the viewer frame. Clipping works on barycentric coordinates of it
/// (clipping is linear, so this is exact), and attributes are interpolated once, on output.
#[derive(Clone, Copy, Debug)]
struct Triangle {
    position: [Vec3; 3],
    normal: [Vec3; 3],
    color: [Vec4; 3],
    uv: [Vec2; 3],
    material: u32,
}

impl Triangle {
    fn position(&self, b: Vec3) -> Vec3 {
        b.x * self.position[0] + b.y * self.position[1] + b.z * self.position[2]
    }

    fn draw_vertex(&self, b: Vec3, theta_ref: f32) -> DrawVertex {
        DrawVertex {
            position: self.position(b).into(),
            theta_ref,
            normal: (b.x * self.normal[0] + b.y * self.normal[1] + b.z * self.normal[2]).into(),
            material: self.material,
            color: (b.x * self.color[0] + b.y * self.color[1] + b.z * self.color[2]).into(),
            uv: (b.x * self.uv[0] + b.y * self.uv[1] + b.z * self.uv[2]).into(),
            _pad: [0.0; 2],
        }
    }
}

/// Half-plane `a·x + b·z ≥ c` in the viewer frame's xz plane.
#[derive(Clone, Copy)]
struct HalfPlane {
    a: f32,
    b: f32,
    c: f32,
}

impl HalfPlane {
    fn distance(&self, p: Vec3) -> f32 {
        let d = self.a * p.x + self.b * p.z - self.c;
        let scale = (self.a * p.x).abs() + (self.b * p.z).abs() + self.c.abs();
        if d.abs() <= SNAP * scale {
            0.0
        } else {
            d
        }
    }
}

/// Barycentric distance below which two clipped vertices are the same point.
const DUPLICATE_EPS: f32 = 1e-6;

fn coincide(a: Vec3, b: Vec3) -> bool {
    (a - b).abs().max_element() <= DUPLICATE_EPS
}

/// Sutherland–Hodgman clip of a convex polygon (barycentric corners) against one half-plane.
/// A vertex that repeats the previous one (a corner on the clip line) is dropped, so no
/// zero-area slivers come out.
fn clip_polygon(tri: &Triangle, poly: &[Vec3], plane: HalfPlane) -> Vec<Vec3> {
    let mut out: Vec<Vec3> = Vec::with_capacity(poly.len() + 1);
    let push = |b: Vec3, out: &mut Vec<Vec3>| {
        if out.last().is_none_or(|&l| !coincide(l, b)) {
            out.push(b);
        }
    };
    for i in 0..poly.len() {
        let cur = poly[i];
        let next = poly[(i + 1) % poly.len()];
        let d0 = plane.distance(tri.position(cur));
        let d1 = plane.distance(tri.position(next));
        if d0 >= 0.0 {
            push(cur, &mut out);
        }
        if (d0 >= 0.0) != (d1 >= 0.0) {
            push(cur + (next - cur) * (d0 / (d0 - d1)), &mut out);
        }
    }
    if out.len() > 1 && coincide(out[out.len() - 1], out[0]) {
        out.pop();
    }
    out
}

/// The three half-planes of sector s: θ ≥ boundary s, θ ≤ boundary s+1, beyond the chord.
fn sector_planes(s: u32, clearance: f32) -> [HalfPlane; 3] {
    // With P = (X, Y) = (−z, x), θ is P's polar angle. cross(d0, P) ≥ 0 ⇔ θ ≥ φ0;
    // cross(P, d1) ≥ 0 ⇔ θ ≤ φ1; dot(P, d_mid) ≥ clearance is the chord.
    let (c0, s0) = BOUNDARY[s as usize];
    let (c1, s1) = BOUNDARY[s as usize + 1];
    let (cm, sm) = MIDDLE[s as usize];
    [
        HalfPlane {
            a: c0,
            b: s0,
            c: 0.0,
        },
        HalfPlane {
            a: -c1,
            b: -s1,
            c: 0.0,
        },
        HalfPlane {
            a: sm,
            b: -cm,
            c: clearance,
        },
    ]
}

/// Distance from the origin to segment ab in the xz plane.
fn segment_distance(a: Vec2, b: Vec2) -> f32 {
    let ab = b - a;
    let len2 = ab.dot(ab);
    let t = if len2 > 0.0 {
        (-a.dot(ab) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (a + ab * t).length()
}

fn cross2(a: Vec2, b: Vec2) -> f32 {
    a.x * b.y - a.y * b.x
}

/// Whether a triangle must be split into sectors (see the module doc).
pub fn needs_axis_split(p: [Vec3; 3], split_radius: f32) -> bool {
    let q = p.map(|v| Vec2::new(v.x, v.z));
    let e0 = cross2(q[1] - q[0], -q[0]);
    let e1 = cross2(q[2] - q[1], -q[1]);
    let e2 = cross2(q[0] - q[2], -q[2]);
    let contains = (e0 >= 0.0 && e1 >= 0.0 && e2 >= 0.0) || (e0 <= 0.0 && e1 <= 0.0 && e2 <= 0.0);
    let near = segment_distance(q[0], q[1])
        .min(segment_distance(q[1], q[2]))
        .min(segment_distance(q[2], q[0]))
        < split_radius;
    let t = p.map(azimuth);
    let span = wrap_angle(t[0] - t[1])
        .abs()
        .max(wrap_angle(t[1] - t[2]).abs())
        .max(wrap_angle(t[2] - t[0]).abs());
    contains || near || span > MAX_SPAN
}

/// The `prepare` stage on the CPU: every output triangle as three [`DrawVertex`]es.
pub fn prepare(
    params: &PrepareParams,
    vertices: &[SceneVertex],
    indices: &[u32],
) -> Vec<DrawVertex> {
    let projection = crate::projection::Projection {
        screen_radius: params.projection.screen_radius,
        eye_radius: params.projection.eye_radius,
        width: params.projection.width as u32,
        height: params.projection.height as u32,
        vertical: if params.projection.vertical_exact != 0 {
            crate::projection::Vertical::Exact
        } else {
            crate::projection::Vertical::Paper
        },
    };
    let view = Mat4::from_cols_array_2d(&params.view);
    let mut out = Vec::new();
    let first = params.first_triangle as usize;
    let last = first + params.triangle_count as usize;
    for t in first..last {
        let v = |k: usize| &vertices[indices[3 * t + k] as usize];
        let tri = Triangle {
            position: [0, 1, 2].map(|k| view.transform_point3(Vec3::from(v(k).position))),
            normal: [0, 1, 2].map(|k| view.transform_vector3(Vec3::from(v(k).normal))),
            color: [0, 1, 2].map(|k| Vec4::from(v(k).color)),
            uv: [0, 1, 2].map(|k| Vec2::from(v(k).uv)),
            material: v(0).material,
        };
        let corners = [Vec3::X, Vec3::Y, Vec3::Z];
        let clearance = params.axis_clearance;
        if needs_axis_split(tri.position, split_radius(clearance)) {
            for s in 0..SECTORS {
                let mut poly = corners.to_vec();
                for plane in sector_planes(s, clearance) {
                    poly = clip_polygon(&tri, &poly, plane);
                }
                for i in 1..poly.len().saturating_sub(1) {
                    emit(&projection, &tri, [poly[0], poly[i], poly[i + 1]], &mut out);
                }
            }
        } else {
            emit(&projection, &tri, corners, &mut out);
        }
    }
    out
}

/// Appends one triangle (barycentric corners) and, where it crosses the seam, its copy on the
/// other side.
fn emit(projection: &Projection, tri: &Triangle, corners: [Vec3; 3], out: &mut Vec<DrawVertex>) {
    let p = corners.map(|b| tri.position(b));
    let theta_c = azimuth((p[0] + p[1] + p[2]) / 3.0);
    let (mut u_min, mut u_max) = (f32::INFINITY, f32::NEG_INFINITY);
    for q in p {
        let theta = theta_c + wrap_angle(azimuth(q) - theta_c);
        let alpha = projection.eye_shift(horizontal_radius(q)).abs();
        u_min = u_min.min(theta - alpha);
        u_max = u_max.max(theta + alpha);
    }
    let mut push = |theta_ref: f32| out.extend(corners.map(|b| tri.draw_vertex(b, theta_ref)));
    push(theta_c);
    if u_max > PI {
        push(theta_c - TAU);
    }
    if u_min < -PI {
        push(theta_c + TAU);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::projection::{Eye, Projection};
    use std::f32::consts::{FRAC_PI_4, FRAC_PI_8};

    fn vertex(p: [f32; 3]) -> SceneVertex {
        SceneVertex {
            position: p,
            normal: [0.0, 1.0, 0.0],
            color: [1.0; 4],
            ..Default::default()
        }
    }

    fn run(tri: [[f32; 3]; 3]) -> (Projection, Vec<DrawVertex>) {
        let projection = Projection::default();
        let params = prepare_params(&projection, Mat4::IDENTITY, 1, 0, 0);
        let v: Vec<SceneVertex> = tri.iter().map(|&p| vertex(p)).collect();
        (projection, prepare(&params, &v, &[0, 1, 2]))
    }

    /// Area of the footprint of a triangle list on the xz plane.
    fn footprint_area(v: &[DrawVertex]) -> f32 {
        v.chunks(3)
            .map(|t| {
                let q: Vec<Vec2> = t
                    .iter()
                    .map(|d| Vec2::new(d.position[0], d.position[2]))
                    .collect();
                0.5 * cross2(q[1] - q[0], q[2] - q[0]).abs()
            })
            .sum()
    }

    #[test]
    fn ordinary_triangle_passes_through_unchanged() {
        let (_, out) = run([[-0.5, 0.0, -3.0], [0.5, 0.0, -3.0], [0.0, 0.5, -3.0]]);
        assert_eq!(out.len(), 3);
        assert!(out[0].theta_ref.abs() < 1e-6);
    }

    #[test]
    fn floor_around_the_axis_is_split_and_keeps_its_area_outside_the_clearance() {
        let tri = [[-4.0, -1.5, 3.0], [4.0, -1.5, 3.0], [0.0, -1.5, -5.0]];
        let (projection, out) = run(tri);
        assert!(
            out.len() >= 3 * 8,
            "expected sector pieces, got {} vertices",
            out.len()
        );
        let clearance = axis_clearance(&projection);
        for d in &out {
            let r = horizontal_radius(Vec3::from(d.position));
            assert!(
                r >= clearance * (1.0 - 1e-4),
                "point at r={r} inside the clearance"
            );
            for eye in Eye::BOTH {
                let p = projection
                    .project(Vec3::from(d.position), eye)
                    .expect("projectable");
                assert!(p.u.is_finite() && p.v.is_finite());
            }
        }
        // The pieces tile the triangle minus the octagon around the axis (area 8·c²·tan(π/8)).
        let full = 0.5 * 8.0 * 8.0;
        let octagon = 8.0 * clearance * clearance * FRAC_PI_8.tan();
        let got = footprint_area(&out); // copies at the seam double some pieces: remove them
        let seam_copies: f32 = footprint_area(
            &out.chunks(3)
                .filter(|t| t[0].theta_ref.abs() > PI)
                .flatten()
                .copied()
                .collect::<Vec<_>>(),
        );
        assert!(
            ((got - seam_copies) - (full - octagon)).abs() < 1e-3 * full,
            "area {got} vs {}",
            full - octagon
        );
        // No piece spans more than one sector.
        for t in out.chunks(3) {
            let th: Vec<f32> = t
                .iter()
                .map(|d| d.theta_ref + wrap_angle(azimuth(Vec3::from(d.position)) - d.theta_ref))
                .collect();
            let span = th.iter().cloned().fold(f32::MIN, f32::max)
                - th.iter().cloned().fold(f32::MAX, f32::min);
            assert!(span <= FRAC_PI_4 + 1e-4, "piece spans {span}");
        }
    }

    #[test]
    fn triangle_with_a_vertex_inside_the_eye_circle_is_clipped_without_nan() {
        let (projection, out) = run([[0.01, -0.5, 0.0], [2.0, -0.5, -2.0], [-2.0, -0.5, -2.0]]);
        assert!(!out.is_empty());
        for d in &out {
            assert!(horizontal_radius(Vec3::from(d.position)) > projection.eye_radius);
            assert!(d
                .position
                .iter()
                .chain(d.normal.iter())
                .all(|x| x.is_finite()));
        }
    }

    #[test]
    fn seam_triangle_gets_a_copy_on_the_other_side() {
        let (_, out) = run([[-0.5, 0.0, 3.0], [0.5, 0.0, 3.0], [0.0, 0.5, 3.0]]);
        assert_eq!(out.len(), 6, "one triangle and its seam copy");
        let refs: Vec<f32> = out.chunks(3).map(|t| t[0].theta_ref).collect();
        assert!((refs[0].abs() - PI).abs() < 1e-3 && (refs[1].abs() - PI).abs() < 1e-3);
        assert!((refs[0] - refs[1]).abs() > 6.0);
    }
}
