//! Comparing a frame against a reference frame (`twister error --against`): how much of the
//! image shows a different surface, and how close the colours are.

use crate::core::frame::Frame;
use crate::error::{Error, Result};

#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Comparison {
    /// Of the pixels (both eyes) where either frame shows a surface, the fraction where the two
    /// show different objects (or one shows background).
    pub different_surface_fraction: f64,
    /// Colour PSNR over all pixels of both eyes, dB (None when the images are identical).
    pub psnr_db: Option<f64>,
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
    Ok(Comparison {
        different_surface_fraction: if covered == 0 { 0.0 } else { different as f64 / covered as f64 },
        psnr_db: (mse > 0.0).then(|| 10.0 * (255.0 * 255.0 / mse).log10()),
    })
}
