//! The slit cameras of the conventional renderer (seed 002 §1, §4.3; the construction is in the
//! module doc of `cpu::slit`): the slits or tiles covering a panorama with their pinhole cameras,
//! the slit stage's parameters, and which objects a slit can see.

use glam::{Mat4, Vec2, Vec3};

use crate::core::panoramas::projection::{Eye, Projection};
use crate::encoding::types::{SlitCamera, SlitParams};

/// Distance of the slit cameras' near plane, metres.
pub const NEAR: f32 = 0.01;

/// A slit (the cylinder) or a tile of one (the sphere): its pixels and its camera.
#[derive(Clone, Copy, Debug)]
pub struct Slit {
    pub first_column: u32,
    pub end_column: u32,
    pub first_row: u32,
    pub end_row: u32,
    pub camera: SlitCamera,
}

pub fn slit_params(projection: &Projection, view: Mat4, eye: Eye, ambient: f32, error_angle: bool) -> SlitParams {
    SlitParams {
        view: view.to_cols_array_2d(),
        projection: projection.into(),
        eye_sign: eye.sign(),
        ambient,
        near: NEAR,
        error_angle: error_angle as u32,
    }
}

/// A camera at `origin` with the given axes, the tile centre at `centre` (NDC) and `scale`
/// (NDC per unit of x_c/z_c, y_c/z_c).
fn camera(origin: Vec3, right: Vec3, up: Vec3, forward: Vec3, centre: Vec2, scale: Vec2) -> SlitCamera {
    SlitCamera {
        origin_sx: origin.extend(scale.x).into(),
        right_cx: right.extend(centre.x).into(),
        up_cy: up.extend(centre.y).into(),
        forward_sy: forward.extend(scale.y).into(),
    }
}

/// The slits of `width` columns covering the panorama, with their cameras, for one eye: whole
/// columns on the cylinder, tiles of `width` × `width` pixels on the sphere.
pub fn slits(projection: &Projection, eye: Eye, width: u32) -> Vec<Slit> {
    let (w_img, h_img) = (projection.width, projection.height);
    if projection.model().drawn_as_pinhole() {
        return vec![Slit {
            first_column: 0,
            end_column: w_img,
            first_row: 0,
            end_row: h_img,
            camera: cave_camera(projection, eye),
        }];
    }
    let column_ranges = (0..w_img.div_ceil(width)).map(move |k| (k * width, ((k + 1) * width).min(w_img)));
    let ndc_x = |c: f32| 2.0 * c / w_img as f32 - 1.0;
    // Clip-space x per radian of azimuth: 2/W pixels⁻¹ × W/2π (VR180: W/π) pixels per radian.
    let clip_per_radian = 2.0 * projection.pixels_per_radian() / w_img as f32;
    if projection.panorama.is_sphere() {
        let mut out = Vec::new();
        for (c0, c1) in column_ranges {
            for r0 in (0..h_img).step_by(width as usize) {
                let r1 = (r0 + width).min(h_img);
                let (cx, cy) = (0.5 * (c0 + c1) as f32, 0.5 * (r0 + r1) as f32);
                let (lon, lat) = projection.pixel_to_screen(cx - 0.5, cy - 0.5);
                let (origin, forward) = projection.sphere_ray(lon, lat, eye);
                let right = Vec3::new(lon.cos(), 0.0, lon.sin());
                let up = right.cross(forward).normalize();
                let right = forward.cross(up).normalize();
                let scale = Vec2::new(clip_per_radian / lat.cos().max(1e-6), 2.0 / std::f32::consts::PI);
                let centre = Vec2::new(ndc_x(cx), 1.0 - 2.0 * cy / h_img as f32);
                let camera = camera(origin, right, up, forward, centre, scale);
                out.push(Slit { first_column: c0, end_column: c1, first_row: r0, end_row: r1, camera });
            }
        }
        return out;
    }
    let (rt, de) = (projection.screen_radius, projection.eye_radius);
    let offset = (de / rt).asin();
    let focal_y_clip = (rt * rt - de * de).sqrt() * projection.pixels_per_metre() / (0.5 * h_img as f32);
    column_ranges
        .map(|(c0, c1)| {
            let centre = 0.5 * (c0 + c1) as f32;
            let (u_c, _) = projection.pixel_to_screen(centre - 0.5, 0.0);
            let phi = u_c - eye.sign() * offset;
            let (s, c) = phi.sin_cos();
            let right = Vec3::new(c, 0.0, s);
            let forward = Vec3::new(s, 0.0, -c);
            let origin = eye.sign() * de * right;
            let scale = Vec2::new(clip_per_radian, focal_y_clip);
            let camera = camera(origin, right, Vec3::Y, forward, Vec2::new(ndc_x(centre), 0.0), scale);
            Slit { first_column: c0, end_column: c1, first_row: 0, end_row: h_img, camera }
        })
        .collect()
}

