//! Sphere tracing of the distance field: where a ray first meets the surface,
//! with a hit threshold that scales with the pixel footprint (distance × pixel
//! angle) so a zoom keeps the same detail at every scale, and surface normals
//! from the distance field. Marching is a `Walk` (a state machine between
//! estimates) so that `walk_many` can march 16 rays side by side through the
//! vector kernel, a new ray taking each lane as soon as its ray ends.
//!
//! Method: ../shared/seeds/004 (ray marching with signed distance bounds,
//! central-difference normals) and 001 (Christensen on the fudge factor).

use crate::fractal::{Estimate, Fractal, TETRAHEDRON, VECTOR};
use crate::math::{normalize_or, sphere_interval, DVec3, Real};
use serde::{Deserialize, Serialize};

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
    /// the step is taken back and the ray goes on at the plain step. 1 turns it off.
    pub over_relaxation: Real,
    /// Camera rays, a block of neighbouring pixels (`cone_block`: 16 is 4×4),
    /// that first march together along one cone holding them all, until
    /// the surface is within a pixel of the cone, and then go on alone
    /// (`march_camera_rays`); 1 marches every ray alone. Not used with
    /// glow, which needs each ray's nearest approach, nor with estimators
    /// other than the analytic one (`Scene::cone_rays`).
    pub cone_rays: u32,
}

