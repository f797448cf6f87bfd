//! Shadow rays of neighbouring surface points towards one light run
//! parallel: each climbs alone out of its own surface's detail, then the
//! group shares one march along an axis through open space (as a camera
//! cone shares the way in), for as long as no ray's light can dim there.

use super::shadow::ShadowWalk;
use crate::fractal::{DeMethod, Estimate, Fractal};
use crate::march::{walk_many, MarchSettings, Walk, CONE_TRUST};
use crate::math::{DVec3, Real};
use std::ops::Range;

/// How far each ray climbs alone before the shared march, in multiples
/// of the group's radius about its axis (at least its finest footprint):
/// far enough that the axis' estimate, less that radius, clears the
/// penumbra test for every ray in open space.
const CLIMB_ALONE: Real = 8.0;

/// Where a bundle stopped by something near takes its rays up again: this
/// share of the way its farthest ray has come further on, by when they
/// have passed it alone.
const REJOIN: Real = 0.5;

/// A group wider than this many of its finest footprints marches alone:
/// its rays are too far apart to share the way.
const WIDEST: Real = 64.0;

/// Scratch space kept by the caller from band to band.
#[derive(Default)]
pub struct BundleScratch {
    /// Where each walk pauses for its bundle (infinity: it never does).
    pause: Vec<Real>,
    paused: Vec<Option<ShadowWalk>>,
    members: Vec<Member>,
    bundles: Vec<Bundle>,
    stops: Vec<Stop>,
    resumed: Vec<(usize, ShadowWalk)>,
    /// One group's walks towards one light, and the lights it has seen.
    set: Vec<(usize, ShadowWalk)>,
    lights: Vec<DVec3>,
}

/// A walk of a bundle: its index in the caller's list and where its
/// origin lies along the light from the bundle's centre.
#[derive(Clone, Copy)]
struct Member {
    index: usize,
    along: Real,
}

/// A group of parallel shadow rays and the axis they share.
#[derive(Clone, Copy)]
struct Bundle {
    centre: DVec3,
    to_light: DVec3,
    /// Every member's point at axis position u lies within `radius` of
    /// the axis point there.
    radius: Real,
    /// Where the shared march starts, and where every ray has left the
    /// bounding sphere.
    start: Real,
    end: Real,
    /// The least `along` of the members: the longest way from an origin.
    nearest: Real,
    footprint: Real,
    eps: Real,
    softness: Real,
    steps: u32,
    members: (usize, usize),
}

/// Walks the shadow rays `walks` (as `Look::shadow_walks` lists them)
/// into `out`, each grouped with its neighbours by `groups` (ranges of
/// `walks`): a group's rays towards one light climb alone to a common
/// height, march on together while the open space around their axis
/// keeps every one fully lit, and go on alone from where it does not.
pub fn walk_shadows(
    walks: &[Result<ShadowWalk, (f32, u64)>],
    groups: impl Iterator<Item = Range<usize>>,
    fractal: &Fractal,
    settings: &MarchSettings,
    out: &mut [(f32, u64)],
    scratch: &mut BundleScratch,
) {
    let s = scratch;
    s.members.clear();
    s.bundles.clear();
    s.pause.clear();
    s.pause.resize(walks.len(), Real::INFINITY);
    // Cones trust only the analytic estimate; so do bundles.
    if fractal.de == DeMethod::Analytic {
        for group in groups {
            form_bundles(walks, group, s);
        }
    }
    s.resumed.clear();
    for (i, walk) in walks.iter().enumerate() {
        match walk {
            Ok(walk) => s.resumed.push((i, *walk)),
            Err(done) => out[i] = *done,
        }
    }
    s.paused.clear();
    s.paused.resize(walks.len(), None);
    // Rounds of climbing alone and marching together, until every ray is
    // answered: a bundle stopped by something near goes on after its rays
    // have passed it.
    while !s.resumed.is_empty() {
        let climbs = s.resumed.iter().map(|&(i, walk)| {
            Ok(Climb {
                walk,
                pause: s.pause[i],
            })
        });
        let (resumed, paused) = (&s.resumed, &mut s.paused);
        walk_many(climbs, fractal, settings, |k, outcome| match outcome {
            Ok(done) => out[resumed[k].0] = done,
            Err(walk) => paused[resumed[k].0] = Some(walk),
        });
        march_axes(fractal, settings, s);
        resume(s, out);
    }
}

