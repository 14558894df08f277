//! Comparing a frame against a reference frame (`twister error --against`): how much of the
//! image shows a different surface, and how close the colours are; and comparing flat-coloured
//! images from two renderers by where their colour boundaries lie (twister against Blender
//! Cycles: `examples/cycles_reference.rs`, `tests/cycles.rs`).

use crate::core::color::linear_to_srgb;
use crate::core::frame::Frame;
use crate::core::scene::Scene;
use crate::error::{Error, Result};

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
    depth.sort_by(f64::total_cmp);
    let (depth_rel_mean, depth_rel_p99) = if depth.is_empty() {
        (None, None)
    } else {
        let p99 = depth[((depth.len() - 1) as f64 * 0.99).round() as usize];
        (Some(depth.iter().sum::<f64>() / depth.len() as f64), Some(p99))
    };
    Ok(Comparison {
        different_surface_fraction: if covered == 0 { 0.0 } else { different as f64 / covered as f64 },
        psnr_db: (mse > 0.0).then(|| 10.0 * (255.0 * 255.0 / mse).log10()),
        depth_rel_mean,
        depth_rel_p99,
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
