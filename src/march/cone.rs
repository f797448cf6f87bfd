//! Cones: one march shared by a block of neighbouring camera rays until
//! the surface is near enough that each ray must go on alone.

use super::{march_many, walk_many, MarchResult, MarchSettings, Marcher, Ray, Walk};
use crate::fractal::{Estimate, Fractal};
use crate::math::{normalize_or, DVec3, Real};

/// The share of an estimate a cone trusts. A cone's overshoot would put
/// every ray of its block past the surface, and a cone over a 4×4 block
/// goes on nearer the surface than one over a run along a row, where the
/// analytic estimate can overstate the distance: for a power-3 Julia set
/// a 4×4 cone trusting the whole estimate started a corner ray 0.27
/// footprints past the surface (`a_cone_never_starts_a_ray_past_the_surface`).
/// At 0.9 it costs S1 5% more primary estimates and no measurable time.
pub const CONE_TRUST: Real = 0.9;

/// The most image rows a block of cone rays spans (`cone_block`): the
/// renderer takes rows this many at a time.
pub const CONE_BLOCK_ROWS: usize = 4;

/// The block of pixels (columns, rows) whose camera rays share a cone, for
/// `n` rays a cone: of the shapes 1, 2 or 4 rows high (so blocks tile a
/// band of `CONE_BLOCK_ROWS`), the one with the shortest diagonal, whose
/// rays stay nearest the cone's axis; on a tie the one with fewer rows.
pub fn cone_block(n: u32) -> (usize, usize) {
    let n = n.max(1) as usize;
    // Row counts that divide a band, and `n`; 1 always does.
    let rows = (1..=CONE_BLOCK_ROWS)
        .filter(|&rows| CONE_BLOCK_ROWS.is_multiple_of(rows) && n.is_multiple_of(rows))
        .min_by_key(|&rows| (n / rows).pow(2) + rows * rows)
        .expect("one row divides everything");
    (n / rows, rows)
}

/// The `rows`×`w` pixels of a band (as offsets into its sums, row after
/// row) into `order` block by block, `block` (columns, rows) at a time:
/// down the band's groups of block rows, across each group a block after
/// another, each block's pixels row by row; `runs` gets each block's size
/// (narrower at the right edge, lower in a short band). A block's camera
/// rays march one cone (`march_camera_rays`).
pub fn cone_blocks(
    w: usize,
    rows: usize,
    (bw, bh): (usize, usize),
    order: &mut Vec<usize>,
    runs: &mut Vec<u32>,
) {
    order.clear();
    runs.clear();
    for y in (0..rows).step_by(bh) {
        let gh = bh.min(rows - y);
        for x in (0..w).step_by(bw) {
            let gw = bw.min(w - x);
            for yy in y..y + gh {
                order.extend(yy * w + x..yy * w + x + gw);
            }
            runs.push((gw * gh) as u32);
        }
    }
}

/// Camera rays marched as `march_many` does, but each run of neighbours
/// (`runs`: the lengths of consecutive runs of `rays`, summing to its
/// length) first shares one march along a cone that holds them all
/// (`ConeWalk`): the stretch where the surface is still far off compared
/// with the run's width is walked once for the run, and each ray starts
/// where the cone stopped. The cone's estimates are shared out over the
/// run's rays. `scratch` is kept by the caller from call to call. A run of
/// one ray (a block cut to one pixel at a band's corner) has no cone: that
/// ray marches alone, bit for bit as `march` would.
pub fn march_camera_rays(
    rays: &[Ray],
    fractal: &Fractal,
    settings: &MarchSettings,
    runs: &[u32],
    results: &mut [MarchResult],
    scratch: &mut ConeScratch,
) {
    debug_assert_eq!(rays.len(), results.len());
    debug_assert_eq!(runs.iter().map(|&n| n as usize).sum::<usize>(), rays.len());
    if runs.iter().all(|&n| n == 1) {
        return march_many(rays, fractal, settings, results);
    }
    let ConeScratch { intervals, free } = scratch;
    // Each ray's way through the bounding sphere, once: the cones and the
    // rays after them both start from it.
    intervals.clear();
    intervals.extend(rays.iter().map(|ray| settings.interval(ray)));
    let intervals = &*intervals;
    let spans = || run_spans(runs);
    free.clear();
    free.resize(runs.len(), (0.0, 0));
    let cones = spans().map(|span| ConeWalk::start(&rays[span.clone()], &intervals[span]));
    walk_many(cones, fractal, settings, |i, out| free[i] = out);
    // Each ray from where its run's cone stopped, in order (`walk_many`
    // numbers the walks as they come).
    let walks = spans().zip(free.iter()).flat_map(|(span, &(t_free, _))| {
        span.map(move |i| Marcher::start_in(&rays[i], settings, intervals[i], t_free))
    });
    walk_many(walks, fractal, settings, |i, result| results[i] = result);
    // Each ray of a run takes its share of the cone's estimates (the first
    // ones one more while there is a remainder), so the frame's total and
    // the per-pixel cost map both hold them.
    for (span, &(_, evaluations)) in spans().zip(free.iter()) {
        let results = &mut results[span];
        let n = results.len() as u32;
        for (k, r) in results.iter_mut().enumerate() {
            r.evaluations += evaluations / n + u32::from((k as u32) < evaluations % n);
        }
    }
}

