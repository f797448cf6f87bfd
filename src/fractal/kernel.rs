//! The vector kernel: 16 orbits side by side in SIMD registers (pulp), in
//! f64 or f32, each lane bit-identical to the scalar orbit, finished into
//! analytic estimates in the registers.

use super::estimate::{distance_to_ball, no_bound_applies};
#[cfg(test)]
use super::orbit::Orbit;
use super::orbit::ITERATIONS;
use super::power::{
    length_squared, powi, triplex_power_int_unchecked, triplex_power_trig, whole_power,
};
use super::{DeMethod, Estimate, Formula, Fractal, OrbitTraps, Precision, Triplex};
pub(super) use crate::math::Stored;
use crate::math::{Arith, DVec3, Lane, Number, Real, Stored32, Vector};
use std::marker::PhantomData;

impl Fractal {
    /// `N` orbits (Mandelbrot or Julia, stopping at the bailout) iterated
    /// side by side in f64, each lane of a vector register holding one
    /// orbit. Each lane does exactly the operations of `orbit`, so its
    /// result is bit-identical. For whole powers; `None` otherwise.
    /// Rendering takes `estimate_lanes`, which finishes the estimates in the
    /// registers; this is what the tests hold the vector orbit to.
    #[cfg(test)]
    pub(super) fn orbit_lanes<const N: usize>(
        &self,
        points: [DVec3; N],
    ) -> Option<[Orbit<f64>; N]> {
        let n = whole_power(self.power)?;
        let mut out = [Orbit::IDLE; N];
        self.in_vectors::<N, f64, _, true>(&points, n, &mut out);
        Some(out)
    }

    /// Analytic estimates at `N` points at once, finished in the vector
    /// registers their orbits ran in (f64 or f32, as the fractal asks):
    /// bit-identical to `estimate` at each point, faster in bulk. Other
    /// estimators and powers fall back to one `estimate` per point.
    pub fn estimate_lanes<const N: usize>(
        &self,
        points: [DVec3; N],
        scales: [Real; N],
    ) -> [Estimate; N] {
        let mut out = [Estimate::IDLE; N];
        self.estimate_lanes_into(&points, &scales, &mut out);
        out
    }

    /// `estimate_lanes` into `out`, for callers that keep one array of
    /// estimates from step to step.
    pub fn estimate_lanes_into<const N: usize>(
        &self,
        points: &[DVec3; N],
        scales: &[Real; N],
        out: &mut [Estimate; N],
    ) {
        self.lanes_into::<N, true>(points, scales, out)
    }

    /// `estimate_lanes_into` for walks that read only the distance, whether
    /// the orbit escaped and what it cost: the vector kernel then keeps no
    /// orbit traps and leaves `out`'s `traps` and `end` as they were.
    /// Distances, escapes, iterations and costs are the same bits as
    /// `estimate_lanes_into`'s.
    pub fn distance_lanes_into<const N: usize>(
        &self,
        points: &[DVec3; N],
        scales: &[Real; N],
        out: &mut [Estimate; N],
    ) {
        self.lanes_into::<N, false>(points, scales, out)
    }

    /// `estimate_lanes_into`, with orbit traps and ends or (`TRAPS` false,
    /// in the vector kernel) without.
    fn lanes_into<const N: usize, const TRAPS: bool>(
        &self,
        points: &[DVec3; N],
        scales: &[Real; N],
        out: &mut [Estimate; N],
    ) {
        if let Some(reference) = self.perturbed_analytic() {
            return reference.estimates_into(self, points, scales, out);
        }
        if let (Some(precision), Some(n)) = (self.lane_analytic(), whole_power(self.power)) {
            return match precision {
                Precision::F64 => self.analytic_lanes::<N, f64, TRAPS>(points, n, out),
                Precision::F32 => self.analytic_lanes::<N, f32, TRAPS>(points, n, out),
            };
        }
        for ((out, &p), &scale) in out.iter_mut().zip(points).zip(scales) {
            *out = self.estimate(p, scale);
        }
    }

