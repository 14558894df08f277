//! The `raster` stage, CPU twin of `shaders/raster.wgsl`, and the software rasterizer that the
//! CPU twins of the drawing stages share.
//!
//! `raster_vertex` projects a subdivided vertex for one eye (seed 002 eq. 1–4) exactly as the
//! vertex shader does. `rasterize` samples pixel centres with a depth test: clip-space
//! near-plane clipping, perspective-correct attributes (with the raster stage's w: 1, linear on
//! the screen, or under the error split r, see `clip_w`), depth interpolated linearly on the screen as GPUs do, and an
//! optional column scissor. Coverage on exact edges may differ from a GPU's tie-breaking rule,
//! so tests compare images with a small tolerance on edge pixels.

use glam::{Vec2, Vec3, Vec4};

use crate::core::panoramas::panorama::ImageMap;
use crate::core::panoramas::projection::{azimuth, horizontal_radius, Eye, Projection};
use crate::core::scenes::scene::unpack_tangent;
use crate::core::shading::texture::MaterialTable;
use crate::cpu::fragment::{
    background_color, pixel_distance, pixel_error, shade_surface, shows_environment, surface_color, Surface,
};
use crate::encoding::constants::{GUARD_BAND_PX, MAX_DEPTH};
use crate::encoding::types::{DrawVertex, RasterParams};

/// Clip-space position of a subdivided vertex (`vs_main` in raster.wgsl), at most
/// `GUARD_BAND_PX` beyond the image's top or bottom edge; on the sphere, beyond the centre of the
/// first or last row on the image's edge (the subdivision culls what lies wholly beyond it, and
/// the triangles drawn across it then reach the pole: no sample there sees the background).
pub fn raster_vertex(params: &RasterParams, v: &DrawVertex) -> Vec4 {
    let projection = Projection::from(&params.projection);
    let p = Vec3::from(v.position);
    let theta0 = azimuth(p);
    let theta = theta0 + std::f32::consts::TAU * ((v.theta_ref - theta0) / std::f32::consts::TAU + 0.5).floor();
    let eye = if params.eye_sign > 0.0 { Eye::Right } else { Eye::Left };
    let q = projection.project_with_azimuth(p, theta, eye);
    let clip = frame_clip(&projection, q.u, q.v, q.depth, params.projection.face as usize)
        * clip_w(&projection, p, q.depth, params.w_by_radius);
    // The node's offset for this eye and the test hook's shift, in pixels of the frame; then the
    // tile's part of it.
    let (w, h) = (projection.width as f32, projection.height as f32);
    let k = if eye == Eye::Right { 2 } else { 0 };
    let (sx, sy) = (params.shift_px[0] + v.offsets[k], params.shift_px[1] + v.offsets[k + 1]);
    let shifted = clip + Vec4::new(2.0 * sx / w, -2.0 * sy / h, 0.0, 0.0) * clip.w;
    projection.tile_clip(shifted)
}

/// What a vertex's clip position is multiplied by (`clip_w` in projection.wgsl): on the cubemap
/// `depth`, its distance along its ray from its eye point, so that each face draws as a pinhole
/// from the eye points (exact where they are the centre: `Projection::seen_from_centre`);
/// elsewhere r, its distance from the vertical axis, where the frame draws with w = r
/// (`RasterParams::w_by_radius`, the error split's azimuth spacing: `cpu::subdivide::spacing`);
/// else 1.
fn clip_w(projection: &Projection, p: Vec3, depth: f32, w_by_radius: u32) -> f32 {
    if projection.model().image_map() == ImageMap::Cubemap {
        return depth.max(crate::core::panoramas::cubemap::CUBE_MIN_DISTANCE);
    }
    if w_by_radius == 0 {
        return 1.0;
    }
    horizontal_radius(p).max(crate::encoding::constants::AZIMUTH_MIN_RADIUS)
}

