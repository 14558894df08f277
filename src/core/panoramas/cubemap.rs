//! The stereo cubemap (`--panorama cubemap`): the full sphere's eye rays (`core::panoramas::sphere`, the
//! same ODS eye model: a point is first projected to the longitude λ and latitude φ of the eye
//! ray that reaches it, from that eye's point on the eye circle) drawn on the six faces of a cube,
//! each face a 90° gnomonic image of those rays' directions:
//!
//! ```text
//!   D = (cos φ sin λ, sin φ, −cos φ cos λ)      the ray's direction
//!   face f: normal n, right r, up u             (the table below)
//!   x = col·F + (1 + D·r / D·n)·F/2             F = W/3, the face's side in pixels
//!   y = row·F + (1 − D·u / D·n)·F/2
//! ```
//!
//! One eye's image is the 3×2 grid of YouTube's cubemap layout (Spherical Video V2, `cbmp`
//! layout 0): right, left, up in the top row, down, front, back in the bottom row; the right,
//! left, front and back faces upright, the up face's top towards the front (−z), the down face's
//! top towards the back (+z). Each face is the image a camera at the centre looking along its
//! normal would take, not mirrored: r = n × u.
//!
//! Exact ODS: every pixel shows the ray of its own direction from its eye's point, so the edges
//! of the scene are curved on a face wherever the eyes' offset matters (near things), and the
//! adaptive subdivision splits them; what a triangle covers beyond a face's edge is drawn on the
//! neighbouring face (the raster stage draws the subdivided triangles once per face, clipped to
//! it). Each face draws as a pinhole from the eye points (the clip position scaled by the
//! distance along the ray: `clip_w` in cpu/raster.rs), exact where the rays come from the
//! centre. The subdivision splits an edge for how far its eye point turns away from the chord
//! between its nodes' (`pinhole_profile` in cpu/subdivide/edges.rs), in pixels of the sphere at
//! the faces' resolution ([`Projection::measured`]).
//!
//! The WGSL twin is `shaders/shared/projection_cubemap.wgsl`.

use glam::{Vec3, Vec4};

use crate::core::panoramas::equirect::Equirect;
use crate::core::panoramas::panorama::{EyeModel, EyePacking, ImageMap, Panorama, PanoramaKind};
use crate::core::panoramas::projection::Projection;
use crate::error::{Error, Result};

/// One face of the cube: its name, where it sits in an eye's 3×2 grid, and its camera's axes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CubeFace {
    pub name: &'static str,
    /// Column and row in the grid.
    pub cell: [u32; 2],
    /// The direction its centre shows, its image's right and its image's up.
    pub normal: Vec3,
    pub right: Vec3,
    pub up: Vec3,
}

const fn face(name: &'static str, cell: [u32; 2], normal: Vec3, right: Vec3, up: Vec3) -> CubeFace {
    CubeFace { name, cell, normal, right, up }
}

/// The six faces in the grid's order (row by row): right, left, up / down, front, back.
pub const CUBE_FACES: [CubeFace; 6] = [
    face("right", [0, 0], Vec3::X, Vec3::Z, Vec3::Y),
    face("left", [1, 0], Vec3::NEG_X, Vec3::NEG_Z, Vec3::Y),
    face("up", [2, 0], Vec3::Y, Vec3::NEG_X, Vec3::NEG_Z),
    face("down", [0, 1], Vec3::NEG_Y, Vec3::NEG_X, Vec3::Z),
    face("front", [1, 1], Vec3::NEG_Z, Vec3::X, Vec3::Y),
    face("back", [2, 1], Vec3::Z, Vec3::NEG_X, Vec3::Y),
];

pub use crate::core::panoramas::sphere::direction;

impl Projection {
    /// The direction a vertex seen at (`lon`, `lat`) is drawn in on the cubemap: within half a
    /// pixel of a pole (1/F radians, F the face's side), the pole itself, so that every vertex
    /// there is one point on the up or down face: the nodes around the axis (the square the cuts
    /// remove, whose images ring the pole at longitudes that differ from triangle to triangle)
    /// meet, and a pixel centred on the pole (an odd F) is covered. As the sphere puts what lies
    /// beyond its first row's centre on the image's edge. `cube_ray` in projection_cubemap.wgsl.
    pub fn cube_ray(&self, lon: f32, lat: f32) -> Vec3 {
        if lat.abs() > std::f32::consts::FRAC_PI_2 - 3.0 / self.width as f32 {
            return Vec3::new(0.0, lat.signum(), 0.0);
        }
        direction(lon, lat)
    }
}

