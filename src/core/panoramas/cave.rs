//! CAVE walls (`--panorama cave --cave FILE.json`, seeds 000 and 001's display): each wall a
//! rectangle in the scene, and per wall and eye the off-axis perspective image a tracked head's
//! eye sees on it (`--head X,Y,Z[,YAW]`: the eyes fixed d_e either side of the head along its
//! right, as `core::panoramas::head`). The frame drawn is the head's (origin midway between the eyes, the
//! eyes at s·d_e·(1, 0, 0)); the wall is given in the display's frame (`--viewer`, `--yaw`) and
//! turned into the head's with the head ([`Head`]). For a point p, eye E, the wall's corner C
//! (lower left), its right R and up U (full width and height) and n = (R × U)/|R × U| (towards
//! the room):
//!
//! ```text
//!   t = ((C − E)·n) / ((p − E)·n)          seen where t > 0
//!   H = E + t·(p − E)                      where the line from the eye through p meets the wall
//!   x = W·(H − C)·R/|R|²,  y = H_px·(1 − (H − C)·U/|U|²),  depth |p − E|
//! ```
//!
//! A perspective: straight lines stay straight, so every projection method draws a wall exactly
//! with no subdivision, as one pinhole camera per eye (the slit stage's camera form,
//! `encoding::slits`). The WGSL twin is `shaders/shared/projection_cave.wgsl`.

use std::path::Path;

use glam::{Mat3, Vec3};

use crate::core::panoramas::panorama::{EyeModel, ImageMap, Panorama, PanoramaKind};
pub use crate::core::panoramas::projection::CaveWall;
use crate::core::panoramas::projection::{Eye, Head, Projected, Projection};
use crate::error::{Error, Result};

/// A wall of a `--cave` file: its name (the outputs' prefix), three corners in scene units and
/// its size in pixels.
#[derive(Clone, Debug, PartialEq, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct NamedWall {
    pub name: String,
    pub lower_left: [f32; 3],
    pub lower_right: [f32; 3],
    pub upper_left: [f32; 3],
    pub pixels: [u32; 2],
}

#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct CaveFile {
    walls: Vec<NamedWall>,
}

/// The most walls a `--cave` file may have, and the largest file read.
pub const MAX_WALLS: usize = 64;
const MAX_FILE_BYTES: u64 = 1 << 20;

/// The walls of a `--cave` file, checked: readable JSON of at most 1 MiB, 1 to 64 walls with
/// distinct names of letters, digits, `-` and `_`, finite corners, right and up edges that are
/// not degenerate and meet at a right angle, and sizes of 2 to `MAX_IMAGE_SIDE` pixels. Each
/// problem is one error naming the file (and the wall).
pub fn read_cave(path: &Path) -> Result<Vec<NamedWall>> {
    use std::io::Read;
    let bad = |what: String| Error::setting("cave", format!("{}: {what}", path.display()));
    let file = std::fs::File::open(path).map_err(|e| bad(format!("cannot open the CAVE file: {e}")))?;
    let mut text = String::new();
    file.take(MAX_FILE_BYTES + 1)
        .read_to_string(&mut text)
        .map_err(|e| bad(format!("cannot read the CAVE file as text: {e}")))?;
    if text.len() as u64 > MAX_FILE_BYTES {
        return Err(bad(format!("a CAVE file is at most {MAX_FILE_BYTES} bytes")));
    }
    let cave: CaveFile = serde_json::from_str(&text).map_err(|e| {
        bad(format!(
            "not a CAVE file ({e}): expected {{\"walls\": [{{\"name\", \"lower_left\", \"lower_right\", \"upper_left\", \"pixels\"}}]}}"
        ))
    })?;
    if cave.walls.is_empty() || cave.walls.len() > MAX_WALLS {
        return Err(bad(format!("a CAVE has 1 to {MAX_WALLS} walls, this file {}", cave.walls.len())));
    }
    for (k, wall) in cave.walls.iter().enumerate() {
        let named = |what: String| bad(format!("wall {:?}: {what}", wall.name));
        if wall.name.is_empty() || !wall.name.chars().all(|c| c.is_ascii_alphanumeric() || c == '-' || c == '_') {
            return Err(named("a name is letters, digits, '-' and '_' (it names the wall's files)".into()));
        }
        if cave.walls[..k].iter().any(|w| w.name == wall.name) {
            return Err(named("two walls have this name".into()));
        }
        let corners = [wall.lower_left, wall.lower_right, wall.upper_left];
        let max = crate::core::scenes::scene::MAX_COORDINATE;
        if corners.iter().flatten().any(|c| !c.is_finite() || c.abs() > max) {
            return Err(named(format!("corners must be finite coordinates within ±{max:e}")));
        }
        let [ll, lr, ul] = corners.map(Vec3::from);
        let (right, up) = (lr - ll, ul - ll);
        let scale = right.length().max(up.length());
        if right.length() <= 1e-6 * scale.max(1e-30) || up.length() <= 1e-6 * scale.max(1e-30) || scale == 0.0 {
            return Err(named("degenerate: its corners must span a rectangle of non-zero width and height".into()));
        }
        let cos = right.dot(up) / (right.length() * up.length());
        if cos.abs() > 1e-5 {
            return Err(named(format!(
                "not a rectangle: lower_right and upper_left must leave lower_left at a right angle, within 0.0006° ({:.4}°)",
                cos.clamp(-1.0, 1.0).acos().to_degrees()
            )));
        }
        let side = crate::core::panoramas::projection::MAX_IMAGE_SIDE;
        if wall.pixels.iter().any(|&p| !(2..=side).contains(&p)) {
            return Err(named(format!("pixels must be WIDTH,HEIGHT of 2 to {side} each, got {:?}", wall.pixels)));
        }
    }
    Ok(cave.walls)
}

