//! The fulldome master (`--panorama fisheye`): the full sphere's eye rays (`core::panoramas::sphere`, the
//! same ODS eye model, so a point is first projected to the longitude λ and latitude φ of the
//! eye ray that reaches it) drawn in an equidistant azimuthal image, the planetarium convention:
//!
//! ```text
//!   D = (cos φ sin λ, sin φ, −cos φ cos λ)           the ray's direction
//!   A = (0, cos t, sin t), F = (0, sin t, −cos t), R = (1, 0, 0)
//!                                                   the dome's axis, its front and its right
//!                                                   (t = --dome-tilt: the front raised by t)
//!   ψ = atan2(√(a² + b²), D·A), a = D·R, b = D·F    the angle from the axis
//!   ρ = k·ψ, k = (W/2) / (FOV/2)                    equidistant: the FOV circle inscribed
//!   x = W/2 + ρ·a/√(a² + b²),  y = H/2 + ρ·b/√(a² + b²)
//! ```
//!
//! so the zenith (t = 0) is at the centre, straight ahead at the bottom edge's middle and the
//! viewer's right on the right, as one sees the dome looking up with the front below. Outside
//! the FOV circle (ρ > W/2) the image shows the background. The WGSL twin is
//! `fisheye_pixel` / `fisheye_direction` in `shaders/shared/projection.wgsl`.

use glam::Vec3;

use crate::core::panoramas::panorama::{EyeModel, ImageMap, Panorama, PanoramaKind};
use crate::core::panoramas::projection::Projection;
use crate::error::{Error, Result};

/// The fulldome master.
pub struct Fisheye;

impl Projection {
    /// The fulldome master: `width` × `width` pixels per eye, the zenith at the centre, 180°.
    pub fn fisheye(width: u32) -> Projection {
        Projection::of(Fisheye.kind(), width)
    }

    /// The fisheye's settings: its field of view, its tilt, and a tilted dome's antipode off the rim.
    fn validate_fisheye(&self) -> Result<()> {
        {
            if !(self.fov.is_finite() && self.fov > 0.0 && self.fov <= 360.0) {
                return Err(Error::setting(
                    "view.projection.fov",
                    format!("must be a field of view in degrees, 0 < FOV ≤ 360, got {}", self.fov),
                ));
            }
            if !(self.dome_tilt.is_finite() && self.dome_tilt.abs() <= 90.0) {
                return Err(Error::setting(
                    "view.projection.dome_tilt",
                    format!("must be degrees between -90 and 90, got {}", self.dome_tilt),
                ));
            }
            if self.dome_tilt != 0.0 && self.fisheye_antipode_cone(0.0).is_none() {
                return Err(Error::setting(
                    "view.projection.dome_tilt",
                    format!(
                        "a tilted dome takes a field of view below 340°, got {}: the point opposite its axis \
                         then lies within 10° of the image's rim",
                        self.fov
                    ),
                ));
            }
        }
        Ok(())
    }

    /// k: pixels per radian from the dome's axis, W / FOV.
    pub fn fisheye_pixels_per_radian(&self) -> f32 {
        self.width as f32 / self.fov.to_radians()
    }

    /// The dome's axis, front and right (see the module doc).
    pub fn dome_basis(&self) -> [Vec3; 3] {
        let (s, c) = self.dome_tilt.to_radians().sin_cos();
        [Vec3::new(0.0, c, s), Vec3::new(0.0, s, -c), Vec3::X]
    }

    /// The image position (x right, y down, pixel centres at +0.5) of the ray of longitude
    /// `lon` and latitude `lat`. Continuous in λ: no seam.
    pub fn fisheye_pixel(&self, lon: f32, lat: f32) -> [f32; 2] {
        let d = Vec3::new(lat.cos() * lon.sin(), lat.sin(), -lat.cos() * lon.cos());
        let [axis, front, right] = self.dome_basis();
        let (a, b, c) = (d.dot(right), d.dot(front), d.dot(axis));
        let h = (a * a + b * b).sqrt();
        let psi = h.atan2(c);
        // ψ/h → 1 at the axis.
        let ratio = if h > 0.0 { psi / h } else { 1.0 };
        let k = self.fisheye_pixels_per_radian();
        [0.5 * self.width as f32 + k * ratio * a, 0.5 * self.height as f32 + k * ratio * b]
    }