/// The clip position on the whole frame of screen point (u, v) at `distance` from its eye,
/// depth r/(r + 1) (`frame_clip` in projection.wgsl; the cubemap: for the draw of face `face`,
/// its own depth, `Projection::cube_clip`).
fn frame_clip(projection: &Projection, u: f32, v: f32, distance: f32, face: usize) -> Vec4 {
    if projection.model().image_map() == ImageMap::Cubemap {
        let c = projection.cube_clip(projection.cube_ray(u, v), distance, face);
        return Vec4::new(c.x, c.y, c.z.min(MAX_DEPTH * c.w), c.w);
    }
    let depth = (distance / (distance + 1.0)).min(MAX_DEPTH);
    if projection.model().image_map() == ImageMap::Fisheye {
        let [x, y] = projection.fisheye_pixel(u, v);
        let (w, h) = (projection.width as f32, projection.height as f32);
        return Vec4::new(2.0 * x / w - 1.0, 1.0 - 2.0 * y / h, depth, 1.0);
    }
    let half_height = 0.5 * projection.height as f32;
    let y_limit = 1.0 + GUARD_BAND_PX / half_height;
    let mut y = (v * projection.pixels_per_v() / half_height).clamp(-y_limit, y_limit);
    // The sphere: beyond the centre of the first (last) row, on the image's edge (the pole).
    if projection.panorama.is_sphere() && y.abs() > 1.0 - 1.0 / projection.height as f32 {
        y = y.signum();
    }
    Vec4::new(u * projection.turn_px() / (std::f32::consts::PI * projection.width as f32), y, depth, 1.0)
}

/// A vertex ready for rasterization.
#[derive(Clone, Copy, Debug)]
pub struct ClipVertex {
    pub clip: Vec4,
    pub view_position: Vec3,
    pub normal: Vec3,
    /// glTF's tangent (viewer frame xyz, sign w), zero where none.
    pub tangent: Vec4,
    pub color: Vec4,
    pub uv: Vec2,
    pub object: u32,
    pub material: u32,
}

impl ClipVertex {
    fn lerp(a: &ClipVertex, b: &ClipVertex, t: f32) -> ClipVertex {
        ClipVertex {
            clip: a.clip + (b.clip - a.clip) * t,
            view_position: a.view_position + (b.view_position - a.view_position) * t,
            normal: a.normal + (b.normal - a.normal) * t,
            tangent: a.tangent + (b.tangent - a.tangent) * t,
            color: a.color + (b.color - a.color) * t,
            uv: a.uv + (b.uv - a.uv) * t,
            object: a.object,
            material: a.material,
        }
    }
}

/// The outputs of a drawing stage for one eye.
pub struct RasterImage {
    pub width: u32,
    pub height: u32,
    pub rgba: Vec<u8>,
    pub depth: Vec<f32>,
    /// Display-position error per pixel; −1 for background and points no eye sees.
    pub error: Vec<f32>,
    /// Object id + 1 per pixel; 0 for background.
    pub object: Vec<u32>,
    /// Distance from the pixel's eye point, metres; +∞ for background.
    pub distance: Vec<f32>,
}

impl RasterImage {
    pub fn new(width: u32, height: u32, background: [f32; 3]) -> Self {
        let bg = background.map(|c| (c.clamp(0.0, 1.0) * 255.0 + 0.5).floor() as u8);
        let n = (width * height) as usize;
        RasterImage {
            width,
            height,
            rgba: (0..n).flat_map(|_| [bg[0], bg[1], bg[2], 255]).collect(),
            depth: vec![1.0; n],
            error: vec![-1.0; n],
            object: vec![0; n],
            distance: vec![f32::INFINITY; n],
        }
    }
}

/// The interpolated inputs of a fragment.
#[derive(Clone, Copy, Debug)]
pub struct FragmentIn {
    pub view_position: Vec3,
    /// The change of `view_position` one pixel right and one down (both in the surface's plane).
    pub dp_dx: Vec3,
    pub dp_dy: Vec3,
    pub normal: Vec3,
    pub surface: Surface,
}

/// What a fragment writes: colour, display-position error, distance from its eye point.
#[derive(Clone, Copy, Debug)]
pub struct FragmentOut {
    pub rgba: [u8; 4],
    pub error: f32,
    pub distance: f32,
}

/// What a fragment writes, or None where it is discarded.
pub type FragmentFn<'a> = dyn Fn(&FragmentIn) -> Option<FragmentOut> + 'a;

