//! The accuracy reference: a march by membership tests and bisection that
//! trusts no distance estimate.

use super::{MarchSettings, Ray};
use crate::fractal::Fractal;
use crate::math::{DVec3, Real};

/// Where `ray` first enters the set, found without trusting any distance
/// estimate: steps of `step_fraction` of a pixel footprint (never below
/// `min_step`) testing membership (does the orbit stay under the bailout?),
/// then bisection of the crossing to a thousandth of the footprint. The
/// accuracy reference; far slower than `march`. Gives up after `max_tests`
/// membership tests. Returns the crossing and the tests spent.
pub fn march_by_membership(
    ray: &Ray,
    fractal: &Fractal,
    settings: &MarchSettings,
    step_fraction: Real,
    min_step: Real,
    max_tests: u32,
) -> (Option<Real>, u32) {
    let Some((t_enter, t_exit)) = settings.interval(ray) else {
        return (None, 0);
    };
    let at = |t: Real| ray.at(t);
    let mut tests = 1;
    if fractal.contains(at(t_enter)) {
        return (Some(t_enter), tests);
    }
    let mut t = t_enter;
    while tests < max_tests {
        let next = t + (step_fraction * ray.footprint(t)).max(min_step);
        tests += 1;
        if fractal.contains(at(next)) {
            let (lo, bisections) =
                bisect_membership(fractal, &at, t, next, |lo| 1e-3 * ray.footprint(lo));
            return (Some(lo), tests + bisections);
        }
        if next > t_exit {
            return (None, tests);
        }
        t = next;
    }
    (None, tests)
}

/// Bisects [`lo` (outside the set), `hi` (inside)] by membership until the
/// interval is narrower than `width(lo)` or cannot be split; returns the
/// last point outside and the membership tests spent.
pub(super) fn bisect_membership(
    fractal: &Fractal,
    at: &impl Fn(Real) -> DVec3,
    mut lo: Real,
    mut hi: Real,
    width: impl Fn(Real) -> Real,
) -> (Real, u32) {
    let mut tests = 0;
    while hi - lo > width(lo) {
        let mid = 0.5 * (lo + hi);
        if !(lo < mid && mid < hi) {
            break; // the interval cannot be split any further
        }
        tests += 1;
        if fractal.contains(at(mid)) {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    (lo, tests)
}
