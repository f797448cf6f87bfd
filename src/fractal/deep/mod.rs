//! Orbits of frames deeper than f64 resolves, by perturbation. A deep frame
//! has an anchor (its target, to as many digits as the timeline gave), and
//! its points are small f64 offsets from it. One reference orbit is
//! iterated from the anchor in high precision (`reference`); each point's
//! orbit is its difference δ from that, iterated in f64 by the perturbed
//! step (`step`), which keeps δ's relative precision however small δ is.
//!
//! Where a point's orbit comes nearer the origin than it is to the
//! reference's (|Z + δ| < |δ|), or the reference ends (it escaped first),
//! the point is rebased onto the orbit of the origin: δ becomes the point
//! itself, from index 0 (Zhuoran's rebasing, from 2-D deep zooms). In
//! Mandelbrot mode the reference is the orbit of 0 with c = anchor, so it
//! serves both; in Julia mode the orbit of 0 is a second reference.

pub use super::orbit::Derivative;
use super::orbit::{Orbit, ITERATIONS};
use super::power::{length_squared, powi, whole_power, whole_power_step};
use super::{DeMethod, Estimate, Formula, Fractal, OrbitTraps, Precision, Triplex};
use crate::exact::{big_from_f64, Big};
use crate::math::{DVec3, Number, Real};
use step::Delta;

mod lanes;
mod reference;
mod step;

/// One reference orbit: its points, and the perturbed step's data at each.
#[derive(Clone, Debug, PartialEq)]
struct Track {
    z: Vec<Triplex<Real>>,
    /// |Z|² − E² at each point (`reference::excess`).
    excess: Vec<Real>,
    /// `None` on the pole axis (and at the origin), where the step falls
    /// back to the plain power.
    steps: Vec<Option<step::Point>>,
}

impl Track {
    fn new(fractal: &Fractal, n: u32, points: &[[Big; 3]], bits: usize) -> Track {
        let escape = fractal.escape_radius::<Real>();
        let z: Vec<_> = points.iter().map(reference::rounded).collect();
        let steps = points
            .iter()
            .map(|p| step::Point::new(fractal.formula, p, n))
            .collect();
        let excess = points
            .iter()
            .map(|p| reference::excess(p, escape, bits))
            .collect();
        Track { z, excess, steps }
    }

    /// Whether Z + `d` at index `m` is past the escape radius E, tested as
    /// (|Z|² − E²) + (2Z + δ)·δ > 0.
    #[inline(always)]
    fn outside<T: Number>(&self, m: usize, d: Triplex<T>) -> bool {
        let z = self.z[m];
        let mut sum = T::from_real(self.excess[m]);
        for k in 0..3 {
            sum = sum + (T::from_real(2.0 * z[k]) + d[k]) * d[k];
        }
        sum.value() > 0.0
    }
}

/// A deep frame's reference: where its points are measured from and the
/// high-precision orbits their orbits are differences from.
#[derive(Clone, Debug, PartialEq)]
pub struct Reference {
    /// The anchor rounded to f64: the world position of the frame's origin,
    /// for what needs a point's place only roughly (bounding spheres, bounds
    /// far from the set).
    pub anchor: DVec3,
    /// Bits of precision the reference orbits were computed with.
    pub bits: usize,
    main: Track,
    /// Julia mode's orbit of 0; Mandelbrot mode's is `main`.
    critical: Option<Track>,
    /// Where a point starts on `main`: 1 in Mandelbrot mode (`main` starts
    /// at 0, and z₀ = c is its second point), 0 in Julia mode.
    start: usize,
    n: u32,
    /// What an orbit's running derivative starts at (1, or `DR_SCALED`
    /// where the frame is so deep that it would pass f64's range).
    pub(super) dr_scale: Real,
}

/// Where a frame's pixel is below 2^this, a running derivative reaches
/// 1/pixel and more on its way out, near f64's range: orbits carry it
/// times `DR_SCALED`, and estimates take that back (a power of two, so the
/// estimates' bits are the same wherever neither passes the range).
const DR_SCALED_BELOW: Real = -700.0;
const DR_SCALED: Real = 4.909093465297727e-91; // 2⁻³⁰⁰

