//! A scene's look: colours, lights and the display settings a timeline
//! sets, with their defaults.

use super::palette::Palette;
use crate::color::Display;
use crate::color::ToneMap;
use crate::math::{DVec3, Vec3};
use serde::{Deserialize, Serialize};

/// Colours and light of a scene. Colours are linear RGB.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Look {
    /// Direction towards the light (need not be unit length).
    pub light_direction: DVec3,
    pub light_colour: Vec3,
    /// More directional lights beside the key light above (fill, rim, a second sun).
    pub extra_lights: Vec<Light>,
    /// Light that reaches every surface regardless of orientation.
    pub ambient: Vec3,
    /// Surface colour where no trap pulls.
    pub base_colour: Vec3,
    /// Colours the x=0, y=0 and z=0 plane traps blend towards.
    pub trap_x_colour: Vec3,
    pub trap_y_colour: Vec3,
    pub trap_z_colour: Vec3,
    /// How strongly the origin trap darkens crevices (0 = not at all).
    pub trap_occlusion: f32,
    /// A gradient that colours the surface by an orbit quantity, mixed
    /// over the trap colours; none by default. Left out of a scene's
    /// serialised form when absent, so frames without one keep their hashes.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub palette: Option<Palette>,
    /// Background at the top and bottom of the frame (by the camera's up vector).
    pub background_top: Vec3,
    pub background_bottom: Vec3,
    /// How linear light becomes 8-bit display values (PNG frames; an EXR
    /// keeps the linear light as rendered): multiplied by `exposure`, then
    /// mapped by `tone_map`. Left out of a scene's serialised form at
    /// their defaults, so frames rendered before they existed keep their
    /// hashes.
    #[serde(skip_serializing_if = "ToneMap::is_clip")]
    pub tone_map: ToneMap,
    #[serde(skip_serializing_if = "is_one")]
    pub exposure: f32,
    /// Leave the background out: misses add no sky (glow stays, as light
    /// with no coverage), and alpha is the fractal's coverage, for
    /// compositing. Otherwise the background is drawn and every pixel is opaque.
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub transparent_background: bool,
}

pub(super) fn is_one(x: &f32) -> bool {
    *x == 1.0
}

impl Look {
    /// The display transform of this look: its exposure and tone map.
    pub fn display_transform(&self) -> Display {
        Display {
            exposure: self.exposure,
            tone_map: self.tone_map,
        }
    }
}

impl Default for Look {
    fn default() -> Self {
        Look {
            light_direction: DVec3::new(0.6, 0.8, 0.5),
            light_colour: Vec3::new(1.0, 0.95, 0.85),
            extra_lights: Vec::new(),
            ambient: Vec3::new(0.12, 0.13, 0.16),
            base_colour: Vec3::new(0.75, 0.72, 0.68),
            trap_x_colour: Vec3::new(0.75, 0.28, 0.08),
            trap_y_colour: Vec3::new(0.10, 0.35, 0.65),
            trap_z_colour: Vec3::new(0.85, 0.65, 0.20),
            trap_occlusion: 0.8,
            palette: None,
            background_top: Vec3::new(0.02, 0.03, 0.06),
            background_bottom: Vec3::new(0.10, 0.09, 0.12),
            tone_map: ToneMap::Clip,
            exposure: 1.0,
            transparent_background: false,
        }
    }
}

/// Blinn–Phong highlight of the light.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Specular {
    pub strength: f32,
    pub shininess: f32,
}

impl Default for Specular {
    fn default() -> Self {
        Specular {
            strength: 0.3,
            shininess: 32.0,
        }
    }
}

/// A directional light: where it comes from and how bright it is.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Light {
    /// Direction towards the light (need not be unit length).
    pub direction: DVec3,
    pub colour: Vec3,
    pub intensity: f32,
}

impl Default for Light {
    fn default() -> Self {
        Light {
            direction: DVec3::new(-0.5, 0.3, -0.8),
            colour: Vec3::new(0.45, 0.5, 0.6),
            intensity: 1.0,
        }
    }
}

/// Most lights a scene may have (the key light and seven more).
pub const MAX_LIGHTS: usize = 8;
