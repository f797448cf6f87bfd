//! Soft shadows (Quilez's penumbra estimate along a shadow march) and
//! distance-field ambient occlusion, walked many rays side by side.

use super::SurfacePoint;
use crate::fractal::Fractal;
use crate::march::MarchSettings;
use crate::math::{DVec3, Real};
use serde::{Deserialize, Serialize};

/// Shadows from the light: a march from each lit hit towards the light.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Shadows {
    /// Penumbra sharpness k of Quilez's k·h/t estimate; 0 gives hard shadows.
    pub softness: Real,
    /// Steps of the shadow march before the light counts as reached.
    pub max_steps: u32,
}

impl Default for Shadows {
    fn default() -> Self {
        Shadows {
            softness: 16.0,
            max_steps: 128,
        }
    }
}

/// Occlusion from the distance field: a few estimates along the normal.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct AmbientOcclusion {
    pub samples: u32,
    /// Reach along the normal as a fraction of the camera distance to the hit,
    /// so a zoom sees the same occlusion at every scale.
    pub radius: Real,
    /// 0 = no darkening, 1 = full.
    pub strength: f32,
}

impl Default for AmbientOcclusion {
    fn default() -> Self {
        AmbientOcclusion {
            samples: 5,
            radius: 0.05,
            strength: 1.0,
        }
    }
}

/// Light reaching `from` along `to_light`: 1 unoccluded, 0 blocked, in between
/// in a penumbra (`softness` > 0). Returns the factor and the estimates spent.
/// One ray alone: what the tests hold the walks side by side to.
#[cfg(test)]
pub fn shadow(
    fractal: &Fractal,
    settings: &MarchSettings,
    shadows: &Shadows,
    from: DVec3,
    to_light: DVec3,
    footprint: Real,
) -> (f32, u64) {
    crate::march::walk_one(
        ShadowWalk::start(settings, shadows, from, to_light, footprint),
        fractal,
        settings,
    )
}

/// Where a surface point's shadow rays start: a couple of footprints off
/// the surface, so it does not shadow itself.
pub(super) fn shadow_origin(at: &SurfacePoint) -> DVec3 {
    at.point + at.normal * (2.0 * at.footprint)
}

/// A shadow ray between estimates (see `shadow`), so many can be walked
/// side by side (`march::walk_many`).
#[derive(Clone, Copy, Debug)]
pub struct ShadowWalk {
    pub(super) from: DVec3,
    pub(super) to_light: DVec3,
    pub(super) footprint: Real,
    pub(super) t: Real,
    pub(super) t_exit: Real,
    pub(super) eps: Real,
    pub(super) softness: Real,
    light: Real,
    pub(super) steps_left: u32,
    pub(super) spent: u64,
}

impl ShadowWalk {
    /// Starts a couple of footprints off the surface; the output at once
    /// for a ray that misses the bounding sphere or may take no step.
    pub fn start(
        settings: &MarchSettings,
        shadows: &Shadows,
        from: DVec3,
        to_light: DVec3,
        footprint: Real,
    ) -> Result<ShadowWalk, (f32, u64)> {
        let Some((_, t_exit)) = settings.interval_from(from, to_light) else {
            return Err((1.0, 0));
        };
        let walk = ShadowWalk {
            from,
            to_light,
            footprint,
            t: 2.0 * footprint,
            t_exit,
            eps: settings.hit_threshold * footprint,
            softness: shadows.softness,
            light: 1.0,
            steps_left: shadows.max_steps,
            spent: 0,
        };
        match walk.finished() {
            true => Err(walk.output()),
            false => Ok(walk),
        }
    }

    pub(super) fn finished(&self) -> bool {
        self.steps_left == 0 || self.t > self.t_exit
    }

    pub(super) fn output(&self) -> (f32, u64) {
        (self.light.clamp(0.0, 1.0) as f32, self.spent)
    }
}

impl crate::march::Walk for ShadowWalk {
    type Output = (f32, u64);
    const READS_ORBIT: bool = false;

    fn next_point(&self) -> (DVec3, Real) {
        (self.from + self.to_light * self.t, self.footprint)
    }

    fn advance(
        &mut self,
        e: &crate::fractal::Estimate,
        _: Real,
        _: &Fractal,
        settings: &MarchSettings,
    ) -> Option<(f32, u64)> {
        self.spent += e.orbits as u64;
        if !e.escaped || e.distance < self.eps {
            return Some((0.0, self.spent));
        }
        if self.softness > 0.0 {
            self.light = self.light.min(self.softness * e.distance / self.t);
        }
        self.t += e.distance * settings.fudge;
        self.steps_left -= 1;
        self.finished().then(|| self.output())
    }
}

