//! The TWISTER display's cylinder (`--panorama cylinder`, seed 002 §2.1, eq. 1–4): concentric
//! mosaics, eyes on the circle of radius d_e about the axis, each point drawn at u = θ ± α,
//! v = R_T·y/r (the paper's vertical model) or what a pinhole on the eye circle sees (the exact
//! one); with a tracked head, where the line from a fixed eye meets the screen
//! (`core::panoramas::head`). The derivation is in `core::panoramas::projection`'s module doc.
//! WGSL: `shaders/shared/projection.wgsl` (and `projection_head.wgsl`).

use glam::Vec3;

use crate::core::panoramas::panorama::{EyeModel, ImageMap, Panorama, PanoramaKind};
use crate::core::panoramas::projection::{
    horizontal_radius, linear_pixel, linear_screen, Eye, Projected, Projection, Vertical,
};

/// The cylinder.
pub struct Cylinder;

impl Projection {
    /// acos(d_e / R_T), the constant term of α.
    pub fn acos_eye_screen(&self) -> f32 {
        (self.eye_radius / self.screen_radius).clamp(0.0, 1.0).acos()
    }

    /// α(r) = acos(d_e/r) − acos(d_e/R_T) (eq. 3). Points with r ≤ d_e are seen by no eye;
    /// the ratio is clamped so that the result stays finite (the pre-pass culls them).
    pub fn eye_shift(&self, r: f32) -> f32 {
        (self.eye_radius / r).clamp(0.0, 1.0).acos() - self.acos_eye_screen()
    }

    /// The screen height of a point at height `y` and distance `r` from the axis.
    pub fn screen_height(&self, y: f32, r: f32) -> f32 {
        match self.vertical {
            Vertical::Paper => self.screen_radius * y / r,
            Vertical::Exact => {
                let (rt, de) = (self.screen_radius, self.eye_radius);
                let t_screen = (rt * rt - de * de).sqrt();
                let t_point = (r * r - de * de).max(1e-12).sqrt();
                y * t_screen / t_point
            }
        }
    }

    /// Pixels per metre of screen (square pixels): W / (2π·R_T). The cylinder only.
    pub fn pixels_per_metre(&self) -> f32 {
        self.width as f32 / (std::f32::consts::TAU * self.screen_radius)
    }

    /// Half the screen height in metres (the cylinder).
    pub fn half_height_m(&self) -> f32 {
        0.5 * self.height as f32 / self.pixels_per_metre()
    }
}

impl Panorama for Cylinder {
    fn kind(&self) -> PanoramaKind {
        PanoramaKind::Cylinder
    }

    fn wgsl_name(&self) -> &'static str {
        "PANORAMA_CYLINDER"
    }

    fn shader_bits(&self) -> u32 {
        1
    }

    fn eye_model(&self) -> EyeModel {
        EyeModel::Circle
    }

    fn image_map(&self) -> ImageMap {
        ImageMap::Linear
    }

    fn default_size(&self, width: u32) -> [u32; 2] {
        [width, (width / 5).max(2)]
    }

    fn sees(&self, p: &Projection, q: Vec3) -> bool {
        horizontal_radius(q) > p.eye_radius
    }

    fn project_with_azimuth(&self, p: &Projection, q: Vec3, theta: f32, eye: Eye) -> Projected {
        if let Some(head) = &p.head {
            return p.head_project(head, q, theta, eye);
        }
        let r = horizontal_radius(q);
        Projected { u: theta + eye.sign() * p.eye_shift(r), v: p.screen_height(q.y, r), depth: r }
    }

    fn to_pixel(&self, p: &Projection, u: f32, v: f32) -> [f32; 2] {
        linear_pixel(p, u, v)
    }

    fn pixel_to_screen(&self, p: &Projection, x: f32, y: f32) -> (f32, f32) {
        linear_screen(p, x, y)
    }

    fn pixels_per_v(&self, p: &Projection) -> f32 {
        p.pixels_per_metre()
    }

    /// The cylinder's half height over R_T (v = R_T·y/r).
    fn fill_tan(&self, p: &Projection) -> f32 {
        p.half_height_m() / p.screen_radius
    }

    /// The screen point (R_T sin u, v, −R_T cos u), seen from the centre (the head).
    fn screen_direction(&self, p: &Projection, u: f32, v: f32) -> Vec3 {
        if let Some(head) = &p.head {
            return p.head_screen_point(head, u, v).normalize();
        }
        let rt = p.screen_radius;
        Vec3::new(rt * u.sin(), v, -rt * u.cos()).normalize()
    }

    /// The exact model has v ≥ v_paper·√(1 − d_e²/R_T²), so k = half height /
    /// (R_T·√(1 − d_e²/R_T²)) is safe for both vertical models; from a tracked head's eye, the
    /// screen's rows rise at most to its edge's height over its nearest distance from the eye.
    fn vertical_limit(&self, p: &Projection) -> f32 {
        let (rt, de) = (p.screen_radius, p.eye_radius);
        if let Some(head) = &p.head {
            let [x, y, z] = head.offset;
            return (p.half_height_m() + y.abs()) / (rt - (x * x + z * z).sqrt() - de);
        }
        p.half_height_m() / (rt * (1.0 - (de / rt) * (de / rt)).sqrt())
    }

    /// From the eye whose tangent ray meets the screen at the pixel's column (viewing direction
    /// φ = u − s·asin(d_e/R_T), as the slit cameras) through the screen point
    /// (R_T sin u, v, −R_T cos u) — the exact vertical model's ray; the paper model has no
    /// single ray per pixel and uses the same. A tracked head: from its fixed eye.
    fn ray(&self, p: &Projection, eye: Eye, u: f32, v: f32) -> (Vec3, Vec3) {
        if let Some(head) = &p.head {
            let origin = p.head_eye(eye);
            return (origin, (p.head_screen_point(head, u, v) - origin).normalize());
        }
        let (rt, de) = (p.screen_radius, p.eye_radius);
        let phi = u - eye.sign() * (de / rt).asin();
        let origin = eye.sign() * de * Vec3::new(phi.cos(), 0.0, phi.sin());
        let screen = Vec3::new(rt * u.sin(), v, -rt * u.cos());
        (origin, (screen - origin).normalize())
    }

    /// Inverts eq. 1–4 at depth r (the distance from the axis): θ = u ∓ α(r) and y = v·r/R_T
    /// (paper) or y = v·√(r² − d_e²)/√(R_T² − d_e²) (exact). A tracked head: along the ray, the
    /// depth the distance from the eye.
    fn unproject(&self, p: &Projection, u: f32, v: f32, r: f32, eye: Eye) -> Vec3 {
        if p.head.is_some() {
            let (origin, ray) = self.ray(p, eye, u, v);
            return origin + r * ray;
        }
        let theta = u - eye.sign() * p.eye_shift(r);
        let height = match p.vertical {
            Vertical::Paper => v * r / p.screen_radius,
            Vertical::Exact => {
                let (rt, de) = (p.screen_radius, p.eye_radius);
                v * (r * r - de * de).max(0.0).sqrt() / (rt * rt - de * de).sqrt()
            }
        };
        Vec3::new(r * theta.sin(), height, -r * theta.cos())
    }
}
