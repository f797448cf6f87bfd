//! Timing: how many runs of a frame a variant gets, and their median wall time.

use crate::render::{render_frame, Film};
use crate::scene::Scene;
use std::time::Instant;

/// Timed runs per variant: more while the variant has had under
/// `TIMING_BUDGET_SECONDS`, at most `MAX_TIMED_RUNS`; at least
/// `MIN_TIMED_RUNS` where they fit in `SLOW_BUDGET_SECONDS`, so a slow
/// frame is not rendered five times over.
pub const MIN_TIMED_RUNS: usize = 5;
pub const MAX_TIMED_RUNS: usize = 21;
pub(super) const TIMING_BUDGET_SECONDS: f64 = 0.3;
pub(super) const SLOW_BUDGET_SECONDS: f64 = 3.0;

/// Renders `scene` and returns the film with the median wall time of
/// several runs. The median, not the fastest run: a single lucky run of a
/// 15 ms frame would move variants on and off the Pareto front.
pub(super) fn timed_render(
    scene: &Scene,
    frame_index: u32,
    width: u32,
    height: u32,
) -> (Film, f64) {
    let mut seconds = Vec::with_capacity(MAX_TIMED_RUNS);
    let mut film = None;
    let started = Instant::now();
    let more = |runs: usize, elapsed: f64| {
        runs == 0
            || (runs < MAX_TIMED_RUNS && elapsed < TIMING_BUDGET_SECONDS)
            || (runs < MIN_TIMED_RUNS && elapsed < SLOW_BUDGET_SECONDS)
    };
    while more(seconds.len(), started.elapsed().as_secs_f64()) {
        let t0 = Instant::now();
        let f = render_frame(scene, frame_index, width, height, &|| {});
        seconds.push(t0.elapsed().as_secs_f64());
        film = Some(f);
    }
    (
        film.expect("rendered at least once"),
        crate::math::median(&mut seconds),
    )
}
