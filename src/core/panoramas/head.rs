//! The TWISTER cylinder seen by a tracked head away from the display's centre (`--head`, seeds
//! 000 and 001's question for the cylinder): the eyes are two fixed points, d_e either side of
//! the head along its right, and a point is drawn where the line from an eye through it meets
//! the screen cylinder of radius R_T about the display's centre.
//!
//! The frame drawn is the head's (origin midway between the eyes, +y up, the head looking along
//! −z): there the eyes stand at s·d_e·(1, 0, 0), and the display's frame is the head's turned by
//! γ and moved by O ([`Head`]: p_display = R_y(γ)·p_head + O, O the head in the display's frame).
//! For a point p, with E the eye and d = p − E in the display's frame:
//!
//! ```text
//!   t > 0 with |(E + t·d)_xz| = R_T            the ray's exit through the screen
//!   H = E + t·d                                its screen point
//!   u = atan2(H_x, −H_z),  v = H_y,  depth |p − E|
//! ```
//!
//! so the cylinder's image (u across, v up, square pixels) and its inverse stay as they are. The
//! caller's unwrapped azimuth θ of p (about the head) carries u across the seam: u = θ − γ +
//! wrap(u − θ + γ). That difference is continuous wherever the ray does not pass the head's
//! vertical axis after p, which only points within d_e of that axis do — and those, as on the
//! centred cylinder, no eye is said to see (`sees`: r > d_e), so the subdivision's cuts around
//! the axis and its seam copies work unchanged. The WGSL twin is `head_*` in
//! shaders/shared/projection.wgsl.

use glam::{Mat3, Vec3};

use crate::core::panoramas::panorama::EyeModel;
pub use crate::core::panoramas::projection::Head;
use crate::core::panoramas::projection::{azimuth, wrap_angle, Eye, Projected, Projection, Vertical};
use crate::error::{Error, Result};

impl Head {
    /// The head at `position` (scene units × `scale` = metres, scene frame) facing `yaw_deg`,
    /// for a display at `viewer` facing `viewer_yaw_deg` (both as `--viewer` and `--yaw` mean
    /// them).
    pub fn relative(position: Vec3, yaw_deg: f32, viewer: Vec3, viewer_yaw_deg: f32) -> Head {
        let offset = Mat3::from_rotation_y(-viewer_yaw_deg.to_radians()) * (position - viewer);
        // Within ±π: a turn a whole turn off (a head at −179° before a viewer at 173°: −352°)
        // would draw every piece a whole image width off its place, where one seam copy each
        // way no longer reaches the image's other side (the search: background in the first
        // columns).
        Head {
            offset: offset.to_array(),
            turn: crate::core::panoramas::projection::wrap_angle((yaw_deg - viewer_yaw_deg).to_radians()),
        }
    }

    /// Head frame → display frame, rotation part.
    pub fn rotation(&self) -> Mat3 {
        Mat3::from_rotation_y(self.turn)
    }

    /// Display frame → head frame, as a matrix on points (`RenderSettings::view` composes it).
    pub fn to_head(&self) -> glam::Mat4 {
        glam::Mat4::from_rotation_y(-self.turn) * glam::Mat4::from_translation(-Vec3::from(self.offset))
    }
}

impl Projection {
    /// The tracked head's settings: the cylinder, finite, the eyes within the screen, the exact model.
    pub(crate) fn validate_head(&self) -> Result<()> {
        if let Some(head) = &self.head {
            let [x, y, z] = head.offset;
            let circle = self.model().eye_model() == EyeModel::Circle;
            if self.model().eye_model() == EyeModel::Sphere {
                return Err(Error::setting(
                    "view.projection.head",
                    "a tracked head looks at the cylinder panorama or CAVE walls",
                ));
            }
            if !(head.offset.iter().all(|c| c.is_finite()) && head.turn.is_finite()) {
                return Err(Error::setting("view.projection.head", format!("must be finite, got {head:?}")));
            }
            let reach = (x * x + z * z).sqrt() + self.eye_radius;
            if circle && reach >= self.screen_radius {
                return Err(Error::setting(
                    "view.projection.head",
                    format!(
                        "the eyes reach the screen: the head is {:.3} m from the display's axis, plus the eye radius {} \
                         makes {reach:.3} m, not within the screen radius {}",
                        (x * x + z * z).sqrt(),
                        self.eye_radius,
                        self.screen_radius
                    ),
                ));
            }
            let _ = y;
            if circle && self.vertical == Vertical::Paper {
                return Err(Error::setting(
                    "view.projection.vertical",
                    "a tracked head draws each point where the line from the eye meets the screen: the exact model",
                ));
            }
        }
        Ok(())
    }

    /// The eye's position in the head's frame.
    pub fn head_eye(&self, eye: Eye) -> Vec3 {
        Vec3::new(eye.sign() * self.eye_radius, 0.0, 0.0)
    }