/// The fragment entry point of the drawing stages (`fs_error` in fragment.wgsl; `fs_main`
/// writes the same colour): surface colour, shading, display-position error (in pixels, or in
/// arcminutes with `error_angle`), distance.
pub fn fragment(
    table: &MaterialTable,
    ambient: f32,
    projection: &Projection,
    eye: Eye,
    error_angle: bool,
    f: &FragmentIn,
) -> Option<FragmentOut> {
    let frag_xy = f.surface.frag_xy;
    if !projection.shows_pixel(frag_xy.x, frag_xy.y) {
        return None; // outside the fisheye's circle
    }
    let color = surface_color(table, &f.surface)?;
    Some(FragmentOut {
        rgba: shade_surface(
            table,
            ambient,
            projection,
            eye,
            f.view_position,
            f.normal,
            color,
            &f.surface,
            f.dp_dx,
            f.dp_dy,
        ),
        error: pixel_error(projection, eye, f.view_position, frag_xy, error_angle),
        distance: pixel_distance(projection, eye, f.view_position, f.dp_dx.cross(f.dp_dy), frag_xy),
    })
}

/// Rasterizes one triangle into `img`, within the scissor rectangle [columns start, end, rows
/// start, end).
pub fn rasterize(img: &mut RasterImage, tri: [ClipVertex; 3], scissor: [u32; 4], fragment: &FragmentFn) {
    rasterize_within(img, tri, &[NEAR_PLANE], scissor, fragment);
}

/// Rasterizes one triangle into `img` clipped against `planes` (clip space, `plane · clip ≥ 0`
/// inside), within the scissor rectangle.
pub fn rasterize_within(
    img: &mut RasterImage,
    tri: [ClipVertex; 3],
    planes: &[Vec4],
    scissor: [u32; 4],
    fragment: &FragmentFn,
) {
    for t in clipped(tri, planes) {
        rasterize_clipped(img, t, scissor, fragment);
    }
}

/// The near plane z ≥ 0 (the raster stage's triangles, z = depth·w with w > 0, cross it only
/// on the cubemap, where z is linear in the point: `Projection::cube_clip`).
pub(crate) const NEAR_PLANE: Vec4 = Vec4::new(0.0, 0.0, 1.0, 0.0);

/// A triangle clipped against the near plane z ≥ 0 in clip space: none, one or two triangles.
pub(crate) fn near_clipped(tri: [ClipVertex; 3]) -> Vec<[ClipVertex; 3]> {
    clipped(tri, &[NEAR_PLANE])
}

/// A triangle clipped against planes in clip space (`plane · clip ≥ 0` inside), as a fan of
/// triangles.
pub(crate) fn clipped(tri: [ClipVertex; 3], planes: &[Vec4]) -> Vec<[ClipVertex; 3]> {
    let mut poly: Vec<ClipVertex> = tri.to_vec();
    for plane in planes {
        let mut next = Vec::with_capacity(poly.len() + 1);
        for i in 0..poly.len() {
            let (a, b) = (&poly[i], &poly[(i + 1) % poly.len()]);
            let (da, db) = (plane.dot(a.clip), plane.dot(b.clip));
            if da >= 0.0 {
                next.push(*a);
            }
            if (da >= 0.0) != (db >= 0.0) {
                next.push(ClipVertex::lerp(a, b, da / (da - db)));
            }
        }
        poly = next;
    }
    (1..poly.len().saturating_sub(1)).map(|i| [poly[0], poly[i], poly[i + 1]]).collect()
}

/// A clipped triangle on the pixel grid: its corners in pixels, its signed area, and the
/// pixels of its bounding box within a scissor rectangle.
pub(crate) struct ScreenTriangle {
    pub tri: [ClipVertex; 3],
    s: [[f32; 2]; 3],
    area: f32,
    /// Columns and rows of its bounding box within the scissor, [start, end).
    pub columns: std::ops::Range<i64>,
    pub rows: std::ops::Range<i64>,
}

impl ScreenTriangle {
    /// The triangle on a `width` × `height` grid within `scissor` [columns start, end, rows
    /// start, end); None if it is degenerate or has a corner at or behind the eye.
    pub fn new(tri: [ClipVertex; 3], width: u32, height: u32, scissor: [u32; 4]) -> Option<ScreenTriangle> {
        if tri.iter().any(|v| !v.clip.is_finite() || v.clip.w <= 0.0) {
            return None;
        }
        let (w, h) = (width as f32, height as f32);
        let s = tri.map(|v| [(v.clip.x / v.clip.w + 1.0) * 0.5 * w, (1.0 - v.clip.y / v.clip.w) * 0.5 * h]);
        let area = (s[1][0] - s[0][0]) * (s[2][1] - s[0][1]) - (s[2][0] - s[0][0]) * (s[1][1] - s[0][1]);
        if area == 0.0 {
            return None;
        }
        let min_x = s.iter().map(|p| p[0]).fold(f32::MAX, f32::min).floor().max(scissor[0] as f32) as i64;
        let max_x = s.iter().map(|p| p[0]).fold(f32::MIN, f32::max).ceil().min(scissor[1].min(width) as f32) as i64;
        let min_y = s.iter().map(|p| p[1]).fold(f32::MAX, f32::min).floor().max(scissor[2] as f32) as i64;
        let max_y = s.iter().map(|p| p[1]).fold(f32::MIN, f32::max).ceil().min(scissor[3].min(height) as f32) as i64;
        Some(ScreenTriangle { tri, s, area, columns: min_x..max_x, rows: min_y..max_y })
    }

