//! The iteration driver: one orbit (bailout, running derivative, orbit
//! traps, Julia mode) generic over f64, f32 and dual numbers.

use super::power::{length_squared, triplex_power_trig_scaled, whole_power, whole_power_step};
use super::{Formula, Fractal, OrbitTraps, Triplex};
use crate::math::{DVec3, Number, Real};

thread_local! {
    /// Orbit iterations computed on this thread: the unit of work the
    /// benchmark turns into flops. Thread-local, so counting takes no lock
    /// and shares no cache line.
    pub(super) static ITERATIONS: std::cell::Cell<u64> = const { std::cell::Cell::new(0) };
}

/// Orbit iterations this thread has computed since it started; differences
/// around a piece of work count that work's iterations.
pub fn iterations_on_this_thread() -> u64 {
    ITERATIONS.with(|count| count.get())
}

/// The end of one orbit.
#[derive(Clone, Copy, Debug)]
pub struct Orbit<T> {
    pub z: Triplex<T>,
    pub r: T,
    /// Running scalar derivative |dz/dp|.
    pub dr: T,
    pub traps: OrbitTraps,
    pub iterations: u32,
    pub escaped: bool,
}

impl Orbit<f64> {
    /// A placeholder: where the kernel skips a register of padding, its
    /// lanes keep this (zero iterations, zero orbits).
    pub(super) const IDLE: Orbit<f64> = Orbit {
        z: [0.0; 3],
        r: 0.0,
        dr: 0.0,
        traps: OrbitTraps {
            origin: 0.0,
            planes: DVec3::ZERO,
        },
        iterations: 0,
        escaped: false,
    };
}

/// An orbit being iterated: the loop body of `orbit`. The vector kernel
/// (`Register::step`) repeats it operation for operation on registers and
/// ends the same way (`Orbit::ended`, `OrbitTraps::ended`, which
/// `Register::estimates` repeats by selection); tests hold the two to the
/// bit.
#[derive(Clone, Copy)]
pub(super) struct OrbitState<T> {
    z: Triplex<T>,
    c: Triplex<T>,
    /// 1 in Mandelbrot mode (dc/dc), 0 in Julia mode.
    plus_one: T,
    n: T,
    /// |z|² and |z|: the bailout test needs only the first, so the square
    /// root is off the loop's critical path.
    r2: T,
    r: T,
    dr: T,
    traps: OrbitTraps,
    i: u32,
}

impl<T: Number> OrbitState<T> {
    #[inline(always)]
    pub(super) fn start(fractal: &Fractal, p: Triplex<T>) -> Self {
        let (c, plus_one) = match fractal.julia {
            Some(k) => (
                [T::from_real(k.x), T::from_real(k.y), T::from_real(k.z)],
                0.0,
            ),
            None => (p, 1.0),
        };
        let r2 = length_squared(p);
        OrbitState {
            z: p,
            c,
            plus_one: T::from_real(plus_one),
            n: T::from_real(fractal.power),
            r2,
            r: r2.sqrt(),
            dr: T::from_real(1.0),
            traps: OrbitTraps {
                origin: Real::INFINITY,
                planes: DVec3::splat(Real::INFINITY),
            },
            i: 0,
        }
    }

    /// One iteration: z ↦ zⁿ + c with the running derivative and the traps.
    #[inline(always)]
    pub(super) fn step(&mut self, power: &impl Fn(Triplex<T>, T) -> (Triplex<T>, T)) {
        let z = self.z;
        let zv = DVec3::new(z[0].value(), z[1].value(), z[2].value());
        // |z|² as the orbit's own arithmetic rounds it (`r2`, so in f64
        // `zv.length_squared()` to the bit), as the vector kernels keep it.
        self.traps.origin = self.traps.origin.min(self.r2.value());
        self.traps.planes = self.traps.planes.min(zv.abs());
        let (w, r_n_minus_1) = power(z, self.r);
        self.dr = self.n * r_n_minus_1 * self.dr + self.plus_one;
        let c = self.c;
        self.z = [w[0] + c[0], w[1] + c[1], w[2] + c[2]];
        self.r2 = length_squared(self.z);
        self.r = self.r2.sqrt();
        self.i += 1;
    }

    /// Whether |z| has passed the bailout, tested on squares. A NaN radius
    /// has not, and keeps iterating to the limit.
    #[inline(always)]
    pub(super) fn outside(&self, bailout: Real) -> bool {
        self.r2.value() > bailout * bailout
    }

    #[inline(always)]
    pub(super) fn finish(self, bailout: Real) -> Orbit<T> {
        Orbit::ended(
            self.z, self.r2, self.r, self.dr, self.traps, self.i, bailout,
        )
    }
}

