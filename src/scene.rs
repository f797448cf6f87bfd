//! Plain data for one instant of a frame: camera, fractal, marcher quality,
//! look and effects. A timeline produces one `Scene` per frame (one per
//! sample under motion blur); the renderer consumes it. Its serde
//! form is also the timeline's `scene:` block, and its JSON serialisation is
//! what each frame's content hash is taken over.

use crate::camera::Camera;
use crate::fractal::Fractal;
use crate::march::MarchSettings;
use serde::{Deserialize, Serialize};

/// The fewest samples a pixel for a smooth depth of field (each sample
/// leaves from its own point on the lens); fewer render, with a warning.
pub const LENS_SAMPLES: u32 = 4;

/// The fewest samples a pixel for motion blur to blur rather than show its
/// separate instants; fewer render, with a warning.
pub const MOTION_BLUR_SAMPLES: u32 = 8;

/// Everything needed to render one frame.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Scene {
    pub camera: Camera,
    pub fractal: Fractal,
    pub quality: MarchSettings,
    pub look: crate::shade::Look,
    /// Optional effects; each off unless declared.
    pub effects: crate::shade::Effects,
    /// Anti-aliasing samples per pixel (1 = one ray through the pixel
    /// centre); with `adaptive`, the most a pixel takes.
    pub samples_per_pixel: u32,
    /// Samples where they are needed instead of the same in every pixel;
    /// left out of the frame's hash when off, so uniform frames keep theirs.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub adaptive: Option<Adaptive>,
    /// Seed of the deterministic sample pattern.
    pub seed: u64,
}

impl Default for Scene {
    fn default() -> Self {
        Scene {
            camera: Camera::default(),
            fractal: Fractal::default(),
            quality: MarchSettings::default(),
            look: crate::shade::Look::default(),
            effects: crate::shade::Effects::default(),
            samples_per_pixel: 1,
            adaptive: None,
            seed: 0,
        }
    }
}

/// Adaptive sampling: every pixel takes `first` samples, then pixels whose
/// estimated error is still above `noise` take as many again, wave after
/// wave, up to `samples_per_pixel` (see `render::adaptive`).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Adaptive {
    /// Samples every pixel takes before any is judged.
    pub first: u32,
    /// The error a pixel may keep: the standard error of its mean, in
    /// display values (0 to 1, after tone map and sRGB curve).
    pub noise: f32,
}

impl Default for Adaptive {
    fn default() -> Self {
        Adaptive {
            first: 2,
            noise: 0.02,
        }
    }
}

impl Scene {
    /// Camera rays that march one cone together (`quality.cone_rays`), or 1
    /// where cones do not apply (`march_alone_reason`).
    pub fn cone_rays(&self) -> u32 {
        match self.march_alone_reason() {
            Some(_) => 1,
            None => self.quality.cone_rays,
        }
    }

    /// Why camera rays must march alone whatever `quality.cone_rays` says:
    /// glow needs each ray's own nearest approach, and estimators other
    /// than the analytic one have finite differences that can overestimate
    /// a step a cone would trust for all its rays.
    pub fn march_alone_reason(&self) -> Option<MarchAlone> {
        if self.effects.glow.is_some() {
            Some(MarchAlone::Glow)
        } else if self.fractal.de != crate::fractal::DeMethod::Analytic {
            Some(MarchAlone::Estimator(self.fractal.de))
        } else {
            None
        }
    }
}

impl Scene {
    /// The adaptive sampling that takes effect: none where the first wave
    /// already takes every sample.
    pub fn adapts(&self) -> Option<&Adaptive> {
        let n = self.samples_per_pixel;
        self.adaptive.as_ref().filter(|a| a.first.min(n) < n)
    }

    /// How many samples a pixel takes, in words: `4 sample(s) per pixel`,
    /// or `adaptive: 2 to 16 samples per pixel, to noise 0.01`.
    pub fn sampling_summary(&self) -> String {
        let n = self.samples_per_pixel;
        match self.adapts() {
            Some(a) => format!(
                "adaptive: {} to {n} samples per pixel, to noise {}",
                a.first, a.noise
            ),
            _ => format!("{n} sample(s) per pixel"),
        }
    }
}

/// Why a scene's camera rays march alone (`Scene::march_alone_reason`).
/// Asked for every row, so a value rather than a message.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum MarchAlone {
    Glow,
    Estimator(crate::fractal::DeMethod),
}

impl std::fmt::Display for MarchAlone {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            MarchAlone::Glow => f.write_str("for glow"),
            MarchAlone::Estimator(de) => write!(f, "for the {} estimator", de.name()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cones_only_with_the_analytic_estimator_and_without_glow() {
        let mut s = Scene::default();
        assert_eq!(s.cone_rays(), s.quality.cone_rays);
        s.quality.cone_rays = 4;
        assert_eq!(s.cone_rays(), 4);
        for de in crate::fractal::DeMethod::ALL {
            s.fractal.de = de;
            let expected = if de == crate::fractal::DeMethod::Analytic {
                4
            } else {
                1
            };
            assert_eq!(s.cone_rays(), expected, "{de:?}");
        }
        s.fractal.de = crate::fractal::DeMethod::Analytic;
        s.effects.glow = Some(crate::shade::Glow::default());
        assert_eq!(s.cone_rays(), 1);
    }
}