    /// Screen-space barycentric weights of a point.
    pub fn barycentric(&self, qx: f32, qy: f32) -> [f32; 3] {
        let s = &self.s;
        let edge = |a: [f32; 2], b: [f32; 2]| (b[0] - a[0]) * (qy - a[1]) - (b[1] - a[1]) * (qx - a[0]);
        [edge(s[1], s[2]) / self.area, edge(s[2], s[0]) / self.area, edge(s[0], s[1]) / self.area]
    }

    /// The depth at barycentrics `b` (interpolated linearly on the screen, as GPUs do), if the
    /// point is inside the triangle.
    pub fn covers(&self, b: [f32; 3]) -> Option<f32> {
        if b.iter().any(|&x| x < 0.0) {
            return None;
        }
        Some((0..3).map(|k| b[k] * self.tri[k].clip.z / self.tri[k].clip.w).sum::<f32>())
    }

    /// Perspective-correct weights from screen-space ones.
    fn perspective(&self, b: [f32; 3]) -> [f32; 3] {
        let pw = [0, 1, 2].map(|k| b[k] / self.tri[k].clip.w);
        let sum: f32 = pw.iter().sum();
        pw.map(|w| w / sum)
    }

    /// The fragment of pixel (x, y), its attributes at the pixel's centre (inside the triangle
    /// or not, as a GPU interpolates them for a pixel some of whose samples it covers), and the
    /// derivatives as the GPU takes them over its 2×2 quad of pixels: fine (the difference
    /// across the quad in this pixel's row for x, in its column for y; lavapipe's dpdx is fine
    /// too), from points outside the triangle where the quad reaches beyond it, as helper
    /// invocations do.
    pub fn fragment_input(&self, x: i64, y: i64) -> FragmentIn {
        let tri = &self.tri;
        let (px, py) = (x as f32 + 0.5, y as f32 + 0.5);
        let pw = self.perspective(self.barycentric(px, py));
        let mix3 = |f: &dyn Fn(&ClipVertex) -> Vec3| (0..3).map(|k| pw[k] * f(&tri[k])).sum::<Vec3>();
        let uv_at = |x: f32, y: f32| {
            let w = self.perspective(self.barycentric(x, y));
            (0..3).map(|k| w[k] * tri[k].uv).sum::<Vec2>()
        };
        let position_at = |x: f32, y: f32| {
            let w = self.perspective(self.barycentric(x, y));
            (0..3).map(|k| w[k] * tri[k].view_position).sum::<Vec3>()
        };
        let (qx, qy) = ((x & !1) as f32 + 0.5, (y & !1) as f32 + 0.5);
        FragmentIn {
            view_position: mix3(&|v| v.view_position),
            dp_dx: position_at(qx + 1.0, py) - position_at(qx, py),
            dp_dy: position_at(px, qy + 1.0) - position_at(px, qy),
            normal: mix3(&|v| v.normal),
            surface: Surface {
                material: tri[0].material,
                color: (0..3).map(|k| pw[k] * tri[k].color).sum::<Vec4>(),
                uv: (0..3).map(|k| pw[k] * tri[k].uv).sum::<Vec2>(),
                duv_dx: uv_at(qx + 1.0, py) - uv_at(qx, py),
                duv_dy: uv_at(px, qy + 1.0) - uv_at(px, qy),
                frag_xy: Vec2::new(px, py),
                // Counter-clockwise in normalized device coordinates (y up) is clockwise on the
                // pixel grid (y down): negative `area`.
                front_facing: self.area < 0.0,
                tangent: (0..3).map(|k| pw[k] * tri[k].tangent).sum::<Vec4>(),
            },
        }
    }
}