    /// The vector kernel's analytic estimates in `E`, with their bounds.
    fn analytic_lanes<const N: usize, E: KernelLane, const TRAPS: bool>(
        &self,
        points: &[DVec3; N],
        n: u32,
        out: &mut [Estimate; N],
    ) {
        self.in_vectors::<N, E, _, TRAPS>(points, n, out);
        self.bound_lanes::<E>(points, out)
    }

    /// The bounds `estimate` puts on its estimator (`bounded`), on the
    /// vector kernel's estimates, outside the kernel: a cheap test but for
    /// the rare lane a bound applies to.
    pub(super) fn bound_lanes<T: Number>(&self, points: &[DVec3], out: &mut [Estimate]) {
        // `bounded`'s own first test, worked out once for all lanes.
        let near = self.escape_radius::<T>().min(2.0);
        let critical = self.julia.is_some();
        for (out, &p) in out.iter_mut().zip(points) {
            if out.escaped && !no_bound_applies(p, out.iterations, near, critical, out.distance) {
                let (distance, orbits) =
                    self.bounded::<T>(p, 0.0, out.distance, out.iterations, true);
                out.distance = distance;
                out.orbits += orbits;
            }
        }
    }

    /// `points` run through the vector kernel for whole power `n`, one
    /// vector at a time, each writing its results in place into `out`
    /// (lanes past the points start outside the bailout ball and cost no
    /// iterations), with the iterations counted for this thread; without
    /// orbit traps where `TRAPS` is false.
    #[inline(always)]
    pub(super) fn in_vectors<const N: usize, E: KernelLane, Out: Finished, const TRAPS: bool>(
        &self,
        points: &[DVec3; N],
        n: u32,
        out: &mut [Out; N],
    ) {
        for (chunk, out) in points.chunks(VECTOR).zip(out.chunks_mut(VECTOR)) {
            // Chunks of points and of results have the same lengths.
            if let Ok(lanes) = <&[DVec3; VECTOR]>::try_from(chunk) {
                let full = <&mut [Out; VECTOR]>::try_from(out).expect("as long as the points");
                E::dispatch(Kernel::<E, Out, TRAPS> {
                    fractal: self,
                    points: lanes,
                    live: VECTOR,
                    n,
                    out: full,
                    lane: PhantomData,
                });
            } else {
                let lanes: [DVec3; VECTOR] =
                    std::array::from_fn(|k| chunk.get(k).copied().unwrap_or(IDLE_POINT));
                // Starting from `out`, which a kernel without traps leaves
                // them in.
                let mut full = [Out::IDLE; VECTOR];
                full[..out.len()].copy_from_slice(out);
                E::dispatch(Kernel::<E, Out, TRAPS> {
                    fractal: self,
                    points: &lanes,
                    live: chunk.len(),
                    n,
                    out: &mut full,
                    lane: PhantomData,
                });
                out.copy_from_slice(&full[..out.len()]);
            }
        }
        let iterations: u64 = out.iter().map(|o| o.iterations() as u64).sum();
        ITERATIONS.with(|count| count.set(count.get() + iterations));
    }
}

/// A point for a lane with nothing to do: outside the bailout ball, so its
/// orbit ends before the first iteration.
pub const IDLE_POINT: DVec3 = DVec3::splat(Real::MAX);

/// Orbits the lane kernel takes per call: two AVX-512 registers of eight
/// f64 in flight at once (with AVX2, two registers of four at a time, twice).
pub const VECTOR: usize = 16;

/// The most f64 lanes one register has (AVX-512's eight), as `Stored` holds.
pub(super) const REGISTER: usize = VECTOR / 2;
const _: () = assert!(std::mem::size_of::<Stored>() == REGISTER * 8);

