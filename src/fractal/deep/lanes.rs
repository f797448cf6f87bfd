//! Perturbed orbits side by side in SIMD registers. All lanes of a register
//! start on the reference together and take the common step together; a
//! lane that needs anything else (its escape, a rebase, a reference point
//! on the pole axis, the iteration limit) leaves the register and is
//! finished by the scalar loop (`Reference::run`) from where it stands.
//! Both do the same operations in the same order, so a lane's orbit is
//! bit-identical to the scalar one.

use super::super::kernel::{Register as Kernel, Stored, IDLE_POINT, REGISTER, VECTOR};
use super::super::orbit::Orbit;
use super::super::power::{length_squared, powi};
use super::super::{Estimate, Fractal, OrbitTraps};
use super::{add, Reference, State};
use crate::math::{Arith, DVec3, Real, Vector};

/// The perturbed orbits of `points` (offsets from the anchor), one
/// register of them at a time, each stopping at the bailout.
pub(super) struct Lanes<'a> {
    pub reference: &'a Reference,
    pub fractal: &'a Fractal,
    pub points: &'a [DVec3],
    pub out: &'a mut [Orbit<f64>],
}

impl pulp::WithSimd for Lanes<'_> {
    type Output = ();

    #[inline(always)]
    fn with_simd<S: pulp::Simd>(self, simd: S) {
        let lanes = S::F64_LANES;
        let (reference, fractal) = (self.reference, self.fractal);
        // Two registers at a time: their chains of dependent operations are
        // independent, so the processor overlaps them.
        for (points, out) in self
            .points
            .chunks(2 * lanes)
            .zip(self.out.chunks_mut(2 * lanes))
        {
            let split = points.len().min(lanes);
            let (first, second) = out.split_at_mut(split);
            let mut a = Register::start(simd, reference, fractal, &points[..split]);
            let mut b = Register::start(simd, reference, fractal, &points[split..]);
            loop {
                let run_a = a.check(reference, fractal, first);
                let run_b = b.check(reference, fractal, second);
                if !(run_a || run_b) {
                    break;
                }
                if run_a {
                    a.step(reference, fractal);
                }
                if run_b {
                    b.step(reference, fractal);
                }
            }
        }
    }
}

/// One register of perturbed orbits on the main reference, and which of
/// its lanes are still in it.
struct Register<S: pulp::Simd> {
    simd: S,
    s: State<Vector<S>>,
    dc: [Vector<S>; 3],
    origin: Vector<S>,
    planes: [Vector<S>; 3],
    live: [bool; REGISTER],
    count: usize,
    /// 1 in Mandelbrot mode, 0 in Julia mode; and the power: the
    /// derivative's constants, splatted once.
    plus_one: Vector<S>,
    power: Vector<S>,
}

impl<S: pulp::Simd> Register<S> {
    #[inline(always)]
    fn splat(&self, v: Real) -> Vector<S> {
        Vector::splat(self.simd, v)
    }

    #[inline(always)]
    fn store(v: Vector<S>) -> Stored {
        Kernel::<S>::store(v)
    }

    /// The orbits of `points` (at most a register of them) before iterating.
    #[inline(always)]
    fn start(simd: S, reference: &Reference, fractal: &Fractal, points: &[DVec3]) -> Self {
        let load = |axis: usize| {
            let mut a = Stored::ZERO;
            for (k, p) in points.iter().enumerate() {
                a[k] = p[axis];
            }
            Kernel::load(simd, &a)
        };
        let delta = [load(0), load(1), load(2)];
        let infinity = Vector::splat(simd, Real::INFINITY);
        let mut live = [false; REGISTER];
        live[..points.len()].fill(true);
        Register {
            simd,
            s: reference.start(delta),
            dc: reference.dc(fractal, delta),
            origin: infinity,
            planes: [infinity; 3],
            live,
            count: points.len(),
            plus_one: Vector::splat(
                simd,
                if fractal.julia.is_none() {
                    reference.dr_scale
                } else {
                    0.0
                },
            ),
            power: Vector::splat(simd, reference.n as Real),
        }
    }

    /// Sends the lanes that need more than the common step to the scalar
    /// loop, which writes their orbits to `out`; whether any lane is left.
    #[inline(always)]
    fn check(&mut self, reference: &Reference, fractal: &Fractal, out: &mut [Orbit<f64>]) -> bool {
        if self.count == 0 {
            return false;
        }
        let (simd, s, track) = (self.simd, &self.s, &reference.main);
        let limit = fractal.iterations;
        let common = s.i < limit && track.steps[s.m].is_some() && s.m + 1 < track.z.len();
        // `Track::outside` and `Reference::run`'s rebase test, in the register.
        let leaving = !common || {
            let z = track.z[s.m];
            let mut sum = self.splat(track.excess[s.m]);
            for (zk, dk) in z.iter().zip(s.d) {
                sum = sum + (self.splat(2.0 * zk) + dk) * dk;
            }
            let outside = simd.greater_than_f64s(sum.1, self.splat(0.0).1);
            let rebase = simd.less_than_f64s(s.r2.1, length_squared(s.d).1);
            let either = simd.or_m64s(outside, rebase);
            let flags = Self::store(Vector(
                simd,
                simd.select_f64s(either, self.splat(1.0).1, self.splat(0.0).1),
            ));
            (0..REGISTER).any(|k| self.live[k] && flags[k] > 0.0)
        };
        if !leaving {
            return true;
        }
        let store = Self::store;
        let (d, z, r2, dr) = (s.d.map(store), s.z.map(store), store(s.r2), store(s.dr));
        let (o, p, dc) = (
            store(self.origin),
            self.planes.map(store),
            self.dc.map(store),
        );
        for k in 0..REGISTER {
            if !self.live[k] {
                continue;
            }
            let dk = [d[0][k], d[1][k], d[2][k]];
            if !common || track.outside(s.m, dk) || r2[k] < length_squared(dk) {
                let lane = State {
                    d: dk,
                    z: [z[0][k], z[1][k], z[2][k]],
                    r2: r2[k],
                    dr: dr[k],
                    traps: OrbitTraps {
                        origin: o[k],
                        planes: DVec3::new(p[0][k], p[1][k], p[2][k]),
                    },
                    ..s.place()
                };
                let dck = [dc[0][k], dc[1][k], dc[2][k]];
                out[k] = reference.run(fractal, lane, dck, limit, true).orbit;
                self.live[k] = false;
                self.count -= 1;
            }
        }
        self.count > 0
    }