/// log₂ of the pixel a reference of `bits` at `anchor` serves: `crate::deep::bits`
/// keeps 96 bits past the pixel's share of the anchor's size.
fn pixel_log2(anchor: DVec3, bits: usize) -> Real {
    anchor.abs().max_element().max(Real::MIN_POSITIVE).log2() + 96.0 - bits as Real
}

impl Reference {
    /// The reference for `fractal` at `anchor` (its components in high
    /// precision, `bits` of them): `None` for a power that is not whole,
    /// which the perturbed step does not cover.
    pub fn new(fractal: &Fractal, anchor: [Big; 3], bits: usize) -> Option<Reference> {
        let n = whole_power(fractal.power)?;
        let escape = fractal.escape_radius::<Real>();
        let limit = fractal.iterations;
        let zero = || [0.0; 3].map(|v| big_from_f64(v, bits));
        let anchor_f64 = DVec3::from_array(anchor.each_ref().map(|v| v.to_f64().value()));
        let anchor = off_the_axis(fractal.formula, anchor, bits);
        let orbit = |start, c: &[Big; 3], limit| {
            let points = reference::orbit(fractal.formula, n, start, c, limit, escape, bits);
            Track::new(fractal, n, &points, bits)
        };
        let (main, critical, start) = match fractal.julia {
            None => (orbit(zero(), &anchor, limit + 1), None, 1),
            Some(k) => {
                let c = crate::exact::big_point(k, fractal.julia_digits.as_ref(), bits);
                let main = orbit(anchor, &c, limit);
                (main, Some(orbit(zero(), &c, limit)), 0)
            }
        };
        // A point rebased onto the orbit of 0 takes at least one step on it.
        let origin_track = critical.as_ref().unwrap_or(&main);
        (origin_track.z.len() >= 2).then_some(Reference {
            anchor: anchor_f64,
            bits,
            main,
            critical,
            start,
            n,
            dr_scale: if pixel_log2(anchor_f64, bits) < DR_SCALED_BELOW {
                DR_SCALED
            } else {
                1.0
            },
        })
    }

    /// The orbit of the point `delta` from the anchor: what
    /// `Fractal::orbit` gives at anchor + `delta`, computed as a difference.
    pub(super) fn orbit<T: Number>(
        &self,
        fractal: &Fractal,
        delta: Triplex<T>,
        limit: u32,
        stop_at_bailout: bool,
    ) -> Orbit<T> {
        self.walk(fractal, delta, limit, stop_at_bailout).orbit
    }

    /// `orbit`, with where the walk ended on the reference.
    fn walk<T: Number>(
        &self,
        fractal: &Fractal,
        delta: Triplex<T>,
        limit: u32,
        stop_at_bailout: bool,
    ) -> Walked<T> {
        let dc = self.dc(fractal, delta);
        self.run(fractal, self.start(delta), dc, limit, stop_at_bailout)
    }

    /// Where the running derivative of the anchor's own orbit reaches
    /// `value`, or why it does not.
    pub fn derivative_passes(&self, fractal: &Fractal, value: Real) -> Derivative {
        let plus_one = if fractal.julia.is_none() { 1.0 } else { 0.0 };
        let escape2 = fractal.escape_radius::<Real>().powi(2);
        let mut dr: Real = 1.0;
        for (i, z) in self.main.z[self.start..].iter().enumerate() {
            let r2 = z[0] * z[0] + z[1] * z[1] + z[2] * z[2];
            if dr >= value {
                return Derivative::Passes(i as u32);
            }
            if r2 > escape2 {
                return Derivative::Escapes(i as u32);
            }
            dr = self.n as Real * r2.sqrt().powi(self.n as i32 - 1) * dr + plus_one;
        }
        Derivative::Stays
    }

    /// The c offset of the point `delta`: itself in Mandelbrot mode, 0 in Julia mode.
    #[inline(always)]
    fn dc<T: Delta>(&self, fractal: &Fractal, delta: Triplex<T>) -> Triplex<T> {
        match fractal.julia {
            None => delta,
            Some(_) => [delta[0].constant(0.0); 3],
        }
    }

    /// The orbit of the point `delta` before its first iteration.
    #[inline(always)]
    fn start<T: Delta>(&self, delta: Triplex<T>) -> State<T> {
        let z = add(self.main.z[self.start], delta);
        State {
            on_origin: false,
            m: self.start,
            d: delta,
            z,
            r2: length_squared(z),
            dr: delta[0].constant(self.dr_scale),
            traps: OrbitTraps {
                origin: Real::INFINITY,
                planes: DVec3::splat(Real::INFINITY),
            },
            i: 0,
            rebased: 0,
        }
    }

