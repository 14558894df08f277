//! The TWISTER projection (seed 002, §2.1, eq. 1–4), CPU side.
//!
//! Viewer frame: the viewer stands at the origin, +y is up, straight ahead is −z. For a point
//! `p = (x, y, z)`:
//!
//! ```text
//!   r = √(x² + z²)                       (eq. 1, cylindrical radius; also the depth)
//!   θ = atan2(x, −z)                     (azimuth, 0 straight ahead, +π/2 to the right)
//!   α = acos(d_e / r) − acos(d_e / R_T)  (eq. 3)
//!   u = θ ± α                            (eq. 2/4; + for the right eye, − for the left eye)
//!   v = R_T · y / r                      (eq. 4, `Vertical::Paper`)
//!   v = y · √(R_T² − d_e²) / √(r² − d_e²)  (`Vertical::Exact`: a pinhole on the eye circle)
//! ```
//!
//! `R_T` is [`Projection::screen_radius`], `d_e` is [`Projection::eye_radius`].
//!
//! **Which eye gets which sign.** An eye sits on the circle of radius d_e and looks along the
//! tangent; the right eye is on the right of its viewing direction φ, at `d_e·right(φ)`. Its ray
//! reaches distance r from the axis after √(r² − d_e²) and is then seen from the origin at angle
//! `φ + asin(d_e/r)`; it meets the screen at `φ + asin(d_e/R_T)`. Eliminating φ,
//! `u = θ − asin(d_e/r) + asin(d_e/R_T) = θ + α` (using asin = π/2 − acos). So the right eye is
//! `θ + α`: a point beyond the screen (r > R_T, α > 0) is seen further right by the right eye,
//! the uncrossed disparity of ordinary stereo. The tests check this against a brute-force
//! construction (eye point, tangent ray, cylinder hit) for both eyes and both vertical models.
//!
//! Pixels: u ∈ [−π, π) spans the image width with θ = 0 at the centre column; pixels are square,
//! one pixel = 2π·R_T/W metres of screen; v = 0 is the middle row, +y is up in the image.
//!
//! The full sphere's eye model and its forward map are in `core::panoramas::sphere`; the fisheye's image map
//! in `core::panoramas::fisheye`.
//!
//! The WGSL twin of this module is `shaders/shared/projection.wgsl`; both must stay in step.

use glam::{Vec2, Vec3};

pub use crate::core::panoramas::kind::PanoramaKind;
use crate::error::{Error, Result};

/// The vertical model: how the screen height `v` of a point is computed.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Vertical {
    /// `v = R_T·y/r`, the paper's design (seed 002 eq. 4).
    #[default]
    Paper,
    /// `v = y·√(R_T²−d_e²)/√(r²−d_e²)`: what a pinhole camera on the eye circle, looking along
    /// the tangent, sees. The slit renderer converges to this model.
    Exact,
}

crate::choices!(Vertical {
    Paper => ("paper", "v = R_T·y/r, the paper's vertical model"),
    Exact => ("exact", "What a pinhole on the eye circle sees (the slit renderer's limit)"),
});

/// One of the viewer's two eyes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Eye {
    Left,
    Right,
}

impl Eye {
    pub const BOTH: [Eye; 2] = [Eye::Left, Eye::Right];
    /// The sign of α in `u = θ ± α` (see the module doc for the derivation).
    pub fn sign(self) -> f32 {
        match self {
            Eye::Left => -1.0,
            Eye::Right => 1.0,
        }
    }
    pub fn name(self) -> &'static str {
        match self {
            Eye::Left => "left",
            Eye::Right => "right",
        }
    }
}