/// The face a direction falls on: the one whose normal it is closest to (ties to the earlier
/// face). `cube_face_of` in projection_cubemap.wgsl.
pub fn cube_face_of(d: Vec3) -> usize {
    // The shadow cubes' order (+x, −x, +y, −y, +z, −z) with the front (−z) before the back.
    match crate::core::shading::shadow::major_axis_face(d) {
        4 => 5,
        5 => 4,
        k => k as usize,
    }
}

/// The smallest |w| a vertex of a face's draw keeps: a direction on (or within this of) the
/// face's horizon plane, D·n = 0, is drawn at w = `CUBE_MIN_W`: in the same direction on the face,
/// 10⁴ face widths out. The cuts around the axis put nodes exactly on the planes x = 0 and
/// z = 0, the side faces' horizons; an H200 drew no triangle with such a vertex (w = z = −0: the
/// floor beyond a wall's foot, a quarter of a face, showed the background under `vertex`), where
/// lavapipe clipped it. Moved there, each edge to it still leaves in its direction, and the
/// triangle's image within the face moves by under 10⁻⁴ of a face.
pub const CUBE_MIN_W: f32 = 1e-5;

/// The smallest distance along its ray a vertex's clip position is scaled by (`clip_w` in
/// cpu/raster.rs): a face draws as a pinhole, w = D·n times that distance.
pub const CUBE_MIN_DISTANCE: f32 = 1e-6;

/// The near plane of a face's draw, as a fraction of R_T: clip z = w − ν with ν =
/// `CUBE_NEAR`·R_T (a few millimetres at the usual R_T), so that z = 0 is the plane w = ν, linear
/// in the point like w itself. The rasterizer's clipping at z = 0 then cuts an edge that crosses
/// the face's horizon plane where its w is ν, in front of the face: the depth r/(r + 1) that the
/// other panoramas use is not linear, and clipped an edge from a point in front of the face to
/// one behind it where w had already turned negative (a wall across the eyes' height, drawn on
/// the down face, left holes at the face's edges). Depth after the divide, 1 − ν/w, orders
/// points along a pixel's ray as their distance does.
pub const CUBE_NEAR: f32 = 5e-3;

/// A face's w for D·n (`cube_clip`; `horizon_w` in projection_cubemap.wgsl).
fn horizon_w(w: f32) -> f32 {
    if w.abs() < CUBE_MIN_W {
        CUBE_MIN_W
    } else {
        w
    }
}

impl Projection {
    /// The stereo cubemap: one eye's 3×2 grid of faces `width`/3 pixels square, parallel rays,
    /// Blender's pole merge.
    pub fn cubemap(width: u32) -> Projection {
        Projection::of(Cubemap.kind(), width)
    }

    /// The cubemap's grid: a width of three faces and a height of two.
    fn validate_cubemap(&self) -> Result<()> {
        if self.width % 3 != 0 || 3 * self.height != 2 * self.width {
            return Err(Error::setting(
                "view.projection.width/height",
                format!(
                    "a cubemap is a 3x2 grid of square faces: the width a multiple of 3 and the height 2/3 of it \
                     (e.g. 1536x1024), got {}x{}",
                    self.width, self.height
                ),
            ));
        }
        Ok(())
    }

    /// F: a face's side in pixels, W / 3.
    pub fn cube_face_px(&self) -> f32 {
        self.width as f32 / 3.0
    }

    /// The image position of direction `d` on face `f`, beyond the face's edges where `d` lies
    /// outside it; None where `d` points away from the face (D·n ≤ 0).
    pub fn cube_pixel_on_face(&self, d: Vec3, f: usize) -> Option<[f32; 2]> {
        let face = &CUBE_FACES[f];
        let w = d.dot(face.normal);
        if w <= 0.0 {
            return None;
        }
        let s = self.cube_face_px();
        let [col, row] = face.cell.map(|c| c as f32);
        Some([s * (col + 0.5 * (1.0 + d.dot(face.right) / w)), s * (row + 0.5 * (1.0 - d.dot(face.up) / w))])
    }

