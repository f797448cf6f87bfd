//! The distance estimators built on the orbit, the escape radius, and the
//! bounds that keep an estimate safe where its formula fails.

use super::orbit::Orbit;
use super::{DeMethod, Estimate, Fractal, Precision, Triplex};
use crate::math::{DVec3, Dual, Number, Real};

impl Fractal {
    /// The analytic estimator in f64 at world coordinates (no deep frame's
    /// offsets): where a hit can be checked by the potential estimate's
    /// stencil (`MarchSettings::confirm_hits`).
    pub fn plain_analytic(&self) -> bool {
        self.lane_analytic() == Some(Precision::F64)
    }

    /// The precision the vector kernel runs this fractal's analytic
    /// estimates in at world coordinates (f64 or f32); `None` for other
    /// estimators and deep frames.
    pub(super) fn lane_analytic(&self) -> Option<Precision> {
        (self.de == DeMethod::Analytic && self.deep.is_none()).then_some(self.precision)
    }

    /// The radius past which an orbit counts as escaped in `T`: `bailout`,
    /// or lower where the step that passes it could leave `T`'s range. That
    /// step lands within Eⁿ + |c| of the origin, and |z|² of it must stay
    /// finite, with 2¹⁴ to spare for the running derivative (which near the
    /// surface is about r·ln r/distance): so Eⁿ ≤ 2^(½·range − 14), about
    /// 1e150 in f64 and 1e15 in f32. Past that, |z|² overflowed and the
    /// estimate read ∞/∞ (0, a false hit): f64 at bailout 1e30, f32 at any
    /// bailout above 237 for power 8. Lowering the escape radius above the
    /// set's own radius (`set_radius`) keeps the set but for orbits that
    /// would have escaped an iteration or two later. Cheap: a power is taken
    /// only where the bailout is that large (`lowered`).
    #[inline]
    pub fn escape_radius<T: Number>(&self) -> Real {
        let limit_log2 = 0.5 * T::MAX_LOG2 - 14.0;
        // The bailout is below 2^e (e from its exponent bits).
        let e = ((self.bailout.to_bits() >> 52) & 0x7ff) as Real - 1022.0;
        if self.power * e <= limit_log2 {
            self.bailout
        } else {
            lowered(self.bailout, limit_log2 / self.power)
        }
    }

    /// A radius the set (at this iteration count and escape radius `escape`)
    /// lies within. The triplex power takes |z| to |z|ⁿ exactly, so
    /// |zⁿ + c| ≥ |z|ⁿ − |c| and mₖ₊₁ = mₖⁿ − |c| (|c| = |p| in Mandelbrot
    /// mode), m₀ = |p|, bounds |zₖ| from below while it stays ≥ 0: a radius
    /// whose m passes `escape` within the iterations (at most 64 counted)
    /// holds no point of the set. m grows with the radius (in Mandelbrot mode
    /// from 2^(1/(n−1)) up, where mₖ ≥ |p| and ∂mₖ/∂|p| ≥ 1), so bisection
    /// finds the least such radius. For the power-8 bulb it is 1.105 at any
    /// bailout. Kept per thread for the last fractal asked about.
    pub fn set_radius(&self, escape: Real) -> Real {
        thread_local! {
            static LAST: std::cell::Cell<([u64; 4], Real)> = const { std::cell::Cell::new(([0; 4], Real::NAN)) };
        }
        let c_norm = self.julia.map(|c| c.length());
        let key = [
            self.power.to_bits(),
            escape.to_bits(),
            c_norm.unwrap_or(-1.0).to_bits(),
            self.iterations as u64,
        ];
        let (last_key, last) = LAST.with(|l| l.get());
        if last_key == key && !last.is_nan() {
            return last;
        }
        let n = self.power;
        let steps = self.iterations.min(64);
        let escapes = |rho: Real| {
            let c = c_norm.unwrap_or(rho);
            let mut m = rho;
            for _ in 0..steps {
                if m > escape {
                    return true;
                }
                m = m.powf(n) - c;
                if m.is_nan() || m < 0.0 {
                    return false;
                }
            }
            m > escape
        };
        let lowest = if c_norm.is_some() {
            0.0
        } else {
            2f64.powf(1.0 / (n - 1.0))
        };
        let radius = if !(lowest < escape && escapes(escape)) {
            escape
        } else if escapes(lowest) {
            lowest
        } else {
            // A bracket by doubling first: the escape radius may be 1e18.
            let (mut lo, mut hi) = (lowest, (2.0 * lowest.max(0.5)).min(escape));
            while !escapes(hi) {
                (lo, hi) = (hi, (2.0 * hi).min(escape));
            }
            for _ in 0..60 {
                let mid = 0.5 * (lo + hi);
                if escapes(mid) {
                    hi = mid;
                } else {
                    lo = mid;
                }
            }
            // Room for the orbit's rounding, f32's included.
            (hi * (1.0 + 1e-4)).min(escape)
        };
        LAST.with(|l| l.set((key, radius)));
        radius
    }

