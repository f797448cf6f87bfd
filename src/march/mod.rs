//! Sphere tracing of the distance field: where a ray first meets the surface,
//! with a hit threshold that scales with the pixel footprint (distance × pixel
//! angle) so a zoom keeps the same detail at every scale, and surface normals
//! from the distance field. Marching is a `Walk` (a state machine between
//! estimates) so that `walk_many` can march 16 rays side by side through the
//! vector kernel, a new ray taking each lane as soon as its ray ends.
//!
//! Method: ../shared/seeds/004 (ray marching with signed distance bounds,
//! central-difference normals) and 001 (Christensen on the fudge factor).

// A walk that ends before its first step hands back its outcome, a hit's
// whole estimate wide, in place of the walk: once per ray, not worth a box.
#![allow(clippy::result_large_err)]

use crate::fractal::{Estimate, Fractal, TETRAHEDRON};
use crate::math::{sphere_interval, DVec3, Real};
use serde::{Deserialize, Serialize};

mod cone;
pub mod judge;
mod membership;
mod normal;
mod walk;

pub use cone::{
    cone_block, cone_blocks, march_camera_rays, run_spans, ConeScratch, CONE_BLOCK_ROWS, CONE_TRUST,
};
use membership::bisect_membership;
pub use membership::march_by_membership;
pub use normal::{normal, normals_many};
pub use walk::{walk_many, walk_one, Walk};

/// The marcher's quality knobs.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct MarchSettings {
    /// How near the surface a hit lands, as a fraction of the pixel footprint:
    /// with `membership_step`, the most a hit may lie short of the crossing;
    /// without it (0), the estimate under which a ray stops.
    pub hit_threshold: Real,
    /// Near the surface the estimate can understate the distance many times
    /// over, so a ray that trusts it stops short. Rays step at least this
    /// many footprints, test membership at each point and stop only inside
    /// the set, bisecting the crossing (`Marcher::advance`); 0 trusts the
    /// estimate and stops where it falls under `hit_threshold`.
    pub membership_step: Real,
    /// Each step advances by `fudge × estimate` (1 = trust the estimate fully).
    pub fudge: Real,
    /// Steps before a ray is given up as a miss.
    pub max_steps: u32,
    /// Finite-difference step for normals, as a fraction of the pixel footprint.
    pub normal_step: Real,
    /// Radius of the sphere that bounds the fractal; rays are marched only inside it.
    pub bounding_radius: Real,
    /// Over-relaxed sphere tracing (Keinert et al. 2014, "Enhanced Sphere
    /// Tracing"): steps of `over_relaxation × fudge × estimate` while the
    /// unbounding spheres of successive points overlap; where they do not,
    /// or the step lands inside the set, the step is taken back and the ray
    /// goes on at the plain step. 1 turns it off.
    pub over_relaxation: Real,
    /// Camera rays, a block of neighbouring pixels (`cone_block`: 16 is 4×4),
    /// that first march together along one cone holding them all, until
    /// the surface is within a pixel of the cone, and then go on alone
    /// (`march_camera_rays`); 1 marches every ray alone. Not used with
    /// glow, which needs each ray's nearest approach, nor with estimators
    /// other than the analytic one (`Scene::cone_rays`).
    pub cone_rays: u32,
    /// Plain steps a hit takes on towards the surface once the estimate
    /// falls under `hit_threshold`, while it keeps falling and until it is
    /// under a quarter of it: the threshold decides hit or miss, these bring
    /// the hit nearer the set (0 stops at the threshold).
    pub refine_steps: u32,
    /// Whether a hit the analytic estimate settles on is checked by the
    /// potential estimate (½·G/|∇G|, four more orbits): where that puts the
    /// set a threshold or more away, the ray grazes it and marches on.
    /// Left out of a scene's serialised form when off, so frames keep
    /// their hashes.
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub confirm_hits: bool,
    /// The bounding sphere's centre in the frame's coordinates: the world
    /// origin, or in a deep frame (measured from its anchor) minus the anchor.
    #[serde(skip)]
    pub centre: DVec3,
}