/// The vector kernel: `VECTOR` orbits of a whole power `n` in `E` (f64 or
/// f32), compiled for each instruction set and picked at run time by the
/// processor (`KernelLane::dispatch`), so one binary runs
/// everywhere and uses the widest registers it finds. Each operation is
/// written out as the vector instruction it is, so the speed does not rest
/// on the compiler vectorising; Rust never fuses a multiply and an add
/// unasked, so every version rounds exactly as the scalar `orbit` does.
/// `Kernel<Estimate>` writes the analytic estimates, finished in the
/// registers; `Kernel<Orbit<f64>>`, for the tests, the orbits. Only the first
/// `live` points are wanted: the rest are padding (`IDLE_POINT`), and a
/// register of nothing but padding is loaded but neither iterated nor
/// finished, its results left as they were (`Finished::IDLE` from
/// `in_vectors`). `TRAPS` false leaves out the orbit traps and ends
/// (`Fractal::distance_lanes_into`).
pub(super) struct Kernel<'a, E, Out, const TRAPS: bool> {
    pub(super) fractal: &'a Fractal,
    pub(super) points: &'a [DVec3; VECTOR],
    pub(super) live: usize,
    /// The whole power.
    pub(super) n: u32,
    pub(super) out: &'a mut [Out; VECTOR],
    pub(super) lane: PhantomData<E>,
}

impl<E: KernelLane, Out: Finished, const TRAPS: bool> pulp::WithSimd for Kernel<'_, E, Out, TRAPS> {
    type Output = ();

    #[inline(always)]
    fn with_simd<S: pulp::Simd>(self, simd: S) {
        let Self {
            fractal,
            points,
            live,
            n,
            out,
            lane: _,
        } = self;
        run_vector::<S, E, Out, TRAPS>(simd, fractal, points, live, n, out)
    }
}

/// What a register's finished lanes become. A trait rather than a closure
/// so it is inlined into the code compiled for the instruction set.
pub(super) trait Finished: Copy {
    const IDLE: Self;
    /// The orbit iterations this result took.
    fn iterations(&self) -> u32;
    /// `escape` is the escape radius the orbits stopped at; `traps`,
    /// whether the register kept its orbit traps.
    fn write<S: pulp::Simd>(
        register: &Register<S>,
        fractal: &Fractal,
        points: &[DVec3],
        out: &mut [Self],
        escape: Real,
        traps: bool,
    );
}

#[cfg(test)]
impl Finished for Orbit<f64> {
    const IDLE: Self = Orbit::IDLE;
    fn iterations(&self) -> u32 {
        self.iterations
    }
    #[inline(always)]
    fn write<S: pulp::Simd>(
        register: &Register<S>,
        _: &Fractal,
        _: &[DVec3],
        out: &mut [Self],
        escape: Real,
        _: bool,
    ) {
        register.finish(out, escape)
    }
}

impl Finished for Estimate {
    const IDLE: Self = Estimate::IDLE;
    fn iterations(&self) -> u32 {
        self.iterations
    }
    #[inline(always)]
    fn write<S: pulp::Simd>(
        register: &Register<S>,
        fractal: &Fractal,
        points: &[DVec3],
        out: &mut [Self],
        escape: Real,
        traps: bool,
    ) {
        register.estimates(fractal, points, out, escape, traps)
    }
}

/// A float the kernel iterates orbits in: f64, whose registers are finished
/// as they are, or f32, whose lanes are widened to f64 (exactly) first, as
/// the scalar f32 estimate finishes in f64.
pub(super) trait KernelLane: Lane + Number {
    /// Runs `op` with the instruction set this float's kernel uses.
    fn dispatch<Op: pulp::WithSimd<Output = ()>>(op: Op);
    fn write<S: pulp::Simd, Out: Finished>(
        register: &Register<S, Self>,
        fractal: &Fractal,
        points: &[DVec3],
        out: &mut [Out],
        escape: Real,
        traps: bool,
    );
}

impl KernelLane for f64 {
    #[inline(always)]
    fn dispatch<Op: pulp::WithSimd<Output = ()>>(op: Op) {
        pulp::Arch::new().dispatch(op)
    }
    #[inline(always)]
    fn write<S: pulp::Simd, Out: Finished>(
        register: &Register<S>,
        fractal: &Fractal,
        points: &[DVec3],
        out: &mut [Out],
        escape: Real,
        traps: bool,
    ) {
        Out::write(register, fractal, points, out, escape, traps)
    }
}