/// Splits `group`'s walks by light and makes a bundle of each set that
/// lies close enough about its axis, marking where its members pause.
fn form_bundles(
    walks: &[Result<ShadowWalk, (f32, u64)>],
    group: Range<usize>,
    s: &mut BundleScratch,
) {
    let live = || {
        group
            .clone()
            .filter_map(|i| Some((i, *walks[i].as_ref().ok()?)))
    };
    s.lights.clear();
    for (_, first) in live() {
        if s.lights.contains(&first.to_light) {
            continue;
        }
        s.lights.push(first.to_light);
        s.set.clear();
        s.set
            .extend(live().filter(|(_, w)| w.to_light == first.to_light));
        let Some(mut bundle) = bundle_of(&s.set) else {
            continue;
        };
        bundle.members = (s.members.len(), s.members.len() + s.set.len());
        for &(index, w) in &s.set {
            let along = (w.from - bundle.centre).dot(bundle.to_light);
            s.pause[index] = bundle.start - along;
            s.members.push(Member { index, along });
        }
        s.bundles.push(bundle);
    }
}

/// The bundle of `set`'s parallel walks (at least two), or none where
/// they lie too far apart or leave the bounding sphere before it would
/// begin. Its members are left for the caller to fill in.
fn bundle_of(set: &[(usize, ShadowWalk)]) -> Option<Bundle> {
    let (_, any) = *set.first()?;
    if set.len() < 2 {
        return None;
    }
    let to_light = any.to_light;
    let centre = set.iter().map(|(_, w)| w.from).sum::<DVec3>() / set.len() as Real;
    let along = |w: &ShadowWalk| (w.from - centre).dot(to_light);
    let most = |f: &dyn Fn(&ShadowWalk) -> Real| {
        set.iter()
            .map(|(_, w)| f(w))
            .fold(Real::NEG_INFINITY, Real::max)
    };
    let radius = most(&|w| crate::math::length(w.from - centre - to_light * along(w)));
    let footprint = -most(&|w| -w.footprint);
    if radius.is_nan() || radius > WIDEST * footprint {
        return None;
    }
    let start = most(&|w| along(w) + w.t) + CLIMB_ALONE * radius.max(footprint);
    let end = most(&|w| along(w) + w.t_exit);
    (start < end).then(|| Bundle {
        centre,
        to_light,
        radius,
        start,
        end,
        nearest: -most(&|w| -along(w)),
        footprint,
        eps: most(&|w| w.eps),
        softness: any.softness,
        steps: 0,
        members: (0, 0),
    })
}

/// Marches the axis of each bundle that has a member paused on it.
fn march_axes(fractal: &Fractal, settings: &MarchSettings, s: &mut BundleScratch) {
    s.stops.clear();
    s.stops.resize(s.bundles.len(), Stop::NONE);
    let (members, paused) = (&s.members, &s.paused);
    let axes = s.bundles.iter().map(|bundle| {
        let waiting = members[bundle.members.0..bundle.members.1]
            .iter()
            .filter_map(|m| paused[m.index]);
        match waiting.clone().map(|w| w.steps_left).min() {
            Some(steps) => Ok(AxisWalk {
                bundle: Bundle { steps, ..*bundle },
                u: bundle.start,
                previous: bundle.start,
                taken: 0,
                spent: 0,
            }),
            None => Err(Stop::NONE),
        }
    });
    let stops = &mut s.stops;
    walk_many(axes, fractal, settings, |b, stop| stops[b] = stop);
}

/// Hands each bundle's outcome to its paused members: the axis' cost
/// shared out, and each either lit or set to go on alone.
fn resume(s: &mut BundleScratch, out: &mut [(f32, u64)]) {
    let BundleScratch {
        pause,
        paused,
        members,
        bundles,
        stops,
        resumed,
        ..
    } = s;
    resumed.clear();
    for (bundle, stop) in bundles.iter_mut().zip(stops.iter()) {
        if let Some(next) = stop.next {
            bundle.start = next;
        }
        let group = &members[bundle.members.0..bundle.members.1];
        let n = group.iter().filter(|m| paused[m.index].is_some()).count() as u64;
        let waiting = group
            .iter()
            .filter_map(|m| Some((m, paused[m.index].take()?)));
        for (k, (m, mut walk)) in waiting.enumerate() {
            walk.spent += stop.spent / n + u64::from((k as u64) < stop.spent % n);
            walk.steps_left -= stop.taken;
            match stop.at {
                Some(u) => walk.t = walk.t.max(u - m.along),
                None => walk.t = Real::INFINITY,
            }
            pause[m.index] = stop.next.map_or(Real::INFINITY, |u| u - m.along);
            match walk.finished() {
                true => out[m.index] = walk.output(),
                false => resumed.push((m.index, walk)),
            }
        }
    }
}