impl MarchSettings {
    /// Where `ray` enters and leaves the bounding sphere, if it meets it.
    #[inline]
    pub fn interval(&self, ray: &Ray) -> Option<(Real, Real)> {
        self.interval_from(ray.origin, ray.dir)
    }

    /// Where the ray from `origin` along `dir` enters and leaves the
    /// bounding sphere, if it meets it.
    #[inline]
    pub fn interval_from(&self, origin: DVec3, dir: DVec3) -> Option<(Real, Real)> {
        sphere_interval(origin - self.centre, dir, self.bounding_radius)
    }

    /// The plain step an estimate allows: `fudge` times the estimate, no
    /// longer than the bounding sphere is wide.
    #[inline]
    pub fn step(&self, distance: Real) -> Real {
        distance.min(self.bounding_radius * 2.0) * self.fudge
    }
}

impl Default for MarchSettings {
    fn default() -> Self {
        MarchSettings {
            hit_threshold: 0.5,
            membership_step: 0.0,
            fudge: 1.0,
            max_steps: 300,
            normal_step: 0.5,
            bounding_radius: 1.5,
            over_relaxation: 1.2,
            cone_rays: 16,
            refine_steps: 2,
            confirm_hits: false,
            centre: DVec3::ZERO,
        }
    }
}

/// A ray through a pixel: origin, unit direction, and the angle one pixel subtends.
#[derive(Clone, Copy, Debug)]
pub struct Ray {
    pub origin: DVec3,
    pub dir: DVec3,
    pub pixel_angle: Real,
    /// Width of the cone where the ray starts: 0 for camera rays; for a ray
    /// leaving a surface, the camera pixel's width there, so secondary rays
    /// resolve no finer than the pixel they serve.
    pub start_footprint: Real,
}

impl Ray {
    /// The point at distance `t` along the ray.
    #[inline]
    pub fn at(&self, t: Real) -> DVec3 {
        self.origin + self.dir * t
    }

    /// Width of one pixel's cone at distance `t` along the ray.
    #[inline]
    pub fn footprint(&self, t: Real) -> Real {
        // A floor keeps the threshold non-zero for a camera sitting on the
        // surface; the least normal f64, so deep frames keep their pixels.
        (self.start_footprint + t * self.pixel_angle).max(Real::MIN_POSITIVE)
    }
}

/// Where a ray met the surface.
#[derive(Clone, Copy, Debug)]
pub struct Hit {
    pub t: Real,
    pub point: DVec3,
    pub estimate: Estimate,
}

/// Outcome of marching one ray, with the orbits it computed.
#[derive(Clone, Copy, Debug)]
pub struct MarchResult {
    pub hit: Option<Hit>,
    pub evaluations: u32,
    /// Smallest estimate along the ray, in pixel footprints (∞ when nothing
    /// was estimated): how near a miss came, for glow.
    pub closest: Real,
    /// The march ran out of `max_steps`; its hit is the nearest point it
    /// had under the threshold, else the hit that failed its check
    /// (`confirm_hits`), else where it stopped.
    pub out_of_steps: bool,
}

impl Default for MarchResult {
    /// A miss that estimated nothing.
    fn default() -> Self {
        MarchResult {
            hit: None,
            evaluations: 0,
            closest: Real::INFINITY,
            out_of_steps: false,
        }
    }
}

/// Sphere-traces `ray` against `fractal` inside the bounding sphere.
///
/// Every estimate also tells whether its point is inside the set (its orbit
/// stayed bounded). A step that lands inside has overshot the surface (an
/// estimator that overestimates, or a fudge too large for a thin feature); the
/// crossing is then found by bisecting membership between the last point
/// outside and that one, so the hit never lies past the surface by more than
/// the hit threshold.
pub fn march(ray: &Ray, fractal: &Fractal, settings: &MarchSettings) -> MarchResult {
    walk_one(Marcher::start(ray, settings), fractal, settings)
}

/// Marches many rays side by side (`walk_many`): `results[i]` is
/// bit-identical to `march(&rays[i], ..)`.
pub fn march_many(
    rays: &[Ray],
    fractal: &Fractal,
    settings: &MarchSettings,
    results: &mut [MarchResult],
) {
    debug_assert_eq!(rays.len(), results.len());
    let walks = rays.iter().map(|ray| Marcher::start(ray, settings));
    walk_many(walks, fractal, settings, |i, result| results[i] = result);
}