/// The display geometry: the panorama (the TWISTER screen cylinder or the full sphere), the eye
/// circle and the image raster.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Projection {
    /// R_T: radius of the display cylinder, metres (the cylinder only).
    pub screen_radius: f32,
    /// d_e: radius of the circle the eyes move on, metres (half the interocular distance).
    pub eye_radius: f32,
    /// Image width in pixels (covers the full 2π of azimuth; VR180: π, see [`Projection::turn_px`]).
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// The cylinder's vertical model.
    pub vertical: Vertical,
    pub panorama: PanoramaKind,
    /// The full sphere: rays converge on the sphere of this radius, metres; None: parallel rays.
    pub convergence: Option<f32>,
    /// The full sphere: the eye offset fades out between these altitudes, degrees; None: off.
    pub pole_merge: Option<(f32, f32)>,
    /// The fisheye: the field of view inscribed in the square image, degrees (180: the dome's
    /// hemisphere).
    pub fov: f32,
    /// The fisheye: the dome's front raised by this many degrees (its axis tilted back).
    pub dome_tilt: f32,
    /// The cylinder: a tracked head away from the display's centre (`core::panoramas::head`); None: the
    /// paper's eyes on the circle about the centre.
    pub head: Option<Head>,
    /// The CAVE: the wall drawn, in the display's frame (`core::panoramas::cave`); None elsewhere.
    pub wall: Option<CaveWall>,
    /// A frame larger than the adapter draws is drawn in tiles: this draw's [x, y, width,
    /// height] in the frame's pixels (the maps stay the frame's); None: the whole frame.
    pub tile: Option<[u32; 4]>,
}

/// A tracked head before the cylinder (`core::panoramas::head`, which has its maths): where the head is,
/// seen from the display: its position O in the display's frame (metres;
/// the display's centre is the origin, its front −z) and the turn γ (radians) that takes the
/// head's frame into the display's (a direction at azimuth θ about the head lies at θ − γ about
/// the display).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Head {
    pub offset: [f32; 3],
    pub turn: f32,
}

/// A CAVE wall in the display's frame, metres (`core::panoramas::cave`, which has its maths): its lower
/// left corner, and its right and up edges (full width and height).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct CaveWall {
    pub corner: [f32; 3],
    pub right: [f32; 3],
    pub up: [f32; 3],
}

/// The pole merge Blender uses by default (degrees of altitude).
pub const DEFAULT_POLE_MERGE: (f32, f32) = (60.0, 75.0);

impl Default for Projection {
    /// The paper's TWISTER images: 3168×600 per eye, R_T = 1 m, d_e = 0.032 m.
    fn default() -> Self {
        Projection {
            screen_radius: 1.0,
            eye_radius: 0.032,
            width: 3168,
            height: 600,
            vertical: Vertical::Paper,
            panorama: Default::default(),
            convergence: None,
            pole_merge: Some(DEFAULT_POLE_MERGE),
            fov: 180.0,
            dome_tilt: 0.0,
            head: None,
            wall: None,
            tile: None,
        }
    }
}

/// A projected point: screen azimuth `u` (radians, not wrapped), screen height `v` (metres on
/// the screen), and depth `r` (metres from the axis).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Projected {
    pub u: f32,
    pub v: f32,
    pub depth: f32,
}

/// Wraps an angle into [−π, π). Same formula as `wrap_angle` in projection.wgsl.
pub fn wrap_angle(a: f32) -> f32 {
    let tau = std::f32::consts::TAU;
    a - tau * ((a + std::f32::consts::PI) / tau).floor()
}

/// θ = atan2(x, −z): the azimuth of a viewer-frame point. x = −0 counts as +0 (θ = π straight
/// behind), as in projection.wgsl.
pub fn azimuth(p: Vec3) -> f32 {
    (p.x + 0.0).atan2(-p.z)
}

/// r = √(x² + z²): the distance of a viewer-frame point from the vertical axis.
pub fn horizontal_radius(p: Vec3) -> f32 {
    (p.x * p.x + p.z * p.z).sqrt()
}

/// The largest image side a frame may have, in pixels, whatever the adapter (frames beyond the
/// adapter's textures are drawn in tiles): JPEG's limit.
pub const MAX_IMAGE_SIDE: u32 = 65535;