impl KernelLane for f32 {
    /// AVX2's registers of eight f32 where the processor has them (AVX-512's
    /// sixteen would hold a whole call in one register, leaving nothing to
    /// overlap its square roots with), else one lane at a time.
    #[inline(always)]
    fn dispatch<Op: pulp::WithSimd<Output = ()>>(op: Op) {
        #[cfg(target_arch = "x86_64")]
        if let Some(simd) = pulp::x86::V3::try_new() {
            return pulp::Simd::vectorize(simd, op);
        }
        pulp::Simd::vectorize(pulp::Scalar::new(), op)
    }
    #[inline(always)]
    fn write<S: pulp::Simd, Out: Finished>(
        register: &Register<S, f32>,
        fractal: &Fractal,
        points: &[DVec3],
        out: &mut [Out],
        escape: Real,
        traps: bool,
    ) {
        let wide = S::F64_LANES;
        for (k, (points, out)) in points.chunks(wide).zip(out.chunks_mut(wide)).enumerate() {
            let register = register.widened(k * wide);
            Out::write(&register, fractal, points, out, escape, traps);
        }
    }
}

/// Lanes `from..` of an f32 register as a register of f64, exactly.
#[inline(always)]
fn widen<S: pulp::Simd>(simd: S, v: Vector<S, f32>, from: usize) -> Vector<S> {
    let narrow: Stored32 = Register::<S, f32>::store(v);
    let mut wide = Stored::ZERO;
    for (w, &x) in wide.iter_mut().zip(&narrow.0[from..]) {
        *w = x as f64;
    }
    Register::<S>::load(simd, &wide)
}

impl<S: pulp::Simd> Register<S, f32> {
    /// Lanes `from..` as a register of f64 to finish: its orbits' state
    /// widened exactly (`c` is left as `z`: a widened register is not
    /// iterated again).
    #[inline(always)]
    fn widened(&self, from: usize) -> Register<S> {
        let simd = self.simd;
        let z = [
            widen(simd, self.z[0], from),
            widen(simd, self.z[1], from),
            widen(simd, self.z[2], from),
        ];
        let planes = [
            widen(simd, self.planes[0], from),
            widen(simd, self.planes[1], from),
            widen(simd, self.planes[2], from),
        ];
        let i = widen(simd, self.i, from);
        Register {
            simd,
            z,
            c: z,
            plus_one: self.plus_one,
            r2: widen(simd, self.r2, from),
            r: widen(simd, self.r, from),
            dr: widen(simd, self.dr, from),
            origin: widen(simd, self.origin, from),
            planes,
            i,
            running: simd.equal_f64s(i.1, i.1),
        }
    }
}

