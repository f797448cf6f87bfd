//! What a hit looks like: orbit-trap colour, Lambert diffuse from the main
//! light and up to `MAX_LIGHTS` − 1 extra ones plus ambient, the background
//! gradient for misses, and the optional effects a scene declares (shadows,
//! ambient occlusion, specular, fog, glow, motion blur, and the path tracer
//! with its skies).
//! An effect that is off (`None`) runs no code and spends no estimate.
//!
//! Colouring idea from ../shared/seeds/000 (Quilez, "Coloring"): the three plane
//! traps blend a base colour towards three others, and the origin trap darkens
//! crevices like a cheap occlusion term. Soft shadows follow Quilez's penumbra
//! estimate (the smallest k·h/t along the shadow march); distance-field
//! occlusion compares the estimate with the distance stepped along the normal.

use crate::fractal::OrbitTraps;
use crate::math::{DVec3, Real, Vec3};
use serde::{Deserialize, Serialize};

mod bundle;
mod fog;
mod lighting;
mod look;
mod palette;
mod path;
mod shadow;
mod sky;

pub use bundle::{walk_shadows, BundleScratch};
pub use fog::{fogged, glow, Fog, Glow};
pub use look::{Look, Specular, MAX_LIGHTS};
#[cfg(test)]
pub use palette::{OrbitQuantity, Palette};
pub use palette::{Stop, Table as PaletteTable, MAX_STOPS};
pub use path::{trace_paths, PathScratch, PathTracing};
pub use shadow::{occlusions, AmbientOcclusion, ShadowWalk, Shadows};
pub use sky::Sky;

/// The effects a scene calls for; each is off unless given.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Effects {
    pub shadows: Option<Shadows>,
    pub ambient_occlusion: Option<AmbientOcclusion>,
    pub specular: Option<Specular>,
    pub fog: Option<Fog>,
    pub glow: Option<Glow>,
    pub motion_blur: Option<MotionBlur>,
    pub path_tracing: Option<PathTracing>,
}

/// Samples spread over an open shutter, each seeing the timeline at its own time.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct MotionBlur {
    /// How long the shutter is open, as a fraction of the frame interval (180° = 0.5).
    pub shutter: Real,
}

impl Default for MotionBlur {
    fn default() -> Self {
        MotionBlur { shutter: 0.5 }
    }
}

impl Effects {
    /// Names of the enabled effects, for `info`.
    pub fn enabled(&self) -> Vec<&'static str> {
        let mut v = Vec::new();
        if self.shadows.is_some() {
            v.push("shadows");
        }
        if self.ambient_occlusion.is_some() {
            v.push("ambient_occlusion");
        }
        if self.specular.is_some() {
            v.push("specular");
        }
        if self.fog.is_some() {
            v.push("fog");
        }
        if self.glow.is_some() {
            v.push("glow");
        }
        if self.motion_blur.is_some() {
            v.push("motion_blur");
        }
        if self.path_tracing.is_some() {
            v.push("path_tracing");
        }
        v
    }
}

/// Estimates spent by the shading stages of one sample.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct StageCounts {
    pub shadows: u64,
    pub occlusion: u64,
    /// Path tracing: marching of bounce rays, and of rays towards the sun.
    pub bounces: u64,
    pub sun_rays: u64,
}

/// A hit as shading needs it.
#[derive(Clone, Copy, Debug)]
pub struct SurfacePoint {
    pub point: DVec3,
    pub normal: DVec3,
    /// Direction from the camera towards the point.
    pub view_dir: DVec3,
    /// Camera distance to the point, and one pixel's width there.
    pub t: Real,
    pub footprint: Real,
    pub traps: OrbitTraps,
    /// The look's palette's colour here, where it has one that shows
    /// (`coloured`); `None` costs nothing.
    pub palette_colour: Option<Vec3>,
}

impl SurfacePoint {
    /// Where `ray` met the surface (`hit`), with the surface `normal` there.
    pub fn from_hit(ray: &crate::march::Ray, hit: &crate::march::Hit, normal: DVec3) -> Self {
        SurfacePoint {
            point: hit.point,
            normal,
            view_dir: ray.dir,
            t: hit.t,
            footprint: ray.footprint(hit.t),
            traps: hit.estimate.traps,
            palette_colour: None,
        }
    }

    /// This point with its colour from `palette` (the look's, where it
    /// shows: `palette_table`), placed by `estimate`, the one taken at the
    /// point (the hit's).
    pub fn coloured(
        mut self,
        palette: Option<&PaletteTable>,
        fractal: &crate::fractal::Fractal,
        estimate: &crate::fractal::Estimate,
    ) -> Self {
        if let Some(table) = palette {
            self.palette_colour = Some(table.colour(table.quantity(fractal, self.point, estimate)));
        }
        self
    }
}

/// The table of `look`'s palette for `fractal`'s hits, where it has one
/// with some mix: made once for all the hits that share them.
pub fn palette_table(look: &Look, fractal: &crate::fractal::Fractal) -> Option<PaletteTable> {
    let palette = look.palette.as_ref().filter(|p| p.mix > 0.0)?;
    Some(palette.table(fractal))
}

#[cfg(test)]
mod tests;