impl Projection {
    pub fn validate(&self) -> Result<()> {
        if !(self.screen_radius.is_finite() && self.screen_radius > 0.0) {
            return Err(Error::setting(
                "view.projection.screen_radius",
                format!("must be a positive number of metres, got {}", self.screen_radius),
            ));
        }
        if !(self.eye_radius >= 0.0 && self.eye_radius < self.screen_radius) {
            return Err(Error::setting(
                "view.projection.eye_radius",
                format!("must be in [0, screen radius {}), got {}", self.screen_radius, self.eye_radius),
            ));
        }
        if let Some(c) = self.convergence {
            if !(c.is_finite() && c > self.eye_radius) {
                return Err(Error::setting(
                    "view.projection.convergence",
                    format!(
                        "must be `parallel` or a distance in metres beyond the eye radius {}, got {c}",
                        self.eye_radius
                    ),
                ));
            }
        }
        if let Some((from, to)) = self.pole_merge {
            if !(from.is_finite() && to.is_finite() && 0.0 <= from && from < to && to <= 90.0) {
                return Err(Error::setting(
                    "view.projection.pole_merge",
                    format!("must be `off` or FROM,TO degrees with 0 ≤ FROM < TO ≤ 90, got {from},{to}"),
                ));
            }
        }
        self.validate_head()?;
        if self.wall.is_some() && !self.model().drawn_as_pinhole() {
            return Err(Error::setting("view.projection.wall", "a wall belongs to the CAVE panorama"));
        }
        self.model().validate(self)?;
        if let Some([x, y, w, h]) = self.tile {
            let inside = w > 0
                && h > 0
                && x.checked_add(w).is_some_and(|e| e <= self.width)
                && y.checked_add(h).is_some_and(|e| e <= self.height);
            if !inside {
                return Err(Error::setting(
                    "view.projection.tile",
                    format!("must lie within the {}x{} frame, got {x},{y} {w}x{h}", self.width, self.height),
                ));
            }
        }
        if self.width < 2 || self.height < 2 || self.width > MAX_IMAGE_SIDE || self.height > MAX_IMAGE_SIDE {
            return Err(Error::setting(
                "view.projection.width/height",
                format!(
                    "image size must be between 2 and {MAX_IMAGE_SIDE} pixels per side, got {}x{}",
                    self.width, self.height
                ),
            ));
        }
        Ok(())
    }

    /// The eye offset at a point's altitude (height `y`, distance `r` from the axis): the
    /// sphere's, which its pole merge fades towards the poles
    /// ([`sphere_eye_offset`](Self::sphere_eye_offset)), else d_e (`eye_offset` in projection.wgsl).
    pub fn eye_offset(&self, r: f32, y: f32) -> f32 {
        if self.panorama.is_sphere() {
            self.sphere_eye_offset(r, y)
        } else {
            self.eye_radius
        }
    }

    /// Projects a viewer-frame point for one eye. `None` when the eye does not see it (the
    /// cylinder: r ≤ d_e; the sphere: r below the eye offset at its altitude) or it is not finite.
    pub fn project(&self, p: Vec3, eye: Eye) -> Option<Projected> {
        self.model().project(self, p, eye)
    }

    /// Like [`project`](Self::project) but with θ given (already unwrapped by the caller).
    /// Points no eye sees are drawn with the offset clamped (they stay finite).
    pub fn project_with_azimuth(&self, p: Vec3, theta: f32, eye: Eye) -> Projected {
        self.model().project_with_azimuth(self, p, theta, eye)
    }

    /// The size of the image this draw makes: the tile's, or the frame's.
    pub fn image_size(&self) -> [u32; 2] {
        self.tile.map_or([self.width, self.height], |[_, _, w, h]| [w, h])
    }

    /// Where this draw's image starts in the frame, pixels.
    pub fn tile_origin(&self) -> Vec2 {
        self.tile.map_or(Vec2::ZERO, |[x, y, _, _]| Vec2::new(x as f32, y as f32))
    }

    /// A clip position on the whole frame as the tile's draw has it (`tile_clip` in
    /// projection.wgsl): NDC scaled by frame/tile and shifted, linear in clip space.
    pub fn tile_clip(&self, clip: glam::Vec4) -> glam::Vec4 {
        let Some([x, y, w, h]) = self.tile else { return clip };
        let (fw, fh) = (self.width as f32, self.height as f32);
        let (x, y, w, h) = (x as f32, y as f32, w as f32, h as f32);
        glam::Vec4::new(
            clip.x * fw / w + clip.w * ((fw - 2.0 * x) / w - 1.0),
            clip.y * fh / h + clip.w * (1.0 - (fh - 2.0 * y) / h),
            clip.z,
            clip.w,
        )
    }