/// One ray's march between estimates: where to estimate next, and what to
/// do with the estimate. `march` and `march_many` both drive it, so the
/// two cannot step differently.
#[derive(Clone, Copy)]
struct Marcher {
    ray: Ray,
    t: Real,
    t_exit: Real,
    /// The last point found outside the set. Only its distance along the
    /// ray: its estimate is needed only after an overshoot (rare), and
    /// then taken again, which is cheaper than keeping every step's.
    outside: Option<Real>,
    omega: Real,
    previous_distance: Real,
    previous_step: Real,
    steps: u32,
    evaluations: u32,
    closest: Real,
    /// Once the estimate falls under the hit threshold: the nearest point
    /// so far and its estimate, and the plain steps taken on from it
    /// (`Marcher::refine`).
    nearest: Option<(Real, Estimate)>,
    refined: u32,
    /// A hit being confirmed (`Marcher::confirm`).
    check: Option<Check>,
    /// Set when a hit failed its check: until the estimate rises over the
    /// threshold again, only a `REFINED` estimate stops the ray.
    passing: bool,
    /// The first hit that failed its check: a ray that then runs out of
    /// steps stops there, or at a later `nearest`, not wherever it crept to.
    grazed: Option<(Real, Estimate)>,
}

/// The potential estimate's check of the hit at `Marcher::nearest`: the
/// stencil's samples so far, and the step the ray goes on by if it fails.
#[derive(Clone, Copy)]
struct Check {
    sampled: u8,
    /// A sample in the set: the set is within the stencil, so it confirms.
    inside: bool,
    gradient: DVec3,
    resume: Real,
}

/// Bumped whenever a change alters the frames of scenes that check hits
/// (`confirm_hits`), so resume re-renders those and no others.
pub const CONFIRM_REVISION: u32 = 1;

/// The offset along each axis of the potential check's stencil points, in
/// footprints of the hit.
const STENCIL: Real = 0.25;

/// Whether the potential check's stencil around `point`, a `footprint`
/// wide, stands above f64's noise there (the potential estimator's own
/// floor), so a hit there can be checked (`MarchSettings::confirm_hits`).
pub(crate) fn check_resolves(footprint: Real, point: DVec3) -> bool {
    STENCIL * footprint > Real::EPSILON.sqrt() * point.length().max(1e-3)
}

/// A refined hit stops stepping once the estimate is under this share of
/// the hit threshold (`MarchSettings::refine_steps`).
const REFINED: Real = 0.25;

impl Marcher {
    /// Starts at the bounding sphere, or the miss of a ray that passes it by.
    fn start(ray: &Ray, settings: &MarchSettings) -> Result<Marcher, MarchResult> {
        Marcher::start_in(ray, settings, settings.interval(ray), 0.0)
    }

    /// `start` with the ray's bounding-sphere `interval` already known, and
    /// no nearer than `t_free`: the ray is known to meet no surface before
    /// it (a cone around it was marched that far).
    fn start_in(
        ray: &Ray,
        settings: &MarchSettings,
        interval: Option<(Real, Real)>,
        t_free: Real,
    ) -> Result<Marcher, MarchResult> {
        let Some((t_enter, t_exit)) = interval else {
            return Err(MarchResult::default());
        };
        let t_enter = t_enter.max(t_free);
        if t_enter > t_exit {
            return Err(MarchResult::default());
        }
        Ok(Marcher {
            ray: *ray,
            t: t_enter,
            t_exit,
            outside: None,
            omega: settings.over_relaxation,
            previous_distance: 0.0,
            previous_step: 0.0,
            steps: 0,
            evaluations: 0,
            closest: Real::INFINITY,
            nearest: None,
            refined: 0,
            check: None,
            passing: false,
            grazed: None,
        })
    }

    /// Replaces the last over-relaxed step by the plain one and stops
    /// over-relaxing.
    /// Whether the last step was longer than its estimate vouched for.
    fn relaxed(&self) -> bool {
        self.previous_step > self.previous_distance
    }

    fn take_back(&mut self) {
        self.t += self.previous_distance - self.previous_step;
        self.previous_step = self.previous_distance;
        self.omega = 1.0;
    }