    /// `distance`, the estimate of an escaped point `p` after `iterations`,
    /// or a bound in its place where its formula is known to fail; with the
    /// orbits the bound took. Both `estimate` and the vector kernel finish
    /// with this, so they agree to the bit.
    ///
    /// - Far from the set (past twice `set_radius`, or past the escape
    ///   radius): ½·r·ln r/dr holds only near the boundary ("Distance Estimated 3D Fractals", part V:
    ///   "for points far away we can restrict the maximum DE step"); after
    ///   one iteration it is about ½·|p|·ln|p|, beyond the true distance
    ///   from |p| ≈ 4.5 (power 8), so rays entering a large bounding sphere
    ///   stepped past the bulb; and past the bailout the old bound |p| − B
    ///   drew the bailout ball as a surface. With R = `set_radius` and
    ///   p′ = p·R/|p| its projection onto that sphere, every point q of the
    ///   set has |p − q|² ≥ |p′ − q|² + (|p| − R)², so the distance is at
    ///   least √(d(p′)² + (|p| − R)²): a bound that grows as |p| − R and
    ///   meets the estimate at p′.
    /// - Near the critical point in Julia mode (`near_critical`): the first
    ///   step z ↦ zⁿ + c has zero derivative at z = 0, so dr there is 0 and
    ///   ½·r·ln r/dr infinite (0/0 at the point: a hit at once), and near
    ///   it far too large. Where the estimate is not below |p| (its ball
    ///   holds the critical point, so the linearisation it rests on fails),
    ///   compose instead: the set is its own preimage, and the power
    ///   stretches distances within radius ρ by n·ρⁿ⁻¹ (the scalar
    ///   derivative's model, which the analytic estimate trusts everywhere
    ///   else), so a point of the set within δ of p puts one within
    ///   n·(|p| + δ)ⁿ⁻¹·δ of z₁ = pⁿ + c: δ is the root of
    ///   n·(|p| + δ)ⁿ⁻¹·δ = d(z₁). Where δ ≪ |p| that is the estimate
    ///   itself; at p = 0 it is (d(z₁)/n)^(1/n).
    pub fn bounded<T: Number>(
        &self,
        p: DVec3,
        scale: Real,
        distance: Real,
        iterations: u32,
        near_critical: bool,
    ) -> (Real, u32) {
        let escape = self.escape_radius::<T>();
        // The common case, a point near the set off Julia's critical point,
        // in few operations: every estimate of a march comes through here.
        let critical = near_critical && self.julia.is_some();
        let p = self.world(p);
        if no_bound_applies(p, iterations, escape.min(2.0), critical, distance) {
            return (distance, 0);
        }
        self.bounded_by_roots::<T>(p, escape, scale, distance, iterations, near_critical)
    }