    /// The image position (x right, y down, pixel centres at +0.5) of the ray of longitude
    /// `lon`, latitude `lat`: on the face it falls on.
    pub fn cube_pixel(&self, lon: f32, lat: f32) -> [f32; 2] {
        let d = direction(lon, lat);
        self.cube_pixel_on_face(d, cube_face_of(d)).unwrap_or([f32::NAN; 2])
    }

    /// The face whose square holds image position (x, y) (the nearest face for a position
    /// outside the grid).
    pub fn cube_face_at(&self, x: f32, y: f32) -> usize {
        let s = self.cube_face_px();
        let col = (x / s).floor().clamp(0.0, 2.0) as usize;
        let row = (y / s).floor().clamp(0.0, 1.0) as usize;
        3 * row + col
    }

    /// The unit direction the cubemap shows at image position (x, y) (beyond a face's edge, the
    /// same face's plane goes on).
    pub fn cube_direction_at(&self, x: f32, y: f32) -> Vec3 {
        let face = &CUBE_FACES[self.cube_face_at(x, y)];
        let s = self.cube_face_px();
        let [col, row] = face.cell.map(|c| c as f32);
        let a = 2.0 * (x / s - col) - 1.0;
        let b = 1.0 - 2.0 * (y / s - row);
        (face.normal + a * face.right + b * face.up).normalize()
    }

    /// The clip-space position on the whole grid of direction `d` (unit length) of a point at
    /// `distance` along it from its eye for the draw of face `f`, before the raster stage scales
    /// it by that distance (a pinhole, `clip_w`): w = D·n, so that the rasterizer's perspective
    /// divide is the face's gnomonic map and its clipping keeps what lies in front of the face;
    /// the draw's scissor (the face's square) keeps the face. Linear in D: the great circle
    /// between two directions is the straight line between their images on every face. A
    /// direction on the face's horizon plane is moved just in front of it (`horizon_w`); z is
    /// w − ν/distance (after the scaling w·distance − ν, see [`CUBE_NEAR`]; the raster stage
    /// keeps it at most `MAX_DEPTH`·w).
    pub fn cube_clip(&self, d: Vec3, distance: f32, f: usize) -> Vec4 {
        let face = &CUBE_FACES[f];
        let w = horizon_w(d.dot(face.normal));
        let near = CUBE_NEAR * self.screen_radius / distance.max(CUBE_MIN_DISTANCE);
        let [col, row] = face.cell.map(|c| c as f32);
        // Pixel x = F·(col + (1 + X/w)/2) over a width of 3F; pixel y = F·(row + (1 − Y/w)/2)
        // over a height of 2F; NDC x = 2x/W − 1, NDC y = 1 − 2y/H.
        Vec4::new(
            ((2.0 * col + 1.0) / 3.0 - 1.0) * w + d.dot(face.right) / 3.0,
            (0.5 - row) * w + 0.5 * d.dot(face.up),
            w - near,
            w,
        )
    }

    /// The planes (in this draw's clip space, `plane · clip ≥ 0` inside) of face `f`'s square
    /// on the grid: what the GPU's scissor keeps of a draw of that face, for the CPU twin's
    /// clipping (a tile's draw: the square in the tile's NDC).
    pub fn cube_face_planes(&self, f: usize) -> [Vec4; 4] {
        let [x0, y0, s] = self.cube_face_rect(f).map(|v| v as f32);
        let (o, [w, h]) = (self.tile_origin(), self.image_size().map(|v| v as f32));
        let ndc_x = |px: f32| 2.0 * (px - o.x) / w - 1.0;
        let ndc_y = |py: f32| 1.0 - 2.0 * (py - o.y) / h;
        let (left, right, bottom, top) = (ndc_x(x0), ndc_x(x0 + s), ndc_y(y0 + s), ndc_y(y0));
        [
            Vec4::new(1.0, 0.0, 0.0, -left),
            Vec4::new(-1.0, 0.0, 0.0, right),
            Vec4::new(0.0, 1.0, 0.0, -bottom),
            Vec4::new(0.0, -1.0, 0.0, top),
        ]
    }

    /// Face `f`'s square within this draw's image (a tile's, or the frame's): [x, y, width,
    /// height] in the image's pixels, None where the tile holds none of it (the draw's scissor).
    pub fn cube_face_scissor(&self, f: usize) -> Option<[u32; 4]> {
        let [x0, y0, s] = self.cube_face_rect(f);
        let [tx, ty, tw, th] = self.tile.unwrap_or([0, 0, self.width, self.height]);
        let (left, top) = (x0.max(tx), y0.max(ty));
        let (right, bottom) = ((x0 + s).min(tx + tw), (y0 + s).min(ty + th));
        (left < right && top < bottom).then(|| [left - tx, top - ty, right - left, bottom - top])
    }