impl<T: Number> Orbit<T> {
    /// The orbit that stopped at `z` (|z|² = `r2`, |z| = `r`) after `i`
    /// iterations: what both orbit loops, scalar and vector, end with.
    #[inline(always)]
    pub(super) fn ended(
        z: Triplex<T>,
        r2: T,
        r: T,
        dr: T,
        traps: OrbitTraps,
        i: u32,
        bailout: Real,
    ) -> Orbit<T> {
        Orbit {
            z,
            r,
            dr,
            traps: traps.ended([z[0].value(), z[1].value(), z[2].value()], r2.value()),
            iterations: i,
            // `OrbitState::outside`.
            escaped: r2.value() > bailout * bailout,
        }
    }
}

impl Fractal {
    /// The Julia set of c = 0 in power 8: exactly the unit ball, a shape whose
    /// true distance is known (|p| − 1), for checking marching and shading.
    pub fn unit_ball() -> Fractal {
        Fractal {
            formula: Formula::Quilez,
            julia: Some(DVec3::ZERO),
            iterations: 40,
            ..Fractal::default()
        }
    }

    /// Iterates the orbit of `p`: at most `limit` iterations, stopping at the
    /// bailout when `stop_at_bailout` (otherwise exactly `limit`, as the
    /// escape-length gradient needs). Allocation-free (it adds its iterations
    /// to this thread's count): the innermost loop.
    #[inline]
    pub fn orbit<T: Number>(&self, p: Triplex<T>, limit: u32, stop_at_bailout: bool) -> Orbit<T> {
        let (formula, n) = (self.formula, self.power);
        // One copy of the loop per kind of exponent, so the classic power 8
        // unrolls into straight-line code.
        match whole_power(n) {
            Some(8) => self.orbit_with(p, limit, stop_at_bailout, |z, r| {
                whole_power_step(formula, z, r, 8)
            }),
            Some(k) => self.orbit_with(p, limit, stop_at_bailout, |z, r| {
                whole_power_step(formula, z, r, k)
            }),
            None => self.orbit_with(p, limit, stop_at_bailout, |z, r| {
                // One powf serves both: rⁿ = rⁿ⁻¹·r.
                let r_n_minus_1 = r.powf(n - 1.0);
                let w = triplex_power_trig_scaled(formula, z, r, n, r_n_minus_1 * r);
                (w, r_n_minus_1)
            }),
        }
    }

    /// Where the running derivative of `p`'s orbit reaches `value`, or why
    /// it does not within `limit` iterations: the f64 twin of
    /// `deep::Reference::derivative_passes`, one iteration at a time.
    pub fn derivative_passes(&self, p: DVec3, value: Real, limit: u32) -> Derivative {
        let (formula, n) = (self.formula, self.power);
        let escape = self.escape_radius::<Real>();
        let mut state = OrbitState::start(self, p.to_array());
        let whole = whole_power(n);
        let power = |z: Triplex<Real>, r: Real| match whole {
            Some(k) => whole_power_step(formula, z, r, k),
            None => {
                let r_n_minus_1 = r.powf(n - 1.0);
                (
                    triplex_power_trig_scaled(formula, z, r, n, r_n_minus_1 * r),
                    r_n_minus_1,
                )
            }
        };
        while state.i < limit {
            if state.dr >= value {
                return Derivative::Passes(state.i);
            }
            if state.outside(escape) {
                return Derivative::Escapes(state.i);
            }
            state.step(&power);
        }
        Derivative::Stays
    }

    /// The orbit loop, given the power step: (z, |z|) ↦ (zⁿ, |z|ⁿ⁻¹).
    #[inline(always)]
    pub(super) fn orbit_with<T: Number>(
        &self,
        p: Triplex<T>,
        limit: u32,
        stop_at_bailout: bool,
        power: impl Fn(Triplex<T>, T) -> (Triplex<T>, T),
    ) -> Orbit<T> {
        let escape = self.escape_radius::<T>();
        let mut state = OrbitState::start(self, p);
        while state.i < limit {
            if stop_at_bailout && state.outside(escape) {
                break;
            }
            state.step(&power);
        }
        ITERATIONS.with(|count| count.set(count.get() + state.i as u64));
        state.finish(escape)
    }
}

/// Where an orbit's running derivative passes a value
/// (`Fractal::derivative_passes`, `deep::Reference::derivative_passes`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Derivative {
    /// Its derivative passes the value after this many iterations.
    Passes(u32),
    /// It escapes after this many, before its derivative does.
    Escapes(u32),
    /// Neither within the reference's iterations: a point inside the set.
    Stays,
}