    /// `bounded`'s tests taken on |p| itself, at the world position `p`:
    /// where `no_bound_applies` holds, they keep the estimate as it is.
    pub(super) fn bounded_by_roots<T: Number>(
        &self,
        p: DVec3,
        escape: Real,
        scale: Real,
        distance: Real,
        iterations: u32,
        near_critical: bool,
    ) -> (Real, u32) {
        let scaled = p.abs().max_element();
        let length = if scaled < 1e150 {
            p.length()
        } else {
            scaled * (p / scaled).length()
        };
        // The set radius is at least min(1, escape): nothing to bound within 2.
        if iterations == 0 || length > escape.min(2.0) {
            let radius = self.set_radius(escape);
            if iterations == 0 || length > escape.min(2.0 * radius) {
                let gap = length - radius;
                if length > 8.0 * radius {
                    return (gap, 0);
                }
                let projected = p * (radius / length);
                let e = self.estimate_raw::<T>(self.local(projected), scale);
                let near = if e.escaped { e.distance } else { 0.0 };
                return (near.hypot(gap), e.orbits);
            }
        }
        if near_critical && self.julia.is_some() && !(distance > 0.0 && distance < length) {
            let n = self.power;
            // d(z₁) is the estimate times the first step's stretch n·|p|ⁿ⁻¹
            // (the running derivative is that product); at the critical
            // point itself, where both are 0, it takes the orbit from z₁.
            let slope = n * length.powf(n - 1.0);
            let (target, orbits) =
                if distance > 0.0 && (distance * slope).is_finite() && slope > 0.0 {
                    (distance * slope, 0)
                } else {
                    let first: Orbit<T> = self.orbit(
                        [T::from_real(p.x), T::from_real(p.y), T::from_real(p.z)],
                        1,
                        false,
                    );
                    let z1 = DVec3::new(first.z[0].value(), first.z[1].value(), first.z[2].value());
                    let e = self.estimate_in::<T>(self.local(z1), scale, false);
                    (if e.escaped { e.distance } else { 0.0 }, 1 + e.orbits)
                };
            // δⁿ ≤ the stretch, and so is δ·n·|p|ⁿ⁻¹: both roots lie above.
            let mut hi = (target / n).powf(1.0 / n);
            if slope > 0.0 {
                hi = hi.min(target / slope);
            }
            let lo = stretch_root(n, length, target, hi);
            return (as_distance(lo), orbits);
        }
        (distance, 0)
    }

    /// Whether `p` belongs to the set at this iteration count: its orbit never
    /// passes the bailout. Trusts no distance estimate.
    /// Iterates in the estimator's precision, so a march that finds a point
    /// inside by its estimate bisects the same set.
    pub fn contains(&self, p: DVec3) -> bool {
        match self.precision {
            Precision::F64 => {
                !self
                    .orbit_at([p.x, p.y, p.z], self.iterations, true)
                    .escaped
            }
            Precision::F32 => {
                let q = [p.x as f32, p.y as f32, p.z as f32];
                !self.orbit_at(q, self.iterations, true).escaped
            }
        }
    }

    /// The orbit of the frame's point `p`: itself, or in a deep frame the
    /// anchor plus `p`, by perturbation.
    #[inline]
    pub fn orbit_at<T: Number>(
        &self,
        p: Triplex<T>,
        limit: u32,
        stop_at_bailout: bool,
    ) -> Orbit<T> {
        match &self.deep {
            None => self.orbit(p, limit, stop_at_bailout),
            Some(reference) => reference.orbit(self, p, limit, stop_at_bailout),
        }
    }

    /// Whether an estimate's `end` is where its f64 orbit ends, bit for
    /// bit: `orbit_at::<f64>(p, self.iterations, true)`, or in a deep frame
    /// at a footprint f64 resolves, the plain orbit of `p`'s world position.
    /// The f64 estimators finish that orbit (the vector kernels repeat it),
    /// but for the Jacobian method, whose dual numbers divide by
    /// multiplying with an inverse.
    pub fn ends_f64_orbits(&self) -> bool {
        let plain_orbit = match self.de {
            DeMethod::Analytic
            | DeMethod::Potential
            | DeMethod::SinhPotential
            | DeMethod::EscapeLength => true,
            DeMethod::Jacobian => false,
        };
        self.precision == Precision::F64 && plain_orbit
    }

    /// The world position of the frame's point `p` (to f64, for bounds).
    #[inline(always)]
    pub fn world(&self, p: DVec3) -> DVec3 {
        match &self.deep {
            None => p,
            Some(reference) => reference.anchor + p,
        }
    }

    /// The frame's point at world position `w`: `world`'s inverse.
    #[inline(always)]
    pub fn local(&self, w: DVec3) -> DVec3 {
        match &self.deep {
            None => w,
            Some(reference) => w - reference.anchor,
        }
    }

    /// Estimates the distance from `p` to the surface. `scale` is the size of
    /// detail that matters there (the pixel footprint); the finite-difference
    /// methods step a fraction of it.
    pub fn estimate(&self, p: DVec3, scale: Real) -> Estimate {
        if let Some(estimate) = self.plain_estimate(p, scale) {
            return estimate;
        }
        match self.precision {
            Precision::F64 => self.estimate_in::<f64>(p, scale, true),
            Precision::F32 => self.estimate_in::<f32>(p, scale, true),
        }
    }