    fn track(&self, on_origin: bool) -> &Track {
        match on_origin {
            true => self.critical.as_ref().unwrap_or(&self.main),
            false => &self.main,
        }
    }

    /// Iterates `state` on to `limit` (stopping at the bailout where asked):
    /// the loop every perturbed orbit ends in, the vector kernel's lanes
    /// included wherever they need more than the common step.
    fn run<T: Number>(
        &self,
        fractal: &Fractal,
        mut s: State<T>,
        dc: Triplex<T>,
        limit: u32,
        stop_at_bailout: bool,
    ) -> Walked<T> {
        let escape = fractal.escape_radius::<T>();
        // The tracks' excesses are over f64's escape radius; f32's may be lower.
        let exact = escape == fractal.escape_radius::<Real>();
        let plus_one = T::from_real(if fractal.julia.is_none() {
            self.dr_scale
        } else {
            0.0
        });
        let nn = T::from_real(self.n as Real);
        let outside = |s: &State<T>| {
            if exact {
                self.track(s.on_origin).outside(s.m, s.d)
            } else {
                s.r2.value() > escape * escape
            }
        };
        while s.i < limit {
            if stop_at_bailout && outside(&s) {
                break;
            }
            if s.m + 1 >= self.track(s.on_origin).z.len()
                || s.r2.value() < length_squared(s.d).value()
            {
                (s.on_origin, s.m, s.d) = (true, 0, s.z);
                s.rebased += 1;
            }
            let zv = DVec3::new(s.z[0].value(), s.z[1].value(), s.z[2].value());
            s.traps.origin = s.traps.origin.min(zv.length_squared());
            s.traps.planes = s.traps.planes.min(zv.abs());
            let r = s.r2.sqrt();
            s.dr = nn * powi(r, self.n - 1, |a, b| a * b) * s.dr + plus_one;
            let track = self.track(s.on_origin);
            let difference = match &track.steps[s.m] {
                Some(point) => point.power_difference(fractal.formula, s.d),
                None => self.plain_difference(fractal, track.z[s.m], s.d),
            };
            s.d = [0, 1, 2].map(|k| difference[k] + dc[k]);
            s.m += 1;
            s.z = add(track.z[s.m], s.d);
            s.r2 = length_squared(s.z);
            s.i += 1;
        }
        ITERATIONS.with(|count| count.set(count.get() + s.i as u64));
        let mut orbit = Orbit::ended(s.z, s.r2, s.r2.sqrt(), s.dr, s.traps, s.i, escape);
        orbit.escaped = outside(&s);
        Walked {
            orbit,
            delta: s.d,
            rebased: s.rebased,
        }
    }

    /// (Z + δ)ⁿ − Zⁿ where the perturbed step does not apply: at Z = 0 it is
    /// δⁿ, exact; on the pole axis, the plain difference (f64's precision).
    fn plain_difference<T: Number>(
        &self,
        fractal: &Fractal,
        z: Triplex<Real>,
        d: Triplex<T>,
    ) -> Triplex<T> {
        let power = |p: Triplex<T>| {
            let r = length_squared(p).sqrt();
            whole_power_step(fractal.formula, p, r, self.n).0
        };
        if z == [0.0; 3] {
            return power(d);
        }
        let zt = z.map(T::from_real);
        let (a, b) = (power(add(z, d)), power(zt));
        [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
    }
}

/// The least footprint, as a share of a point's largest coordinate, that
/// f64 resolves: 2²⁶ times its resolution there. Orbits near a repelling
/// fixed point amplify f64's rounding far more than their pixels' offsets:
/// on `deep_zoom.ron`'s tip f64 frames turn to noise from 2⁻³⁰, so this
/// keeps a margin of 16 over the worst case seen. A frame whose pixel at
/// its target is finer is deep; within a deep frame, a point whose
/// footprint passes it is estimated in f64 alone. Such points lie far from
/// the anchor (rays leaving for the rest of the bulb, occlusion's reach):
/// their perturbed orbits would part from the reference at once and be
/// rebased, to finish one at a time outside the vector kernel.
pub const F64_RESOLVES: Real = 1.0 / (1u64 << 26) as Real;

impl Reference {
    /// Whether f64 alone resolves the point `p` (an offset from the anchor)
    /// where detail of size `scale` matters (`F64_RESOLVES`).
    #[inline(always)]
    pub(super) fn resolves_in_f64(&self, p: DVec3, scale: Real) -> bool {
        scale >= F64_RESOLVES * (self.anchor + p).abs().max_element()
    }
}

impl Fractal {
    /// What this frame's orbits carry their running derivative times
    /// (`Reference::dr_scale`): 1 but in the deepest frames.
    pub(in crate::fractal) fn dr_scale(&self) -> Real {
        self.deep.as_ref().map_or(1.0, |r| r.dr_scale)
    }