    /// The longitude and latitude of the ray the fisheye shows at image position (x, y); beyond
    /// the circle the same formula goes on (to the antipode at ρ = π·k).
    pub fn fisheye_direction_at(&self, x: f32, y: f32) -> (f32, f32) {
        let (dx, dy) = (x - 0.5 * self.width as f32, y - 0.5 * self.height as f32);
        let k = self.fisheye_pixels_per_radian();
        let rho = (dx * dx + dy * dy).sqrt();
        let psi = rho / k;
        let s = if rho > 0.0 { psi.sin() / rho } else { 1.0 / k };
        let [axis, front, right] = self.dome_basis();
        let d = s * dx * right + s * dy * front + psi.cos() * axis;
        (d.x.atan2(-d.z), d.y.atan2((d.x * d.x + d.z * d.z).sqrt()))
    }

    /// How far, in pixels, a drawn edge beyond the fisheye's rim may dip towards the image's
    /// centre from the circle its ends lie on (0 on the other panoramas): a chord of length c on
    /// a circle of radius R dips c²/8R. The length rule's parts are at most L long (the
    /// lattice's diagonals up to about 1.5·L); the error split (`error_split`) bounds each part's
    /// deviation from its curve by τ (4τ, for the zipper's diagonals and the second
    /// differences' sampling). The dropped cone keeps this much more margin beyond the rim
    /// ([`Projection::dome_antipode_cone`]), so that what is dropped leaves no chord inside the
    /// circle.
    fn fisheye_chord_dip_px(&self, error_split: bool, edge_px: f32, max_error_px: f32) -> f32 {
        if error_split {
            4.0 * max_error_px
        } else {
            (1.5 * edge_px).powi(2) / (8.0 * 0.5 * self.width as f32)
        }
    }

    /// The largest dip [`Projection::chord_dip_px`] a tilted dome's cone leaves room for (the
    /// cone must stay: its antipode is off the vertical axis), in pixels.
    pub fn max_chord_dip_px(&self) -> f32 {
        (180.0 - 0.5 * self.fov - 10.0).max(0.0).to_radians() * self.fisheye_pixels_per_radian()
    }

    /// The cone around the point opposite the dome's axis whose triangles the subdivision drops:
    /// beyond the field of view, and where the image folds onto a ring (ρ = π·k) around that point,
    /// whose small triangles would be drawn as chords across the whole image. Its half-angle β
    /// reaches to 10° (a margin for the eye rays' offset from the centre) plus `dip_px` (how far
    /// the drawn edges' chords may dip towards the centre, `encoding::subdivide::chord_dip_px`,
    /// in radians at k pixels per radian) beyond the field of view's edge: the edges between what
    /// is dropped and what is drawn lie in the cone, and their chords stay outside the circle. At
    /// most 90° (so that it is convex); None where it would vanish (FOV ≥ 340° with no dip: the
    /// antipode is then on the rim; with no tilt it lies on the vertical axis, which the axis
    /// cuts keep whole triangles away from).
    /// Returns cos β: a point p lies in the cone when p·A < −cos β·|p|. Convex (β < 90°): a
    /// triangle whose corners all lie in it lies in it.
    fn fisheye_antipode_cone(&self, dip_px: f32) -> Option<f32> {
        let margin = 10.0 + (dip_px / self.fisheye_pixels_per_radian()).to_degrees();
        let beta = (180.0 - 0.5 * self.fov - margin).min(90.0);
        (beta > 0.0).then(|| beta.to_radians().cos())
    }

