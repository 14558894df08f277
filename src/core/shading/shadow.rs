//! Shadow maps for the drawing stages (issue 17): where a directional or spot light's map looks
//! and how a surface point reads it.
//!
//! A shadow map is a depth image of the scene rendered from the light (the `shadow` stage),
//! independent of the panorama: an orthographic view along a directional light's direction
//! fitted to the scene's bounding box; a perspective view from a spot light's position covering
//! its outer cone (at most [`MAX_SPOT_FOV_DEG`]) out to the farthest corner of the box (or its
//! range); for a point light a cube of six perspective faces (±x, ±y, ±z, 92° each, half the
//! side), the face read chosen by the direction from the light. The first
//! [`MAX_SHADOWED_LIGHTS`] lights of a frame get maps; any others light without shadow in the
//! drawing stages (the ray tracer shadows every light by rays).
//!
//! A surface point p (viewer frame) with normal n facing the light l is looked up at
//! p' = p + (NORMAL_OFFSET_TEXELS · n + LIGHT_OFFSET_TEXELS · l) · t, t the world size of one
//! texel there (constant for an orthographic map, ∝ the distance along the axis for a spot
//! light): the normal offset keeps a lit surface from shadowing itself (acne) at any slope, at
//! the price of moving shadow edges by about two texels. Its depth is compared with the four
//! nearest texels and the four results weighted bilinearly (percentage-closer filtering,
//! `shadow_visibility` in surface.wgsl and cpu/fragment.rs).

use bytemuck::{Pod, Zeroable};
use glam::{Mat4, Vec3, Vec4};

use crate::core::shading::light::{GpuLight, LightKind, NO_SHADOW_MAP};

/// Lights of a frame that get shadow maps.
pub const MAX_SHADOWED_LIGHTS: usize = 4;
/// Map entries a frame may have (a point light takes six).
pub const MAX_SHADOW_MAPS: usize = 6 * MAX_SHADOWED_LIGHTS;
/// `GpuShadowMap::projection`: orthographic, perspective, or the first of a cube's six faces
/// (+x, −x, +y, −y, +z, −z) (`SHADOW_*` in the WGSL `constants` module).
pub const SHADOW_ORTHOGRAPHIC: u32 = 0;
pub const SHADOW_PERSPECTIVE: u32 = 1;
pub const SHADOW_CUBE: u32 = 2;
/// A cube face's full angle: a little over 90° so that the filter's taps near a face's edge
/// stay on it.
pub const CUBE_FACE_FOV_DEG: f32 = 92.0;
/// The widest spot light cone a map covers (its full angle); wider cones are cut to it.
pub const MAX_SPOT_FOV_DEG: f32 = 170.0;
/// The look-up's offsets along the normal and towards the light, in texels.
pub const NORMAL_OFFSET_TEXELS: f32 = 1.5;
pub const LIGHT_OFFSET_TEXELS: f32 = 1.0;
/// The default side of a map, texels (`--shadow-map-size`).
pub const DEFAULT_SHADOW_MAP_SIZE: u32 = 2048;

/// `ShadowMap` in shaders/shared/surface.wgsl: a map's projection (viewer frame → the light's
/// clip space, depth 0..1), where its depths start in the depth buffer, its side in texels, the
/// world size of a texel (at unit distance along the axis for a perspective map) and its kind
/// (`SHADOW_*`). 80 bytes.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct GpuShadowMap {
    pub clip_from_viewer: [[f32; 4]; 4],
    pub offset: u32,
    pub size: u32,
    pub texel: f32,
    pub projection: u32,
}

impl GpuShadowMap {
    pub fn matrix(&self) -> Mat4 {
        Mat4::from_cols_array_2d(&self.clip_from_viewer)
    }
}

/// The eight corners of the box `min..max` moved by `m`.
pub fn box_corners(min: Vec3, max: Vec3, m: Mat4) -> [Vec3; 8] {
    std::array::from_fn(|i| {
        let pick = |bit: usize, lo: f32, hi: f32| if i >> bit & 1 == 0 { lo } else { hi };
        m.transform_point3(Vec3::new(pick(0, min.x, max.x), pick(1, min.y, max.y), pick(2, min.z, max.z)))
    })
}

