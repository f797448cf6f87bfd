//! Palettes: a gradient of colour stops, interpolated in OKLab, from which
//! an orbit quantity of the hit (its origin trap, its smooth escape count
//! or its final point's angle) picks the surface colour, mixed over the
//! trap colours.
//!
//! A frame's hits use the palette through its `Table`, made once per
//! frame: the stops in OKLab and the logarithms the smooth count divides
//! by. The smooth count and angle come from the hit's own estimate, whose
//! orbit already ended where they are read: in f64 with any estimator but
//! the Jacobian one, a hit iterates no more orbit and converts no stop.
//!
//! OKLab: Ottosson, "A perceptual color space for image processing" (2020),
//! by the `oklab` crate. The smooth escape count: Vepstas, "Renormalizing
//! the Mandelbrot escape" (1997), for a power n and escape radius E.

use crate::fractal::{Estimate, Formula, Fractal};
use crate::math::{DVec3, Real, Vec3};
use oklab::{linear_srgb_to_oklab, oklab_to_linear_srgb, Oklab, Rgb};
use serde::{Deserialize, Serialize};

/// The most stops a palette may have: each stop's position and colour is a
/// parameter a track can animate, and the table lists every one.
pub const MAX_STOPS: usize = 8;

/// A gradient over [0, 1] and how a hit picks its place on it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Palette {
    /// The gradient's stops, by position (from 0 to 1, each at or after
    /// the one before); from 1 to `MAX_STOPS` of them.
    pub stops: Vec<Stop>,
    /// The orbit quantity that places a hit on the gradient.
    pub by: OrbitQuantity,
    /// Repeats of the gradient per unit of the quantity.
    pub scale: f32,
    /// Shift along the gradient, in gradients: animating it cycles the colours.
    pub offset: f32,
    /// How much the palette's colour replaces the trap colours (0 = not at
    /// all, 1 = wholly). The origin trap's darkening of crevices stays.
    pub mix: f32,
    /// What the gradient does past its ends.
    pub wrap: Wrap,
}

/// One stop of a gradient: a linear-RGB colour at a position in [0, 1].
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Stop {
    pub position: f32,
    pub colour: Vec3,
}

/// What of a hit's orbit places it on the gradient.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum OrbitQuantity {
    /// The orbit's closest approach to the origin, |z| (0 deep in
    /// crevices, about 1 on the outer skin). Free: the march gathered it.
    Trap,
    /// The continuous escape count i + 1 − ln(ln|z|/ln E)/ln n, which an
    /// orbit that escapes one step later continues without a jump. Read
    /// from where the hit's last estimate's orbit ended.
    SmoothIterations,
    /// The azimuth of the orbit's last point about the formula's pole
    /// axis, in turns (0 to 1).
    Angle,
}

/// How the gradient continues past [0, 1].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum Wrap {
    /// Cyclic: past the last stop the colour runs on into the first, so
    /// the gradient repeats without a seam, as a colour wheel does.
    Repeat,
    /// There and back: 0 to 1, then 1 to 0, and again.
    Mirror,
    /// Held: below the first stop its colour, past the last stop its colour.
    Clamp,
}

impl Default for Palette {
    fn default() -> Self {
        let stop = |position, r, g, b| Stop {
            position,
            colour: Vec3::new(r, g, b),
        };
        Palette {
            stops: vec![
                stop(0.0, 0.02, 0.05, 0.20),
                stop(0.3, 0.05, 0.40, 0.50),
                stop(0.6, 0.90, 0.60, 0.15),
                stop(0.85, 0.60, 0.08, 0.10),
            ],
            by: OrbitQuantity::SmoothIterations,
            scale: 0.25,
            offset: 0.0,
            mix: 1.0,
            wrap: Wrap::Repeat,
        }
    }
}

/// What a frame's hits share of a palette (`Palette::table`): each stop's
/// colour in OKLab (its cube roots are most of a conversion's cost), and
/// the logarithms of the escape radius and power the smooth count divides
/// by.
#[derive(Clone, Debug)]
pub struct Table {
    palette: Palette,
    lab: Vec<Oklab>,
    logs: [Real; 2],
}

impl Palette {
    /// This palette as `fractal`'s hits use it.
    pub fn table(&self, fractal: &Fractal) -> Table {
        Table {
            palette: self.clone(),
            lab: self.stops.iter().map(|s| to_lab(s.colour)).collect(),
            logs: [fractal.escape_radius::<Real>().ln(), fractal.power.ln()],
        }
    }
}

impl Table {
    /// The colour of a hit whose orbit quantity is `x`.
    pub fn colour(&self, x: f32) -> Vec3 {
        let p = &self.palette;
        let t = x * p.scale + p.offset;
        // A quantity that is not finite (an orbit gone NaN) takes the start.
        let t = if t.is_finite() { t } else { 0.0 };
        self.at(p.wrap.fold(t))
    }

