//! The walk between estimates that one ray, or 16 side by side through
//! the vector kernel, is driven by.

use super::MarchSettings;
use crate::fractal::{Estimate, Fractal, VECTOR};
use crate::math::{DVec3, Real};

/// A walk along a ray driven by distance estimates, one at a time: sphere
/// tracing, a shadow ray. `walk_one` and `walk_many` both drive it, so a walk
/// takes the same steps whichever does.
pub trait Walk: Copy {
    type Output;
    /// Whether `advance` reads an estimate's orbit traps or the end of its
    /// orbit. `walk_many` takes estimates without them for walks that do
    /// not (`Fractal::distance_lanes_into`), which the kernel works out
    /// faster.
    const READS_ORBIT: bool;
    /// The point to estimate next and its pixel footprint.
    fn next_point(&self) -> (DVec3, Real);
    /// Takes the estimate at `next_point` (and its footprint, as
    /// `next_point` gave it); the output once the walk ends.
    fn advance(
        &mut self,
        estimate: &Estimate,
        footprint: Real,
        fractal: &Fractal,
        settings: &MarchSettings,
    ) -> Option<Self::Output>;
}

/// Drives one walk (or returns the output it started with) to its end.
pub fn walk_one<W: Walk>(
    walk: Result<W, W::Output>,
    fractal: &Fractal,
    settings: &MarchSettings,
) -> W::Output {
    let mut walk = match walk {
        Ok(walk) => walk,
        Err(done) => return done,
    };
    loop {
        let (point, footprint) = walk.next_point();
        if let Some(done) = walk.advance(
            &fractal.estimate(point, footprint),
            footprint,
            fractal,
            settings,
        ) {
            return done;
        }
    }
}

/// Drives many walks, `VECTOR` at a time (one call of the lane kernel): each step's estimates are taken
/// side by side through `Fractal::estimate_lanes_into` (`distance_lanes_into`
/// for walks that do not read the orbit), and a lane whose walk
/// ends takes the next walk at once, so the lanes stay full. Each walk's
/// output, bit-identical to `walk_one`'s, goes to `done` with its index
/// (walks that end at the start included), in the order walks end.
pub fn walk_many<W: Walk>(
    walks: impl IntoIterator<Item = Result<W, W::Output>>,
    fractal: &Fractal,
    settings: &MarchSettings,
    mut done: impl FnMut(usize, W::Output),
) {
    let mut walks = walks.into_iter().enumerate();
    let mut lanes: [Option<(usize, W)>; VECTOR] = [None; VECTOR];
    let mut estimates = [Estimate::IDLE; VECTOR];
    loop {
        for lane in lanes.iter_mut().filter(|lane| lane.is_none()) {
            for (i, walk) in walks.by_ref() {
                match walk {
                    Ok(walk) => {
                        *lane = Some((i, walk));
                        break;
                    }
                    Err(output) => done(i, output),
                }
            }
        }
        if lanes.iter().all(Option::is_none) {
            return;
        }
        // Idle lanes estimate a point outside the bailout ball: no iterations.
        let mut points = [crate::fractal::IDLE_POINT; VECTOR];
        let mut footprints = [1.0; VECTOR];
        for ((lane, point), footprint) in lanes.iter().zip(&mut points).zip(&mut footprints) {
            if let Some((_, walk)) = lane {
                (*point, *footprint) = walk.next_point();
            }
        }
        if W::READS_ORBIT {
            fractal.estimate_lanes_into(&points, &footprints, &mut estimates);
        } else {
            fractal.distance_lanes_into(&points, &footprints, &mut estimates);
        }
        for ((lane, estimate), &footprint) in lanes.iter_mut().zip(&estimates).zip(&footprints) {
            if let Some((i, walk)) = lane {
                if let Some(output) = walk.advance(estimate, footprint, fractal, settings) {
                    done(*i, output);
                    *lane = None;
                }
            }
        }
    }
}