/// The light's view: `eye` at the origin looking along unit `dir` down −z, `up` towards +y
/// (right-handed).
fn look_to(eye: Vec3, dir: Vec3, up: Vec3) -> Mat4 {
    let f = dir.normalize();
    let s = f.cross(up).normalize();
    let u = s.cross(f);
    Mat4::from_cols(
        Vec4::new(s.x, u.x, -f.x, 0.0),
        Vec4::new(s.y, u.y, -f.y, 0.0),
        Vec4::new(s.z, u.z, -f.z, 0.0),
        Vec4::new(-s.dot(eye), -u.dot(eye), f.dot(eye), 1.0),
    )
}

/// Orthographic projection of the view box x ∈ [l, r], y ∈ [b, t], −z ∈ [near, far] onto
/// clip x, y ∈ [−1, 1] and depth ∈ [0, 1] (wgpu's convention).
fn orthographic(l: f32, r: f32, b: f32, t: f32, near: f32, far: f32) -> Mat4 {
    Mat4::from_cols(
        Vec4::new(2.0 / (r - l), 0.0, 0.0, 0.0),
        Vec4::new(0.0, 2.0 / (t - b), 0.0, 0.0),
        Vec4::new(0.0, 0.0, -1.0 / (far - near), 0.0),
        Vec4::new(-(r + l) / (r - l), -(t + b) / (t - b), -near / (far - near), 1.0),
    )
}

/// Perspective projection of a square cone of full angle `fov` along −z: w = −z (the distance
/// along the axis), depth = far·(w − near) / ((far − near)·w), 0 at `near` and 1 at `far`.
fn perspective(fov: f32, near: f32, far: f32) -> Mat4 {
    let k = 1.0 / (0.5 * fov).tan();
    Mat4::from_cols(
        Vec4::new(k, 0.0, 0.0, 0.0),
        Vec4::new(0.0, k, 0.0, 0.0),
        Vec4::new(0.0, 0.0, far / (near - far), -1.0),
        Vec4::new(0.0, 0.0, near * far / (near - far), 0.0),
    )
}

/// An up vector not parallel to `forward`.
fn up_for(forward: Vec3) -> Vec3 {
    if forward.y.abs() > 0.99 {
        Vec3::X
    } else {
        Vec3::Y
    }
}