    /// The deep frame's reference, where its estimates go through the
    /// perturbed analytic kernel (f64 offsets).
    pub(in crate::fractal) fn perturbed_analytic(&self) -> Option<&Reference> {
        let analytic = self.de == DeMethod::Analytic && self.precision == Precision::F64;
        self.deep.as_deref().filter(|_| analytic)
    }

    /// This fractal in world coordinates, without the deep frame's
    /// reference: what estimates the points f64 resolves. Field by field,
    /// so that a new field must be placed here.
    pub(super) fn plain(&self) -> Fractal {
        Fractal {
            formula: self.formula,
            power: self.power,
            iterations: self.iterations,
            auto: self.auto,
            bailout: self.bailout,
            julia: self.julia,
            julia_digits: None,
            de: self.de,
            precision: self.precision,
            deep: None,
            perturbation: self.perturbation,
        }
    }

    /// The analytic estimate at the deep frame's point `p` where f64 alone
    /// resolves it (`F64_RESOLVES`), from the plain fractal at its world
    /// position; `None` where the frame is not deep or `p` needs the
    /// reference.
    pub(in crate::fractal) fn plain_estimate(&self, p: DVec3, scale: Real) -> Option<Estimate> {
        let reference = self.perturbed_analytic()?;
        reference
            .resolves_in_f64(p, scale)
            .then(|| self.plain().estimate(reference.anchor + p, scale))
    }
}

/// `anchor`, or where it lies on the pole axis a point 2⁻⁽ᵇⁱᵗˢ⁻³²⁾ of its
/// size off it: a reference on the axis keeps its whole orbit there, where
/// the perturbed step has no azimuth to differ from and falls back to the
/// plain difference, losing δ. The shift is 2⁻⁶⁴ of a pixel or less
/// (`crate::deep::bits` keeps 96 bits past the pixel), so points keep their
/// offsets from the target.
fn off_the_axis(formula: Formula, mut anchor: [Big; 3], bits: usize) -> [Big; 3] {
    let equator = formula.shape().equator;
    let zero = big_from_f64(0.0, bits);
    if equator.iter().all(|&k| anchor[k] == zero) {
        let size = anchor
            .iter()
            .map(|v| v.to_f64().value().abs())
            .fold(0.0, Real::max);
        let shift = bits as isize - 32;
        anchor[equator[0]] = big_from_f64(size.max(Real::MIN_POSITIVE), bits) >> shift;
    }
    anchor
}

/// A perturbed orbit being iterated: on which track (the main reference or
/// the orbit of the origin), where on it, the difference from it, the
/// point itself and what `OrbitState` keeps.
#[derive(Clone, Copy)]
struct State<T> {
    on_origin: bool,
    m: usize,
    d: Triplex<T>,
    z: Triplex<T>,
    r2: T,
    dr: T,
    traps: OrbitTraps,
    i: u32,
    rebased: u32,
}

/// Where a perturbed orbit ended: the orbit, its last difference from the
/// reference, and how often it was rebased.
struct Walked<T> {
    orbit: Orbit<T>,
    #[cfg_attr(not(test), allow(dead_code))]
    delta: Triplex<T>,
    #[cfg_attr(not(test), allow(dead_code))]
    rebased: u32,
}

#[inline(always)]
fn add<T: Delta>(z: Triplex<Real>, d: Triplex<T>) -> Triplex<T> {
    [
        d[0].constant(z[0]) + d[0],
        d[1].constant(z[1]) + d[1],
        d[2].constant(z[2]) + d[2],
    ]
}

#[cfg(test)]
mod tests;