impl NamedWall {
    /// The wall in the display's frame: scene units × `scale` = metres, the display at `viewer`
    /// (metres) facing `yaw_deg`, as `--viewer` and `--yaw` place it.
    pub fn in_display(&self, scale: f32, viewer: Vec3, yaw_deg: f32) -> CaveWall {
        let turn = Mat3::from_rotation_y(-yaw_deg.to_radians());
        let [ll, lr, ul] = [self.lower_left, self.lower_right, self.upper_left].map(|c| Vec3::from(c) * scale);
        CaveWall {
            corner: (turn * (ll - viewer)).to_array(),
            right: (turn * (lr - ll)).to_array(),
            up: (turn * (ul - ll)).to_array(),
        }
    }
}

/// The least distance from an eye to a wall's plane, metres.
pub const MIN_EYE_DISTANCE: f32 = 0.01;

impl Projection {
    /// A CAVE wall's settings: the wall and a tracked head, each eye before the wall's front.
    fn validate_cave(&self) -> Result<()> {
        let Some(wall) = &self.wall else {
            return Err(Error::setting("view.projection.wall", "the CAVE panorama draws a wall: give it one"));
        };
        if self.head.is_none() {
            return Err(Error::setting(
                "view.projection.head",
                "a CAVE wall is seen by a tracked head: give its place",
            ));
        }
        if [wall.corner, wall.right, wall.up].iter().flatten().any(|c| !c.is_finite()) {
            return Err(Error::setting("view.projection.wall", format!("must be finite, got {wall:?}")));
        }
        let [corner, right, up] = self.cave_wall();
        let n = right.cross(up);
        if !(n.length() > 0.0) {
            return Err(Error::setting("view.projection.wall", "degenerate: no width or no height"));
        }
        let n = n.normalize();
        for eye in Eye::BOTH {
            let distance = (self.head_eye(eye) - corner).dot(n);
            if distance < MIN_EYE_DISTANCE {
                return Err(Error::setting(
                    "view.projection.wall",
                    if distance <= 0.0 {
                        format!(
                            "faces away from the {} eye ({:.3} m behind its plane): seen from the room its lower \
                             right corner must lie to the right of its lower left",
                            eye.name(),
                            -distance
                        )
                    } else {
                        format!(
                            "the {} eye is {distance:.4} m from its plane, closer than {MIN_EYE_DISTANCE} m",
                            eye.name()
                        )
                    },
                ));
            }
        }
        Ok(())
    }

    /// The head of a CAVE's frame (`core::panoramas::head`), turning the display's frame into it.
    fn cave_head(&self) -> Head {
        self.head.unwrap_or(Head { offset: [0.0; 3], turn: 0.0 })
    }