/// Runs the first `live` of `points` two registers at a time; each
/// register, with its points, writes its lanes' results (`Finished::write`).
/// Registers past `live` are skipped.
#[inline(always)]
pub(super) fn run_vector<S: pulp::Simd, E: KernelLane, Out: Finished, const TRAPS: bool>(
    simd: S,
    fractal: &Fractal,
    points: &[DVec3; VECTOR],
    live: usize,
    n: u32,
    out: &mut [Out; VECTOR],
) {
    // Registers are stored in `Stored` arrays of `REGISTER` f64 lanes.
    const { assert!(S::F64_LANES >= 1 && S::F64_LANES <= REGISTER) };
    let lanes = E::lanes::<S>();
    // Two registers of `E` in one call (`KernelLane::dispatch` keeps f32
    // to registers of eight).
    assert!(lanes >= 1 && 2 * lanes <= VECTOR);
    // Worked out once: the escape test runs every iteration.
    let escape = fractal.escape_radius::<E>();
    let bound = E::escape_bound(escape * escape);
    // Two registers at a time: their dependency chains are independent,
    // so the processor overlaps one's square roots and division with
    // the other's multiplications instead of waiting.
    let pairs = live.div_ceil(2 * lanes);
    for (pair, (points, out)) in points
        .chunks(2 * lanes)
        .zip(out.chunks_mut(2 * lanes))
        .take(pairs)
        .enumerate()
    {
        // One copy of the loop per formula, with its shape a constant, and
        // for each one's classic power (the bulb's 8, the quaternion's 2)
        // one whose powers unroll.
        let f = fractal;
        let (a, b) = match (f.formula, n) {
            (Formula::Quilez, 8) => {
                orbit_registers(simd, f, points, bound, 8, Formula::Quilez, TRAPS)
            }
            (Formula::Asin, 8) => orbit_registers(simd, f, points, bound, 8, Formula::Asin, TRAPS),
            (Formula::WhiteNylander, 8) => {
                orbit_registers(simd, f, points, bound, 8, Formula::WhiteNylander, TRAPS)
            }
            (Formula::Quaternion, 2) => {
                orbit_registers(simd, f, points, bound, 2, Formula::Quaternion, TRAPS)
            }
            (Formula::Quilez, n) => {
                orbit_registers(simd, f, points, bound, n, Formula::Quilez, TRAPS)
            }
            (Formula::Asin, n) => orbit_registers(simd, f, points, bound, n, Formula::Asin, TRAPS),
            (Formula::WhiteNylander, n) => {
                orbit_registers(simd, f, points, bound, n, Formula::WhiteNylander, TRAPS)
            }
            (Formula::Quaternion, n) => {
                orbit_registers(simd, f, points, bound, n, Formula::Quaternion, TRAPS)
            }
        };
        let (first, second) = out.split_at_mut(lanes);
        E::write(&a, f, &points[..lanes], first, escape, TRAPS);
        // A second register of padding alone has stayed where it started.
        if live > (2 * pair + 1) * lanes {
            E::write(&b, f, &points[lanes..], second, escape, TRAPS);
        }
    }
}

/// Two registers of orbits iterated in one loop (see `Register`), stopping
/// at `bound` (`Lane::escape_bound` of the squared escape radius), keeping
/// orbit traps where `traps` asks.
#[inline(always)]
pub(super) fn orbit_registers<S: pulp::Simd, E: Lane + Number>(
    simd: S,
    fractal: &Fractal,
    points: &[DVec3],
    bound: E,
    n: u32,
    formula: Formula,
    traps: bool,
) -> (Register<S, E>, Register<S, E>) {
    let lanes = points.len() / 2;
    let mut a = Register::start(simd, fractal, &points[..lanes]);
    let mut b = Register::start(simd, fractal, &points[lanes..]);
    // The iteration count is kept in `E`, exact to 2²⁴ in f32.
    debug_assert!(Real::from(fractal.iterations) * E::EPSILON < 1.0);
    for _ in 0..fractal.iterations {
        let (run_a, run_b) = (a.check(bound), b.check(bound));
        if !(run_a || run_b) {
            break;
        }
        if run_a {
            a.step(formula, n, traps);
        }
        if run_b {
            b.step(formula, n, traps);
        }
    }
    (a, b)
}

/// One register of orbits: `OrbitState` on `Vector`s of f64 or f32, each
/// lane's state frozen by selection once it has escaped. Lanes near the
/// pole axis take the trigonometric form one at a time, as
/// `whole_power_step` does.
#[derive(Clone, Copy)]
pub(super) struct Register<S: pulp::Simd, E: Lane = f64> {
    simd: S,
    z: Triplex<Vector<S, E>>,
    c: Triplex<Vector<S, E>>,
    plus_one: f64,
    r2: Vector<S, E>,
    r: Vector<S, E>,
    dr: Vector<S, E>,
    origin: Vector<S, E>,
    planes: Triplex<Vector<S, E>>,
    i: Vector<S, E>,
    running: E::Mask<S>,
}

impl<S: pulp::Simd, E: Lane + Number> Register<S, E> {
    #[inline(always)]
    pub(super) fn splat(&self, v: f64) -> Vector<S, E> {
        Vector::splat(self.simd, v)
    }

    #[inline(always)]
    pub(super) fn select(
        &self,
        mask: E::Mask<S>,
        new: Vector<S, E>,
        old: Vector<S, E>,
    ) -> Vector<S, E> {
        Vector(self.simd, E::select(self.simd, mask, new.1, old.1))
    }