/// The maps of a frame's lights (viewer frame, the first `count` of `lights`), for a scene
/// whose bounding box has `corners` (viewer frame), `size` texels square (a cube's faces half
/// that, at least 64, a multiple of 64): the first [`MAX_SHADOWED_LIGHTS`] lights get maps and
/// their `shadow_map` the index of the first; the others get [`NO_SHADOW_MAP`].
pub fn plan_shadow_maps(lights: &mut [GpuLight], count: usize, corners: &[Vec3; 8], size: u32) -> Vec<GpuShadowMap> {
    let mut maps: Vec<GpuShadowMap> = Vec::new();
    let mut shadowed = 0;
    let extent = corners.iter().fold(0.0f32, |m, c| m.max((*c - corners[0]).length())).max(1e-3);
    let push = |maps: &mut Vec<GpuShadowMap>, matrix: Mat4, size: u32, texel: f32, projection: u32| {
        let offset = maps.last().map_or(0, |m| m.offset + m.size * m.size);
        maps.push(GpuShadowMap { clip_from_viewer: matrix.to_cols_array_2d(), offset, size, texel, projection });
    };
    for light in lights.iter_mut().take(count) {
        light.shadow_map = NO_SHADOW_MAP;
        let dir = Vec3::from(light.direction).normalize_or_zero();
        let point = light.kind == LightKind::Point as u32;
        if shadowed == MAX_SHADOWED_LIGHTS || (dir == Vec3::ZERO && !point) {
            continue;
        }
        shadowed += 1;
        light.shadow_map = maps.len() as u32;
        let position = Vec3::from(light.position);
        // A perspective map's far plane: the box's farthest corner, or the light's range.
        let far = {
            let far_box = corners.iter().map(|c| (*c - position).length()).fold(0.0f32, f32::max);
            let far = if light.range > 0.0 { far_box.min(light.range) } else { far_box };
            far.max(1e-3) * 1.01
        };
        if light.kind == LightKind::Directional as u32 {
            // Looking along the light from the box's centre; the box's extent across and along.
            let centre = corners.iter().sum::<Vec3>() / 8.0;
            let view = look_to(centre, dir, up_for(dir));
            let (mut lo, mut hi) = (Vec3::splat(f32::MAX), Vec3::splat(f32::MIN));
            for c in corners {
                let q = view.transform_point3(*c);
                lo = lo.min(q);
                hi = hi.max(q);
            }
            // Square texels; a margin so the box's faces are not on the map's edges.
            let margin = 0.01 * extent;
            let half = 0.5 * (hi.x - lo.x).max(hi.y - lo.y) + margin;
            let (cx, cy) = (0.5 * (lo.x + hi.x), 0.5 * (lo.y + hi.y));
            let proj = orthographic(cx - half, cx + half, cy - half, cy + half, -hi.z - margin, -lo.z + margin);
            push(&mut maps, proj * view, size, 2.0 * half / size as f32, SHADOW_ORTHOGRAPHIC);
        } else if point {
            let face = (size / 2 / 64 * 64).max(64);
            let fov = CUBE_FACE_FOV_DEG.to_radians();
            for axis in [Vec3::X, Vec3::NEG_X, Vec3::Y, Vec3::NEG_Y, Vec3::Z, Vec3::NEG_Z] {
                let view = look_to(position, axis, up_for(axis));
                let texel = 2.0 * (0.5 * fov).tan() / face as f32;
                push(&mut maps, perspective(fov, far * 1e-3, far) * view, face, texel, SHADOW_CUBE);
            }
        } else {
            let view = look_to(position, dir, up_for(dir));
            let outer = light.outer_cos.clamp(-1.0, 1.0).acos();
            let fov = (2.0 * outer + 2f32.to_radians()).min(MAX_SPOT_FOV_DEG.to_radians());
            let texel = 2.0 * (0.5 * fov).tan() / size as f32;
            push(&mut maps, perspective(fov, far * 1e-3, far) * view, size, texel, SHADOW_PERSPECTIVE);
        }
    }
    maps
}

/// The face of a cube whose light is seen from p along the unit direction `l` (towards the
/// light): the major axis of −l (+x, −x, +y, −y, +z, −z: 0..5).
pub fn cube_face(l: Vec3) -> u32 {
    major_axis_face(-l)
}

/// The major axis of `d` as a face in the order +x, −x, +y, −y, +z, −z (0..5; ties to the
/// earlier axis), the shadow cubes' and (with ±z swapped) the stereo cubemap's.
pub fn major_axis_face(d: Vec3) -> u32 {
    let a = d.abs();
    let axis = if a.x >= a.y && a.x >= a.z {
        0
    } else if a.y >= a.z {
        1
    } else {
        2
    };
    2 * axis + (d[axis as usize] < 0.0) as u32
}