    /// The estimator's value at `p` within the bounds of `bounded` (the
    /// critical-point bound only where `near_critical`).
    pub(super) fn estimate_in<T: Number>(
        &self,
        p: DVec3,
        scale: Real,
        near_critical: bool,
    ) -> Estimate {
        let mut estimate = self.estimate_raw::<T>(p, scale);
        if estimate.escaped {
            let (distance, orbits) = self.bounded::<T>(
                p,
                scale,
                estimate.distance,
                estimate.iterations,
                near_critical,
            );
            estimate.distance = distance;
            estimate.orbits += orbits;
        }
        estimate
    }

    /// What `estimate_in::<f64>(p, scale, true)` makes of `p`'s orbit,
    /// given the orbit: for kernels that iterate orbits side by side.
    pub(super) fn estimate_finished(&self, p: DVec3, scale: Real, orbit: &Orbit<f64>) -> Estimate {
        let mut estimate = self.estimate_from_orbit::<f64>(p, scale, orbit, None);
        if estimate.escaped {
            let (distance, orbits) =
                self.bounded::<f64>(p, scale, estimate.distance, estimate.iterations, true);
            estimate.distance = distance;
            estimate.orbits += orbits;
        }
        estimate
    }

    /// The estimator's formula at `p`, without `bounded`'s bounds.
    pub(super) fn estimate_raw<T: Number>(&self, p: DVec3, scale: Real) -> Estimate {
        let at = |q: DVec3| [T::from_real(q.x), T::from_real(q.y), T::from_real(q.z)];
        // The Jacobian method runs its one orbit in dual numbers, whose values
        // follow the plain orbit closely enough to estimate from: no second
        // orbit is needed (though not bit for bit: `ends_f64_orbits`).
        let (centre, jacobian): (Orbit<T>, Option<glam::DMat3>) = if self.de == DeMethod::Jacobian {
            let dual: Orbit<Dual<T>> = self.orbit_at(
                [
                    Dual::variable(T::from_real(p.x), 0),
                    Dual::variable(T::from_real(p.y), 1),
                    Dual::variable(T::from_real(p.z), 2),
                ],
                self.iterations,
                true,
            );
            let jacobian = glam::DMat3::from_cols_array_2d(
                &[0, 1, 2].map(|col| [0, 1, 2].map(|row| dual.z[row].d[col].value())),
            );
            let plain = Orbit {
                z: dual.z.map(|c| c.v),
                r: dual.r.v,
                dr: dual.dr.v,
                traps: dual.traps,
                iterations: dual.iterations,
                escaped: dual.escaped,
            };
            (plain, Some(jacobian))
        } else {
            (self.orbit_at(at(p), self.iterations, true), None)
        };
        self.estimate_from_orbit(p, scale, &centre, jacobian)
    }