    #[inline(always)]
    pub(super) fn any(&self, mask: E::Mask<S>) -> bool {
        E::first_true(self.simd, mask) < E::lanes::<S>()
    }

    #[inline(always)]
    pub(super) fn store(v: Vector<S, E>) -> E::Stored {
        let mut a = E::Stored::default();
        E::store::<S>(v.1, a.as_mut());
        a
    }

    #[inline(always)]
    pub(super) fn load(simd: S, a: &E::Stored) -> Vector<S, E> {
        Vector(simd, E::load::<S>(a.as_ref()))
    }

    /// The orbits of `points` (one register's worth) before iterating.
    #[inline(always)]
    pub(super) fn start(simd: S, fractal: &Fractal, points: &[DVec3]) -> Self {
        debug_assert_eq!(points.len(), E::lanes::<S>());
        let mut xyz = [E::Stored::default(); 3];
        for (k, p) in points.iter().enumerate() {
            for (axis, v) in xyz.iter_mut().zip([p.x, p.y, p.z]) {
                axis.as_mut()[k] = E::from_f64(v);
            }
        }
        let z = [
            Self::load(simd, &xyz[0]),
            Self::load(simd, &xyz[1]),
            Self::load(simd, &xyz[2]),
        ];
        let splat = |v: f64| Vector::splat(simd, v);
        let (c, plus_one) = match fractal.julia {
            Some(k) => ([splat(k.x), splat(k.y), splat(k.z)], 0.0),
            None => (z, 1.0),
        };
        let r2 = length_squared(z);
        let infinity = splat(Real::INFINITY);
        Register {
            simd,
            z,
            c,
            plus_one,
            r2,
            r: r2.sqrt(),
            dr: splat(1.0),
            origin: infinity,
            planes: [infinity; 3],
            i: splat(0.0),
            running: E::equal(simd, infinity.1, infinity.1),
        }
    }

    /// Stops the lanes past the bailout (`OrbitState::outside`: a NaN
    /// radius keeps iterating alike); whether any lane still runs.
    /// `bound` is `Lane::escape_bound` of the squared escape radius.
    #[inline(always)]
    pub(super) fn check(&mut self, bound: E) -> bool {
        let simd = self.simd;
        let outside = self.outside(bound);
        self.running = E::and(simd, self.running, E::not(simd, outside));
        self.any(self.running)
    }

    /// The lanes past the bailout (`OrbitState::outside`).
    #[inline(always)]
    pub(super) fn outside(&self, bound: E) -> E::Mask<S> {
        E::past(self.simd, self.r2.1, E::splat(self.simd, bound))
    }

    /// `OrbitState::step` on the running lanes; the traps stay as they
    /// started unless `traps` asks.
    #[inline(always)]
    pub(super) fn step(&mut self, formula: Formula, n: u32, traps: bool) {
        let simd = self.simd;
        let (one, infinity) = (self.splat(1.0), self.splat(Real::INFINITY));
        let (z, running) = (self.z, self.running);
        let (mut w, rho2, power_r2) = triplex_power_int_unchecked(formula, z, n, one);
        // `triplex_power_int`'s test, lane by lane.
        let finite = |v: Vector<S, E>| E::less(simd, E::abs(simd, v.1), infinity.1);
        let margin = self.splat(formula.shape().axis_margin());
        let usable = E::and(
            simd,
            E::greater(simd, rho2.1, (margin * power_r2).1),
            E::and(simd, E::and(simd, finite(w[0]), finite(w[1])), finite(w[2])),
        );
        let near_axis = E::and(simd, running, E::not(simd, usable));
        if self.any(near_axis) {
            let flags = Self::store(self.select(near_axis, one, self.splat(0.0)));
            let exact =
                near_axis_powers::<E>(formula, z.map(Self::store), Self::store(self.r), n, &flags);
            for axis in 0..3 {
                let fixed = Self::load(simd, &exact[axis]);
                w[axis] = self.select(near_axis, fixed, w[axis]);
            }
        }
        if traps {
            self.trap(z);
        }
        let power = self.splat(n as Real);
        let dr = power * powi(self.r, n - 1, |a, b| a * b) * self.dr + self.splat(self.plus_one);
        self.dr = self.select(running, dr, self.dr);
        let c = self.c;
        let next_z = [w[0] + c[0], w[1] + c[1], w[2] + c[2]];
        let next_r2 = length_squared(next_z);
        self.r2 = self.select(running, next_r2, self.r2);
        self.r = self.select(running, next_r2.sqrt(), self.r);
        for axis in 0..3 {
            self.z[axis] = self.select(running, next_z[axis], z[axis]);
        }
        self.i = self.select(running, self.i + one, self.i);
    }
}