    /// The wall in the head's frame (the frame drawn): [corner, right, up].
    pub fn cave_wall(&self) -> [Vec3; 3] {
        let Some(wall) = &self.wall else { return [Vec3::ZERO; 3] };
        let head = self.cave_head();
        let turn = head.rotation().transpose();
        [
            turn * (Vec3::from(wall.corner) - Vec3::from(head.offset)),
            turn * Vec3::from(wall.right),
            turn * Vec3::from(wall.up),
        ]
    }

    /// Where `eye` sees head-frame point `p` on the wall: image position (x right, y down) and
    /// the distance from the eye; None where the point lies behind the eye's plane parallel to
    /// the wall.
    pub fn cave_pixel(&self, p: Vec3, eye: Eye) -> Option<([f32; 2], f32)> {
        let [corner, right, up] = self.cave_wall();
        let n = right.cross(up).normalize();
        let e = self.head_eye(eye);
        let q = p - e;
        let along = q.dot(n);
        if !(along < 0.0) {
            return None;
        }
        let hit = e + (corner - e).dot(n) / along * q - corner;
        let a = hit.dot(right) / right.length_squared();
        let b = hit.dot(up) / up.length_squared();
        Some(([a * self.width as f32, (1.0 - b) * self.height as f32], q.length()))
    }

    /// The wall's point at image position (x, y), head frame.
    pub fn cave_point(&self, x: f32, y: f32) -> Vec3 {
        let [corner, right, up] = self.cave_wall();
        corner + x / self.width as f32 * right + (1.0 - y / self.height as f32) * up
    }

    /// Whether a head-frame point lies before both eyes' planes parallel to the wall (the
    /// `sees` of projection.wgsl, the same for both eyes: |p·n| beyond d_e).
    pub fn cave_sees(&self, p: Vec3) -> bool {
        let [_, right, up] = self.cave_wall();
        p.dot(right.cross(up).normalize()) < -self.eye_radius
    }
}

/// CAVE walls: one wall per frame.
pub struct Cave;

impl Panorama for Cave {
    fn kind(&self) -> PanoramaKind {
        PanoramaKind::Cave
    }