    /// Whether image position (x, y) lies inside the fisheye's FOV circle (radius W/2).
    fn fisheye_shows_pixel(&self, x: f32, y: f32) -> bool {
        let (dx, dy) = (x - 0.5 * self.width as f32, y - 0.5 * self.height as f32);
        dx * dx + dy * dy <= 0.25 * (self.width as f32) * (self.width as f32)
    }
}

impl Panorama for Fisheye {
    fn kind(&self) -> PanoramaKind {
        PanoramaKind::Fisheye
    }

    fn wgsl_name(&self) -> &'static str {
        "PANORAMA_FISHEYE"
    }

    /// The sphere's eye model in its own image.
    fn shader_bits(&self) -> u32 {
        2 | 4
    }

    fn eye_model(&self) -> EyeModel {
        EyeModel::Sphere
    }

    fn image_map(&self) -> ImageMap {
        ImageMap::Fisheye
    }

    fn turn_share(&self) -> Option<f32> {
        None
    }

    fn player_tag(&self) -> Option<&'static str> {
        Some("fisheye")
    }

    fn default_size(&self, width: u32) -> [u32; 2] {
        [width, width]
    }

    fn takes_unmeasured_edges(&self) -> bool {
        false
    }

    fn validate(&self, p: &Projection) -> Result<()> {
        p.validate_fisheye()
    }

    fn to_pixel(&self, p: &Projection, u: f32, v: f32) -> [f32; 2] {
        p.fisheye_pixel(u, v)
    }

    fn pixel_to_screen(&self, p: &Projection, column: f32, row: f32) -> (f32, f32) {
        p.fisheye_direction_at(column + 0.5, row + 0.5)
    }

    fn pixels_per_v(&self, p: &Projection) -> f32 {
        p.fisheye_pixels_per_radian()
    }

    fn shows_pixel(&self, p: &Projection, x: f32, y: f32) -> bool {
        p.fisheye_shows_pixel(x, y)
    }

    fn chord_dip_px(&self, p: &Projection, error_split: bool, edge_px: f32, max_error_px: f32) -> f32 {
        p.fisheye_chord_dip_px(error_split, edge_px, max_error_px)
    }

    fn antipode_cone(&self, p: &Projection, dip_px: f32) -> Option<f32> {
        p.fisheye_antipode_cone(dip_px)
    }
}

#[cfg(test)]
mod tests {
    use crate::core::panoramas::projection::{Camera, Eye, Projection};
    use glam::Vec3;
    use rand::SeedableRng;

    /// An equidistant fisheye's pixel direction (as Cycles' `fisheye_to_direction`), in f64
    /// from the format's definition, for a camera looking along the dome's axis with the image's
    /// up towards the dome's back: the pixel at (u, v) from the centre (up positive, in image
    /// widths) lies r = 2·√(u² + v²)·FOV/2 from the axis, at azimuth atan2(v, u) in the image.
    fn pixel_direction(p: &Projection, x: f64, y: f64) -> [f64; 3] {
        let (u, v) = (x / p.width as f64 - 0.5, 0.5 - y / p.height as f64);
        let r = (u * u + v * v).sqrt() * 2.0;
        let theta = r * (p.fov as f64).to_radians() / 2.0;
        let phi = v.atan2(u);
        // Camera frame: x right, y image-up, z along the axis.
        let cam = [theta.sin() * phi.cos(), theta.sin() * phi.sin(), theta.cos()];
        let t = (p.dome_tilt as f64).to_radians();
        let axis = [0.0, t.cos(), t.sin()];
        let back = [0.0, -t.sin(), t.cos()]; // image up = away from the front
        (0..3)
            .map(|i| cam[0] * [1.0, 0.0, 0.0][i] + cam[1] * back[i] + cam[2] * axis[i])
            .collect::<Vec<_>>()
            .try_into()
            .unwrap()
    }