    /// Pixels per unit of v: per metre of screen height (the cylinder), per radian of latitude
    /// (the sphere: H/π).
    pub fn pixels_per_v(&self) -> f32 {
        self.model().pixels_per_v(self)
    }

    /// Pixels per full turn of azimuth (2π): the width, or twice it for VR180 (whose width
    /// spans π); the images without a seam (the fisheye, the cubemap, the CAVE) f32::MAX (x
    /// never wraps). `turn_px` in projection.wgsl.
    pub fn turn_px(&self) -> f32 {
        self.model().turn_share().map_or(f32::MAX, |share| self.width as f32 / share)
    }

    /// Pixels per radian of azimuth: W / 2π (VR180: W / π).
    pub fn pixels_per_radian(&self) -> f32 {
        self.turn_px() / std::f32::consts::TAU
    }

    /// Continuous image coordinates (x right, y down, pixel centres at +0.5) of a screen point;
    /// `u` is wrapped into [−π, π), azimuth 0 at the image's centre column (VR180: |u| > π/2
    /// falls outside the image).
    pub fn to_pixel(&self, u: f32, v: f32) -> [f32; 2] {
        self.model().to_pixel(self, u, v)
    }

    /// The screen point (u, v) at the centre of pixel (column, row); u ∈ [−π, π) (VR180:
    /// [−π/2, π/2)).
    pub fn pixel_to_screen(&self, column: f32, row: f32) -> (f32, f32) {
        self.model().pixel_to_screen(self, column, row)
    }

    /// The tangent of the half vertical angle that `--fit` and the screen-filling built-ins fill:
    /// the cylinder's half height over R_T (v = R_T·y/r); elsewhere tan 30° (about the
    /// cylinder's default view).
    pub fn fill_tan(&self) -> f32 {
        self.model().fill_tan(self)
    }

    /// The unit direction, seen from the centre, of screen point (u, v): on the cylinder the
    /// screen point (R_T sin u, v, −R_T cos u), on the sphere longitude u, latitude v.
    /// `screen_direction` in fragment.wgsl.
    pub fn screen_direction(&self, u: f32, v: f32) -> Vec3 {
        self.model().screen_direction(self, u, v)
    }

    /// The slope k such that a point with |y| > k·r shows in no pixel row: above the top of the
    /// cylinder's image, or on the sphere beyond the centre of its first (or last) pixel row
    /// (its panorama's `vertical_limit`).
    pub fn vertical_limit(&self) -> f32 {
        self.model().vertical_limit(self)
    }

    /// Whether image position (x, y) shows the panorama (the fisheye: inside its circle).
    pub fn shows_pixel(&self, x: f32, y: f32) -> bool {
        self.model().shows_pixel(self, x, y)
    }

    /// How far a drawn edge may dip inside the image's rim (its panorama's `chord_dip_px`).
    pub fn chord_dip_px(&self, error_split: bool, edge_px: f32, max_error_px: f32) -> f32 {
        self.model().chord_dip_px(self, error_split, edge_px, max_error_px)
    }

    /// The cone about the antipode of the image's axis the subdivision drops
    /// (its panorama's `antipode_cone`).
    pub fn dome_antipode_cone(&self, dip_px: f32) -> Option<f32> {
        self.model().antipode_cone(self, dip_px)
    }

    /// The image the subdivision measures its edges on (its panorama's `measured`).
    pub fn measured(&self) -> Projection {
        self.model().measured(self)
    }

    /// The horizontal distance in pixels between two image x coordinates, wrapping around the
    /// full turn (VR180: a turn is twice the width, so no two pixels of its image wrap; the
    /// fisheye and the cubemap: no wrap).
    pub fn wrapped_dx(&self, a: f32, b: f32) -> f32 {
        if self.model().turn_share().is_none() {
            return (a - b).abs();
        }
        let w = self.turn_px();
        let d = (a - b).rem_euclid(w);
        d.min(w - d)
    }
}