    /// `Reference::run`'s step, operation for operation, on every lane.
    #[inline(always)]
    fn step(&mut self, reference: &Reference, fractal: &Fractal) {
        let simd = self.simd;
        let lesser = |a: Vector<S>, b: Vector<S>| {
            Vector(
                simd,
                simd.select_f64s(simd.less_than_f64s(a.1, b.1), a.1, b.1),
            )
        };
        let s = &mut self.s;
        self.origin = lesser(s.r2, self.origin);
        for (plane, zk) in self.planes.iter_mut().zip(s.z) {
            *plane = lesser(*plane, Vector(simd, simd.abs_f64s(zk.1)));
        }
        let r = s.r2.sqrt();
        s.dr = self.power * powi(r, reference.n - 1, |a, b| a * b) * s.dr + self.plus_one;
        let track = &reference.main;
        let point = track.steps[s.m].as_ref().expect("checked before the step");
        let difference = point.power_difference(fractal.formula, s.d);
        s.d = [0, 1, 2].map(|a| difference[a] + self.dc[a]);
        s.m += 1;
        s.z = add(track.z[s.m], s.d);
        s.r2 = length_squared(s.z);
        s.i += 1;
    }
}

impl<S: pulp::Simd> State<Vector<S>> {
    /// The register's place on the reference, for a lane leaving it (its
    /// own values are filled in by the caller).
    fn place(&self) -> State<Real> {
        State {
            on_origin: self.on_origin,
            m: self.m,
            d: [0.0; 3],
            z: [0.0; 3],
            r2: 0.0,
            dr: 0.0,
            traps: OrbitTraps {
                origin: 0.0,
                planes: DVec3::ZERO,
            },
            i: self.i,
            rebased: self.rebased,
        }
    }
}

impl Reference {
    /// The analytic estimates at `points` (offsets from the anchor), a
    /// register of orbits at a time: bit-identical to `Fractal::estimate`
    /// at each. The points f64 resolves (`resolves_in_f64`) go to the plain
    /// kernel at their world positions, the others to perturbed orbits.
    pub(in crate::fractal) fn estimates_into(
        &self,
        fractal: &Fractal,
        points: &[DVec3],
        scales: &[Real],
        out: &mut [Estimate],
    ) {
        let arch = pulp::Arch::new();
        let plain = fractal.plain();
        for ((points, scales), out) in points
            .chunks(VECTOR)
            .zip(scales.chunks(VECTOR))
            .zip(out.chunks_mut(VECTOR))
        {
            let mut world = [IDLE_POINT; VECTOR];
            let mut deep = Partition::default();
            for (k, (&p, &scale)) in points.iter().zip(scales).enumerate() {
                match self.resolves_in_f64(p, scale) {
                    true => world[k] = self.anchor + p,
                    false => deep.push(k, p, scale),
                }
            }
            if deep.count < points.len() {
                let mut estimates = [Estimate::IDLE; VECTOR];
                let mut padded = [0.0; VECTOR];
                padded[..scales.len()].copy_from_slice(scales);
                plain.estimate_lanes_into(&world, &padded, &mut estimates);
                out.copy_from_slice(&estimates[..out.len()]);
            }
            let count = deep.count;
            let mut orbits = [Orbit::IDLE; VECTOR];
            if count > 0 {
                arch.dispatch(Lanes {
                    reference: self,
                    fractal,
                    points: &deep.points[..count],
                    out: &mut orbits[..count],
                });
            }
            for (j, orbit) in orbits[..count].iter().enumerate() {
                let (k, p, scale) = (deep.index[j], deep.points[j], deep.scales[j]);
                out[k] = fractal.estimate_finished(p, scale, orbit);
            }
        }
    }
}

/// The points of a register's worth that need perturbed orbits, packed,
/// with where each came from.
#[derive(Default)]
struct Partition {
    index: [usize; VECTOR],
    points: [DVec3; VECTOR],
    scales: [Real; VECTOR],
    count: usize,
}

impl Partition {
    #[inline(always)]
    fn push(&mut self, k: usize, p: DVec3, scale: Real) {
        (self.index[self.count], self.points[self.count]) = (k, p);
        self.scales[self.count] = scale;
        self.count += 1;
    }
}