    /// A ray whose estimate is under the hit threshold (`near`) or was:
    /// the hit at the nearest point so far, or `None` to step on by the
    /// plain step towards the surface, while the estimate keeps falling
    /// and is not yet `REFINED` of the threshold. A grazing ray whose
    /// estimate rises again keeps the hit it had.
    fn refine(
        &mut self,
        estimate: &Estimate,
        near: bool,
        footprint: Real,
        settings: &MarchSettings,
        fractal: &Fractal,
    ) -> Option<MarchResult> {
        let t = self.t;
        let nearer = self
            .nearest
            .is_none_or(|(_, e)| estimate.distance < e.distance);
        if near && nearer {
            self.nearest = Some((t, *estimate));
        }
        self.nearest?;
        let fine = estimate.distance < REFINED * settings.hit_threshold * footprint;
        let step = settings.step(estimate.distance);
        if !(near && nearer) || fine || self.refined >= settings.refine_steps {
            return self.confirm(step, fractal, settings);
        }
        self.refined += 1;
        self.outside = Some(t);
        (self.previous_distance, self.previous_step) = (step, step);
        self.t += step;
        if self.t > self.t_exit {
            return self.confirm(step, fractal, settings);
        }
        None
    }

    /// The hit at the nearest point, or, where `confirm_hits` asks and the
    /// estimate there was not yet `REFINED`, the start of its check: the
    /// next four points are the potential's tetrahedral stencil around it
    /// (`checked`). `resume` is the step the ray goes on by if it fails.
    fn confirm(
        &mut self,
        resume: Real,
        fractal: &Fractal,
        settings: &MarchSettings,
    ) -> Option<MarchResult> {
        let (t, estimate) = self.nearest.expect("a hit to confirm");
        if !settings.confirm_hits {
            return Some(self.hit(t, estimate));
        }
        let footprint = self.ray.footprint(t);
        let resolved = check_resolves(footprint, self.ray.at(t));
        let coarse = estimate.distance >= REFINED * settings.hit_threshold * footprint;
        // A check failed at the last step would stop, out of steps, at
        // this same hit: skip its four orbits.
        let last = self.steps >= settings.max_steps;
        if self.passing || last || !coarse || !resolved || !fractal.plain_analytic() {
            return Some(self.hit(t, estimate));
        }
        self.check = Some(Check {
            sampled: 0,
            inside: false,
            gradient: DVec3::ZERO,
            resume,
        });
        None
    }

    /// Takes the estimate at the check's next stencil point; after the
    /// fourth, the hit, or the ray marching on past a set the potential
    /// estimate puts a threshold or more away.
    fn checked(
        &mut self,
        sample: &Estimate,
        fractal: &Fractal,
        settings: &MarchSettings,
    ) -> Option<MarchResult> {
        let mut check = self.check.take().expect("a check under way");
        self.evaluations += sample.orbits;
        check.gradient += TETRAHEDRON[check.sampled as usize] * sample.potential(fractal.power);
        check.inside |= !sample.escaped;
        check.sampled += 1;
        if (check.sampled as usize) < TETRAHEDRON.len() {
            self.check = Some(check);
            return None;
        }
        let (t, estimate) = self.nearest.expect("the hit under the check");
        let footprint = self.ray.footprint(t);
        let slope = check.gradient.length() / (4.0 * STENCIL * footprint);
        let distance = 0.5 * estimate.potential(fractal.power) / slope;
        // A slope of 0 or ∞ cannot judge.
        let grazes = !check.inside
            && slope.is_finite()
            && slope > 0.0
            && distance >= settings.hit_threshold * footprint;
        if !grazes {
            return Some(self.hit(t, estimate));
        }
        self.passing = true;
        self.grazed = self.grazed.or(self.nearest);
        self.nearest = None;
        self.refined = 0;
        self.outside = Some(self.t);
        (self.previous_distance, self.previous_step) = (check.resume, check.resume);
        self.t += check.resume;
        if self.t > self.t_exit {
            return Some(self.miss());
        }
        None
    }

    fn miss(&self) -> MarchResult {
        MarchResult {
            hit: None,
            evaluations: self.evaluations,
            closest: self.closest,
            out_of_steps: false,
        }
    }