/// A CAVE wall's camera for one eye (`core::panoramas::cave`): at the eye, looking into the wall along its
/// normal, its right and up the wall's; the wall's image spans the NDC square, so the pinhole's
/// x_c/z_c maps to the wall's fraction a with NDC 2a − 1 = cx + sx·x_c/z_c, sx = 2δ/|R|, cx =
/// −2(C − E)·R̂/|R| − 1 (δ the eye's distance to the wall's plane), and likewise up.
fn cave_camera(projection: &Projection, eye: Eye) -> SlitCamera {
    let [corner, right, up] = projection.cave_wall();
    let e = projection.head_eye(eye);
    let forward = -right.cross(up).normalize();
    let delta = (corner - e).dot(forward);
    let (r, u) = (right.normalize(), up.normalize());
    let scale = Vec2::new(2.0 * delta / right.length(), 2.0 * delta / up.length());
    let centre =
        Vec2::new(-2.0 * (corner - e).dot(r) / right.length() - 1.0, -2.0 * (corner - e).dot(u) / up.length() - 1.0);
    camera(e, r, u, forward, centre, scale)
}

impl Slit {
    /// The slit's pixels within this draw's image (a tile's, or the frame's): [x, y, width,
    /// height] in the image's pixels, None where the tile holds none of them (the scissor).
    pub fn scissor(&self, projection: &Projection) -> Option<[u32; 4]> {
        let [tx, ty, tw, th] = projection.tile.unwrap_or([0, 0, projection.width, projection.height]);
        let (left, top) = (self.first_column.max(tx), self.first_row.max(ty));
        let (right, bottom) = (self.end_column.min(tx + tw), self.end_row.min(ty + th));
        (left < right && top < bottom).then(|| [left - tx, top - ty, right - left, bottom - top])
    }
}

/// A viewer-frame point in a slit camera's coordinates (x_c right, y_c up, z_c forward).
pub fn camera_coordinates(camera: &SlitCamera, p: Vec3) -> Vec3 {
    let rel = p - Vec3::from_slice(&camera.origin_sx[..3]);
    Vec3::new(
        rel.dot(Vec3::from_slice(&camera.right_cx[..3])),
        rel.dot(Vec3::from_slice(&camera.up_cy[..3])),
        rel.dot(Vec3::from_slice(&camera.forward_sy[..3])),
    )
}

/// Whether a sphere (viewer frame) can be seen through a slit: in front of the near plane and
/// within the planes through the camera and the slit's edges (conservative).
pub fn sphere_in_slit(params: &SlitParams, slit: &Slit, center: Vec3, radius: f32) -> bool {
    let cam = &slit.camera;
    let c = camera_coordinates(cam, center);
    if c.z < params.near - radius {
        return false;
    }
    let p = Projection::from(&params.projection);
    let ndc_x = |col: u32| 2.0 * col as f32 / p.width as f32 - 1.0;
    let ndc_y = |row: u32| 1.0 - 2.0 * row as f32 / p.height as f32;
    // The edges as tangents: x_c/z_c = (x_ndc − centre)/scale.
    let tx = [slit.first_column, slit.end_column].map(|k| (ndc_x(k) - cam.right_cx[3]) / cam.origin_sx[3]);
    let ty = [slit.end_row, slit.first_row].map(|k| (ndc_y(k) - cam.up_cy[3]) / cam.forward_sy[3]);
    // Signed distance to the plane a = t·z_c (normal (1, −t)/√(1+t²)), positive on the side
    // of larger a.
    let side = |a: f32, t: f32| (a - t * c.z) / (1.0 + t * t).sqrt();
    side(c.x, tx[0]) >= -radius
        && side(c.x, tx[1]) <= radius
        && side(c.y, ty[0]) >= -radius
        && side(c.y, ty[1]) <= radius
}
