//! The `reduce_error` stage, CPU twin of `shaders/reduce_error.wgsl`: statistics of the
//! display-position error over the visible pixels of both eyes (seed 002 §4.1).
//!
//! Pixels with a negative error (background, or points no eye sees) are left out. Mean and std
//! are exact sums (the GPU uses per-workgroup sums and compensated summation); max is exact.
//! Percentiles come from a histogram with bins of 1/64 px below 64 px and of 1 px from 64 to
//! 1024 px (one overflow bin beyond, whose percentile reports the max), interpolated by rank
//! within the bin: their resolution is 1/64 px below 64 px.

use crate::encoding::types::ErrorStats;

const FINE_BINS: usize = constants::FINE_BINS as usize;
const COARSE_BINS: usize = constants::COARSE_BINS as usize;
const BINS: usize = constants::BINS as usize;
use crate::encoding::constants;

pub fn bin_of(e: f32) -> usize {
    if e < 64.0 {
        ((e * 64.0).floor() as usize).min(FINE_BINS - 1)
    } else if e < 1024.0 {
        FINE_BINS + ((e - 64.0).floor() as usize).min(COARSE_BINS - 1)
    } else {
        BINS - 1
    }
}

fn bin_low(b: usize) -> f32 {
    if b < FINE_BINS {
        b as f32 / 64.0
    } else {
        64.0 + (b - FINE_BINS) as f32
    }
}

fn bin_width(b: usize) -> f32 {
    if b < FINE_BINS {
        1.0 / 64.0
    } else {
        1.0
    }
}

/// The reduction on the CPU over any number of error images.
pub fn reduce_error<'a>(images: impl IntoIterator<Item = &'a [f32]>) -> ErrorStats {
    let mut histogram = vec![0u32; BINS];
    let (mut count, mut sum, mut sum_sq, mut max) = (0u32, 0f64, 0f64, 0f32);
    for img in images {
        for &e in img.iter().filter(|e| **e >= 0.0) {
            histogram[bin_of(e)] += 1;
            count += 1;
            sum += e as f64;
            sum_sq += (e as f64) * (e as f64);
            max = max.max(e);
        }
    }
    if count == 0 {
        return ErrorStats::default();
    }
    let percentile = |p: f32| {
        let rank = ((p * count as f32).ceil() as u32).max(1);
        let mut cumulative = 0;
        for (b, &n) in histogram.iter().enumerate() {
            if cumulative + n >= rank {
                if b == BINS - 1 {
                    return max;
                }
                // Interpolate by rank within the bin, never beyond the largest error.
                let low = bin_low(b);
                let high = (low + bin_width(b)).min(max);
                return low + (high - low).max(0.0) * (rank - cumulative) as f32 / n as f32;
            }
            cumulative += n;
        }
        0.0
    };
    let mean = sum / count as f64;
    ErrorStats {
        count,
        mean: mean as f32,
        std_dev: (sum_sq / count as f64 - mean * mean).max(0.0).sqrt() as f32,
        p50: percentile(0.5),
        p90: percentile(0.9),
        p99: percentile(0.99),
        max,
        _pad: 0.0,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn statistics_of_known_values() {
        // 1..=1000 hundredths of a pixel, plus background (−1) that must be ignored.
        let values: Vec<f32> = (1..=1000).map(|i| i as f32 / 100.0).chain([-1.0; 50]).collect();
        let s = reduce_error([values.as_slice()]);
        assert_eq!(s.count, 1000);
        assert!((s.mean - 5.005).abs() < 1e-4);
        let std = ((1..=1000).map(|i| (i as f64 / 100.0 - 5.005).powi(2)).sum::<f64>() / 1000.0).sqrt();
        assert!((s.std_dev as f64 - std).abs() < 1e-4);
        assert_eq!(s.max, 10.0);
        // Nearest-rank percentiles, within the 1/64 px bin resolution.
        for (got, want) in [(s.p50, 5.0), (s.p90, 9.0), (s.p99, 9.9)] {
            assert!((got - want).abs() <= 1.0 / 64.0, "{got} vs {want}");
        }
    }

    #[test]
    fn percentiles_never_exceed_the_max() {
        let values = [0.0001f32, 0.0002, 0.0003];
        let s = reduce_error([&values[..]]);
        assert!(s.p50 <= s.max && s.p99 <= s.max && s.max == 0.0003, "{s:?}");
    }

    #[test]
    fn large_errors_use_coarse_bins_and_the_overflow_reports_the_max() {
        let values = [100.5f32, 200.0, 2000.0, 3000.0];
        let s = reduce_error([&values[..]]);
        assert_eq!(s.max, 3000.0);
        assert_eq!(s.p99, 3000.0);
        // Nearest rank: the 2nd of 4 values, within its 1 px bin.
        assert!((s.p50 - 200.0).abs() <= 1.0, "{}", s.p50);
    }
}
