//! Comparing a frame against a reference frame (`twister error --against`): how much of the
//! image shows a different surface, and how close the colours are; against the ray tracer, where
//! the traced image shows each drawn surface point (the display-position error measured without
//! the analytic projection); and comparing flat-coloured
//! images from two renderers by where their colour boundaries lie (twister against Blender
//! Cycles: `examples/cycles_reference.rs`, `tests/cycles.rs`).

use crate::core::frame::Frame;
use crate::core::scenes::scene::Scene;
use crate::core::shading::color::linear_to_srgb;
use crate::error::{Error, Result};
use glam::Vec3;

#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Comparison {
    /// Of the pixels (both eyes) where either frame shows a surface, the fraction where the two
    /// show different objects (or one shows background).
    pub different_surface_fraction: f64,
    /// Colour PSNR over all pixels of both eyes, dB (None when the images are identical).
    pub psnr_db: Option<f64>,
    /// Where both frames measured depth: over the pixels showing the same object in both, the
    /// mean and 99th percentile of the relative difference of the distances along the pixels'
    /// rays, |d − d_ref| / d_ref (against `trace`: how far the drawn surface lies from the true
    /// hit).
    pub depth_rel_mean: Option<f64>,
    pub depth_rel_p99: Option<f64>,
    /// Where both frames measured depth: of the pixels showing the same object in both, the
    /// fraction whose distances differ by more than [`SAME_PLANE`] (relative): another triangle
    /// of that object (a different plane) is shown. The drawing stages' distance is the pixel's
    /// ray to the drawn triangle's plane, so the same triangle gives the same distance; adjacent
    /// coplanar triangles count as one surface.
    pub different_triangle_fraction: Option<f64>,
    /// Where both frames have their surface points (`Frame::positions`), the reference a traced
    /// one: [`traced_display_error`].
    pub traced_error: Option<TracedError>,
}

/// The display-position error of a frame measured against a traced frame: for each pixel p
/// showing a surface point X, the place q* in the traced image whose ray meets X, and |q* − p|
/// in pixels (x wraps). It shares no code with the analytic error (seed 002 §4.1): only the
/// traced rays say where a point belongs.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct TracedError {
    pub mean_px: f64,
    pub p99_px: f64,
    pub max_px: f64,
    /// Pixels measured (both eyes).
    pub pixels: u64,
    /// Pixels whose point the traced image does not show nearby (occluded there, or beyond the
    /// search), left out of the statistics.
    pub unmatched: u64,
}

/// The relative distance difference under which two pixels show the same plane.
pub const SAME_PLANE: f64 = 1e-4;

/// How far the traced image may be searched from a pixel for the point it shows, pixels.
pub const TRACED_SEARCH_STEPS: usize = 24;

/// [`TracedError`] of the surface points `drawn` (per eye, NaN: none) against the traced
/// points `traced` with their object ids (`drawn_object`, `traced_object`; 0: background), on
/// images `width` × `height`.
///
/// Per pixel p with point X: from p, step to the 8-neighbour (same object in the traced image)
/// whose traced point is nearest X until none is nearer (at most [`TRACED_SEARCH_STEPS`]); at
/// that pixel q, the traced points of q's horizontal and vertical neighbours give the local map
/// Y(q + δ) ≈ Y(q) + J·δ, and δ solves it for X in least squares (|δ| ≤ 1.5 per axis). X is
/// matched if it lies within one pixel footprint of Y(q) + J·δ.
pub fn traced_display_error(
    drawn: &[Vec<[f32; 3]>; 2],
    drawn_object: &[Vec<u32>; 2],
    traced: &[Vec<[f32; 3]>; 2],
    traced_object: &[Vec<u32>; 2],
    width: usize,
    height: usize,
) -> TracedError {
    let mut errors: Vec<f64> = Vec::new();
    let mut unmatched = 0u64;
    for k in 0..2 {
        let eye = TracedEye {
            pos: &drawn[k],
            obj: &drawn_object[k],
            tpos: &traced[k],
            tobj: &traced_object[k],
            width,
            height,
        };
        for i in 0..width * height {
            match eye.error_at(i) {
                Some(Some(e)) => errors.push(e),
                Some(None) => unmatched += 1,
                None => {}
            }
        }
    }
    errors.sort_by(f64::total_cmp);
    let n = errors.len();
    TracedError {
        mean_px: if n == 0 { 0.0 } else { errors.iter().sum::<f64>() / n as f64 },
        p99_px: if n == 0 { 0.0 } else { errors[((n - 1) as f64 * 0.99).round() as usize] },
        max_px: errors.last().copied().unwrap_or(0.0),
        pixels: n as u64,
        unmatched,
    }
}

/// One eye's drawn surface points and object ids, and the traced image's (see
/// [`traced_display_error`]).
struct TracedEye<'e> {
    pos: &'e [[f32; 3]],
    obj: &'e [u32],
    tpos: &'e [[f32; 3]],
    tobj: &'e [u32],
    width: usize,
    height: usize,
}