/// The indices of each run of `runs` (the lengths of consecutive runs).
pub fn run_spans(runs: &[u32]) -> impl Iterator<Item = std::ops::Range<usize>> + '_ {
    runs.iter().scan(0, |start, &n| {
        let span = *start..*start + n as usize;
        *start = span.end;
        Some(span)
    })
}

/// `march_camera_rays`' scratch space: each ray's bounding-sphere interval;
/// for each run, where its rays may start and what its cone cost.
#[derive(Default)]
pub struct ConeScratch {
    intervals: Vec<Option<(Real, Real)>>,
    free: Vec<(Real, u32)>,
}

/// A march along the axis of a cone that holds a run of rays: each step
/// is the share of the estimate it trusts (`CONE_TRUST`) less how far the
/// farthest ray can be from the axis point there, shortened by how much
/// further the rays spread over the step, so every ray's own path to the
/// next point stays inside the ball the estimate clears (with a fudge of 1
/// too). It stops where that shared step falls below a pixel footprint (the
/// rays must go on alone), where every ray has left the bounding sphere,
/// or, a step back, at a point inside the set. The axis runs between the
/// run's first and last rays, the centre of a block when those are its
/// opposite corners, as `cone_blocks` orders them; any run is safe,
/// since the spread is taken over all its rays.
#[derive(Clone, Copy)]
pub(super) struct ConeWalk {
    /// The cone's axis, with the run's first ray's footprint.
    axis: Ray,
    /// A ray of the run is at most `spread.0 + t · spread.1` from the axis
    /// point at the same `t`.
    spread: (Real, Real),
    t: Real,
    /// Where the walk was before its last step.
    previous: Real,
    t_end: Real,
    steps: u32,
    evaluations: u32,
}

impl ConeWalk {
    /// The cone of `run` (rays from nearly one point, in nearly one
    /// direction, with their bounding-sphere `intervals`), from where the
    /// first of them enters the bounding sphere; the walk's output, 0 and
    /// no estimates, if none does or if the run is a single ray.
    pub(super) fn start(
        run: &[Ray],
        intervals: &[Option<(Real, Real)>],
    ) -> Result<ConeWalk, (Real, u32)> {
        if run.len() == 1 {
            return Err((0.0, 0)); // a ray alone has no cone to share
        }
        let (first, last) = (run[0], run[run.len() - 1]);
        let origin = (first.origin + last.origin) * 0.5;
        let dir = normalize_or(first.dir + last.dir, first.dir);
        let mut spread: (Real, Real) = (0.0, 0.0);
        let mut t_start = Real::INFINITY;
        let mut t_end: Real = 0.0;
        for (ray, interval) in run.iter().zip(intervals) {
            spread.0 = spread.0.max(crate::math::length(ray.origin - origin));
            spread.1 = spread.1.max((ray.dir - dir).length());
            if let Some((enter, exit)) = *interval {
                t_start = t_start.min(enter);
                t_end = t_end.max(exit);
            }
        }
        if !t_start.is_finite() {
            return Err((0.0, 0)); // every ray of the run misses the sphere
        }
        Ok(ConeWalk {
            axis: Ray {
                origin,
                dir,
                ..first
            },
            spread,
            t: t_start,
            previous: t_start,
            t_end,
            steps: 0,
            evaluations: 0,
        })
    }
}

impl Walk for ConeWalk {
    type Output = (Real, u32);
    const READS_ORBIT: bool = false;

    fn next_point(&self) -> (DVec3, Real) {
        (self.axis.at(self.t), self.axis.footprint(self.t))
    }

    fn advance(
        &mut self,
        estimate: &Estimate,
        footprint: Real,
        _: &Fractal,
        settings: &MarchSettings,
    ) -> Option<(Real, u32)> {
        self.evaluations += estimate.orbits;
        self.steps += 1;
        if !estimate.escaped {
            // Inside the set: an estimate overshot. The rays start from the
            // last point the cone stepped from, and find the crossing alone.
            return Some((self.previous, self.evaluations));
        }
        // Over a step s a ray drifts s·spread.1 further from the axis while
        // the axis point moves s: a ray's point at t + s is within
        // reach + s·(1 + spread.1) of this axis point, which this step
        // keeps within the plain step the estimate allows.
        let reach = self.spread.0 + self.t * self.spread.1;
        let step = (CONE_TRUST * settings.step(estimate.distance) - reach) / (1.0 + self.spread.1);
        // A ray alone hits within hit_threshold footprints of the surface:
        // past a threshold of 1, the rays go on alone that much sooner.
        let alone = footprint * settings.hit_threshold.max(1.0);
        if step < alone || self.steps >= settings.max_steps {
            return Some((self.t, self.evaluations));
        }
        self.previous = self.t;
        self.t += step;
        if self.t >= self.t_end {
            return Some((self.t_end, self.evaluations));
        }
        None
    }
}
