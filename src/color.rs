//! The display transform: how linear light becomes display values.
//! Exposure, then a tone map, then the sRGB transfer curve (exact, and as a
//! table of 8-bit codes).

use serde::{Deserialize, Serialize};

/// The curve from exposed linear light to display values in [0, 1].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum ToneMap {
    /// Values above 1 are white: each channel clips on its own, so a bright
    /// orange highlight turns yellow, then white.
    #[default]
    Clip,
    /// A filmic curve (Narkowicz's rational fit of the ACES reference
    /// transform, per channel): highlights roll off towards white instead
    /// of clipping, and mid-tones lift (0.18 shows as 0.27); 1 shows as
    /// 0.80, 4 as 0.97, and white is reached near 7.2.
    Filmic,
}

impl ToneMap {
    pub(crate) fn is_clip(&self) -> bool {
        *self == ToneMap::Clip
    }

    /// The display value of exposed linear `x` (at or above 0), before the
    /// sRGB curve; `Clip` leaves `x` as it is (the sRGB coding clips).
    #[inline]
    pub fn apply(self, x: f32) -> f32 {
        match self {
            ToneMap::Clip => x,
            ToneMap::Filmic => {
                // White from about 7.2 on; capped so x² cannot overflow
                // (infinity over infinity would show black).
                let x = if x > 0.0 { x.min(64.0) } else { 0.0 };
                (x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14)
            }
        }
    }
}

/// How linear light becomes display values in [0, 1] before the sRGB
/// curve: multiplied by `exposure`, then mapped by `tone_map`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Display {
    pub exposure: f32,
    pub tone_map: ToneMap,
}

/// The plain display: linear light as it is, clipped.
impl Default for Display {
    fn default() -> Self {
        Display {
            exposure: 1.0,
            tone_map: ToneMap::Clip,
        }
    }
}

impl Display {
    /// Whether display values are the linear light itself (clipped):
    /// PNG coding then takes its plain path.
    pub fn is_plain(&self) -> bool {
        self.tone_map == ToneMap::Clip && self.exposure == 1.0
    }

    /// The display value of linear `x` (`exposure`, then `tone_map`).
    #[inline]
    pub fn apply(&self, x: f32) -> f32 {
        self.tone_map.apply(x * self.exposure)
    }
}

/// Converts a linear-light value to the sRGB transfer curve (IEC 61966-2-1).
/// NaN shows as 0 and +infinity as 1: light too bright for f32 (a huge
/// exposure times a bright light) is white, not black.
pub fn linear_to_srgb(x: f32) -> f32 {
    let x = if x.is_nan() { 0.0 } else { x.clamp(0.0, 1.0) };
    linear_to_srgb_f64(x as f64) as f32
}

/// The sRGB curve without a `powf` per channel: values from 2⁻¹³ to 1 fall
/// in buckets of 1/128 of an octave, keyed by the top bits of the float,
/// and the curve is a straight line across each (within 0.1 of a 16-bit
/// code of `linear_to_srgb`, tested over every value); below 2⁻¹³ it is the
/// curve's own straight segment.
pub struct SrgbCurve {
    /// The curve at each bucket's start and its slope across the bucket.
    start: [f32; SRGB_BUCKETS],
    slope: [f32; SRGB_BUCKETS],
}

/// Below this the curve is its straight segment, 12.92 x.
const SRGB_LOWEST: f32 = 1.0 / 8192.0;
/// Mantissa bits in the bucket key: 128 buckets per octave.
const SRGB_KEY_SHIFT: u32 = f32::MANTISSA_DIGITS - 1 - 7;
const SRGB_FIRST_KEY: u32 = SRGB_LOWEST.to_bits() >> SRGB_KEY_SHIFT;
const SRGB_BUCKETS: usize = ((1.0f32.to_bits() >> SRGB_KEY_SHIFT) - SRGB_FIRST_KEY) as usize;