/// The linear image map (the cylinder, the sphere's equirectangular images): x linear in u,
/// wrapped into [−π, π) about the centre column at `turn_px` pixels a turn; y linear in v.
pub(crate) fn linear_pixel(p: &Projection, u: f32, v: f32) -> [f32; 2] {
    let x = wrap_angle(u) / std::f32::consts::TAU * p.turn_px() + 0.5 * p.width as f32;
    let y = 0.5 * p.height as f32 - v * p.pixels_per_v();
    [x, y]
}

/// The inverse of [`linear_pixel`] at the centre of pixel (column, row).
pub(crate) fn linear_screen(p: &Projection, column: f32, row: f32) -> (f32, f32) {
    let u = (column + 0.5 - 0.5 * p.width as f32) / p.turn_px() * std::f32::consts::TAU;
    let v = (0.5 * p.height as f32 - (row + 0.5)) / p.pixels_per_v();
    (u, v)
}

/// A frame's panorama as a camera (pbrt's `Camera`, for two eyes): where an eye's image shows a
/// viewer-frame point, and its inverse, the point at a given depth that a pixel shows. The
/// rasterizer's stages and their twins use the forward map; the inverse places points from
/// pixels (tests, ray generation).
pub trait Camera {
    fn kind(&self) -> PanoramaKind;
    /// Image size per eye, pixels.
    fn size(&self) -> [u32; 2];
    /// Continuous image coordinates (x right, y down; pixel centres at +0.5, x wrapped into the
    /// image) and the depth of a viewer-frame point for one eye; None where no eye sees it.
    fn project_pixel(&self, p: Vec3, eye: Eye) -> Option<([f32; 2], f32)>;
    /// The viewer-frame point at `depth` that `eye` sees at image coordinates `pixel`:
    /// `project_pixel(unproject_pixel(q, d, e), e) == (q, d)` for every depth an eye sees.
    fn unproject_pixel(&self, pixel: [f32; 2], depth: f32, eye: Eye) -> Vec3;
}

impl Camera for Projection {
    fn kind(&self) -> PanoramaKind {
        self.panorama
    }

    fn size(&self) -> [u32; 2] {
        [self.width, self.height]
    }

    fn project_pixel(&self, p: Vec3, eye: Eye) -> Option<([f32; 2], f32)> {
        self.project(p, eye).map(|q| (self.to_pixel(q.u, q.v), q.depth))
    }

    /// The panorama's inverse (its `unproject`) at the pixel's screen point.
    fn unproject_pixel(&self, [x, y]: [f32; 2], depth: f32, eye: Eye) -> Vec3 {
        let (u, v) = self.pixel_to_screen(x - 0.5, y - 0.5);
        self.model().unproject(self, u, v, depth, eye)
    }
}

/// The ray of the pixel at `frag_xy`: its eye point and unit direction (each panorama's
/// `ray` at the pixel's screen point).
pub fn pixel_ray(projection: &Projection, eye: Eye, frag_xy: Vec2) -> (Vec3, Vec3) {
    let (u, v) = projection.pixel_to_screen(frag_xy.x - 0.5, frag_xy.y - 0.5);
    projection.model().ray(projection, eye, u, v)
}

/// The points the pixels' rays meet at `distances` (per eye, +∞: none → NaN), viewer frame:
/// a traced frame's surface points (`Frame::positions`).
pub fn ray_hit_points(projection: &Projection, distances: &[Vec<f32>; 2]) -> [Vec<[f32; 3]>; 2] {
    std::array::from_fn(|k| {
        let eye = Eye::BOTH[k];
        distances[k]
            .iter()
            .enumerate()
            .map(|(i, &t)| {
                if !t.is_finite() {
                    return [f32::NAN; 3];
                }
                let w = projection.image_size()[0];
                let (x, y) = ((i as u32 % w) as f32 + 0.5, (i as u32 / w) as f32 + 0.5);
                let (o, d) = pixel_ray(projection, eye, Vec2::new(x, y) + projection.tile_origin());
                (o + t * d).to_array()
            })
            .collect()
    })
}

#[cfg(test)]
#[path = "projection_tests.rs"]
pub(crate) mod tests;