impl TracedEye<'_> {
    /// The pixel (x, y), x wrapped around the panorama; None beyond the top or bottom.
    fn at(&self, x: i64, y: i64) -> Option<usize> {
        (0..self.height as i64).contains(&y).then(|| y as usize * self.width + x.rem_euclid(self.width as i64) as usize)
    }

    /// Whether traced pixel j shows a point of object `o`.
    fn usable(&self, j: usize, o: u32) -> bool {
        self.tobj[j] == o && Vec3::from(self.tpos[j]).is_finite()
    }

    /// The 8-neighbour of (qx, qy) whose traced point of object `o` is nearest `x`, among those
    /// nearer than `bound` (squared).
    fn nearer(&self, (qx, qy): (i64, i64), bound: f32, o: u32, x: Vec3) -> Option<(i64, i64, f32)> {
        let mut best: Option<(i64, i64, f32)> = None;
        for (dx, dy) in [(-1, 0), (1, 0), (0, -1), (0, 1), (-1, -1), (1, -1), (-1, 1), (1, 1)] {
            if let Some(j) = self.at(qx + dx, qy + dy).filter(|&j| self.usable(j, o)) {
                let dist = (Vec3::from(self.tpos[j]) - x).length_squared();
                if dist < best.map_or(bound, |b| b.2) {
                    best = Some((qx + dx, qy + dy, dist));
                }
            }
        }
        best
    }

    /// The display-position error of drawn pixel i, pixels: None where it shows no surface;
    /// Some(None) where the traced image has no match for its point.
    fn error_at(&self, i: usize) -> Option<Option<f64>> {
        let (o, x) = (self.obj[i], Vec3::from(self.pos[i]));
        if o == 0 || !x.is_finite() {
            return None;
        }
        let (px, py) = ((i % self.width) as i64, (i / self.width) as i64);
        // The start: p itself, or the nearest usable pixel around it; then descend.
        let start = if self.usable(i, o) {
            Some((px, py, (Vec3::from(self.tpos[i]) - x).length_squared()))
        } else {
            self.nearer((px, py), f32::INFINITY, o, x)
        };
        let Some(mut q) = start else { return Some(None) };
        for _ in 0..TRACED_SEARCH_STEPS {
            match self.nearer((q.0, q.1), q.2, o, x) {
                Some(next) => q = next,
                None => break,
            }
        }
        let y = Vec3::from(self.tpos[self.at(q.0, q.1).expect("inside")]);
        // The local map from the neighbours (one side or the other, same object).
        let axis = |dx: i64, dy: i64| {
            [1i64, -1].into_iter().find_map(|s| {
                self.at(q.0 + s * dx, q.1 + s * dy)
                    .filter(|&j| self.usable(j, o))
                    .map(|j| (Vec3::from(self.tpos[j]) - y) * s as f32)
            })
        };
        let (Some(a), Some(b)) = (axis(1, 0), axis(0, 1)) else { return Some(None) };
        let r = x - y;
        let (aa, ab, bb) = (a.dot(a), a.dot(b), b.dot(b));
        let det = aa * bb - ab * ab;
        let (dx, dy) = if det > 1e-12 * aa * bb {
            (
                ((bb * a.dot(r) - ab * b.dot(r)) / det).clamp(-1.5, 1.5),
                ((aa * b.dot(r) - ab * a.dot(r)) / det).clamp(-1.5, 1.5),
            )
        } else {
            (0.0, 0.0)
        };
        let footprint = aa.max(bb).sqrt();
        if (y + dx * a + dy * b - x).length() > footprint {
            return Some(None);
        }
        let mut ex = (q.0 as f32 + dx - px as f32).abs();
        ex = ex.min(self.width as f32 - ex);
        let ey = q.1 as f32 + dy - py as f32;
        Some(Some((ex * ex + ey * ey).sqrt() as f64))
    }
}