impl<S: pulp::Simd, E: Lane + Number> Register<S, E> {
    /// The running lanes' traps updated with `z`, as the scalar step: f64::min
    /// for the origin trap (a NaN never replaces a number), glam's
    /// `if a < b { a } else { b }` for the planes (a NaN |z| does).
    #[inline(always)]
    fn trap(&mut self, z: Triplex<Vector<S, E>>) {
        let (simd, running) = (self.simd, self.running);
        let lesser =
            |a: Vector<S, E>, b: Vector<S, E>| E::select(simd, E::less(simd, a.1, b.1), a.1, b.1);
        let origin = lesser(self.r2, self.origin);
        self.origin = Vector(simd, E::select(simd, running, origin, self.origin.1));
        for (plane, z) in self.planes.iter_mut().zip(z) {
            let next = lesser(*plane, Vector(simd, E::abs(simd, z.1)));
            *plane = Vector(simd, E::select(simd, running, next, plane.1));
        }
    }
}

impl<S: pulp::Simd> Register<S, f64> {
    /// The finished orbits, into `out` (one per lane).
    #[cfg(test)]
    #[inline(always)]
    pub(super) fn finish(&self, out: &mut [Orbit<f64>], escape: Real) {
        let store = Self::store;
        let (z, planes) = (self.z.map(store), self.planes.map(store));
        let [origin, r2, r, dr, i] = [self.origin, self.r2, self.r, self.dr, self.i].map(store);
        for (k, out) in out.iter_mut().enumerate() {
            let traps = OrbitTraps {
                origin: origin[k],
                planes: DVec3::new(planes[0][k], planes[1][k], planes[2][k]),
            };
            let end = [z[0][k], z[1][k], z[2][k]];
            *out = Orbit::ended(end, r2[k], r[k], dr[k], traps, i[k] as u32, escape);
        }
    }

    /// The analytic estimates at `points` (one per lane) from the finished
    /// orbits, into `out`: `estimate_from_orbit`'s formula, its logarithm
    /// and division taken in the registers, and so is the choice among its
    /// cases and the traps' ending (`Orbit::ended`), exact as selections;
    /// a point outside the bailout from the start, which is rare, goes
    /// lane by lane. Without `traps` (the register kept none), `out`'s
    /// traps and ends are left as they were.
    #[inline(always)]
    pub(super) fn estimates(
        &self,
        fractal: &Fractal,
        points: &[DVec3],
        out: &mut [Estimate],
        escape: Real,
        traps: bool,
    ) {
        // The analytic estimator is the only one finished here
        // (`estimate_lanes_into` sends the others one point at a time).
        debug_assert!(fractal.de == DeMethod::Analytic);
        let simd = self.simd;
        let (r, dr) = (self.r, self.dr);
        let (zero, one, infinity) = (self.splat(0.0), self.splat(1.0), self.splat(Real::INFINITY));
        // `half_r_ln_r_over`, operation for operation.
        let raw = self.splat(0.5) * crate::math::ln_in_range(r) * r / dr;
        // The cases of `estimate_from_orbit`. An escaped orbit that took a
        // step ends with r in `in_ln_range` (at least ½ and finite), or
        // else its estimate is not above 0 or not finite, which
        // `as_distance` makes 0 as it does here: so one selection holds
        // `as_distance` and every case but the rare one.
        let escaped = self.outside(escape * escape);
        let stepped = simd.greater_than_or_equal_f64s(self.i.1, one.1);
        let in_range = simd.and_m64s(
            simd.greater_than_or_equal_f64s(r.1, self.splat(0.5).1),
            simd.less_than_f64s(r.1, infinity.1),
        );
        let usual = simd.and_m64s(
            simd.and_m64s(escaped, simd.and_m64s(stepped, in_range)),
            simd.and_m64s(
                simd.greater_than_f64s(raw.1, zero.1),
                simd.less_than_f64s(raw.1, infinity.1),
            ),
        );
        let distance = self.select(usual, raw, zero);
        let rare = simd.and_m64s(escaped, simd.not_m64s(stepped));
        let store = Self::store;
        let (distance, i) = (store(distance), store(self.i));
        let escaped = store(self.select(escaped, one, zero));
        if traps {
            self.write_with_traps(out, &distance, &i, &escaped);
        } else {
            for (k, out) in out.iter_mut().enumerate() {
                out.distance = distance[k];
                out.iterations = i[k] as u32;
                out.escaped = escaped[k] != 0.0;
                out.orbits = 1;
            }
        }
        if self.any(rare) {
            let rare = store(self.select(rare, one, zero));
            for k in (0..out.len()).filter(|&k| rare[k] != 0.0) {
                out[k].distance = distance_to_ball(points[k], escape);
            }
        }
    }