    fn hit(&self, t: Real, estimate: Estimate) -> MarchResult {
        MarchResult {
            hit: Some(Hit {
                t,
                point: self.ray.at(t),
                estimate,
            }),
            evaluations: self.evaluations,
            closest: self.closest,
            out_of_steps: false,
        }
    }
}

impl Walk for Marcher {
    type Output = MarchResult;
    // A hit carries its estimate's traps and end to shading.
    const READS_ORBIT: bool = true;

    fn next_point(&self) -> (DVec3, Real) {
        if let (Some(check), Some((t, _))) = (&self.check, self.nearest) {
            let footprint = self.ray.footprint(t);
            let at = self.ray.at(t) + TETRAHEDRON[check.sampled as usize] * (STENCIL * footprint);
            return (at, footprint);
        }
        (self.ray.at(self.t), self.ray.footprint(self.t))
    }

    fn advance(
        &mut self,
        estimate: &Estimate,
        footprint: Real,
        fractal: &Fractal,
        settings: &MarchSettings,
    ) -> Option<MarchResult> {
        if self.check.is_some() {
            return self.checked(estimate, fractal, settings);
        }
        let (t, ray) = (self.t, self.ray);
        self.evaluations += estimate.orbits;
        if self.steps == settings.max_steps {
            // Out of steps inside the bounding sphere: the ray is creeping
            // along a surface it keeps almost touching (a grazing ray).
            // Calling that a miss punches background-coloured speckles into
            // the surface; call it a hit, and count it.
            let (t, estimate) = self.nearest.or(self.grazed).unwrap_or((t, *estimate));
            return Some(MarchResult {
                out_of_steps: true,
                ..self.hit(t, estimate)
            });
        }
        self.steps += 1;
        self.closest = self.closest.min(estimate.distance / footprint);
        // An over-relaxed step holds only where this point's free space
        // reaches back to cover its relaxed part: where the spheres do not
        // overlap it may have jumped over surface, and where it landed
        // inside, that part may hold several crossings, of which bisecting
        // would find any, not the first. Go from the last point by the plain
        // step instead, without relaxation.
        let covers = |e: &Estimate| {
            e.escaped && self.previous_distance + settings.fudge * e.distance >= self.previous_step
        };
        if self.relaxed() && !covers(estimate) {
            self.take_back();
            return None;
        }
        if !estimate.escaped {
            if let Some(t_out) = self.outside {
                // Overshot: bisect [outside, t (inside)] down to the threshold.
                let at = |t: Real| ray.at(t);
                let (lo, tests) = bisect_membership(fractal, &at, t_out, t, |lo| {
                    settings.hit_threshold * ray.footprint(lo)
                });
                self.evaluations += tests;
                let estimate = fractal.estimate(at(lo), ray.footprint(lo));
                self.evaluations += estimate.orbits;
                self.closest = 0.0;
                return Some(self.hit(lo, estimate));
            }
        }
        // Inside from the start (the camera is in the set), or, trusting
        // the estimate, near enough.
        let near = estimate.distance < settings.hit_threshold * footprint;
        self.passing &= near;
        let trusted = settings.membership_step <= 0.0
            && near
            && !(self.passing && estimate.distance >= REFINED * settings.hit_threshold * footprint);
        if !estimate.escaped {
            return Some(self.hit(t, *estimate));
        }
        if trusted || self.nearest.is_some() {
            return self.refine(estimate, trusted, footprint, settings, fractal);
        }
        self.outside = Some(t);
        let step = settings.step(estimate.distance);
        let floor = settings.membership_step * footprint;
        // The over-relaxed step is checked at the next point (or, leaving the
        // bounding sphere, by retrying the plain step); a plain step is safe.
        // A step up to the floor is not: membership at the next point checks it.
        self.previous_distance = step.max(floor);
        self.previous_step = if step < floor {
            floor
        } else {
            step * self.omega
        };
        self.t += self.previous_step;
        if self.t > self.t_exit && self.relaxed() {
            self.take_back();
        }
        if self.t > self.t_exit {
            return Some(self.miss());
        }
        None
    }
}

#[cfg(test)]
mod tests;
