//! Fog over distance and glow near the surface.

use crate::math::{mix, Real, Vec3};
use serde::{Deserialize, Serialize};

/// Exponential fog over the distance to each hit (the background is left as is).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Fog {
    /// Extinction per camera–target distance (scale-free, so zooms keep their haze).
    pub density: Real,
    pub colour: Vec3,
}

impl Default for Fog {
    fn default() -> Self {
        Fog {
            density: 0.5,
            colour: Vec3::new(0.10, 0.09, 0.12),
        }
    }
}

/// Glow around the surface where rays miss it narrowly.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Glow {
    pub colour: Vec3,
    pub strength: f32,
    /// Fall-off distance, in pixel footprints.
    pub width: Real,
}

impl Default for Glow {
    fn default() -> Self {
        Glow {
            colour: Vec3::new(0.9, 0.6, 0.3),
            strength: 0.6,
            width: 4.0,
        }
    }
}

/// Fog over a hit `distance` away, with `scale` the camera–target distance.
pub fn fogged(c: Vec3, fog: &Fog, distance: Real, scale: Real) -> Vec3 {
    let clear = (-fog.density * distance / scale.max(1e-300)).exp() as f32;
    mix(fog.colour, c, clear)
}

/// Glow added to a ray that came within `closest` footprints of the surface.
pub fn glow(glow: &Glow, closest: Real) -> Vec3 {
    if !closest.is_finite() {
        return Vec3::ZERO;
    }
    glow.colour * (glow.strength * (-closest / glow.width.max(1e-9)).exp() as f32)
}