/// A shadow walk that pauses where its bundle's shared march begins.
#[derive(Clone, Copy)]
struct Climb {
    walk: ShadowWalk,
    pause: Real,
}

impl Walk for Climb {
    /// The walk's outcome, or the walk paused.
    type Output = Result<(f32, u64), ShadowWalk>;
    // It hands each estimate to the shadow walk it drives.
    const READS_ORBIT: bool = ShadowWalk::READS_ORBIT;

    fn next_point(&self) -> (DVec3, Real) {
        self.walk.next_point()
    }

    fn advance(
        &mut self,
        e: &Estimate,
        footprint: Real,
        fractal: &Fractal,
        settings: &MarchSettings,
    ) -> Option<Self::Output> {
        if let Some(done) = self.walk.advance(e, footprint, fractal, settings) {
            return Some(Ok(done));
        }
        (self.walk.t >= self.pause).then_some(Err(self.walk))
    }
}

/// Where a bundle's shared march ended: at axis position `at`, where its
/// members go on alone, or (`None`) with every member lit; the steps it
/// took and the estimates it spent.
#[derive(Clone, Copy)]
struct Stop {
    at: Option<Real>,
    /// Where the bundle takes its rays up again, if before its end.
    next: Option<Real>,
    taken: u32,
    spent: u64,
}

impl Stop {
    /// A bundle with no member waiting on it marches nothing.
    const NONE: Stop = Stop {
        at: None,
        next: None,
        taken: 0,
        spent: 0,
    };
}

/// The shared march along a bundle's axis. A step is the share of the
/// estimate a cone trusts less the bundle's radius, so every member's own
/// path to its next point stays in the ball the estimate clears; it goes
/// on only while that clearance keeps every member's penumbra test at 1.
#[derive(Clone, Copy)]
struct AxisWalk {
    bundle: Bundle,
    u: Real,
    /// Where the axis was before its last step.
    previous: Real,
    taken: u32,
    spent: u64,
}

impl Walk for AxisWalk {
    type Output = Stop;
    const READS_ORBIT: bool = false;

    fn next_point(&self) -> (DVec3, Real) {
        let b = &self.bundle;
        (b.centre + b.to_light * self.u, b.footprint)
    }

    fn advance(
        &mut self,
        e: &Estimate,
        _: Real,
        _: &Fractal,
        settings: &MarchSettings,
    ) -> Option<Self::Output> {
        let b = &self.bundle;
        self.spent += e.orbits as u64;
        let clear = settings.fudge * CONE_TRUST * e.distance - b.radius;
        let farthest = self.u - b.nearest;
        let dims = b.softness > 0.0 && b.softness * clear < farthest;
        if !e.escaped {
            // Inside: the rays go on alone from the last point outside.
            return Some(self.stop(Some(self.previous)));
        }
        if clear < b.eps || dims {
            return Some(self.stop(Some(self.u)));
        }
        self.previous = self.u;
        self.u += clear;
        self.taken += 1;
        if self.u > b.end {
            return Some(self.stop(None));
        }
        // Out of the fewest steps a member has left: the others go on.
        (self.taken >= b.steps).then(|| self.stop(Some(self.u)))
    }
}

impl AxisWalk {
    fn stop(&self, at: Option<Real>) -> Stop {
        let b = &self.bundle;
        let gap = |u: Real| (REJOIN * (u - b.nearest)).max(CLIMB_ALONE * b.radius.max(b.footprint));
        let next = at.map(|u| u + gap(u)).filter(|&u| u < b.end);
        Stop {
            at,
            next,
            taken: self.taken,
            spent: self.spent,
        }
    }
}