fn rasterize_clipped(img: &mut RasterImage, tri: [ClipVertex; 3], scissor: [u32; 4], fragment: &FragmentFn) {
    let w = img.width;
    let Some(t) = ScreenTriangle::new(tri, img.width, img.height, scissor) else { return };
    for y in t.rows.clone() {
        for x in t.columns.clone() {
            let Some(z) = t.covers(t.barycentric(x as f32 + 0.5, y as f32 + 0.5)) else { continue };
            let i = (y as u32 * w + x as u32) as usize;
            if !(z < img.depth[i]) || !(z >= 0.0) {
                continue;
            }
            let Some(out) = fragment(&t.fragment_input(x, y)) else {
                continue;
            };
            img.depth[i] = z;
            img.rgba[4 * i..4 * i + 4].copy_from_slice(&out.rgba);
            img.error[i] = out.error;
            img.distance[i] = out.distance;
            img.object[i] = tri[0].object + 1;
        }
    }
}

/// The raster stage on the CPU: both eyes (left, right) from one walk over the triangles, as
/// the GPU's multiview draw does (each vertex projected for each eye with that eye's parameters).
pub fn raster(
    params: &[RasterParams; 2],
    vertices: &[DrawVertex],
    table: &MaterialTable,
    background: [f32; 3],
) -> [RasterImage; 2] {
    let projection = Projection::from(&params[0].projection);
    // This draw's image: a tile of the frame, or the frame (its fragments at the frame's pixels).
    let [width, height] = projection.image_size();
    let origin = projection.tile_origin();
    let mut images = params.map(|_| RasterImage::new(width, height, background));
    if shows_environment(table) {
        for (img, eye) in images.iter_mut().zip(Eye::BOTH) {
            fill_background(img, table, &projection, eye);
        }
    }
    // One draw, or the cubemap's six, each face's clipped to its square (the GPU's scissor).
    let draws: Vec<(Option<usize>, Vec<Vec4>)> = if projection.model().image_map() == ImageMap::Cubemap {
        (0..6).map(|f| (Some(f), [&[NEAR_PLANE][..], &projection.cube_face_planes(f)].concat())).collect()
    } else {
        vec![(None, vec![NEAR_PLANE])]
    };
    for (face, planes) in &draws {
        let params = params.map(|p| RasterParams {
            projection: crate::encoding::types::ProjectionUniform { face: face.unwrap_or(0) as u32, ..p.projection },
            ..p
        });
        for tri in vertices.chunks_exact(3) {
            for ((eye_params, eye), img) in params.iter().zip(Eye::BOTH).zip(images.iter_mut()) {
                let cv = clip_vertices(eye_params, tri);
                let fragment = |f: &FragmentIn| {
                    let mut f = *f;
                    f.surface.frag_xy += origin;
                    fragment(table, eye_params.ambient, &projection, eye, eye_params.error_angle != 0, &f)
                };
                rasterize_within(img, cv, planes, [0, width, 0, height], &fragment);
            }
        }
    }
    images
}

/// A subdivided triangle's corners as the raster stage's vertex shader gives them for one eye.
pub(crate) fn clip_vertices(params: &RasterParams, tri: &[DrawVertex]) -> [ClipVertex; 3] {
    [0, 1, 2].map(|k| ClipVertex {
        clip: raster_vertex(params, &tri[k]),
        view_position: Vec3::from(tri[k].position),
        normal: Vec3::from(tri[k].normal),
        tangent: unpack_tangent(tri[k].tangent),
        color: Vec4::from(tri[k].color),
        uv: Vec2::from(tri[k].uv),
        object: tri[k].object,
        material: tri[k].material,
    })
}

/// Paints the environment into an image's background (the background triangle drawn first).
pub fn fill_background(img: &mut RasterImage, table: &MaterialTable, projection: &Projection, eye: Eye) {
    for y in 0..img.height {
        for x in 0..img.width {
            let at = Vec2::new(x as f32 + 0.5, y as f32 + 0.5) + projection.tile_origin();
            if !projection.shows_pixel(at.x, at.y) {
                continue; // outside the fisheye's circle: the background colour
            }
            let i = 4 * (y * img.width + x) as usize;
            let c = background_color(table, projection, eye, at);
            img.rgba[i..i + 4].copy_from_slice(&c);
        }
    }
}