    fn wgsl_name(&self) -> &'static str {
        "PANORAMA_CAVE"
    }

    fn shader_bits(&self) -> u32 {
        16
    }

    fn eye_model(&self) -> EyeModel {
        EyeModel::Pinhole
    }

    fn image_map(&self) -> ImageMap {
        ImageMap::Plane
    }

    fn turn_share(&self) -> Option<f32> {
        None
    }

    fn default_size(&self, width: u32) -> [u32; 2] {
        [width, width]
    }

    fn validate(&self, p: &Projection) -> Result<()> {
        p.validate_cave()
    }

    fn sees(&self, p: &Projection, q: Vec3) -> bool {
        p.cave_sees(q)
    }

    /// Before both eyes' planes (as `sees` in projection.wgsl), then this eye's.
    fn project(&self, p: &Projection, q: Vec3, eye: Eye) -> Option<Projected> {
        let seen = (q.is_finite() && p.cave_sees(q)).then(|| p.cave_pixel(q, eye)).flatten();
        seen.map(|([x, y], depth)| Projected { u: x, v: y, depth })
    }

    fn project_with_azimuth(&self, p: &Projection, q: Vec3, _theta: f32, eye: Eye) -> Projected {
        let ([x, y], depth) = p.cave_pixel(q, eye).unwrap_or(([f32::NAN; 2], f32::NAN));
        Projected { u: x, v: y, depth }
    }

    /// The CAVE's (u, v) are its image position.
    fn to_pixel(&self, _p: &Projection, u: f32, v: f32) -> [f32; 2] {
        [u, v]
    }

    fn pixel_to_screen(&self, _p: &Projection, column: f32, row: f32) -> (f32, f32) {
        (column + 0.5, row + 0.5)
    }

    /// v is the image row itself.
    fn pixels_per_v(&self, _p: &Projection) -> f32 {
        1.0
    }

    /// The wall's point, seen from the head.
    fn screen_direction(&self, p: &Projection, u: f32, v: f32) -> Vec3 {
        p.cave_point(u, v).normalize()
    }

    /// From the eye through the wall's point: the depth is the distance from the eye.
    fn ray(&self, p: &Projection, eye: Eye, u: f32, v: f32) -> (Vec3, Vec3) {
        let origin = p.head_eye(eye);
        (origin, (p.cave_point(u, v) - origin).normalize())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::core::panoramas::projection::Camera;
    use rand::{Rng, SeedableRng};

    /// A 3 m cube's front wall and a floor, seen by a head off the centre and turned.
    pub(crate) fn walls() -> Vec<NamedWall> {
        let w = |name: &str, ll: [f32; 3], lr: [f32; 3], ul: [f32; 3], pixels: [u32; 2]| NamedWall {
            name: name.into(),
            lower_left: ll,
            lower_right: lr,
            upper_left: ul,
            pixels,
        };
        vec![
            w("front", [-1.5, 0.0, -1.5], [1.5, 0.0, -1.5], [-1.5, 3.0, -1.5], [300, 300]),
            w("left", [-1.5, 0.0, 1.5], [-1.5, 0.0, -1.5], [-1.5, 3.0, 1.5], [300, 300]),
            w("floor", [-1.5, 0.0, 1.5], [1.5, 0.0, 1.5], [-1.5, 0.0, -1.5], [300, 300]),
        ]
    }

    /// The forward map against a brute-force ray per pixel: the pixel `project_pixel` gives a
    /// point is the one whose ray (from the eye through the wall's point at the pixel, built from
    /// the wall's corners) passes through the point within 10⁻³ px; and the inverse.
    #[test]
    fn each_wall_draws_a_point_where_the_line_from_the_eye_meets_the_wall() {
        let mut rng = rand::rngs::StdRng::seed_from_u64(35);
        let (viewer, yaw, head_at, head_yaw) = (Vec3::new(0.0, 1.6, 0.0), 10.0, Vec3::new(0.3, 1.7, 0.4), 35.0);
        let mut compared = 0;
        for named in walls() {
            let wall = named.in_display(1.0, viewer, yaw);
            let head = Head::relative(head_at, head_yaw, viewer, yaw);
            let proj = Projection {
                panorama: Cave.kind(),
                width: named.pixels[0],
                height: named.pixels[1],
                wall: Some(wall),
                head: Some(head),
                vertical: crate::core::panoramas::projection::Vertical::Exact,
                ..Projection::default()
            };
            proj.validate().unwrap();
            // Scene → head frame, as `RenderSettings::view` composes it.
            let to_head = head.to_head()
                * glam::Mat4::from_rotation_y(-f32::to_radians(yaw))
                * glam::Mat4::from_translation(-viewer);
            let [ll, lr, ul] = [named.lower_left, named.lower_right, named.upper_left].map(Vec3::from);
            for _ in 0..1500 {
                let p =
                    Vec3::new(rng.random_range(-8.0..8.0), rng.random_range(-3.0..6.0), rng.random_range(-8.0..8.0));
                let ph = to_head.transform_point3(p);
                for eye in Eye::BOTH {
                    let Some(([x, y], depth)) = proj.project_pixel(ph, eye) else { continue };
                    // Far beyond the wall's image (a ray grazing its plane) f32 resolves x, y
                    // only to ~10⁻⁷ of their size: compared on and around the image.
                    let (w, h) = (named.pixels[0] as f32, named.pixels[1] as f32);
                    if !((-w..2.0 * w).contains(&x) && (-h..2.0 * h).contains(&y)) {
                        continue;
                    }
                    // The eye in the scene, and the wall's point at (x, y) from its corners.
                    let eye_at = to_head.inverse().transform_point3(proj.head_eye(eye));
                    let at =
                        ll + x / named.pixels[0] as f32 * (lr - ll) + (1.0 - y / named.pixels[1] as f32) * (ul - ll);
                    let dir = (at - eye_at).normalize();
                    let to_p = p - eye_at;
                    assert!(to_p.dot(dir) > 0.0, "the point lies ahead along the pixel's ray");
                    let miss = (to_p - to_p.dot(dir) * dir).length();
                    // A pixel at the point's distance: the wall's pixel scaled by distance ratio.
                    let px = (lr - ll).length() / named.pixels[0] as f32 * to_p.length() / (at - eye_at).length();
                    assert!(miss < 1e-3 * px + 1e-6, "{} {eye:?} {p}: misses by {} px", named.name, miss / px);
                    assert!((depth - to_p.length()).abs() < 1e-4 * depth);
                    let back = proj.unproject_pixel([x, y], depth, eye);
                    assert!((back - ph).length() < 1e-3 * depth.max(1.0), "{ph} → ({x}, {y}) → {back}");
                    compared += 1;
                }
            }
        }
        assert!(compared > 2000, "{compared}");
    }

    #[test]
    fn hostile_cave_files_are_one_error_naming_the_file_and_wall() {
        let dir = std::env::temp_dir().join(format!("twister-cave-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let file = dir.join("cave.json");
        let wall = r#"{"name": "front", "lower_left": [0,0,-1], "lower_right": [1,0,-1], "upper_left": [0,1,-1], "pixels": [64, 64]}"#;
        let cases = [
            ("", "not a CAVE file"),
            ("{\"walls\": [", "not a CAVE file"),
            ("{\"walls\": []}", "1 to 64 walls"),
            (&*format!("{{\"walls\": [{wall}, {wall}]}}"), "two walls have this name"),
            (wall, "not a CAVE file"),
            (&*format!("{{\"walls\": [{}]}}", wall.replace("front", "../x")), "a name is letters"),
            (&*format!("{{\"walls\": [{}]}}", wall.replace("[1,0,-1]", "[0,0,-1]")), "degenerate"),
            (&*format!("{{\"walls\": [{}]}}", wall.replace("[0,1,-1]", "[0.5,1,-1]")), "not a rectangle"),
            (&*format!("{{\"walls\": [{}]}}", wall.replace("[64, 64]", "[64, 0]")), "pixels must be"),
            (&*format!("{{\"walls\": [{}]}}", wall.replace("[64, 64]", "[64, 99999999999]")), "not a CAVE file"),
            (&*format!("{{\"walls\": [{}]}}", wall.replace("[0,0,-1]", "[0,0,1e39]")), "corners must be finite"),
            (&*format!("{{\"walls\": [{}], \"floors\": 1}}", wall), "unknown field"),
            (&*" ".repeat(2 << 20), "at most"),
        ];
        for (text, needle) in cases {
            std::fs::write(&file, text).unwrap();
            let e = read_cave(&file).unwrap_err().to_string();
            assert!(e.contains("cave.json") && e.contains(needle), "{text:.80}: {e}");
        }
        let e = read_cave(&dir.join("none.json")).unwrap_err().to_string();
        assert!(e.contains("none.json") && e.contains("cannot open"), "{e}");
        std::fs::write(&file, format!("{{\"walls\": [{wall}]}}")).unwrap();
        assert_eq!(read_cave(&file).unwrap().len(), 1);
        let _ = std::fs::remove_dir_all(&dir);
    }

    /// A wall whose front faces away from the eyes, or with an eye on its plane, is refused.
    #[test]
    fn a_wall_facing_away_or_touching_an_eye_is_refused() {
        let front = &walls()[0];
        let cave = |head_at: Vec3, wall: CaveWall| Projection {
            panorama: Cave.kind(),
            wall: Some(wall),
            head: Some(Head::relative(head_at, 0.0, Vec3::ZERO, 0.0)),
            ..Projection::default()
        };
        let wall = front.in_display(1.0, Vec3::ZERO, 0.0);
        cave(Vec3::new(0.0, 1.6, 0.0), wall).validate().unwrap();
        let behind = cave(Vec3::new(0.0, 1.6, -2.0), wall).validate().unwrap_err().to_string();
        assert!(behind.contains("faces away"), "{behind}");
        let mirrored = CaveWall { right: (-Vec3::from(wall.right)).to_array(), ..wall };
        let e = cave(Vec3::new(0.0, 1.6, 0.0), mirrored).validate().unwrap_err().to_string();
        assert!(e.contains("faces away"), "{e}");
        let touching = cave(Vec3::new(0.0, 1.6, -1.495), wall).validate().unwrap_err().to_string();
        assert!(touching.contains("closer than"), "{touching}");
    }
}
