//! Palettes: a gradient of colour stops, interpolated in OKLab, from which
//! an orbit quantity of the hit (its origin trap, its smooth escape count
//! or its final point's angle) picks the surface colour, mixed over the
//! trap colours.
//!
//! OKLab: Ottosson, "A perceptual color space for image processing" (2020),
//! by the `oklab` crate. The smooth escape count: Vepstas, "Renormalizing
//! the Mandelbrot escape" (1997), for a power n and escape radius E.

use crate::fractal::{Formula, Fractal, OrbitTraps};
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
    /// orbit that escapes one step later continues without a jump. One
    /// more orbit per hit.
    SmoothIterations,
    /// The azimuth of the orbit's last point about the formula's pole
    /// axis, in turns (0 to 1). One more orbit per hit.
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

impl Palette {
    /// The colour of a hit whose orbit quantity is `x`.
    pub fn colour(&self, x: f32) -> Vec3 {
        let t = x * self.scale + self.offset;
        // A quantity that is not finite (an orbit gone NaN) takes the start.
        let t = if t.is_finite() { t } else { 0.0 };
        self.at(self.wrap.fold(t))
    }

    /// The gradient's colour at `t` in [0, 1].
    pub fn at(&self, t: f32) -> Vec3 {
        let stops = &self.stops;
        let (Some(first), Some(last)) = (stops.first(), stops.last()) else {
            return Vec3::ZERO;
        };
        let next = stops.partition_point(|s| s.position <= t);
        let (a, b) = match (next, self.wrap) {
            (0, Wrap::Repeat) => (shifted(last, -1.0), *first),
            (0, _) => return first.colour,
            (n, Wrap::Repeat) if n == stops.len() => (*last, shifted(first, 1.0)),
            (n, _) if n == stops.len() => return last.colour,
            (n, _) => (stops[n - 1], stops[n]),
        };
        let span = b.position - a.position;
        let f = if span > 0.0 {
            (t - a.position) / span
        } else {
            1.0
        };
        mix_oklab(a.colour, b.colour, f.clamp(0.0, 1.0))
    }

    /// The orbit quantity `by` names for the frame's point `point`, whose
    /// orbit met `traps`: the trap's at once, the others from one more orbit.
    pub fn quantity(&self, fractal: &Fractal, point: DVec3, traps: &OrbitTraps) -> f32 {
        match self.by {
            OrbitQuantity::Trap => traps.origin.sqrt() as f32,
            OrbitQuantity::SmoothIterations | OrbitQuantity::Angle => {
                // In a deep frame `point` is an offset from the anchor, and
                // `orbit_at` iterates it by perturbation.
                let orbit = fractal.orbit_at([point.x, point.y, point.z], fractal.iterations, true);
                match self.by {
                    OrbitQuantity::Angle => azimuth_turns(fractal.formula, orbit.z),
                    _ => smooth_iterations(
                        orbit.iterations,
                        orbit.r,
                        fractal.escape_radius::<Real>(),
                        fractal.power,
                    ),
                }
            }
        }
    }
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

/// `stop` moved by `by` along the gradient: the neighbour across the seam
/// of a repeating one.
fn shifted(stop: &Stop, by: f32) -> Stop {
    Stop {
        position: stop.position + by,
        ..*stop
    }
}

/// The colour a fraction `f` of the way from `a` to `b`, interpolated in
/// OKLab, where equal steps look equal; never negative.
pub fn mix_oklab(a: Vec3, b: Vec3, f: f32) -> Vec3 {
    let lab = |c: Vec3| linear_srgb_to_oklab(Rgb::new(c.x, c.y, c.z));
    let (p, q) = (lab(a), lab(b));
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
pub fn smooth_iterations(iterations: u32, r: Real, escape: Real, power: Real) -> f32 {
    let ratio = (r.ln() / escape.ln()).max(1.0);
    (iterations as Real + 1.0 - ratio.ln() / power.ln()) as f32
}

/// The azimuth of `z` about `formula`'s pole axis, in turns from 0 to 1.
fn azimuth_turns(formula: Formula, z: [Real; 3]) -> f32 {
    let phi = match formula {
        Formula::Quilez => z[0].atan2(z[2]),
        Formula::WhiteNylander | Formula::Asin => z[1].atan2(z[0]),
    };
    (phi / std::f64::consts::TAU + 0.5) as f32
}
