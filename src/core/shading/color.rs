//! sRGB transfer functions (IEC 61966-2-1): colours are given and stored as display values,
//! shaded in linear light.

use glam::Vec3;

/// sRGB-encoded → linear (IEC 61966-2-1).
pub fn srgb_to_linear(c: f32) -> f32 {
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// Linear → sRGB-encoded.
pub fn linear_to_srgb(c: f32) -> f32 {
    if c <= 0.0031308 {
        c * 12.92
    } else {
        1.055 * c.powf(1.0 / 2.4) - 0.055
    }
}

/// A linear colour in [0, 1] as the sRGB colour target stores it.
pub fn display_bytes(c: Vec3) -> [u8; 4] {
    let q = |x: f32| (linear_to_srgb(x.clamp(0.0, 1.0)) * 255.0 + 0.5).floor() as u8;
    [q(c.x), q(c.y), q(c.z), 255]
}