impl MarchSettings {
    /// Where `ray` enters and leaves the bounding sphere, if it meets it.
    #[inline]
    pub fn interval(&self, ray: &Ray) -> Option<(Real, Real)> {
        sphere_interval(ray.origin, ray.dir, self.bounding_radius)
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
        }
    }
}

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
        // A floor keeps the threshold non-zero for a camera sitting on the surface.
        (self.start_footprint + t * self.pixel_angle).max(1e-15)
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
    /// The march ran out of `max_steps` and its hit is where it stopped.
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
fn run_spans(runs: &[u32]) -> impl Iterator<Item = std::ops::Range<usize>> + '_ {
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
struct ConeWalk {
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
    fn start(run: &[Ray], intervals: &[Option<(Real, Real)>]) -> Result<ConeWalk, (Real, u32)> {
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
            spread.0 = spread.0.max((ray.origin - origin).length());
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

/// A walk along a ray driven by distance estimates, one at a time: sphere
/// tracing, a shadow ray. `walk_one` and `walk_many` both drive it, so a walk
/// takes the same steps whichever does.
pub trait Walk: Copy {
    type Output;
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
/// side by side through `Fractal::estimate_lanes_into`, and a lane whose walk
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
        fractal.estimate_lanes_into(&points, &footprints, &mut estimates);
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
}

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
        })
    }

    /// Replaces the last over-relaxed step by the plain one and stops
    /// over-relaxing.
    fn take_back(&mut self) {
        self.t += self.previous_distance - self.previous_step;
        self.omega = 1.0;
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

    fn next_point(&self) -> (DVec3, Real) {
        (self.ray.at(self.t), self.ray.footprint(self.t))
    }

    fn advance(
        &mut self,
        estimate: &Estimate,
        footprint: Real,
        fractal: &Fractal,
        settings: &MarchSettings,
    ) -> Option<MarchResult> {
        let (t, ray) = (self.t, self.ray);
        self.evaluations += estimate.orbits;
        if self.steps == settings.max_steps {
            // Out of steps inside the bounding sphere: the ray is creeping
            // along a surface it keeps almost touching (a grazing ray).
            // Calling that a miss punches background-coloured speckles into
            // the surface; call it a hit, and count it.
            return Some(MarchResult {
                out_of_steps: true,
                ..self.hit(t, *estimate)
            });
        }
        self.steps += 1;
        self.closest = self.closest.min(estimate.distance / footprint);
        if self.omega > 1.0
            && estimate.escaped
            && self.previous_distance + settings.fudge * estimate.distance < self.previous_step
        {
            // The spheres of free space around this point and the last one do
            // not overlap: the long step may have jumped over surface. Go from
            // the last point by the plain step instead, without relaxation.
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
        let trusted = settings.membership_step <= 0.0
            && estimate.distance < settings.hit_threshold * footprint;
        if !estimate.escaped || trusted {
            return Some(self.hit(t, *estimate));
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
        if self.t > self.t_exit && self.previous_step > self.previous_distance {
            self.take_back();
        }
        if self.t > self.t_exit {
            return Some(MarchResult {
                hit: None,
                evaluations: self.evaluations,
                closest: self.closest,
                out_of_steps: false,
            });
        }
        None
    }
}

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
fn bisect_membership(
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

/// Surface normal at `hit` from a tetrahedral central difference of the
/// estimate, with a step proportional to the pixel footprint. Returns the normal
/// and the number of orbits used; falls back to facing the ray.
pub fn normal(ray: &Ray, hit: &Hit, fractal: &Fractal, settings: &MarchSettings) -> (DVec3, u32) {
    // The four estimates are independent: evaluated side by side.
    let (points, footprint) = normal_points(ray, hit, settings);
    let estimates = fractal.estimate_lanes(points, [footprint; 4]);
    normal_from(ray, &estimates)
}

/// `normal` for many hits, four to a call of the lane kernel (its 16
/// estimates), so a hit does not pay for a call of its own: `out(i, ray,
/// hit, …)` gets what `normal` gives for each hit (`i` as given with it),
/// bit for bit (each lane of the kernel is independent of the others).
pub fn normals_many<'h>(
    hits: impl IntoIterator<Item = (usize, &'h Ray, &'h Hit)>,
    fractal: &Fractal,
    settings: &MarchSettings,
    mut out: impl FnMut(usize, &'h Ray, &'h Hit, (DVec3, u32)),
) {
    let mut hits = hits.into_iter().peekable();
    let mut estimates = [Estimate::IDLE; VECTOR];
    while hits.peek().is_some() {
        // The last call's spare lanes idle outside the bailout ball.
        let mut batch = [None; VECTOR / 4];
        let mut points = [crate::fractal::IDLE_POINT; VECTOR];
        let mut footprints = [1.0; VECTOR];
        for (k, (slot, hit)) in batch.iter_mut().zip(hits.by_ref()).enumerate() {
            let (p, f) = normal_points(hit.1, hit.2, settings);
            points[4 * k..4 * k + 4].copy_from_slice(&p);
            footprints[4 * k..4 * k + 4].fill(f);
            *slot = Some(hit);
        }
        fractal.estimate_lanes_into(&points, &footprints, &mut estimates);
        for (k, &(i, ray, hit)) in batch.iter().flatten().enumerate() {
            out(i, ray, hit, normal_from(ray, &estimates[4 * k..4 * k + 4]));
        }
    }
}

/// The four points `normal` estimates around `hit` (a tetrahedron a
/// `normal_step` of footprints across, stepped back along the ray so that
/// it straddles the surface rather than sits inside, where the estimate is
/// flat zero), and the footprint there.
fn normal_points(ray: &Ray, hit: &Hit, settings: &MarchSettings) -> ([DVec3; 4], Real) {
    let footprint = ray.footprint(hit.t);
    let h = settings.normal_step * footprint;
    let centre = hit.point - ray.dir * h;
    (TETRAHEDRON.map(|k| centre + k * h), footprint)
}

/// The normal from the estimates at `normal_points`, and the orbits they
/// took; facing the ray where the gradient is zero.
fn normal_from(ray: &Ray, estimates: &[Estimate]) -> (DVec3, u32) {
    let mut gradient = DVec3::ZERO;
    let mut orbits = 0;
    for (k, e) in TETRAHEDRON.iter().zip(estimates) {
        gradient += *k * e.distance;
        orbits += e.orbits;
    }
    (normalize_or(gradient, -ray.dir), orbits)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn unit_ball() -> Fractal {
        Fractal::unit_ball()
    }

    /// Each ray's bounding-sphere interval, as `march_camera_rays` gives
    /// them to a cone.
    fn intervals(rays: &[Ray], settings: &MarchSettings) -> Vec<Option<(Real, Real)>> {
        rays.iter().map(|ray| settings.interval(ray)).collect()
    }

    fn ray(origin: DVec3, dir: DVec3) -> Ray {
        Ray {
            origin,
            dir: dir.normalize(),
            pixel_angle: 1e-3,
            start_footprint: 0.0,
        }
    }

    #[test]
    fn marching_many_side_by_side_is_bit_identical_to_one_at_a_time() {
        use crate::fractal::Formula;
        // Rays fanned over the bulb from two sides: hits, misses, grazing
        // rays, rays that never reach the bounding sphere; 61 of them, so
        // the last batch leaves lanes idle.
        let mut rays = vec![];
        for (k, origin) in [DVec3::new(0.3, -2.6, 0.4), DVec3::new(2.0, 0.5, -1.7)]
            .into_iter()
            .enumerate()
        {
            for i in 0..30 + k {
                let a = i as Real / 30.0;
                let dir = -origin + DVec3::new(4.0 * a - 2.0, 0.9 * (7.0 * a).sin(), 4.4 * a - 2.2);
                rays.push(ray(origin, dir));
            }
        }
        let bulb = |formula, power, julia| Fractal {
            formula,
            power,
            julia,
            ..Fractal::default()
        };
        let fractals = [
            bulb(Formula::Quilez, 8.0, None),
            bulb(Formula::Asin, 8.0, None),
            bulb(
                Formula::WhiteNylander,
                3.0,
                Some(DVec3::new(0.3, -0.5, 0.2)),
            ),
            bulb(Formula::Quilez, 7.5, None),
            Fractal::unit_ball(),
        ];
        for max_steps in [300, 7] {
            let settings = MarchSettings {
                max_steps,
                ..MarchSettings::default()
            };
            for f in &fractals {
                let mut many = vec![MarchResult::default(); rays.len()];
                march_many(&rays, f, &settings, &mut many);
                let mut hits = 0;
                for (r, m) in rays.iter().zip(&many) {
                    let one = march(r, f, &settings);
                    assert_eq!(format!("{one:?}"), format!("{m:?}"), "{f:?} along {r:?}");
                    hits += one.hit.is_some() as usize;
                }
                assert!(
                    hits > 5 && hits < rays.len() - 5,
                    "{hits} hits: too few misses or hits"
                );
                // The hits' normals four to a call, as one at a time (the
                // last call's spare lanes idle).
                let hit_rays: Vec<(usize, &Ray, &Hit)> = rays
                    .iter()
                    .zip(&many)
                    .enumerate()
                    .filter_map(|(i, (r, m))| Some((i, r, m.hit.as_ref()?)))
                    .collect();
                let mut normals = vec![None; rays.len()];
                normals_many(hit_rays.iter().copied(), f, &settings, |i, ray, hit, n| {
                    // Handed back with the ray and hit it was given with.
                    assert!(std::ptr::eq(ray, &rays[i]));
                    assert!(std::ptr::eq(hit, many[i].hit.as_ref().expect("a hit")));
                    assert!(normals[i].replace(n).is_none(), "ray {i} twice")
                });
                for &(i, r, hit) in &hit_rays {
                    let one = normal(r, hit, f, &settings);
                    assert_eq!(
                        format!("{:?}", Some(one)),
                        format!("{:?}", normals[i]),
                        "{f:?}"
                    );
                }
                assert_eq!(normals.iter().flatten().count(), hit_rays.len());
            }
        }
    }

    /// A pinhole camera at `origin` looking at the centre: the ray `u`
    /// pixels right and `v` pixels up of the middle, pixels `angle` apart.
    fn pinhole(origin: DVec3, angle: Real) -> impl Fn(Real, Real) -> Ray {
        let ahead = (-origin).normalize();
        let right = ahead.cross(DVec3::Z).normalize();
        let up = right.cross(ahead);
        move |u, v| Ray {
            origin,
            dir: (ahead + right * (u * angle) + up * (v * angle)).normalize(),
            pixel_angle: angle,
            start_footprint: 0.0,
        }
    }

    /// Rows of camera rays: one origin, directions `angle` apart, the rows
    /// far apart.
    fn camera_rows(origin: DVec3, rows: usize, width: usize, angle: Real) -> Vec<Vec<Ray>> {
        let ray = pinhole(origin, angle);
        (0..rows)
            .map(|row| {
                let v = (row as Real - rows as Real / 2.0) * 97.0;
                (0..width)
                    .map(|x| ray(x as Real - width as Real / 2.0, v))
                    .collect()
            })
            .collect()
    }

    /// Bands of camera rays four neighbouring pixels high and `width` wide,
    /// each band's rays in the renderer's order (`cone_blocks` for the
    /// default cone of 16 rays, blocks of 4×4 pixels), with its blocks'
    /// sizes (narrower at the right edge where 4 does not divide `width`).
    /// The bands are far apart.
    fn camera_blocks(
        origin: DVec3,
        bands: usize,
        width: usize,
        angle: Real,
    ) -> Vec<(Vec<Ray>, Vec<u32>)> {
        let ray = pinhole(origin, angle);
        let block = cone_block(MarchSettings::default().cone_rays);
        (0..bands)
            .map(|band| {
                let v0 = (band as Real - bands as Real / 2.0) * 97.0;
                let (mut order, mut runs) = (vec![], vec![]);
                cone_blocks(width, CONE_BLOCK_ROWS, block, &mut order, &mut runs);
                let rays = order
                    .iter()
                    .map(|&p| {
                        ray(
                            (p % width) as Real - width as Real / 2.0,
                            v0 + (p / width) as Real,
                        )
                    })
                    .collect();
                (rays, runs)
            })
            .collect()
    }

    /// The default bulb, the benchmark's (asin, bailout 10) and a Julia set.
    fn cone_test_fractals() -> [Fractal; 3] {
        use crate::fractal::Formula;
        let (asin, julia) = (Formula::Asin, Some(DVec3::new(0.3, -0.5, 0.2)));
        [
            Fractal::default(),
            Fractal {
                formula: asin,
                bailout: 10.0,
                ..Fractal::default()
            },
            Fractal {
                julia,
                power: 3.0,
                ..Fractal::default()
            },
        ]
    }

    #[test]
    fn a_cone_never_starts_a_ray_past_the_surface() {
        // Each run's cone against every one of its rays' first crossing,
        // found by membership steps (no distance estimate trusted): runs of
        // 8 and 16 rays along a row and blocks of 4×4 pixels (the default),
        // pinhole rays and rays whose origins spread over a lens, as depth
        // of field gives them.
        let settings = MarchSettings::default();
        let (mut advanced, mut crossings) = (0, 0);
        let origin = DVec3::new(0.3, -2.6, 0.4);
        // Each set of rays with its runs' lengths.
        let mut layouts: Vec<(Vec<Ray>, Vec<u32>)> = vec![];
        for rays in camera_rows(origin, 6, 32, 2e-3) {
            for n in [8, 16] {
                layouts.push((rays.clone(), vec![n; rays.len() / n as usize]));
            }
        }
        layouts.extend(camera_blocks(origin, 3, 32, 2e-3));
        for f in &cone_test_fractals() {
            for aperture in [0.0, 0.01] {
                for (rays, runs) in &layouts {
                    let rays: Vec<Ray> = rays
                        .iter()
                        .copied()
                        .enumerate()
                        .map(|(k, ray)| {
                            let (a, r) = (k as Real * 2.4, (k % 5) as Real / 4.0);
                            // Through a point of the lens towards where the
                            // pinhole ray is 2.5 along: focused there.
                            let lens = DVec3::new(a.cos(), 0.0, a.sin()) * (aperture * r);
                            let focus = ray.at(2.5);
                            Ray {
                                origin: ray.origin + lens,
                                dir: (focus - ray.origin - lens).normalize(),
                                ..ray
                            }
                        })
                        .collect();
                    let first_crossings: Vec<Option<Real>> = rays
                        .iter()
                        .map(|ray| march_by_membership(ray, f, &settings, 0.25, 1e-9, 100_000).0)
                        .collect();
                    for span in run_spans(runs) {
                        let run = &rays[span.clone()];
                        let (t_free, _) = walk_one(
                            ConeWalk::start(run, &intervals(run, &settings)),
                            f,
                            &settings,
                        );
                        for (ray, crossing) in run.iter().zip(&first_crossings[span]) {
                            let enter = settings
                                .interval(ray)
                                .map_or(Real::INFINITY, |(enter, _)| enter);
                            if aperture == 0.0 {
                                advanced += (t_free > enter + 20.0 * ray.footprint(enter)) as usize;
                            }
                            if let Some(t) = *crossing {
                                crossings += 1;
                                assert!(t_free <= t, "{f:?}: cone to {t_free}, surface at {t}");
                            }
                        }
                    }
                }
            }
        }
        // The pinhole cones did go ahead of most rays, and most rays meet
        // the surface (3 fractals × 2 lenses × (2 × 192 + 384) rays).
        assert!(
            advanced > 1500 && crossings > 2500,
            "{advanced} advanced, {crossings} crossings"
        );
    }

    #[test]
    fn a_cone_that_lands_inside_starts_its_rays_a_step_back() {
        // A fudge of 3 trusts the unit ball's exact distance three times
        // over, so the cone's step lands inside the ball: its rays must
        // start from the point before, in front of the surface (t = 2 on
        // the axis, a little more off it).
        let settings = MarchSettings {
            fudge: 3.0,
            ..MarchSettings::default()
        };
        let origin = DVec3::new(0.0, 0.0, 3.0);
        let run: Vec<Ray> = (0..8)
            .map(|k| ray(origin, DVec3::new(1e-3 * k as Real, 0.0, -1.0)))
            .collect();
        let (t_free, evaluations) = walk_one(
            ConeWalk::start(&run, &intervals(&run, &settings)),
            &unit_ball(),
            &settings,
        );
        // From the sphere (t = 1.5) it stepped to the centre, inside: back.
        assert_eq!(evaluations, 2);
        assert!((1.5..2.0).contains(&t_free), "cone stopped at {t_free}");
    }

    #[test]
    fn rays_after_a_cone_find_the_surface_they_find_alone() {
        let settings = MarchSettings::default();
        let origin = DVec3::new(-2.2, -1.1, 0.9);
        // Rows of 64 in runs of 8 and in runs of uneven lengths, one of them
        // a single ray; bands in blocks of 4×4 pixels (the default), 30
        // pixels wide, so the last block of each band is 2×4.
        let rows = |runs: &[u32]| -> Vec<(Vec<Ray>, Vec<u32>)> {
            let rows = camera_rows(origin, 6, 64, 1.5e-3);
            rows.into_iter().map(|rays| (rays, runs.to_vec())).collect()
        };
        let cases = [
            rows(&[8; 8]),
            rows(&[13, 7, 16, 1, 27]),
            camera_blocks(origin, 3, 30, 1.5e-3),
        ];
        for f in &cone_test_fractals() {
            for (case, groups) in cases.iter().enumerate() {
                let (mut both, mut near, mut differ, mut rays_seen) = (0, 0, 0, 0);
                let mut evaluations = [0u64; 2];
                for (rays, runs) in groups {
                    let mut marched = [(); 2].map(|_| vec![MarchResult::default(); rays.len()]);
                    let alone_runs = vec![1; rays.len()];
                    for (k, runs) in [&alone_runs, runs].into_iter().enumerate() {
                        let (results, scratch) = (&mut marched[k], &mut ConeScratch::default());
                        march_camera_rays(rays, f, &settings, runs, results, scratch);
                        evaluations[k] += results.iter().map(|m| m.evaluations as u64).sum::<u64>();
                    }
                    let alone: Vec<MarchResult> =
                        rays.iter().map(|ray| march(ray, f, &settings)).collect();
                    // One ray a cone is every ray alone, to the bit.
                    assert_eq!(format!("{alone:?}"), format!("{:?}", marched[0]));
                    // A run of one among longer runs marches alone too.
                    for span in run_spans(runs).filter(|span| span.len() == 1) {
                        let (a, c) = (&alone[span.start], &marched[1][span.start]);
                        assert_eq!(format!("{a:?}"), format!("{c:?}"), "run of one at {span:?}");
                    }
                    rays_seen += rays.len();
                    for ((ray, a), c) in rays.iter().zip(&alone).zip(&marched[1]) {
                        match (a.hit, c.hit) {
                            (Some(a), Some(c)) => {
                                both += 1;
                                near += ((a.t - c.t).abs() <= 2.0 * ray.footprint(a.t)) as usize;
                            }
                            (None, None) => {}
                            _ => differ += 1,
                        }
                    }
                }
                // The same surface within a couple of footprints, nearly
                // everywhere, for fewer estimates.
                assert!(both > 100, "{f:?}, case {case}: {both} hits");
                assert!(
                    near * 100 >= both * 95,
                    "{f:?}, case {case}: {near} of {both} within 2 footprints"
                );
                assert!(
                    differ * 100 <= 3 * rays_seen,
                    "{f:?}, case {case}: {differ} hit/miss differ"
                );
                assert!(
                    evaluations[1] * 10 < evaluations[0] * 9,
                    "{f:?}, case {case}: {evaluations:?}"
                );
            }
        }
    }

    #[test]
    fn cone_blocks_have_the_shortest_diagonal_four_rows_allow() {
        let shapes: Vec<_> = [1, 2, 3, 4, 6, 8, 12, 16, 32, 64, 9]
            .map(cone_block)
            .to_vec();
        assert_eq!(
            shapes,
            [
                (1, 1),
                (2, 1),
                (3, 1),
                (2, 2),
                (3, 2),
                (4, 2),
                (3, 4),
                (4, 4),
                (8, 4),
                (16, 4),
                (9, 1)
            ]
        );
        assert!(shapes.iter().all(|&(_, rows)| rows <= CONE_BLOCK_ROWS));
        assert_eq!(cone_block(MarchSettings::default().cone_rays), (4, 4));
    }

    #[test]
    fn cone_blocks_cover_a_band_in_rectangles() {
        // Widths that the block divides and that it does not, full and
        // short bands, and every block shape the renderer uses.
        for (w, rows) in [(8, 4), (10, 4), (7, 3), (5, 1), (1, 4)] {
            for n in [1, 2, 4, 8, 12, 16, 32] {
                let (bw, bh) = cone_block(n);
                let (mut order, mut runs) = (vec![], vec![]);
                cone_blocks(w, rows, (bw, bh), &mut order, &mut runs);
                // Every pixel of the band exactly once.
                let mut sorted = order.clone();
                sorted.sort_unstable();
                assert_eq!(
                    sorted,
                    (0..w * rows).collect::<Vec<_>>(),
                    "{w}x{rows} n={n}"
                );
                // Each run is a rectangle of at most bw×bh pixels, row by row.
                let mut at = 0;
                for &run in &runs {
                    let block = &order[at..at + run as usize];
                    at += run as usize;
                    let xs = block.iter().map(|p| p % w);
                    let ys = block.iter().map(|p| p / w);
                    let (x0, x1) = (xs.clone().min().unwrap(), xs.max().unwrap());
                    let (y0, y1) = (ys.clone().min().unwrap(), ys.max().unwrap());
                    assert!(x1 - x0 < bw && y1 - y0 < bh, "{w}x{rows} n={n}: {block:?}");
                    assert_eq!(block.len(), (x1 - x0 + 1) * (y1 - y0 + 1), "{block:?}");
                    assert!(block.windows(2).all(|p| p[0] < p[1]), "{block:?}");
                }
                assert_eq!(at, order.len());
                // As few blocks as the band holds, the first a whole one.
                assert_eq!(runs.len(), w.div_ceil(bw) * rows.div_ceil(bh));
                assert_eq!(runs[0] as usize, bw.min(w) * bh.min(rows));
            }
        }
    }

    #[test]
    fn hits_the_unit_ball_where_geometry_says() {
        let r = ray(DVec3::new(0.0, 0.0, 3.0), -DVec3::Z);
        let m = march(&r, &unit_ball(), &MarchSettings::default());
        let hit = m.hit.expect("ray through the centre hits");
        // The hit fires once the estimate is below half a footprint (1e-3 at t≈2);
        // the estimate is about half the true distance, so the hit lies within 2e-3.
        assert!(hit.t < 2.0 && hit.t > 2.0 - 2e-3, "t = {}", hit.t);
        let (n, _) = normal(&r, &hit, &unit_ball(), &MarchSettings::default());
        assert!(n.dot(DVec3::Z) > 0.99, "normal {n}");
    }

    #[test]
    fn misses_when_ray_passes_beside() {
        let r = ray(DVec3::new(0.0, 1.2, 3.0), -DVec3::Z);
        let m = march(&r, &unit_ball(), &MarchSettings::default());
        assert!(m.hit.is_none());
        assert!(m.evaluations > 0);
        let away = ray(DVec3::new(0.0, 0.0, 3.0), DVec3::Z);
        assert_eq!(
            march(&away, &unit_ball(), &MarchSettings::default()).evaluations,
            0
        );
    }

    #[test]
    fn hit_threshold_scales_with_footprint() {
        let far = ray(DVec3::new(0.0, 0.0, 3.0), -DVec3::Z);
        assert!((far.footprint(2.0) - 2e-3).abs() < 1e-15);
        // The marcher stops further from the surface when pixels are wider:
        // the gap to the unit sphere is below the threshold in each case and
        // the coarse pixel stops well before the fine one.
        let settings = MarchSettings::default();
        let gap = |pixel_angle: Real| {
            let r = Ray { pixel_angle, ..far };
            2.0 - march(&r, &unit_ball(), &settings).hit.unwrap().t
        };
        let (coarse, fine) = (gap(1e-1), gap(1e-5));
        assert!(
            coarse < 2.0 * settings.hit_threshold * 0.2 && coarse > 1e-3,
            "{coarse}"
        );
        assert!(
            fine < 2.0 * settings.hit_threshold * 2e-5 && fine >= 0.0,
            "{fine}"
        );
    }

    #[test]
    fn over_relaxation_never_steps_through_the_surface() {
        // Rays from all around at every angle of incidence, down to grazing:
        // whatever the relaxation, the hit is the sphere's first crossing
        // within the threshold, and grazing misses stay misses.
        let ball = unit_ball();
        let mut spent = Vec::new();
        for omega in [1.0, 1.2, 1.5, 1.9] {
            let mut evaluations = 0;
            let settings = MarchSettings {
                over_relaxation: omega,
                ..MarchSettings::default()
            };
            for i in 0..200 {
                let offset = i as Real / 200.0 * 1.1; // impact parameter 0 … 1.1
                let origin = DVec3::new(offset, 0.0, 3.0);
                let r = ray(origin, -DVec3::Z);
                let m = march(&r, &ball, &settings);
                evaluations += m.evaluations;
                if offset < 1.0 {
                    let exact = 3.0 - (1.0 - offset * offset).sqrt();
                    let hit = m
                        .hit
                        .unwrap_or_else(|| panic!("ω={omega}, b={offset}: missed"));
                    // The estimate is half the true distance near this sphere
                    // (½·r·ln r / |dz|), so hits stop within twice the threshold.
                    let tolerance = 2.0 * settings.hit_threshold * r.footprint(exact);
                    // Within that of the surface, on the near side.
                    let gap = hit.point.length() - 1.0;
                    assert!(
                        gap.abs() <= tolerance && hit.t <= exact + tolerance,
                        "ω={omega}, b={offset}: t={} exact={exact} gap={gap}",
                        hit.t
                    );
                } else if offset > 1.02 {
                    // Beyond a few footprints of the silhouette (within it a
                    // grazing ray may legitimately stop).
                    assert!(m.hit.is_none(), "ω={omega}, b={offset}");
                }
            }
            spent.push(evaluations);
        }
        // And the default pays: fewer estimates (on this smooth sphere larger
        // factors take back too many steps to gain).
        assert!(spent[1] < spent[0], "{spent:?}");
    }

    #[test]
    fn membership_reference_finds_the_unit_sphere() {
        let r = ray(DVec3::new(0.0, 0.0, 3.0), -DVec3::Z);
        let (t, tests) = march_by_membership(
            &r,
            &unit_ball(),
            &MarchSettings::default(),
            0.25,
            1e-9,
            1_000_000,
        );
        let t = t.unwrap();
        // Quarter-footprint steps from the sphere (t = 1.5) to t = 2 number
        // ln(2/1.5)/(0.25·1e-3) ≈ 1151, then about 11 bisections.
        assert!((1140..1180).contains(&tests), "{tests} tests");
        // Bisected to a thousandth of the 2e-3 footprint, from the outside.
        assert!(t <= 2.0 && t > 2.0 - 2e-6, "{t}");
        let beside = ray(DVec3::new(0.0, 1.2, 3.0), -DVec3::Z);
        assert!(march_by_membership(
            &beside,
            &unit_ball(),
            &MarchSettings::default(),
            0.25,
            1e-9,
            1_000_000
        )
        .0
        .is_none());
    }

    #[test]
    fn overshooting_steps_are_caught_by_membership() {
        // A fudge of 3 makes every step overshoot, as an estimator that
        // overestimates would. On the unit ball the exact answer is known: every
        // hit must lie outside the ball and within the hit threshold of it.
        let settings = MarchSettings {
            fudge: 3.0,
            ..MarchSettings::default()
        };
        let mut hits = 0;
        for i in 0..40 {
            let a = i as Real * 0.37;
            let origin = DVec3::new(a.cos() * 2.5, (a * 0.7).sin(), a.sin() * 2.5);
            let r = ray(
                origin,
                -origin + DVec3::new(0.0, 0.3 * (a * 3.0).sin(), 0.0),
            );
            if let Some(hit) = march(&r, &unit_ball(), &settings).hit {
                let gap = hit.point.length() - 1.0;
                let limit = settings.hit_threshold * r.footprint(hit.t);
                assert!(
                    gap > 0.0 && gap <= limit * 1.0001,
                    "ray {i}: gap {gap}, limit {limit}"
                );
                hits += 1;
            }
        }
        assert!(hits > 30);
    }

    #[test]
    fn oblique_normal_on_the_ball_points_outward() {
        let r = ray(DVec3::new(0.5, 0.3, 3.0), DVec3::new(-0.1, 0.0, -1.0));
        let m = march(&r, &unit_ball(), &MarchSettings::default());
        let hit = m.hit.unwrap();
        let (n, _) = normal(&r, &hit, &unit_ball(), &MarchSettings::default());
        let expected = hit.point.normalize();
        assert!(n.dot(expected) > 0.995, "{n} vs {expected}");
    }

    #[test]
    fn no_method_stops_past_the_membership_crossing() {
        // Random rays at the bulb: whatever the estimator, the hit may come early
        // (a pixel cone grazing a feature in front) but never more than one
        // footprint past where the centre ray really enters the set.
        use crate::fractal::DeMethod;
        let settings = MarchSettings::default();
        for de in DeMethod::ALL {
            let f = Fractal {
                de,
                ..Fractal::default()
            };
            let mut checked = 0;
            for i in 0..60u64 {
                let u = |d: u32| crate::math::sample_1d(99, 0, i, 0, d);
                let origin = DVec3::new(u(0) - 0.5, u(1) - 0.5, u(2) - 0.5).normalize() * 2.5;
                let aim = DVec3::new(u(3) - 0.5, u(4) - 0.5, u(5) - 0.5) * 0.8;
                let r = Ray {
                    origin,
                    dir: (aim - origin).normalize(),
                    pixel_angle: 2e-3,
                    start_footprint: 0.0,
                };
                let (reference, _) = march_by_membership(&r, &f, &settings, 0.125, 1e-9, 1_000_000);
                if let (Some(hit), Some(t)) = (march(&r, &f, &settings).hit, reference) {
                    assert!(
                        hit.t <= t + r.footprint(t),
                        "{de:?} ray {i}: hit {} past crossing {t}",
                        hit.t
                    );
                    checked += 1;
                }
            }
            assert!(checked > 20, "{de:?}: only {checked} rays hit");
        }
    }

    #[test]
    fn membership_walk_lands_on_the_crossing_the_estimate_stops_short_of() {
        // Near the bulb's surface the estimate understates the distance, so a
        // ray that trusts it stops where no point of the set is within its
        // hit threshold further on. Walking by membership, every hit has a
        // point of the set within hit_threshold footprints further along
        // the ray: the crossing it was bisected from.
        let f = Fractal::default();
        let trusting = MarchSettings::default();
        let walking = MarchSettings {
            membership_step: 0.25,
            ..MarchSettings::default()
        };
        let (mut trusted_on, mut walked_on, mut hits) = (0, 0, 0);
        for i in 0..200u64 {
            let u = |d: u32| crate::math::sample_1d(7, 0, i, 0, d);
            let origin = DVec3::new(u(0) - 0.5, u(1) - 0.5, u(2) - 0.5).normalize() * 2.5;
            let aim = DVec3::new(u(3) - 0.5, u(4) - 0.5, u(5) - 0.5) * 0.8;
            let r = Ray {
                origin,
                dir: (aim - origin).normalize(),
                pixel_angle: 1e-3,
                start_footprint: 0.0,
            };
            // A point of the set within the threshold further on, sampled
            // finely: the crossing may be a sheet far thinner than a footprint.
            let on = |hit: Option<Hit>, settings: &MarchSettings| {
                hit.is_some_and(|h| {
                    let reach = settings.hit_threshold * r.footprint(h.t);
                    (1..=256).any(|k| f.contains(r.at(h.t + reach * k as Real / 256.0)))
                })
            };
            let (a, b) = (march(&r, &f, &trusting).hit, march(&r, &f, &walking).hit);
            hits += b.is_some() as u32;
            trusted_on += on(a, &trusting) as u32;
            walked_on += on(b, &walking) as u32;
        }
        assert!(hits > 50, "{hits} hits");
        assert_eq!(walked_on, hits, "every walked hit is on a crossing");
        assert!(
            trusted_on < hits / 2,
            "{trusted_on} of {hits} trusted hits on one"
        );
    }

    #[test]
    fn membership_walk_never_stops_outside_the_set_it_reached() {
        // On the unit ball the walk ends within hit_threshold footprints
        // short of the sphere, from outside, for any walk step; and a ray
        // passing beside it, however near, misses (no threshold fattens it).
        for step in [0.05, 0.5, 4.0] {
            let settings = MarchSettings {
                membership_step: step,
                ..MarchSettings::default()
            };
            for i in 0..50 {
                let b = i as Real / 50.0 * 0.999;
                let r = ray(DVec3::new(b, 0.0, 3.0), -DVec3::Z);
                let hit = march(&r, &unit_ball(), &settings).hit.expect("hits");
                let gap = hit.point.length() - 1.0;
                let limit = settings.hit_threshold * r.footprint(hit.t);
                assert!(
                    gap > 0.0 && gap <= limit * 1.0001,
                    "step {step}, b {b}: gap {gap}"
                );
            }
            let beside = ray(DVec3::new(1.0 + 1e-3, 0.0, 3.0), -DVec3::Z);
            assert!(march(&beside, &unit_ball(), &settings).hit.is_none());
        }
        // Half a footprint off the sphere, the estimate alone calls it a hit.
        let beside = ray(DVec3::new(1.0 + 1e-3, 0.0, 3.0), -DVec3::Z);
        assert!(march(&beside, &unit_ball(), &MarchSettings::default())
            .hit
            .is_some());
    }

    #[test]
    fn camera_inside_the_set_hits_at_once_and_never_steps_back() {
        // Naive: inside, ln(r) with r < 1 makes ½·ln r·r/dr negative, a step backwards.
        let r_inside: Real = 0.5;
        assert!(0.5 * r_inside.ln() * r_inside < 0.0);
        let f = Fractal::default();
        let r = ray(DVec3::new(0.0, 0.1, 0.0), DVec3::Z);
        let m = march(&r, &f, &MarchSettings::default());
        let hit = m.hit.expect("a ray from inside hits");
        assert_eq!(hit.t, 0.0);
        assert_eq!(m.evaluations, 1);
    }

    #[test]
    fn rays_out_of_steps_are_hits_every_time() {
        // Two steps are too few to reach the bulb from the sphere: the decision
        // must be the same hit on every call (no speckle, no flicker).
        let settings = MarchSettings {
            max_steps: 2,
            ..MarchSettings::default()
        };
        let f = Fractal::default();
        let r = ray(DVec3::new(0.2, 0.3, 3.0), -DVec3::Z);
        let result = march(&r, &f, &settings);
        assert!(result.out_of_steps, "and is counted as out of steps");
        let first = result.hit.expect("out of steps counts as a hit");
        // With steps enough, the same ray's hit is a true one.
        assert!(!march(&r, &f, &MarchSettings::default()).out_of_steps);
        for _ in 0..5 {
            assert_eq!(march(&r, &f, &settings).hit.unwrap().t, first.t);
        }
        assert!(first.t.is_finite() && first.point.is_finite());
    }

    /// Hits (t and point) of an n×n block of pixels in the middle of a
    /// 1920×1080 frame, with the camera `distance` from a surface point,
    /// looking straight at it; with each ray's footprint at the hit.
    /// Where the deep-zoom measurements look at the bulb: the surface
    /// point on the ray from `origin` along `dir`.
    const SURFACES: [(DVec3, DVec3); 2] = [
        (DVec3::new(0.1, 0.35, 2.0), DVec3::new(0.3, -0.2, -1.0)),
        (DVec3::new(-0.4, 0.2, 2.0), DVec3::new(0.2, -0.1, -1.0)),
    ];

    fn block_hits_with_depth(
        precision: crate::fractal::Precision,
        distance: Real,
        n: u32,
    ) -> Vec<(Real, DVec3, Real)> {
        block_hits_at(SURFACES[0], precision, distance, n)
    }

    fn block_hits_at(
        (origin, dir): (DVec3, DVec3),
        precision: crate::fractal::Precision,
        distance: Real,
        n: u32,
    ) -> Vec<(Real, DVec3, Real)> {
        let f = Fractal {
            precision,
            iterations: 30,
            ..Fractal::default()
        };
        // The surface point on a fixed ray: membership steps of 1e-4, then
        // bisection to the last bit of f64.
        let dir = dir.normalize();
        let exact = Fractal {
            iterations: 30,
            ..Fractal::default()
        };
        let mut lo = 0.0;
        while !exact.contains(origin + dir * (lo + 1e-4)) {
            lo += 1e-4;
        }
        let mut hi = lo + 1e-4;
        for _ in 0..80 {
            let mid = 0.5 * (lo + hi);
            if exact.contains(origin + dir * mid) {
                hi = mid;
            } else {
                lo = mid;
            }
        }
        let target = origin + dir * lo;
        let camera = crate::scene::Camera {
            position: target - dir * distance,
            target,
            up: DVec3::Y,
            roll_degrees: 0.0,
            fov_degrees: 40.0,
            ..crate::scene::Camera::default()
        }
        .frame();
        let settings = MarchSettings::default();
        let mut hits = Vec::new();
        for y in 0..n {
            for x in 0..n {
                let r = camera.ray(960.0 + x as Real, 540.0 + y as Real, 1920, 1080);
                if let Some(h) = march(&r, &f, &settings).hit {
                    hits.push((h.t, h.point, r.footprint(h.t)));
                }
            }
        }
        hits
    }

    fn block_hits(precision: crate::fractal::Precision, distance: Real, n: u32) -> Vec<DVec3> {
        block_hits_with_depth(precision, distance, n)
            .into_iter()
            .map(|(_, p, _)| p)
            .collect()
    }

    fn distinct(points: &[DVec3]) -> usize {
        let mut v: Vec<[u64; 3]> = points
            .iter()
            .map(|p| p.to_array().map(f64::to_bits))
            .collect();
        v.sort();
        v.dedup();
        v.len()
    }

    #[test]
    fn deep_zoom_in_f64_stays_sharp_to_1e_12() {
        // At 1e-12 from the surface, 1920 pixels wide, neighbouring pixels are
        // 3.6e-16 apart at the target: f64 still resolves each of them.
        for distance in [1e-4, 1e-8, 1e-12] {
            let with_depth = block_hits_with_depth(crate::fractal::Precision::F64, distance, 6);
            let hits: Vec<DVec3> = with_depth.iter().map(|h| h.1).collect();
            assert_eq!(hits.len(), 36, "misses at {distance}");
            assert!(hits.iter().all(|p| p.is_finite()));
            assert_eq!(distinct(&hits), 36, "blocky at {distance}");
            // And the depths follow the surface: within half a footprint
            // of a plane (a depth stuck at the camera or in one terrace
            // over a sloping block would not be).
            let off = depth_off_plane(&with_depth, 6);
            assert!(
                off < 0.5,
                "depths {off} footprints off a plane at {distance}"
            );
        }
        // The same test sees blockiness where it exists: f32 at 1e-8.
        let f32_hits = block_hits(crate::fractal::Precision::F32, 1e-8, 6);
        assert!(distinct(&f32_hits) < 36);
    }

    mod properties {
        use super::*;
        use proptest::prelude::*;

        proptest! {
            #![proptest_config(ProptestConfig::with_cases(200))]
            #[test]
            fn marcher_terminates_with_a_finite_result(
                ox in -3.0f64..3.0, oy in -3.0f64..3.0, oz in -3.0f64..3.0,
                dx in -1.0f64..1.0, dy in -1.0f64..1.0, dz in -1.0f64..1.0,
                pixel_angle in 1e-9f64..1e-1,
                power in 2.0f64..10.0,
                julia in proptest::option::of((-1.2f64..1.2, -1.2f64..1.2, -1.2f64..1.2)),
            ) {
                let dir = DVec3::new(dx, dy, dz);
                prop_assume!(dir.length() > 1e-3);
                let f = Fractal {
                    power,
                    julia: julia.map(|(a, b, c)| DVec3::new(a, b, c)),
                    ..Fractal::default()
                };
                let settings = MarchSettings::default();
                let r = Ray { origin: DVec3::new(ox, oy, oz), dir: dir.normalize(), pixel_angle, start_footprint: 0.0 };
                let m = march(&r, &f, &settings);
                // Every step and bisection is bounded: 300 steps plus at most ~1100 bisections.
                prop_assert!(m.evaluations <= settings.max_steps + 1200);
                if let Some(hit) = m.hit {
                    prop_assert!(hit.t.is_finite() && hit.t >= 0.0 && hit.point.is_finite());
                    let (n, _) = normal(&r, &hit, &f, &settings);
                    prop_assert!(n.is_finite() && (n.length() - 1.0).abs() < 1e-9);
                }
            }
        }
    }

    /// Root-mean-square distance of hit depths from the plane that fits
    /// them best over the pixel grid (`n`×`n`, row by row), in footprints:
    /// how far a deep zoom's depths depart from the smooth surface they sample.
    fn depth_off_plane(hits: &[(Real, DVec3, Real)], n: u32) -> Real {
        // Least squares of t = a + b·x + c·y over a full grid: x and y are
        // centred, so the three coefficients separate.
        let m = (n as Real - 1.0) / 2.0;
        let at = |i: usize| ((i as u32 % n) as Real - m, (i as u32 / n) as Real - m);
        let count = hits.len() as Real;
        let a = hits.iter().map(|h| h.0).sum::<Real>() / count;
        let sxx: Real = (0..hits.len()).map(|i| at(i).0.powi(2)).sum();
        let b = hits
            .iter()
            .enumerate()
            .map(|(i, h)| at(i).0 * h.0)
            .sum::<Real>()
            / sxx;
        let c = hits
            .iter()
            .enumerate()
            .map(|(i, h)| at(i).1 * h.0)
            .sum::<Real>()
            / sxx;
        let squares: Real = hits
            .iter()
            .enumerate()
            .map(|(i, h)| ((h.0 - a - b * at(i).0 - c * at(i).1) / h.2).powi(2))
            .sum();
        (squares / count).sqrt()
    }

    fn distinct_depths(hits: &[(Real, DVec3, Real)]) -> usize {
        let mut v: Vec<u64> = hits.iter().map(|h| h.0.to_bits()).collect();
        v.sort();
        v.dedup();
        v.len()
    }

    #[test]
    #[ignore = "measurement for README: cargo test --release -- --ignored zoom_depth_limits --nocapture"]
    fn zoom_depth_limits() {
        use crate::fractal::Precision;
        let distances = [
            1e-3, 1e-4, 1e-5, 1e-6, 1e-8, 1e-10, 1e-12, 5e-13, 2e-13, 1e-13, 5e-14, 2e-14, 1e-14,
            5e-15, 2e-15,
        ];
        for d in distances {
            let wide = block_hits_with_depth(Precision::F64, d, 8);
            let single = block_hits_with_depth(Precision::F32, d, 8);
            let median_off = |a: &[(Real, DVec3, Real)], b: &[(Real, DVec3, Real)]| {
                let mut e: Vec<Real> = a
                    .iter()
                    .zip(b)
                    .map(|(a, b)| (a.0 - b.0).abs() / a.2)
                    .collect();
                e.sort_by(|a, b| a.total_cmp(b));
                e.get(e.len() / 2).copied().unwrap_or(Real::NAN)
            };
            let other = |p| block_hits_at(SURFACES[1], p, d, 8);
            eprintln!(
                "{d:e} second surface: f32 depth off f64 by median {:.2} footprints",
                median_off(&other(Precision::F64), &other(Precision::F32))
            );
            let mut errors: Vec<Real> = wide
                .iter()
                .zip(&single)
                .map(|(a, b)| (a.0 - b.0).abs() / a.2)
                .collect();
            errors.sort_by(|a, b| a.total_cmp(b));
            let points: Vec<DVec3> = wide.iter().map(|h| h.1).collect();
            let plane = if wide.len() == 64 {
                format!("{:.2}", depth_off_plane(&wide, 8))
            } else {
                "-".into()
            };
            eprintln!(
                "{d:e}: f64 {} hits, {} distinct points, {} distinct depths, {plane} footprints off a plane; f32 depth off f64 by median {:.2} / max {:.2} footprints",
                wide.len(),
                distinct(&points),
                distinct_depths(&wide),
                errors.get(errors.len() / 2).copied().unwrap_or(Real::NAN),
                errors.last().copied().unwrap_or(Real::NAN),
            );
        }
    }
}