/// Ambient light reaching a surface point: 1 in the open, less in crevices.
/// One point alone: the tests' reference for `occlusions`.
#[cfg(test)]
pub fn occlusion(
    fractal: &Fractal,
    ao: &AmbientOcclusion,
    point: DVec3,
    normal: DVec3,
    t: Real,
    footprint: Real,
) -> (f32, u64) {
    // One walk alone, estimate by estimate: the reference `occlusions`'
    // lanes are held to.
    let walk = OcclusionWalk::start(ao, 0, point, normal, t, footprint);
    crate::march::walk_one(Ok(walk), fractal, &MarchSettings::default()).1
}

/// `occlusion` at many surface points (index, point, normal, distance from
/// the camera, footprint), each an `OcclusionWalk`, walked side by side
/// (`march::walk_many`) so a point's few samples do not pay for a call of
/// the lane kernel of their own. `out(i, …)` gets point `i`'s, bit for bit
/// what it would get alone: each point sums its samples in order.
pub fn occlusions(
    fractal: &Fractal,
    ao: &AmbientOcclusion,
    points: impl IntoIterator<Item = (usize, DVec3, DVec3, Real, Real)>,
    mut out: impl FnMut(usize, (f32, u64)),
) {
    let walks = points.into_iter().map(|(i, point, normal, t, footprint)| {
        Ok(OcclusionWalk::start(ao, i, point, normal, t, footprint))
    });
    // `walk_many` needs no quality settings for these walks.
    let settings = MarchSettings::default();
    crate::march::walk_many(walks, fractal, &settings, |_, (i, found)| out(i, found));
}

/// One surface point's ambient occlusion (see `occlusions`): `samples`
/// estimates at evenly spaced distances along the normal, out to `radius`
/// times the camera distance, each weighing 0.6 of the one before.
#[derive(Clone, Copy, Debug)]
pub(super) struct OcclusionWalk {
    /// The point's index, handed back with its output.
    index: usize,
    point: DVec3,
    normal: DVec3,
    /// Distance from the camera, and the footprint there.
    t: Real,
    footprint: Real,
    radius: Real,
    strength: Real,
    /// The sample to take next, 1 to `n`, and how far along the normal it
    /// lies (`distance`).
    k: u32,
    n: u32,
    along: Real,
    blocked: Real,
    weights: Real,
    weight: Real,
    spent: u64,
}

impl OcclusionWalk {
    pub(super) fn start(
        ao: &AmbientOcclusion,
        index: usize,
        point: DVec3,
        normal: DVec3,
        t: Real,
        footprint: Real,
    ) -> OcclusionWalk {
        let mut walk = OcclusionWalk {
            index,
            point,
            normal,
            t,
            footprint,
            radius: ao.radius,
            strength: ao.strength as Real,
            k: 1,
            n: ao.samples.max(1),
            along: 0.0,
            blocked: 0.0,
            weights: 0.0,
            weight: 1.0,
            spent: 0,
        };
        walk.along = walk.distance();
        walk
    }

    /// How far along the normal sample `k` lies.
    pub(super) fn distance(&self) -> Real {
        self.radius * self.t * self.k as Real / self.n as Real
    }
}

impl crate::march::Walk for OcclusionWalk {
    type Output = (usize, (f32, u64));
    const READS_ORBIT: bool = false;

    fn next_point(&self) -> (DVec3, Real) {
        (self.point + self.normal * self.along, self.footprint)
    }

    fn advance(
        &mut self,
        e: &crate::fractal::Estimate,
        _: Real,
        _: &Fractal,
        _: &MarchSettings,
    ) -> Option<Self::Output> {
        let d = self.along;
        self.spent += e.orbits as u64;
        // Where the field is nearer than the distance stepped, geometry crowds
        // in. The estimate is about half the true distance near the surface
        // (the ½ in ½·ln r·r/dr, kept for safe marching), so double it here.
        self.blocked += self.weight * ((d - 2.0 * e.distance) / d).clamp(0.0, 1.0);
        self.weights += self.weight;
        self.weight *= 0.6;
        if self.k < self.n {
            self.k += 1;
            self.along = self.distance();
            return None;
        }
        let ambient = 1.0 - self.strength * self.blocked / self.weights;
        Some((self.index, (ambient.clamp(0.0, 1.0) as f32, self.spent)))
    }
}