impl SrgbCurve {
    /// The table, built once (about 2 ms).
    pub fn get() -> &'static SrgbCurve {
        static TABLE: std::sync::OnceLock<SrgbCurve> = std::sync::OnceLock::new();
        TABLE.get_or_init(SrgbCurve::new)
    }

    fn new() -> SrgbCurve {
        let exact = |bits: u32| linear_to_srgb_f64(f32::from_bits(bits) as f64);
        let mut table = SrgbCurve {
            start: [0.0; SRGB_BUCKETS],
            slope: [0.0; SRGB_BUCKETS],
        };
        for i in 0..SRGB_BUCKETS {
            let first = (SRGB_FIRST_KEY + i as u32) << SRGB_KEY_SHIFT;
            let next = first + (1 << SRGB_KEY_SHIFT);
            let width = f32::from_bits(next) as f64 - f32::from_bits(first) as f64;
            table.start[i] = exact(first) as f32;
            table.slope[i] = ((exact(next) - exact(first)) / width) as f32;
        }
        table
    }

    /// `linear_to_srgb(x)`, within 0.1 of a 16-bit code.
    #[inline]
    pub fn value(&self, x: f32) -> f32 {
        // Without branches a predictor would miss: NaN becomes 0, and the
        // clamp takes 1 and up to the float just below it.
        let x = if x.is_nan() { 0.0 } else { x };
        let x = x.clamp(0.0, f32::from_bits(1.0f32.to_bits() - 1));
        if x < SRGB_LOWEST {
            return 12.92 * x;
        }
        let bits = x.to_bits();
        let i = ((bits >> SRGB_KEY_SHIFT) - SRGB_FIRST_KEY) as usize;
        let first = f32::from_bits(bits >> SRGB_KEY_SHIFT << SRGB_KEY_SHIFT);
        (self.start[i] + (x - first) * self.slope[i]).min(1.0)
    }

    /// The 16-bit sRGB code of linear `x`.
    #[inline]
    pub fn code16(&self, x: f32) -> u16 {
        (self.value(x) * 65535.0 + 0.5) as u16
    }

    /// The 8-bit sRGB code of linear `x`, dithered by `offset` in [0, 1):
    /// rounded down after the offset is added, so over many pixels the
    /// codes average to the exact value (a gradient shows no bands), and
    /// a value that is a code exactly (black, white) stays that code.
    #[inline]
    pub fn dithered_byte(&self, x: f32, offset: f32) -> u8 {
        (self.value(x) * 255.0 + offset).min(255.0) as u8
    }
}

/// `linear_to_srgb` in f64, for building the table.
fn linear_to_srgb_f64(x: f64) -> f64 {
    if x <= 0.003_130_8 {
        12.92 * x
    } else {
        1.055 * x.powf(1.0 / 2.4) - 0.055
    }
}

/// The dither offset of pixel (x, y), in [0, 1): white noise from a hash
/// of the pixel alone, so a frame's bytes are the same on any thread and
/// the pattern stands still in a video rather than crawling.
#[inline]
pub fn dither_offset(x: u32, y: u32) -> f32 {
    // lowbias32 (Chris Wellons' integer hash) of the two coordinates.
    let mut h = x.wrapping_mul(0x9E37_79B9) ^ y.wrapping_mul(0x85EB_CA6B).rotate_left(16);
    h ^= h >> 16;
    h = h.wrapping_mul(0x7FEB_352D);
    h ^= h >> 15;
    h = h.wrapping_mul(0x846C_A68B);
    h ^= h >> 16;
    (h >> 8) as f32 * (1.0 / 16_777_216.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_srgb_table_follows_the_curve_for_every_float() {
        let table = SrgbCurve::get();
        // Every f32 from 0 to 1, in 16-bit codes of the exact curve.
        use rayon::prelude::*;
        let worst = (0..=1.0f32.to_bits())
            .into_par_iter()
            .map(|bits| {
                let x = f32::from_bits(bits);
                ((table.value(x) as f64 - linear_to_srgb_f64(x as f64)) * 65535.0).abs()
            })
            .reduce(|| 0.0, f64::max);
        assert!(worst < 0.1, "{worst} of a 16-bit code");
        for (x, v) in [
            (f32::NAN, 0.0),
            (f32::NEG_INFINITY, 0.0),
            (-1.0, 0.0),
            (2.0, 1.0),
            (f32::INFINITY, 1.0), // too bright for f32: white
        ] {
            assert_eq!(table.value(x), v, "{x}");
        }
        assert_eq!(table.code16(1.0), 65535);
        assert_eq!(table.code16(0.18), 30235); // 0.461357 · 65535 = 30234.97
        assert_eq!(table.dithered_byte(1.0, 0.999), 255);
        assert_eq!(table.dithered_byte(0.0, 0.999), 0);
    }

    #[test]
    fn dithered_codes_average_to_the_exact_value() {
        let table = SrgbCurve::get();
        // A value between two codes: a third of the way from 117 to 118.
        let x = 0.178_966; // sRGB 0.460118 · 255 = 117.33
        let exact = linear_to_srgb_f64(x as f64) * 255.0;
        let codes: Vec<f64> = (0..256u32)
            .flat_map(|y| (0..256u32).map(move |x| (x, y)))
            .map(|(px, py)| table.dithered_byte(x, dither_offset(px, py)) as f64)
            .collect();
        let mean = codes.iter().sum::<f64>() / codes.len() as f64;
        assert!((mean - exact).abs() < 0.01, "mean {mean}, exact {exact}");
        assert!(codes
            .iter()
            .all(|&c| c == exact.floor() || c == exact.ceil()));
        // Undithered, every code would be the nearest: 0.33 away on average.
        assert!((exact - exact.round()).abs() > 0.3);
    }

    #[test]
    fn srgb_curve_end_points_and_midtone() {
        assert_eq!(linear_to_srgb(0.0), 0.0);
        assert!((linear_to_srgb(1.0) - 1.0).abs() < 1e-6);
        // 18% grey is about 46% in sRGB.
        assert!((linear_to_srgb(0.18) - 0.4613).abs() < 1e-3);
        assert_eq!(linear_to_srgb(f32::NAN), 0.0);
    }
}