    /// The estimates of `estimates` (their stored distances, iterations and
    /// escapes) with the finished orbits' traps and ends, into `out`.
    #[inline(always)]
    fn write_with_traps(
        &self,
        out: &mut [Estimate],
        distance: &Stored,
        i: &Stored,
        escaped: &Stored,
    ) {
        let simd = self.simd;
        let infinity = self.splat(Real::INFINITY);
        // `OrbitTraps::ended`: an orbit whose origin trap is still +∞ met
        // no trap and takes those of where it ended (its |z|² is `r2`,
        // computed as `length_squared` computes it).
        let untrapped = simd.equal_f64s(self.origin.1, infinity.1);
        let origin = self.select(untrapped, self.r2, self.origin);
        // No closures: inside pulp's instruction-set functions one may not
        // be inlined, which would make each vector operation a call.
        let mut planes = [Stored::ZERO; 3];
        for ((plane, z), met) in planes.iter_mut().zip(self.z).zip(self.planes) {
            let end = Vector(simd, simd.abs_f64s(z.1));
            *plane = Self::store(self.select(untrapped, end, met));
        }
        let origin = Self::store(origin);
        let end = self.z.map(Self::store);
        for (k, out) in out.iter_mut().enumerate() {
            *out = Estimate {
                distance: distance[k],
                traps: OrbitTraps {
                    origin: origin[k],
                    planes: DVec3::new(planes[0][k], planes[1][k], planes[2][k]),
                },
                iterations: i[k] as u32,
                escaped: escaped[k] != 0.0,
                orbits: 1,
                end: [end[0][k], end[1][k], end[2][k]],
            };
        }
    }
}

/// The trigonometric power of the lanes flagged (non-zero) in `which`, as
/// `whole_power_step` takes it near the pole axis; other lanes are left 0.
/// Rare, and out of line so the vector loop keeps its registers.
#[cold]
#[inline(never)]
pub(super) fn near_axis_powers<E: Lane + Number>(
    formula: Formula,
    z: [E::Stored; 3],
    r: E::Stored,
    n: u32,
    which: &E::Stored,
) -> [E::Stored; 3] {
    let mut out = [E::Stored::default(); 3];
    let r = r.as_ref();
    for k in (0..which.as_ref().len()).filter(|&k| which.as_ref()[k] != E::default()) {
        let at = [z[0].as_ref()[k], z[1].as_ref()[k], z[2].as_ref()[k]];
        let exact = triplex_power_trig(formula, at, r[k], n as Real);
        for axis in 0..3 {
            out[axis].as_mut()[k] = exact[axis];
        }
    }
    out
}