    /// The estimate at `p` given its orbit (and, for the Jacobian method, the
    /// orbit's Jacobian): the one place each estimator's formula lives.
    pub(super) fn estimate_from_orbit<T: Number>(
        &self,
        p: DVec3,
        scale: Real,
        centre: &Orbit<T>,
        jacobian: Option<glam::DMat3>,
    ) -> Estimate {
        let at = |q: DVec3| [T::from_real(q.x), T::from_real(q.y), T::from_real(q.z)];
        let mut orbits = 1;
        let distance = if !centre.escaped {
            0.0
        } else if centre.iterations == 0 {
            distance_to_ball(self.world(p), self.escape_radius::<T>())
        } else {
            let r = centre.r.value();
            let d = match self.de {
                DeMethod::Analytic => half_r_ln_r_over(r, centre.dr.value()) * self.dr_scale(),
                DeMethod::Jacobian => {
                    let jacobian = jacobian.expect("computed above for this method");
                    let norm = spectral_norm(jacobian);
                    if norm.is_finite() && norm > 0.0 {
                        half_r_ln_r_over(r, norm)
                    } else {
                        // On the pole axis the dual numbers meet acos'(±1) = ∞. There
                        // the azimuthal stretch is n²·r^(n−1) against the scalar
                        // n·r^(n−1), so bound the norm by n·dr: conservative.
                        half_r_ln_r_over(r, self.power * centre.dr.value()) * self.dr_scale()
                    }
                }
                DeMethod::Potential | DeMethod::SinhPotential | DeMethod::EscapeLength => {
                    // Tetrahedral finite differences; the step is a fraction of the
                    // pixel footprint but never below the precision's noise floor.
                    // A deep frame's points are offsets from its anchor, as
                    // fine as its pixels: no floor of a thousandth there.
                    let size = if self.deep.is_some() {
                        crate::math::length(p)
                    } else {
                        p.length().max(1e-3)
                    };
                    let floor = T::EPSILON.sqrt() * size;
                    let h = (0.25 * scale).max(floor);
                    let k = centre.iterations;
                    let sample = |q: DVec3| -> Real {
                        match self.de {
                            DeMethod::EscapeLength => self.orbit_at(at(q), k, false).r.value(),
                            _ => {
                                let o: Orbit<T> = self.orbit_at(at(q), self.iterations, true);
                                potential(o.r.value(), o.iterations, self.power)
                            }
                        }
                    };
                    let mut gradient = DVec3::ZERO;
                    for dir in TETRAHEDRON {
                        gradient += dir * sample(p + dir * h);
                    }
                    orbits += 4;
                    let slope = crate::math::length(gradient) / (4.0 * h);
                    // Samples that overflowed make the slope infinite and the
                    // distance 0: a false hit. And where the precision's
                    // floor, not the footprint, set the step and the surface
                    // is nearer than it (by the analytic estimate of the same
                    // orbit), the stencil straddles the surface: r after k
                    // iterations leaps by orders across it (in f32, 3.4e-4·|p|
                    // wide, stopping rays 1e-3 … 1e-7 from the surface at
                    // once). Both fall back to the analytic estimate.
                    let straddles =
                        h > 0.25 * scale && h > guarded_distance(centre, self.dr_scale());
                    if !(slope.is_finite() && slope > 0.0)
                        || (self.de == DeMethod::EscapeLength && straddles)
                    {
                        Real::NAN
                    } else {
                        match self.de {
                            DeMethod::EscapeLength => half_r_ln_r_over(r, slope)
                                .min(ESCAPE_LENGTH_CAP * guarded_distance(centre, self.dr_scale())),
                            DeMethod::Potential => {
                                0.5 * potential(r, centre.iterations, self.power) / slope
                            }
                            _ => {
                                let g = potential(r, centre.iterations, self.power);
                                0.5 * g.sinh() / (g.exp() * slope)
                            }
                        }
                    }
                }
            };
            if d.is_finite() {
                d.max(0.0)
            } else {
                guarded_distance(centre, self.dr_scale())
            }
        };
        Estimate {
            distance,
            traps: centre.traps,
            iterations: centre.iterations,
            escaped: centre.escaped,
            orbits,
            end: centre.z.map(|c| c.value()),
        }
    }
}

/// The spectral norm (largest singular value) of `m`: the most it stretches
/// any direction, by 24 rounds of power iteration on mᵀm. The Mandelbulb's
/// Jacobians are strongly anisotropic, so this converges well within them; it
/// approaches the norm from below. Falls back to the Frobenius norm (an upper
/// bound) if the iteration degenerates.
pub fn spectral_norm(m: glam::DMat3) -> Real {
    let mtm = m.transpose() * m;
    let mut v = DVec3::splat(1.0 / 3f64.sqrt());
    let mut lambda = 0.0;
    for _ in 0..24 {
        let w = mtm * v;
        let len = w.length();
        if !(len.is_finite() && len > 0.0) {
            lambda = 0.0;
            break;
        }
        lambda = len;
        v = w / len;
    }
    if lambda > 0.0 {
        lambda.sqrt()
    } else {
        (0..3)
            .map(|c| m.col(c).length_squared())
            .sum::<Real>()
            .sqrt()
    }
}

/// The most the escape-length estimate may say, in analytic estimates of
/// the same orbit: its stencil's slope of r after k iterations can come out
/// near flat, and uncapped it overstated distances up to 25×, stepping rays
/// up to 34 footprints past the set at bailout 2.
const ESCAPE_LENGTH_CAP: Real = 4.0;

/// A safe distance where an estimator's formula gave NaN or infinity (a
/// gradient that vanished or overflowed, a derivative infinite on an axis, a
/// running derivative beyond f32's range): the analytic estimate from the same
/// orbit if that is finite, else 0, which the marcher treats as a hit: it may
/// stop early but never skips surface.
pub(super) fn guarded_distance<T: Number>(centre: &Orbit<T>, dr_scale: Real) -> Real {
    as_distance(half_r_ln_r_over(centre.r.value(), centre.dr.value()) * dr_scale)
}

/// `bailout`, or 2^`log2` where that is lower. Out of line: inlined, the
/// compiler took the power before the test on every call (the kernel asks
/// for the escape radius once per register), as it may with `exp2`.
#[cold]
#[inline(never)]
fn lowered(bailout: Real, log2: Real) -> Real {
    bailout.min(log2.exp2())
}

