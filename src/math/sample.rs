//! Stateless uniform numbers keyed by (seed, frame, pixel, sample,
//! dimension), and points drawn from them.

use super::{DVec3, Real};

/// A uniform number in [0, 1) from (seed, frame, pixel, sample, dimension):
/// a stateless hash, so samples never depend on evaluation order.
pub fn sample_1d(seed: u64, frame: u32, pixel: u64, sample: u32, dim: u32) -> Real {
    // SplitMix64 finaliser over a combined key.
    let mut x = seed
        ^ (frame as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15)
        ^ pixel.wrapping_mul(0xBF58_476D_1CE4_E5B9)
        ^ ((sample as u64) << 32 | dim as u64).wrapping_mul(0x94D0_49BB_1331_11EB);
    x = (x ^ (x >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    x = (x ^ (x >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    x ^= x >> 31;
    (x >> 11) as Real / (1u64 << 53) as Real
}

/// `count` points spread over the shell of radii `radius` around the origin,
/// from the sampler with `seed`: the same points every run.
pub fn shell_points(count: usize, radius: std::ops::Range<Real>, seed: u64) -> Vec<DVec3> {
    (0..count as u64)
        .map(|i| {
            let u = |d: u32| sample_1d(seed, 0, i, 0, d);
            let z = 2.0 * u(0) - 1.0;
            let phi = std::f64::consts::TAU * u(1);
            let s = (1.0 - z * z).sqrt();
            let r = radius.start + (radius.end - radius.start) * u(2);
            DVec3::new(s * phi.cos(), z, s * phi.sin()) * r
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sampler_is_uniform_and_deterministic() {
        let mut sum = 0.0;
        for i in 0..10_000u64 {
            let u = sample_1d(7, 3, i, 0, 0);
            assert!((0.0..1.0).contains(&u));
            sum += u;
        }
        assert!((sum / 10_000.0 - 0.5).abs() < 0.01);
        assert_eq!(sample_1d(1, 2, 3, 4, 5), sample_1d(1, 2, 3, 4, 5));
        assert_ne!(sample_1d(1, 2, 3, 4, 5), sample_1d(1, 2, 3, 4, 6));
    }
}
