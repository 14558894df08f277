//! Where a pixel's samples lie (`--samples N`): the standard sample positions of Vulkan and
//! Direct3D for 1, 2, 4, 8 and 16 samples, which a multisampling adapter draws at, and for 32
//! the 8 pattern in each quarter of the pixel. The ray tracer shoots its rays through them
//! (`sample_position` in shaders/trace.wgsl), so its samples are stratified as the raster's.

use glam::Vec2;

/// The standard positions, in 16ths of a pixel from its corner (Vulkan's
/// `standardSampleLocations`), by count ([`STANDARD_POSITIONS`]).
const TWO: [[f32; 2]; 2] = [[12.0, 12.0], [4.0, 4.0]];
const FOUR: [[f32; 2]; 4] = [[6.0, 2.0], [14.0, 6.0], [2.0, 10.0], [10.0, 14.0]];
const EIGHT: [[f32; 2]; 8] =
    [[9.0, 5.0], [7.0, 11.0], [13.0, 9.0], [5.0, 3.0], [3.0, 13.0], [1.0, 7.0], [11.0, 15.0], [15.0, 1.0]];
const SIXTEEN: [[f32; 2]; 16] = [
    [9.0, 9.0],
    [7.0, 5.0],
    [5.0, 10.0],
    [12.0, 7.0],
    [3.0, 6.0],
    [10.0, 13.0],
    [13.0, 11.0],
    [11.0, 3.0],
    [6.0, 14.0],
    [8.0, 1.0],
    [4.0, 2.0],
    [2.0, 12.0],
    [0.0, 8.0],
    [15.0, 4.0],
    [14.0, 15.0],
    [1.0, 0.0],
];

/// Each count's standard positions: the tables `sample_position` reads, also generated into the
/// WGSL `constants` module as `SAMPLES_2` … `SAMPLES_16` (src/encoding/constants.rs).
pub const STANDARD_POSITIONS: [(u32, &[[f32; 2]]); 4] = [(2, &TWO), (4, &FOUR), (8, &EIGHT), (16, &SIXTEEN)];

/// Where sample `i` of `n` lies in its pixel (0..1 from the pixel's corner); any other `n`: the
/// centre.
pub fn sample_position(n: u32, i: u32) -> Vec2 {
    let at = |p: [f32; 2]| Vec2::from(p) / 16.0;
    match n {
        2 => at(TWO[i as usize]),
        4 => at(FOUR[i as usize]),
        8 => at(EIGHT[i as usize]),
        16 => at(SIXTEEN[i as usize]),
        32 => (Vec2::new((i & 1) as f32, ((i >> 1) & 1) as f32) + at(EIGHT[(i >> 2) as usize])) * 0.5,
        _ => Vec2::splat(0.5),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every count's positions are distinct, inside the pixel, and stratified: each row and
    /// column of a grid of min(n, 16) holds at most max(n / 16, 1) samples, and their mean is near
    /// the centre.
    #[test]
    fn positions_are_stratified_in_the_pixel() {
        for n in [1u32, 2, 4, 8, 16, 32] {
            let p: Vec<Vec2> = (0..n).map(|i| sample_position(n, i)).collect();
            assert!(p.iter().all(|q| q.cmpge(Vec2::ZERO).all() && q.cmplt(Vec2::ONE).all()), "{n}: {p:?}");
            let mean = p.iter().copied().sum::<Vec2>() / n as f32;
            assert!((mean - Vec2::splat(0.5)).length() < 0.1, "{n}: mean {mean}");
            let cells = n.min(16);
            for axis in 0..2 {
                let mut seen = vec![0u32; cells as usize];
                for q in &p {
                    seen[((q[axis] * cells as f32) as usize).min(cells as usize - 1)] += 1;
                }
                assert!(seen.iter().all(|&c| c <= (n / 16).max(1)), "{n} axis {axis}: {seen:?}");
            }
            for (i, a) in p.iter().enumerate() {
                assert!(p[..i].iter().all(|b| (*a - *b).length() > 1e-3), "{n}: repeated {a}");
            }
        }
    }
}