    /// The forward map against the pixel's direction built from the fisheye's definition: the
    /// pixel `project_pixel` gives a point is the one whose ray (that direction, from the eye
    /// point the sphere's model gives its longitude) passes through the point; and the inverse.
    #[test]
    fn the_fisheye_draws_each_point_where_its_pixels_ray_meets_it() {
        let mut rng = rand::rngs::StdRng::seed_from_u64(21);
        let mut compared = 0;
        for (fov, tilt) in [(180.0f32, 0.0f32), (220.0, 0.0), (180.0, 30.0), (330.0, -20.0), (360.0, 0.0)] {
            let proj = Projection { fov, dome_tilt: tilt, ..Projection::fisheye(1024) };
            proj.validate().unwrap();
            for _ in 0..1500 {
                let p = crate::core::panoramas::projection::tests::random_point(&mut rng);
                let dist = p.length();
                for eye in Eye::BOTH {
                    let Some(([x, y], depth)) = proj.project_pixel(p, eye) else { continue };
                    let rho = ((x - 512.0).powi(2) + (y - 512.0).powi(2)).sqrt();
                    if rho / proj.fisheye_pixels_per_radian() > 170f32.to_radians() {
                        continue; // near the antipode the image folds: not a place to compare
                    }
                    let d = pixel_direction(&proj, x as f64, y as f64);
                    let d = Vec3::new(d[0] as f32, d[1] as f32, d[2] as f32);
                    // The eye point of that direction (Cycles' spherical stereo), then the ray.
                    let (lon, lat) = (d.x.atan2(-d.z), d.y.atan2((d.x * d.x + d.z * d.z).sqrt()));
                    let (origin, dir) = proj.sphere_ray(lon, lat, eye);
                    assert!((dir - d).length() < 1e-4, "{fov} {tilt}: ray direction {dir} vs {d}");
                    let to_p = p - origin;
                    let miss = (to_p - to_p.dot(dir) * dir).length();
                    // A thousandth of a pixel at this distance.
                    let px = to_p.length() / proj.fisheye_pixels_per_radian();
                    assert!(miss < 2e-3 * px + 1e-6, "{fov} {tilt} {eye:?} {p}: misses by {miss} ({} px)", miss / px);
                    assert!((depth - to_p.length()).abs() < 1e-4 * depth);
                    let back = proj.unproject_pixel([x, y], depth, eye);
                    assert!((back - p).length() < 1e-3 * dist, "{p} → ({x}, {y}) → {back}");
                    compared += 1;
                }
            }
        }
        assert!(compared > 8000, "{compared}");
    }

    #[test]
    fn the_zenith_is_at_the_centre_and_straight_ahead_at_the_bottom() {
        let proj = Projection { eye_radius: 0.0, ..Projection::fisheye(1000) };
        let at = |p: Vec3| proj.project_pixel(p, Eye::Left).unwrap().0;
        let close = |a: [f32; 2], b: [f32; 2]| (a[0] - b[0]).abs() < 1e-3 && (a[1] - b[1]).abs() < 1e-3;
        assert!(close(at(Vec3::new(0.0, 5.0, -1e-6)), [500.0, 500.0]));
        assert!(close(at(Vec3::new(0.0, 0.0, -5.0)), [500.0, 1000.0]), "{:?}", at(Vec3::new(0.0, 0.0, -5.0)));
        assert!(close(at(Vec3::new(0.0, 1.0, -1.0)), [500.0, 750.0]), "45° up ahead");
        assert!(close(at(Vec3::new(5.0, 0.0, 0.0)), [1000.0, 500.0]), "the right on the right");
        assert!(close(at(Vec3::new(0.0, 0.0, 5.0)), [500.0, 0.0]), "behind at the top");
        // Tilted 30°: the front's rim shows 30° up.
        let tilted = Projection { dome_tilt: 30.0, ..proj };
        let up30 = Vec3::new(0.0, 30f32.to_radians().sin(), -30f32.to_radians().cos());
        let q = tilted.project_pixel(up30, Eye::Left).unwrap().0;
        assert!(close(q, [500.0, 1000.0]), "{q:?}");
        assert!(proj.shows_pixel(500.0, 999.0) && !proj.shows_pixel(20.0, 20.0));
    }
}
