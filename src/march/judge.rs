//! How near a hit lies to the set, judged by membership tests alone: the 3D
//! distance to the nearest point of the set, and how deep past the first
//! point of the set along its ray it lies. The measure of docs/surface.md.

use super::{MarchSettings, Ray};
use crate::fractal::Fractal;
use crate::math::{sample_1d, DVec3, Real};

/// The most points `past_the_set` tests on one ray.
const MOST_STEPS: u32 = 1 << 24;

/// Ball radii searched for the set around a hit, in footprints.
pub const BALLS: [Real; 6] = [0.25, 0.5, 1.0, 2.0, 4.0, 8.0];

/// The distance from `p` to the nearest of `samples` uniform samples of
/// the set in the smallest ball of `BALLS` (times `footprint`) that holds
/// one, in footprints; None where none does. An upper bound that tightens
/// with `samples`; `seed` makes it repeat exactly.
pub fn distance_to_set(
    fractal: &Fractal,
    p: DVec3,
    footprint: Real,
    samples: usize,
    seed: u64,
) -> Option<Real> {
    let mut drawn = 0u32;
    let mut next = || {
        drawn += 1;
        2.0 * sample_1d(seed, 0, 0, drawn, 0) - 1.0
    };
    BALLS.iter().find_map(|&radius| {
        let mut nearest = Real::INFINITY;
        let mut taken = 0;
        while taken < samples {
            let q = DVec3::new(next(), next(), next());
            if q.length_squared() > 1.0 {
                continue;
            }
            taken += 1;
            let length = q.length();
            if length < nearest && fractal.contains(p + q * (radius * footprint)) {
                nearest = length;
            }
        }
        nearest.is_finite().then_some(nearest * radius)
    })
}

/// How far the hit at `hit` on `ray` lies past the first point of the set
/// along it, in footprints of the hit: 0 where a scan in steps of `step`
/// footprints from where the ray enters the bounding sphere meets none
/// before it. Near the camera, where a footprint shrinks to nothing, it
/// steps no finer than at a hundredth of the hit's distance; it gives up
/// (0) after `MOST_STEPS` points.
pub fn past_the_set(
    fractal: &Fractal,
    settings: &MarchSettings,
    ray: &Ray,
    hit: Real,
    step: Real,
) -> Real {
    let enter = settings.interval(ray).map_or(0.0, |(enter, _)| enter);
    let mut t = enter.max(0.0);
    // At most `MOST_STEPS`, and never a step lost to rounding (a deep
    // frame's footprint may be below t's ulp): the scan always ends.
    for _ in 0..MOST_STEPS {
        if t >= hit {
            break;
        }
        if fractal.contains(ray.at(t)) {
            return (hit - t) / ray.footprint(hit);
        }
        let dt = step * ray.footprint(t.max(0.01 * hit));
        t += dt.max(4.0 * Real::EPSILON * t.abs());
    }
    0.0
}

/// How far along the unit `dir` from `origin` the set begins: membership
/// steps of `step`, then bisection to the last bit of f64. Only for an
/// `origin` outside the set whose ray meets it.
pub fn surface_along(fractal: &Fractal, origin: DVec3, dir: DVec3, step: Real) -> Real {
    let mut lo = 0.0;
    while !fractal.contains(origin + dir * (lo + step)) {
        lo += step;
    }
    let mut hi = lo + step;
    for _ in 0..80 {
        let mid = 0.5 * (lo + hi);
        if fractal.contains(origin + dir * mid) {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    lo
}

/// Root-mean-square distance of an `n`×`n` grid's depths (row by row, as
/// (depth, footprint)) from the plane that fits them best, in footprints:
/// how far a block of hits departs from the smooth surface it samples.
pub fn depth_off_plane(hits: &[(Real, Real)], n: u32) -> Real {
    // Least squares of t = a + b·x + c·y over a full grid: x and y are
    // centred, so the three coefficients separate.
    let m = (n as Real - 1.0) / 2.0;
    let at = |i: usize| ((i as u32 % n) as Real - m, (i as u32 / n) as Real - m);
    let count = hits.len() as Real;
    let a = hits.iter().map(|h| h.0).sum::<Real>() / count;
    let sxx: Real = (0..hits.len()).map(|i| at(i).0.powi(2)).sum();
    let slope = |axis: fn((Real, Real)) -> Real| {
        hits.iter()
            .enumerate()
            .map(|(i, h)| axis(at(i)) * h.0)
            .sum::<Real>()
            / sxx
    };
    let (b, c) = (slope(|x| x.0), slope(|x| x.1));
    let squares: Real = hits
        .iter()
        .enumerate()
        .map(|(i, h)| ((h.0 - a - b * at(i).0 - c * at(i).1) / h.1).powi(2))
        .sum();
    (squares / count).sqrt()
}
