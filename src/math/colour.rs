//! Small colour helpers that keep NaN and infinity out of pixels.

use super::Vec3;

/// Linear blend of two colours, `t` clamped to 0..=1.
pub fn mix(a: Vec3, b: Vec3, t: f32) -> Vec3 {
    a + (b - a) * t.clamp(0.0, 1.0)
}

/// Replaces a non-finite colour channel by zero so no NaN reaches a pixel.
pub fn finite_or_zero(c: Vec3) -> Vec3 {
    Vec3::new(
        if c.x.is_finite() { c.x } else { 0.0 },
        if c.y.is_finite() { c.y } else { 0.0 },
        if c.z.is_finite() { c.z } else { 0.0 },
    )
}