/// Compares two frames rendered with the error pass (`measure.error`, for their object ids).
pub fn compare(frame: &Frame, reference: &Frame) -> Result<Comparison> {
    let (Some(m), Some(r)) = (&frame.measurement, &reference.measurement) else {
        return Err(Error::Compare("both frames must be rendered with the error pass (measure.error)".into()));
    };
    let (mut covered, mut different) = (0u64, 0u64);
    for (a, b) in m.object.iter().zip(&r.object) {
        for (x, y) in a.iter().zip(b) {
            if *x != 0 || *y != 0 {
                covered += 1;
                different += (x != y) as u64;
            }
        }
    }
    let (mut sq, mut n) = (0f64, 0u64);
    for (a, b) in [(&frame.left, &reference.left), (&frame.right, &reference.right)] {
        for (p, q) in a.rgba.chunks(4).zip(b.rgba.chunks(4)) {
            for c in 0..3 {
                let d = p[c] as f64 - q[c] as f64;
                sq += d * d;
                n += 1;
            }
        }
    }
    let mse = sq / n.max(1) as f64;
    let mut depth: Vec<f64> = Vec::new();
    if let (Some(da), Some(db)) = (&frame.depth, &reference.depth) {
        for k in 0..2 {
            for (((x, y), p), q) in m.object[k].iter().zip(&r.object[k]).zip(&da[k]).zip(&db[k]) {
                if *x != 0 && x == y && p.is_finite() && q.is_finite() && *q > 0.0 {
                    depth.push(((p - q) / q).abs() as f64);
                }
            }
        }
    }
    let different_triangle_fraction =
        (!depth.is_empty()).then(|| depth.iter().filter(|&&d| d > SAME_PLANE).count() as f64 / depth.len() as f64);
    depth.sort_by(f64::total_cmp);
    let (depth_rel_mean, depth_rel_p99) = if depth.is_empty() {
        (None, None)
    } else {
        let p99 = depth[((depth.len() - 1) as f64 * 0.99).round() as usize];
        (Some(depth.iter().sum::<f64>() / depth.len() as f64), Some(p99))
    };
    let traced_error = match (&frame.positions, &reference.positions) {
        (Some(drawn), Some(traced)) => Some(traced_display_error(
            drawn,
            &m.object,
            traced,
            &r.object,
            frame.left.width as usize,
            frame.left.height as usize,
        )),
        _ => None,
    };
    Ok(Comparison {
        different_surface_fraction: if covered == 0 { 0.0 } else { different as f64 / covered as f64 },
        psnr_db: (mse > 0.0).then(|| 10.0 * (255.0 * 255.0 / mse).log10()),
        depth_rel_mean,
        depth_rel_p99,
        different_triangle_fraction,
        traced_error,
    })
}

/// A scene's vertex colours as display (sRGB) bytes, sorted: what an unlit render (ambient 1)
/// shows of it.
pub fn display_palette(scene: &Scene) -> Vec<[u8; 3]> {
    let set: std::collections::BTreeSet<[u8; 3]> = scene
        .vertices
        .iter()
        .map(|v| [0, 1, 2].map(|c| (linear_to_srgb(v.color[c]) * 255.0 + 0.5).floor() as u8))
        .collect();
    set.into_iter().collect()
}

/// Per pixel, the palette colour it shows (within 3 levels per channel), or None: a pixel that
/// blends two colours at an edge.
pub fn palette_labels(rgb: &[[u8; 3]], palette: &[[u8; 3]]) -> Vec<Option<usize>> {
    rgb.iter().map(|p| palette.iter().position(|q| (0..3).all(|c| p[c].abs_diff(q[c]) <= 3))).collect()
}

/// How two label images (see [`palette_labels`]) of one panorama differ.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct BoundaryAgreement {
    /// Pixels labelled in both images.
    pub compared: usize,
    /// Of those, the pixels whose labels differ.
    pub differ: usize,
    /// Of those, how far the boundary moved: the smallest r (1, 2, 3, 4, or more: 5) such that
    /// the pixel has its label in one image within r pixels in the other (x wraps around).
    pub moved: [usize; 5],
    /// Up to 5 pixels whose boundary moved more than 1 pixel: (x, y, label in a, label in b).
    pub examples: Vec<(usize, usize, usize, usize)>,
}

/// Compares two label images of `width` × `height` pixels: every pixel labelled differently
/// should lie within 1 pixel of a region of its own label in the other image, i.e. the
/// boundaries between the two renders moved by at most a pixel.
pub fn boundary_agreement(a: &[Option<usize>], b: &[Option<usize>], width: usize, height: usize) -> BoundaryAgreement {
    let near = |img: &[Option<usize>], i: usize, label: usize, reach: i64| {
        let (x, y) = ((i % width) as i64, (i / width) as i64);
        (-reach..=reach).any(|dy| {
            (-reach..=reach).any(|dx| {
                let (nx, ny) = ((x + dx).rem_euclid(width as i64), y + dy);
                dx * dx + dy * dy <= reach * reach
                    && (0..height as i64).contains(&ny)
                    && img[ny as usize * width + nx as usize] == Some(label)
            })
        })
    };
    let mut out = BoundaryAgreement::default();
    for i in 0..width * height {
        let (Some(la), Some(lb)) = (a[i], b[i]) else { continue };
        out.compared += 1;
        if la == lb {
            continue;
        }
        out.differ += 1;
        let r = (1..=4i64).find(|&r| near(b, i, la, r) || near(a, i, lb, r)).unwrap_or(5) as usize;
        out.moved[r - 1] += 1;
        if r > 1 && out.examples.len() < 5 {
            out.examples.push((i % width, i / width, la, lb));
        }
    }
    out
}