    /// Face `f`'s square on the grid: [x, y, side] in pixels (the draw's scissor).
    pub fn cube_face_rect(&self, f: usize) -> [u32; 3] {
        let s = self.width / 3;
        let [col, row] = CUBE_FACES[f].cell;
        [col * s, row * s, s]
    }
}

/// The stereo cubemap.
pub struct Cubemap;

impl Panorama for Cubemap {
    fn kind(&self) -> PanoramaKind {
        PanoramaKind::Cubemap
    }

    fn wgsl_name(&self) -> &'static str {
        "PANORAMA_CUBEMAP"
    }

    /// The sphere's eye model in its own image.
    fn shader_bits(&self) -> u32 {
        2 | 8
    }

    fn eye_model(&self) -> EyeModel {
        EyeModel::Sphere
    }

    fn image_map(&self) -> ImageMap {
        ImageMap::Cubemap
    }

    fn turn_share(&self) -> Option<f32> {
        None
    }

    fn player_tag(&self) -> Option<&'static str> {
        Some("cubemap")
    }

    fn eye_packing(&self) -> EyePacking {
        EyePacking::TopBottom
    }

    fn default_size(&self, width: u32) -> [u32; 2] {
        [width, 2 * width / 3]
    }

    fn validate(&self, p: &Projection) -> Result<()> {
        p.validate_cubemap()
    }

    fn to_pixel(&self, p: &Projection, u: f32, v: f32) -> [f32; 2] {
        p.cube_pixel(u, v)
    }

    fn pixel_to_screen(&self, p: &Projection, column: f32, row: f32) -> (f32, f32) {
        let d = p.cube_direction_at(column + 0.5, row + 0.5);
        (d.x.atan2(-d.z), d.y.atan2((d.x * d.x + d.z * d.z).sqrt()))
    }

    /// A face's centre: F/2 pixels per radian (its least).
    fn pixels_per_v(&self, p: &Projection) -> f32 {
        0.5 * p.cube_face_px()
    }

    /// The equirectangular image the subdivision measures a cubemap's edges on: the sphere with
    /// the faces' angular resolution at their centres (a turn of 4F pixels), the same eye model.
    /// A face magnifies its edges up to twice that (sec²45° at the middle of its sides), where
    /// `--edge-px` is then met within a factor of two.
    fn measured(&self, p: &Projection) -> Projection {
        let f = p.width / 3;
        Projection { panorama: Equirect.kind(), width: 4 * f, height: 2 * f, tile: None, ..*p }
    }

    fn tile_face(&self, p: &Projection) -> u32 {
        p.width / 3
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::core::panoramas::projection::{Camera, Eye};
    use glam::Vec2;
    use rand::{Rng, SeedableRng};

    /// A face pixel's direction from the layout's definition (Spherical Video V2's `cbmp` layout
    /// 0, written out here without the face table): the centre of each cell, its right and up.
    fn layout_direction(cell: [u32; 2], a: f64, b: f64) -> [f64; 3] {
        // (centre, image right, image up) per cell, from the layout's words.
        let (n, r, u): ([f64; 3], [f64; 3], [f64; 3]) = match cell {
            [0, 0] => ([1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, 1.0, 0.0]), // right: its right is behind
            [1, 0] => ([-1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]), // left: its right ahead
            [2, 0] => ([0.0, 1.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 0.0, -1.0]), // up: its top forwards
            [0, 1] => ([0.0, -1.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 0.0, 1.0]), // down: its top back
            [1, 1] => ([0.0, 0.0, -1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]), // front
            _ => ([0.0, 0.0, 1.0], [-1.0, 0.0, 0.0], [0.0, 1.0, 0.0]),     // back
        };
        let d: Vec<f64> = (0..3).map(|i| n[i] + a * r[i] + b * u[i]).collect();
        let l = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
        [d[0] / l, d[1] / l, d[2] / l]
    }

    /// The forward map against each pixel's ray built from the layout's definition: the pixel
    /// `project_pixel` gives a point has the ray (that direction, from the eye point the sphere's
    /// model gives it) that passes through the point, within 10⁻³ px; and the inverse.
    #[test]
    fn the_cubemap_draws_each_point_where_its_pixels_ray_meets_it() {
        let mut rng = rand::rngs::StdRng::seed_from_u64(34);
        let proj = Projection::cubemap(3 * 512);
        proj.validate().unwrap();
        let s = proj.cube_face_px() as f64;
        let mut faces = [0; 6];
        for _ in 0..3000 {
            let p = crate::core::panoramas::projection::tests::random_point(&mut rng);
            let dist = p.length();
            for eye in Eye::BOTH {
                let Some(([x, y], depth)) = proj.project_pixel(p, eye) else { continue };
                assert!((0.0..=proj.width as f32).contains(&x) && (0.0..=proj.height as f32).contains(&y));
                let cell = [(x as f64 / s).floor().min(2.0) as u32, (y as f64 / s).floor().min(1.0) as u32];
                faces[(3 * cell[1] + cell[0]) as usize] += 1;
                let (fa, fb) =
                    (2.0 * (x as f64 / s - cell[0] as f64) - 1.0, 1.0 - 2.0 * (y as f64 / s - cell[1] as f64));
                let d = layout_direction(cell, fa, fb);
                let d = Vec3::new(d[0] as f32, d[1] as f32, d[2] as f32);
                let (lon, lat) = (d.x.atan2(-d.z), d.y.atan2((d.x * d.x + d.z * d.z).sqrt()));
                let (origin, dir) = proj.sphere_ray(lon, lat, eye);
                let to_p = p - origin;
                let miss = (to_p - to_p.dot(dir) * dir).length();
                // A thousandth of a pixel at this distance (a pixel spans at most 2/F radians).
                let px = to_p.length() * 2.0 / s as f32;
                assert!(miss < 1e-3 * px + 1e-6, "{eye:?} {p}: misses by {} px", miss / px);
                assert!((depth - to_p.length()).abs() < 1e-4 * depth);
                let back = proj.unproject_pixel([x, y], depth, eye);
                assert!((back - p).length() < 1e-3 * dist, "{p} → ({x}, {y}) → {back}");
            }
        }
        assert!(faces.iter().all(|&n| n > 300), "every face compared: {faces:?}");
    }

    /// A direction on a face's horizon plane (D·n = 0: the cuts around the axis put nodes on
    /// x = 0 and z = 0) is drawn with w > 0 (no rasterizer's clipping meets a vertex at w = 0)
    /// behind the near plane (z < 0), out on the face in the direction a point just in front of
    /// the plane lies: an edge to it leaves a vertex inside the face the same way.
    #[test]
    fn a_direction_on_a_faces_horizon_is_drawn_in_front_of_it_in_its_direction() {
        let proj = Projection::cubemap(300);
        let offset = |c: Vec4, f: usize| {
            let face = &CUBE_FACES[f];
            let centre = proj.cube_clip(face.normal, 0.5, f);
            (Vec2::new(c.x, c.y) / c.w - Vec2::new(centre.x, centre.y) / centre.w).normalize()
        };
        for (f, face) in CUBE_FACES.iter().enumerate() {
            let n = face.normal;
            for d in [Vec3::new(0.0, -1.7, -9.5e-6), Vec3::new(0.3, -1.0, 0.0), Vec3::new(0.0, 0.2, -1.0), Vec3::X] {
                let on_plane = d - d.dot(n) * n;
                if on_plane.length() < 1e-3 {
                    continue;
                }
                let c = proj.cube_clip(on_plane, 0.5, f);
                assert!(c.w >= CUBE_MIN_W && c.z < 0.0, "face {f}, {on_plane}: {c}");
                let in_front = proj.cube_clip(on_plane + 1e-3 * on_plane.length() * n, 0.5, f);
                assert!(offset(c, f).dot(offset(in_front, f)) > 1.0 - 1e-6, "face {f}, {on_plane}: {c} vs {in_front}");
            }
        }
    }

    /// An edge from a point in front of a face to one behind it (a wall across the eyes'
    /// height, drawn on the down face) is clipped where the rasterizer clips it (z = 0, the
    /// raster stage's clip position scaled by the distance) at a point of the 3-D edge in front
    /// of the face, drawn where that point belongs: z is linear in the point. (With the depth
    /// r/(r + 1) as z, the clip fell where w had turned negative, and the face showed holes.)
    #[test]
    fn an_edge_across_a_faces_horizon_is_clipped_in_front_of_the_face_where_it_belongs() {
        let proj = Projection { eye_radius: 0.0, ..Projection::cubemap(300) };
        let near = CUBE_NEAR * proj.screen_radius;
        let clip = |p: Vec3, f: usize| proj.cube_clip(p.normalize(), p.length(), f) * p.length();
        let mut rng = rand::rngs::StdRng::seed_from_u64(7);
        let mut checked = 0;
        for _ in 0..2000 {
            let mut point =
                || Vec3::new(rng.random_range(-5.0..5.0), rng.random_range(-5.0..5.0), rng.random_range(-5.0..5.0));
            let (a, b) = (point(), point());
            for f in 0..6 {
                let (ca, cb) = (clip(a, f), clip(b, f));
                if !(ca.z > 0.0 && cb.z < 0.0 && cb.w < 0.0) {
                    continue;
                }
                let t = ca.z / (ca.z - cb.z);
                let c = ca + (cb - ca) * t;
                assert!((c.w - near).abs() < 1e-3 * near, "face {f}, {a} → {b}: clipped at w = {}", c.w);
                let p = a + (b - a) * t;
                let want = proj.cube_clip(p.normalize(), p.length(), f);
                let (got, want) = (Vec2::new(c.x, c.y) / c.w, Vec2::new(want.x, want.y) / want.w);
                assert!((got - want).length() < 1e-3 * (1.0 + want.length()), "face {f}, {a} → {b}: {got} vs {want}");
                checked += 1;
            }
        }
        assert!(checked > 500, "{checked} edges across a horizon");
    }

    /// The clip positions of the face draws are the face's map after the divide, and points
    /// beyond a face's edge continue its plane (so the scissor cuts a triangle at the edge where
    /// the neighbour's draw starts it).
    #[test]
    fn the_face_draws_divide_to_the_faces_map_and_meet_at_the_edges() {
        let proj = Projection::cubemap(300);
        let (w, h) = (proj.width as f32, proj.height as f32);
        let mut rng = rand::rngs::StdRng::seed_from_u64(5);
        for _ in 0..500 {
            let d = Vec3::new(rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0));
            for f in 0..6 {
                let c = proj.cube_clip(d, 0.5, f);
                match proj.cube_pixel_on_face(d, f) {
                    Some([x, y]) => {
                        let got = [(c.x / c.w + 1.0) * 0.5 * w, (1.0 - c.y / c.w) * 0.5 * h];
                        // Relative to the distance from the face's centre (f32 near D·n = 0).
                        let tol = 1e-5 * (1.0 + x.abs() + y.abs());
                        assert!((got[0] - x).abs() < tol && (got[1] - y).abs() < tol, "{d} face {f}");
                        let inside = proj.cube_face_planes(f).iter().all(|p| p.dot(c) >= 0.0);
                        let [x0, y0, s] = proj.cube_face_rect(f).map(|v| v as f32);
                        let in_rect = (x0..=x0 + s).contains(&x) && (y0..=y0 + s).contains(&y);
                        assert_eq!(inside, in_rect, "{d} face {f}: ({x}, {y})");
                        if in_rect && cube_face_of(d) == f {
                            assert_eq!(proj.cube_face_at(x, y), f);
                            assert!((proj.cube_direction_at(x, y) - d.normalize()).length() < 1e-5);
                        }
                    }
                    None => assert!(c.w <= 0.0),
                }
            }
        }
        // The middle of the front face's top edge is the middle of the up face's bottom edge
        // turned: 45° up straight ahead.
        let up45 = Vec3::new(0.0, 1.0, -1.0);
        let front = proj.cube_pixel_on_face(up45, 4).unwrap();
        let up = proj.cube_pixel_on_face(up45, 2).unwrap();
        assert!((front[0] - 150.0).abs() < 1e-4 && (front[1] - 100.0).abs() < 1e-4, "{front:?}");
        assert!((up[0] - 250.0).abs() < 1e-4 && up[1].abs() < 1e-4, "the up face's top is forwards: {up:?}");
    }

    #[test]
    fn a_grid_that_is_not_three_by_two_squares_is_refused() {
        for (w, h) in [(400, 266), (300, 300), (301, 200)] {
            let e = Projection { width: w, height: h, ..Projection::cubemap(300) }.validate().unwrap_err().to_string();
            assert!(e.contains("3x2 grid") && e.contains(&format!("{w}x{h}")), "{e}");
        }
        Projection::cubemap(300).validate().unwrap();
    }
}
