//! Perturbed orbits side by side in SIMD registers. All lanes of a register
//! start on the reference together and take the common step together; a
//! lane that needs anything else (its escape, a rebase, a reference point
//! on the pole axis, the iteration limit) leaves the register and is
//! finished by the scalar loop (`Reference::run`) from where it stands.
//! Both do the same operations in the same order, so a lane's orbit is
//! bit-identical to the scalar one.

use super::super::kernel::{Stored, REGISTER};
use super::super::orbit::Orbit;
use super::super::power::{length_squared, powi};
use super::super::{Fractal, OrbitTraps};
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
        for (points, out) in self.points.chunks(lanes).zip(self.out.chunks_mut(lanes)) {
            register(simd, self.reference, self.fractal, points, out);
        }
    }
}

/// One register's worth of `points` (at most `S::F64_LANES`) into `out`.
#[inline(always)]
fn register<S: pulp::Simd>(
    simd: S,
    reference: &Reference,
    fractal: &Fractal,
    points: &[DVec3],
    out: &mut [Orbit<f64>],
) {
    let load = |axis: usize| {
        let mut a = Stored::ZERO;
        for (k, p) in points.iter().enumerate() {
            a[k] = p[axis];
        }
        Vector(simd, S::as_simd_f64s(&a[..S::F64_LANES]).0[0])
    };
    let store = |v: Vector<S>| {
        let mut a = Stored::ZERO;
        S::as_mut_simd_f64s(&mut a[..S::F64_LANES]).0[0] = v.1;
        a
    };
    let delta = [load(0), load(1), load(2)];
    let dc = reference.dc(fractal, delta);
    let dcs = dc.map(store);
    let mut s = reference.start(delta);
    let splat = |v: Real| Vector::splat(simd, v);
    let (mut origin, mut planes) = (splat(Real::INFINITY), [splat(Real::INFINITY); 3]);
    let plus_one = splat(if fractal.julia.is_none() { 1.0 } else { 0.0 });
    let nn = splat(reference.n as Real);
    let mut live = [false; REGISTER];
    live[..points.len()].fill(true);
    let limit = fractal.iterations;
    let track = &reference.main;
    loop {
        // Lanes that need more than the common step leave for the scalar loop.
        let (d, z, r2, dr) = (s.d.map(store), s.z.map(store), store(s.r2), store(s.dr));
        let (o, p) = (store(origin), planes.map(store));
        let common = s.i < limit && track.steps[s.m].is_some() && s.m + 1 < track.z.len();
        for k in 0..points.len() {
            if !live[k] {
                continue;
            }
            let dk = [d[0][k], d[1][k], d[2][k]];
            let leaves = !common || track.outside(s.m, dk) || r2[k] < length_squared(dk);
            if leaves {
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
                let dck = [dcs[0][k], dcs[1][k], dcs[2][k]];
                out[k] = reference.run(fractal, lane, dck, limit, true).orbit;
                live[k] = false;
            }
        }
        if !live.iter().any(|&l| l) {
            return;
        }
        // `Reference::run`'s step, operation for operation.
        let lesser = |a: Vector<S>, b: Vector<S>| {
            Vector(
                simd,
                simd.select_f64s(simd.less_than_f64s(a.1, b.1), a.1, b.1),
            )
        };
        origin = lesser(s.r2, origin);
        for (plane, zk) in planes.iter_mut().zip(s.z) {
            *plane = lesser(*plane, Vector(simd, simd.abs_f64s(zk.1)));
        }
        let r = s.r2.sqrt();
        s.dr = nn * powi(r, reference.n - 1, |a, b| a * b) * s.dr + plus_one;
        let point = track.steps[s.m].as_ref().expect("checked above");
        let difference = point.power_difference(fractal.formula, s.d);
        s.d = [0, 1, 2].map(|a| difference[a] + dc[a]);
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
    /// at each.
    pub(in crate::fractal) fn estimates_into(
        &self,
        fractal: &Fractal,
        points: &[DVec3],
        scales: &[Real],
        out: &mut [crate::fractal::Estimate],
    ) {
        let blank = Orbit {
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
        let arch = pulp::Arch::new();
        for ((points, scales), out) in points
            .chunks(REGISTER)
            .zip(scales.chunks(REGISTER))
            .zip(out.chunks_mut(REGISTER))
        {
            let mut orbits = [blank; REGISTER];
            arch.dispatch(Lanes {
                reference: self,
                fractal,
                points,
                out: &mut orbits[..points.len()],
            });
            for (((out, orbit), &p), &scale) in out.iter_mut().zip(&orbits).zip(points).zip(scales)
            {
                *out = fractal.estimate_finished(p, scale, orbit);
            }
        }
    }
}