/// Where p (viewer frame) falls in a map: texel coordinates (x right, y down, texel centres at
/// k + 0.5) and depth; None where the map does not see it (behind a spot light).
pub fn shadow_coordinates(map: &GpuShadowMap, p: Vec3) -> Option<(f32, f32, f32)> {
    let q: Vec4 = map.matrix() * p.extend(1.0);
    if q.w <= 0.0 {
        return None;
    }
    let ndc = q.truncate() / q.w;
    let size = map.size as f32;
    Some(((ndc.x * 0.5 + 0.5) * size, (0.5 - ndc.y * 0.5) * size, ndc.z))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::core::shading::light::Light;

    fn light(kind: LightKind, position: Vec3, direction: Vec3) -> GpuLight {
        Light {
            kind,
            position,
            direction: direction.normalize(),
            color: Vec3::ONE,
            range: None,
            inner_cone: 0.3,
            outer_cone: 0.6,
        }
        .gpu()
    }

    #[test]
    fn maps_cover_the_box_and_a_point_light_gets_a_cube() {
        let corners = box_corners(Vec3::new(-2.0, 0.0, -3.0), Vec3::new(2.0, 3.0, 1.0), Mat4::IDENTITY);
        let mut lights = vec![
            light(LightKind::Point, Vec3::new(0.0, 2.0, 0.0), Vec3::NEG_Y),
            light(LightKind::Directional, Vec3::ZERO, Vec3::new(0.3, -1.0, 0.2)),
            light(LightKind::Spot, Vec3::new(0.0, 2.9, -1.0), Vec3::NEG_Y),
        ];
        let all = plan_shadow_maps(&mut lights, 3, &corners, 256);
        assert_eq!(all.len(), 8);
        assert_eq!(lights.iter().map(|l| l.shadow_map).collect::<Vec<_>>(), [0, 6, 7]);
        // The cube's faces are half the side; each map starts where the last ended.
        assert!(all[..6].iter().all(|m| m.size == 128 && m.projection == SHADOW_CUBE));
        assert_eq!(all[7].offset, 6 * 128 * 128 + 256 * 256);
        // Below the point light, the −y face sees the floor at its centre; beside it, +x.
        let below = Vec3::new(0.0, 0.0, 0.0);
        let face = cube_face((Vec3::new(0.0, 2.0, 0.0) - below).normalize());
        assert_eq!(face, 3);
        let (x, y, z) = shadow_coordinates(&all[face as usize], below).unwrap();
        assert!((x - 64.0).abs() < 1e-2 && (y - 64.0).abs() < 1e-2 && (0.0..1.0).contains(&z));
        assert_eq!(cube_face(Vec3::new(-1.0, 0.2, 0.1).normalize()), 0);
        let beside = shadow_coordinates(&all[0], Vec3::new(1.5, 2.1, -0.2)).unwrap();
        assert!((0.0..128.0).contains(&beside.0) && (0.0..128.0).contains(&beside.1));
        let maps = &all[6..];
        // Every corner of the box is inside the directional light's map, depth within 0..1.
        for c in corners {
            let (x, y, z) = shadow_coordinates(&maps[0], c).unwrap();
            assert!((0.0..=256.0).contains(&x) && (0.0..=256.0).contains(&y) && (0.0..=1.0).contains(&z), "{c}");
        }
        // Along the directional light, depth grows; the spot light sees the floor below it
        // at the map's centre, and a point nearer to it at a smaller depth.
        let dir = Vec3::new(0.3, -1.0, 0.2).normalize();
        let a = shadow_coordinates(&maps[0], Vec3::new(0.0, 1.5, -1.0)).unwrap();
        let b = shadow_coordinates(&maps[0], Vec3::new(0.0, 1.5, -1.0) + dir).unwrap();
        assert!((a.0 - b.0).abs() < 1e-3 && (a.1 - b.1).abs() < 1e-3 && b.2 > a.2);
        let floor = shadow_coordinates(&maps[1], Vec3::new(0.0, 0.0, -1.0)).unwrap();
        let table = shadow_coordinates(&maps[1], Vec3::new(0.0, 1.0, -1.0)).unwrap();
        assert!((floor.0 - 128.0).abs() < 1e-2 && (floor.1 - 128.0).abs() < 1e-2);
        assert!(table.2 < floor.2 && floor.2 < 1.0);
        // A texel's world size where the floor is: the map's width there / 256.
        let edge = shadow_coordinates(&maps[1], Vec3::new(1.0, 0.0, -1.0)).unwrap();
        let texel_world = maps[1].texel * 2.9;
        assert!(((edge.0 - floor.0).hypot(edge.1 - floor.1) * texel_world - 1.0).abs() < 1e-3);
    }

    #[test]
    fn only_the_first_lights_get_maps() {
        let corners = box_corners(Vec3::splat(-1.0), Vec3::splat(1.0), Mat4::IDENTITY);
        let mut lights: Vec<GpuLight> =
            (0..6).map(|_| light(LightKind::Directional, Vec3::ZERO, Vec3::new(0.0, -1.0, 0.1))).collect();
        let maps = plan_shadow_maps(&mut lights, 6, &corners, 64);
        assert_eq!(maps.len(), MAX_SHADOWED_LIGHTS);
        assert_eq!(lights[4].shadow_map, NO_SHADOW_MAP);
        assert_eq!(lights[3].shadow_map, 3);
    }
}
