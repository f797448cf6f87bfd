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
    if x <= 0.003_130_8 {
        12.92 * x
    } else {
        1.055 * x.powf(1.0 / 2.4) - 0.055
    }
}

/// 8-bit sRGB codes from linear light without a `powf` per channel: equal,
/// for every f32, to `(linear_to_srgb(x) * 255.0 + 0.5) as u8` (tested over
/// every value in [2⁻¹³, 1]), so frames keep their bytes. Values from 2⁻¹³
/// to 1 fall in buckets of 1/128 of an octave, keyed by the top bits of the
/// float; a bucket spans under one code step of the curve (at most about
/// two thirds, just below 1), so it holds the code at its start and at most
/// one threshold where the code goes up by one (checked as the table is built).
pub struct SrgbBytes {
    base: [u8; SRGB_BUCKETS],
    next: [f32; SRGB_BUCKETS],
}

/// Below this every value codes to 0 (12.92 · 2⁻¹³ · 255 < 0.5).
const SRGB_LOWEST: f32 = 1.0 / 8192.0;
/// The float just below 1: the top of the last bucket.
const SRGB_BELOW_ONE: f32 = f32::from_bits(1.0f32.to_bits() - 1);
/// Mantissa bits in the bucket key: 128 buckets per octave.
const SRGB_KEY_SHIFT: u32 = f32::MANTISSA_DIGITS - 1 - 7;
const SRGB_FIRST_KEY: u32 = SRGB_LOWEST.to_bits() >> SRGB_KEY_SHIFT;
const SRGB_BUCKETS: usize = ((1.0f32.to_bits() >> SRGB_KEY_SHIFT) - SRGB_FIRST_KEY) as usize;

impl SrgbBytes {
    /// The table, built on first use (a few thousand `powf`s).
    pub fn get() -> &'static SrgbBytes {
        static TABLE: std::sync::OnceLock<SrgbBytes> = std::sync::OnceLock::new();
        TABLE.get_or_init(SrgbBytes::new)
    }

    /// The code the curve gives `x`, computed the slow way.
    fn exact(x: f32) -> u8 {
        (linear_to_srgb(x) * 255.0 + 0.5) as u8
    }

    fn new() -> SrgbBytes {
        let mut table = SrgbBytes {
            base: [0; SRGB_BUCKETS],
            next: [f32::INFINITY; SRGB_BUCKETS],
        };
        for i in 0..SRGB_BUCKETS {
            let first = (SRGB_FIRST_KEY + i as u32) << SRGB_KEY_SHIFT;
            let last = first + (1 << SRGB_KEY_SHIFT) - 1;
            let base = Self::exact(f32::from_bits(first));
            table.base[i] = base;
            let end = Self::exact(f32::from_bits(last));
            assert!(
                end <= base.saturating_add(1),
                "an sRGB bucket spans two steps"
            );
            if end > base {
                // The first value of the bucket whose code is above its start.
                let (mut below, mut above) = (first, last);
                while above - below > 1 {
                    let mid = below + (above - below) / 2;
                    if Self::exact(f32::from_bits(mid)) > base {
                        above = mid;
                    } else {
                        below = mid;
                    }
                }
                table.next[i] = f32::from_bits(above);
            }
        }
        table
    }

    /// The 8-bit sRGB code of linear `x`: 0 for NaN and anything at or
    /// below 0, 255 from 1 up, +infinity included.
    #[inline]
    pub fn byte(&self, x: f32) -> u8 {
        // Without branches (a frame's values come in no order a predictor
        // could follow): NaN becomes 0; the clamp takes all below the lowest
        // value to it, whose code is 0 too, and 1 and up to the float just
        // below 1, whose code is 255.
        let x = if x.is_nan() { 0.0 } else { x };
        let x = x.clamp(SRGB_LOWEST, SRGB_BELOW_ONE);
        let i = ((x.to_bits() >> SRGB_KEY_SHIFT) - SRGB_FIRST_KEY) as usize;
        self.base[i] + (x >= self.next[i]) as u8
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn srgb_bytes_match_the_curve_for_every_float() {
        let table = SrgbBytes::get();
        // Every f32 from 2^-13 to 1, where the table does its work.
        use rayon::prelude::*;
        let (from, to) = (SRGB_LOWEST.to_bits(), 1.0f32.to_bits());
        let wrong = (from..=to)
            .into_par_iter()
            .filter(|&bits| {
                let x = f32::from_bits(bits);
                table.byte(x) != SrgbBytes::exact(x)
            })
            .count();
        assert_eq!(wrong, 0);
        // Below, above and beside: a stride through the rest of the floats.
        let rest = (0..u32::MAX / 9973)
            .map(|k| f32::from_bits(k * 9973))
            .chain([
                0.0,
                -0.0,
                -1.0,
                2.0,
                f32::MAX,
                f32::MIN_POSITIVE,
                f32::EPSILON,
            ])
            .chain([f32::NAN, f32::INFINITY, f32::NEG_INFINITY]);
        for x in rest {
            assert_eq!(table.byte(x), SrgbBytes::exact(x), "{x:e}");
        }
        // The curve's own ends and mid-grey, stated independently.
        assert_eq!(table.byte(1.0), 255);
        assert_eq!(table.byte(f32::INFINITY), 255); // too bright for f32: white
        assert_eq!(table.byte(f32::NAN), 0);
        assert_eq!(table.byte(f32::NEG_INFINITY), 0);
        assert_eq!(table.byte(0.18), 118); // 0.4613 · 255 + 0.5
        assert_eq!(table.byte(0.0031308), 10); // 0.04045 · 255 + 0.5
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