    /// u, v and depth of head-frame point `p` for `eye` (see the module doc), u unwrapped about
    /// the caller's azimuth θ of p.
    pub fn head_project(&self, head: &Head, p: Vec3, theta: f32, eye: Eye) -> Projected {
        let e_head = self.head_eye(eye);
        let rot = head.rotation();
        let e = rot * e_head + Vec3::from(head.offset);
        let d = rot * (p - e_head);
        let (a, b) = (d.x * d.x + d.z * d.z, 2.0 * (e.x * d.x + e.z * d.z));
        let c = e.x * e.x + e.z * e.z - self.screen_radius * self.screen_radius;
        let t = (-b + (b * b - 4.0 * a * c).max(0.0).sqrt()) / (2.0 * a).max(1e-30);
        let hit = e + t * d;
        let u_hit = azimuth(hit);
        let u = theta - head.turn + wrap_angle(u_hit - theta + head.turn);
        Projected { u, v: hit.y, depth: (p - e_head).length() }
    }

    /// The screen point of (u, v), in the head's frame.
    pub fn head_screen_point(&self, head: &Head, u: f32, v: f32) -> Vec3 {
        let rt = self.screen_radius;
        let s = Vec3::new(rt * u.sin(), v, -rt * u.cos());
        head.rotation().transpose() * (s - Vec3::from(head.offset))
    }
}

#[cfg(test)]
mod tests {
    use crate::core::panoramas::projection::{pixel_ray, Camera, Eye, Head, Projection, Vertical};
    use glam::{Vec2, Vec3};
    use rand::{Rng, SeedableRng};

    /// Every point is drawn at the pixel whose ray (from the fixed eye through that pixel's
    /// screen point, built here from the screen's geometry) passes through it; the inverse takes
    /// pixels back to points. Heads off the centre and turned, both eyes.
    #[test]
    fn an_off_centre_head_sees_each_point_where_its_line_meets_the_screen() {
        let mut rng = rand::rngs::StdRng::seed_from_u64(34);
        let mut compared = 0;
        for (offset, turn) in [([0.3f32, 0.1, -0.2], 0.0f32), ([-0.5, -0.2, 0.4], 0.7), ([0.0, 0.0, 0.0], -1.2)] {
            let head = Head { offset, turn };
            let proj = Projection { vertical: Vertical::Exact, head: Some(head), ..Projection::default() };
            proj.validate().unwrap();
            for _ in 0..2000 {
                let b: f32 = rng.random_range(-std::f32::consts::PI..std::f32::consts::PI);
                let r = 10f32.powf(rng.random_range(-1.0..1.3));
                let p = Vec3::new(r * b.sin(), rng.random_range(-2.0..2.0), -r * b.cos());
                for eye in Eye::BOTH {
                    let Some(([x, y], depth)) = proj.project_pixel(p, eye) else { continue };
                    if !(0.0..600.0).contains(&y) {
                        continue;
                    }
                    // The pixel's screen point from the display's geometry, then the line.
                    let (u, v) = proj.pixel_to_screen(x - 0.5, y - 0.5);
                    let s_display = Vec3::new(u.sin(), v, -u.cos());
                    let rot = glam::Mat3::from_rotation_y(turn);
                    let s = rot.transpose() * (s_display - Vec3::from(offset));
                    let e = Vec3::new(eye.sign() * 0.032, 0.0, 0.0);
                    let dir = (s - e).normalize();
                    let to_p = p - e;
                    let miss = (to_p - to_p.dot(dir) * dir).length();
                    // A thousandth of a pixel at the point's distance (a pixel spans about
                    // 2π/3168 rad seen from the head).
                    let px = to_p.length() * std::f32::consts::TAU / 3168.0;
                    assert!(miss < 2e-3 * px + 1e-6, "{offset:?} {turn} {eye:?} {p}: misses by {} px", miss / px);
                    assert!(to_p.dot(dir) > 0.0, "in front of the eye");
                    assert!((depth - to_p.length()).abs() < 1e-4 * depth);
                    // pixel_ray agrees, and the inverse.
                    let (o, d) = pixel_ray(&proj, eye, Vec2::new(x, y));
                    assert!((o - e).length() < 1e-6 && (d - dir).length() < 1e-4);
                    let back = proj.unproject_pixel([x, y], depth, eye);
                    assert!((back - p).length() < 1e-3 * r.max(1.0), "{p} → ({x}, {y}) → {back}");
                    compared += 1;
                }
            }
        }
        assert!(compared > 5000, "{compared}");
    }

    #[test]
    fn a_head_at_the_centre_facing_ahead_sees_what_a_pinhole_on_the_axis_sees() {
        // d_e = 0 and the head at the centre: the screen point straight along the line from the
        // centre, the cylinder's exact model with no eye offset.
        let proj = Projection {
            eye_radius: 0.0,
            vertical: Vertical::Exact,
            head: Some(Head { offset: [0.0; 3], turn: 0.0 }),
            ..Projection::default()
        };
        let plain = Projection { eye_radius: 0.0, vertical: Vertical::Exact, ..Projection::default() };
        for p in [Vec3::new(1.0, 0.3, -2.0), Vec3::new(-3.0, -1.0, 0.5), Vec3::new(0.2, 0.1, 4.0)] {
            let (a, b) = (proj.project_pixel(p, Eye::Left).unwrap().0, plain.project_pixel(p, Eye::Left).unwrap().0);
            assert!((a[0] - b[0]).abs() < 1e-3 && (a[1] - b[1]).abs() < 1e-3, "{a:?} {b:?}");
        }
    }
}