/// An estimate `d` as a distance: `d` where it is above 0 and finite, else
/// +0 (never −0: the vector kernel selects the same, `Register::estimates`).
#[inline(always)]
pub(super) fn as_distance(d: Real) -> Real {
    if d > 0.0 && d.is_finite() {
        d
    } else {
        0.0
    }
}

/// The δ at which the stretch n·(ρ + δ)ⁿ⁻¹·δ reaches `target`, found by
/// Newton's method from `hi`, a δ at or past it: the stretch is convex and
/// rising, so each step lands between the root and the last, and the
/// answer never passes the root by more than rounding.
pub(super) fn stretch_root(n: Real, rho: Real, target: Real, hi: Real) -> Real {
    let whole = super::power::whole_power(n);
    // (ρ + δ)ⁿ⁻² by multiplications where the power is whole.
    let power = |x: Real| match whole {
        Some(n) => x.powi(n as i32 - 2),
        None => x.powf(n - 2.0),
    };
    let mut delta = hi;
    for _ in 0..64 {
        let x = rho + delta;
        let below = power(x);
        let excess = n * below * x * delta - target;
        let slope = n * below * (rho + n * delta);
        let next = delta - excess / slope;
        // Done once the step stalls, is lost to rounding, or is not a number.
        let moving = next > 0.0 && next < delta;
        if !moving || delta - next <= delta * 1e-13 {
            return if moving { next } else { delta };
        }
        delta = next;
    }
    delta
}

/// Whether none of `Fractal::bounded`'s bounds applies at `p`: its orbit
/// iterated, it lies within `near` (the escape radius, at most 2), and,
/// near Julia's critical point (`critical`), its `distance` is shorter
/// than |p|. The test every estimate of a march takes, so it is kept to a
/// few operations: squares, not square roots.
#[inline(always)]
pub(super) fn no_bound_applies(
    p: DVec3,
    iterations: u32,
    near: Real,
    critical: bool,
    distance: Real,
) -> bool {
    let r2 = p.length_squared();
    // A NaN |p|² is no more within `near` than a large one.
    let within = r2 <= near * near;
    if iterations == 0 || !within {
        return false;
    }
    // Short of the bound by a margin far above rounding, so that wherever
    // this says no bound applies, `bounded`'s tests on |p| agree.
    const MARGIN: Real = 1.0 - 1.0 / (1u64 << 40) as Real;
    !critical || (r2 < MARGIN * near * near && distance > 0.0 && distance * distance < MARGIN * r2)
}

/// The distance from `p` to the bailout ball, for a point outside it before
/// iterating. The set lies inside that ball by definition, so the distance
/// to it is a bound, where the estimators' asymptotics (½·r·ln r) are not.
/// Measured without overflow, for points out to f64's largest.
#[inline]
pub(super) fn distance_to_ball(p: DVec3, bailout: Real) -> Real {
    let scale = p.abs().max_element();
    (scale * (p / scale).length() - bailout).max(0.0)
}

/// ½·r·ln r / `slope`: the distance bound of an orbit that escaped to radius
/// r, given how fast |z| grows with the starting point ("Distance Estimated 3D Fractals", part V).
/// The logarithm is `math::ln`, which the vector kernel repeats to the bit.
#[inline]
pub(super) fn half_r_ln_r_over(r: Real, slope: Real) -> Real {
    0.5 * crate::math::ln(r) * r / slope
}

/// Tetrahedral stencil for gradients: four corners of a cube, summing to zero.
pub const TETRAHEDRON: [DVec3; 4] = [
    DVec3::new(1.0, -1.0, -1.0),
    DVec3::new(-1.0, -1.0, 1.0),
    DVec3::new(-1.0, 1.0, -1.0),
    DVec3::new(1.0, 1.0, 1.0),
];

impl Estimate {
    /// The potential G = ln r/nᵏ of the estimate's orbit (0 where it stayed
    /// bounded), n being the fractal's `power`.
    pub fn potential(&self, power: Real) -> Real {
        if !self.escaped {
            return 0.0;
        }
        potential(self.end_radius(), self.iterations, power)
    }
}

/// The Hubbard–Douady potential G = ln r / n^k of an orbit that reached radius
/// `r` after `k` iterations (0 for a bounded orbit, which has r ≤ bailout).
pub(super) fn potential(r: Real, k: u32, n: Real) -> Real {
    if r > 1.0 {
        r.ln() / n.powi(k as i32)
    } else {
        0.0
    }
}