    /// The gradient's colour at `t` in [0, 1].
    pub fn at(&self, t: f32) -> Vec3 {
        let stops = &self.palette.stops;
        let (Some(first), Some(last)) = (stops.first(), stops.last()) else {
            return Vec3::ZERO;
        };
        let (last_index, n) = (stops.len() - 1, stops.len());
        let next = stops.partition_point(|s| s.position <= t);
        // The stops either side of `t` (by index) and their positions, the
        // neighbour across a repeating gradient's seam moved a gradient along.
        let (a, at_a, b, at_b) = match (next, self.palette.wrap) {
            (0, Wrap::Repeat) => (last_index, last.position - 1.0, 0, first.position),
            (0, _) => return first.colour,
            (k, Wrap::Repeat) if k == n => (last_index, last.position, 0, first.position + 1.0),
            (k, _) if k == n => return last.colour,
            (k, _) => (k - 1, stops[k - 1].position, k, stops[k].position),
        };
        let span = at_b - at_a;
        let f = if span > 0.0 { (t - at_a) / span } else { 1.0 };
        mix_lab(self.lab[a], self.lab[b], f.clamp(0.0, 1.0))
    }

    /// The orbit quantity `by` names for the frame's point `point`, given
    /// the estimate taken there (a hit's): the trap's and, in f64, the
    /// others from where its orbit ended; in f32 from one more orbit.
    pub fn quantity(&self, fractal: &Fractal, point: DVec3, estimate: &Estimate) -> f32 {
        match self.palette.by {
            OrbitQuantity::Trap => estimate.traps.origin.sqrt() as f32,
            OrbitQuantity::Angle => {
                azimuth_turns(fractal.formula, orbit_end(fractal, point, estimate).1)
            }
            OrbitQuantity::SmoothIterations => {
                let (iterations, _, r) = orbit_end(fractal, point, estimate);
                smooth_count(iterations, r, self.logs)
            }
        }
    }
}

/// Where the orbit of the frame's point `point` ended (iterations, last
/// point, its radius): read from `estimate`, the one taken there, where
/// its orbit is the f64 one, else iterated once more.
fn orbit_end(fractal: &Fractal, point: DVec3, estimate: &Estimate) -> (u32, [Real; 3], Real) {
    if fractal.ends_f64_orbits() {
        return (estimate.iterations, estimate.end, estimate.end_radius());
    }
    // In a deep frame `point` is an offset from the anchor, and `orbit_at`
    // iterates it by perturbation.
    let orbit = fractal.orbit_at([point.x, point.y, point.z], fractal.iterations, true);
    (orbit.iterations, orbit.z, orbit.r)
}

impl Wrap {
    /// `t` brought into [0, 1] as the gradient continues.
    pub fn fold(self, t: f32) -> f32 {
        match self {
            Wrap::Repeat => t.rem_euclid(1.0),
            Wrap::Mirror => {
                let u = t.rem_euclid(2.0);
                if u > 1.0 {
                    2.0 - u
                } else {
                    u
                }
            }
            Wrap::Clamp => t.clamp(0.0, 1.0),
        }
    }
}

/// The colour a fraction `f` of the way from `a` to `b`, interpolated in
/// OKLab, where equal steps look equal; never negative.
#[cfg(test)]
pub fn mix_oklab(a: Vec3, b: Vec3, f: f32) -> Vec3 {
    mix_lab(to_lab(a), to_lab(b), f)
}

/// A linear-RGB colour in OKLab.
fn to_lab(c: Vec3) -> Oklab {
    #[cfg(test)]
    CONVERSIONS.with(|n| n.set(n.get() + 1));
    linear_srgb_to_oklab(Rgb::new(c.x, c.y, c.z))
}

#[cfg(test)]
thread_local! {
    /// Colours `to_lab` converted on this thread: how the tests see that a
    /// palette converts its stops once.
    pub(super) static CONVERSIONS: std::cell::Cell<u64> = const { std::cell::Cell::new(0) };
}

/// The colour a fraction `f` of the way from `p` to `q` (in OKLab), in
/// linear RGB; never negative.
fn mix_lab(p: Oklab, q: Oklab, f: f32) -> Vec3 {
    let lerp = |x: f32, y: f32| x + (y - x) * f;
    let c = oklab_to_linear_srgb(Oklab {
        l: lerp(p.l, q.l),
        a: lerp(p.a, q.a),
        b: lerp(p.b, q.b),
    });
    Vec3::new(c.r, c.g, c.b).max(Vec3::ZERO)
}

/// The continuous escape count of an orbit that stopped after `iterations`
/// at radius `r`, for escape radius `escape` and power `power`. An orbit
/// that never escaped (r ≤ E) counts `iterations + 1`, where its escaping
/// neighbours' counts tend.
#[cfg(test)]
pub fn smooth_iterations(iterations: u32, r: Real, escape: Real, power: Real) -> f32 {
    smooth_count(iterations, r, [escape.ln(), power.ln()])
}

/// `smooth_iterations`, given ln E and ln n.
fn smooth_count(iterations: u32, r: Real, [ln_escape, ln_power]: [Real; 2]) -> f32 {
    let ratio = (r.ln() / ln_escape).max(1.0);
    (iterations as Real + 1.0 - ratio.ln() / ln_power) as f32
}

/// The azimuth of `z` about `formula`'s pole axis, in turns from 0 to 1.
fn azimuth_turns(formula: Formula, z: [Real; 3]) -> f32 {
    let (_, [e1, e2]) = formula.shape().split(z);
    let phi = e2.atan2(e1);
    (phi / std::f64::consts::TAU + 0.5) as f32
}
